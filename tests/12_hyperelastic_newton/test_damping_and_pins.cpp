// Chapter 12: Rayleigh damping in backward Euler by Newton (D = αM + βK_t, K_t the definite tangent
// at the step's start) and pins that move with their velocity: against chapter 10's θ-step on a
// linear body, the objective written out, finite differences, the energy books, and a body carried
// rigidly by translating pins. docs/12_hyperelastic_newton.md#rayleigh-damping,
// docs/12_hyperelastic_newton.md#moving-pins
#include "12_hyperelastic_newton/force_models.hpp"
#include "12_hyperelastic_newton/hyperelastic.hpp"
#include "12_hyperelastic_newton/newton.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"
#include "common/random.hpp"

#include "../10_linear_dynamics/dynamics_fixtures.hpp"
#include "../common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

using namespace fem;
using namespace fem::hyper;
using fem::test::EntriesNear;
using fem::test::entries_of;
using fem::test::sci;
using Catch::Matchers::Contains;

namespace {

/// Chapter 10's test cantilever (Y = 2e6, no gravity unless asked) with Rayleigh damping α, β.
dynamics::Scene damped_cantilever(double alpha, double beta, bool gravity = false)
{
    dynamics::Scene scene = test::cantilever_scene(6, 2, gravity);
    scene.damping = {alpha, beta};
    return scene;
}

/// A state of the body with a random velocity on the free dofs and a random displacement (seeded).
dynamics::State moving_state(dynamics::Body& body, unsigned seed)
{
    const Eigen::VectorXd free = body.dofs().free_mask();
    return dynamics::initial_state(body, 1e-3 * fem::random_vector(free.size(), seed).cwiseProduct(free),
                                   0.2 * fem::random_vector(free.size(), seed + 1).cwiseProduct(free));
}

/// The pins of a body moving with velocity c cos(ω t) (a hook for Simulation): ṽ_p is the mean
/// velocity over the step, (g(t + Δt) − g(t))/Δt with g(t) = c sin(ω t)/ω.
dynamics::Simulation::BeforeStep shaking_pins(const Eigen::Vector3d& c, double omega, double time_step)
{
    return [c, omega, time_step](dynamics::Body& body, const dynamics::State& state, double step_end) {
        const Eigen::Vector3d mean = c * (std::sin(omega * step_end) - std::sin(omega * state.time)) / (omega * time_step);
        Eigen::VectorXd velocity = Eigen::VectorXd::Zero(body.dofs().full_size());
        for (const int v : body.scene().pinned)
            velocity.segment<3>(3 * v) = mean;
        body.set_pin_velocity(velocity);
        return false;
    };
}

}  // namespace

TEST_CASE("damped objective: E gains (dt/2) v^T D v with D = alpha M + beta K at the step's start", "[ex12.7]")
{
    const dynamics::Scene scene = damped_cantilever(0.02, 0.01);
    dynamics::Body body(scene);  // linear: K_t = K
    const dynamics::State state = moving_state(body, 51);
    const double dt = scene.time_step;
    const Eigen::VectorXd v = 0.3 * fem::random_vector(state.v.size(), 53).cwiseProduct(body.dofs().free_mask());
    const StepDamping damping(body, state.u);
    // Written out from chapter 10's pieces: ½ΔvᵀMΔv + ½ u⁺ᵀKu⁺ − Δt vᵀf_ext + (Δt/2) vᵀ(αM + βK)v.
    const dynamics::SparseMatrix& M = body.mass_matrix();
    const dynamics::SparseMatrix K = dynamic_cast<dynamics::LinearElasticity&>(body.model()).K();
    const Eigen::VectorXd change = v - state.v, u = state.u + dt * v;
    const double expected = 0.5 * change.dot(M * change) + 0.5 * u.dot(K * u) - dt * v.dot(body.external_forces()) +
                            0.5 * dt * v.dot(0.02 * (M * v) + 0.01 * (K * v));
    CHECK(backward_euler_objective(body, state, dt, v, nullptr, damping) == Approx(expected).epsilon(1e-12));
    CHECK((damping.times(v) - (0.02 * (M * v) + 0.01 * (K * v))).norm() <= 1e-12 * (K * v).norm() * 0.01);
    // A damped body's objective without its damping is refused, not silently undamped.
    CHECK_THROWS_WITH(backward_euler_objective(body, state, dt, v), Contains("StepDamping"));
    CHECK_THROWS_WITH(backward_euler_gradient(body, state, dt, v), Contains("beta = 0.01"));
}

