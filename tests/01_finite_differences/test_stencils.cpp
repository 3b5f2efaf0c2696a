// Chapter 01: the stencils are exact on polynomials of their degree, converge at their order, and
// hit a round-off floor. docs/01_finite_differences.md
#include "01_finite_differences/finite_differences.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

using namespace fem::fd;
using Catch::Matchers::Contains;

namespace {

// Steps h = 2⁻³ … 2⁻⁸ and x = 0.75 keep every sample exact in binary, so a stencil that is exact
// on a polynomial reproduces its derivative to a few ulps.
const double x0 = 0.75;
const double steps[] = {0.125, 0.0625, 0.03125, 0.015625, 0.0078125, 0.00390625};

const double x_smooth = 0.3;

double cubic(double x) { return 2.0 - 3.0 * x + 0.5 * x * x + 4.0 * x * x * x; }

/// Relative errors of a stencil at the steps h_k = 0.1 / 2^k, k = 0 … count−1.
template <typename Stencil>
std::pair<std::vector<double>, std::vector<double>> sweep(Stencil stencil, double exact, int count)
{
    std::vector<double> h, error;
    for (int k = 0; k < count; ++k) {
        h.push_back(0.1 / std::pow(2.0, k));
        const ScalarFunction f = [](double x) { return std::exp(std::sin(x)); };
        error.push_back(std::abs(stencil(f, x_smooth, h.back()) - exact));
    }
    return {h, error};
}

// f(x) = exp(sin x) at x = 0.3 (where f'' is not small), and its derivatives.
const double f1 = std::cos(x_smooth) * std::exp(std::sin(x_smooth));
const double f2 = (std::cos(x_smooth) * std::cos(x_smooth) - std::sin(x_smooth)) * std::exp(std::sin(x_smooth));

/// The order fitted to a stencil's errors against the exact value over six steps h = 0.1 … 0.1/32.
template <typename Stencil>
double observed_order_of(Stencil stencil, double exact)
{
    const auto [h, error] = sweep(stencil, exact, 6);
    return fitted_order(h, error);
}

}  // namespace

TEST_CASE("forward difference: exact for linear functions, error h f''/2 for a quadratic", "[ex01.1]")
{
    for (double h : steps) {
        CHECK(forward_difference([](double x) { return 5.0 - 3.0 * x; }, x0, h) ==
              Approx(-3.0).epsilon(1e-13));
        // f = x²: (f(x+h) − f(x))/h = 2x + h exactly.
        CHECK(forward_difference([](double x) { return x * x; }, x0, h) ==
              Approx(2.0 * x0 + h).epsilon(1e-13));
    }
}

TEST_CASE("backward difference: exact for linear functions, error −h f''/2 for a quadratic", "[ex01.2]")
{
    for (double h : steps) {
        CHECK(backward_difference([](double x) { return 5.0 - 3.0 * x; }, x0, h) ==
              Approx(-3.0).epsilon(1e-13));
        CHECK(backward_difference([](double x) { return x * x; }, x0, h) ==
              Approx(2.0 * x0 - h).epsilon(1e-13));
    }
}

TEST_CASE("central difference: exact up to quadratics, error h² f'''/6 for a cubic", "[ex01.3]")
{
    for (double h : steps) {
        CHECK(central_difference([](double x) { return 1.0 + 2.0 * x - 7.0 * x * x; }, x0, h) ==
              Approx(2.0 - 14.0 * x0).epsilon(1e-13));
        // f = cubic: f'(x) + 4 h² (f''' = 24, 24/6 = 4).
        const double exact = -3.0 + x0 + 12.0 * x0 * x0;
        CHECK(central_difference(cubic, x0, h) == Approx(exact + 4.0 * h * h).epsilon(1e-13));
    }
}

TEST_CASE("central second difference: exact up to cubics, error h² f''''/12 for a quartic", "[ex01.4]")
{
    for (double h : steps) {
        CHECK(central_second_difference(cubic, x0, h) == Approx(1.0 + 24.0 * x0).epsilon(1e-12));
        // f = x⁴: f'' = 12 x², plus h² · 24/12 = 2 h².
        CHECK(central_second_difference([](double x) { return x * x * x * x; }, x0, h) ==
              Approx(12.0 * x0 * x0 + 2.0 * h * h).epsilon(1e-12));
    }
}

// The observed order of each stencil on a smooth function, one test per exercise (01.1 … 01.4).
TEST_CASE("observed order of the forward difference: 1", "[ex01.1]")
{
    CHECK(observed_order_of(forward_difference, f1) == Approx(1.0).margin(0.1));
}

TEST_CASE("observed order of the backward difference: 1", "[ex01.2]")
{
    CHECK(observed_order_of(backward_difference, f1) == Approx(1.0).margin(0.1));
}

