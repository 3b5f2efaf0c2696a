// Chapter 12: backward Euler by Newton's method: the objective and its gradient against finite
// differences and chapter 10's linear step, the line search, quadratic convergence, hard cases and the
// solver by name. The force model's own tests: test_hyperelastic_model.cpp.
// docs/12_hyperelastic_newton.md
#include "12_hyperelastic_newton/force_models.hpp"
#include "12_hyperelastic_newton/hyperelastic.hpp"
#include "12_hyperelastic_newton/newton.hpp"

#include "06_assembly/assembly.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"
#include "common/random.hpp"
#include "common/vtk_io.hpp"

#include "../common/test_support.hpp"
#include "pinned_cube.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Cholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

using namespace fem;
using namespace fem::hyper;
using fem::test::EntriesNear;
using fem::test::entries_of;
using Catch::Matchers::Contains;

using fem::test::pinned_cube;

TEST_CASE("the backward Euler objective: its terms, and its minimum at chapter 10's step for a linear body", "[ex12.7]")
{
    dynamics::Scene scene = pinned_cube(1e5, 0.3);
    dynamics::Body body(scene);
    dynamics::State state = dynamics::initial_state(body);
    state.v = 0.1 * fem::random_vector(state.v.size(), 21).cwiseProduct(body.dofs().free_mask());
    const double dt = scene.time_step;
    const Eigen::VectorXd v = 0.2 * fem::random_vector(state.v.size(), 22).cwiseProduct(body.dofs().free_mask());
    // E(v) written out: ½ΔvᵀMΔv + ½ uᵀKu (linear U) − Δt vᵀ f_ext.
    const Eigen::VectorXd u = state.u + dt * v, change = v - state.v;
    Eigen::VectorXd forces;
    const double elastic = body.model().evaluate(u, forces);
    CHECK(backward_euler_objective(body, state, dt, v) ==
          Approx(0.5 * change.dot(body.mass_matrix() * change) + elastic - dt * v.dot(body.external_forces())).epsilon(1e-12));
    // Chapter 10's backward Euler step lands on the minimum: E grows in every direction from it.
    dynamics::ThetaMethod theta(1.0);
    dynamics::State stepped = state;
    theta.step(body, dt, stepped);
    const double at_step = backward_euler_objective(body, state, dt, stepped.v);
    for (unsigned seed = 30; seed < 35; ++seed) {
        const Eigen::VectorXd nudge = 1e-3 * fem::random_vector(v.size(), seed).cwiseProduct(body.dofs().free_mask());
        CHECK(backward_euler_objective(body, state, dt, stepped.v + nudge) > at_step);
    }
}

TEST_CASE("the backward Euler gradient: the objective's by finite differences, zero at chapter 10's step", "[ex12.8]")
{
    dynamics::Scene scene = pinned_cube(1e5, 0.3);
    dynamics::Body body(scene);
    dynamics::State state = dynamics::initial_state(body);
    const double dt = scene.time_step;
    const Eigen::VectorXd v = 0.2 * fem::random_vector(state.v.size(), 23).cwiseProduct(body.dofs().free_mask());
    const Eigen::VectorXd direction = fem::random_vector(v.size(), 24).cwiseProduct(body.dofs().free_mask());
    CHECK(test::best_error(test::central_difference_errors(
              [&](double h) { return Eigen::VectorXd::Constant(1, backward_euler_objective(body, state, dt, v + h * direction)); },
              Eigen::VectorXd::Constant(1, backward_euler_gradient(body, state, dt, v).dot(direction)), 0.1)) < 1e-6);
    dynamics::ThetaMethod theta(1.0);
    dynamics::State stepped = state;
    theta.step(body, dt, stepped);
    const Eigen::VectorXd at_step = body.dofs().gather(backward_euler_gradient(body, state, dt, stepped.v));
    const double gradient_norm = at_step.norm(), allowed = 1e-10 * momentum_scale(body, state, dt);
    INFO("|grad E| at chapter 10's backward Euler step: " << gradient_norm << ", allowed " << allowed);
    CHECK(gradient_norm <= allowed);
}

TEST_CASE("Newton backward Euler: one iteration and chapter 10's step for a linear body", "[ex12.9]")
{
    dynamics::Scene scene = pinned_cube(1e5, 0.3);
    dynamics::Body newton_body(scene), theta_body(scene);
    NewtonBackwardEuler newton;
    dynamics::ThetaMethod theta(1.0);
    dynamics::State a = dynamics::initial_state(newton_body), b = dynamics::initial_state(theta_body);
    for (int k = 0; k < 5; ++k) {
        const dynamics::StepInfo info = newton.step(newton_body, scene.time_step, a);
        theta.step(theta_body, scene.time_step, b);
        CHECK(info.newton_iterations == 1);
    }
    CHECK_THAT(entries_of(a.u), EntriesNear(b.u, 1e-8 * b.u.norm()));
    CHECK_THAT(entries_of(a.v), EntriesNear(b.v, 1e-8 * b.v.norm()));
}

