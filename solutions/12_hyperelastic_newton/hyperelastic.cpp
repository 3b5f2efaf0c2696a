#include "12_hyperelastic_newton/hyperelastic.hpp"

#include "common/error.hpp"
#include "common/parallel.hpp"
#include "common/vtk_io.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>

namespace fem::hyper {

double element_energy(const Material& material, double volume, const Eigen::Matrix3d& H)
{
    return volume * material.energy_density(H);
}

Vector12d element_forces(const Material& material, double volume, const tet::Jacobian& B, const Eigen::Matrix3d& H)
{
    Vector12d forces;
    // BEGIN EXERCISE 12.4 element_forces #element-forces-and-hessians
    // HINT: The tet's elastic forces, the negative gradient of its energy V ψ with vec(F) = B q_e, in `forces`
    // HINT: (docs/12_hyperelastic_newton.md#element-forces-and-hessians); the stress is material.first_piola(H).
    // HINT: vec is row-major, as B was built: flatten(P) gives it; P.reshaped() is column-major, i.e. vec(Pᵀ), and
    // HINT: only a non-symmetric P shows the difference.
    forces = -volume * (B.transpose() * flatten(material.first_piola(H)));
    // END EXERCISE
    return forces;
}

Matrix12d element_hessian(const Material& material, double volume, const tet::Jacobian& B, const Eigen::Matrix3d& H,
                          std::optional<Projection> projection)
{
    Matrix12d hessian;
    // BEGIN EXERCISE 12.5 element_hessian #element-forces-and-hessians
    // HINT: The tet's Hessian, the second derivative of V ψ with vec(F) = B q_e, in `hessian`
    // HINT: (docs/12_hyperelastic_newton.md#element-forces-and-hessians). When `projection` is set the caller needs
    // HINT: it positive semi-definite (#definiteness): take ∂P/∂F from material.projected_piola_derivative(H,
    // HINT: *projection) instead of material.piola_derivative(H) (a material may project analytically,
    // HINT: #the-analytic-eigensystem), and project nothing yourself.
    const Matrix9d dP = projection ? material.projected_piola_derivative(H, *projection) : material.piola_derivative(H);
    // Bᵀ dP B using only B's 36 nonzeros of 108, B(3a + b, 3i + a) = ∇φᵢ(b) = g(i, b): first
    // W = dP B (column 3j + c is Σ_d g(j, d) dP(:, 3c + d)), then row 3i + a of Bᵀ W is
    // Σ_b g(i, b) W(3a + b, :). A third of the dense product's work, and no general GEMM.
    Eigen::Matrix<double, 4, 3> g;
    for (int i = 0; i < 4; ++i)
        g.row(i) = B.block<3, 1>(0, 3 * i).transpose();
    Eigen::Matrix<double, 9, 12> W;
    for (int j = 0; j < 4; ++j)
        for (int c = 0; c < 3; ++c)
            W.col(3 * j + c) = g(j, 0) * dP.col(3 * c) + g(j, 1) * dP.col(3 * c + 1) + g(j, 2) * dP.col(3 * c + 2);
    for (int i = 0; i < 4; ++i)
        for (int a = 0; a < 3; ++a)
            hessian.row(3 * i + a) = volume * (g(i, 0) * W.row(3 * a) + g(i, 1) * W.row(3 * a + 1) + g(i, 2) * W.row(3 * a + 2));
    // END EXERCISE
    return hessian;
}

HyperelasticElasticity::HyperelasticElasticity(const TetMesh& mesh, std::unique_ptr<Material> material,
                                               Projection projection)
    : mesh_(mesh), material_(std::move(material)), projection_(projection), volumes_(mesh.T.rows()), pattern_(mesh),
      K_(assembly::csc_of_symmetric(pattern_.zero_matrix()))
{
    if (!material_)
        throw Error("HyperelasticElasticity: no material");
    B_.reserve(static_cast<std::size_t>(mesh.T.rows()));
    gradients_.reserve(static_cast<std::size_t>(mesh.T.rows()));
    for (Eigen::Index t = 0; t < mesh.T.rows(); ++t) {
        const tet::TetVertices X = tet::tet_vertices(mesh, mesh.V, static_cast<int>(t));
        B_.push_back(tet::jacobian_matrix(X));  // fem::Error for a zero-volume tet
        gradients_.push_back(tet::shape_gradients(X));
        volumes_[t] = std::abs(tet::signed_volume(X));
    }
}

MatrixX3d HyperelasticElasticity::displacement_rows(const Eigen::VectorXd& u) const
{
    if (u.size() != 3 * mesh_.V.rows())
        throw Error(str("displacement has ", u.size(), " entries, expected 3n = ", 3 * mesh_.V.rows()));
    return io::vertex_rows(u);
}

Eigen::Matrix3d HyperelasticElasticity::displacement_gradient(const MatrixX3d& displacement, Eigen::Index t) const
{
    Eigen::Matrix<double, 4, 3> corners;
    for (int i = 0; i < 4; ++i)
        corners.row(i) = displacement.row(mesh_.T(t, i));
    return corners.transpose() * gradients_[static_cast<std::size_t>(t)];  // H = Σᵢ uᵢ ∇φᵢᵀ
}

double HyperelasticElasticity::energy(const Eigen::VectorXd& u)
{
    const MatrixX3d x = displacement_rows(u);
    // Every tet's energy on every core, then the sum in tet order (common/parallel.hpp).
    element_energies_.resize(static_cast<std::size_t>(mesh_.T.rows()));
    parallel_for(mesh_.T.rows(), [&](Eigen::Index t) {
        element_energies_[static_cast<std::size_t>(t)] = element_energy(*material_, volumes_[t], displacement_gradient(x, t));
    });
    double total = 0.0;
    for (const double e : element_energies_) {
        total += e;
        if (!std::isfinite(total))
            return std::numeric_limits<double>::infinity();
    }
    return total;
}

double HyperelasticElasticity::evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& forces)
{
    const MatrixX3d x = displacement_rows(u);
    // Every tet's energy and forces on every core, each into its own slot, then the sums in tet
    // order (common/parallel.hpp: the same bits on any number of threads, and the same tet named
    // when one is inverted: the lowest-numbered).
    Eigen::VectorXd sum = Eigen::VectorXd::Zero(u.size());
    double total = 0.0;
    parallel_for_then_add(
        mesh_.T.rows(), element_forces_,
        [&](Eigen::Index t, ElementForces& slot) {
            const Eigen::Matrix3d H = displacement_gradient(x, t);
            slot.energy = element_energy(*material_, volumes_[t], H);
            if (!std::isfinite(slot.energy))
                throw Error(str(material_->name(), ": tet ", t, " has det F = ", 1.0 + volume_change(H),
                                ", where the material is undefined (inverted)"));
            slot.forces = element_forces(*material_, volumes_[t], B_[static_cast<std::size_t>(t)], H);
        },
        [&](Eigen::Index t, const ElementForces& slot) {
            total += slot.energy;
            for (int i = 0; i < 4; ++i)
                sum.segment<3>(3 * mesh_.T(t, i)) += slot.forces.segment<3>(3 * i);
        });
    forces.swap(sum);  // only now: a failed evaluation leaves forces as it was
    return total;
}

