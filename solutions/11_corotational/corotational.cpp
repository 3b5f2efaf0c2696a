#include "11_corotational/corotational.hpp"

#include "common/error.hpp"
#include "common/parallel.hpp"
#include "common/simd.hpp"
#include "common/vtk_io.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#include <immintrin.h>
#endif

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

// --- Newton's polar iteration, one matrix or four at a time -------------------------------------
//
// The arithmetic of a step is written once, for lanes T: a double, or four doubles in an AVX2
// register (GCC's vector extension). Entry by entry, in the same order, so four matrices at a time
// give the bits of one at a time. X is held as its 9 entries, column-major (X(i, j) = x[3 j + i]).

// (Results come back through references: a function returning an AVX2 register by value would
// have another calling convention when compiled for baseline x86-64.)

/// The cofactors of X (column c: the cross product of columns c + 1 and c + 2, so that
/// cofactors / det X = X⁻ᵀ) into cof, and det X = column 0 · cof column 0.
template <class T>
[[gnu::always_inline]] inline void cofactors_and_determinant(const T (&x)[9], T (&cof)[9], T& det)
{
    for (int c = 0; c < 3; ++c) {
        const T* a = x + 3 * ((c + 1) % 3);
        const T* b = x + 3 * ((c + 2) % 3);
        cof[3 * c + 0] = a[1] * b[2] - a[2] * b[1];
        cof[3 * c + 1] = a[2] * b[0] - a[0] * b[2];
        cof[3 * c + 2] = a[0] * b[1] - a[1] * b[0];
    }
    det = x[0] * cof[0] + x[1] * cof[1] + x[2] * cof[2];
}

/// sum = ‖X‖² (the entries' squares summed in order).
template <class T>
[[gnu::always_inline]] inline void squared_norm(const T (&x)[9], T& sum)
{
    sum = x[0] * x[0];
    for (int e = 1; e < 9; ++e)
        sum += x[e] * x[e];
}

/// One Newton step: x ← ½(ζ X + s cof) with s = 1/(ζ det X) (one division for all nine entries),
/// and change_squared = ‖X_{k+1} − X_k‖² (no square root: it is compared with squared thresholds).
template <class T>
[[gnu::always_inline]] inline void newton_polar_step(T (&x)[9], const T (&cof)[9], const T& zeta, const T& scale,
                                                     T& change_squared)
{
    T next = 0.5 * (zeta * x[0] + scale * cof[0]);
    change_squared = (next - x[0]) * (next - x[0]);
    x[0] = next;
    for (int e = 1; e < 9; ++e) {
        next = 0.5 * (zeta * x[e] + scale * cof[e]);
        change_squared += (next - x[e]) * (next - x[e]);
        x[e] = next;
    }
}

// The thresholds of polar_rotation_newton (see its comment in the header).
constexpr double flat_fraction = 1e-6;      // det F ≤ this · ‖F‖³: the SVD instead
constexpr double scaling_window = 1e-2;     // ζ = |det X|^(−1/3) while |det X − 1| exceeds this ...
constexpr double scaled_change = 1e-4;      // ... and no step has changed X by less than 1e-2 (squared)
constexpr double converged_change = 1e-16;  // a step's change below 1e-8 (squared): converged
constexpr int newton_step_cap = 40;

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define FEM_AVX2_POLAR 1
using Lanes = double __attribute__((vector_size(32)));     // four doubles in an AVX2 register
using LaneMask = long long __attribute__((vector_size(32)));  // what comparing two Lanes gives

__attribute__((target("avx2,fma"))) bool any_lane(LaneMask mask)
{
    return (mask[0] | mask[1] | mask[2] | mask[3]) != 0;
}

/// polar_rotation_newton of four finite F at once (lane l: F[l]), each step of each lane the same
/// operations as polar_rotation_newton's: the same R, bit for bit. Returns false, leaving the four to
/// the caller, when a lane needs what the lanes do not do: the SVD (det F ≤ 10⁻⁶ ‖F‖³, or 40 steps)
/// or a scaled step (a cube root).
__attribute__((target("avx2,fma"))) bool polar_rotations_newton_avx2(const Eigen::Matrix3d* F, Eigen::Matrix3d* R)
{
    Lanes x[9], cof[9];
    for (int e = 0; e < 9; ++e)
        x[e] = Lanes{F[0].data()[e], F[1].data()[e], F[2].data()[e], F[3].data()[e]};
    Lanes det, size_squared, change_squared;
    cofactors_and_determinant(x, cof, det);
    squared_norm(x, size_squared);
    if (any_lane(!(det > flat_fraction * size_squared * Lanes(_mm256_sqrt_pd(__m256d(size_squared))))))
        return false;
    const Lanes one = {1.0, 1.0, 1.0, 1.0};
    LaneMask scaled = {-1, -1, -1, -1}, done = {0, 0, 0, 0};
    for (int step = 0; step < newton_step_cap; ++step) {
        if (step > 0)
            cofactors_and_determinant(x, cof, det);
        if (any_lane(scaled & ~done & ((det - 1.0 > scaling_window) | (det - 1.0 < -scaling_window))))
            return false;
        const Lanes scale = 1.0 / (one * det);
        newton_polar_step(x, cof, one, scale, change_squared);
        scaled &= !(change_squared < scaled_change);
        const LaneMask converged = (change_squared < converged_change) & ~done;
        for (int l = 0; l < 4; ++l)
            if (converged[l])
                for (int e = 0; e < 9; ++e)
                    R[l].data()[e] = x[e][l];
        done |= converged;
        if (!any_lane(~done))
            return true;
    }
    return false;
}
#endif

}  // namespace

