#pragma once
// Chapter 11: corotational linear elasticity. docs/11_corotational.md
//
// Linear elasticity measures strain with ε = ½(∇u + ∇uᵀ), which is not zero when a body merely
// rotates: a rotated beam grows and shears (chapter 05's rotation table). The corotational element
// removes the rotation first. For each tet, find the rotation R_e that best maps its rest edges to
// its deformed edges, measure the displacement in the element's rotated frame, apply the linear
// element there and rotate the forces back:
//     f_e = −R_e K_e (R_eᵀ x_e − X_e),          (x_e, X_e: the 12 deformed and rest coordinates)
//     U_e = ½ (R_eᵀ x_e − X_e)ᵀ K_e (R_eᵀ x_e − X_e),
//     K_R = Σ_e E_eᵀ R̂_e K_e R̂_eᵀ E_e,           R̂_e = diag(R_e, R_e, R_e, R_e) (12×12),
// K_R being the "warped stiffness" (the derivative of R_e is left out, as in the lecture). Rotating
// a whole body by Q rotates every R_e by Q, so the forces rotate with it and the energy does not
// change: no ghost growth.
//
// The best-fit rotation (the lecture's "Finding Best-Fit Rotation"): with the rest edges
// P = [X₁ − X₀; X₂ − X₀; X₃ − X₀] and the deformed edges Q (one edge a row, 3×3), S = Pᵀ Q = U Σ Vᵀ
// and the rotation that takes rest to deformed is R = V Uᵀ. The slide writes U Vᵀ, which is its
// inverse (its transpose); with it the forces would be rotated the wrong way. If det(V Uᵀ) < 0 (a
// reflection: the tet is inverted or flat), the sign of V's column of the smallest singular value
// is flipped, giving the closest proper rotation.

#include "10_linear_dynamics/body.hpp"

#include "04_tet_jacobians/tet_jacobians.hpp"
#include "05_strain_stress/strain_stress.hpp"
#include "06_assembly/assembly.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <string>
#include <vector>

