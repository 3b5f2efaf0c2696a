#pragma once
// What each model costs and gets wrong on a scene: every fixed model and auto against a converged
// reference. docs/scenes.md#what-each-model-costs

#include "scenes/runner.hpp"

#include "common/cli.hpp"

#include <string>
#include <vector>

namespace fem::scenes {

/// The reference of the comparison: stable neo-Hookean under backward Euler at Δt/reference_refinement.
/// Backward Euler's damping keeps coarser steps out of its first-order range on the gallery's swings
/// (the cantilever's load potential at 0.5 s moves by 2.8, 1.6 and 0.83 mJ from Δt/2 to Δt/4, Δt/8
/// and Δt/16: halving only from Δt/8 on), so Richardson extrapolation from Δt/4 and Δt/8 would not
/// hold; the reference is the plain finer run, and its own halving is reported beside it.
inline constexpr int reference_refinement = 16;

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
    double reference_time_step = 0.0;  ///< the finest step, Δt / reference_refinement [s]
    /// How far the reference moves when its Δt doubles (the run at 2 Δt_ref against it): the largest
    /// vertex distance over all frames [m]; backward Euler being first order, about the reference's
    /// own error. It must be below the errors the comparison reports.
    double reference_change = 0.0;
    /// "stable-neo-hookean", "linear", "corotational", every other material chapter 12's registry
    /// compares (material_descriptions(): "stvk", "neo-hookean"), "auto"
    std::vector<ModelError> rows;
};

/// Runs each model (stable neo-Hookean, linear, corotational, the other compared materials of
/// chapter 12's registry: StVK, neo-Hookean) and auto at the scene's Δt, and the reference (stable
/// neo-Hookean at Δt/reference_refinement, and at twice that step to measure its convergence), and compares the positions frame by frame: RMS and max error
/// of the tet vertices and of the boundary vertices, time per step and total. With run set, prints
/// the table and writes <out>/models_<scene>.csv. fem::Error when the reference run fails. A stop
/// signal (common/interrupt.hpp) ends it after the current run, with the rows so far.
/// docs/scenes.md#what-each-model-costs
ModelComparison compare_models(const SceneSpec& scene, const RunContext* run);

}  // namespace fem::scenes
