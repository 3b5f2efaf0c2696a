// Chapter 14: the checks of the issue on a one-cube block — at rest its contact forces carry its
// weight, on a slope it sticks or slides as Coulomb says, dropped it lands at √(2gh) and never
// rebounds higher, fired at the floor or a sphere at 100 times a drop's speed it never gets inside.
// docs/14_contact.md#checks
#include "14_contact/contact.hpp"
#include "14_contact/contact_scenes.hpp"
#include "14_contact/obstacles.hpp"
#include "fire_at.hpp"
#include "one_thread.hpp"
#include "rest_weight.hpp"
#include "slope_creep.hpp"

#include "12_hyperelastic_newton/newton.hpp"

#include "04_tet_jacobians/tet_jacobians.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

using namespace fem;
using namespace fem::contact;
using fem::test::degree;


TEST_CASE("a cube at rest on the floor: its contact forces sum to its weight at equilibrium, none below",
          "[ex14.2]")
{
    BlockSettings settings;
    settings.height = 0.5 * settings.contact.activation_distance;
    settings.time_step = 0.05;  // backward Euler's damping brings the block to rest in a few steps
    settings.newton.relative_tolerance = 1e-10;
    BlockScene block = block_scene(settings);
    for (int step = 0; step < 40; ++step) {
        block.step();
        REQUIRE(lowest_height(*block.body, block.state.u) > 0.0);
    }
    const test::RestWeight rest = test::rest_weight(block, settings);
    const Eigen::Vector3d& total = rest.barrier;  // no friction: the barrier's forces are all of them
    const double weight = rest.weight, bound = rest.bound;
    INFO("sum of contact forces " << total.transpose() << " N, weight " << weight << " N, bound " << bound << " N");
    CHECK(std::abs(total.z() - weight) <= bound);
    CHECK(bound <= 1e-6 * weight);  // equilibrium: the momentum no longer changes
    CHECK(std::abs(total.x()) + std::abs(total.y()) <= 1e-9 * weight);
    CHECK(lowest_height(*block.body, block.state.u) > 0.0);
    CHECK(lowest_height(*block.body, block.state.u) < settings.contact.activation_distance);
}

TEST_CASE("a cube on a slope with tan(theta) < mu sticks: it creeps at most eps_v dt a step, as the mollifier says",
          "[ex14.4]")
{
    for (int updates : {1, 3, 0}) {  // IPC's one lagged update a step, the lag updated within it, and to convergence
    BlockSettings settings;
    settings.slope = 20.0 * degree;
    settings.friction = 0.5;
    settings.height = 0.5 * settings.contact.activation_distance;
    settings.friction_updates = updates;
    const double epsilon = settings.contact.friction_velocity * settings.time_step;
    const test::SlopeCreep creep = test::slope_creep(settings, 40);
    const double expected = test::expected_creep(settings);
    INFO(updates << " updates: creep per step " << creep.last << " m, expected " << expected << " m, eps_v dt = "
                 << epsilon << " m");
    CHECK(creep.largest <= epsilon);
    CHECK(std::abs(creep.last - expected) <= 0.01 * expected);
    }
}

TEST_CASE("friction lagged to convergence: one more update of the converged lag moves no vertex beyond its tolerance",
          "[ex14.4]")
{
    BlockSettings settings;
    settings.slope = 25.0 * degree;  // tan 25° = 0.466 against μ = 0.5: near the stick-slip threshold
    settings.friction = 0.5;
    settings.height = 0.5 * settings.contact.activation_distance;
    settings.friction_updates = 0;
    BlockScene block = block_scene(settings);
    const double tolerance = friction_lag_tolerance * settings.contact.friction_velocity * settings.time_step;
    int most = 0;
    for (int step = 0; step < 20; ++step) {
        const dynamics::State start = block.state;
        int solves = 0;
        block.step(&solves);
        most = std::max(most, solves);
        // The definition, checked from outside: solve the step again with λ, T lagged at its answer.
        block.contact->lag_friction_at(block.state.u);
        dynamics::State again = start;
        block.integrator->step(*block.body, settings.time_step, again);
        CHECK((again.u - block.state.u).lpNorm<Eigen::Infinity>() <= tolerance);
    }
    CHECK(most >= 2);  // the lag did need updating in some step
    settings.friction_updates = -1;
    CHECK_THROWS_WITH(block_scene(settings).step(), Catch::Contains(">= 0"));
}

