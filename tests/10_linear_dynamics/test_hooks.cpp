// Chapter 10: the step hook and moving pins. A hook before each step may move the pins, change the
// loads or switch the model; the loop books the energy that puts in, and the books must balance.
// docs/10_linear_dynamics.md#the-step-hook, docs/10_linear_dynamics.md#moving-pins
#include "10_linear_dynamics/modes.hpp"
#include "dynamics_fixtures.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <string>

using namespace fem::dynamics;
using fem::test::cantilever_scene;
using fem::test::sci;
using Catch::Matchers::Contains;

namespace {

/// The velocity c on every dof (3n, vertex-major).
Eigen::VectorXd uniform_velocity(const Body& body, const Eigen::Vector3d& c)
{
    Eigen::VectorXd v(body.dofs().full_size());
    for (Eigen::Index i = 0; i < v.size() / 3; ++i)
        v.segment<3>(3 * i) = c;
    return v;
}

/// c on the pinned dofs only (3n).
Eigen::VectorXd on_pins(const Body& body, const Eigen::VectorXd& full)
{
    return full.cwiseProduct(Eigen::VectorXd::Ones(full.size()) - body.dofs().free_mask());
}

/// The clamp of the cantilever (its x = 0 face) turned about the beam's axis by g(t): angle
/// φ(t) = φ_max s(t/T), s(τ) = 3τ² − 2τ³, the rest position X going to R(φ) X (the axis through y = z = 0.01).
Eigen::VectorXd clamp_displacement(const Body& body, double t)
{
    const double T = 0.2, phi = 0.5 * std::min(1.0, t / T) * std::min(1.0, t / T) * (3.0 - 2.0 * std::min(1.0, t / T));
    const Eigen::Matrix3d R = Eigen::AngleAxisd(phi, Eigen::Vector3d::UnitX()).toRotationMatrix();
    const Eigen::Vector3d centre(0.0, 0.01, 0.01);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(body.dofs().full_size());
    for (int v : body.scene().pinned) {
        const Eigen::Vector3d X = body.mesh().V.row(v).transpose();
        g.segment<3>(3 * v) = centre + R * (X - centre) - X;
    }
    return g;
}

/// A hook that moves the clamp as clamp_displacement says: ṽ_p = (g(t + Δt) − u_p)/Δt.
Simulation::BeforeStep turning_clamp(double time_step)
{
    return [time_step](Body& body, const State& state, double step_end) {
        body.set_pin_velocity(on_pins(body, (clamp_displacement(body, step_end) - state.u) / time_step));
        return false;  // the pins' motion changes nothing at t
    };
}

}  // namespace

TEST_CASE("pins translating at constant speed carry a damped body rigidly: no strain, no damping, no work", "[ex10.4]")
{
    // Rayleigh damping of a rigid translation: β K v = 0 (K annihilates rigid motion); α M v would
    // not vanish (mass-proportional damping drags against the fixed frame), so α = 0 here.
    Scene scene = cantilever_scene();
    scene.damping = {0.0, 0.02};
    const Eigen::Vector3d c(0.3, -0.2, 0.5);
    const int steps = 40;
    for (const double theta : {1.0, 0.5})
        for (const StepForm form : {StepForm::velocity_change, StepForm::velocity})
            for (const PinnedRoute route : {PinnedRoute::eliminate, PinnedRoute::keep}) {
                Body body(scene);
                ImplicitOptions options = fem::test::with_form(form);
                options.pinned = route;
                ThetaMethod integrator(theta, options);
                const Eigen::VectorXd velocity = uniform_velocity(body, c);
                body.set_pin_velocity(on_pins(body, velocity));
                Simulation simulation(body, integrator, initial_state(body, {}, velocity));
                double damping = 0.0, boundary = 0.0;
                simulation.run(steps, [&](const State&, const StepRecord& record) {
                    damping = record.damping_dissipated;
                    boundary = record.work_in;
                });
                const double t = simulation.state().time;
                const double u_error = (simulation.state().u - t * velocity).cwiseAbs().maxCoeff();
                const double v_error = (simulation.state().v - velocity).cwiseAbs().maxCoeff();
                const double bound = fem::test::trajectory_roundoff(body, scene.time_step, theta, steps);
                // The energies' round-off: K v and K u of a rigid motion vanish only to ε |K||v| and
                // ε |K||u|; over the run the damping work Δt β vᵀKv and the pins' work Δt ṽᵀ(K u + …)
                // add up to at most steps Δt ε |v|ᵀ|K||v| (β + t). A lagging body (a missing coupling)
                // strains by ~c Δt / L and costs orders of magnitude more.
                const SparseMatrix& K = body.model().stiffness(simulation.state().u);
                const double energy_bound = steps * scene.time_step * 2.220446049250313e-16 *
                                            velocity.cwiseAbs().dot(K.cwiseAbs() * velocity.cwiseAbs()) *
                                            (scene.damping.beta + t);
                CAPTURE(theta, form == StepForm::velocity, route == PinnedRoute::keep, sci(u_error), sci(v_error),
                        sci(damping), sci(boundary), sci(bound), sci(energy_bound));
                CHECK(u_error <= bound * t * c.norm());
                CHECK(v_error <= bound * c.norm());
                CHECK(std::abs(damping) <= energy_bound);
                CHECK(std::abs(boundary) <= energy_bound);
            }
}

