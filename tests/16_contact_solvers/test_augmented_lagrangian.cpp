// Chapter 16's tests of the augmented Lagrangian contact solver on scenes: its derivatives against
// central differences, no configuration Newton evaluates ever inside (chapter 15's referee on, the
// smallest distance after every step), a block at rest and the stack against their weights, momentum
// of two bodies kept to round-off, the fired block, and bad input refused.
// docs/16_contact_solvers.md#what-is-guaranteed

#include "16_contact_solvers/augmented_lagrangian.hpp"
#include "16_contact_solvers/solver_runs.hpp"

#include "../14_contact/one_thread.hpp"

#include "12_hyperelastic_newton/force_models.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"
#include "common/random.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <memory>
#include <vector>

using namespace fem;
using namespace fem::contact;

namespace {

/// The total contact force on the vertices of which (3) [N] (forces: 3n).
template <class Which>
Eigen::Vector3d force_on(const Eigen::VectorXd& forces, Which which)
{
    Eigen::Vector3d total = Eigen::Vector3d::Zero();
    for (Eigen::Index v = 0; v < forces.size() / 3; ++v)
        if (which(static_cast<int>(v)))
            total += forces.segment<3>(3 * v);
    return total;
}

/// Σ m Δv / Δt over the vertices of which (3) [N]: what the forces on them beyond the weight must equal.
template <class Which>
Eigen::Vector3d momentum_change(const dynamics::Body& body, const dynamics::State& before, const dynamics::State& after,
                                Which which)
{
    Eigen::Vector3d total = Eigen::Vector3d::Zero();
    const Eigen::VectorXd& m = body.dof_masses();
    for (Eigen::Index v = 0; v < m.size() / 3; ++v)
        if (which(static_cast<int>(v)))
            total += m[3 * v] * (after.v - before.v).segment<3>(3 * v);
    return total / body.scene().time_step;
}

}  // namespace

TEST_CASE("augmented Lagrangian potential: gradient and Hessian against central differences, every kind of pair",
          "[ex16.2]")
{
    // Two cubes, the upper one turned about z and shifted (point–triangle and edge–edge pairs between
    // them), the lower one 0.5 δ above the floor (vertex–obstacle pairs) or above the turned box's
    // highest corner (an obstacle's corner against a triangle, its edges against the cube's edges).
    const double delta = 1e-3;
    const bool with_box = GENERATE(false, true);
    TetMesh lower = box_mesh(1, 1, 1, Eigen::Vector3d::Constant(0.1));
    lower.V.col(2).array() += 0.5 * delta;
    TetMesh upper = box_mesh(1, 1, 1, Eigen::Vector3d::Constant(0.06));
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    upper.V = (upper.V * turn.transpose()).eval();
    upper.V.rowwise() += Eigen::RowVector3d(0.03, 0.01, 0.1 + 1.5 * delta);
    dynamics::Scene scene;
    scene.mesh.V.resize(16, 3);
    scene.mesh.V << lower.V, upper.V;
    scene.mesh.T.resize(12, 4);
    scene.mesh.T << lower.T, (upper.T.array() + 8).matrix();
    scene.material = {1e6, 0.3, 1000.0};
    scene.time_step = 1.0 / 100.0;
    dynamics::Body body(scene, hyper::make_force_model("stable-neo-hookean", scene.mesh, scene.material));
    AugmentedLagrangianOptions options;
    options.self_contact = true;
    options.vertex_body = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1};
    const std::shared_ptr<const Obstacle> obstacle =
        with_box ? turned_box() : std::make_shared<HalfSpace>(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
    AugmentedLagrangianContact al(body, {obstacle}, options);
    dynamics::State state = dynamics::initial_state(body);
    al.begin_step(body, state, scene.time_step);
    // The lower cube pushed 0.3 δ down (0.2 δ above the floor), the upper one 1.1 δ (0.7 δ above the
    // lower): every pair within δ violated, so the update gives it λ > 0.
    Eigen::VectorXd pushed = Eigen::VectorXd::Zero(48);
    for (int v = 0; v < 16; ++v)
        pushed[3 * v + 2] = v < 8 ? -0.3 * delta : -1.1 * delta;
    al.update_multipliers(pushed, Eigen::VectorXd::Zero(48));
    int kinds[3] = {0, 0, 0}, pushing = 0;
    for (const ContactConstraint& c : al.constraints()) {
        ++kinds[static_cast<int>(c.kind)];
        pushing += c.multiplier > 0.0 ? 1 : 0;
    }
    INFO((with_box ? "turned box" : "floor") << ": " << kinds[0] << " vertex-obstacle, " << kinds[1]
                                             << " point-triangle, " << kinds[2] << " edge-edge pairs, " << pushing
                                             << " with lambda > 0");
    REQUIRE(kinds[1] > 0);
    REQUIRE(kinds[2] > 0);
    REQUIRE(pushing > 4);
    const Eigen::VectorXd u = pushed + 1e-4 * delta * random_vector(48, 3);
    REQUIRE(std::isfinite(al.energy(u)));
    const Eigen::VectorXd g = al.gradient(u);
    const Eigen::MatrixXd H = Eigen::MatrixXd(al.hessian(u));
    const test::CentralDifferences differences = test::central_differences(al, u, 1e-9);
    CHECK((g - differences.gradient).norm() <= 1e-6 * g.norm());
    // Each pair's block is projected to PSD on its own: H − H_exact ⪰ 0, and H ⪰ 0.
    const Eigen::MatrixXd exact = 0.5 * (differences.hessian + differences.hessian.transpose());
    const double size = exact.norm();
    CHECK(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H - exact).eigenvalues().minCoeff() >= -1e-5 * size);
    CHECK(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues().minCoeff() >= -1e-9 * size);
    if (!with_box) {  // the floor's and the flat faces' pairs: the lower cube's blocks are exact
        for (int v = 0; v < 8; ++v)  // the lower cube's bottom vertices touch only the floor
            if (scene.mesh.V(v, 2) < 0.01)
                CHECK((H.block<3, 3>(3 * v, 3 * v) - exact.block<3, 3>(3 * v, 3 * v)).norm() <= 1e-6 * size);
    }
}

