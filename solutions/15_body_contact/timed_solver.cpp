// Chapter 15: the linear solver, timed. docs/15_body_contact.md#the-cost-of-contact
#include "15_body_contact/timed_solver.hpp"

#include "common/error.hpp"
#include "common/timer.hpp"

namespace fem::contact {

TimedSolver::TimedSolver(std::unique_ptr<cg::LinearSolver> inner)
    : LinearSolver(inner->name(), inner->options()), inner_(std::move(inner))
{
}

void TimedSolver::do_prepare(const Eigen::SparseMatrix<double>& A, bool same_pattern)
{
    new_patterns += same_pattern ? 0 : 1;
    ++prepares;
    nonzeros += double(A.nonZeros());
    // A factorization that fails (a matrix that is not positive definite) costs its time too.
    const Timer timer;
    try {
        inner_->prepare(A);
    } catch (const Error&) {
        seconds += timer.seconds();
        throw;
    }
    seconds += inner_->stats().prepare_seconds;
}

int TimedSolver::do_solve(const Eigen::VectorXd& b, Eigen::VectorXd& x)
{
    // The tolerance set on this (inexact Newton sets one per solve) is the inner solver's.
    inner_->set_relative_tolerance(options().relative_tolerance);
    inner_->solve(b, x);
    seconds += inner_->stats().solve_seconds;
    return inner_->stats().iterations;
}

}  // namespace fem::contact
