#pragma once
// Chapter 11: a third way to solve the changing step matrix of a corotational body.
// docs/11_corotational.md#solving-a-changing-matrix
//
// The warped stiffness changes every step, so chapter 10's "factor once" no longer holds. Besides
// refactoring every step (chapter 08's Cholesky reuses its symbolic analysis on the fixed pattern)
// and warm-started PCG with IC(0), a factorization can be kept frozen and used as the
// preconditioner of CG on the current matrix: A₀⁻¹ A(u) is the identity while the body is at rest
// and drifts away as its elements rotate, so the iterations grow with the rotation. The frozen
// factor is refreshed when CG needs more than refresh_iterations.

#include "09_conjugate_gradient/linear_solver.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>

namespace fem::corot {

/// PCG preconditioned by a frozen sparse Cholesky factor (chapter 09's "default" solver), behind
/// chapter 09's solver interface so that chapter 10's ThetaMethod can use it
/// (ImplicitOptions::make_solver). docs/11_corotational.md#solving-a-changing-matrix
class FrozenFactorPcg final : public cg::LinearSolver {
public:
    /// options: CG's relative tolerance and cap; refresh_iterations: refactor the preconditioner
    /// when a solve needed more iterations than this (0: never). fem::Error for a tolerance outside
    /// (0, 1) or negative counts.
    explicit FrozenFactorPcg(const cg::SolverOptions& options = {}, int refresh_iterations = 0);

    bool is_direct() const override { return false; }
    /// How many times the preconditioner was factored (1 after the first prepare()).
    int factorizations() const { return factorizations_; }

protected:
    void do_prepare(const Eigen::SparseMatrix<double>& A, bool same_pattern) override;
    int do_solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override;

private:
    cg::SolverOptions options_;
    int refresh_iterations_;
    std::unique_ptr<cg::LinearSolver> factor_;
    Eigen::SparseMatrix<double> A_;
    bool refresh_ = true;
    int factorizations_ = 0;
};

}  // namespace fem::corot
