#pragma once
// Chapter 14's tests: a step potential that hands every call to a ContactPotential, for tests to
// derive from and watch what Newton evaluates (the configurations, their distances).
// docs/14_contact.md#checks

#include "14_contact/contact.hpp"

#include "12_hyperelastic_newton/newton.hpp"

#include <Eigen/Core>

namespace fem::test {

/// A hyper::StepPotential whose every function is contact's (not owned: it must outlive this).
class ContactDelegate : public hyper::StepPotential {
public:
    explicit ContactDelegate(contact::ContactPotential& contact) : contact_(contact) {}
    void begin_step(dynamics::Body& body, const dynamics::State& state, double time_step) override
    {
        contact_.begin_step(body, state, time_step);
    }
    double energy(const Eigen::VectorXd& u) const override { return contact_.energy(u); }
    Eigen::VectorXd gradient(const Eigen::VectorXd& u) const override { return contact_.gradient(u); }
    dynamics::SparseMatrix hessian(const Eigen::VectorXd& u) const override { return contact_.hessian(u); }
    double largest_safe_step(const Eigen::VectorXd& u, const Eigen::VectorXd& du) const override
    {
        return contact_.largest_safe_step(u, du);
    }
    Eigen::VectorXd start_velocity(const dynamics::Body& body, const dynamics::State& state,
                                   double time_step) const override
    {
        return contact_.start_velocity(body, state, time_step);
    }

protected:
    contact::ContactPotential& contact_;
};

}  // namespace fem::test
