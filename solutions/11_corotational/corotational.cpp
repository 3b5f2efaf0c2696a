// The corotational element and model: the rotated stiffness and force of a tet (exercises 11.4,
// 11.5), the shape-gradient form, and CorotationalElasticity, whose warped stiffness K_R is
// exercise 11.6. The rotations are rotations.cpp's (and polar_newton.cpp's, the fast ones).
// docs/11_corotational.md#forces-and-warped-stiffness
#include "11_corotational/corotational.hpp"

#include "common/error.hpp"
#include "common/parallel.hpp"
#include "common/vtk_io.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>

namespace fem::corot {
namespace {

/// x_e as 12 vertex-major coordinates of tet t from a #V×3 matrix.
Vector12d element_vector(const TetMesh& mesh, const MatrixX3d& positions, Eigen::Index t)
{
    Vector12d q;
    for (int i = 0; i < 4; ++i)
        q.segment<3>(3 * i) = positions.row(mesh.T(t, i)).transpose();
    return q;
}

}  // namespace

Matrix12d rotated_stiffness(const Matrix12d& K_e, const Eigen::Matrix3d& R)
{
    Matrix12d rotated;
    // BEGIN EXERCISE 11.4 rotated_stiffness #forces-and-warped-stiffness
    // HINT: block (a, b) of the result is R K_ab Rᵀ, K_ab the 3×3 block K_e(3a…3a+2, 3b…3b+2);
    // HINT: K_e is symmetric, so block (b, a) is the transpose of block (a, b).
    for (int a = 0; a < 4; ++a)
        for (int b = a; b < 4; ++b) {
            const Eigen::Matrix3d block = R * K_e.block<3, 3>(3 * a, 3 * b) * R.transpose();
            rotated.block<3, 3>(3 * a, 3 * b) = block;
            if (b != a)
                rotated.block<3, 3>(3 * b, 3 * a) = block.transpose();
        }
    // END EXERCISE
    return rotated;
}

Vector12d corotated_displacement(const Eigen::Matrix3d& R, const Vector12d& x_e, const Vector12d& X_e)
{
    Vector12d d;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int i = 0; i < 4; ++i) {
        d.segment<3>(3 * i) = R.transpose() * x_e.segment<3>(3 * i) - X_e.segment<3>(3 * i);
        mean += 0.25 * d.segment<3>(3 * i);
    }
    for (int i = 0; i < 4; ++i)
        d.segment<3>(3 * i) -= mean;  // a translation: K_e ignores it, round-off would not
    return d;
}

Vector12d corotated_force(const Matrix12d& K_e, const Eigen::Matrix3d& R, const Vector12d& x_e, const Vector12d& X_e)
{
    Vector12d force;
    // BEGIN EXERCISE 11.5 corotated_force #forces-and-warped-stiffness
    // HINT: d = corotated_displacement(R, x_e, X_e); apply K_e; rotate each 3-block of K_e d back
    // HINT: with R and negate: f_e = −R̂ K_e (R̂ᵀ x_e − X_e).
    const Vector12d local_force = K_e * corotated_displacement(R, x_e, X_e);
    for (int i = 0; i < 4; ++i)
        force.segment<3>(3 * i) = -(R * local_force.segment<3>(3 * i));
    // END EXERCISE
    return force;
}

GradientFormElement gradient_form_forces(const Eigen::Matrix3d& F, const Eigen::Matrix3d& R,
                                         const Eigen::Matrix3d& rest_edges_inverse, double volume,
                                         const elastic::Lame& lame)
{
    const Eigen::Matrix3d rotated = R.transpose() * F;
    const Eigen::Matrix3d strain = 0.5 * (rotated + rotated.transpose()) - Eigen::Matrix3d::Identity();
    const double trace = strain.trace();
    Eigen::Matrix3d stress = 2.0 * lame.mu * strain;
    stress.diagonal().array() += lame.lambda * trace;
    GradientFormElement element;
    element.energy = volume * (lame.mu * strain.squaredNorm() + 0.5 * lame.lambda * trace * trace);
    // f_a = −V R σ g_a for a = 1, 2, 3 (g_a: row a − 1 of T_X⁻¹), and f₀ = −(f₁ + f₂ + f₃)
    element.forces.rightCols<3>().noalias() = (-volume * (R * stress)) * rest_edges_inverse.transpose();
    element.forces.col(0) = -element.forces.rightCols<3>().rowwise().sum();
    return element;
}

