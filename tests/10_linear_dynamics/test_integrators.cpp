// Chapter 10: integrators and the time loop on whole bodies: energy bookkeeping, statics, free
// fall, pinned dofs two ways, solvers, and the stability hard cases.
// docs/10_linear_dynamics.md#the-pieces-of-a-simulation
#include "10_linear_dynamics/modes.hpp"
#include "dynamics_fixtures.hpp"

#include "../common/test_support.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <functional>

using namespace fem::dynamics;
using fem::test::EntriesNear;
using fem::test::entries_of;
using fem::test::cantilever_scene;
using Catch::Matchers::Contains;

namespace {

/// The static sag K_ff⁻¹ f_ff of a body (full vector), by Eigen's own sparse Cholesky.
Eigen::VectorXd static_solution(Body& body)
{
    const auto [K, M] = fem::test::free_matrices(body);
    const Eigen::SimplicialLDLT<SparseMatrix> llt(K);
    return fem::test::expanded(body, llt.solve(body.dofs().gather(body.external_forces())));
}

/// A smooth starting shape: the static sag under gravity, for scenes that have none.
Eigen::VectorXd sag_shape(const Scene& scene)
{
    Scene loaded = scene;
    loaded.gravity = Eigen::Vector3d(0.0, 0.0, -9.81);
    Body body(loaded);
    return static_solution(body);
}

/// The largest gaps between two runs of one scene stepped side by side, relative to the first
/// run's largest u and v.
struct TrajectoryGap {
    double u = 0.0, v = 0.0;
};

/// Steps a and b together and measures how far they part; each_step (if given) sees b's state.
TrajectoryGap trajectory_gap(Simulation& a, Simulation& b, int steps,
                             const std::function<void(const State&)>& each_step = nullptr)
{
    double u_gap = 0.0, v_gap = 0.0, u_size = 0.0, v_size = 0.0;
    for (int step = 0; step < steps; ++step) {
        a.run(1);
        b.run(1);
        u_gap = std::max(u_gap, (a.state().u - b.state().u).norm());
        v_gap = std::max(v_gap, (a.state().v - b.state().v).norm());
        u_size = std::max(u_size, a.state().u.norm());
        v_size = std::max(v_size, a.state().v.norm());
        if (each_step)
            each_step(b.state());
    }
    return {u_gap / u_size, v_gap / v_size};
}

}  // namespace

TEST_CASE("the midpoint rule keeps an undamped body's energy to round-off over 1000 steps", "[ex10.4]")
{
    const Scene scene = cantilever_scene();
    Body body(scene);
    for (const StepForm form : {StepForm::velocity_change, StepForm::velocity}) {
        ThetaMethod midpoint(0.5, fem::test::with_form(form));
        Simulation simulation(body, midpoint, initial_state(body, sag_shape(scene)));
        const double start = energies(body, simulation.state()).total();
        REQUIRE(start > 0.0);
        double drift = 0.0;
        simulation.run(1000, [&](const State&, const StepRecord& record) {
            drift = std::max(drift, std::abs(record.energies.total() - start) / start);
        });
        CAPTURE(form == StepForm::velocity, fem::test::sci(drift));
        // Solving for Δv keeps it near 3e-11; the lecture's v⁺ form loses ~7× more to the
        // cancellation of M v (docs/10_linear_dynamics.md#two-forms-of-one-step).
        CHECK(drift <= (form == StepForm::velocity_change ? 1e-10 : 1e-9));
    }
    // Backward Euler on the same start loses energy every step.
    ThetaMethod backward(1.0);
    Simulation damped(body, backward, initial_state(body, sag_shape(scene)));
    const double start = energies(body, damped.state()).total();
    double previous = start;
    bool monotone = true;
    damped.run(200, [&](const State&, const StepRecord& record) {
        monotone = monotone && record.energies.total() <= previous * (1.0 + 1e-13);
        previous = record.energies.total();
    });
    CHECK(monotone);
    CHECK(previous < 0.5 * start);
}

