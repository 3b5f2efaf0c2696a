// Chapter 01: FTCS for the 1D heat equation against the exact sine-mode solution, its stability
// limit, and the detection of blow-up. docs/01_finite_differences.md#the-1d-heat-equation
#include "01_finite_differences/finite_differences.hpp"
#include "01_finite_differences/heat_rod.hpp"

#include "common/error.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace fem::fd;
using Catch::Matchers::Contains;
using fem::test::EntriesNear;
using fem::test::entries_of;

namespace {

/// The stability limit h²/(2c) written out, so that the tests of ftcs_step (exercise 01.6) do not
/// need explicit_stability_limit (exercise 01.7).
double limit_formula(double h, double c)
{
    return h * h / (2.0 * c);
}

/// Max-norm error at time t of FTCS from the sine mode k, with Δt = ratio × the stability limit.
double sine_mode_error(int points, double ratio, double t_end, int k = 1)
{
    HeatRod rod;
    rod.points = points;
    rod.c = 0.5;
    const double dt_limit = limit_formula(rod.h(), rod.c);
    const int steps = static_cast<int>(std::ceil(t_end / (ratio * dt_limit)));
    const double dt = t_end / steps;
    const HeatRun run = simulate_heat_rod(rod, sine_mode(rod, k), dt, steps);
    REQUIRE_FALSE(run.blew_up);
    double error = 0.0;
    for (int i = 0; i < rod.points; ++i)
        error = std::max(error, std::abs(run.u[i] - sine_mode_solution(rod, k, rod.x(i), run.time)));
    return error;
}

}  // namespace

TEST_CASE("the stability limit is h²/(2c)", "[ex01.7]")
{
    CHECK(explicit_stability_limit(0.1, 1.0) == Approx(0.005).epsilon(1e-15));
    CHECK(explicit_stability_limit(0.02, 0.25) == Approx(8e-4).epsilon(1e-15));
    CHECK_THROWS_AS(explicit_stability_limit(0.0, 1.0), fem::Error);
    CHECK_THROWS_AS(explicit_stability_limit(0.1, -1.0), fem::Error);
}

TEST_CASE("one FTCS step applies the second difference inside and the Dirichlet values at the ends",
          "[ex01.6]")
{
    HeatRod rod;
    rod.points = 5;
    rod.length = 4.0;  // h = 1
    rod.c = 0.25;
    rod.u_left = 2.0;
    rod.u_right = -1.0;
    Eigen::VectorXd u(5), next;
    u << 2.0, 0.0, 4.0, 0.0, -1.0;
    ftcs_step(rod, 0.5, u, next);  // r = c Δt / h² = 0.125
    REQUIRE(next.size() == 5);
    CHECK(next[0] == 2.0);
    CHECK(next[1] == Approx(0.0 + 0.125 * (4.0 - 0.0 + 2.0)));
    CHECK(next[2] == Approx(4.0 + 0.125 * (0.0 - 8.0 + 0.0)));
    CHECK(next[3] == Approx(0.0 + 0.125 * (-1.0 + 4.0)));
    CHECK(next[4] == -1.0);
    // A linear profile between the end values is the steady state: FTCS leaves it unchanged.
    Eigen::VectorXd linear = Eigen::VectorXd::LinSpaced(5, 2.0, -1.0);
    ftcs_step(rod, 0.5, linear, next);
    CHECK_THAT(entries_of(next), EntriesNear(linear, 1e-14));
}

TEST_CASE("FTCS matches the decaying sine mode and converges at O(h²) with Δt ∝ h²", "[ex01.6]")
{
    const double t_end = 0.1;
    std::vector<double> h, error;
    for (int points : {11, 21, 41, 81}) {
        h.push_back(1.0 / (points - 1));
        error.push_back(sine_mode_error(points, 0.9, t_end));
    }
    CHECK(error.back() < 1e-4);
    CHECK(fitted_order(h, error) == Approx(2.0).margin(0.1));
    // A higher mode decays faster, and FTCS follows it too.
    CHECK(sine_mode_error(81, 0.5, 0.01, 3) < 1e-3);
}