// --- CorotationalElasticity ------------------------------------------------------------------------

CorotationalElasticity::CorotationalElasticity(const TetMesh& mesh, const dynamics::Material& material, RotationFit fit,
                                               PolarAlgorithm algorithm, ForceForm form)
    : mesh_(mesh), lame_(elastic::lame_parameters(material.youngs_modulus, material.poisson_ratio)), fit_(fit),
      algorithm_(algorithm), form_(form), K_e_(assembly::element_stiffnesses(mesh, lame_)), pattern_(mesh),
      K_R_(assembly::csc_of_symmetric(pattern_.zero_matrix())), volumes_(mesh.T.rows()),
      rest_edges_inverse_(static_cast<std::size_t>(mesh.T.rows()))
{
    for (Eigen::Index t = 0; t < mesh.T.rows(); ++t) {
        volumes_[t] = std::abs(tet_signed_volume6(mesh, static_cast<int>(t))) / 6.0;
        rest_edges_inverse_[static_cast<std::size_t>(t)] =
            tet::edge_matrix(tet::tet_vertices(mesh, mesh.V, static_cast<int>(t))).inverse();
    }
}

std::vector<Eigen::Matrix3d> CorotationalElasticity::rotations(const Eigen::VectorXd& u) const
{
    return rotations(u, nullptr);
}

std::vector<Eigen::Matrix3d> CorotationalElasticity::rotations(const Eigen::VectorXd& u,
                                                               std::vector<Eigen::Matrix3d>* gradients) const
{
    if (u.size() != 3 * mesh_.V.rows())
        throw Error(str("displacement has ", u.size(), " entries, expected 3n = ", 3 * mesh_.V.rows()));
    for (Eigen::Index i = 0; i < u.size(); ++i)
        if (!std::isfinite(u[i]))
            throw Error(str("displacement entry ", i, " (vertex ", i / 3, ") is ", u[i], "; every entry must be finite"));
    const MatrixX3d x = mesh_.V + io::vertex_rows(u);
    std::vector<Eigen::Matrix3d> R(static_cast<std::size_t>(mesh_.T.rows()));
    if (gradients)
        gradients->resize(R.size());
    // F = T_x T_X⁻¹ (chapter 04's deformation_gradient, with the rest inverse kept)
    const auto deformation_gradient = [&](Eigen::Index t) {
        return Eigen::Matrix3d(tet::edge_matrix(tet::tet_vertices(mesh_, x, static_cast<int>(t))) *
                               rest_edges_inverse_[static_cast<std::size_t>(t)]);
    };
    if (fit_ == RotationFit::polar && algorithm_ == PolarAlgorithm::newton) {
        // Four tets at a time (polar_rotations_newton), each group of four on one core.
        const Eigen::Index tets = mesh_.T.rows();
        parallel_for((tets + 3) / 4, [&](Eigen::Index group) {
            const Eigen::Index first = 4 * group, count = std::min<Eigen::Index>(4, tets - first);
            Eigen::Matrix3d F[4];
            for (Eigen::Index k = 0; k < count; ++k) {
                F[k] = deformation_gradient(first + k);
                if (gradients)
                    (*gradients)[static_cast<std::size_t>(first + k)] = F[k];
            }
            polar_rotations_newton(F, &R[static_cast<std::size_t>(first)], static_cast<std::size_t>(count));
        });
        return R;
    }
    parallel_for(mesh_.T.rows(), [&](Eigen::Index t) {  // each tet's own rotation: on every core
        const auto e = static_cast<std::size_t>(t);
        const Eigen::Matrix3d F = deformation_gradient(t);
        if (gradients)
            (*gradients)[e] = F;
        switch (fit_) {
        case RotationFit::polar: R[e] = polar_rotation(F); break;
        case RotationFit::centroid:
            R[e] = best_fit_rotation(centroid_covariance(tet::tet_vertices(mesh_, mesh_.V, static_cast<int>(t)),
                                                         tet::tet_vertices(mesh_, x, static_cast<int>(t))));
            break;
        case RotationFit::edges:
            R[e] = best_fit_rotation(edge_covariance(tet::tet_vertices(mesh_, mesh_.V, static_cast<int>(t)),
                                                     tet::tet_vertices(mesh_, x, static_cast<int>(t))));
            break;
        }
    });
    return R;
}

