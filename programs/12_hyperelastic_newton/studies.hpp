#pragma once
// The studies of ch12_hyperelastic_newton, one file each (study_*.cpp), called in order by main.cpp.
// Not part of the chapter's library: only the executable uses them.

#include "12_hyperelastic_newton/force_models.hpp"
#include "12_hyperelastic_newton/hyperelastic.hpp"
#include "12_hyperelastic_newton/newton.hpp"

#include "10_linear_dynamics/body.hpp"

#include "common/cli.hpp"
#include "common/vtk_io.hpp"

#include <memory>
#include <string>
#include <vector>

namespace fem::hyper::study {

/// The executable's options (main.cpp checks them before any study runs).
struct Settings {
    dynamics::Material soft{2e5, 0.45, 1100.0};    ///< the swinging beam (chapter 11's)
    double duration = 1.5;                         ///< length of the swing [s]
    int swing_cells = 20;                          ///< cells along the swinging beam
    std::vector<int> cost_cells{20, 40, 100};      ///< cells along the beams of the cost study
    double seconds = 0.2;                          ///< measuring time per timed kernel [s]
};

/// A force model's name (force_model_names()) as the figures' legends write it: a material's
/// in_words (material_descriptions(), e.g. "stable-neo-hookean" -> "stable neo-Hookean (course)");
/// any other name ("linear", "corotational") as it is.
std::string model_in_words(const std::string& name);

void materials_study(const RunContext& run, const Settings& settings);
void newton_study(const RunContext& run, const Settings& settings);
void swing_study(const RunContext& run, const Settings& settings);
void cost_study(const RunContext& run, const Settings& settings);

}  // namespace fem::hyper::study
