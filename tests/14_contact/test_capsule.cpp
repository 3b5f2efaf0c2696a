// Chapter 14: the capsule obstacle (a segment with a radius) — its distance, gradient and Hessian
// against a closed form and central differences, its time of impact (exact, never late), the
// triangles it is drawn as, and a block dropped on a horizontal one carrying its weight.
// docs/14_contact.md#obstacles
#include "14_contact/contact.hpp"
#include "14_contact/contact_scenes.hpp"
#include "14_contact/obstacles.hpp"
#include "rest_weight.hpp"

#include "common/error.hpp"
#include "common/random.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <memory>

using namespace fem;
using namespace fem::contact;

namespace {

/// The capsule's d₀ as a potential of x (3) for test::central_differences.
struct CapsuleDistance {
    const Capsule& capsule;
    double energy(const Eigen::VectorXd& x) const { return capsule.local_distance(x); }
    Eigen::VectorXd gradient(const Eigen::VectorXd& x) const { return capsule.local_gradient(x); }
};

/// A tilted capsule from a to b, radius 0.2: the one of the checks below.
const Eigen::Vector3d a(0.1, -0.2, 0.3), b(0.6, 0.4, -0.1);
constexpr double radius = 0.2;

}  // namespace

TEST_CASE("capsule: distance, gradient and Hessian in closed form beside the segment and beyond its ends")
{
    // Along x from (0, 0, 0) to (2, 0, 0), r = 0.5.
    const Capsule rod(Eigen::Vector3d::Zero(), Eigen::Vector3d(2.0, 0.0, 0.0), 0.5);
    CHECK(rod.name() == "capsule");
    // Beside it, 1.5 m up: d = 1, n = +z, ∇²d = (I − e eᵀ − n nᵀ)/1.5 (curved only around the axis).
    const Eigen::Vector3d beside(0.7, 0.0, 1.5);
    CHECK(rod.local_distance(beside) == Approx(1.0).epsilon(1e-15));
    CHECK((rod.local_gradient(beside) - Eigen::Vector3d::UnitZ()).norm() < 1e-15);
    const Eigen::Matrix3d cylinder = Eigen::Vector3d(0.0, 1.0 / 1.5, 0.0).asDiagonal();
    CHECK((rod.local_hessian(beside) - cylinder).norm() < 1e-15);
    // Beyond the end b = (2, 0, 0), at (5, 4, 0): d = 5 − 0.5, n = (3, 4, 0)/5, ∇²d = (I − n nᵀ)/5.
    const Eigen::Vector3d beyond(5.0, 4.0, 0.0), n(0.6, 0.8, 0.0);
    CHECK(rod.local_distance(beyond) == Approx(4.5).epsilon(1e-15));
    CHECK((rod.local_gradient(beyond) - n).norm() < 1e-15);
    CHECK((rod.local_hessian(beyond) - (Eigen::Matrix3d::Identity() - n * n.transpose()) / 5.0).norm() < 1e-15);
    // Inside, on the axis's side: negative, −(r − ρ).
    CHECK(rod.local_distance(Eigen::Vector3d(1.0, 0.2, 0.0)) == Approx(-0.3).epsilon(1e-15));
    // Moving: at t it stands shifted by t w.
    const Capsule moving(Eigen::Vector3d::Zero(), Eigen::Vector3d(2.0, 0.0, 0.0), 0.5, 0.0, Eigen::Vector3d(0.0, 0.0, 1.0));
    CHECK(moving.distance(beside, 0.5) == Approx(0.5).epsilon(1e-15));
    CHECK(moving.local_features().corners.rows() == 0);  // smooth: no corners, no edges
}

TEST_CASE("capsule: gradient and Hessian against central differences, beside the segment and beyond either end")
{
    const Capsule capsule(a, b, radius);
    int beside = 0, beyond = 0;
    for (unsigned seed = 1; seed <= 60; ++seed) {
        const Eigen::Vector3d x = 0.35 * (a + b) + 0.8 * random_vector(3, seed);
        const double d = capsule.local_distance(x);
        const double along = (b - a).normalized().dot(x - a);
        if (d < 1e-2 || std::abs(along) < 1e-3 || std::abs(along - (b - a).norm()) < 1e-3)
            continue;  // outside, away from where the end balls meet the tube (the Hessian jumps there)
        (along > 0.0 && along < (b - a).norm() ? beside : beyond) += 1;
        const test::CentralDifferences differences = test::central_differences(CapsuleDistance{capsule}, x, 1e-6);
        INFO("x = " << x.transpose() << ", d = " << d);
        CHECK((capsule.local_gradient(x) - differences.gradient).norm() < 1e-8);
        CHECK((capsule.local_hessian(x) - differences.hessian).norm() < 1e-6 * (1.0 + differences.hessian.norm()));
        CHECK(capsule.local_gradient(x).norm() == Approx(1.0).epsilon(1e-14));
    }
    CHECK(beside > 5);
    CHECK(beyond > 5);
}