TEST_CASE("the line search: every accepted step decreases E by at least c alpha |slope|, where full steps overshoot",
          "[ex12.9]")
{
    // E(x) = Σ wᵢ √(1 + xᵢ²) is convex, but Newton's full step takes each xᵢ to −xᵢ³: from |xᵢ| near
    // or above 1 it overshoots, decreasing E too little or raising it. With c = 0.4 the Armijo test
    // E(x + αd) ≤ E(x) + c α ∇Eᵀd then rejects steps that a test without its c α ∇Eᵀd term, or one
    // against the E of the first iterate instead of the current one, accepts.
    const Eigen::Vector2d weights(100.0, 1.0);
    const auto energy = [&](const Eigen::VectorXd& x) {
        return weights.dot(Eigen::VectorXd((1.0 + x.array().square()).sqrt()));
    };
    const auto gradient = [&](const Eigen::VectorXd& x) {
        return Eigen::VectorXd(weights.array() * x.array() / (1.0 + x.array().square()).sqrt());
    };
    const auto curvature = [&](const Eigen::VectorXd& x) {  // the Hessian's diagonal (it is diagonal)
        return Eigen::VectorXd(weights.array() / (1.0 + x.array().square()).pow(1.5));
    };
    // The iterates in order: newton_minimize asks for the Hessian once per iterate it leaves (the
    // exact one is positive definite here), and the last is the result.
    std::vector<Eigen::VectorXd> iterates;
    dynamics::SparseMatrix hessian(2, 2);
    NewtonProblem problem;
    problem.objective = [&](const Eigen::VectorXd& x, double* magnitude) {
        if (magnitude != nullptr)
            *magnitude = energy(x);
        return energy(x);
    };
    problem.gradient = gradient;
    problem.hessian = [&](const Eigen::VectorXd& x, bool) -> const dynamics::SparseMatrix& {
        iterates.push_back(x);
        hessian = Eigen::MatrixXd(curvature(x).asDiagonal()).sparseView();
        return hessian;
    };
    problem.scale = 1.0;
    problem.what = "the overshooting test problem";
    NewtonOptions options;
    options.armijo = 0.4;
    options.relative_tolerance = 1e-10;
    const auto solver = cg::make_solver("default");
    std::string failure;  // a wrong line search may end in the iteration cap: the steps below say why
    try {
        const NewtonResult result = newton_minimize(problem, Eigen::Vector2d(0.9, 2.0), options, *solver);
        iterates.push_back(result.x);
        CHECK(result.gradient_history.back() <= options.relative_tolerance);
        CHECK(result.step_lengths.size() + 1 == iterates.size());
    } catch (const Error& e) {
        failure = e.what();
    }
    double shortest = 1.0;
    for (std::size_t k = 0; k + 1 < iterates.size(); ++k) {
        const Eigen::VectorXd& x = iterates[k];
        const Eigen::VectorXd direction = -gradient(x).cwiseQuotient(curvature(x));
        // The step taken, measured along the Newton direction computed here.
        const double alpha = (iterates[k + 1] - x).dot(direction) / direction.squaredNorm();
        const double slope = gradient(x).dot(direction), noise = objective_round_off * energy(x);
        shortest = std::min(shortest, alpha);
        const auto armijo_holds = [&](double a) {
            return energy(x + a * direction) <= energy(x) + options.armijo * a * slope + noise;
        };
        INFO("iteration " << k << ": E " << energy(x) << " -> " << energy(iterates[k + 1]) << " with alpha " << alpha
                          << "; Armijo asks E(x + alpha d) <= E(x) + c alpha grad^T d = "
                          << energy(x) + options.armijo * alpha * slope
                          << ", E(x) of the current iterate (not of the first), c alpha grad^T d included");
        CHECK((iterates[k + 1] - (x + alpha * direction)).norm() <= 1e-12 * (1.0 + x.norm()));
        CHECK(armijo_holds(alpha));
        if (alpha < 1.0)
            CHECK_FALSE(armijo_holds(alpha / options.shrink));  // the largest α = shrinkᵏ that passes
    }
    CHECK(shortest < 1.0);  // full steps were rejected: the case the test is about
    INFO(failure);
    CHECK(failure.empty());
}

