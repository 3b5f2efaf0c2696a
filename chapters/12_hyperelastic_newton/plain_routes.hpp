#pragma once
// The plain route of a hyperelastic Newton step, for the "peers, like for like" table of the cost
// study (docs/12_hyperelastic_newton.md#making-it-fast): the element loops and the assembly written
// the way a student writes them first. Per tet H = [u₁ − u₀, u₂ − u₀, u₃ − u₀] T_X⁻¹, the energy
// V ψ(H), the forces −V Bᵀ vec(P) and the Hessian V Bᵀ (∂P/∂F) B as dense products with chapter
// 04's 9×12 B, the definite Hessian with ∂P/∂F clamped by Eigen's SelfAdjointEigenSolver (9×9),
// and the 3n×3n matrices from 144 triplets per tet (setFromTriplets). Stepped by this chapter's
// NewtonBackwardEuler with chapter 11's plain Cholesky (SimplicialLLT::compute at every Newton
// iteration, corot::plain::plain_cholesky), so the line search, the stopping rule and the step
// matrix are ours by construction and the plain route differs only in the element loops, the
// assembly and the factorization: its steps agree with ours to round-off
// (tests/12_hyperelastic_newton/test_plain_route.cpp). Code in solutions/12_hyperelastic_newton/
// plain_routes.cpp, an OWN file of the chapter (CMakeLists.txt): only its executable and tests use it.

#include "12_hyperelastic_newton/materials.hpp"
#include "12_hyperelastic_newton/newton.hpp"

#include "10_linear_dynamics/body.hpp"

#include "04_tet_jacobians/tet_jacobians.hpp"

#include <Eigen/Core>

#include <memory>
#include <string>
#include <vector>

namespace fem::hyper::plain {

/// A hyperelastic body (U = Σ V_t ψ(F_t)) written the plain way, as a chapter 10 force model: the
/// same energy, forces and Hessians as HyperelasticElasticity with Projection::clamp, to round-off.
/// fem::Error for a zero-volume rest tet or a u of the wrong size.
class PlainHyperelastic final : public dynamics::ForceModel {
public:
    PlainHyperelastic(const TetMesh& mesh, std::unique_ptr<Material> material);

    std::string name() const override { return material_->name() + " (plain)"; }
    /// U(u) and f(u) = −Σ_t E_tᵀ V_t Bᵀ vec(P(H_t)).
    double evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& forces) override;
    /// K(u) = Σ_t E_tᵀ V_t Bᵀ (∂P/∂F) B E_t (3n×3n, both triangles), from triplets.
    const dynamics::SparseMatrix& stiffness(const Eigen::VectorXd& u) override;
    /// The same with every ∂P/∂F's negative eigenvalues set to zero (PSD).
    const dynamics::SparseMatrix& definite_stiffness(const Eigen::VectorXd& u) override;
    /// U(u) alone (the line search's test; +∞ where the material is).
    double energy(const Eigen::VectorXd& u) override;
    bool constant_stiffness() const override { return false; }
    /// Zero for every tet: the plain route is timed, not drawn.
    Eigen::VectorXd von_mises_stress(const Eigen::VectorXd& u) const override;

private:
    Eigen::Matrix3d displacement_gradient(const Eigen::VectorXd& u, Eigen::Index t) const;
    const dynamics::SparseMatrix& hessian(const Eigen::VectorXd& u, bool definite);

    TetMesh mesh_;
    std::unique_ptr<Material> material_;
    std::vector<tet::Jacobian> B_;                     // chapter 04's 9×12 per tet
    std::vector<Eigen::Matrix3d> rest_edges_inverse_;  // T_X⁻¹ per tet
    Eigen::VectorXd volumes_;
    dynamics::SparseMatrix K_;
};

/// Newton's options for the plain route: `options` with chapter 11's plain Cholesky as the solver.
NewtonOptions plain_newton_options(NewtonOptions options = {});

}  // namespace fem::hyper::plain