TEST_CASE("observed order of the central difference: 2", "[ex01.3]")
{
    CHECK(observed_order_of(central_difference, f1) == Approx(2.0).margin(0.1));
}

TEST_CASE("observed order of the central second difference: 2", "[ex01.4]")
{
    CHECK(observed_order_of(central_second_difference, f2) == Approx(2.0).margin(0.1));
}

TEST_CASE("observed_orders recovers the exponent of C hᵖ pair by pair", "[ex01.5]")
{
    const std::vector<double> h{0.1, 0.05, 0.02, 0.01};
    for (double p : {1.0, 2.0, 3.5}) {
        std::vector<double> error;
        for (double step : h)
            error.push_back(7.0 * std::pow(step, p));
        const auto orders = observed_orders(h, error);
        REQUIRE(orders.size() == 3);
        for (double order : orders)
            CHECK(order == Approx(p).epsilon(1e-12));
        CHECK(fitted_order(h, error) == Approx(p).epsilon(1e-12));
    }
    // An error that stops shrinking has order 0; one that grows has a negative order.
    const auto flat = observed_orders({0.1, 0.01}, {1e-6, 1e-6});
    CHECK(flat[0] == Approx(0.0).margin(1e-14));
    const auto growing = observed_orders({1e-8, 1e-10}, {1e-8, 1e-6});
    CHECK(growing[0] == Approx(-1.0).epsilon(1e-12));
}

TEST_CASE("the one-sided error has a round-off floor near h = sqrt(eps) times the scale",
          "[ex01.1]")
{
    // f = exp at x = 1: scale e; the best step is about 2 sqrt(eps) ≈ 3e-8.
    const ScalarFunction f = [](double x) { return std::exp(x); };
    const double exact = std::exp(1.0);
    std::vector<double> h, error;
    for (int k = 2; k <= 30; ++k) {  // h = 10^-1 … 10^-15 in half decades
        h.push_back(std::pow(10.0, -0.5 * k));
        error.push_back(std::abs(forward_difference(f, 1.0, h.back()) - exact) / exact);
    }
    const auto best = std::min_element(error.begin(), error.end()) - error.begin();
    const double eps = std::numeric_limits<double>::epsilon();
    CHECK(h[best] >= 0.1 * std::sqrt(eps));
    CHECK(h[best] <= 10.0 * std::sqrt(eps));
    CHECK(error[best] < 1e-7);
    CHECK(error[best] > 0.1 * std::sqrt(eps));  // no stencil beats the floor ~ sqrt(eps)
    // Both sides of the V: truncation for large h, round-off for small h.
    CHECK(error.front() > 100.0 * error[best]);
    CHECK(error.back() > 100.0 * error[best]);
}

TEST_CASE("the central error bottoms out near h = eps^(1/3)", "[ex01.3]")
{
    const ScalarFunction f = [](double x) { return std::exp(x); };
    std::vector<double> h, error;
    for (int k = 2; k <= 30; ++k) {
        h.push_back(std::pow(10.0, -0.5 * k));
        error.push_back(std::abs(central_difference(f, 1.0, h.back()) - std::exp(1.0)) / std::exp(1.0));
    }
    const auto best = std::min_element(error.begin(), error.end()) - error.begin();
    const double cube_root_eps = std::cbrt(std::numeric_limits<double>::epsilon());
    CHECK(h[best] >= 0.1 * cube_root_eps);
    CHECK(h[best] <= 10.0 * cube_root_eps);
    CHECK(error[best] < 1e-9);
}

TEST_CASE("bad steps and convergence data are rejected with fem::Error", "[fd][errors]")
{
    const ScalarFunction f = [](double x) { return x; };
    for (double h : {0.0, -1e-3, std::nan(""), std::numeric_limits<double>::infinity()}) {
        CHECK_THROWS_AS(forward_difference(f, 0.0, h), fem::Error);
        CHECK_THROWS_AS(backward_difference(f, 0.0, h), fem::Error);
        CHECK_THROWS_AS(central_difference(f, 0.0, h), fem::Error);
        CHECK_THROWS_AS(central_second_difference(f, 0.0, h), fem::Error);
    }
    CHECK_THROWS_WITH(forward_difference(f, 0.0, -1.0), Contains("step h") && Contains("> 0"));
    CHECK_THROWS_WITH(observed_orders({0.1}, {0.1}), Contains("at least 2"));
    CHECK_THROWS_WITH(observed_orders({0.1, 0.05}, {0.1}), Contains("one error per step"));
    CHECK_THROWS_WITH(observed_orders({0.1, 0.05}, {0.1, 0.0}), Contains("error[1]"));
    CHECK_THROWS_AS(observed_orders({0.1, -0.05}, {0.1, 0.1}), fem::Error);
    CHECK_THROWS_WITH(fitted_order({0.1, 0.1}, {0.1, 0.2}), Contains("equal"));
}