TEST_CASE("symplectic Euler moves pins at their velocity, lumped and consistent mass", "[ex10.5]")
{
    Scene scene = cantilever_scene();
    scene.time_step = 1e-5;  // below the explicit limit of this beam (about 1.7e-5 s with lumped mass)
    const Eigen::Vector3d c(0.3, -0.2, 0.5);
    for (const MassModel mass : {MassModel::lumped, MassModel::consistent}) {
        scene.mass = mass;
        Body body(scene);
        SymplecticEuler integrator;
        const Eigen::VectorXd velocity = uniform_velocity(body, c);
        body.set_pin_velocity(on_pins(body, velocity));
        Simulation simulation(body, integrator, initial_state(body, {}, velocity));
        simulation.run(20);
        const double t = simulation.state().time;
        const double u_error = (simulation.state().u - t * velocity).cwiseAbs().maxCoeff();
        CAPTURE(mass == MassModel::consistent, sci(u_error));
        CHECK(u_error <= 1e-12 * t * c.norm());
        CHECK((simulation.state().v - velocity).cwiseAbs().maxCoeff() <= 1e-12 * c.norm());
    }
}

TEST_CASE("symplectic Euler puts pins started from rest where their velocity takes them", "[ex10.5]")
{
    // The pins' step is u_p⁺ = u_p + Δt ṽ_p, whatever their velocity was: a step that kept v_p would
    // leave them at rest.
    Scene scene = cantilever_scene();
    scene.time_step = 1e-5;
    Body body(scene);
    SymplecticEuler integrator;
    const Eigen::VectorXd pins = on_pins(body, uniform_velocity(body, Eigen::Vector3d(0.3, -0.2, 0.5)));
    body.set_pin_velocity(pins);
    Simulation simulation(body, integrator, initial_state(body));
    simulation.run(20);
    const Eigen::VectorXd where = on_pins(body, simulation.state().u) - simulation.state().time * pins;
    CAPTURE(sci(where.cwiseAbs().maxCoeff()));
    CHECK(where.cwiseAbs().maxCoeff() <= 1e-15);
    CHECK(on_pins(body, simulation.state().v) == pins);
}

TEST_CASE("with turning pins the midpoint rule's books balance to round-off, damped or not", "[ex10.9]")
{
    // The midpoint rule's energy identity on a linear body: H⁺ − H = Δt ṽ_pᵀ r_p − Δt v_θᵀ D v_θ
    // exactly, so H(t) − H(0) − W_in + damping must vanish up to round-off: a wrong boundary work
    // (a missing coupling, the pins at the wrong time) shows as a drift of the size of the work.
    for (const double beta : {0.0, 0.002}) {
        Scene scene = cantilever_scene();
        scene.damping = {0.0, beta};
        Body body(scene);
        ThetaMethod midpoint(0.5);
        Simulation simulation(body, midpoint, initial_state(body));
        simulation.set_before_step(turning_clamp(scene.time_step));
        double worst = 0.0, work = 0.0, largest = 0.0;
        simulation.run(40, [&](const State& state, const StepRecord& record) {
            worst = std::max(worst, std::abs(record.integrator_dissipated));
            work = record.work_in;
            largest = std::max(largest, record.energies.magnitude());
            // The pins are where their motion says, at the step's end.
            const Eigen::VectorXd pins = on_pins(body, state.u - clamp_displacement(body, state.time));
            CHECK(pins.cwiseAbs().maxCoeff() <= 1e-15);
        });
        CAPTURE(beta, sci(worst), sci(work), sci(largest));
        REQUIRE(work > 1e-4);  // the turning clamp did real work on the beam
        CHECK(worst <= 1e-9 * largest);
    }
}

TEST_CASE("with turning pins backward Euler dissipates, never adds energy", "[ex10.9]")
{
    Scene scene = cantilever_scene();
    Body body(scene);
    ThetaMethod backward(1.0);
    Simulation simulation(body, backward, initial_state(body));
    simulation.set_before_step(turning_clamp(scene.time_step));
    double lowest = 0.0, largest = 0.0;
    simulation.run(40, [&](const State&, const StepRecord& record) {
        lowest = std::min(lowest, record.integrator_dissipated);
        largest = std::max(largest, record.energies.magnitude());
    });
    CAPTURE(sci(lowest), sci(largest), sci(simulation.last().integrator_dissipated));
    CHECK(lowest >= -1e-9 * largest);
    CHECK(simulation.last().integrator_dissipated > 1e-3 * simulation.last().work_in);
}