namespace fem::corot {

using Matrix12d = elastic::Matrix12d;
using Vector12d = Eigen::Matrix<double, 12, 1>;

/// S = Pᵀ Q (3×3) with P and Q the rest and deformed edge matrices of one tet: row i is
/// X_{i+1} − X₀ and x_{i+1} − x₀ (i = 0, 1, 2), the lecture's. It depends on which corner is X₀.
/// docs/11_corotational.md#the-best-fit-rotation
Eigen::Matrix3d edge_covariance(const tet::TetVertices& X, const tet::TetVertices& x);

/// S = Σᵢ (Xᵢ − X̄)(xᵢ − x̄)ᵀ over the four corners about their centroids (3×3): the same
/// least-squares fit with every corner weighted alike, independent of the corner order.
/// docs/11_corotational.md#edges-centroid-or-polar-decomposition
Eigen::Matrix3d centroid_covariance(const tet::TetVertices& X, const tet::TetVertices& x);

/// The proper rotation closest to A Bᵀ, for A and B orthogonal (3×3) with their columns in the
/// order of descending singular values (as an SVD gives them): A Bᵀ when det(A Bᵀ) = +1, else
/// A diag(1, 1, −1) Bᵀ — the reflection moved onto the smallest singular value, where it changes
/// the fit least. docs/11_corotational.md#reflections
Eigen::Matrix3d proper_rotation(Eigen::Matrix3d A, const Eigen::Matrix3d& B);

/// The proper rotation R (RᵀR = I, det R = +1) that best maps rest edges to deformed edges:
/// S = U Σ Vᵀ (Eigen's JacobiSVD), R = proper_rotation(V, U): V Uᵀ, and when det(V Uᵀ) < 0 the
/// column of V belonging to the smallest singular value changes sign. S = 0 (every edge collapsed) gives R = I. Never NaN for
/// finite S; fem::Error for a non-finite S. docs/11_corotational.md#the-best-fit-rotation
Eigen::Matrix3d best_fit_rotation(const Eigen::Matrix3d& S);

/// The rotation of the polar decomposition F = R_p S_p (S_p symmetric positive semi-definite), from
/// the SVD F = U Σ Vᵀ: R_p = proper_rotation(U, V) = U Vᵀ, with the same reflection fix; the rotation closest to F
/// (it minimises ‖F − R‖). For a tet, F = Qᵀ P⁻ᵀ; R_p equals the edge fit when PᵀP ∝ I (the corner
/// tet) and the centroid fit when the corners' covariance is ∝ I (a regular tet), and differs from
/// both for skewed tets. docs/11_corotational.md#edges-centroid-or-polar-decomposition
Eigen::Matrix3d polar_rotation(const Eigen::Matrix3d& F);

/// The change δR of the polar rotation R = polar_rotation(F) when F changes by δF (a derivation
/// exercise): with S = RᵀF (symmetric) and w the vector of the skew matrix RᵀδF − δFᵀR
/// (w = (A₃₂ − A₂₃, A₁₃ − A₃₁, A₂₁ − A₁₂) for A = RᵀδF), ω = ((tr S) I − S)⁻¹ w and δR = R ω̂
/// (ω̂ a = ω × a). Rᵀ δR is skew. fem::Error for a non-finite F or δF, or where (tr S) I − S is
/// singular (two singular values of F zero: δR is unbounded). docs/11_corotational.md#the-derivative-of-r
Eigen::Matrix3d polar_rotation_variation(const Eigen::Matrix3d& F, const Eigen::Matrix3d& dF);

/// The same rotation as polar_rotation, by Higham's scaled Newton iteration on the polar factor:
/// X₀ = F, X_{k+1} = ½(ζ_k X_k + ζ_k⁻¹ X_k⁻ᵀ), ζ_k = |det X_k|^(−1/3) while X_k is far from
/// orthogonal (and det X_k not within 1 % of 1), 1 after; X⁻ᵀ from cross products of X's columns.
/// Each step maps every singular value σ to ½(σ + 1/σ) and leaves the singular vectors alone, so it
/// converges quadratically: an error ε becomes about ε²/2, and a step's change is about the error
/// it removed. Stops after a step that changed X by less than 1e-8 (the new error, ~1e-16, is
/// round-off): three steps for an element's F at strains of 1e-3. Falls back to the SVD
/// (polar_rotation) when det F ≤ 1e-6 ‖F‖³ — inverted or nearly flat, where the iteration would
/// reach a reflection or crawl — or after 40 steps. N. J. Higham, Functions of Matrices, §8.9.
/// docs/11_corotational.md#a-faster-polar-decomposition
Eigen::Matrix3d polar_rotation_newton(const Eigen::Matrix3d& F);

/// R[k] = polar_rotation_newton(F[k]) for k < count, four at a time in AVX2 registers where the
/// processor has them (common/simd.hpp): every lane does the same operations in the same order as
/// the function above, so the same bits; four that include one needing more (the SVD, a scaled
/// step) go one at a time. fem::Error naming the first non-finite F (before any R is written).
/// docs/11_corotational.md#a-faster-polar-decomposition
void polar_rotations_newton(const Eigen::Matrix3d* F, Eigen::Matrix3d* R, std::size_t count);

/// R̂ K_e R̂ᵀ with R̂ = diag(R, R, R, R): every 3×3 block (a, b) becomes R K_ab Rᵀ (12×12). K_e must
/// be symmetric (an element stiffness): the ten blocks a ≤ b are computed, the others transposed.
/// docs/11_corotational.md#forces-and-warped-stiffness
Matrix12d rotated_stiffness(const Matrix12d& K_e, const Eigen::Matrix3d& R);

/// The element's displacement in its rotated frame, d = R̂ᵀ x_e − X_e (vertex i's block is
/// Rᵀ x_i − X_i, 12 entries), less its mean over the four corners: that mean is a translation,
/// which K_e annihilates in exact arithmetic, and removing it keeps a far-moved element's forces
/// and energy free of its round-off. Zero for a rigid motion x_i = R X_i + c.
/// docs/11_corotational.md#forces-and-warped-stiffness
Vector12d corotated_displacement(const Eigen::Matrix3d& R, const Vector12d& x_e, const Vector12d& X_e);

/// The corotated element force f_e = −R̂ K_e (R̂ᵀ x_e − X_e) (12 entries, vertex-major like x_e
/// and X_e). docs/11_corotational.md#forces-and-warped-stiffness
Vector12d corotated_force(const Matrix12d& K_e, const Eigen::Matrix3d& R, const Vector12d& x_e, const Vector12d& X_e);

/// The shape-gradient form of the same element force (a linear tet with Lamé parameters λ, μ and
/// rest volume V; g_a the gradient of corner a's shape function, g₀ = −g₁ − g₂ − g₃, so that the
/// rest edge inverse T_X⁻¹ has rows g₁, g₂, g₃ and F = T_x T_X⁻¹ = Σ_a x_a g_aᵀ):
///   ε = sym(RᵀF) − I (3×3),  σ = λ tr(ε) I + 2μ ε,  U_e = V (μ ε:ε + ½ λ tr(ε)²),  f_a = −V R σ g_a.
/// It is the lecture's −R̂ K_e (R̂ᵀ x_e − X_e) written out for K_e = V Bᵀ C B (chapter 05): the
/// strain from F, which the rotation needed anyway, instead of a 12×12 product; and F from edges is
/// free of a far translation's round-off, as corotated_displacement's mean removal is.
/// docs/11_corotational.md#the-shape-gradient-form
struct GradientFormElement {
    double energy = 0.0;                 ///< U_e
    Eigen::Matrix<double, 3, 4> forces;  ///< column a: f_a
};

/// U_e and the corner forces f_a = −V R σ g_a of one tet in the shape-gradient form above:
/// F the deformation gradient, R its rotation, rest_edges_inverse T_X⁻¹ (rows g₁, g₂, g₃), volume V.
GradientFormElement gradient_form_forces(const Eigen::Matrix3d& F, const Eigen::Matrix3d& R,
                                         const Eigen::Matrix3d& rest_edges_inverse, double volume,
                                         const elastic::Lame& lame);

/// How CorotationalElasticity computes each element's force and energy (the same numbers to
/// round-off; K_R is R K_ab Rᵀ of the stored K_e in both). docs/11_corotational.md#the-shape-gradient-form
enum class ForceForm {
    stiffness_matrix,  ///< corotated_force of the stored K_e (the lecture's form, the exercises; the default)
    shape_gradients,   ///< gradient_form_forces (no 12×12 product: the faster one)
};

/// Which rotation an element uses (docs/11_corotational.md#edges-centroid-or-polar-decomposition).
enum class RotationFit {
    polar,     ///< polar_rotation of the deformation gradient (the default: order-independent, and
               ///< it leaves RᵀF symmetric, so the corotated strain holds no rotation)
    centroid,  ///< best_fit_rotation of centroid_covariance (shape matching)
    edges,     ///< best_fit_rotation of edge_covariance (the lecture's; depends on the corner order)
};

/// How the polar rotation of an element is computed (both give the same R to round-off).
enum class PolarAlgorithm {
    newton,  ///< polar_rotation_newton (the default: several times faster, SVD for hard cases)
    svd,     ///< polar_rotation, Eigen's JacobiSVD (the reference)
};

/// Corotational linear elasticity as a chapter 10 force model: per step, one rotation per tet,
/// the corotated forces and energy, and the warped stiffness K_R scattered into chapter 06's fixed
/// CSR pattern (route c: no new pattern, no triplets). K changes with u: chapter 10's implicit step
/// refactors (or re-preconditions) every step. docs/11_corotational.md#the-force-model
class CorotationalElasticity final : public dynamics::ForceModel {
public:
    /// K_e of every tet at rest (chapter 06's element_stiffnesses) and the assembly pattern.
    /// fem::Error for bad indices, a zero-volume rest tet (naming it) or a bad material.
    CorotationalElasticity(const TetMesh& mesh, const dynamics::Material& material,
                           RotationFit fit = RotationFit::polar, PolarAlgorithm algorithm = PolarAlgorithm::newton,
                           ForceForm form = ForceForm::stiffness_matrix);

