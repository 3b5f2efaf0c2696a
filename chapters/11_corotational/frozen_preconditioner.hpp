#pragma once
// Chapter 11: a third way to solve the changing step matrix of a corotational body.
// docs/11_corotational.md#solving-a-changing-matrix
//
// The warped stiffness changes every step, so chapter 10's "factor once" no longer holds. Besides
// refactoring every step (chapter 08's Cholesky reuses its symbolic analysis on the fixed pattern)
// and warm-started PCG with IC(0), a factorization can be kept frozen and used as the
// preconditioner of CG on the current matrix: A₀⁻¹ A(u) is the identity while the body is at rest
// and drifts away as its elements rotate, so the iterations grow with the rotation. The frozen
// factor is refreshed by a RefreshRule: after too many iterations, or when the extra iterations
// have cost as much as a factorization.

#include "08_direct_solvers/sparse_cholesky.hpp"
#include "09_conjugate_gradient/conjugate_gradient.hpp"
#include "09_conjugate_gradient/linear_operator.hpp"
#include "09_conjugate_gradient/linear_solver.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <functional>
#include <memory>
#include <optional>
#include <vector>

namespace fem::corot {

/// The rotations of the unknowns' 3-blocks: entry i rotates unknowns 3i, 3i+1, 3i+2 (for a body's
/// reduced step matrix, the free vertices in order). Asked for at every prepare().
using BlockRotations = std::function<std::vector<Eigen::Matrix3d>()>;

/// The precision the frozen factor is applied in: its substitutions read L from memory, so a copy
/// rounded to float (chapter 08's solve_single_precision) halves their cost. The float factor is not
/// an exactly linear, symmetric M⁻¹; the cost study measures that plain PCG still reaches its
/// tolerance in the true residual, beside flexible PCG (chapter 09's CgBeta::polak_ribiere).
/// docs/11_corotational.md#a-single-precision-preconditioner
enum class FactorPrecision { single_precision, double_precision };

/// When FrozenFactorPcg factors the current matrix again (at the next prepare()); both rules may be
/// on, e.g. RefreshRule{.iterations_above = 30} or RefreshRule{.balance_cost = true}.
struct RefreshRule {
    /// Refactor after a solve that needed more than this many CG iterations (0: no such limit).
    int iterations_above = 0;
    /// Refactor once the iterations beyond a fresh factor's (those of the first solve after a
    /// factorization), summed over the solves since it, cost as much as a factorization did. Costs
    /// in flops, counted, not timed (the same refreshes on any machine): a factorization Σ_j c_j²
    /// (c_j: nonzeros of column j of L), an iteration 4 × the factor's stored entries (two
    /// substitutions) + 2 nnz(A). When the iterations grow steadily, by s a solve, the mean cost of
    /// a solve F/N + (b + s N/2)·c over a refresh interval of N solves is least at N = √(2F/(s c)),
    /// where the extra iterations have cost s c N²/2 = F: this rule stops there.
    bool balance_cost = false;
};

/// PCG preconditioned by a frozen sparse Cholesky factor (chapter 08's supernodal factorization), behind
/// chapter 09's solver interface so that chapter 10's ThetaMethod can use it
/// (ImplicitOptions::make_solver). docs/11_corotational.md#solving-a-changing-matrix
///
/// With block rotations, the frozen factor turns with the body: if A₀ was factored when the blocks
/// had rotations R₀ᵢ and they have Rᵢ now, the preconditioner is Q A₀⁻¹ Qᵀ with the block-diagonal
/// Q = diag(Rᵢ R₀ᵢᵀ). For a body that only rotated, A = Q A₀ Qᵀ exactly (a lumped mass is the same
/// in every frame): the preconditioner stays exact however far the body turns, and only the
/// element-to-element variation of the rotations costs iterations.
class FrozenFactorPcg final : public cg::LinearSolver {
public:
    /// options: CG's relative tolerance and cap; refresh: when to refactor the preconditioner
    /// (RefreshRule{}: never); rotations: the blocks' rotations (empty: a plain frozen factor);
    /// precision: of the factor's substitutions.
    /// fem::Error for a tolerance outside (0, 1) or negative counts.
    explicit FrozenFactorPcg(const cg::SolverOptions& options = {}, RefreshRule refresh = {},
                             BlockRotations rotations = {},
                             FactorPrecision precision = FactorPrecision::single_precision);

    bool is_direct() const override { return false; }
    /// How many times the preconditioner was factored (1 after the first prepare()).
    int factorizations() const { return factorizations_; }

protected:
    /// Keeps A, asks for the rotations, and factors A when it must (first call, a new pattern, or a
    /// refresh after too many iterations). fem::Error if the rotations do not match A's size.
    void do_prepare(const Eigen::SparseMatrix<double>& A, bool same_pattern) override;
    int do_solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override;

private:
    /// A₀⁻¹ r with the frozen factor, in the chosen precision.
    Eigen::VectorXd apply_factor(const Eigen::VectorXd& r) const;

    RefreshRule refresh_rule_;
    BlockRotations rotations_;
    FactorPrecision precision_;
    std::optional<direct::SparseCholesky> factor_;   // used directly: no residual check per application
    const Eigen::SparseMatrix<double>* A_ = nullptr;  // the base class's copy, alive until the next prepare
    std::vector<Eigen::Matrix3d> frozen_rotations_;   // R₀ᵢ, when the factor was made
    std::vector<Eigen::Matrix3d> turn_;               // Qᵢ = Rᵢ R₀ᵢᵀ
    bool refresh_ = true;
    int factorizations_ = 0;
    // RefreshRule::balance_cost's accounts, in flops (reset at each factorization)
    double factorization_cost_ = 0.0, iteration_cost_ = 0.0, extra_cost_ = 0.0;
    int fresh_iterations_ = -1;  // of the first solve after the factorization (-1: none yet)
};

}  // namespace fem::corot
