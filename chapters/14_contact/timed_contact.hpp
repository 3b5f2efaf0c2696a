#pragma once
// Chapter 14: where a contact step's time goes — the contact potential and the linear solver, each
// wrapped to sum its own wall time, so that a run can split a step into the barrier (with its broad
// phase), the continuous collision check and the linear solves (study 6 of ch14_contact, the scenes
// runner's contact_steps.csv). docs/14_contact.md#bodies-against-bodies-the-cost
//
// The wrappers change no answer: each forwards every call to the object it wraps and adds the
// call's wall time to a sum (common/timer.hpp). Read a sum before and after a step for that step's
// share.

#include "14_contact/contact.hpp"

#include "12_hyperelastic_newton/newton.hpp"

#include "09_conjugate_gradient/linear_solver.hpp"

#include "10_linear_dynamics/body.hpp"

#include <memory>

namespace fem::contact {

/// A chapter 09 LinearSolver, timed: seconds sums the wrapped solver's own prepare_seconds (its
/// factorisation or preconditioner, with the symbolic analysis of a new pattern) and solve_seconds
/// of every prepare and solve, and the time of each prepare that failed (fem::Error, passed on: a
/// Cholesky factorization of a matrix that is not positive definite); new_patterns counts the prepares with a new sparsity pattern (a new
/// fill-reducing ordering and symbolic analysis). Answers as the wrapped solver: it starts with the
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

/// The contact potential (a chapter 12 StepPotential for NewtonBackwardEuler::set_potential), timed:
///   barrier_seconds sums begin_step (κ, the lagged friction pairs) and every energy, gradient and
///     Hessian — the barrier with its broad phase (a tree, or the last motion's candidates) and the
///     friction terms;
///   collision_seconds sums largest_safe_step (the continuous collision check of the line search,
///     with its own broad phase over the swept boxes) and start_velocity (the start's check against
///     the obstacles).
/// The work contact_step asks of the ContactPotential itself (its stages' obstacle_advance, the
/// barrier energies it books as work) is not in either.
class TimedContact final : public hyper::StepPotential {
public:
    /// Wraps contact (not owned: it must outlive this).
    explicit TimedContact(ContactPotential& contact) : contact_(contact) {}
    void begin_step(dynamics::Body& body, const dynamics::State& state, double time_step) override;
    double energy(const Eigen::VectorXd& u) const override;
    Eigen::VectorXd gradient(const Eigen::VectorXd& u) const override;
    dynamics::SparseMatrix hessian(const Eigen::VectorXd& u) const override;
    dynamics::SparseMatrix exact_hessian(const Eigen::VectorXd& u) const override;
    double largest_safe_step(const Eigen::VectorXd& u, const Eigen::VectorXd& du) const override;
    Eigen::VectorXd start_velocity(const dynamics::Body& body, const dynamics::State& state,
                                   double time_step) const override;

    mutable double barrier_seconds = 0.0;    ///< the barrier and its broad phase so far [s]
    mutable double collision_seconds = 0.0;  ///< the collision checks so far [s]

private:
    ContactPotential& contact_;
};

}  // namespace fem::contact