TEST_CASE("a block at rest on the floor: the multipliers carry its weight to 1e-3, every step's momentum balance "
          "holds, nothing crosses", "[ex16.3]")
{
    // Placed 0.5 δ above the floor (inside δ: the constraints act from the first step), at rest.
    SolverScene resting = drop_scene(0.5e-3, 100);
    double weight = 0.0, worst_balance = 0.0, last_error = 0.0, smallest = std::numeric_limits<double>::infinity();
    const SolverRun run = run_scene(resting, ContactSolver::augmented_lagrangian, {}, true,
                                    [&](const dynamics::Body& body, const dynamics::State& before,
                                        const dynamics::State& after, const Eigen::VectorXd& forces) {
                                        const auto all = [](int) { return true; };
                                        weight = body.dof_masses().sum() / 3.0 * 9.81;
                                        const Eigen::Vector3d F = force_on(forces, all);
                                        // Σ m Δv/Δt = F + W (internal forces cancel): the converged step's balance.
                                        const Eigen::Vector3d residual =
                                            F - weight * Eigen::Vector3d::UnitZ() - momentum_change(body, before, after, all);
                                        worst_balance = std::max(worst_balance, residual.norm() / weight);
                                        last_error = std::abs(F.z() - weight) / weight;
                                        smallest = std::min(smallest, body.positions(after.u).col(2).minCoeff());
                                    });
    INFO(run.error);
    REQUIRE(run.error.empty());
    CHECK(worst_balance < 1e-3);
    CHECK(last_error < 1e-3);
    CHECK(smallest > 0.0);
    CHECK(run.largest_violation <= AugmentedLagrangianOptions{}.violation_tolerance * 1e-3);
}

TEST_CASE("the stack of three: the force through each interface against the weight above to 1e-3", "[ex16.3]")
{
    const SolverScene stack = stack_scene(1e-3, 100);
    double errors[2] = {0.0, 0.0};
    const SolverRun run = run_scene(stack, ContactSolver::augmented_lagrangian, {}, false,
                                    [&](const dynamics::Body& body, const dynamics::State&, const dynamics::State&,
                                        const Eigen::VectorXd& forces) {
                                        for (int k = 0; k < 2; ++k) {
                                            const auto above = [k](int v) { return stack_block(v) > k; };
                                            double weight = 0.0;
                                            for (int v = 0; v < 24; ++v)
                                                weight += above(v) ? body.dof_masses()[3 * v] * 9.81 : 0.0;
                                            // the pairs among the blocks above cancel: what is left passes interface k
                                            errors[k] = std::abs(force_on(forces, above).z() - weight) / weight;
                                        }
                                    });
    INFO(run.error);
    REQUIRE(run.error.empty());
    CHECK(errors[0] < 1e-3);
    CHECK(errors[1] < 1e-3);
    CHECK(run.smallest_distance > 0.0);
}

TEST_CASE("two blocks thrown at each other, spinning: momentum kept to round-off, never an intersection", "[ex16.3]")
{
    const SolverScene two = two_bodies_scene(box_mesh(2, 2, 2, Eigen::Vector3d::Constant(0.1)), 0.1, 5e-3, 0.5, 5.0, 12);
    const SolverRun run = run_scene(two, ContactSolver::augmented_lagrangian, {}, true);
    INFO(run.error);
    REQUIRE(run.error.empty());
    CHECK(run.contact_steps > 3);  // they met
    CHECK(run.smallest_distance > 0.0);
    CHECK(run.momentum_drift < 1e-12);
    CHECK(run.largest_violation <= AugmentedLagrangianOptions{}.violation_tolerance * 1e-3);
}

