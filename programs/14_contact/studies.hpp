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
    int mesh_queries = 20000;                              ///< random points a mesh distance is timed on
    std::vector<double> grid_spacings{0.01, 0.005, 0.0025}; ///< the sampled grids' spacings h [m]
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
/// Δt as the tables write it: "1/100" for 0.01 s.
std::string time_step_label(double time_step);

void drop_study(const RunContext& run, const Settings& settings);
void slope_study(const RunContext& run, const Settings& settings);
/// The distance to a mesh three ways, then bowl_study.
void mesh_study(const RunContext& run, const Settings& settings);
/// A block dropped into the bowl (the mesh obstacle in use): bowl.pvd, its PNG frames, bowl_table.csv.
void bowl_study(const RunContext& run);
/// The broad phase of self-contact three ways (brute force, AABB tree, spatial hash) on two blocks
/// of k³ cells closing on each other: candidate pairs, whether they agree, time per search;
/// self_broad_phase_table.csv (study_self.cpp).
void self_contact_study(const RunContext& run);
/// Two coarse bunnies thrown at each other, with self-contact and without: per step the time in
/// the linear solves, the barrier (with its broad phase) and the collision check, the momentum's
/// drift, intersection-free or not; two_bunnies_table.csv (study_bodies.cpp). Then the contact run
/// with Newton's tolerance 10⁻³: its iterations and how far it ends from the default's;
/// two_bunnies_tolerance_table.csv. With hessian_variants (ch14_contact --hessian-variants; eight more
/// runs of the bunnies, minutes), the contact run again with the barrier's Hessian projected
/// otherwise or tried exact first, κ doubled or fixed, and Newton also stopped by its step's length
/// (NewtonOptions::step_tolerance): two_bunnies_hessian_table.csv.
void bodies_study(const RunContext& run, bool hessian_variants = false);
/// test_stack.cpp's three blocks settled on the floor for each d̂ and Newton tolerance: the force
/// between blocks against the weight above, the gaps against d̂, the height against the tightest
/// tolerance's, Newton iterations and time per step; stack_tolerance_table.csv (study_stack.cpp).
void stack_study(const RunContext& run);

}  // namespace fem::contact::study
