// Chapter 02: explicit Euler, implicit Euler and Crank–Nicolson: one step by hand, amplification
// factors, a steady state with non-zero boundary values, and the observed orders in space and time
// against exact solutions. docs/02_heat_equation.md#the-theta-scheme
#include "01_finite_differences/finite_differences.hpp"
#include "02_heat_equation/heat_grid.hpp"
#include "02_heat_equation/heat_schemes.hpp"
#include "heat_test_support.hpp"

#include "common/error.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <utility>
#include <vector>

using namespace fem::heat;
using fem::fd::fitted_order;
using fem::heat::test::explicit_limit_formula;
using fem::heat::test::max_difference;
using fem::test::EntriesNear;
using fem::test::entries_of;

namespace {

constexpr Scheme implicit_schemes[] = {Scheme::implicit_euler, Scheme::crank_nicolson};

/// The amplification factor of each scheme written out: z = cΔtλ.
double amplification_formula(Scheme scheme, double z)
{
    switch (scheme) {
    case Scheme::explicit_euler:
        return 1.0 + z;
    case Scheme::implicit_euler:
        return 1.0 / (1.0 - z);
    case Scheme::crank_nicolson:
        return (1.0 + z / 2.0) / (1.0 - z / 2.0);
    }
    return 0.0;
}

/// Runs `steps` steps of size t_end/steps and returns the final state (the run must not stop).
Eigen::VectorXd run_to(const Grid& grid, const BoundaryValues& g, double c, Scheme scheme,
                       const Eigen::VectorXd& u0, double t_end, int steps)
{
    HeatStepper stepper(grid, g, c, scheme, t_end / steps);
    const HeatRun run = simulate_heat(stepper, u0, steps);
    REQUIRE_FALSE(run.blew_up);
    REQUIRE(run.steps_taken == steps);
    return run.u;
}

/// The manufactured solution with a non-zero boundary: a decaying sine mode on top of the
/// harmonic x² − y² (time-independent, so u_t = c Δu holds and g = x² − y² on the boundary).
double decaying_on_harmonic(double c, double x, double y, double t)
{
    return sine_mode_solution(1, 1, c, x, y, t) + x * x - y * y;
}

/// Max-norm error at t_end of `scheme` against decaying_on_harmonic, with `steps` steps.
double error_against_exact(int n, Scheme scheme, double c, double t_end, int steps)
{
    const Grid grid{n};
    const BoundaryValues g = boundary_values(grid, [](double x, double y) { return x * x - y * y; });
    const Eigen::VectorXd u0 = sample(grid, [c](double x, double y) { return decaying_on_harmonic(c, x, y, 0.0); });
    const Eigen::VectorXd u = run_to(grid, g, c, scheme, u0, t_end, steps);
    const Eigen::VectorXd exact =
        sample(grid, [c, t_end](double x, double y) { return decaying_on_harmonic(c, x, y, t_end); });
    return max_difference(u, exact);
}

/// One step of `scheme` from the sine modes (1, 1), (3, 2) and (24, 24) of a 24×24 grid, with Δt
/// at each of `ratios` times the explicit limit, multiplies each mode by the scheme's amplification
/// factor, and amplification_factor() says so too.
void check_amplification(Scheme scheme, const std::vector<double>& ratios)
{
    const Grid grid{24};
    const BoundaryValues zero = constant_boundary(grid, 0.0);
    const double c = 1.3, limit = explicit_limit_formula(grid.h(), c);
    for (double ratio : ratios) {
        const double dt = ratio * limit;
        HeatStepper stepper(grid, zero, c, scheme, dt);
        for (auto [k, l] : std::vector<std::pair<int, int>>{{1, 1}, {3, 2}, {24, 24}}) {
            const double z = c * dt * test::eigenvalue_formula(grid.n, k, l);
            const double g = amplification_formula(scheme, z);
            CHECK(amplification_factor(scheme, c, dt, laplacian_eigenvalue(grid, k, l)) ==
                  Approx(g).margin(1e-12));
            const Eigen::VectorXd v = sine_mode(grid, k, l);
            Eigen::VectorXd next;
            stepper.step(v, next);
            INFO(scheme_name(scheme) << ", dt/limit = " << ratio << ", mode (" << k << ", " << l
                                     << "), g = " << g);
            CHECK(max_difference(next, g * v) < 1e-10);
        }
    }
}

/// g = x² − y² is harmonic and the 5-point stencil is exact on quadratics, so the steady state of
/// the discrete problem is x² − y² itself at the unknowns: the 15×15 grid, its boundary values and
/// that steady state.
struct HarmonicSquare {
    Grid grid{15};
    BoundaryValues g = boundary_values(grid, harmonic);
    Eigen::VectorXd steady = sample(grid, harmonic);
    static double harmonic(double x, double y) { return x * x - y * y; }
};

/// The largest change one step of `scheme` (Δt = 0.9 × the explicit limit) makes to the steady state.
double change_of_steady_state(Scheme scheme)
{
    const HarmonicSquare square;
    HeatStepper stepper(square.grid, square.g, 1.0, scheme, 0.9 * explicit_limit_formula(square.grid.h(), 1.0));
    Eigen::VectorXd next;
    stepper.step(square.steady, next);
    return max_difference(next, square.steady);
}

/// h = 1/8 … 1/64 and the max-norm errors at t = 0.05 of `scheme` against decaying_on_harmonic,
/// with step counts that make Δt exactly ∝ h² or ∝ h: (n+1)²/4 steps for explicit Euler (Δt = 0.8
/// × the explicit limit), (n+1)²/16 for implicit Euler (Δt = 0.8 h²), (n+1)/2 for Crank–Nicolson
/// (Δt = h/10).
std::pair<std::vector<double>, std::vector<double>> errors_in_space(Scheme scheme)
{
    std::vector<double> h, error;
    for (int cells : {8, 16, 32, 64}) {
        const int steps = scheme == Scheme::explicit_euler   ? cells * cells / 4
                          : scheme == Scheme::implicit_euler ? cells * cells / 16
                                                             : cells / 2;
        h.push_back(1.0 / cells);
        error.push_back(error_against_exact(cells - 1, scheme, 1.0, 0.05, steps));
    }
    return {h, error};
}

/// Δt and the errors at t = 0.05 of `scheme` with the given step counts against the exact-in-time
/// solution exp(cλt) v of u' = c L u from two sine modes of a 16×16 grid: the time error alone (no
/// space error).
std::pair<std::vector<double>, std::vector<double>> errors_in_time(Scheme scheme, const std::vector<int>& step_counts)
{
    const Grid grid{16};
    const BoundaryValues zero = constant_boundary(grid, 0.0);
    const double c = 1.0, t_end = 0.05;
    const Eigen::VectorXd v11 = sine_mode(grid, 1, 1), v23 = sine_mode(grid, 2, 3);
    const Eigen::VectorXd u0 = v11 + 0.5 * v23;
    const Eigen::VectorXd exact_in_time = std::exp(c * test::eigenvalue_formula(16, 1, 1) * t_end) * v11 +
                                          0.5 * std::exp(c * test::eigenvalue_formula(16, 2, 3) * t_end) * v23;
    std::vector<double> dt, error;
    for (int steps : step_counts) {
        dt.push_back(t_end / steps);
        error.push_back(max_difference(run_to(grid, zero, c, scheme, u0, t_end, steps), exact_in_time));
    }
    return {dt, error};
}

}  // namespace

