#pragma once
// The plain route of a corotational step, for the "peers, like for like" table of the cost study
// (docs/11_corotational.md#making-it-fast): the code a student writes first, with nothing of this
// chapter's speed-ups. Per step it computes one rotation per tet from Eigen's 3×3 JacobiSVD of F,
// the corotated forces f_e = −R̂ K_e (R̂ᵀ x_e − X_e), the warped stiffness K_R from a list of
// triplets (setFromTriplets), and factors the step matrix afresh with Eigen's SimplicialLLT
// (compute(): ordering, symbolic and numeric factorization every step). The step itself is chapter
// 10's ThetaMethod, so the plain route and ours differ only in those three parts, and agree to
// round-off (tests/11_corotational/test_plain_route.cpp). Code in solutions/11_corotational/
// plain_routes.cpp, part of the chapter's library: chapter 12's plain route factors with it.

#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include "09_conjugate_gradient/linear_solver.hpp"

#include "05_strain_stress/strain_stress.hpp"

#include <Eigen/Core>

#include <memory>
#include <string>
#include <vector>

namespace fem::corot::plain {

/// How the plain model finds each tet's rotation.
enum class PlainRotation {
    jacobi_svd,    ///< Eigen's JacobiSVD of F = U Σ Vᵀ, R = U Vᵀ (U's last column negated when det < 0)
    polar_newton,  ///< this chapter's polar_rotations_newton (one rung of the ladder of speed-ups)
};

/// Corotational elasticity written the plain way (a chapter 10 force model): per call one rotation
/// per tet (rotations kept for the last u, as any code computes them once per step), the element
/// forces −R̂ K_e (R̂ᵀ x_e − X_e) (the displacement's mean over the four corners removed, as in
/// corotated_displacement), and K_R = Σ_e E_eᵀ R̂_e K_e R̂_eᵀ E_e from 144 triplets per tet. The same
/// physics as CorotationalElasticity's default (polar fit, stiffness-matrix forces): forces and
/// K_R agree to round-off. fem::Error for a zero-volume rest tet or a u of the wrong size.
class PlainCorotational final : public dynamics::ForceModel {
public:
    PlainCorotational(const TetMesh& mesh, const dynamics::Material& material,
                      PlainRotation rotation = PlainRotation::jacobi_svd);

    std::string name() const override { return "corotational (plain)"; }
    /// U = Σ_e ½ dᵀ K_e d and f = Σ_e E_eᵀ f_e, d = R̂ᵀ x_e − X_e less its mean.
    double evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& forces) override;
    /// K_R at u (3n×3n, both triangles), from triplets.
    const dynamics::SparseMatrix& stiffness(const Eigen::VectorXd& u) override;
    bool constant_stiffness() const override { return false; }
    /// Zero for every tet: the plain route is timed, not drawn.
    Eigen::VectorXd von_mises_stress(const Eigen::VectorXd& u) const override;

private:
    /// The rotation of every tet at u (recomputed only when u changed).
    const std::vector<Eigen::Matrix3d>& rotations_at(const Eigen::VectorXd& u);

    TetMesh mesh_;
    PlainRotation rotation_;
    std::vector<Eigen::Matrix<double, 12, 12>> K_e_;  // chapter 06's element stiffnesses at rest
    std::vector<Eigen::Matrix3d> rest_edges_inverse_;  // T_X⁻¹ per tet, for F = T_x T_X⁻¹
    Eigen::VectorXd rotated_at_;
    std::vector<Eigen::Matrix3d> rotations_;
    dynamics::SparseMatrix K_R_;
};

/// The plain factorization: a chapter 09 LinearSolver (name "eigen-llt, refactored") whose prepare
/// calls Eigen's SimplicialLLT::compute(A) every time — fill-reducing ordering, symbolic analysis
/// and numeric factorization, reusing nothing — and whose solve is its two triangular solves.
/// fem::Error when A is not positive definite.
std::unique_ptr<cg::LinearSolver> plain_cholesky();

/// ThetaMethod options that solve every step with plain_cholesky() (the velocity-change form, as
/// the chapter's default).
dynamics::ImplicitOptions plain_step_options();

}  // namespace fem::corot::plain
