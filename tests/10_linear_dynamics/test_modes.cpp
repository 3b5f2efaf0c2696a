// Chapter 10: modes and the scalar oscillator they reduce every step to. The simulated body must
// follow the closed-form modal recurrence to round-off. docs/10_linear_dynamics.md#modes
#include "10_linear_dynamics/modes.hpp"
#include "dynamics_fixtures.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>

#include <complex>
#include <cmath>

using namespace fem::dynamics;
using fem::test::cantilever_scene;
using Catch::Matchers::Contains;

namespace {

/// Starts the cantilever at rest in its first mode (amplitude: a tip displacement of ~1 mm), runs
/// `steps` steps with `integrator`, and returns the largest deviation of the tip trajectory from
/// amplitude · (Gⁿ)₀₀ · φ₁(tip), relative to the largest tip displacement.
double recurrence_deviation(const Scene& scene, Integrator& integrator, const Eigen::Matrix2d& G, int steps)
{
    Body body(scene);
    const auto [K, M] = fem::test::free_matrices(body);
    const Modes modes = lowest_modes_dense(K, M, 1);
    const int tip_dof = 3 * fem::test::tip_vertex(scene) + 2;
    Eigen::VectorXd phi = fem::test::expanded(body, modes.shapes.col(0));
    phi *= 1e-3 / std::abs(phi[tip_dof]);
    return modal_recurrence_deviation(body, integrator, phi, tip_dof, G, steps);
}

}  // namespace

TEST_CASE("oscillator step matrix: the theta-step's two equations solved, and backward Euler's eigenvalues",
          "[ex10.7]")
{
    for (const double theta : {1.0, 0.5, 0.8})
        for (const double xi : {0.0, 0.05, 1.0, 3.0})
            for (const double omega_dt : {0.01, 1.0, 30.0}) {
                const double omega = 20.0, dt = omega_dt / omega;
                const Eigen::Matrix2d G = oscillator_step_matrix(omega, xi, dt, theta);
                const Eigen::Matrix2d reference = fem::test::theta_step_by_solving(omega, xi, dt, theta);
                CAPTURE(theta, xi, omega_dt);
                CHECK((G - reference).cwiseAbs().maxCoeff() <= 1e-14 * reference.cwiseAbs().maxCoeff());
            }
    // Backward Euler, undamped: eigenvalues 1/(1 ∓ iωΔt).
    const double omega = 20.0, dt = 0.03;
    const Eigen::EigenSolver<Eigen::Matrix2d> eig(oscillator_step_matrix(omega, 0.0, dt, 1.0));
    for (int k = 0; k < 2; ++k) {
        const std::complex<double> lambda = eig.eigenvalues()[k];
        CHECK(std::abs(lambda) == Approx(1.0 / std::sqrt(1.0 + omega * omega * dt * dt)).epsilon(1e-13));
        CHECK(std::abs(std::arg(lambda)) == Approx(std::atan(omega * dt)).epsilon(1e-13));
    }
    // The midpoint rule keeps the undamped oscillator's energy: |λ| = 1.
    const Eigen::EigenSolver<Eigen::Matrix2d> mid(oscillator_step_matrix(omega, 0.0, dt, 0.5));
    CHECK(std::abs(mid.eigenvalues()[0]) == Approx(1.0).epsilon(1e-14));
    CHECK_THROWS_AS(oscillator_step_matrix(-1.0, 0.0, dt), fem::Error);
    CHECK_THROWS_AS(oscillator_step_matrix(omega, 0.0, 0.0), fem::Error);
    CHECK_THROWS_AS(oscillator_step_matrix(omega, 0.0, dt, 0.3), fem::Error);
}

// The recurrence uses ω₁ from the eigensolver, whose λ₁ = ω₁² carries a relative round-off of
// ε λ_max/λ₁; the phase ω₁ t accumulates it. A coarse beam (ω_max/ω₁ ≈ 100) keeps that near 1e-12,
// so the 1e-10 below tests the integrator, not the eigensolver.
TEST_CASE("a body started in mode 1 follows the modal recurrence of backward Euler and the midpoint rule",
          "[ex10.4]")
{
    const Scene scene = cantilever_scene(6, 1);
    Body body(scene);
    const auto [K, M] = fem::test::free_matrices(body);
    const double omega = lowest_modes_dense(K, M, 1).omega[0];
    for (const double theta : {1.0, 0.5}) {
        ThetaMethod integrator(theta);
        const Eigen::Matrix2d G = fem::test::theta_step_by_solving(omega, 0.0, scene.time_step, theta);
        const double deviation = recurrence_deviation(scene, integrator, G, 100);
        CAPTURE(theta, fem::test::sci(deviation));
        CHECK(deviation <= 1e-10);
    }
}

