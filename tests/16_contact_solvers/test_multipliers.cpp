// Chapter 16's tests of the augmented Lagrangian's pieces: the term ψ and its derivatives against
// finite differences, the multiplier update against a one-constraint problem solved by hand, the
// filter and the stopping rule. docs/16_contact_solvers.md#the-augmented-lagrangian

#include "16_contact_solvers/augmented_lagrangian.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace fem;
using namespace fem::contact;

TEST_CASE("augmented term: slope and curvature against central differences, both sides of the kink", "[ch16]")
{
    const double lambda = 3.0, mu = 50.0;  // the kink at g = λ/μ = 0.06
    for (double g : {-0.2, -0.01, 0.0, 0.03, 0.059, 0.07, 0.5}) {
        const double h = 1e-6;
        const AugmentedTerm term = augmented_term(g, lambda, mu);
        const double slope = (augmented_term(g + h, lambda, mu).value - augmented_term(g - h, lambda, mu).value) / (2 * h);
        const double curvature =
            (augmented_term(g + h, lambda, mu).slope - augmented_term(g - h, lambda, mu).slope) / (2 * h);
        INFO("g = " << g);
        CHECK(term.slope == Approx(slope).margin(1e-7));
        CHECK(term.curvature == Approx(curvature).margin(1e-5));
    }
    // Beyond the kink the pair exerts no force and ψ = −λ²/(2μ), a constant.
    CHECK(augmented_term(0.5, lambda, mu).value == Approx(-lambda * lambda / (2 * mu)));
    CHECK(augmented_term(0.5, lambda, mu).slope == 0.0);
}

TEST_CASE("augmented term: refuses a penalty <= 0 and a negative multiplier", "[ch16]")
{
    CHECK_THROWS_AS(augmented_term(0.0, 1.0, 0.0), Error);
    CHECK_THROWS_AS(augmented_term(0.0, -1.0, 1.0), Error);
    CHECK_THROWS_AS(augmented_multiplier(0.0, 1.0, -1.0), Error);
    CHECK_THROWS_AS(augmented_multiplier(std::nan(""), 1.0, 1.0), Error);
}

// min ½ k (x − a)² subject to g = x − δ ≥ 0 with a < δ: the answer x* = δ, λ* = k (δ − a). The inner
// minimiser of ½ k (x − a)² + ψ(x − δ, λ, μ) is x = (k a + λ + μ δ)/(k + μ) while λ − μ g > 0, so its
// g = (λ − k (δ − a))/(k + μ) and the update λ⁺ = λ − μ g = (k λ + μ k (δ − a))/(k + μ): the error
// λ − λ* shrinks by k/(k + μ) each update, in closed form.
TEST_CASE("multiplier update: a spring pulled through a wall, the closed form of every update", "[ex16.1]")
{
    const double k = 200.0, a = -0.3, delta = 0.01, mu = 600.0;
    const double exact = k * (delta - a);
    double lambda = 0.0;
    for (int update = 1; update <= 12; ++update) {
        const double x = (k * a + lambda + mu * delta) / (k + mu);  // the inner minimiser, by hand
        const double g = x - delta;
        REQUIRE(lambda - mu * g > 0.0);
        const double next = augmented_multiplier(g, lambda, mu);
        INFO("update " << update);
        CHECK(next == Approx((k * lambda + mu * k * (delta - a)) / (k + mu)).epsilon(1e-13));
        CHECK(std::abs(next - exact) == Approx(std::abs(lambda - exact) * k / (k + mu)).epsilon(1e-9));
        lambda = next;
    }
    CHECK(lambda == Approx(exact).epsilon(1e-6));
    // A pair beyond its constraint loses its multiplier: max(0, λ − μ g) = 0.
    CHECK(augmented_multiplier(1.0, 5.0, 100.0) == 0.0);
    CHECK(augmented_multiplier(0.01, 5.0, 100.0) == Approx(4.0));
}

TEST_CASE("active-set filter: keeps pushing pairs and near ones, drops far idle ones", "[ex16.2]")
{
    const double delta = 1e-3;
    CHECK(keeps_constraint(0.5, 2.0, delta, 1.0));       // far but still pushing (λ > 0)
    CHECK(keeps_constraint(0.9e-3, 0.0, delta, 1.0));    // idle but within filter_gap δ
    CHECK(keeps_constraint(-1e-4, 0.0, delta, 1.0));     // violated
    CHECK(keeps_constraint(-5e-3, 0.0, delta, 1.0));     // violated by more than filter_gap δ: g ≤ filter_gap δ all the same
    CHECK_FALSE(keeps_constraint(1.1e-3, 0.0, delta, 1.0));
    CHECK_FALSE(keeps_constraint(2e-4, 0.0, delta, 0.1));
}

TEST_CASE("stopping rule: violation, complementarity and the time of impact, each alone refuses", "[ex16.3]")
{
    const double delta = 1e-3;
    OuterResiduals r;
    r.violation = 0.9e-5;
    r.complementarity = 0.5e-5;
    CHECK(outer_converged(r, delta, 1e-2, 1e-2));
    OuterResiduals violated = r;
    violated.violation = 1.1e-5;
    CHECK_FALSE(outer_converged(violated, delta, 1e-2, 1e-2));
    OuterResiduals slack = r;
    slack.complementarity = 2e-5;
    CHECK_FALSE(outer_converged(slack, delta, 1e-2, 1e-2));
    OuterResiduals locked = r;
    locked.impact_complete = false;
    CHECK_FALSE(outer_converged(locked, delta, 1e-2, 1e-2));
    // Each residual against its own tolerance: the violation against violation_tolerance, the
    // complementarity against dual_tolerance.
    CHECK(outer_converged(r, delta, 1e-2, 6e-3));
    CHECK_FALSE(outer_converged(r, delta, 6e-3, 1e-2));
}