TEST_CASE("damped gradient: the damped objective's by finite differences, zero at chapter 10's damped step", "[ex12.8]")
{
    const dynamics::Scene scene = damped_cantilever(0.02, 0.01);
    dynamics::Body body(scene);  // linear: this exercise builds on no other
    const dynamics::State state = moving_state(body, 55);
    const double dt = scene.time_step;
    const StepDamping damping(body, state.u);
    const Eigen::VectorXd v = 0.3 * fem::random_vector(state.v.size(), 57).cwiseProduct(body.dofs().free_mask());
    const Eigen::VectorXd direction = fem::random_vector(v.size(), 58).cwiseProduct(body.dofs().free_mask());
    const auto objective = [&](double h) {
        return Eigen::VectorXd::Constant(1, backward_euler_objective(body, state, dt, v + h * direction, nullptr, damping));
    };
    const std::vector<double> errors = test::central_difference_errors(
        objective, Eigen::VectorXd::Constant(1, backward_euler_gradient(body, state, dt, v, damping).dot(direction)), 0.1);
    CHECK(*std::min_element(errors.begin(), errors.end()) < 1e-6);

    // The gradient vanishes at chapter 10's damped backward Euler step.
    dynamics::State stepped = state;
    dynamics::ThetaMethod(1.0).step(body, dt, stepped);
    const Eigen::VectorXd at_step = body.dofs().gather(backward_euler_gradient(body, state, dt, stepped.v, damping));
    CHECK(at_step.norm() <= 1e-10 * momentum_scale(body, state, dt));
}

TEST_CASE("the damping's K_t is the definite tangent: where StVK's exact K is indefinite, D still removes energy",
          "[ex12.9]")
{
    dynamics::Scene scene;
    scene.mesh = box_mesh(1, 1, 1, Eigen::Vector3d(0.1, 0.1, 0.1));
    scene.material = {1e5, 0.3, 1000.0};
    scene.damping = {0.0, 0.02};
    dynamics::Body body(scene, make_force_model("stvk", scene.mesh, scene.material));
    Eigen::VectorXd u = Eigen::VectorXd::Zero(body.dofs().full_size());
    for (Eigen::Index v = 0; v < scene.mesh.V.rows(); ++v)
        u[3 * v + 2] = -0.5 * scene.mesh.V(v, 2);  // squashed to half its height: StVK's K turns indefinite
    const auto exact_model = make_force_model("stvk", scene.mesh, scene.material);
    const Eigen::MatrixXd K = Eigen::MatrixXd(exact_model->stiffness(u));
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(K);
    const Eigen::VectorXd v = eigen.eigenvectors().col(0);  // the most negative direction of K(u)
    const StepDamping damping(body, u);
    CAPTURE(eigen.eigenvalues()[0], eigen.eigenvalues().cwiseAbs().maxCoeff());
    REQUIRE(v.dot(K * v) < -1e-3 * eigen.eigenvalues().cwiseAbs().maxCoeff());  // βK(u) would put energy in
    CHECK(v.dot(damping.times(v)) >= -1e-12 * 0.02 * eigen.eigenvalues().cwiseAbs().maxCoeff());
    const Eigen::VectorXd eigenvalues = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(
        Eigen::MatrixXd(damping.start_stiffness())).eigenvalues();
    CHECK(eigenvalues.minCoeff() >= -1e-12 * eigenvalues.maxCoeff());  // K_t is positive semi-definite
}

TEST_CASE("damped Newton backward Euler on a linear body is chapter 10's damped theta = 1 step", "[ex12.9]")
{
    for (const auto& [alpha, beta] : {std::pair{0.02, 0.0}, std::pair{0.0, 0.01}, std::pair{0.02, 0.01}}) {
        const dynamics::Scene scene = damped_cantilever(alpha, beta, true);
        dynamics::Body newton_body(scene), theta_body(scene);
        NewtonBackwardEuler newton;
        dynamics::ThetaMethod theta(1.0);
        dynamics::State a = moving_state(newton_body, 61), b = moving_state(theta_body, 61);
        const int steps = 20;
        double newton_damping = 0.0, theta_damping = 0.0;
        for (int k = 0; k < steps; ++k) {
            const dynamics::StepInfo info = newton.step(newton_body, scene.time_step, a);
            newton_damping += info.damping_work;
            theta_damping += theta.step(theta_body, scene.time_step, b).damping_work;
            CHECK(info.newton_iterations == 1);
        }
        const double bound = test::trajectory_roundoff(theta_body, scene.time_step, 1.0, steps);
        CAPTURE(alpha, beta, sci(bound), sci((a.u - b.u).norm() / b.u.norm()), sci((a.v - b.v).norm() / b.v.norm()));
        CHECK_THAT(entries_of(a.u), EntriesNear(b.u, bound * b.u.norm()));
        CHECK_THAT(entries_of(a.v), EntriesNear(b.v, bound * b.v.norm()));
        CHECK(newton_damping > 0.0);
        CHECK(std::abs(newton_damping - theta_damping) <= bound * theta_damping);
    }
}

