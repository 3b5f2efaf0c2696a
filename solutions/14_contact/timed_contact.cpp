// Chapter 14: the contact potential and the linear solver, timed. docs/14_contact.md#bodies-against-bodies-the-cost
#include "14_contact/timed_contact.hpp"

#include "common/error.hpp"
#include "common/timer.hpp"

namespace fem::contact {

namespace {

/// call(), its wall time added to seconds.
template <class Call>
auto timed(double& seconds, Call call)
{
    const Timer timer;
    auto result = call();
    seconds += timer.seconds();
    return result;
}

}  // namespace

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

void TimedContact::begin_step(dynamics::Body& body, const dynamics::State& state, double time_step)
{
    const Timer timer;
    contact_.begin_step(body, state, time_step);
    barrier_seconds += timer.seconds();
}

double TimedContact::energy(const Eigen::VectorXd& u) const
{
    return timed(barrier_seconds, [&] { return contact_.energy(u); });
}

Eigen::VectorXd TimedContact::gradient(const Eigen::VectorXd& u) const
{
    return timed(barrier_seconds, [&] { return contact_.gradient(u); });
}

dynamics::SparseMatrix TimedContact::hessian(const Eigen::VectorXd& u) const
{
    return timed(barrier_seconds, [&] { return contact_.hessian(u); });
}

dynamics::SparseMatrix TimedContact::exact_hessian(const Eigen::VectorXd& u) const
{
    return timed(barrier_seconds, [&] { return contact_.exact_hessian(u); });
}

double TimedContact::largest_safe_step(const Eigen::VectorXd& u, const Eigen::VectorXd& du) const
{
    return timed(collision_seconds, [&] { return contact_.largest_safe_step(u, du); });
}

Eigen::VectorXd TimedContact::start_velocity(const dynamics::Body& body, const dynamics::State& state,
                                             double time_step) const
{
    return timed(collision_seconds, [&] { return contact_.start_velocity(body, state, time_step); });
}

}  // namespace fem::contact