TEST_CASE("FTCS is stable at 0.99× the limit and blows up at 1.01×, and says so", "[ex01.7]")
{
    HeatRod rod;
    rod.points = 51;
    const double limit = explicit_stability_limit(rod.h(), rod.c);
    for (const Eigen::VectorXd& u0 : {sine_mode(rod, 1), hot_middle(rod)}) {
        const int steps = 20000;
        const HeatRun stable = simulate_heat_rod(rod, u0, 0.99 * limit, steps);
        CHECK_FALSE(stable.blew_up);
        CHECK(stable.steps_taken == steps);
        CHECK(stable.u.allFinite());
        CHECK(stable.u.cwiseAbs().maxCoeff() <= 1.0);

        const HeatRun unstable = simulate_heat_rod(rod, u0, 1.01 * limit, steps);
        CHECK(unstable.blew_up);
        CHECK(unstable.blow_up_step > 0);
        CHECK(unstable.blow_up_step < steps);
        CHECK(unstable.steps_taken == unstable.blow_up_step - 1);
        CHECK(unstable.u.allFinite());  // the last valid state, never NaN
        CHECK(unstable.u.cwiseAbs().maxCoeff() <= 1.0 + 1e-9);
    }
}

TEST_CASE("the observer sees the initial state, every k-th step and the last one", "[ex01.6]")
{
    HeatRod rod;
    rod.points = 11;
    std::vector<int> seen;
    std::vector<double> totals;
    simulate_heat_rod(rod, hot_middle(rod), 0.5 * limit_formula(rod.h(), rod.c), 10,
                      [&](int step, double, const Eigen::VectorXd& u) {
                          seen.push_back(step);
                          totals.push_back(u.sum());
                      },
                      4);
    CHECK(seen == std::vector<int>{0, 4, 8, 10});
    // Heat leaves through the cold ends: the total only decreases.
    for (std::size_t i = 1; i < totals.size(); ++i)
        CHECK(totals[i] < totals[i - 1]);
}

TEST_CASE("bad rods, steps and initial states are rejected with fem::Error", "[heat][errors]")
{
    HeatRod rod;
    const Eigen::VectorXd u0 = Eigen::VectorXd::Zero(rod.points);
    auto bad = rod;
    bad.points = 2;
    CHECK_THROWS_WITH(simulate_heat_rod(bad, Eigen::VectorXd::Zero(2), 1e-4, 1), Contains("at least 3"));
    bad = rod;
    bad.c = 0.0;
    CHECK_THROWS_WITH(simulate_heat_rod(bad, u0, 1e-4, 1), Contains("diffusivity c"));
    bad = rod;
    bad.length = -1.0;
    CHECK_THROWS_AS(simulate_heat_rod(bad, u0, 1e-4, 1), fem::Error);
    bad = rod;
    bad.u_left = std::nan("");
    CHECK_THROWS_AS(simulate_heat_rod(bad, u0, 1e-4, 1), fem::Error);
    CHECK_THROWS_WITH(simulate_heat_rod(rod, u0, 0.0, 1), Contains("time step dt"));
    CHECK_THROWS_AS(simulate_heat_rod(rod, u0, -1e-4, 1), fem::Error);
    CHECK_THROWS_AS(simulate_heat_rod(rod, u0, 1e-4, -1), fem::Error);
    CHECK_THROWS_WITH(simulate_heat_rod(rod, Eigen::VectorXd::Zero(7), 1e-4, 1), Contains("7 values"));
    Eigen::VectorXd nan_state = u0;
    nan_state[3] = std::nan("");
    CHECK_THROWS_WITH(simulate_heat_rod(rod, nan_state, 1e-4, 1), Contains("non-finite"));
}
