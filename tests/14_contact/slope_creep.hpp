#pragma once
// Chapter 14's tests: the creep of a block that sticks to a slope (tan θ < μ), step by step.
// docs/14_contact.md#checks

#include "14_contact/contact_scenes.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace fem::test {

/// One degree in radians: the slopes' angles are given in degrees (17.0 * degree).
inline constexpr double degree = std::numbers::pi / 180.0;

/// What a sticking block's creep came to: the last step's move along the slope [m] and the largest
/// |move| of a step once the lagged normal force has settled (from step 5 on) [m].
struct SlopeCreep {
    double last = 0.0, largest = 0.0;
};

/// `steps` steps of the block of settings (its slope and friction set), every one leaving it above
/// the floor (REQUIRE); each step's move is its mean velocity along x (the slope's direction) × Δt.
inline SlopeCreep slope_creep(const contact::BlockSettings& settings, int steps)
{
    contact::BlockScene block = contact::block_scene(settings);
    SlopeCreep creep;
    for (int step = 0; step < steps; ++step) {
        block.step();
        REQUIRE(contact::lowest_height(*block.body, block.state.u) > 0.0);
        creep.last = contact::mean_velocity(*block.body, block.state.v).x() * settings.time_step;
        if (step >= 5)  // the lagged normal force settles from the start's gap to the weight's share
            creep.largest = std::max(creep.largest, std::abs(creep.last));
    }
    return creep;
}

/// The steady creep a step: the friction μλ f₁(y) holds the tangential load, f₁(y) = tan θ/μ, so
/// y = ε (1 − √(1 − tan θ/μ)) with ε = ε_v Δt (the root of 2y/ε − y²/ε² = tan θ/μ below ε) [m].
inline double expected_creep(const contact::BlockSettings& settings)
{
    const double epsilon = settings.contact.friction_velocity * settings.time_step;
    return epsilon * (1.0 - std::sqrt(1.0 - std::tan(settings.slope) / settings.friction));
}

}  // namespace fem::test