    /// Its name, as tables and chapter 12's registry of models by name (force_models.hpp) write it.
    static constexpr const char* model_name = "corotational";
    std::string name() const override { return model_name; }
    /// Rotations at u, then U = Σ U_e and f = Σ E_eᵀ f_e. fem::Error if u has not 3n entries.
    double evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& forces) override;
    /// K_R at u (3n×3n, CSC with both triangles), assembled into the pattern.
    const dynamics::SparseMatrix& stiffness(const Eigen::VectorXd& u) override;
    bool constant_stiffness() const override { return false; }
    /// von Mises of C ε_e with the corotated strain ε_e = B_e (R̂ᵀ x_e − X_e) (chapter 05).
    Eigen::VectorXd von_mises_stress(const Eigen::VectorXd& u) const override;

    /// The rotation of every tet at u (#T), by the chosen fit.
    std::vector<Eigen::Matrix3d> rotations(const Eigen::VectorXd& u) const;

    /// One rotation per vertex (#V), at the u of the last evaluate() or stiffness() call (identity
    /// before any): the polar rotation of the volume-weighted mean Σ_t vol_t R_t / Σ_t vol_t over
    /// the tets around the vertex — the frame the vertex turned with. fem::Error before the model
    /// was evaluated.
    std::vector<Eigen::Matrix3d> vertex_rotations() const;

private:
    /// rotations(u), kept for the last u: a step asks for the forces and then K_R at the same u,
    /// and the SVDs are the expensive part of both. With ForceForm::shape_gradients it also keeps
    /// each tet's F (gradients_).
    const std::vector<Eigen::Matrix3d>& rotations_at(const Eigen::VectorXd& u);
    /// The rotation of every tet at u by the chosen fit, and its F into gradients (when not null).
    std::vector<Eigen::Matrix3d> rotations(const Eigen::VectorXd& u, std::vector<Eigen::Matrix3d>* gradients) const;

