// Chapter 14: the barrier and the friction mollifier, the obstacles' distances and times of impact,
// and the contact potential's gradient and Hessian, against central differences and exact roots.
// docs/14_contact.md
#include "14_contact/barrier.hpp"
#include "14_contact/contact.hpp"
#include "14_contact/contact_scenes.hpp"
#include "14_contact/friction.hpp"
#include "14_contact/obstacles.hpp"

#include "12_hyperelastic_newton/materials.hpp"

#include "common/error.hpp"
#include "common/random.hpp"
#include "common/test_support.hpp"

#include "contact_derivatives.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

using namespace fem;
using namespace fem::contact;

namespace {

/// The central difference (f(x + h) − f(x − h))/(2h).
template <class F>
double central(const F& f, double x, double h)
{
    return (f(x + h) - f(x - h)) / (2.0 * h);
}

/// Obstacles of every kind, at rest, for the checks of distances and times of impact.
std::vector<std::shared_ptr<const Obstacle>> every_obstacle()
{
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(0.4, Eigen::Vector3d(1.0, 2.0, 0.5).normalized()).toRotationMatrix();
    return {std::make_shared<HalfSpace>(Eigen::Vector3d(0.1, -0.2, 0.05), Eigen::Vector3d(0.3, -0.2, 1.0)),
            std::make_shared<Sphere>(Eigen::Vector3d(0.2, 0.1, -0.3), 0.25),
            std::make_shared<Box>(Eigen::Vector3d(-0.1, 0.2, 0.0), Eigen::Vector3d(0.2, 0.1, 0.15), rotation)};
}

}  // namespace

TEST_CASE("barrier: b, b' and b'' against central differences, zero from dhat on, C2 there, infinite at d <= 0",
          "[ex14.1]")
{
    const double dhat = 1e-3;
    for (double d : {1e-6, 1e-5, 1e-4, 3e-4, 5e-4, 9e-4, 9.99e-4}) {
        const BarrierValue b = barrier(d, dhat);
        const double h = 1e-4 * std::min(d, dhat - d);  // small against the distance to either end
        INFO("d = " << d);
        const auto value = [&](double x) { return barrier(x, dhat).value; };
        const auto first = [&](double x) { return barrier(x, dhat).first; };
        CHECK(b.value > 0.0);
        CHECK(b.first < 0.0);   // it pushes outward
        CHECK(b.second > 0.0);  // convex on (0, d̂)
        CHECK(std::abs(b.first - central(value, d, h)) <= 1e-6 * std::abs(b.first) + 1e-14);
        CHECK(std::abs(b.second - central(first, d, h)) <= 1e-6 * std::abs(b.second) + 1e-12);
    }
    // C² at d̂: the three vanish as d → d̂ from below, and are exactly 0 from d̂ on.
    const BarrierValue near = barrier(dhat * (1.0 - 1e-6), dhat);
    CHECK(std::abs(near.value) < 1e-20);
    CHECK(std::abs(near.first) < 1e-14);
    CHECK(std::abs(near.second) < 1e-5);
    CHECK(barrier(dhat, dhat).value == 0.0);
    CHECK(barrier(2.0 * dhat, dhat).second == 0.0);
    // The closed form at d = d̂/2: b = (d̂/2)² ln 2.
    CHECK(barrier(0.5 * dhat, dhat).value == Approx(0.25 * dhat * dhat * std::log(2.0)).epsilon(1e-12));
    CHECK(std::isinf(barrier(0.0, dhat).value));
    CHECK(std::isinf(barrier(-1e-3, dhat).value));
    CHECK_THROWS_AS(barrier(1e-4, 0.0), Error);
}