TEST_CASE("the line search where E's differences are round-off: the slopes decide, and Newton converges", "[ex12.9]")
{
    // E(x) = Σ wᵢ √(1 + (xᵢ − cᵢ)²) plus a noise of ±η that jumps with every bit of x: the round-off
    // of a body's energy whose terms cancel (a resting or translated body), here η = 1e-9, 100 times
    // what objective_round_off × E's terms allows and 1/100 of objective_resolution × them. The
    // gradient is exact. Near the minimum Newton's decrease (~|∇E|²) falls far below η: E's Armijo
    // test then passes or fails by the noise's draw, and only the slopes can tell a good step.
    const Eigen::Vector2d weights(100.0, 1.0), centre(0.3, -0.7);
    const double noise_amplitude = 1e-9;
    const auto noise = [&](const Eigen::VectorXd& x) {  // splitmix64 of x's bits, mapped to [−1, 1]
        std::uint64_t h = 0x9e3779b97f4a7c15ULL;
        for (Eigen::Index i = 0; i < x.size(); ++i) {
            std::uint64_t bits = 0;
            std::memcpy(&bits, &x[i], sizeof bits);
            h ^= bits + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
            h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ULL;
            h = (h ^ (h >> 27)) * 0x94d049bb133111ebULL;
            h ^= h >> 31;
        }
        return 2.0 * (static_cast<double>(h >> 11) / 9007199254740992.0) - 1.0;
    };
    const auto smooth = [&](const Eigen::VectorXd& x) {
        return weights.dot(Eigen::VectorXd((1.0 + (x - centre).array().square()).sqrt()));
    };
    const auto gradient = [&](const Eigen::VectorXd& x) {
        const Eigen::ArrayXd y = (x - centre).array();
        return Eigen::VectorXd(weights.array() * y / (1.0 + y.square()).sqrt());
    };
    REQUIRE(noise_amplitude > 10.0 * objective_round_off * weights.sum());
    REQUIRE(noise_amplitude < 0.1 * objective_resolution * weights.sum());
    // Newton with the Hessian times hessian_scale (1: exact; 1/3: a model whose full steps overshoot
    // threefold, as a stale factor's can); the iterates in order, recorded where the Hessian is asked.
    const auto minimise = [&](double hessian_scale, const Eigen::Vector2d& start, std::vector<Eigen::VectorXd>& iterates) {
        dynamics::SparseMatrix hessian(2, 2);
        NewtonProblem problem;
        problem.objective = [&](const Eigen::VectorXd& x, double* magnitude) {
            if (magnitude != nullptr)
                *magnitude = smooth(x);  // the terms' size, which does not show the noise
            return smooth(x) + noise_amplitude * noise(x);
        };
        problem.gradient = gradient;
        problem.hessian = [&](const Eigen::VectorXd& x, bool) -> const dynamics::SparseMatrix& {
            iterates.push_back(x);
            const Eigen::ArrayXd y = (x - centre).array();
            const Eigen::VectorXd diagonal = hessian_scale * weights.array() / (1.0 + y.square()).pow(1.5);
            hessian = Eigen::MatrixXd(diagonal.asDiagonal()).sparseView();
            return hessian;
        };
        problem.scale = weights.norm();
        problem.what = "the noisy test problem";
        NewtonOptions options;
        options.relative_tolerance = 1e-12;
        const auto solver = cg::make_solver("default");
        NewtonResult result = newton_minimize(problem, start, options, *solver);
        iterates.push_back(result.x);
        return result;
    };

    SECTION("the exact Hessian: Newton's quadratic convergence, none of it lost to the noise")
    {
        std::vector<Eigen::VectorXd> iterates;
        NewtonResult result;
        REQUIRE_NOTHROW(result = minimise(1.0, Eigen::Vector2d(0.9, 0.4), iterates));
        INFO("iterations " << result.iterations << ", last |gradient| / scale " << result.gradient_history.back());
        CHECK(result.gradient_history.back() <= 1e-12);
        CHECK((result.x - centre).norm() <= 1e-10);
        CHECK(result.iterations <= 10);
    }
    SECTION("a Hessian a third of the true one, from where every change is below the resolution: each "
            "accepted step passes Armijo by the trapezoid rule, and the overshooting full steps are refused")
    {
        const Eigen::Vector2d start = centre + Eigen::Vector2d(1e-7, -2e-7);
        std::vector<Eigen::VectorXd> iterates;
        std::string failure;  // a wrong line search may end in the iteration cap: the steps below say why
        try {
            const NewtonResult result = minimise(1.0 / 3.0, start, iterates);
            CHECK(result.gradient_history.back() <= 1e-12);
        } catch (const Error& e) {
            failure = e.what();
        }
        REQUIRE(iterates.size() > 2);
        for (std::size_t k = 0; k + 1 < iterates.size(); ++k) {
            const Eigen::VectorXd step = iterates[k + 1] - iterates[k];
            const double slope_start = gradient(iterates[k]).dot(step), slope_end = gradient(iterates[k + 1]).dot(step);
            // α d over the direction the 1/3 Hessian gives: 1 for a full step (3 Newton steps).
            const Eigen::VectorXd full = -3.0 * gradient(iterates[k]).cwiseQuotient(Eigen::VectorXd(
                                             weights.array() / (1.0 + (iterates[k] - centre).array().square()).pow(1.5)));
            const double alpha = step.dot(full) / full.squaredNorm();
            INFO("iteration " << k << ": alpha " << alpha << ", grad^T (alpha d) at x " << slope_start << " and at x + alpha d "
                              << slope_end << "; Armijo by the trapezoid rule asks (start + end)/2 <= c * start = "
                              << NewtonOptions{}.armijo * slope_start << " (the end slope at x + alpha d, not at x)");
            CHECK(0.5 * (slope_start + slope_end) <= NewtonOptions{}.armijo * slope_start);
            CHECK(alpha < 1.0);  // every full step overshoots threefold: refused
        }
        INFO(failure);
        CHECK(failure.empty());
    }
}