TEST_CASE("energy balance: the loss splits into damping work and backward Euler's own dissipation",
          "[ex10.4]")
{
    Scene scene = cantilever_scene(8, 2, true);
    scene.damping = {0.02, 0.01};
    Body body(scene);
    ThetaMethod integrator(1.0);
    Simulation simulation(body, integrator, initial_state(body));
    const SparseMatrix& K = body.model().stiffness(simulation.state().u);
    double expected_integrator = 0.0, expected_damping = 0.0;
    Eigen::VectorXd u = simulation.state().u, v = simulation.state().v;
    simulation.run(60, [&](const State& state, const StepRecord& record) {
        if (state.step == 0)
            return;
        // Backward Euler removes ½|Δv|²_M + ½|Δu|²_K per step; damping removes Δt v⁺ᵀ D v⁺.
        const Eigen::VectorXd du = state.u - u, dv = state.v - v;
        expected_integrator += 0.5 * dv.dot(body.mass_matrix() * dv) + 0.5 * du.dot(K * du);
        const Eigen::VectorXd Dv = 0.02 * (body.mass_matrix() * state.v) + 0.01 * (K * state.v);
        expected_damping += scene.time_step * state.v.dot(Dv);
        u = state.u;
        v = state.v;
        const double scale = record.energies.magnitude();
        CHECK(record.damping_dissipated == Approx(expected_damping).margin(1e-12 * scale));
        CHECK(record.integrator_dissipated == Approx(expected_integrator).margin(1e-10 * scale));
    });
    CHECK(simulation.last().damping_dissipated > 0.0);
    CHECK(simulation.last().integrator_dissipated > 0.0);
}

TEST_CASE("a damped beam under gravity settles to the static solution K^-1 f", "[ex10.4]")
{
    Scene scene = cantilever_scene(8, 2, true);
    scene.damping = {0.0, 0.02};
    scene.time_step = 0.05;
    Body body(scene);
    const Eigen::VectorXd expected = static_solution(body);
    ThetaMethod integrator(1.0);
    Simulation simulation(body, integrator, initial_state(body));
    int settled_at = -1;
    simulation.run(300, [&](const State& state, const StepRecord&) {
        if (settled_at < 0 && (state.u - expected).norm() <= 1e-8 * expected.norm())
            settled_at = state.step;
    });
    CAPTURE(settled_at);
    CHECK(settled_at > 0);
    CHECK_THAT(entries_of(simulation.state().u), EntriesNear(expected, 1e-8 * expected.norm()));
    CHECK(simulation.state().v.norm() <= 1e-7 * expected.norm() / scene.time_step);
}

TEST_CASE("free fall: nothing pinned, the body falls rigidly on backward Euler's discrete parabola", "[ex10.4]")
{
    Scene scene = cantilever_scene(4, 1, true);
    scene.pinned.clear();
    scene.time_step = 0.02;
    Body body(scene);
    ThetaMethod integrator(1.0);
    Simulation simulation(body, integrator, initial_state(body));
    const double g = -9.81, dt = scene.time_step;
    const Eigen::VectorXd masses = body.dof_masses();
    const double total_mass = masses.sum() / 3.0;
    double centre_error = 0.0, deformation = 0.0;
    simulation.run(50, [&](const State& state, const StepRecord&) {
        const double n = state.step;
        const double expected = dt * dt * g * n * (n + 1.0) / 2.0;  // not ½ g t²
        Eigen::Vector3d centre = Eigen::Vector3d::Zero();
        for (Eigen::Index v = 0; v < body.mesh().V.rows(); ++v)
            centre += masses[3 * v] * state.u.segment<3>(3 * v) / total_mass;
        centre_error = std::max(centre_error, (centre - Eigen::Vector3d(0.0, 0.0, expected)).norm());
        for (Eigen::Index v = 0; v < body.mesh().V.rows(); ++v)
            deformation = std::max(deformation, (state.u.segment<3>(3 * v) - centre).norm());
    });
    const double fallen = dt * dt * 9.81 * 50 * 51 / 2.0;
    // The elastic forces K u of a translated body cancel only to δF = ε Σ|K_ij||u_j|; a constant
    // force error δF moves the centre by δF/(m g) of the fall, and deforms the body as little.
    const double K_noise = fem::test::force_roundoff(body.model().stiffness(simulation.state().u), simulation.state().u);
    const double bound = K_noise / (total_mass * 9.81);
    CAPTURE(fem::test::sci(centre_error / fallen), fem::test::sci(deformation / fallen), fem::test::sci(bound));
    CHECK(centre_error <= bound * fallen);
    CHECK(deformation <= bound * fallen);
    CHECK(std::abs(fallen - 0.5 * 9.81 * 1.0) > 0.01);  // the discrete parabola is not ½ g t²
}

