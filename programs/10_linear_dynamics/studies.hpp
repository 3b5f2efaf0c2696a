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

/// The most steps symplectic Euler may take in the accuracy study: 8 runs' worth of its explicit
/// limit for a beam stiffened far beyond rubber (ν → 0.5, a huge Y) would run for hours.
constexpr long long max_explicit_steps = 2'000'000;

/// The fewest steps symplectic Euler needs over settings.duration on the accuracy study's beam
/// (Δt = 0.9 · 2/ω_max); the study runs 1, 2, 4 and 8 times as many. fem::Error naming --youngs,
/// --poisson and --density, with the count, when 8 times as many exceed max_explicit_steps.
long long explicit_steps(const Settings& settings);
void statics_study(const RunContext& run, const Settings& settings);
void hard_cases_study(const RunContext& run, const Settings& settings);
void cost_study(const RunContext& run, const Settings& settings);
void demo_scenes(const RunContext& run, const Settings& settings);

}  // namespace fem::dynamics::study