TEST_CASE("Newton backward Euler: the gradient and Hessian of E by finite differences, quadratic convergence",
          "[ex12.9]")
{
    dynamics::Scene scene = pinned_cube(1e5, 0.4);
    scene.gravity = Eigen::Vector3d(0.0, 0.0, -200.0);  // a large sag: a nonlinear step
    dynamics::Body body(scene, std::make_unique<HyperelasticElasticity>(scene.mesh, make_material("neo-hookean", 1e5, 0.4)));
    const dynamics::State state = dynamics::initial_state(body);
    const Eigen::VectorXd v = 0.3 * fem::random_vector(state.v.size(), 9).cwiseProduct(body.dofs().free_mask());
    const Eigen::VectorXd direction = fem::random_vector(v.size(), 10).cwiseProduct(body.dofs().free_mask());
    const double dt = scene.time_step;
    const Eigen::VectorXd gradient = backward_euler_gradient(body, state, dt, v);
    CHECK(test::best_error(test::central_difference_errors(
              [&](double h) { return Eigen::VectorXd::Constant(1, backward_euler_objective(body, state, dt, v + h * direction)); },
              Eigen::VectorXd::Constant(1, gradient.dot(direction)), 0.1)) < 1e-6);
    HyperelasticElasticity exact(scene.mesh, make_material("neo-hookean", 1e5, 0.4));  // stiffness(): no projection
    const Eigen::VectorXd H_d = dynamics::step_matrix(body.mass_matrix(), exact.stiffness(state.u + dt * v),
                                                      dynamics::Damping{}, dt, 1.0) * direction;
    CHECK(test::best_error(test::central_difference_errors([&](double h) { return backward_euler_gradient(body, state, dt, v + h * direction); },
                                               H_d, 0.1)) < 1e-6);

    // Quadratic convergence needs the true Hessian.
    dynamics::Body& exact_body = body;
    NewtonOptions options;
    options.relative_tolerance = 1e-8;
    options.hessian = HessianChoice::exact;
    NewtonBackwardEuler newton(options);
    dynamics::State stepped = dynamics::initial_state(exact_body);
    newton.step(exact_body, dt, stepped);
    const std::vector<double>& g = newton.last().gradient_history;
    CAPTURE(g);
    REQUIRE(g.size() >= 4);
    // Near the solution the gradient falls quadratically: g_{k+1} ≤ C g_k² with a modest C, on the
    // last iteration that starts below 10⁻² (full steps there: α = 1).
    std::size_t k = g.size() - 2;
    while (k > 0 && g[k] < 1e-6)
        --k;
    CAPTURE(g[k], g[k + 1]);
    CHECK(g[k] < 1e-2);
    CHECK(g[k + 1] <= 100.0 * g[k] * g[k]);
    CHECK(g.back() <= 1e-8);
    for (const double alpha : newton.last().step_lengths)
        CHECK(alpha > 0.0);
}