TEST_CASE("pinned dofs eliminated or kept with P A P + (I - P): the same trajectory", "[ex10.4]")
{
    Scene scene = cantilever_scene(8, 2, true);
    scene.damping = {0.01, 0.01};
    for (const double theta : {1.0, 0.5}) {
        Body eliminated(scene), kept(scene);
        ImplicitOptions keep;
        keep.pinned = PinnedRoute::keep;
        ThetaMethod a(theta), b(theta, keep);
        Simulation sa(eliminated, a, initial_state(eliminated));
        Simulation sb(kept, b, initial_state(kept));
        double pinned_motion = 0.0;
        const TrajectoryGap gap = trajectory_gap(sa, sb, 40, [&](const State& state) {
            pinned_motion += (state.u - state.u.cwiseProduct(kept.dofs().free_mask())).norm();
        });
        const double bound = fem::test::trajectory_roundoff(eliminated, scene.time_step, theta, 40);
        CAPTURE(theta, fem::test::sci(gap.u), fem::test::sci(gap.v), fem::test::sci(bound));
        CHECK(gap.u <= bound);
        CHECK(gap.v <= bound);
        CHECK(pinned_motion == 0.0);
    }
}

TEST_CASE("the lecture's velocity form equals the velocity-change form, damped too, at theta = 1/2 and 3/4", "[ex10.4]")
{
    // The two forms are one step written two ways (docs/10_linear_dynamics.md#two-forms-of-one-step):
    // the lecture's A v⁺ = M v + Δt (f + f_ext) − (1 − θ)Δt (D v + θΔt K v) must give the same
    // trajectory as A Δv = Δt [f + f_ext − D v − θΔt K v] to round-off. Below θ = 1 its correction
    // carries D v: without damping nothing shows it is missing, so this run is damped.
    Scene scene = cantilever_scene(8, 2, true);
    for (const Damping damping : {Damping{0.0, 0.0}, Damping{0.02, 0.01}}) {
        scene.damping = damping;
        for (const double theta : {0.5, 0.75}) {
            Body velocity_body(scene), change_body(scene);
            ThetaMethod lecture(theta, fem::test::with_form(StepForm::velocity)),
                change(theta, fem::test::with_form(StepForm::velocity_change));
            Simulation reference(change_body, change, initial_state(change_body));
            Simulation tested(velocity_body, lecture, initial_state(velocity_body));
            const TrajectoryGap gap = trajectory_gap(reference, tested, 40);
            // The velocity form loses up to ~7× more to the cancellation of M v (the midpoint test above).
            const double bound = 10.0 * fem::test::trajectory_roundoff(change_body, scene.time_step, theta, 40);
            CAPTURE(theta, damping.alpha, damping.beta, fem::test::sci(gap.u), fem::test::sci(gap.v), fem::test::sci(bound));
            INFO("the lecture's form (StepForm::velocity) left the velocity-change form's trajectory; if only the "
                 "damped runs differ, its (1 - theta) dt (D v + theta dt K v) correction misses D v (damping_times)");
            CHECK(gap.u <= bound);
            CHECK(gap.v <= bound);
        }
    }
}