TEST_CASE("Rayleigh damping acts on each mode with xi = alpha/(2 omega) + beta omega/2, each term alone",
          "[ex10.4]")
{
    Scene scene = cantilever_scene(6, 1);
    Body body(scene);
    const auto [K, M] = fem::test::free_matrices(body);
    const double omega = lowest_modes_dense(K, M, 1).omega[0];
    for (const Damping damping : {Damping{0.02, 0.0}, Damping{0.0, 0.02}}) {
        scene.damping = damping;
        const double xi = damping.alpha / (2.0 * omega) + damping.beta * omega / 2.0;
        CHECK(damping_ratio(damping, omega) == Approx(xi));
        for (const double theta : {1.0, 0.5}) {
            ThetaMethod integrator(theta);
            const double deviation = recurrence_deviation(
                scene, integrator, fem::test::theta_step_by_solving(omega, xi, scene.time_step, theta), 100);
            // The undamped recurrence is far off: the test tells damping from no damping.
            ThetaMethod again(theta);
            const double undamped = recurrence_deviation(
                scene, again, fem::test::theta_step_by_solving(omega, 0.0, scene.time_step, theta), 100);
            CAPTURE(damping.alpha, damping.beta, theta, deviation, undamped);
            CHECK(deviation <= 1e-10);
            CHECK(undamped >= 1e-4);
        }
    }
}

TEST_CASE("backward Euler's amplitude factor 1/sqrt(1 + w^2 dt^2) and phase atan(w dt) per step, measured",
          "[ex10.4]")
{
    Scene scene = cantilever_scene();
    Body body(scene);
    const auto [K, M] = fem::test::free_matrices(body);
    const Modes modes = lowest_modes_dense(K, M, 1);
    const double omega = modes.omega[0];
    for (const double omega_dt : {0.1, 1.0, 3.0}) {
        scene.time_step = omega_dt / omega;
        scene.duration = 0.0;
        Body moving(scene);
        ThetaMethod integrator(1.0);
        const Eigen::VectorXd phi = fem::test::expanded(moving, modes.shapes.col(0));
        Simulation simulation(moving, integrator, initial_state(moving, 1e-3 * phi));
        // w = p + iωq, with q = φᵀMu and p = φᵀMv, is multiplied by λ = 1/(1 − iωΔt) per step.
        std::complex<double> previous;
        double worst_modulus = 0.0, worst_phase = 0.0;
        simulation.run(20, [&](const State& state, const StepRecord&) {
            const Eigen::VectorXd Mphi = moving.mass_matrix() * phi;
            const std::complex<double> w(Mphi.dot(state.v), omega * Mphi.dot(state.u));
            if (state.step > 0) {
                const std::complex<double> lambda = w / previous;
                worst_modulus = std::max(worst_modulus, std::abs(std::abs(lambda) * std::sqrt(1.0 + omega_dt * omega_dt) - 1.0));
                worst_phase = std::max(worst_phase, std::abs(std::arg(lambda) - std::atan(omega_dt)));
            }
            previous = w;
        });
        CAPTURE(omega_dt, worst_modulus, worst_phase);
        CHECK(worst_modulus <= 1e-10);
        CHECK(worst_phase <= 1e-10);
        // The phase error per step, ωΔt − atan(ωΔt), is what the docs tabulate: positive, O(Δt³).
        CHECK(omega_dt - std::atan(omega_dt) > 0.0);
    }
}

TEST_CASE("modes: Spectra's shift-invert Lanczos on our Cholesky matches the dense generalized eigensolver",
          "[ch10]")
{
    for (const MassModel mass : {MassModel::lumped, MassModel::consistent}) {
        Scene scene = cantilever_scene(10, 2);
        scene.mass = mass;
        Body body(scene);
        const auto [K, M] = fem::test::free_matrices(body);
        const Modes dense = lowest_modes_dense(K, M, 6);
        const Modes lanczos = lowest_modes(K, M, 6);
        for (int k = 0; k < 6; ++k) {
            CHECK(lanczos.omega[k] == Approx(dense.omega[k]).epsilon(1e-9));
            // Shapes: M-orthonormal, and K φ = ω² M φ.
            const Eigen::VectorXd phi = lanczos.shapes.col(k);
            CHECK(phi.dot(M * phi) == Approx(1.0).epsilon(1e-10));
            CHECK((K * phi - lanczos.omega[k] * lanczos.omega[k] * (M * phi)).norm() <=
                  1e-7 * (K * phi).norm());
        }
        // Rigid-body free K is refused by the shift-invert (it needs K positive definite).
        scene.pinned.clear();
        Body free(scene);
        const auto [K_free, M_free] = fem::test::free_matrices(free);
        CHECK_THROWS_AS(lowest_modes(K_free, M_free, 3), fem::Error);
        // ...but the dense solver sees the six rigid modes at ω ≈ 0.
        if (mass == MassModel::lumped) {
            const Modes rigid = lowest_modes_dense(K_free, M_free, 7);
            CHECK(rigid.omega[5] <= 1e-5 * rigid.omega[6]);
            CHECK(rigid.omega[6] > 1.0);
        }
    }
}