TEST_CASE("Newton backward Euler: the line search keeps neo-Hookean tets uninverted where plain Newton fails",
          "[ex12.9]")
{
    // A soft cube pinned at its base, its top slammed down at 40 m/s: one step of 1/24 s would move
    // the top by sixteen times the cube's height.
    dynamics::Scene scene = pinned_cube(1e5, 0.4);
    scene.gravity.setZero();
    scene.time_step = 1.0 / 24.0;
    Eigen::VectorXd v0 = Eigen::VectorXd::Zero(3 * scene.mesh.V.rows());
    for (Eigen::Index v = 0; v < scene.mesh.V.rows(); ++v)
        v0[3 * v + 2] = -400.0 * scene.mesh.V(v, 2);  // −40 m/s at the top, 0 at the pinned base
    const auto run = [&](bool line_search, double& smallest_ratio, int& iterations) {
        auto model = std::make_unique<HyperelasticElasticity>(scene.mesh, make_material("neo-hookean", 1e4, 0.4));
        const HyperelasticElasticity& view = *model;
        dynamics::Body body(scene, std::move(model));
        NewtonOptions options;
        options.line_search = line_search;
        NewtonBackwardEuler newton(options);
        dynamics::State state = dynamics::initial_state(body, {}, v0);
        const dynamics::StepInfo info = newton.step(body, scene.time_step, state);
        smallest_ratio = view.smallest_volume_ratio(state.u);
        iterations = info.newton_iterations;
    };
    double ratio = 0.0;
    int iterations = 0;
    CHECK_THROWS_WITH(run(false, ratio, iterations), Contains("det F"));  // plain Newton inverts a tet
    REQUIRE_NOTHROW(run(true, ratio, iterations));
    CAPTURE(ratio, iterations);
    CHECK(ratio > 0.0);  // every tet still positively oriented
}

TEST_CASE("stable neo-Hookean: a tet squashed through inversion recovers, neo-Hookean refuses to start", "[ex12.9]")
{
    dynamics::Scene scene;
    scene.mesh = box_mesh(1, 1, 1, Eigen::Vector3d(0.1, 0.1, 0.1));
    scene.material = {1e5, 0.4, 1000.0};
    scene.gravity.setZero();
    scene.pinned = assembly::vertices_on_plane(scene.mesh, 2, 0.0);
    scene.time_step = 1.0 / 60.0;
    // The top face pushed 1.5 heights down: through the base, every tet inverted.
    Eigen::VectorXd u0 = Eigen::VectorXd::Zero(3 * scene.mesh.V.rows());
    for (Eigen::Index v = 0; v < scene.mesh.V.rows(); ++v)
        u0[3 * v + 2] = -1.5 * scene.mesh.V(v, 2);
    auto stable_model = std::make_unique<HyperelasticElasticity>(scene.mesh, make_material("stable-neo-hookean", 1e5, 0.4));
    const HyperelasticElasticity& stable = *stable_model;
    dynamics::Body body(scene, std::move(stable_model));
    dynamics::State state = dynamics::initial_state(body, u0);
    CHECK(stable.smallest_volume_ratio(state.u) < 0.0);
    NewtonBackwardEuler newton;
    for (int k = 0; k < 60; ++k) {
        newton.step(body, scene.time_step, state);
        REQUIRE(state.u.allFinite());
    }
    CHECK(stable.smallest_volume_ratio(state.u) > 0.0);  // every tet turned right side out again
    dynamics::Body neo(scene, std::make_unique<HyperelasticElasticity>(scene.mesh, make_material("neo-hookean", 1e5, 0.4)));
    CHECK_THROWS_WITH(dynamics::initial_state(neo, u0), Contains("det F"));
}

TEST_CASE("a vibration that dies out without gravity: Newton converges every step down to underflow", "[ex12.9]")
{
    // A stretched cube released without gravity: backward Euler's damping shrinks the motion by a
    // constant factor a step, so u and v pass 1e-154 (where norms' squares underflow) after some
    // 900 steps. The relative test cannot hold there; smallest_measurable_norm ends the iteration.
    dynamics::Scene scene = pinned_cube(1e5, 0.45);
    scene.gravity.setZero();
    scene.time_step = 1.0 / 60.0;
    Eigen::VectorXd u0 = Eigen::VectorXd::Zero(3 * scene.mesh.V.rows());
    for (Eigen::Index v = 0; v < scene.mesh.V.rows(); ++v)
        u0[3 * v + 2] = 0.1 * scene.mesh.V(v, 2);
    dynamics::Body body(scene, std::make_unique<HyperelasticElasticity>(scene.mesh, make_material("stable-neo-hookean", 1e5, 0.45)));
    dynamics::State state = dynamics::initial_state(body, u0);
    NewtonBackwardEuler newton;
    double smallest = u0.cwiseAbs().maxCoeff();
    for (int k = 0; k < 1500; ++k) {
        REQUIRE_NOTHROW(newton.step(body, scene.time_step, state));
        REQUIRE(state.u.allFinite());
        smallest = std::min(smallest, state.u.cwiseAbs().maxCoeff());
    }
    CHECK(smallest < smallest_measurable_norm);  // the run did reach the regime it guards
}

