#pragma once
// Chapter 14: the barrier's adaptive stiffness κ (after IPC's rule, ipc-toolkit's
// barrier/adaptive_stiffness): balanced against the body's load at the first contact, kept between
// κ_min, which ties the barrier to the vertex mass, and κ_max = 100 κ_min, and doubled while the
// smallest distance keeps falling below ε_d. docs/14_contact.md#the-constants

#include <Eigen/Core>

#include <functional>
#include <utility>

namespace fem::contact {

/// The minimiser of ‖g + κ h‖ over κ: κ = −gᵀh/‖h‖² (g, h of one size), the κ whose barrier force
/// best balances the body's force (IPC's initial κ); 0 when h = 0. fem::Error on sizes.
double balancing_stiffness(const Eigen::VectorXd& g, const Eigen::VectorXd& h);

/// κ_min = m̄ / (Δt² b''(d̂/2)): the barrier's stiffness at d = d̂/2 equals the inertia m̄/Δt² of
/// the average vertex mass m̄ [kg] in backward Euler's Hessian (b'' of the unit barrier; the
/// course's counterpart of IPC's κ_min, which ties the barrier's Hessian to the mass in the same
/// way). fem::Error unless m̄, Δt, d̂ > 0.
double smallest_stiffness(double average_mass, double time_step, double activation_distance);

/// The load g and the unit-κ barrier gradient h (free dofs, one size) that balancing_stiffness
/// balances; asked for only until some step has a vertex within d̂.
using StiffnessBalance = std::function<std::pair<Eigen::VectorXd, Eigen::VectorXd>()>;

/// κ step by step: with κ_min = smallest_stiffness(m̄, Δt, d̂) and κ_max = 100 κ_min, at each step
/// until one has a vertex within d̂ (h ≠ 0), κ = balancing_stiffness(g, h) clamped to [κ_min, κ_max];
/// later κ doubles, up to κ_max, when the smallest distance is below ε_d and smaller than at the
/// last step; always within [κ_min, κ_max] (Δt may change between steps).
class AdaptiveStiffness {
public:
    /// For a body of average surface vertex mass m̄ [kg] and bounding-box diagonal [m], d̂ [m] and
    /// ε_d = doubling_distance × diagonal.
    AdaptiveStiffness(double average_mass, double diagonal, double activation_distance, double doubling_distance);

    /// κ [N/m] of a step of time_step [s] whose start has smallest_distance [m]; balance gives (g, h)
    /// while κ is not yet balanced.
    double next(double time_step, double smallest_distance, const StiffnessBalance& balance);

    /// Whether a step with a vertex within d̂ has balanced κ already.
    bool balanced() const { return balanced_; }

private:
    double average_mass_, activation_distance_, doubling_distance_;  // m̄, d̂, ε_d [m]
    double stiffness_ = 0.0, last_smallest_ = 0.0;
    bool balanced_ = false;
};

}  // namespace fem::contact
