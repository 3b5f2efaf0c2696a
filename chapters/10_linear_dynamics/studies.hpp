#pragma once
// The studies of ch10_linear_dynamics, one file each (study_*.cpp), called in order by main.cpp.
// Not part of the chapter's library: only the executable uses them.

#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include "common/cli.hpp"
#include "common/vtk_io.hpp"

#include <vector>

namespace fem::dynamics::study {

/// The executable's options (main.cpp validates them before any study runs).
struct Settings {
    Material beam{2e6, 0.45, 1100.0};        ///< SOFA's validation cantilever
    Material bunny{1e5, 0.45, 1000.0};       ///< a soft rubber bunny
    double duration = 1.0;                   ///< accuracy horizon and demo length [s]
    int accuracy_cells = 20;                 ///< cells along the beam of the accuracy study
    std::vector<int> cost_cells{20, 40, 60, 100};  ///< cells along the beams of the cost study
    double seconds = 0.2;                    ///< measuring time per timed kernel [s]
};

void modes_study(const RunContext& run, const Settings& settings);
void recurrence_study(const RunContext& run, const Settings& settings);
void accuracy_study(const RunContext& run, const Settings& settings);
void statics_study(const RunContext& run, const Settings& settings);
void hard_cases_study(const RunContext& run, const Settings& settings);
void cost_study(const RunContext& run, const Settings& settings);
void demo_scenes(const RunContext& run, const Settings& settings);

}  // namespace fem::dynamics::study