TEST_CASE("statics: the hyperelastic sag tends to chapter 10's linear one as the load goes to zero, at rate 1",
          "[ex12.9]")
{
    std::vector<double> gaps;
    for (const double g : {1.0, 0.5, 0.25, 0.125}) {  // sags of 6 % of the length and less: the asymptotic range
        dynamics::Scene scene;
        scene.mesh = beam_mesh(0.2, 0.02, 0.02, 8);
        scene.material = {1e5, 0.3, 1000.0};
        scene.pinned = assembly::vertices_on_plane(scene.mesh, 0, 0.0);
        scene.gravity = Eigen::Vector3d(0.0, 0.0, -g);
        dynamics::Body hyper(scene, std::make_unique<HyperelasticElasticity>(scene.mesh, make_material("neo-hookean", 1e5, 0.3)));
        dynamics::Body linear(scene);
        NewtonOptions options;
        options.relative_tolerance = 1e-10;
        const Eigen::VectorXd u = solve_static(hyper, options), u_linear = solve_static(linear, options);
        gaps.push_back((u - u_linear).norm() / u_linear.norm());
    }
    CAPTURE(gaps[0], gaps[1], gaps[2], gaps[3]);
    for (std::size_t k = 1; k < gaps.size(); ++k)
        CHECK(std::log2(gaps[k - 1] / gaps[k]) == Approx(1.0).margin(0.15));
}

TEST_CASE("hard cases: Y = 1e7 at dt = 1/24 s stays stable, nu up to 0.499 converges every step", "[ex12.9]")
{
    for (const double poisson : {0.3, 0.45, 0.49, 0.499}) {
        dynamics::Scene scene;
        scene.mesh = beam_mesh(0.2, 0.02, 0.02, 10);
        scene.material = {1e7, poisson, 1000.0};
        scene.pinned = assembly::vertices_on_plane(scene.mesh, 0, 0.0);
        scene.time_step = 1.0 / 24.0;
        dynamics::Body body(scene, std::make_unique<HyperelasticElasticity>(
                                       scene.mesh, make_material("neo-hookean", scene.material.youngs_modulus, poisson)));
        NewtonBackwardEuler newton;
        dynamics::Simulation simulation(body, newton, dynamics::initial_state(body));
        double h0 = 0.0, highest = -1e300;
        int most_iterations = 0;
        simulation.run(24, [&](const dynamics::State& state, const dynamics::StepRecord& record) {
            if (state.step == 0)
                h0 = record.energies.total();
            highest = std::max(highest, record.energies.total());
            most_iterations = std::max(most_iterations, record.newton_iterations);
        });
        CAPTURE(poisson, most_iterations, highest, h0);
        CHECK(highest <= h0);  // backward Euler never adds energy
        CHECK(simulation.state().u.allFinite());
        CHECK(most_iterations <= 10);
    }
}

TEST_CASE("extreme density: a free body of rho = 1e200 falls as one of rho = 1000 does, never frozen by an overflowed norm",
          "[ex12.9]")
{
    // Nothing pinned, uniform gravity: the exact motion is a rigid fall whatever the density, and
    // backward Euler's discrete parabola is the same for both. At rho = 1e200 the momenta reach 1e194:
    // a plain |gradient| overflowed to inf, passed "inf <= tolerance * inf" and froze the body at
    // u = 0 with 0 Newton iterations (issue 23, row 6).
    const auto fall = [](double density) {
        dynamics::Scene scene;
        scene.mesh = beam_mesh(0.2, 0.02, 0.02, 4);
        scene.material = {1e5, 0.3, density};
        scene.time_step = 1.0 / 60.0;
        dynamics::Body body(scene, std::make_unique<HyperelasticElasticity>(
                                       scene.mesh, make_material("stable-neo-hookean", 1e5, 0.3)));
        NewtonBackwardEuler newton;
        dynamics::Simulation simulation(body, newton, dynamics::initial_state(body));
        int iterations = 0;
        simulation.run(10, [&](const dynamics::State&, const dynamics::StepRecord& record) {
            iterations += record.newton_iterations;
        });
        return std::pair{simulation.state().u, iterations};
    };
    const auto [light, light_iterations] = fall(1000.0);
    const auto [heavy, heavy_iterations] = fall(1e200);
    CAPTURE(light_iterations, heavy_iterations);
    CHECK(heavy_iterations >= 10);  // at least one iteration per step: the body moved
    REQUIRE(heavy.allFinite());
    // z after 10 steps of backward Euler from rest: -g dt^2 (1 + 2 + ... + 10) at every vertex.
    const double dt = 1.0 / 60.0, expected = -9.81 * dt * dt * 55.0;
    for (Eigen::Index v = 0; v < heavy.size() / 3; ++v)
        CHECK(heavy[3 * v + 2] == Approx(expected).epsilon(1e-9));
    CHECK_THAT(entries_of(heavy), EntriesNear(light, 1e-9 * light.norm()));
}