    TetMesh mesh_;
    elastic::Lame lame_;
    RotationFit fit_;
    PolarAlgorithm algorithm_;
    ForceForm form_;
    assembly::ElementMatrices K_e_;
    assembly::AssemblyPattern pattern_;
    dynamics::SparseMatrix K_R_;                  // the pattern's arrays, values rewritten per call
    Eigen::VectorXd volumes_;                     // rest volume of every tet
    Eigen::VectorXd rotated_at_;                  // the u of rotations_
    std::vector<Eigen::Matrix3d> rotations_;
    std::vector<Eigen::Matrix3d> gradients_;           // F of every tet at rotated_at_ (shape_gradients only)
    std::vector<Eigen::Matrix3d> rest_edges_inverse_;  // T_X⁻¹ of every tet (chapter 04), for F
    /// One tet's share of evaluate(): its energy and f_e.
    struct ElementForces {
        double energy = 0.0;
        Vector12d forces;
    };
    // The slots of the parallel loops (common/parallel.hpp), added up in tet order after them.
    std::vector<ElementForces> element_forces_;
    std::vector<Matrix12d> element_matrices_;
};

/// The rotations of the free vertices of `dofs` (vertex_rotations of those whose three dofs are
/// free, in the order of dofs.indices()): the block rotations of the body's reduced step matrix,
/// for a FrozenFactorPcg that turns with the body. fem::Error if a vertex is only partly pinned or
/// the sizes do not match. docs/11_corotational.md#solving-a-changing-matrix
std::vector<Eigen::Matrix3d> free_vertex_rotations(const CorotationalElasticity& model, const dynamics::FreeDofs& dofs);

}  // namespace fem::corot