std::vector<Eigen::Matrix3d> CorotationalElasticity::vertex_rotations() const
{
    if (rotations_.empty())
        throw Error("vertex_rotations: the model has not been evaluated yet (call evaluate or stiffness first)");
    std::vector<Eigen::Matrix3d> sums(static_cast<std::size_t>(mesh_.V.rows()), Eigen::Matrix3d::Zero());
    Eigen::VectorXd weights = Eigen::VectorXd::Zero(mesh_.V.rows());
    for (Eigen::Index t = 0; t < mesh_.T.rows(); ++t)
        for (int i = 0; i < 4; ++i) {
            sums[static_cast<std::size_t>(mesh_.T(t, i))] += volumes_[t] * rotations_[static_cast<std::size_t>(t)];
            weights[mesh_.T(t, i)] += volumes_[t];
        }
    // The weighted mean of rotations, det near 1 (Newton's iteration then needs no scaling), four
    // vertices at a time; a vertex of no tet keeps the identity.
    for (std::size_t v = 0; v < sums.size(); ++v)
        sums[v] = weights[static_cast<Eigen::Index>(v)] > 0.0 ? Eigen::Matrix3d(sums[v] / weights[static_cast<Eigen::Index>(v)])
                                                              : Eigen::Matrix3d::Identity();
    std::vector<Eigen::Matrix3d> rotations(sums.size());
    polar_rotations_newton(sums.data(), rotations.data(), sums.size());
    return rotations;
}

const std::vector<Eigen::Matrix3d>& CorotationalElasticity::rotations_at(const Eigen::VectorXd& u)
{
    if (rotations_.empty() || rotated_at_.size() != u.size() || rotated_at_ != u) {
        rotations_ = rotations(u, form_ == ForceForm::shape_gradients ? &gradients_ : nullptr);
        rotated_at_ = u;
    }
    return rotations_;
}

double CorotationalElasticity::evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& forces)
{
    const std::vector<Eigen::Matrix3d>& R = rotations_at(u);
    const MatrixX3d x = mesh_.V + io::vertex_rows(u);
    // Every tet's force and energy on every core, each into its own slot; then the sums, one tet
    // after another in order (common/parallel.hpp: the same bits on any number of threads).
    Eigen::VectorXd sum = Eigen::VectorXd::Zero(u.size());
    double energy = 0.0;
    parallel_for_then_add(
        mesh_.T.rows(), element_forces_,
        [&](Eigen::Index t, ElementForces& slot) {
            const auto e = static_cast<std::size_t>(t);
            if (form_ == ForceForm::shape_gradients) {
                const GradientFormElement element =
                    gradient_form_forces(gradients_[e], R[e], rest_edges_inverse_[e], volumes_[t], lame_);
                slot.energy = element.energy;
                slot.forces = element.forces.reshaped();
                return;
            }
            const Vector12d x_e = element_vector(mesh_, x, t), X_e = element_vector(mesh_, mesh_.V, t);
            slot.forces = corotated_force(K_e_[e], R[e], x_e, X_e);
            // U_e = ½ dᵀ K_e d = −½ Σᵢ (R dᵢ)·f_e,i, since f_e,i = −R (K_e d)ᵢ: no second product with K_e
            const Vector12d d = corotated_displacement(R[e], x_e, X_e);
            slot.energy = 0.0;
            for (int i = 0; i < 4; ++i)
                slot.energy -= 0.5 * (R[e] * d.segment<3>(3 * i)).dot(slot.forces.segment<3>(3 * i));
        },
        [&](Eigen::Index t, const ElementForces& slot) {
            energy += slot.energy;
            for (int i = 0; i < 4; ++i)
                sum.segment<3>(3 * mesh_.T(t, i)) += slot.forces.segment<3>(3 * i);
        });
    forces.swap(sum);
    return energy;
}