TEST_CASE("omega_max: Lanczos and power iteration against the dense eigensolver", "[ex10.8]")
{
    Body body(cantilever_scene(6, 2));
    const auto [K, M] = fem::test::free_matrices(body);
    const double dense = std::sqrt(Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd>(
                                       Eigen::MatrixXd(K), Eigen::MatrixXd(M), Eigen::EigenvaluesOnly)
                                       .eigenvalues()
                                       .maxCoeff());
    CHECK(highest_frequency(K, M) == Approx(dense).epsilon(1e-9));
    const PowerIteration power = power_iteration(K, body.dofs().gather(body.dof_masses()), 1e-12, 100000);
    CAPTURE(power.iterations);
    CHECK(power.converged);
    CHECK(power.omega <= dense * (1.0 + 1e-12));  // a Rayleigh quotient never overshoots
    CHECK(power.omega == Approx(dense).epsilon(1e-4));
    const PowerIteration short_run = power_iteration(K, body.dofs().gather(body.dof_masses()), 1e-12, 3);
    CHECK_FALSE(short_run.converged);
    CHECK(short_run.iterations == 3);
    CHECK_THROWS_AS(power_iteration(K, Eigen::VectorXd::Zero(K.rows()), 1e-8), fem::Error);
    CHECK_THROWS_AS(power_iteration(K, body.dofs().gather(body.dof_masses()), 0.0), fem::Error);
}

TEST_CASE("explicit stability limit: 2/omega undamped, lowered by damping, the edge of the oscillator's stability",
          "[ex10.6]")
{
    CHECK(explicit_stability_limit(100.0) == Approx(0.02));
    CHECK(explicit_stability_limit(100.0, 0.3) == Approx(0.02 * (std::sqrt(1.09) - 0.3)));
    for (const double xi : {0.0, 0.1, 0.7}) {
        const double omega = 50.0, limit = explicit_stability_limit(omega, xi);
        const auto radius = [&](double dt) {
            const Eigen::EigenSolver<Eigen::Matrix2d> eig(symplectic_oscillator_step_matrix(omega, xi, dt));
            return std::max(std::abs(eig.eigenvalues()[0]), std::abs(eig.eigenvalues()[1]));
        };
        CAPTURE(xi);
        CHECK(radius(0.99 * limit) <= 1.0 + 1e-12);
        CHECK(radius(1.01 * limit) > 1.0 + 1e-3);
    }
    CHECK_THROWS_AS(explicit_stability_limit(0.0), fem::Error);
    CHECK_THROWS_AS(explicit_stability_limit(10.0, -0.1), fem::Error);
}

TEST_CASE("the exact damped oscillator solves its equation in all three regimes", "[ch10]")
{
    for (const double xi : {0.0, 0.2, 1.0, 2.5}) {
        const double omega = 7.0, q0 = 0.3, p0 = -1.1, h = 1e-6;
        for (const double t : {0.0, 0.4, 1.3}) {
            const Eigen::Vector2d now = exact_oscillator(omega, xi, q0, p0, t);
            const Eigen::Vector2d ahead = exact_oscillator(omega, xi, q0, p0, t + h);
            const Eigen::Vector2d behind = exact_oscillator(omega, xi, q0, p0, t - h);
            const double q_dot = (ahead[0] - behind[0]) / (2 * h), p_dot = (ahead[1] - behind[1]) / (2 * h);
            CAPTURE(xi, t);
            CHECK(q_dot == Approx(now[1]).margin(1e-6));
            CHECK(p_dot + 2 * xi * omega * now[1] + omega * omega * now[0] == Approx(0.0).margin(1e-5));
        }
        CHECK(exact_oscillator(7.0, xi, 0.3, -1.1, 0.0).isApprox(Eigen::Vector2d(0.3, -1.1), 1e-14));
    }
}

TEST_CASE("first bending frequency: linear tets lock, converging to Euler-Bernoulli from above", "[ch10]")
{
    const double Y = 2e6, rho = 1100.0, L = 0.2, a = 0.02;
    const double f_beam = euler_bernoulli_first_frequency(Y, rho, L, a * a, std::pow(a, 4) / 12.0);
    CHECK(f_beam == Approx(3.4446).epsilon(1e-3));  // (1.8751²/2π) √(EI/(ρAL⁴)) by hand
    // (mesh ratio − 1) at three refinements: positive (too stiff) and at least halved each time.
    std::vector<double> excess;
    for (const auto& [along, across] : {std::pair{10, 1}, std::pair{20, 2}, std::pair{40, 4}}) {
        Scene scene = cantilever_scene(along, across);
        Body body(scene);
        const auto [K, M] = fem::test::free_matrices(body);
        excess.push_back(lowest_modes(K, M, 1).omega[0] / (2.0 * 3.14159265358979323846) / f_beam - 1.0);
    }
    CAPTURE(excess[0], excess[1], excess[2]);
    CHECK(excess[2] > 0.0);
    CHECK(excess[1] < 0.5 * excess[0]);
    CHECK(excess[2] < 0.5 * excess[1]);
    CHECK_THROWS_AS(euler_bernoulli_first_frequency(Y, rho, 0.0, 1.0, 1.0), fem::Error);
}