TEST_CASE("the explicit stability limit in 2D is h²/(4c)", "[ex02.5]")
{
    CHECK(explicit_stability_limit(0.1, 1.0) == Approx(0.0025).epsilon(1e-15));
    CHECK(explicit_stability_limit(0.02, 0.25) == Approx(4e-4).epsilon(1e-15));
    // Exactly where the checkerboard-like mode (n, n) of a fine grid reaches g = 1 + cΔtλ ≈ −1.
    const Grid grid{200};
    const double limit = explicit_stability_limit(grid.h(), 1.0);
    CHECK(1.0 + limit * laplacian_eigenvalue(grid, grid.n, grid.n) == Approx(-1.0).margin(1e-3));
    CHECK_THROWS_AS(explicit_stability_limit(0.0, 1.0), fem::Error);
    CHECK_THROWS_AS(explicit_stability_limit(0.1, -1.0), fem::Error);
}

TEST_CASE("one explicit Euler step on a 2×2 grid, by hand", "[ex02.4]")
{
    const Grid grid{2};  // h = 1/3
    const BoundaryValues g = boundary_values(grid, [](double x, double) { return x < 0.5 ? 3.0 : 0.0; });
    Eigen::VectorXd u(4), next;
    u << 1.0, 0.0, 0.0, 2.0;
    const double c = 0.5, dt = 0.02, r = c * dt * 9.0;  // r = cΔt/h² = 0.09
    explicit_euler_step(grid, g, c, dt, u, next);
    REQUIRE(next.size() == 4);
    // Unknown (1,1) has the left edge (3) and the bottom edge (x = 1/3: 3) as ring neighbours.
    CHECK(next[0] == Approx(1.0 + r * (0.0 + 3.0 + 0.0 + 3.0 - 4.0 * 1.0)));
    CHECK(next[1] == Approx(0.0 + r * (1.0 + 0.0 + 2.0 + 0.0 - 0.0)));  // (2,1): bottom x = 2/3: 0
    CHECK(next[2] == Approx(0.0 + r * (3.0 + 2.0 + 1.0 + 3.0 - 0.0)));  // (1,2): left 3, top 3
    CHECK(next[3] == Approx(2.0 + r * (0.0 + 0.0 + 0.0 + 0.0 - 8.0)));  // (2,2): right, top 0
}

