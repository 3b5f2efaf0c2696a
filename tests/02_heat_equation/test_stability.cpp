// Chapter 02: stability. Explicit Euler at 0.99× and 1.01× its limit (blow-up detected, never NaN),
// implicit Euler far beyond it, Crank–Nicolson's oscillations against implicit Euler's maximum
// principle on the hot square, and bad input. docs/02_heat_equation.md#stability
#include "02_heat_equation/heat_grid.hpp"
#include "02_heat_equation/heat_schemes.hpp"
#include "heat_test_support.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using namespace fem::heat;
using fem::heat::test::explicit_limit_formula;
using Catch::Matchers::Contains;

TEST_CASE("explicit Euler is stable at 0.99× the limit and blows up at 1.01×, and says so",
          "[ex02.5]")
{
    const Grid grid{32};
    const BoundaryValues zero = constant_boundary(grid, 0.0);
    const double c = 1.0, limit = explicit_stability_limit(grid.h(), c);
    for (const Eigen::VectorXd& u0 : {hot_square(grid), sine_mode(grid, 1, 1)}) {
        const int steps = 20000;
        HeatStepper stable_stepper(grid, zero, c, Scheme::explicit_euler, 0.99 * limit);
        const HeatRun stable = simulate_heat(stable_stepper, u0, steps);
        CHECK_FALSE(stable.blew_up);
        CHECK(stable.first_violation == -1);
        CHECK(stable.steps_taken == steps);
        CHECK(stable.u.allFinite());
        CHECK(stable.highest <= 1.0);
        CHECK(stable.lowest >= 0.0);

        HeatStepper unstable_stepper(grid, zero, c, Scheme::explicit_euler, 1.01 * limit);
        const HeatRun unstable = simulate_heat(unstable_stepper, u0, steps);
        CHECK(unstable.blew_up);
        CHECK(unstable.blow_up_step > 1);
        CHECK(unstable.blow_up_step < steps);
        CHECK(unstable.first_violation == unstable.blow_up_step);
        CHECK(unstable.steps_taken == unstable.blow_up_step - 1);
        CHECK(unstable.time == Approx(unstable.steps_taken * 1.01 * limit));
        CHECK(unstable.u.allFinite());  // the last valid state, never NaN
        CHECK(unstable.u.maxCoeff() <= 1.0 + 1e-9);
        CHECK(unstable.u.minCoeff() >= -1e-9);
    }
}

TEST_CASE("a blown-up run hands no NaN to its observer", "[ex02.4]")
{
    const Grid grid{16};
    HeatStepper stepper(grid, constant_boundary(grid, 0.0), 1.0, Scheme::explicit_euler,
                        3.0 * explicit_limit_formula(grid.h(), 1.0));
    bool all_finite = true;
    int frames = 0;
    const HeatRun run = simulate_heat(stepper, hot_square(grid), 100000,
                                      [&](int, double, const Eigen::VectorXd& u) {
                                          all_finite = all_finite && u.allFinite();
                                          ++frames;
                                      });
    CHECK(run.blew_up);
    CHECK(all_finite);
    CHECK(frames == run.steps_taken + 1);
}

TEST_CASE("implicit Euler stays bounded at 100× the explicit limit", "[ex02.7]")
{
    const Grid grid{32};
    const BoundaryValues zero = constant_boundary(grid, 0.0);
    const double c = 1.0, dt = 100.0 * explicit_limit_formula(grid.h(), c);
    for (const Eigen::VectorXd& u0 : {hot_square(grid), sine_mode(grid, 32, 32)}) {
        HeatStepper stepper(grid, zero, c, Scheme::implicit_euler, dt);
        const HeatRun run = simulate_heat(stepper, u0, 500);
        CHECK_FALSE(run.blew_up);
        CHECK(run.first_violation == -1);
        CHECK(run.steps_taken == 500);
        CHECK(run.u.cwiseAbs().maxCoeff() <= u0.cwiseAbs().maxCoeff());
        CHECK(run.u.cwiseAbs().maxCoeff() < 1e-6);  // and it decays, as the exact solution does
    }
}