TEST_CASE("a cube on a slope with tan(theta) > mu slides with acceleration g (sin theta - mu cos theta)", "[ex14.4]")
{
    BlockSettings settings;
    settings.slope = 30.0 * degree;
    settings.friction = 0.3;
    settings.height = 0.5 * settings.contact.activation_distance;
    BlockScene block = block_scene(settings);
    double speed_then = 0.0, time_then = 0.0;
    for (int step = 0; step < 40; ++step) {
        block.step();
        REQUIRE(lowest_height(*block.body, block.state.u) > 0.0);
        if (step + 1 == 20) {
            speed_then = mean_velocity(*block.body, block.state.v).x();
            time_then = block.state.time;
        }
    }
    const double acceleration =
        (mean_velocity(*block.body, block.state.v).x() - speed_then) / (block.state.time - time_then);
    const double expected = slope_acceleration(settings.gravity, settings.slope, settings.friction);
    // Sliding faster than eps_v, the mollifier is 1: full Coulomb. What is left is the lag of the
    // normal force (from the step's start) while the block's contact settles: 1 % of g.
    INFO("acceleration " << acceleration << ", closed form " << expected);
    CHECK(std::abs(acceleration - expected) <= 1e-2 * settings.gravity);
    CHECK(slope_acceleration(settings.gravity, 20.0 * degree, 0.5) == 0.0);
}

TEST_CASE("a cube dropped from h lands at sqrt(2gh) within backward Euler's lag and never rebounds above h",
          "[ex14.2]")
{
    BlockSettings settings;
    const double h = 0.05, dt = settings.time_step, g = settings.gravity;
    settings.height = h;
    BlockScene block = block_scene(settings);
    double fastest = 0.0, rebound = 0.0;
    bool bounced = false;
    for (int step = 0; step < 40; ++step) {
        block.step();
        const double falling = -mean_velocity(*block.body, block.state.v).z();
        fastest = std::max(fastest, falling);
        bounced = bounced || falling < 0.0;
        const double low = lowest_height(*block.body, block.state.u);
        REQUIRE(low > 0.0);
        if (bounced)
            rebound = std::max(rebound, low);
    }
    // Backward Euler's free fall: v_n = g t_n exactly, the fall H_n = v_n²/(2g) + Δt v_n/2 ≥ v_n²/(2g),
    // so v ≤ √(2gh); at the step the barrier acts the fall is ≥ h − d̂: v ≥ √(2g(h − d̂)) − Δt g/2,
    // and the fastest step is at most one step before it: v_max ≥ √(2g(h − d̂)) − 3 g Δt / 2.
    const double dhat = settings.contact.activation_distance;
    INFO("fastest " << fastest << " m/s, sqrt(2gh) = " << drop_speed(g, h) << " m/s, rebound " << rebound << " m");
    CHECK(fastest <= drop_speed(g, h) * (1.0 + 1e-9));
    CHECK(fastest >= drop_speed(g, h - dhat) - 1.5 * g * dt);
    CHECK(bounced);
    CHECK(rebound <= h);
}


TEST_CASE("fired at the floor at 100 times a drop's speed, no vertex ever gets inside", "[ex14.2]")
{
    test::fire_at(std::make_shared<HalfSpace>(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()));
}

TEST_CASE("fired at a ball at 100 times a drop's speed, no vertex gets inside or jumps across", "[ex14.3]")
{
    // Under the block's four lower corners; one unchecked step would carry them 1 m past it.
    test::fire_at(std::make_shared<Sphere>(Eigen::Vector3d(0.05, 0.05, 0.0), 0.08));
}

TEST_CASE("a conveyor floor (moving along x) drags a resting block up to its speed by friction", "[ex14.4]")
{
    BlockSettings settings;
    settings.height = 1e-4;
    const double belt = 0.1, mu = 0.5;
    settings.obstacles = {std::make_shared<HalfSpace>(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), mu,
                                                     Eigen::Vector3d(belt, 0.0, 0.0))};
    BlockScene block = block_scene(settings);
    // Coulomb: it slides with a = μ g until it moves with the belt, after t = w/(μ g) ≈ 0.02 s.
    for (int step = 0; step < 30; ++step) {
        block.step();
        REQUIRE(lowest_height(*block.body, block.state.u) > 0.0);
    }
    const double speed = mean_velocity(*block.body, block.state.v).x();
    INFO("block speed " << speed << " m/s, belt " << belt << " m/s");
    // Sticking to the belt it lags by less than ε_v (the mollifier's threshold).
    CHECK(std::abs(speed - belt) <= settings.contact.friction_velocity);
}