TEST_CASE("friction mollifier: f0' = f1 and f1' against central differences, f1 from 0 to 1, continuous at eps",
          "[ex14.4]")
{
    const double epsilon = 1e-5;
    for (double y : {1e-8, 1e-7, 2e-6, 5e-6, 9e-6, 2e-5}) {
        const MollifierValue f = friction_mollifier(y, epsilon);
        const double h = 1e-4 * y;
        CHECK(std::abs(f.f1 - central([&](double x) { return friction_mollifier(x, epsilon).f0; }, y, h)) <= 1e-7);
        CHECK(std::abs(f.f1_derivative - central([&](double x) { return friction_mollifier(x, epsilon).f1; }, y, h)) <=
              1e-6 * std::abs(f.f1_derivative) + 1e-6);
        CHECK(f.f1 > 0.0);
        CHECK(f.f1 <= 1.0);
    }
    CHECK(friction_mollifier(0.0, epsilon).f1 == 0.0);
    CHECK(friction_mollifier(0.0, epsilon).f0 == Approx(epsilon / 3.0).epsilon(1e-14));
    const MollifierValue below = friction_mollifier(epsilon * (1.0 - 1e-9), epsilon);
    CHECK(below.f0 == Approx(epsilon).epsilon(1e-8));
    CHECK(below.f1 == Approx(1.0).epsilon(1e-8));
    CHECK(std::abs(below.f1_derivative) < 1e-3 / epsilon);
    CHECK_THROWS_AS(friction_mollifier(-1.0, epsilon), Error);
}

TEST_CASE("obstacles: the gradient and Hessian of every signed distance against central differences")
{
    const double h = 1e-6;
    for (const auto& obstacle : every_obstacle())
        for (unsigned seed = 1; seed <= 40; ++seed) {
            const Eigen::Vector3d x = 0.6 * random_vector(3, seed);
            const double d = obstacle->local_distance(x);
            if (std::abs(d) < 1e-3)
                continue;  // near the surface the box's distance has a kink inside
            Eigen::Vector3d gradient;
            Eigen::Matrix3d hessian;
            for (int i = 0; i < 3; ++i) {
                const Eigen::Vector3d e = h * Eigen::Vector3d::Unit(i);
                gradient[i] = (obstacle->local_distance(x + e) - obstacle->local_distance(x - e)) / (2.0 * h);
                hessian.col(i) = (obstacle->local_gradient(x + e) - obstacle->local_gradient(x - e)) / (2.0 * h);
            }
            INFO(obstacle->name() << " at " << x.transpose() << ", d = " << d);
            CHECK((obstacle->local_gradient(x) - gradient).norm() < 1e-7);
            if (d > 0.0)  // outside, where the barrier uses it
                CHECK((obstacle->local_hessian(x) - hessian).norm() < 1e-4 * (1.0 + hessian.norm()));
        }
}

TEST_CASE("half-space time of impact: exact, where the path crosses the plane, infinite when it moves away",
          "[ex14.2]")
{
    const HalfSpace floor(Eigen::Vector3d(0.0, 0.0, 0.1), Eigen::Vector3d(0.0, 0.0, 2.0));
    const Eigen::Vector3d x(0.3, -0.2, 0.5);
    const double s = floor.local_time_of_impact(x, Eigen::Vector3d(0.1, 0.2, -0.8));
    CHECK(s == Approx(0.5).epsilon(1e-14));
    CHECK(std::abs(floor.local_distance(x + s * Eigen::Vector3d(0.1, 0.2, -0.8))) < 1e-15);
    CHECK(std::isinf(floor.local_time_of_impact(x, Eigen::Vector3d(1.0, 0.0, 0.2))));
    CHECK(std::isinf(floor.local_time_of_impact(x, Eigen::Vector3d(1.0, 0.0, 0.0))));
    // A moving floor: rising at 1 m/s, at t = 0.2 s its plane is at z = 0.3.
    const HalfSpace rising(Eigen::Vector3d(0.0, 0.0, 0.1), Eigen::Vector3d::UnitZ(), 0.0, Eigen::Vector3d(0.0, 0.0, 1.0));
    CHECK(rising.distance(x, 0.2) == Approx(0.2).epsilon(1e-14));
    CHECK(rising.time_of_impact(x, Eigen::Vector3d(0.0, 0.0, -0.4), 0.2) == Approx(0.5).epsilon(1e-14));
}