TEST_CASE("apply_step_hook books a load change as -df u and evaluates the model again", "[ex10.9]")
{
    Scene scene = cantilever_scene(8, 2, true);
    Body body(scene);
    ThetaMethod backward(1.0);
    State state = initial_state(body);
    for (int k = 0; k < 5; ++k)
        backward.step(body, scene.time_step, state);
    REQUIRE(state.u.norm() > 0.0);
    const Eigen::VectorXd df = on_pins(body, Eigen::VectorXd::Zero(state.u.size())) +
                               0.1 * body.gravity_load().cwiseProduct(body.dofs().free_mask());
    const double expected = -df.dot(state.u);
    const auto add_load = [&](Body& b, const State&, double) {
        b.set_applied_loads(df);
        return true;
    };
    const double work = apply_step_hook(add_load, body, state, state.time + scene.time_step);
    CAPTURE(sci(work), sci(expected));
    CHECK(std::abs(work - expected) <= 1e-12 * std::abs(expected));
    CHECK((body.external_forces() - body.gravity_load() - df).cwiseAbs().maxCoeff() <=
          1e-15 * body.gravity_load().cwiseAbs().maxCoeff());

    // A hook that changes nothing puts in nothing, and leaves the forces alone.
    const Eigen::VectorXd forces = state.forces;
    const auto nothing = [](Body&, const State&, double) { return false; };
    CHECK(apply_step_hook(nothing, body, state, state.time + scene.time_step) == 0.0);
    CHECK(state.forces == forces);

    // A hook that reports a change re-evaluates the model: forces and U at u, whatever they were.
    state.forces.setZero();
    state.elastic_energy = -1.0;
    const auto same = [](Body&, const State&, double) { return true; };
    CHECK(apply_step_hook(same, body, state, state.time + scene.time_step) != 0.0);  // U was wrong
    Eigen::VectorXd evaluated;
    const double U = body.model().evaluate(state.u, evaluated);
    CHECK(state.elastic_energy == U);
    CHECK(state.forces == evaluated);
}

TEST_CASE("a load changed every step is booked as work in: the midpoint books balance and nothing diverges", "[ex10.9]")
{
    // A load growing to 50 times gravity within 0.1 s pumps energy in; without its booking the
    // divergence rule would fire (H rises far above H(0)), with it H − W_in stays at H(0).
    Scene scene = cantilever_scene(8, 2, true);
    Body body(scene);
    ThetaMethod midpoint(0.5);
    Simulation simulation(body, midpoint, initial_state(body));
    simulation.set_before_step([](Body& b, const State&, double step_end) {
        b.set_applied_loads(std::min(1.0, step_end / 0.1) * 49.0 * b.gravity_load());
        return true;
    });
    double worst = 0.0, largest = 0.0;
    REQUIRE_NOTHROW(simulation.run(30, [&](const State&, const StepRecord& record) {
        worst = std::max(worst, std::abs(record.integrator_dissipated));
        largest = std::max(largest, record.energies.magnitude());
    }));
    const StepRecord& last = simulation.last();
    CAPTURE(sci(worst), sci(largest), sci(last.work_in), sci(last.energies.total()));
    REQUIRE(last.energies.magnitude() > 10.0 * std::abs(simulation.last().energies.total() - last.work_in));
    CHECK(worst <= 1e-9 * largest);
}

TEST_CASE("the divergence rule counts the hook's work: an explicit step past its limit still fails, naming the step", "[ex10.9]")
{
    Scene scene = cantilever_scene();
    scene.duration = 0.0;  // any dt is then a whole number of steps of it
    Body body(scene);
    const auto [K, M] = fem::test::free_matrices(body);
    const double limit = explicit_stability_limit(highest_frequency(K, M));
    body.set_time_step(1.05 * limit);
    SymplecticEuler explicit_euler;
    Eigen::VectorXd start = Eigen::VectorXd::Zero(body.dofs().full_size());
    start[3 * fem::test::tip_vertex(scene) + 2] = 1e-4;
    Simulation simulation(body, explicit_euler, initial_state(body, start));
    simulation.set_before_step(turning_clamp(1.05 * limit));
    CHECK_THROWS_WITH(simulation.run(5000), Contains("diverged at step") && Contains("symplectic Euler") &&
                                                Contains("stability limit"));
}

TEST_CASE("the pin velocity and applied loads are checked", "[ex10.4]")
{
    Body body(cantilever_scene());
    const Eigen::Index n = body.dofs().full_size();
    CHECK_THROWS_WITH(body.set_pin_velocity(Eigen::VectorXd::Ones(n)), Contains("which is not pinned"));
    CHECK_THROWS_WITH(body.set_pin_velocity(Eigen::VectorXd::Zero(n - 1)), Contains("expected 3n"));
    Eigen::VectorXd nan = Eigen::VectorXd::Zero(n);
    nan[3 * body.scene().pinned.front()] = std::nan("");
    CHECK_THROWS_WITH(body.set_pin_velocity(nan), Contains("non-finite"));
    CHECK_THROWS_WITH(body.set_applied_loads(nan), Contains("non-finite"));
    body.set_pin_velocity({});
    CHECK_FALSE(body.pins_move());
}