TEST_CASE("a damped swing loses energy: damping's books against D written out, backward Euler adds none", "[ex12.9]")
{
    dynamics::Scene scene = dynamics::cantilever_scene({2e5, 0.45, 1100.0}, 6, 0.5);  // chapter 11's soft swing
    const auto swing = [&](const dynamics::Damping& damping, double& computed_damping) {
        scene.damping = damping;
        dynamics::Body body(scene, make_force_model("stable-neo-hookean", scene.mesh, scene.material));
        // An independent model for the damping's K_t: definite_stiffness at the step's start.
        const auto reference = make_force_model("stable-neo-hookean", scene.mesh, scene.material);
        NewtonBackwardEuler newton;
        dynamics::Simulation simulation(body, newton, dynamics::initial_state(body));
        Eigen::VectorXd start = Eigen::VectorXd::Zero(body.dofs().full_size());
        double worst_gain = 0.0, largest = 0.0;
        computed_damping = 0.0;
        simulation.run(dynamics::step_count(scene.duration, scene.time_step),
                       [&](const dynamics::State& state, const dynamics::StepRecord& record) {
                           const dynamics::SparseMatrix& K = reference->definite_stiffness(start);
                           const Eigen::VectorXd Dv = damping.alpha * (body.mass_matrix() * state.v) + damping.beta * (K * state.v);
                           computed_damping += state.step > 0 ? scene.time_step * state.v.dot(Dv) : 0.0;
                           start = state.u;
                           worst_gain = std::min(worst_gain, record.integrator_dissipated);
                           largest = std::max(largest, record.energies.magnitude());
                           CHECK(record.damping_dissipated == Approx(computed_damping).epsilon(1e-9).margin(1e-300));
                       });
        CAPTURE(damping.alpha, damping.beta, sci(worst_gain), sci(largest));
        CHECK(worst_gain >= -1e-9 * largest);  // the integrator itself never added energy
        return simulation.last();
    };
    double damped_sum = 0.0, undamped_sum = 0.0;
    const dynamics::StepRecord undamped = swing({}, undamped_sum);
    const dynamics::StepRecord damped = swing({0.02, 0.02}, damped_sum);
    CAPTURE(undamped.energies.total(), damped.energies.total(), damped.damping_dissipated);
    CHECK(undamped.damping_dissipated == 0.0);
    CHECK(damped.damping_dissipated > 0.0);
    // From rest (H(0) = 0) the damped swing ends lower: damping took out what it booked, and
    // backward Euler's own dissipation (≥ 0 above) comes on top.
    CHECK(damped.energies.total() <= -damped.damping_dissipated + 1e-9 * damped.energies.magnitude());
    CHECK(damped.energies.total() < undamped.energies.total());
}

TEST_CASE("pins translating at constant speed carry a damped stable neo-Hookean body rigidly", "[ex12.9]")
{
    // β K_t c = 0 for a translation c (K annihilates rigid motion); α M c would drag against the
    // fixed frame, so α = 0 here.
    dynamics::Scene scene = damped_cantilever(0.0, 0.02);
    dynamics::Body body(scene, make_force_model("stable-neo-hookean", scene.mesh, scene.material));
    const Eigen::Vector3d c(0.3, -0.2, 0.5);
    const Eigen::VectorXd velocity = c.replicate(body.dofs().full_size() / 3, 1);
    body.set_pin_velocity(velocity.cwiseProduct(Eigen::VectorXd::Ones(velocity.size()) - body.dofs().free_mask()));
    NewtonBackwardEuler newton;
    dynamics::Simulation simulation(body, newton, dynamics::initial_state(body, {}, velocity));
    const int steps = 40;
    double damping = 0.0, boundary = 0.0, strain = 0.0;
    simulation.run(steps, [&](const dynamics::State& state, const dynamics::StepRecord& record) {
        damping = record.damping_dissipated;
        boundary = record.work_in;
        strain = std::max(strain, std::abs(state.elastic_energy));
    });
    const dynamics::State& state = simulation.state();
    const double kinetic = dynamics::kinetic_energy(body.mass_matrix(), velocity), eps = 2.220446049250313e-16;
    // K c and f(t c) vanish for a translation in exact arithmetic; in floating point each is a sum
    // whose round-off is at most a few hundred ε times Σ_ij |K_ij| |c_i| |c_j| (K at rest = K_t).
    const Eigen::VectorXd size = velocity.cwiseAbs();
    const auto rest = make_force_model("stable-neo-hookean", scene.mesh, scene.material);
    const double roundoff = 300.0 * eps * size.dot(rest->definite_stiffness(Eigen::VectorXd::Zero(size.size())).cwiseAbs() * size);
    const double dt = scene.time_step;
    CAPTURE(sci((state.u - state.time * velocity).cwiseAbs().maxCoeff()), sci((state.v - velocity).cwiseAbs().maxCoeff()),
            sci(damping), sci(boundary), sci(strain), sci(kinetic), sci(roundoff));
    CHECK((state.u - state.time * velocity).cwiseAbs().maxCoeff() <= 10.0 * steps * eps * state.time * c.norm());
    CHECK((state.v - velocity).cwiseAbs().maxCoeff() <= 10.0 * steps * eps * c.norm());
    CHECK(std::abs(damping) <= steps * dt * 0.02 * roundoff);                   // Δt β cᵀ K_t c a step
    CHECK(std::abs(boundary) <= steps * dt * (0.02 + state.time) * roundoff);   // Δt cᵀ(β K_t c − f(t c))_p
    CHECK(strain <= 10.0 * steps * eps * kinetic);
    CHECK(std::abs(damping) + std::abs(boundary) <= 1e-9 * kinetic);  // far below anything physical
}

