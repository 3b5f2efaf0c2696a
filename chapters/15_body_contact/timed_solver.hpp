#pragma once
// Chapter 15: where a contact step's time goes — the linear solver, wrapped to sum its own wall time,
// so that a run can split a step into the barrier (with its broad phase) and the continuous
// collision check (the contact potential's own clocks, ContactClocks of contact.hpp) and the linear
// solves (study 6 of ch14_contact, the scenes runner's contact_steps.csv).
// docs/15_body_contact.md#the-cost-of-contact
//
// The wrapper changes no answer: it forwards every call to the solver it wraps and adds the wrapped
// solver's own prepare and solve times to a sum. Read the sum before and after a step for that
// step's share.

#include "09_conjugate_gradient/linear_solver.hpp"

#include <memory>

namespace fem::contact {

/// A chapter 09 LinearSolver, timed: seconds sums the wrapped solver's own prepare_seconds (its
/// factorisation or preconditioner, with the symbolic analysis of a new pattern) and solve_seconds
/// of every prepare and solve, and the time of each prepare that failed (fem::Error, passed on: a
/// Cholesky factorization of a matrix that is not positive definite); new_patterns counts the
/// prepares with a new sparsity pattern (a new fill-reducing ordering and symbolic analysis). Answers as the wrapped solver: it starts with the
/// wrapped solver's options, and each solve passes on the relative tolerance set on it
/// (set_relative_tolerance, which inexact Newton sets per solve).
class TimedSolver final : public cg::LinearSolver {
public:
    /// Wraps inner (owned; not null).
    explicit TimedSolver(std::unique_ptr<cg::LinearSolver> inner);
    bool is_direct() const override { return inner_->is_direct(); }

    double seconds = 0.0;  ///< prepares and solves so far [s]
    int new_patterns = 0;  ///< prepares with a new pattern so far
    int prepares = 0;      ///< prepares so far, failed ones included
    double nonzeros = 0.0; ///< the stored entries of the matrices prepared so far, summed

private:
    void do_prepare(const Eigen::SparseMatrix<double>& A, bool same_pattern) override;
    int do_solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override;
    std::unique_ptr<cg::LinearSolver> inner_;
};

}  // namespace fem::contact