Eigen::Matrix3d proper_rotation(Eigen::Matrix3d A, const Eigen::Matrix3d& B)
{
    // BEGIN EXERCISE 11.1 proper_rotation #reflections
    // HINT: If det(A Bᵀ) < 0, negate A's last column (the smallest singular value's); return A Bᵀ.
    if ((A * B.transpose()).determinant() < 0.0)
        A.col(2) = -A.col(2);
    return A * B.transpose();
    // END EXERCISE
}

Eigen::Matrix3d edge_covariance(const tet::TetVertices& X, const tet::TetVertices& x)
{
    Eigen::Matrix3d P, Q;
    for (int i = 0; i < 3; ++i) {
        P.row(i) = X.row(i + 1) - X.row(0);
        Q.row(i) = x.row(i + 1) - x.row(0);
    }
    return P.transpose() * Q;
}

Eigen::Matrix3d centroid_covariance(const tet::TetVertices& X, const tet::TetVertices& x)
{
    const Eigen::RowVector3d X_mean = X.colwise().mean(), x_mean = x.colwise().mean();
    return (X.rowwise() - X_mean).transpose() * (x.rowwise() - x_mean);
}

Eigen::Matrix3d best_fit_rotation(const Eigen::Matrix3d& S)
{
    if (!S.allFinite())
        throw Error("best-fit rotation: the edge covariance S has a non-finite entry");
    if (S.isZero(0.0))
        return Eigen::Matrix3d::Identity();
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(S, Eigen::ComputeFullU | Eigen::ComputeFullV);
    // BEGIN EXERCISE 11.2 best_fit_rotation #the-best-fit-rotation
    // HINT: S = U Σ Vᵀ. The rotation from rest to deformed is R = V Uᵀ (not the slide's U Vᵀ):
    // HINT: proper_rotation of V and U, which also fixes a reflection.
    return proper_rotation(svd.matrixV(), svd.matrixU());
    // END EXERCISE
}

Eigen::Matrix3d polar_rotation(const Eigen::Matrix3d& F)
{
    if (!F.allFinite())
        throw Error("polar rotation: F has a non-finite entry");
    if (F.isZero(0.0))
        return Eigen::Matrix3d::Identity();
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
    // BEGIN EXERCISE 11.3 polar_rotation #edges-centroid-or-polar-decomposition
    // HINT: F = U Σ Vᵀ = (U Vᵀ)(V Σ Vᵀ): the rotation is U Vᵀ, made proper by proper_rotation.
    return proper_rotation(svd.matrixU(), svd.matrixV());
    // END EXERCISE
}

Eigen::Matrix3d polar_rotation_newton(const Eigen::Matrix3d& F)
{
    if (!F.allFinite())
        throw Error("polar rotation: F has a non-finite entry");
    double x[9], cof[9], det = 0.0, size_squared = 0.0, change_squared = 0.0;
    std::copy(F.data(), F.data() + 9, x);
    cofactors_and_determinant(x, cof, det);
    squared_norm(x, size_squared);
    if (!(det > flat_fraction * size_squared * std::sqrt(size_squared)))
        return polar_rotation(F);  // inverted, flat or zero: the SVD and its reflection fix
    bool scaled = true;
    for (int step = 0; step < newton_step_cap; ++step) {
        if (step > 0)
            cofactors_and_determinant(x, cof, det);
        // Scaling pays where the singular values are far from 1; near det = 1 it would only cost a
        // cube root. One division a step: X⁻ᵀ/ζ = cofactors · (1/(ζ det)).
        const double zeta =
            scaled && std::abs(det - 1.0) > scaling_window ? std::cbrt(1.0 / std::abs(det)) : 1.0;
        newton_polar_step(x, cof, zeta, 1.0 / (zeta * det), change_squared);
        if (change_squared < scaled_change)
            scaled = false;  // a change below 1e-2, near orthogonal: plain Newton converges quadratically
        if (change_squared < converged_change)
            return Eigen::Map<const Eigen::Matrix3d>(x);  // X's error is about change² / 2: round-off
    }
    return polar_rotation(F);
}

void polar_rotations_newton(const Eigen::Matrix3d* F, Eigen::Matrix3d* R, std::size_t count)
{
    for (std::size_t k = 0; k < count; ++k)
        if (!F[k].allFinite())
            throw Error(str("polar rotations: F[", k, "] of ", count, " has a non-finite entry (every entry must be finite)"));
    std::size_t first = 0;
#ifdef FEM_AVX2_POLAR
    if (avx2_enabled())
        for (; first + 4 <= count; first += 4) {
            if (polar_rotations_newton_avx2(F + first, R + first))
                continue;
            for (std::size_t k = first; k < first + 4; ++k)
                R[k] = polar_rotation_newton(F[k]);
        }
#endif
    for (; first < count; ++first)
        R[first] = polar_rotation_newton(F[first]);
}

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
    // BEGIN EXERCISE 11.6 warped_stiffness #forces-and-warped-stiffness
    // HINT: parallel_for_then_add of common/parallel.hpp over the tets, with the slots
    // HINT: element_matrices_: compute each tet's slot = rotated_stiffness(K_e_[t], R[t]) (on every
    // HINT: core), then add it with pattern_.add_element(t, slot, values) (chapter 06's route c into
    // HINT: the fixed pattern; in tet order, so the sums do not depend on the threads).
    parallel_for_then_add(
        mesh_.T.rows(), element_matrices_,
        [&](Eigen::Index t, Matrix12d& slot) {
            const auto e = static_cast<std::size_t>(t);
            slot = rotated_stiffness(K_e_[e], R[e]);
        },
        [&](Eigen::Index t, const Matrix12d& slot) { pattern_.add_element(t, slot, values); });
    // END EXERCISE
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