TEST_CASE("solvers: factor once = refactor every step, and warm-started PCG agrees and needs fewer iterations",
          "[ex10.4]")
{
    Scene scene = cantilever_scene(8, 2, true);
    Body body(scene);
    ImplicitOptions refactor, pcg_options;
    refactor.refactor_every_step = true;
    pcg_options.solver = "ours-pcg-ic0";
    pcg_options.solver_options.relative_tolerance = 1e-12;
    ThetaMethod once(1.0), every(1.0, refactor), pcg(1.0, pcg_options);
    Simulation s1(body, once, initial_state(body));
    Simulation s2(body, every, initial_state(body));
    Simulation s3(body, pcg, initial_state(body));
    s1.run(30);
    s2.run(30);
    std::vector<int> iterations;
    s3.run(30, [&](const State& state, const StepRecord& record) {
        if (state.step > 0)
            iterations.push_back(record.solver_iterations);
    });
    CHECK_THAT(entries_of(s1.state().u), EntriesNear(s2.state().u, 1e-14 * s1.state().u.norm()));
    CHECK_THAT(entries_of(s1.state().u), EntriesNear(s3.state().u, 1e-8 * s1.state().u.norm()));
    // A warm start from the previous velocity: later steps need fewer iterations than the first.
    REQUIRE(iterations.size() == 30);
    CHECK(iterations.back() < iterations.front());
    // Factoring once: the second step prepares nothing.
    ThetaMethod counted(1.0);
    State state = initial_state(body);
    CHECK(counted.step(body, scene.time_step, state).prepared);
    CHECK_FALSE(counted.step(body, scene.time_step, state).prepared);
    CHECK(counted.step(body, 2 * scene.time_step, state).prepared);  // a new Δt: a new matrix
}

TEST_CASE("symplectic Euler follows its own modal recurrence, with lumped and consistent mass", "[ex10.5]")
{
    for (const MassModel mass : {MassModel::lumped, MassModel::consistent}) {
        Scene scene = cantilever_scene();
        scene.mass = mass;
        scene.damping = {0.02, 0.0};
        scene.duration = 0.0;  // any dt is then a whole number of steps of it
        Body body(scene);
        const auto [K, M] = fem::test::free_matrices(body);
        body.set_time_step(0.5 * 2.0 / highest_frequency(K, M));  // half the undamped limit 2/omega_max
        const double dt = body.time_step();
        const Modes modes = lowest_modes_dense(K, M, 1);
        const double omega = modes.omega[0], xi = damping_ratio(scene.damping, omega);
        const int tip = 3 * fem::test::tip_vertex(scene) + 2;
        const Eigen::VectorXd phi = fem::test::expanded(body, modes.shapes.col(0));
        SymplecticEuler integrator;
        Simulation simulation(body, integrator, initial_state(body, 1e-3 * phi));
        // p⁺ = p − Δt(ω² q + 2ξω p), q⁺ = q + Δt p⁺, written out here as the reference.
        double q = 1e-3, p = 0.0, deviation = 0.0;
        simulation.run(300, [&](const State& state, const StepRecord&) {
            if (state.step > 0) {
                p = p - dt * (omega * omega * q + 2.0 * xi * omega * p);
                q = q + dt * p;
            }
            deviation = std::max(deviation, std::abs(state.u[tip] - q * phi[tip]));
        });
        CAPTURE(deviation);
        CHECK(deviation <= 1e-10 * 1e-3 * std::abs(phi[tip]));
    }
}

