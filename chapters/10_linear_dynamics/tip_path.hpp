#pragma once
// Chapter 10: what a swing study records of a run — where one vertex (the tip) is at every step and
// how far the body's volume strays — and the distance between two runs' tips, the error measure of
// the swings of chapters 11 and 12. docs/10_linear_dynamics.md#the-pieces-of-a-simulation

#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include <vector>

namespace fem::dynamics {

/// The path of one vertex through a run, in the x-z plane of a cantilever's swing, with the volume.
struct TipPath {
    int tip = 0;                         ///< the vertex followed
    double time_step = 0.0;              ///< Δt of the run [s]
    std::vector<double> times, x, z;     ///< at every recorded state: t [s], the tip's x and z [m]
    double largest_volume_change = 0.0;  ///< max over the recorded states of |V(t)/V₀ − 1|

    /// Records the body's state (a Simulation observer calls it): t, the tip's x and z, and the
    /// volume of the deformed mesh against the rest mesh's (common/mesh.hpp's total_volume).
    void record(const Body& body, const State& state);
};

/// The largest distance between the tips of run and reference at run's recorded times:
/// max_k |(x, z)_run(t_k) − (x, z)_ref(t_k)| [m]. The reference's Δt must divide run's (its state
/// k·(Δt_run/Δt_ref) is run's state k). fem::Error when it does not, or when the reference is shorter.
double largest_tip_distance(const TipPath& run, const TipPath& reference);

}  // namespace fem::dynamics