TEST_CASE("the matrix-free and the assembled explicit step agree", "[ex02.4]")
{
    const Grid grid{23};
    const BoundaryValues g = boundary_values(grid, [](double x, double y) { return std::cos(4 * x) + y; });
    const Eigen::VectorXd u = hot_square(grid);
    const double c = 2.0, dt = 0.8 * explicit_limit_formula(grid.h(), c);
    Eigen::VectorXd matrix_free, assembled;
    explicit_euler_step(grid, g, c, dt, u, matrix_free);
    explicit_euler_step_assembled(laplacian_matrix(grid), boundary_lift(grid, g), c, dt, u, assembled);
    CHECK(max_difference(matrix_free, assembled) < 1e-13);
}

TEST_CASE("the implicit system matrix is I − θ cΔt L", "[ex02.6]")
{
    const int n = 6;
    const Grid grid{n};
    const double c = 0.7, dt = 0.01;
    const Eigen::MatrixXd L = test::kronecker_laplacian(n);
    const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(n * n, n * n);
    for (double theta : {0.0, 0.5, 1.0}) {
        const Eigen::MatrixXd A = implicit_system_matrix(grid, c, dt, theta);
        INFO("theta = " << theta);
        CHECK_THAT(entries_of(A), EntriesNear(I - theta * c * dt * L, 1e-12));
    }
}

TEST_CASE("explicit Euler multiplies a sine mode by its amplification factor, to 1e-10", "[ex02.4]")
{
    check_amplification(Scheme::explicit_euler, {0.3, 0.99});  // inside its limit
}

TEST_CASE("implicit Euler and Crank–Nicolson multiply a sine mode by their amplification factors, "
          "to 1e-10, far beyond the explicit limit too",
          "[ex02.7]")
{
    for (Scheme scheme : implicit_schemes)
        check_amplification(scheme, {0.3, 10.0, 1000.0});
}

