// Chapter 14: the barrier's adaptive stiffness κ, step by step (IPC's rule). docs/14_contact.md#the-constants
#include "14_contact/adaptive_stiffness.hpp"

#include "14_contact/barrier.hpp"

#include "common/error.hpp"

#include <algorithm>

namespace fem::contact {

double balancing_stiffness(const Eigen::VectorXd& g, const Eigen::VectorXd& h)
{
    if (g.size() != h.size())
        throw Error(str("balancing_stiffness: g and h must have one size, got ", g.size(), " and ", h.size()));
    const double norm = h.squaredNorm();
    return norm > 0.0 ? -g.dot(h) / norm : 0.0;
}

double smallest_stiffness(double average_mass, double time_step, double activation_distance)
{
    require_positive(average_mass, "average vertex mass [kg]");
    require_positive(time_step, "time step dt [s]");
    return average_mass / (time_step * time_step * barrier(0.5 * activation_distance, activation_distance).second);
}

AdaptiveStiffness::AdaptiveStiffness(double average_mass, double diagonal, double activation_distance,
                                     double doubling_distance)
    : average_mass_(average_mass), activation_distance_(activation_distance), doubling_distance_(doubling_distance * diagonal)
{
}

double AdaptiveStiffness::next(double time_step, double smallest_distance, const StiffnessBalance& balance)
{
    const double low = smallest_stiffness(average_mass_, time_step, activation_distance_);
    const double high = 100.0 * low;
    if (!balanced_) {
        const auto [load, unit_barrier] = balance();
        stiffness_ = std::clamp(balancing_stiffness(load, unit_barrier), low, high);
        balanced_ = unit_barrier.norm() > 0.0;
    } else if (smallest_distance < doubling_distance_ && smallest_distance < last_smallest_) {
        stiffness_ = std::min(high, 2.0 * stiffness_);
    }
    stiffness_ = std::clamp(stiffness_, low, high);
    last_smallest_ = smallest_distance;
    return stiffness_;
}

}  // namespace fem::contact
