#pragma once
// What each model costs and gets wrong on a scene: every fixed model and auto against a converged
// reference. docs/scenes.md#what-each-model-costs

#include "scenes/runner.hpp"

#include "common/cli.hpp"

#include <string>
#include <vector>

namespace fem::scenes {

/// The reference of the comparison: the stable neo-Hookean model at Δt / reference_refinement.
inline constexpr int reference_refinement = 8;

/// One model's row of the comparison.
struct ModelError {
    std::string model;
    bool failed = false;        ///< the run failed (its error printed); the numbers below are 0
    double tet_rms = 0.0, tet_max = 0.0;          ///< position error of the tet vertices over all frames [m]
    double surface_rms = 0.0, surface_max = 0.0;  ///< the same on the boundary vertices [m]
    double relative_max = 0.0;  ///< tet_max / the reference's largest displacement
    int newton_iterations = 0;
    double seconds_per_step = 0.0, seconds = 0.0;
    std::string models_used;    ///< e.g. "linear 0-3, stable-neo-hookean 4-120"
};

/// The comparison of one scene.
struct ModelComparison {
    double reference_time_step = 0.0;  ///< Δt / reference_refinement [s]
    /// How far the reference moves when its own Δt is doubled (the run at 2 Δt_ref against it):
    /// the largest vertex distance over all frames [m]; backward Euler being first order, the
    /// reference's own error is about this much too. It must be below the errors it measures.
    double reference_change = 0.0;
    std::vector<ModelError> rows;      ///< "stable-neo-hookean", "linear", "corotational", "stvk", "neo-hookean", "auto"
};

/// Runs each model (stable neo-Hookean, linear, corotational, StVK, neo-Hookean) and auto at the
/// scene's Δt, and the reference (stable neo-Hookean at Δt/reference_refinement, and at twice that
/// step to measure its convergence), and compares the positions frame by frame: RMS and max error
/// of the tet vertices and of the boundary vertices, time per step and total. With run set, prints
/// the table and writes <out>/models_<scene>.csv. fem::Error when the reference run fails. A stop
/// signal (common/interrupt.hpp) ends it after the current run, with the rows so far.
/// docs/scenes.md#what-each-model-costs
ModelComparison compare_models(const SceneSpec& scene, const RunContext* run);

}  // namespace fem::scenes