TEST_CASE("with a harmonic boundary the implicit schemes reach the exact steady state, and keep it",
          "[ex02.7]")
{
    const HarmonicSquare square;
    for (Scheme scheme : implicit_schemes) {
        // From a cold start, to t = 2: every mode of the difference has decayed below 1e-12 (with
        // this Δt Crank–Nicolson still damps the checkerboard mode by |g| ≈ 0.67 per step).
        HeatStepper stepper(square.grid, square.g, 1.0, scheme, 0.005);
        const HeatRun run = simulate_heat(stepper, Eigen::VectorXd::Zero(square.grid.unknowns()), 400);
        INFO(scheme_name(scheme));
        CHECK(max_difference(run.u, square.steady) < 1e-10);
        CHECK(change_of_steady_state(scheme) < 1e-12);
    }
}

TEST_CASE("with a harmonic boundary explicit Euler keeps the exact steady state", "[ex02.4]")
{
    CHECK(change_of_steady_state(Scheme::explicit_euler) < 1e-12);
}

TEST_CASE("explicit Euler: observed order 2 in space (Δt ∝ h²), with a non-zero boundary", "[ex02.4]")
{
    const auto [h, error] = errors_in_space(Scheme::explicit_euler);
    INFO("errors " << error[0] << " … " << error.back());
    CHECK(fitted_order(h, error) == Approx(2.0).margin(0.15));
    CHECK(error.back() < 1e-3);
}

TEST_CASE("implicit schemes: observed order 2 in space (Δt ∝ h² for Euler, ∝ h for CN), with a "
          "non-zero boundary",
          "[ex02.7]")
{
    for (Scheme scheme : implicit_schemes) {
        const auto [h, error] = errors_in_space(scheme);
        INFO(scheme_name(scheme) << ": errors " << error[0] << " … " << error.back());
        CHECK(fitted_order(h, error) == Approx(2.0).margin(0.15));
        CHECK(error.back() < 1e-3);
    }
}

TEST_CASE("explicit Euler: observed order 1 in time against the exact-in-time discrete solution",
          "[ex02.4]")
{
    // Δt = 7.8e-4 … 9.8e-5, below the limit 8.7e-4.
    const auto [dt, error] = errors_in_time(Scheme::explicit_euler, {64, 128, 256, 512});
    INFO("errors " << error[0] << " … " << error.back());
    CHECK(fitted_order(dt, error) == Approx(1.0).margin(0.15));
}

TEST_CASE("implicit schemes: observed order in time against the exact-in-time discrete solution: "
          "1 for implicit Euler, 2 for Crank–Nicolson",
          "[ex02.7]")
{
    const auto [dt_ie, error_ie] = errors_in_time(Scheme::implicit_euler, {16, 32, 64, 128});
    INFO("implicit Euler: errors " << error_ie[0] << " … " << error_ie.back());
    CHECK(fitted_order(dt_ie, error_ie) == Approx(1.0).margin(0.15));
    const auto [dt_cn, error_cn] = errors_in_time(Scheme::crank_nicolson, {8, 16, 32, 64});
    INFO("Crank–Nicolson: errors " << error_cn[0] << " … " << error_cn.back());
    CHECK(fitted_order(dt_cn, error_cn) == Approx(2.0).margin(0.15));
}

TEST_CASE("the observer sees the initial state, every k-th step and the last one", "[ex02.7]")
{
    const Grid grid{9};
    HeatStepper stepper(grid, constant_boundary(grid, 0.0), 1.0, Scheme::implicit_euler, 1e-3);
    std::vector<int> seen;
    std::vector<double> totals;
    const HeatRun run = simulate_heat(stepper, hot_square(grid), 10,
                                      [&](int step, double, const Eigen::VectorXd& u) {
                                          seen.push_back(step);
                                          totals.push_back(u.sum());
                                      },
                                      4);
    CHECK(seen == std::vector<int>{0, 4, 8, 10});
    CHECK(run.time == Approx(0.01));
    // Heat leaves through the cold boundary: the total only decreases.
    for (std::size_t i = 1; i < totals.size(); ++i)
        CHECK(totals[i] < totals[i - 1]);
}