const dynamics::SparseMatrix& HyperelasticElasticity::stiffness(const Eigen::VectorXd& u)
{
    return assemble_hessian(u, std::nullopt);
}

const dynamics::SparseMatrix& HyperelasticElasticity::definite_stiffness(const Eigen::VectorXd& u)
{
    return assemble_hessian(u, projection_);
}

const dynamics::SparseMatrix& HyperelasticElasticity::assemble_hessian(const Eigen::VectorXd& u,
                                                                       std::optional<Projection> projection)
{
    const MatrixX3d x = displacement_rows(u);
    // K_ is a CSC copy of the pattern's CSR arrays (csc_of_symmetric): for a symmetric matrix the
    // two layouts coincide, so the pattern's offsets address K_'s values directly.
    double* values = K_.valuePtr();
    std::fill(values, values + K_.nonZeros(), 0.0);
    // Every tet's Hessian on every core, then added into the pattern in tet order.
    parallel_for_then_add(
        mesh_.T.rows(), element_matrices_,
        [&](Eigen::Index t, Matrix12d& slot) {
            slot = element_hessian(*material_, volumes_[t], B_[static_cast<std::size_t>(t)], displacement_gradient(x, t),
                                   projection);
        },
        [&](Eigen::Index t, const Matrix12d& slot) { pattern_.add_element(t, slot, values); });
    return K_;
}

Eigen::VectorXd HyperelasticElasticity::von_mises_stress(const Eigen::VectorXd& u) const
{
    const MatrixX3d x = displacement_rows(u);
    Eigen::VectorXd stress(mesh_.T.rows());
    for (Eigen::Index t = 0; t < mesh_.T.rows(); ++t) {
        const Eigen::Matrix3d H = displacement_gradient(x, t);
        const double J = 1.0 + volume_change(H);
        if (!(J > 0.0) && !material_->defined_when_inverted()) {
            stress[t] = 0.0;
            continue;
        }
        const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + H;
        const Eigen::Matrix3d sigma = material_->first_piola(H) * F.transpose() / (J > 0.0 ? J : 1.0);
        const Eigen::Matrix3d deviator = sigma - sigma.trace() / 3.0 * Eigen::Matrix3d::Identity();
        stress[t] = std::sqrt(1.5 * deviator.squaredNorm());  // √(3/2 s:s), as chapter 05's von_mises
    }
    return stress;
}

double HyperelasticElasticity::smallest_volume_ratio(const Eigen::VectorXd& u) const
{
    const MatrixX3d x = displacement_rows(u);
    double smallest = std::numeric_limits<double>::infinity();
    for (Eigen::Index t = 0; t < mesh_.T.rows(); ++t)
        smallest = std::min(smallest, 1.0 + volume_change(displacement_gradient(x, t)));
    return smallest;
}

}  // namespace fem::hyper