TEST_CASE("sphere time of impact: the first root, on the sphere, none for a path that misses or leaves", "[ex14.3]")
{
    const Sphere ball(Eigen::Vector3d(0.0, 0.0, 0.0), 1.0);
    // Head on from x = 3 at speed 4: hits at x = 1, s = 0.5.
    CHECK(ball.local_time_of_impact(Eigen::Vector3d(3.0, 0.0, 0.0), Eigen::Vector3d(-4.0, 0.0, 0.0)) ==
          Approx(0.5).epsilon(1e-14));
    CHECK(std::isinf(ball.local_time_of_impact(Eigen::Vector3d(3.0, 0.0, 0.0), Eigen::Vector3d(1.0, 0.0, 0.0))));
    CHECK(std::isinf(ball.local_time_of_impact(Eigen::Vector3d(3.0, 1.5, 0.0), Eigen::Vector3d(-6.0, 0.0, 0.0))));
    for (unsigned seed = 1; seed <= 200; ++seed) {
        const Eigen::Vector3d p = 2.5 * random_vector(3, seed);
        if (ball.local_distance(p) <= 1e-3)
            continue;
        const Eigen::Vector3d dp = 5.0 * random_vector(3, 1000 + seed);
        const double s = ball.local_time_of_impact(p, dp);
        if (std::isinf(s))
            continue;
        INFO("seed " << seed);
        CHECK(std::abs(ball.local_distance(p + s * dp)) < 1e-12);
        for (double fraction : {0.1, 0.5, 0.9, 0.999})  // nothing earlier on the path reaches it
            CHECK(ball.local_distance(p + fraction * s * dp) > 0.0);
    }
}

TEST_CASE("sphere time of impact where the textbook root cancels: close to the sphere, off its centre", "[ex14.3]")
{
    // p = (1 + 2⁻²⁰, 0, 0) just outside the unit ball, so that k = |p|² − 1 = 2⁻¹⁹ + 2⁻⁴⁰ is exact in
    // double, moving in at dp = (−1024, 32 j, 0): −b and √(b² − 4ak) agree in their first 20 digits
    // (bits), so (−b − √Δ)/(2a) keeps only the rest of √Δ's rounding, while 2k/(−b + √Δ) keeps all.
    // The reference: the same stable formula in long double (a, b and k are exact).
    const Sphere ball(Eigen::Vector3d::Zero(), 1.0);
    const Eigen::Vector3d p(1.0 + std::ldexp(1.0, -20), 0.0, 0.0);
    for (int j = 1; j <= 20; ++j) {
        const Eigen::Vector3d dp(-1024.0, 32.0 * j, 0.0);
        const long double a = static_cast<long double>(dp.squaredNorm()), b = 2.0L * static_cast<long double>(dp.dot(p));
        const long double k = static_cast<long double>(p.squaredNorm()) - 1.0L;
        const long double expected = 2.0L * k / (-b + std::sqrt(b * b - 4.0L * a * k));
        const double s = ball.local_time_of_impact(p, dp);
        std::ostringstream where;  // every digit: the cancelled root differs from the stable one beyond the 6th
        where.precision(17);
        where << "sphere_time_of_impact(p = (" << p.transpose() << "), dp = (" << dp.transpose() << ")) = " << s
              << ", expected " << static_cast<double>(expected);
        INFO(where.str());
        CHECK(std::abs(static_cast<long double>(s) - expected) <= 1e-14L * expected);
    }
}