TEST_CASE("capsule time of impact: exact on the side and on an end, none for a path that misses or leaves")
{
    const Capsule rod(Eigen::Vector3d::Zero(), Eigen::Vector3d(2.0, 0.0, 0.0), 0.5);
    // Down onto the side from z = 2.5 at speed 4: hits z = 0.5 at s = 0.5.
    CHECK(rod.local_time_of_impact(Eigen::Vector3d(1.0, 0.0, 2.5), Eigen::Vector3d(0.0, 0.0, -4.0)) ==
          Approx(0.5).epsilon(1e-14));
    // Along the axis onto the end ball at a = 0: from x = −3 at speed 5, hits x = −0.5 at s = 0.5.
    CHECK(rod.local_time_of_impact(Eigen::Vector3d(-3.0, 0.0, 0.0), Eigen::Vector3d(5.0, 0.0, 0.0)) ==
          Approx(0.5).epsilon(1e-14));
    // Parallel to the axis above it, leaving, and passing beside: none.
    CHECK(std::isinf(rod.local_time_of_impact(Eigen::Vector3d(-1.0, 0.0, 0.6), Eigen::Vector3d(5.0, 0.0, 0.0))));
    CHECK(std::isinf(rod.local_time_of_impact(Eigen::Vector3d(1.0, 0.0, 1.0), Eigen::Vector3d(0.0, 0.0, 1.0))));
    CHECK(std::isinf(rod.local_time_of_impact(Eigen::Vector3d(1.0, 1.0, 1.0), Eigen::Vector3d(0.0, -2.0, 0.0))));
    // A path down beyond the end whose infinite cylinder it would cross: it meets the end ball later.
    const Eigen::Vector3d p(2.3, 0.0, 2.0), dp(0.0, 0.0, -4.0);
    const double s = rod.local_time_of_impact(p, dp);
    CHECK(s == Approx((2.0 - std::sqrt(0.25 - 0.09)) / 4.0).epsilon(1e-14));
}

TEST_CASE("capsule time of impact is never late: no point of a random path before it is inside (fuzzed)")
{
    const Capsule capsule(a, b, radius);
    int hits = 0, misses = 0;
    for (unsigned seed = 1; seed <= 400; ++seed) {
        const Eigen::Vector3d p = 0.35 * (a + b) + 1.2 * random_vector(3, seed);
        if (capsule.local_distance(p) <= 1e-3)
            continue;
        // Towards a random point near the segment (most hit, some graze or miss), or anywhere.
        const Eigen::Vector3d toward = a + 0.5 * (1.0 + random_vector(1, 3000 + seed)[0]) * (b - a) +
                                       0.3 * random_vector(3, 4000 + seed);
        const Eigen::Vector3d dp = seed % 3 == 0 ? Eigen::Vector3d(2.0 * random_vector(3, 2000 + seed))
                                                 : Eigen::Vector3d(1.5 * (toward - p));
        const double s = capsule.local_time_of_impact(p, dp);
        INFO("seed " << seed << ", s = " << s);
        if (std::isinf(s)) {
            ++misses;
            for (int k = 0; k <= 1000; ++k)  // the whole path to s = 2: never inside
                CHECK(capsule.local_distance(p + (2.0 * k / 1000.0) * dp) > -1e-12);
            continue;
        }
        ++hits;
        CHECK(s >= 0.0);
        CHECK(std::abs(capsule.local_distance(p + s * dp)) < 1e-12);
        for (int k = 0; k < 1000; ++k)  // nothing earlier on the path reaches it
            CHECK(capsule.local_distance(p + (s * k / 1000.0) * dp) > 0.0);
    }
    CHECK(hits > 50);
    CHECK(misses > 50);
}