TEST_CASE("the block fired at the turned box at 10 and 100 m/s: every step converges, the referee finds nothing",
          "[ex16.3]")
{
    const double speed = GENERATE(10.0, 100.0);
    const SolverRun run = run_scene(fired_scene(turned_box(), speed), ContactSolver::augmented_lagrangian, {}, true);
    INFO(speed << " m/s: " << run.error);
    REQUIRE(run.error.empty());
    CHECK(run.steps.size() == 10);
    CHECK(run.contact_steps >= 1);
    CHECK(run.smallest_distance > 0.0);
}

TEST_CASE("augmented Lagrangian contact: options out of range, no obstacle, no room and a start inside are refused",
          "[ch16]")
{
    const SolverScene drop = drop_scene();
    dynamics::Body body(drop.scene, hyper::make_force_model("stable-neo-hookean", drop.scene.mesh, drop.scene.material));
    const auto refused = [&](AugmentedLagrangianOptions options, const std::string& what) {
        CHECK_THROWS_WITH(AugmentedLagrangianContact(body, drop.obstacles, options), Catch::Contains(what));
    };
    AugmentedLagrangianOptions bad;
    bad.gap = 0.0;
    refused(bad, "gap");
    bad = {};
    bad.penalty_growth = 0.5;
    refused(bad, "penalty_growth");
    bad = {};
    bad.safety = 1.0;
    refused(bad, "safety");
    bad = {};
    bad.stale_steps = 0;
    refused(bad, "stale_steps");
    bad = {};
    bad.filter_gap = -1.0;
    refused(bad, "filter_gap");
    bad = {};
    bad.friction_velocity = 0.0;
    refused(bad, "friction_velocity");
    CHECK_THROWS_WITH(AugmentedLagrangianContact(body, {}), Catch::Contains("obstacle"));

    // A ceiling coming down at 10 m/s onto the block on the floor: squeezed into less than its
    // size in the step, the block has no room; the error names a vertex and the obstacle.
    SolverScene squeeze = drop_scene(0.5e-3, 3);
    squeeze.obstacles.push_back(std::make_shared<HalfSpace>(Eigen::Vector3d(0.0, 0.0, 0.102), -Eigen::Vector3d::UnitZ(),
                                                            0.0, Eigen::Vector3d(0.0, 0.0, -10.0)));
    const SolverRun squeezed = run_scene(squeeze, ContactSolver::augmented_lagrangian);
    CHECK_THAT(squeezed.error, Catch::Contains("no room") && Catch::Contains("vertex"));
    // A block that starts inside the floor.
    SolverScene inside = drop_scene(-0.01, 3);
    const SolverRun started_inside = run_scene(inside, ContactSolver::augmented_lagrangian);
    CHECK_THAT(started_inside.error, Catch::Contains("step 1"));
}

namespace {

/// The mass-weighted mean velocity along x (the slope's direction) of each step's end [m/s].
std::vector<double> slope_velocities(const SolverScene& slope, bool converged, SolverRun& run)
{
    AugmentedLagrangianOptions options;
    options.converged_friction = converged;
    std::vector<double> velocities;
    run = run_scene(slope, ContactSolver::augmented_lagrangian, options, false,
                    [&](const dynamics::Body& body, const dynamics::State&, const dynamics::State& after,
                        const Eigen::VectorXd&) {
                        const Eigen::VectorXd& m = body.dof_masses();
                        double momentum = 0.0;
                        for (Eigen::Index i = 0; i < m.size(); i += 3)
                            momentum += m[i] * after.v[i];
                        velocities.push_back(momentum / (m.sum() / 3.0));
                    });
    return velocities;
}

}  // namespace

TEST_CASE("friction: a block sliding down a slope accelerates at g (sin t - mu cos t) to 1e-6 g, lagged or converged",
          "[ex16.3]")
{
    const double slope = 0.5, mu = 0.3;  // tan θ = 0.55 > μ: it slides
    const bool converged = GENERATE(false, true);
    SolverRun run;
    const std::vector<double> v = slope_velocities(slope_scene(slope, mu, 40), converged, run);
    INFO((converged ? "converged" : "lagged") << ": " << run.error);
    REQUIRE(run.error.empty());
    const double expected = 9.81 * (std::sin(slope) - mu * std::cos(slope)), dt = 0.01;
    double worst = 0.0;
    for (std::size_t s = 20; s < v.size(); ++s)  // settled: the lagged normal force is the weight's share
        worst = std::max(worst, std::abs((v[s] - v[s - 1]) / dt - expected));
    CHECK(worst < 1e-6 * 9.81);
}

TEST_CASE("friction: a block on a slope below tan t = mu creeps no faster than eps_v, lagged or converged",
          "[ex16.3]")
{
    const double slope = 0.15, mu = 0.5;  // tan θ = 0.15 < μ: it sticks
    const bool converged = GENERATE(false, true);
    SolverRun run;
    const std::vector<double> v = slope_velocities(slope_scene(slope, mu, 40), converged, run);
    INFO((converged ? "converged" : "lagged") << ": " << run.error);
    REQUIRE(run.error.empty());
    for (std::size_t s = 5; s < v.size(); ++s)
        CHECK(std::abs(v[s]) <= AugmentedLagrangianOptions{}.friction_velocity);
}