const dynamics::SparseMatrix& CorotationalElasticity::stiffness(const Eigen::VectorXd& u)
{
    const std::vector<Eigen::Matrix3d>& R = rotations_at(u);
    // K_R_ is a CSC copy of the pattern's CSR arrays (csc_of_symmetric): for a symmetric matrix
    // the two layouts coincide, so the pattern's offsets address K_R_'s values directly.
    double* values = K_R_.valuePtr();
    std::fill(values, values + K_R_.nonZeros(), 0.0);
    // Each tet's 12×12 block into its own slot on every core, then the slots added into the fixed
    // pattern one tet after another (common/parallel.hpp: the same sums on any number of threads).
    parallel_for_then_add(
        mesh_.T.rows(), element_matrices_,
        [&](Eigen::Index t, Matrix12d& slot) {
            const auto e = static_cast<std::size_t>(t);
            // BEGIN EXERCISE 11.6 warped_stiffness #forces-and-warped-stiffness
            // HINT: tet e's block of K_R = Σ_e R̂_e K_e R̂_eᵀ: its rest stiffness K_e_[e] turned by its
            // HINT: rotation R[e] (exercise 11.4).
            slot = rotated_stiffness(K_e_[e], R[e]);
            // END EXERCISE
        },
        [&](Eigen::Index t, const Matrix12d& slot) { pattern_.add_element(t, slot, values); });
    return K_R_;
}

Eigen::VectorXd CorotationalElasticity::von_mises_stress(const Eigen::VectorXd& u) const
{
    const std::vector<Eigen::Matrix3d> R = rotations(u);
    const MatrixX3d x = mesh_.V + io::vertex_rows(u);
    const elastic::Matrix6d C = elastic::elasticity_matrix(lame_);
    Eigen::VectorXd stress(mesh_.T.rows());
    for (Eigen::Index t = 0; t < mesh_.T.rows(); ++t) {
        const Vector12d x_e = element_vector(mesh_, x, t), X_e = element_vector(mesh_, mesh_.V, t);
        const Vector12d d = corotated_displacement(R[static_cast<std::size_t>(t)], x_e, X_e);
        const tet::TetVertices rest = tet::tet_vertices(mesh_, mesh_.V, static_cast<int>(t));
        stress[t] = elastic::von_mises(C * (elastic::strain_displacement_matrix(rest) * d));
    }
    return stress;
}

std::vector<Eigen::Matrix3d> free_vertex_rotations(const CorotationalElasticity& model, const dynamics::FreeDofs& dofs)
{
    const std::vector<Eigen::Matrix3d> all = model.vertex_rotations();
    if (dofs.full_size() != 3 * static_cast<Eigen::Index>(all.size()))
        throw Error(str("free_vertex_rotations: ", dofs.full_size(), " dofs for a model of ", all.size(), " vertices"));
    const std::vector<int>& free = dofs.indices();
    std::vector<Eigen::Matrix3d> rotations;
    rotations.reserve(free.size() / 3);
    for (std::size_t i = 0; i < free.size(); i += 3) {
        const int vertex = free[i] / 3;
        if (free[i] % 3 != 0 || i + 2 >= free.size() || free[i + 1] != free[i] + 1 || free[i + 2] != free[i] + 2)
            throw Error(str("free_vertex_rotations: vertex ", vertex, " is only partly pinned; pin all three dofs"));
        rotations.push_back(all[static_cast<std::size_t>(vertex)]);
    }
    return rotations;
}

}  // namespace fem::corot