TEST_CASE("the step-length test: Newton stops at the first direction no larger than step_tolerance", "[ex12.9]")
{
    // E = ½ xᵀA x − bᵀx with the Hessian handed to Newton twice too large (2A, as a projection that
    // adds to the true Hessian): d = −(2A)⁻¹∇E halves the error at every full step, a linear rate of
    // ½, so ‖d_k‖∞ = 2⁻ᵏ⁻¹ ‖x₀ − x*‖∞, and the test stops after the first k with that ≤ τ, at
    // x_{k+1} with ‖x_{k+1} − x*‖∞ = ‖d_k‖∞ ≤ τ; the gradient's test alone goes on to its tolerance.
    Eigen::Matrix3d dense;
    dense << 4.0, 1.0, 0.0, 1.0, 3.0, 1.0, 0.0, 1.0, 2.0;
    const Eigen::SparseMatrix<double> A = dense.sparseView();
    const Eigen::SparseMatrix<double> twice = 2.0 * A;
    const Eigen::Vector3d b(1.0, -2.0, 0.5), solution = dense.llt().solve(b);
    NewtonProblem problem;
    problem.objective = [&](const Eigen::VectorXd& x, double* magnitude) {
        if (magnitude != nullptr)
            *magnitude = std::abs(0.5 * x.dot(A * x)) + std::abs(b.dot(x));
        return 0.5 * x.dot(A * x) - b.dot(x);
    };
    problem.gradient = [&](const Eigen::VectorXd& x) { return Eigen::VectorXd(A * x - b); };
    problem.hessian = [&](const Eigen::VectorXd&, bool) -> const dynamics::SparseMatrix& { return twice; };
    problem.scale = b.norm();
    problem.what = "the quadratic";
    const Eigen::VectorXd start = Eigen::VectorXd::Zero(3);
    const double first = 0.5 * solution.lpNorm<Eigen::Infinity>();  // ‖d₀‖∞
    NewtonOptions options;
    options.relative_tolerance = 1e-10;
    const std::unique_ptr<cg::LinearSolver> solver = cg::make_solver("eigen-llt");
    const NewtonResult gradient_only = newton_minimize(problem, start, options, *solver);
    for (const double tolerance : {1e-2, 1e-4, 1e-6}) {
        CAPTURE(tolerance);
        options.step_tolerance = tolerance;
        const NewtonResult stopped = newton_minimize(problem, start, options, *solver);
        const int k = static_cast<int>(std::ceil(std::log2(first / tolerance) - 1e-9));  // first k: 2⁻ᵏ ‖d₀‖∞ ≤ τ
        CHECK(stopped.iterations == k + 1);
        CHECK(stopped.iterations < gradient_only.iterations);
        CHECK((stopped.x - solution).lpNorm<Eigen::Infinity>() <= tolerance * (1.0 + 1e-9));
        CHECK((stopped.x - solution).lpNorm<Eigen::Infinity>() > 0.25 * tolerance);  // not run on to the end
        CHECK(stopped.gradient_history.size() == static_cast<std::size_t>(stopped.iterations));
    }
}

TEST_CASE("Newton backward Euler: bad options are refused", "[ch12]")
{
    NewtonOptions bad;
    bad.relative_tolerance = 1.5;
    CHECK_THROWS_WITH(NewtonBackwardEuler(bad), Contains("relative tolerance"));
    bad = {};
    bad.max_iterations = 0;
    CHECK_THROWS_AS(NewtonBackwardEuler(bad), Error);
    bad = {};
    bad.armijo = 0.7;
    CHECK_THROWS_AS(NewtonBackwardEuler(bad), Error);
    bad = {};
    bad.solver = "nonsense";
    CHECK_THROWS_AS(NewtonBackwardEuler(bad), Error);
    bad = {};
    bad.forcing = 1.0;
    CHECK_THROWS_WITH(NewtonBackwardEuler(bad), Contains("forcing"));
    bad.forcing = -0.1;
    CHECK_THROWS_AS(NewtonBackwardEuler(bad), Error);
    bad = {};
    bad.step_tolerance = -1e-3;
    CHECK_THROWS_WITH(NewtonBackwardEuler(bad), Contains("step tolerance"));
    bad.step_tolerance = std::numeric_limits<double>::infinity();
    CHECK_THROWS_AS(NewtonBackwardEuler(bad), Error);
}