TEST_CASE("a rising floor lifts the block at its speed, however fast, and the energy books balance", "[ex14.2]")
{
    // Resting 0.1 mm above the floor: from 1 cm/s on, the floor rises more than the gap in one step
    // of 1/100 s, where staying put would reach into it; the step starts carried along instead.
    const double rise = GENERATE(2e-3, 1e-2, 1e-1, 1.0);  // [m/s]
    BlockSettings settings;
    settings.height = 1e-4;
    settings.obstacles = {std::make_shared<HalfSpace>(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.0,
                                                     Eigen::Vector3d(0.0, 0.0, rise))};
    BlockScene block = block_scene(settings);
    // Chapter 10's books: H = K + U + gravity's potential, W_in the work put in (the barrier's store
    // and the floor's push, contact_step's boundary work). Backward Euler only dissipates.
    const double start_energy = dynamics::energies(*block.body, block.state).total();
    double work_in = 0.0, largest = std::abs(start_energy);
    for (int step = 0; step < 50; ++step) {
        work_in += block.step().boundary_work;
        INFO("floor at " << rise << " m/s, step " << step + 1);
        REQUIRE(block.contact->smallest_distance(block.state.u) > 0.0);
        REQUIRE(lowest_height(*block.body, block.state.u) > rise * block.state.time);
        const double energy = dynamics::energies(*block.body, block.state).total();
        largest = std::max(largest, std::abs(energy));
        INFO("H - W_in rose by " << energy - work_in - start_energy << " J (H " << energy << " J, W_in " << work_in
                                 << " J)");
        REQUIRE(energy - work_in - start_energy <= 1e-6 * largest);
    }
    const double speed = mean_velocity(*block.body, block.state.v).z();
    INFO("block speed " << speed << " m/s, floor " << rise << " m/s");
    CHECK(std::abs(speed - rise) <= 1e-2 * rise);
    // Without the floor's push Δt Σ F·w the books would show the lift as a gain of H from nowhere.
    CHECK(work_in > 0.5 * (block.body->dof_masses().sum() / 3.0) * rise * rise);
}

TEST_CASE("two plates squeezing a block stop the run with a clear error before any tet turns inside out", "[ex14.2][slow]")
{
    BlockSettings settings;
    settings.height = 1e-4;
    settings.gravity = 0.0;
    settings.model = GENERATE(as<std::string>{}, "corotational", "stable-neo-hookean");
    const double closing = GENERATE(0.01, 0.5);  // [m/s] each: 0.1 mm and 5 mm a step, a gap of 0.1 mm: in stages
    settings.obstacles = {std::make_shared<HalfSpace>(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.0,
                                     Eigen::Vector3d(0.0, 0.0, closing)),
         std::make_shared<HalfSpace>(Eigen::Vector3d(0.0, 0.0, settings.edge + 2.0 * settings.height),
                                     -Eigen::Vector3d::UnitZ(), 0.0, Eigen::Vector3d(0.0, 0.0, -closing))};
    BlockScene block = block_scene(settings);
    std::string error;
    int steps = 0;
    for (; steps < 600 && error.empty(); ++steps) {
        try {
            block.step();
        } catch (const Error& e) {
            error = e.what();
        }
        // Whatever happened, the state is a valid one: every tet keeps a positive volume.
        const MatrixX3d x = block.body->positions(block.state.u);
        for (int t = 0; t < static_cast<int>(block.body->mesh().T.rows()); ++t) {
            INFO(settings.model << ", step " << steps + 1 << ", tet " << t);
            REQUIRE(tet::signed_volume(tet::tet_vertices(block.body->mesh(), x, t)) > 0.0);
        }
    }
    INFO(settings.model << ": " << steps << " steps, error: " << error);
    REQUIRE(!error.empty());
    CHECK((error.find("leave the body no room") != std::string::npos ||
           error.find("inside out") != std::string::npos));
    // The slow plates close by twice the gap a step: without the step's stages the run stopped at
    // step 1; in stages they squeeze the block for seconds first.
    if (closing < 0.1)
        CHECK(steps > 100);
}

TEST_CASE("a block dropped on a turned box comes to rest on its top face, never inside", "[ex14.1]")
{
    BlockSettings settings;
    settings.height = 0.01;
    // A slab under the block, turned 0.3 rad about z: its top face is z = 0, its time of impact the
    // slab test's.
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    settings.obstacles = {std::make_shared<Box>(Eigen::Vector3d(0.05, 0.05, -0.05), Eigen::Vector3d(0.2, 0.2, 0.05), turn)};
    BlockScene block = block_scene(settings);
    const ContactPotential& contact = *block.contact;
    for (int step = 0; step < 60; ++step) {
        block.step();
        REQUIRE(contact.smallest_distance(block.state.u) > 0.0);
    }
    INFO("lowest vertex " << lowest_height(*block.body, block.state.u) << " m");
    CHECK(lowest_height(*block.body, block.state.u) > 0.0);
    CHECK(lowest_height(*block.body, block.state.u) < settings.contact.activation_distance);
    CHECK(mean_velocity(*block.body, block.state.v).norm() < 1e-3);
}