TEST_CASE("hard case: on the hot square at large Δt Crank–Nicolson oscillates below zero while "
          "implicit Euler stays non-negative",
          "[ex02.7]")
{
    const Grid grid{32};
    const BoundaryValues zero = constant_boundary(grid, 0.0);
    const double c = 1.0, dt = 100.0 * explicit_limit_formula(grid.h(), c);  // cΔt/h² = 25
    const Eigen::VectorXd u0 = hot_square(grid);

    HeatStepper cn(grid, zero, c, Scheme::crank_nicolson, dt);
    const HeatRun oscillating = simulate_heat(cn, u0, 20);
    CHECK_FALSE(oscillating.blew_up);  // bounded: CN is unconditionally stable ...
    CHECK(oscillating.steps_taken == 20);
    CHECK(oscillating.first_violation == 1);  // ... but not positive: negative temperatures at once
    CHECK(oscillating.lowest < -0.05);
    CHECK(oscillating.highest <= 1.0);

    HeatStepper implicit(grid, zero, c, Scheme::implicit_euler, dt);
    const HeatRun monotone = simulate_heat(implicit, u0, 20);
    CHECK_FALSE(monotone.blew_up);
    CHECK(monotone.first_violation == -1);
    CHECK(monotone.lowest >= 0.0);  // (I − cΔt L)⁻¹ has no negative entry: the maximum principle
    CHECK(monotone.highest <= 1.0);

    // Crank–Nicolson keeps the maximum principle while cΔt/h² ≤ 1/2, i.e. Δt ≤ h²/(2c).
    HeatStepper small_step(grid, zero, c, Scheme::crank_nicolson, 0.99 * 2.0 * explicit_limit_formula(grid.h(), c));
    const HeatRun positive = simulate_heat(small_step, u0, 200);
    CHECK(positive.first_violation == -1);
    CHECK(positive.lowest >= 0.0);
}

TEST_CASE("bad schemes, diffusivities, steps and initial states are rejected with fem::Error",
          "[heat][errors]")
{
    const Grid grid{8};
    const BoundaryValues g = constant_boundary(grid, 0.0);
    const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
    CHECK_THROWS_WITH(HeatStepper(Grid{0}, g, 1.0, Scheme::implicit_euler, 1e-3), Contains("1 ≤ n"));
    CHECK_THROWS_WITH(HeatStepper(grid, g, 0.0, Scheme::implicit_euler, 1e-3), Contains("diffusivity c"));
    CHECK_THROWS_AS(HeatStepper(grid, g, -1.0, Scheme::explicit_euler, 1e-3), fem::Error);
    CHECK_THROWS_AS(HeatStepper(grid, g, nan, Scheme::crank_nicolson, 1e-3), fem::Error);
    CHECK_THROWS_WITH(HeatStepper(grid, g, 1.0, Scheme::explicit_euler, 0.0), Contains("time step dt"));
    CHECK_THROWS_AS(HeatStepper(grid, g, 1.0, Scheme::implicit_euler, -1e-3), fem::Error);
    CHECK_THROWS_AS(HeatStepper(grid, g, 1.0, Scheme::implicit_euler, inf), fem::Error);
    BoundaryValues nan_boundary = g;
    nan_boundary.right[3] = nan;
    CHECK_THROWS_WITH(HeatStepper(grid, nan_boundary, 1.0, Scheme::implicit_euler, 1e-3),
                      Contains("right boundary value 3"));

    HeatStepper stepper(grid, g, 1.0, Scheme::explicit_euler, 1e-4);
    const Eigen::VectorXd u0 = hot_square(grid);
    CHECK_THROWS_WITH(simulate_heat(stepper, u0, -1), Contains("steps must be ≥ 0"));
    CHECK_THROWS_AS(simulate_heat(stepper, u0, 10, {}, 0), fem::Error);
    CHECK_THROWS_WITH(simulate_heat(stepper, Eigen::VectorXd::Zero(7), 1), Contains("7 values"));
    Eigen::VectorXd nan_state = u0;
    nan_state[5] = nan;
    CHECK_THROWS_WITH(simulate_heat(stepper, nan_state, 1), Contains("not finite at unknown 5"));
    Eigen::VectorXd next;
    CHECK_THROWS_AS(stepper.step(Eigen::VectorXd::Zero(3), next), fem::Error);
    CHECK_THROWS_AS(explicit_euler_step(grid, g, 1.0, nan, u0, next), fem::Error);
    CHECK_THROWS_AS(explicit_euler_step(grid, g, inf, 1e-4, u0, next), fem::Error);
    // Any matrix of the grid's size will do (laplacian_matrix is exercise 02.2, graded elsewhere).
    const Eigen::SparseMatrix<double> L(grid.unknowns(), grid.unknowns());
    CHECK_THROWS_AS(explicit_euler_step_assembled(L, Eigen::VectorXd::Zero(3), 1.0, 1e-4, u0, next),
                    fem::Error);
    CHECK_THROWS_AS(implicit_system_matrix(grid, 1.0, 1e-3, 1.5), fem::Error);
    CHECK_THROWS_AS(implicit_system_matrix(grid, 1.0, 1e-3, nan), fem::Error);
    CHECK_THROWS_AS(amplification_factor(Scheme::explicit_euler, 1.0, 1e-3, 5.0), fem::Error);
    CHECK_THROWS_WITH(parse_scheme("leapfrog"), Contains("explicit, implicit or crank-nicolson"));
    CHECK(parse_scheme("cn") == Scheme::crank_nicolson);
    CHECK(parse_scheme("implicit") == Scheme::implicit_euler);
}
