#pragma once
// What each model costs and gets wrong on a scene: every fixed model and auto against a converged
// reference. docs/scenes.md#what-each-model-costs

#include "scenes/runner.hpp"

#include "common/cli.hpp"

#include <string>
#include <vector>

namespace fem::scenes {

/// The reference of the comparison: stable neo-Hookean under backward Euler, extrapolated
/// (Richardson) from Δt/(reference_refinement/2) and Δt/reference_refinement: 2 x(Δt/8) − x(Δt/4),
/// second order in the step where each run is first order.
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
    double reference_time_step = 0.0;  ///< the finest step, Δt / reference_refinement [s]
    /// How far the reference moves when its steps are doubled (the same extrapolation from Δt/2 and
    /// Δt/4): the largest vertex distance over all frames [m], an upper estimate of the reference's
    /// own error (about 3 times it, for a second-order extrapolation). It must be below the errors
    /// the comparison reports.
    double reference_change = 0.0;
    /// log2 of how much the runs at Δt/2, Δt/4, Δt/8 move apart: |x(Δt/2) − x(Δt/4)| / |x(Δt/4) −
    /// x(Δt/8)| ≈ 2, order ≈ 1, when backward Euler is in its asymptotic range (the extrapolation
    /// assumes it).
    double observed_order = 0.0;
    std::vector<ModelError> rows;      ///< "stable-neo-hookean", "linear", "corotational", "stvk", "neo-hookean", "auto"
};

/// Runs each model (stable neo-Hookean, linear, corotational, StVK, neo-Hookean) and auto at the
/// scene's Δt, and the reference (stable neo-Hookean at Δt/2, Δt/4 and Δt/8, extrapolated), and compares the positions frame by frame: RMS and max error
/// of the tet vertices and of the boundary vertices, time per step and total. With run set, prints
/// the table and writes <out>/models_<scene>.csv. fem::Error when the reference run fails. A stop
/// signal (common/interrupt.hpp) ends it after the current run, with the rows so far.
/// docs/scenes.md#what-each-model-costs
ModelComparison compare_models(const SceneSpec& scene, const RunContext* run);

}  // namespace fem::scenes