TEST_CASE("moving pins in Newton backward Euler: chapter 10's theta = 1 step and boundary work on a linear body",
          "[ex12.9]")
{
    for (const dynamics::MassModel mass : {dynamics::MassModel::lumped, dynamics::MassModel::consistent}) {
        dynamics::Scene scene = damped_cantilever(0.0, 0.002);
        scene.mass = mass;  // consistent: the pins reach the free dofs through M_fp too
        dynamics::Body newton_body(scene), theta_body(scene);
        NewtonBackwardEuler newton;
        dynamics::ThetaMethod theta(1.0);
        dynamics::Simulation a(newton_body, newton, dynamics::initial_state(newton_body));
        dynamics::Simulation b(theta_body, theta, dynamics::initial_state(theta_body));
        const Eigen::Vector3d c(0.0, 0.05, 0.1);
        a.set_before_step(shaking_pins(c, 20.0, scene.time_step));
        b.set_before_step(shaking_pins(c, 20.0, scene.time_step));
        const int steps = 30;
        a.run(steps);
        b.run(steps);
        const double bound = test::trajectory_roundoff(theta_body, scene.time_step, 1.0, steps);
        const dynamics::State &x = a.state(), &y = b.state();
        CAPTURE(mass == dynamics::MassModel::consistent, sci(bound), sci((x.u - y.u).norm() / y.u.norm()),
                a.last().work_in, b.last().work_in);
        REQUIRE(std::abs(b.last().work_in) > 1e-6);  // the pins did real work
        CHECK_THAT(entries_of(x.u), EntriesNear(y.u, bound * y.u.norm()));
        CHECK_THAT(entries_of(x.v), EntriesNear(y.v, bound * y.v.norm()));
        CHECK(std::abs(a.last().work_in - b.last().work_in) <= bound * std::abs(b.last().work_in));
        CHECK(std::abs(a.last().damping_dissipated - b.last().damping_dissipated) <= bound * b.last().damping_dissipated);
        // The pins are where their motion puts them: g(t) = c sin(ωt)/ω.
        const Eigen::Vector3d g = c * std::sin(20.0 * x.time) / 20.0;
        for (const int v : scene.pinned)
            CHECK_THAT(entries_of(x.u.segment<3>(3 * v)), EntriesNear(g, 1e-14));
    }
}

TEST_CASE("moving pins on stable neo-Hookean: backward Euler's books balance and it never adds energy", "[ex12.9]")
{
    dynamics::Scene scene = damped_cantilever(0.0, 0.0);
    scene.material = {2e5, 0.45, 1100.0};
    dynamics::Body body(scene, make_force_model("stable-neo-hookean", scene.mesh, scene.material));
    NewtonBackwardEuler newton;
    dynamics::Simulation simulation(body, newton, dynamics::initial_state(body));
    simulation.set_before_step(shaking_pins(Eigen::Vector3d(0.0, 0.2, 0.4), 20.0, scene.time_step));
    double lowest = 0.0, largest = 0.0;
    simulation.run(30, [&](const dynamics::State&, const dynamics::StepRecord& record) {
        lowest = std::min(lowest, record.integrator_dissipated);
        largest = std::max(largest, record.energies.magnitude());
    });
    CAPTURE(sci(lowest), sci(largest), simulation.last().work_in);
    CHECK(std::abs(simulation.last().work_in) > 1e-3 * largest);  // the pins drove the motion
    CHECK(lowest >= -1e-9 * largest);
}
