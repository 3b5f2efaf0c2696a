// Chapter 14: a contact scene on chapter 10's time loop (ContactStep) — the same steps as the
// scene's own, and books that close: with a fixed κ backward Euler never adds energy to the body and
// its barrier, so the loop's integrator_dissipated never falls once the barrier's work is booked
// (and does fall, at the rebound, on the body's energy alone). The creep's closed form.
// docs/14_contact.md#results
#include "14_contact/contact_scenes.hpp"

#include "10_linear_dynamics/time_integration.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

using namespace fem;
using namespace fem::contact;

TEST_CASE("a drop on chapter 10's time loop: the scene's own steps, and books that close with the barrier's work",
          "[ex14.2]")
{
    BlockSettings settings;
    settings.height = 0.02;
    settings.time_step = 1.0 / 400.0;
    settings.contact.stiffness = 1e4;  // fixed: one incremental potential for every step
    settings.newton.relative_tolerance = 1e-10;
    const int steps = 80;  // 0.2 s: the fall (64 ms), the impact and the rebound

    BlockScene own = block_scene(settings);
    for (int step = 0; step < steps; ++step)
        own.step();

    BlockScene looped = block_scene(settings);
    dynamics::Simulation simulation(*looped.body, *looped.stepper, looped.state);
    std::vector<double> dissipated, body_only;  // the loop's books, and H(0) − H(t) without the barrier's work
    double largest = 0.0, start = 0.0;
    simulation.run(steps, [&](const dynamics::State&, const dynamics::StepRecord& record) {
        if (record.step == 0)
            start = record.energies.total();
        dissipated.push_back(record.integrator_dissipated);
        body_only.push_back(start - record.energies.total());
        largest = std::max(largest, record.energies.magnitude());
    });
    // The same step function: the same states, bit for bit.
    CHECK((simulation.state().u - own.state.u).lpNorm<Eigen::Infinity>() == 0.0);
    CHECK(looped.contact->smallest_distance(simulation.state().u) > 0.0);

    // E(body) + B never rises under backward Euler with one fixed potential (each step minimises
    // the incremental potential, which the step's start also satisfies), up to Newton's tolerance.
    double worst_books = 0.0, worst_body = 0.0;
    for (std::size_t k = 1; k < dissipated.size(); ++k) {
        worst_books = std::min(worst_books, dissipated[k] - dissipated[k - 1]);
        worst_body = std::min(worst_body, body_only[k] - body_only[k - 1]);
    }
    INFO("largest energy " << largest << " J, worst fall of the books " << worst_books << " J, of H alone "
                           << worst_body << " J");
    CHECK(worst_books >= -1e-9 * largest);
    // Without the barrier's work the rebound looks like energy made: the booking is what closes the books.
    CHECK(worst_body < -1e-4 * largest);
}

TEST_CASE("sticking_creep: the root below eps of the mollifier's f1(y) = tan(theta)/mu, refused when it slides")
{
    constexpr double degree = std::numbers::pi / 180.0;
    for (const auto& [angle, friction] : std::vector<std::pair<double, double>>{{20.0, 0.5}, {5.0, 0.9}, {30.0, 0.6}}) {
        const double y = sticking_creep(angle * degree, friction);  // in units of ε
        INFO(angle << " deg, mu " << friction << ": y = " << y);
        CHECK(y > 0.0);
        CHECK(y < 1.0);
        CHECK(2.0 * y - y * y == Approx(std::tan(angle * degree) / friction).epsilon(1e-12));
    }
    CHECK_THROWS_AS(sticking_creep(30.0 * degree, 0.3), Error);
    CHECK_THROWS_AS(sticking_creep(50.0 * degree, 1.0), Error);
}
