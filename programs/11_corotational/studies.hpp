#pragma once
// The studies of ch11_corotational, one file each (study_*.cpp), called in order by main.cpp.
// Not part of the chapter's library: only the executable uses them.

#include "11_corotational/corotational.hpp"

#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include "common/cli.hpp"
#include "common/vtk_io.hpp"

#include <memory>
#include <string>
#include <vector>

namespace fem::corot::study {

/// The executable's options (main.cpp validates them before any study runs).
struct Settings {
    dynamics::Material soft{2e5, 0.45, 1100.0};   ///< the swinging beam: soft enough to droop ~60°
    dynamics::Material sofa{2e6, 0.45, 1100.0};   ///< SOFA's validation cantilever (the cost goal)
    double duration = 1.5;                        ///< length of the swing [s]
    int swing_cells = 20;                         ///< cells along the swinging beam
    std::vector<int> cost_cells{20, 40, 60, 100}; ///< cells along the beams of the cost study
    double seconds = 0.2;                         ///< measuring time per timed kernel [s]
};

/// The force model called "linear" or "corotational" for a scene: the corotational one in the
/// lecture's configuration (polar fit, forces R K_e (Rᵀx − X)) that this chapter's tables teach and
/// time. Chapter 12's hyper::make_force_model is the course's factory of every model by name (with
/// the faster shape-gradient forces); this chapter cannot use it, a chapter using earlier ones only.
std::unique_ptr<dynamics::ForceModel> force_model(const std::string& name, const dynamics::Scene& scene);

/// The solvers of a changing step matrix compared side by side, by name: "refactor" (chapter 08's
/// Cholesky, its symbolic analysis reused); PCG with IC(0) on the lecture's v⁺ form from zero
/// ("pcg-ic0 v+ from zero") and from the last velocity ("pcg-ic0 v+ from v"), and on the Δv form
/// from the last Δv ("pcg-ic0 dv from last dv"); "frozen-factor-pcg", and the same turned with the
/// body's free vertices ("rotated-frozen-factor-pcg", which needs a corotational body; body must
/// outlive the integrator). All converge to the relative residual `tolerance` (relative to the
/// right-hand side of their form).
dynamics::ImplicitOptions solver_option(const std::string& name, double tolerance, dynamics::Body& body);

/// The solver option names, in the order of the tables.
const std::vector<std::string>& solver_option_names();

void rotation_study(const RunContext& run, const Settings& settings);
void swing_study(const RunContext& run, const Settings& settings);
void cost_study(const RunContext& run, const Settings& settings);

}  // namespace fem::corot::study