TEST_CASE("stability: explicit Euler blows up at 1.01x its limit and the loop says so, bounded at 0.99x",
          "[ex10.5]")
{
    Scene scene = cantilever_scene(6, 2, true);
    scene.duration = 0.0;  // any dt is then a whole number of steps of it
    Body body(scene);
    const auto [K, M] = fem::test::free_matrices(body);
    const double limit = 2.0 / highest_frequency(K, M);  // undamped: 2/omega_max
    const Eigen::VectorXd start = 0.5 * static_solution(body);

    SymplecticEuler above;
    body.set_time_step(1.01 * limit);
    Simulation unstable(body, above, initial_state(body, start));
    int seen = 0;
    REQUIRE_THROWS_WITH(unstable.run(20000, [&](const State& state, const StepRecord&) {
                            CHECK(state.u.allFinite());  // no observer ever sees a NaN state
                            seen = state.step;
                        }),
                        Contains("diverged at step") && Contains("energy"));
    CHECK(seen > 10);

    SymplecticEuler below;
    body.set_time_step(0.99 * limit);
    Simulation stable(body, below, initial_state(body, start));
    double largest = 0.0;
    stable.run(20000, [&](const State& state, const StepRecord&) { largest = std::max(largest, state.u.norm()); });
    CHECK(largest <= 3.0 * static_solution(body).norm());
}

namespace {

/// A wrong implicit step, on purpose: u stays, v grows by half each step (as a θ-step with a wrong
/// sign in its right-hand side would make it grow).
class GainingStep final : public Integrator {
public:
    std::string name() const override { return "a wrong implicit step"; }
    int order() const override { return 1; }
    StepInfo step(Body& body, double time_step, State& state) override
    {
        commit_step(body.model(), time_step, state.u, 1.5 * state.v, state);
        return {};
    }
};

}  // namespace

TEST_CASE("the loop's divergence message fits the integrator: an implicit step is not sent to a stability limit",
          "[ex10.3]")
{
    Scene scene = cantilever_scene(3, 1);
    Body body(scene);
    const Eigen::VectorXd v0 = body.dofs().free_mask().cwiseProduct(Eigen::VectorXd::Constant(body.dofs().full_size(), 0.1));
    GainingStep gaining;
    Simulation simulation(body, gaining, initial_state(body, {}, v0));
    // A linear body: the message points at the step's own terms, not at dt.
    CHECK_THROWS_WITH(simulation.run(100), Contains("diverged at step") && Contains("a wrong implicit step") &&
                                               Contains("cannot gain energy") && Contains("wrong term") &&
                                               !Contains("stability limit"));
}

TEST_CASE("backward Euler at 100x the explicit limit and a very stiff body at dt = 1/30 stay bounded",
          "[ex10.4]")
{
    Scene scene = cantilever_scene(6, 2, true);
    scene.duration = 0.0;
    Body body(scene);
    const auto [K, M] = fem::test::free_matrices(body);
    const double dt = 100.0 * 2.0 / highest_frequency(K, M);  // 100 x the explicit limit 2/omega_max
    body.set_time_step(dt);
    ThetaMethod integrator(1.0);
    Simulation simulation(body, integrator, initial_state(body));
    double previous = 0.0;
    bool monotone = true;
    simulation.run(500, [&](const State& state, const StepRecord& record) {
        // H may rise by the round-off of evaluating U = ½ uᵀK u and W = −f_extᵀu, no more.
        const double noise = 0.5 * fem::test::force_roundoff(body.model().stiffness(state.u), state.u) * state.u.cwiseAbs().maxCoeff() +
                             2.2e-16 * body.external_forces().cwiseAbs().dot(state.u.cwiseAbs());
        monotone = monotone && record.energies.total() <= previous + 10.0 * noise;
        previous = record.energies.total();
    });
    CHECK(monotone);
    CHECK(simulation.state().u.norm() <= 2.0 * static_solution(body).norm());

    scene.material.youngs_modulus = 1e9;
    scene.time_step = 1.0 / 30.0;
    Body stiff(scene);
    ThetaMethod stiff_integrator(1.0);
    Simulation stiff_run(stiff, stiff_integrator, initial_state(stiff));
    double largest = 0.0;
    stiff_run.run(90, [&](const State& state, const StepRecord&) { largest = std::max(largest, state.u.norm()); });
    CHECK(std::isfinite(largest));
    CHECK(largest <= 2.0 * static_solution(stiff).norm());
}