TEST_CASE("contact potential: gradient and Hessian of barrier and friction against central differences", "[ex14.4]")
{
    test::check_contact_derivatives("floor", {std::make_shared<HalfSpace>(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.4)});
    // touching the top face's corner (0.1, 0.1, 0.1002) from above
    test::check_contact_derivatives(
        "sphere", {std::make_shared<Sphere>(Eigen::Vector3d(0.2, 0.2, 0.2),
                                            (Eigen::Vector3d(0.1, 0.1, 0.1002) - Eigen::Vector3d(0.2, 0.2, 0.2)).norm() - 4e-4,
                                            0.4)});
}

TEST_CASE("adaptive kappa: the balancing stiffness minimises the norm of g + kappa h, kappa_min ties the barrier to the mass",
          "[ex14.1]")
{
    const Eigen::VectorXd g = random_vector(12, 3), h = random_vector(12, 4);
    const double kappa = balancing_stiffness(g, h);
    const double best = (g + kappa * h).norm();
    CHECK(best <= (g + (kappa * 1.001) * h).norm());
    CHECK(best <= (g + (kappa * 0.999) * h).norm());
    CHECK(balancing_stiffness(g, Eigen::VectorXd::Zero(12)) == 0.0);
    // κ_min Δt² b''(d̂/2) = m̄
    const double low = smallest_stiffness(0.125, 0.01, 1e-3);
    CHECK(low * 1e-4 * barrier(5e-4, 1e-3).second == Approx(0.125).epsilon(1e-14));
}

TEST_CASE("adaptive kappa doubles while the smallest distance is below eps_d and still falling, up to 100 kappa_min",
          "[ex14.1]")
{
    // A one-cube block (edge 0.1 m, diagonal 0.173 m) over the floor; ε_d = 10⁻³ × diagonal = 1.73·10⁻⁴ m.
    BlockSettings settings;
    settings.height = 5e-4;
    settings.contact.doubling_distance = 1e-3;
    BlockScene block = block_scene(settings);
    dynamics::Body& body = *block.body;
    const double dt = settings.time_step, dhat = settings.contact.activation_distance;
    const double mass = body.dof_masses().sum() / static_cast<double>(body.dof_masses().size());  // every vertex is on the surface
    const double low = smallest_stiffness(mass, dt, dhat), high = 100.0 * low;
    const double threshold = 1e-3 * std::sqrt(3.0) * settings.edge;
    // The block lowered so that its bottom face is at distance d from the floor.
    const auto at = [&](double d) {
        Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * body.mesh().V.rows());
        for (Eigen::Index v = 0; v < body.mesh().V.rows(); ++v)
            u[3 * v + 2] = d - settings.height;
        return dynamics::initial_state(body, u);
    };
    const auto kappa_at = [&](double d) {
        block.contact->begin_step(body, at(d), dt);
        return block.contact->stiffness();
    };
    const double first = kappa_at(4e-4);  // the balancing κ, clamped to [κ_min, κ_max]
    CHECK(first >= low * (1.0 - 1e-12));
    REQUIRE(first <= 0.25 * high);          // room to double twice
    CHECK(kappa_at(3e-4) == first);         // falling, but above ε_d: kept
    CHECK(kappa_at(1e-4) == 2.0 * first);   // below ε_d and falling: doubled
    CHECK(kappa_at(5e-5) == 4.0 * first);   // again
    CHECK(kappa_at(8e-5) == 4.0 * first);   // below ε_d but rising: kept
    CHECK(kappa_at(8e-5) == 4.0 * first);   // not falling: kept
    REQUIRE(threshold > 1e-4);
    // Falling on and on: κ doubles each time until κ_max, never beyond.
    double d = 5e-5, kappa = 4.0 * first;
    for (int k = 0; k < 12; ++k) {
        d *= 0.5;
        const double expected = std::min(high, 2.0 * kappa);
        kappa = kappa_at(d);
        CHECK(kappa == Approx(expected).epsilon(1e-15));
    }
    CHECK(kappa == Approx(high).epsilon(1e-15));
}