TEST_CASE("inexact Newton: CG solved only as tightly as the gradient needs, the same steps, fewer CG iterations",
          "[ex12.9]")
{
    // A swinging soft beam: several Newton iterations a step, each solve by IC(0)-preconditioned CG.
    dynamics::Scene scene;
    scene.mesh = beam_mesh(0.2, 0.02, 0.02, 10);
    scene.material = {2e5, 0.45, 1000.0};
    scene.pinned = assembly::vertices_on_plane(scene.mesh, 0, 0.0);
    scene.time_step = 1.0 / 30.0;
    const auto run = [&](const std::string& solver, double forcing, int& cg_iterations) {
        dynamics::Body body(scene, std::make_unique<HyperelasticElasticity>(scene.mesh, make_material("neo-hookean", 2e5, 0.45)));
        NewtonOptions options;
        options.solver = solver;
        options.forcing = forcing;
        NewtonBackwardEuler newton(options);
        dynamics::Simulation simulation(body, newton, dynamics::initial_state(body));
        cg_iterations = 0;
        simulation.run(10, [&](const dynamics::State&, const dynamics::StepRecord& record) {
            cg_iterations += record.solver_iterations;
        });
        return simulation.state().u;
    };
    int direct_iterations = 0, tight = 0, loose = 0;
    const Eigen::VectorXd reference = run("ours-cholesky", 0.1, direct_iterations);
    const Eigen::VectorXd exact_solves = run("ours-pcg-ic0", 0.0, tight);
    const Eigen::VectorXd inexact = run("ours-pcg-ic0", 0.1, loose);
    CAPTURE(tight, loose);
    CHECK(direct_iterations == 0);  // a factorization solves exactly, whatever the forcing
    // Each run stops at |∇E| ≤ 1e-6 × scale: the positions agree to about that.
    CHECK_THAT(entries_of(exact_solves), EntriesNear(reference, 1e-5 * reference.norm()));
    CHECK_THAT(entries_of(inexact), EntriesNear(reference, 1e-5 * reference.norm()));
    CHECK(loose < tight);
}

TEST_CASE("the solver by name: Newton defaults to the frozen factor, which every model can use, with the direct "
          "solver's answer", "[ex12.9]")
{
    // make_integrator_for's "default" is chapter 11's FrozenFactorPcg for a Newton step (CG iterations
    // counted) and chapter 09's supernodal Cholesky for the linear and corotational steps (none);
    // "frozen-factor-pcg" puts the frozen factor under those too. Either way the motion is the
    // direct solver's to within the tolerances (Newton 1e-6, CG 1e-8).
    dynamics::Scene scene;
    scene.mesh = beam_mesh(0.2, 0.02, 0.02, 10);
    scene.material = {2e5, 0.45, 1000.0};
    scene.pinned = assembly::vertices_on_plane(scene.mesh, 0, 0.0);
    scene.time_step = 1.0 / 30.0;
    const auto run = [&](const std::string& model, const std::string& solver, int& cg_iterations) {
        dynamics::Body body(scene, make_force_model(model, scene.mesh, scene.material));
        const auto integrator = make_integrator_for(model, {.solver = solver});
        dynamics::Simulation simulation(body, *integrator, dynamics::initial_state(body));
        cg_iterations = 0;
        simulation.run(8, [&](const dynamics::State&, const dynamics::StepRecord& record) {
            cg_iterations += record.solver_iterations;
        });
        return simulation.state().u;
    };
    for (const std::string model : {"linear", "corotational", "stable-neo-hookean"}) {
        CAPTURE(model);
        int direct = 0, by_default = 0, frozen = 0;
        const Eigen::VectorXd reference = run(model, "ours-cholesky", direct);
        const Eigen::VectorXd default_u = run(model, "default", by_default);
        const Eigen::VectorXd frozen_u = run(model, std::string(frozen_factor_solver), frozen);
        CHECK(direct == 0);
        CHECK(frozen > 0);
        CHECK((by_default > 0) == is_hyperelastic(model));
        CHECK_THAT(entries_of(default_u), EntriesNear(reference, 1e-5 * reference.norm()));
        CHECK_THAT(entries_of(frozen_u), EntriesNear(reference, 1e-5 * reference.norm()));
    }
    const NewtonOptions named = newton_options_for({.solver = "eigen-llt", .newton_tolerance = 1e-4});
    CHECK(named.solver == "eigen-llt");
    CHECK_FALSE(named.make_solver);
    CHECK(named.relative_tolerance == 1e-4);
    CHECK(newton_options_for({}).make_solver);
}