TEST_CASE("capsule: a bad radius, a zero-length segment or a non-finite end is refused")
{
    const double nan = std::numeric_limits<double>::quiet_NaN();
    CHECK_THROWS_AS(Capsule(a, b, 0.0), Error);
    CHECK_THROWS_AS(Capsule(a, b, -0.1), Error);
    CHECK_THROWS_AS(Capsule(a, b, nan), Error);
    CHECK_THROWS_WITH(Capsule(a, a, radius), Catch::Contains("start and end must differ"));
    CHECK_THROWS_AS(Capsule(Eigen::Vector3d(nan, 0.0, 0.0), b, radius), Error);
}

TEST_CASE("capsule: drawn as a tube with half balls, every drawn point on its surface, where it stands at t")
{
    const Capsule capsule(a, b, radius, 0.0, Eigen::Vector3d(0.0, 0.0, -1.0));
    const TriMesh drawn = capsule.surface_at({-1.0, 1.0, -1.0, 1.0, -1.0, 1.0}, 0.25);
    REQUIRE(drawn.V.rows() == 26 * 48);
    REQUIRE(drawn.F.rows() == 2 * 25 * 48);
    for (Eigen::Index v = 0; v < drawn.V.rows(); ++v)
        CHECK(std::abs(capsule.distance(drawn.V.row(v).transpose(), 0.25)) < 1e-14);
    CHECK(drawn.F.maxCoeff() < drawn.V.rows());
}

TEST_CASE("a block dropped on a horizontal capsule comes to rest astride its crest, its contact forces carrying its weight",
          "[ex14.4]")
{
    // A one-cube block falls from 1 cm above onto a capsule along x of radius 0.5 m whose crest z = 0 runs under
    // the middle of its bottom face: its two bottom edges land on either side of the crest, where the
    // surface falls by 0.05²/(2 · 0.5) = 2.5 mm. The barrier acts on vertices only, so the block
    // stands on those two edges, its normals tilted by ±0.1 rad: their sideways parts cancel. Without
    // friction it would slide off (turning the block about the axis keeps every distance, and lowers
    // it); friction (μ = 0.5, the capsule's) holds it.
    BlockSettings settings;
    settings.height = 0.01;
    settings.time_step = 0.05;  // backward Euler's damping brings the block to rest in a few steps
    settings.newton.relative_tolerance = 1e-10;
    settings.obstacles = {std::make_shared<Capsule>(Eigen::Vector3d(-0.2, 0.05, -0.5), Eigen::Vector3d(0.3, 0.05, -0.5), 0.5, 0.5)};
    BlockScene block = block_scene(settings);
    for (int step = 0; step < 60; ++step) {
        block.step();
        REQUIRE(block.contact->smallest_distance(block.state.u) > 0.0);
    }
    const test::RestWeight rest = test::rest_weight(block, settings);
    INFO("sum of contact forces " << rest.contact.transpose() << " N, of the barrier's " << rest.barrier.transpose()
                                  << " N, weight " << rest.weight << " N, bound " << rest.bound << " N");
    // The floor's check (test_scenes.cpp), on every contact force: the barrier's and the friction's.
    CHECK(std::abs(rest.contact.z() - rest.weight) <= rest.bound);
    CHECK(rest.bound <= 1e-6 * rest.weight);  // equilibrium: the momentum no longer changes
    CHECK(std::abs(rest.contact.x()) + std::abs(rest.contact.y()) <= 1e-6 * rest.weight);
    // The barrier carries the weight but for what friction still holds: the corners, pushed in by the
    // tilted normals, are held by friction until its smoothing lets them creep (1.1e-4 W after 60
    // steps, 3.1e-5 W after 200: measured).
    CHECK(std::abs(rest.barrier.z() - rest.weight) <= 2e-4 * rest.weight);
    CHECK(std::abs(rest.barrier.x()) + std::abs(rest.barrier.y()) <= 1e-6 * rest.weight);
    // On the capsule's surface within d̂, level: its lowest vertices 2.5 mm below the crest.
    CHECK(block.contact->smallest_distance(block.state.u) < settings.contact.activation_distance);
    CHECK(std::abs(lowest_height(*block.body, block.state.u) + 0.0025) < settings.contact.activation_distance);
    CHECK(mean_velocity(*block.body, block.state.v).norm() < 1e-6);
}
