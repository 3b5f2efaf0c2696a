#pragma once
// The studies of ch14_contact, one file each (study_*.cpp), called in order by main.cpp.
// Not part of the chapter's library: only the executable uses them.

#include "14_contact/contact_scenes.hpp"

#include "common/cli.hpp"

#include <string>
#include <vector>

namespace fem::contact::study {

/// The executable's options (main.cpp checks them before any study runs).
struct Settings {
    std::vector<double> activation_distances{1e-3, 1e-4};  ///< d̂ [m] swept
    std::vector<double> stiffnesses{0.0, 1e4};             ///< κ [N/m] swept (0: adaptive)
    std::vector<double> time_steps{1.0 / 100.0, 1.0 / 400.0, 1.0 / 1600.0};  ///< Δt [s] swept
    std::vector<double> tolerances{1e-4, 1e-7};            ///< Newton's relative tolerance swept
    std::vector<int> friction_updates{1, 3, 0};            ///< lagged friction updates per step swept (slope; 0: until converged)
    double drop_height = 0.05;                             ///< h [m]
    double duration = 0.5;                                 ///< length of each run [s]
};

/// The one-line description of a swept configuration, e.g. "dhat 1e-3, kappa adaptive".
struct Case {
    double activation_distance, stiffness, time_step, tolerance;
};
/// Every combination of the settings' sweeps, in the order d̂, κ, Δt, tolerance.
std::vector<Case> sweep(const Settings& settings);
/// The time steps the drop and slope studies take together: duration/Δt for every case of the
/// sweep, once dropped and on each of the two slopes with each friction update count.
double swept_steps(const Settings& settings);
/// main.cpp refuses a sweep of more steps than this before any study runs (about 20 minutes at the
/// block's ~1 ms a step).
inline constexpr double most_swept_steps = 1e6;
/// The block settings of one case.
BlockSettings block_settings(const Case& c);
/// The studies' block's weight ρ a³ g [N] (BlockSettings' cube).
double block_weight();

void drop_study(const RunContext& run, const Settings& settings);
void slope_study(const RunContext& run, const Settings& settings);

}  // namespace fem::contact::study
