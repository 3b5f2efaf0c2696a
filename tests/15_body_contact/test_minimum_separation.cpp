// Chapter 15: the minimum separation of the line search's collision check (issue 48, item 1). A
// projected Newton system is positive definite by construction; it failed chapter 08's pivot test
// ("sparse Cholesky: the matrix is not symmetric positive definite …") because a step's start or
// trial ended a pair of primitives 1.7·10⁻¹⁸ m apart without touching — a block's free flight that
// lands exactly on a plate — so no CCD cut it, and the barrier's Hessian there (~10³²) swamped every
// vertex's mass in double precision. line_search_time_of_impact now also cuts a step where a pair
// would end nearer than a tenth of min(its distance, d̂). docs/15_body_contact.md#the-minimum-separation
#include "15_body_contact/body_contact.hpp"
#include "15_body_contact/pair_barrier.hpp"

#include "contact_bodies.hpp"
#include "../14_contact/one_thread.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>

using namespace fem;
using namespace fem::contact;

namespace {

/// A plate edge on the plate's top face z = 0, from (−2.5, −5, 0) cm to (0, −2.5, 0) cm, and a block
/// edge along x at y = −2.5 cm moving from z = 2 mm down to z = end_height: the plate edge's end
/// (0, −2.5, 0) lies under the block edge's middle, so their distance is the block edge's height.
PrimitiveMotion landing_edges(double end_height)
{
    PrimitiveMotion motion;
    motion.start << -0.025, 0.0, -0.025, 0.025,  //
        -0.05, -0.025, -0.025, -0.025,           //
        0.0, 0.0, 0.002, 0.002;
    motion.end = motion.start;
    motion.end(2, 2) = motion.end(2, 3) = end_height;
    return motion;
}

/// The first error of `steps` contact steps of the block over the plate (test::block_over_plate) at
/// Δt = time_step, stable neo-Hookean rubber (test::free_scene), self-contact between them with the
/// intersection referee on; empty when none. nearest: the smallest pair distance after each step.
std::string land_block(double speed, double time_step, double thickness, double turn, int steps, double& nearest)
{
    const test::ThrownBodies thrown = test::block_over_plate(speed, thickness, turn);
    dynamics::Scene scene = test::free_scene(thrown.mesh);
    scene.time_step = time_step;
    BodyContactOptions options;
    options.self_contact = true;
    options.check_intersections = true;
    test::ContactRun run(scene, options, {}, {}, thrown.velocity, 1e-6);
    nearest = std::numeric_limits<double>::infinity();
    for (int k = 0; k < steps; ++k) {
        try {
            run.step();
        } catch (const Error& e) {
            return str("step ", k + 1, ": ", e.what());
        }
        nearest = std::min(nearest, run.contact->smallest_distance(run.state.u));
    }
    return {};
}

}  // namespace

TEST_CASE("the line search's collision check keeps a minimum separation: a motion that ends a hair from "
          "touching is cut where the distance is still a tenth of min(its start, d-hat)", "[ex15.5]")
{
    // Ending 10⁻¹⁷ m apart: no contact on [0, 1], so the check of touching alone lets the whole step.
    const PrimitiveMotion hair = landing_edges(1e-17);
    CHECK(line_search_time_of_impact(PrimitivePair::edge_edge, hair) == std::numeric_limits<double>::infinity());
    for (const double d_hat : {1e-3, 1e-2}) {
        const double s = line_search_time_of_impact(PrimitivePair::edge_edge, hair, d_hat);
        // The distance at s is the block edge's height, 2 mm (1 − s) + 10⁻¹⁷ s (closed form).
        const double distance = 0.002 * (1.0 - s) + 1e-17 * s;
        CAPTURE(d_hat, s, distance);
        CHECK(s > 0.0);
        CHECK(s < 1.0);
        CHECK(distance >= 0.1 * std::min(0.002, d_hat));
        CHECK(distance <= 0.002);
    }
    // Ending 1.5 mm apart (beyond a tenth of d̂ = 1 mm): the step is not cut.
    CHECK(line_search_time_of_impact(PrimitivePair::edge_edge, landing_edges(0.0015), 1e-3) ==
          std::numeric_limits<double>::infinity());
    // Through the pair's own plane (a crossing): the time of touching still decides, below 1.
    const double crossing = line_search_time_of_impact(PrimitivePair::edge_edge, landing_edges(-0.002), 1e-3);
    CHECK(crossing < 0.5);
}

TEST_CASE("a block landing flat or on its edge on a free plate one tet thick at 2 m/s (dt 1/1000 s: its free "
          "flight ends on the plate) runs, Newton's system never failing to factor", "[ex15.5][slow]")
{
    // The four cases of issue 48: before the minimum separation the flat block stopped in chapter 08's
    // words ("sparse Cholesky: … pivot …") on both plates, the block on its edge with "the line search
    // found no decrease" on the 2 mm plate and "the largest safe step along d is α = 7e-11" on the 1 cm one.
    for (const double thickness : {0.002, 0.01})
        for (const double turn : {0.0, std::atan(1.0)}) {
            double nearest = 0.0;
            const std::string error = land_block(2.0, 1e-3, thickness, turn, 4, nearest);
            CAPTURE(thickness, turn, error, nearest);
            CHECK(error.empty());
            CHECK(nearest > 0.0);
        }
}

TEST_CASE("a block landing flat or on its edge on a free plate one tet thick at 2, 5 and 10 m/s, dt 1/1000 and "
          "1/4000 s, plates 2 mm and 1 cm: 30 steps each run", "[ex15.5][slow]")
{
    for (const double speed : {2.0, 5.0, 10.0})
        for (const double time_step : {1e-3, 2.5e-4})
            for (const double thickness : {0.002, 0.01})
                for (const double turn : {0.0, std::atan(1.0)}) {
                    double nearest = 0.0;
                    const std::string error = land_block(speed, time_step, thickness, turn, 30, nearest);
                    CAPTURE(speed, time_step, thickness, turn, error, nearest);
                    CHECK(error.empty());
                    CHECK(nearest > 0.0);
                }
}