TEST_CASE("integrators by name, and steps that refuse bad input", "[ch10]")
{
    for (const std::string& name : integrator_names())
        CHECK(make_integrator(name)->name().size() > 0);
    CHECK(make_integrator("implicit-midpoint")->order() == 2);
    CHECK(make_integrator("backward-euler")->order() == 1);
    CHECK_THROWS_WITH(make_integrator("rk4"), Contains("backward-euler"));
    CHECK_THROWS_AS(ThetaMethod(0.3), fem::Error);
    ImplicitOptions unknown;
    unknown.solver = "no-such-solver";
    CHECK_THROWS_WITH(ThetaMethod(1.0, unknown), Contains("ours-cholesky"));

    Body body(cantilever_scene(3, 1, true));
    State state = initial_state(body);
    ThetaMethod integrator(1.0);
    CHECK_THROWS_AS(integrator.step(body, 0.0, state), fem::Error);
    // Δt lives in the body's scene: a bad one is refused there, and so is one the duration
    // (1 s here) is no whole number of steps of.
    CHECK_THROWS_WITH(body.set_time_step(0.0), Contains("dt"));
    CHECK_THROWS_WITH(body.set_time_step(-1.0), Contains("dt"));
    CHECK_THROWS_WITH(body.set_time_step(std::nan("")), Contains("dt"));
    CHECK_THROWS_WITH(body.set_time_step(0.3), Contains("whole number of steps"));
    CHECK(body.time_step() == body.scene().time_step);
    body.set_time_step(0.25);
    CHECK(body.scene().time_step == 0.25);
    State wrong = state;
    wrong.u.resize(3);
    CHECK_THROWS_WITH(integrator.step(body, 0.01, wrong), Contains("does not fit"));
    Simulation simulation(body, integrator, state);
    CHECK_THROWS_AS(simulation.run(-1), fem::Error);
}

TEST_CASE("theta_step_dissipation: the energy each theta-step takes out of an undamped body, step by step",
          "[ex10.10]")
{
    // The independent answer: H before minus H after each step, H = ½ vᵀMv + U + W summed here
    // from the state (not by energies()), on a loaded beam falling from rest.
    Body body(cantilever_scene(6, 2, true));
    const SparseMatrix& M = body.mass_matrix();
    const Eigen::VectorXd& f_ext = body.external_forces();
    const auto total = [&](const State& state) {
        return kinetic_energy(M, state.v) + state.elastic_energy + load_potential(f_ext, state.u);
    };
    for (const double theta : {1.0, 0.75, 0.5}) {
        ThetaMethod integrator(theta);
        State state = initial_state(body);
        const SparseMatrix K = body.model().stiffness(state.u);
        double booked = 0.0, measured = 0.0, scale = 0.0;
        for (int step = 0; step < 40; ++step) {
            const State before = state;
            integrator.step(body, 0.01, state);
            const double loss = total(before) - total(state);
            const double derived = theta_step_dissipation(M, K, before.u, state.u, before.v, state.v, theta);
            scale = std::max({scale, kinetic_energy(M, state.v), std::abs(load_potential(f_ext, state.u))});
            CAPTURE(theta, step, fem::test::sci(loss), fem::test::sci(derived));
            CHECK(derived == Approx(loss).margin(1e-9 * scale));
            CHECK(derived >= 0.0);
            booked += derived;
            measured += loss;
        }
        CAPTURE(theta, fem::test::sci(booked), fem::test::sci(measured), fem::test::sci(scale));
        CHECK(booked == Approx(measured).margin(1e-9 * scale));
        if (theta > 0.5)
            CHECK(booked > 1e-3 * scale);  // backward Euler and θ = ¾ lose a visible share
        else
            CHECK(booked == 0.0);          // the midpoint rule loses nothing
    }
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(M.rows());
    const SparseMatrix K = body.model().stiffness(zero);
    CHECK_THROWS_AS(theta_step_dissipation(M, K, zero, zero, zero, zero, 0.4), fem::Error);
    CHECK_THROWS_AS(theta_step_dissipation(M, K, zero, zero, zero, Eigen::VectorXd::Zero(3), 1.0), fem::Error);
}
