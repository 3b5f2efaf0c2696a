// Chapter 15: a triangle mesh as an obstacle — the closest point of a triangle against chapter 13's
// (Ericson's Voronoi walk, written independently), the AABB tree's nearest triangle against testing
// every one, the distance's gradient and Hessian and the barrier's on it against central differences
// in the face, edge and vertex regions, conservative advancement, and the sampled grid's error bound.
// docs/15_body_contact.md#mesh-obstacles
#include "14_contact/barrier.hpp"
#include "15_body_contact/mesh_obstacle.hpp"

#include "13_skinning/skinning.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh_io.hpp"
#include "common/random.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

using namespace fem;
using namespace fem::contact;

namespace {

/// One triangle in a tilted plane, for the region checks.
TriMesh one_triangle()
{
    TriMesh mesh;
    mesh.V.resize(3, 3);
    mesh.V << 0.0, 0.0, 0.0,  //
        0.3, 0.05, 0.02,      //
        0.1, 0.25, -0.04;
    mesh.F.resize(1, 3);
    mesh.F << 0, 1, 2;
    return mesh;
}

/// The course's bowl (data/bowl.obj, 0.3 m across): an open sheet, so its distance has no inside.
TriMesh bowl()
{
    return io::read_tri_mesh(data_path("bowl.obj"));
}

}  // namespace

TEST_CASE("closest point of a triangle: chapter 13's Voronoi walk's point, its feature where it is put",
          "[ex15.1]")
{
    for (unsigned seed = 1; seed <= 500; ++seed) {
        const Eigen::Vector3d a = random_vector(3, seed), b = random_vector(3, 1000 + seed), c = random_vector(3, 2000 + seed);
        if ((b - a).cross(c - a).norm() < 1e-3)
            continue;
        const Eigen::Vector3d p = 2.0 * random_vector(3, 3000 + seed);
        const TrianglePoint q = closest_triangle_point(p, a, b, c);
        INFO("seed " << seed);
        CHECK((q.point - skin::closest_point_on_triangle(p, a, b, c)).norm() < 1e-12);
    }
    const TriMesh t = one_triangle();
    const Eigen::Vector3d a = t.V.row(0), b = t.V.row(1), c = t.V.row(2);
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    // Above the centroid: the face; off the middle of edge b → c, outward in the plane: that edge;
    // beyond corner c along the sum of its edges' outward directions: the corner.
    const TrianglePoint face = closest_triangle_point((a + b + c) / 3.0 + 0.01 * n, a, b, c);
    CHECK(face.feature == TriangleFeature::face);
    const Eigen::Vector3d out_bc = (c - b).cross(n).normalized();
    const TrianglePoint edge = closest_triangle_point(0.5 * (b + c) + 0.02 * out_bc - 0.01 * n, a, b, c);
    CHECK(edge.feature == TriangleFeature::edge);
    CHECK(edge.corner == 1);
    CHECK((edge.point - 0.5 * (b + c)).norm() < 1e-12);
    const Eigen::Vector3d beyond_c = (c - a).normalized() + (c - b).normalized();
    const TrianglePoint corner = closest_triangle_point(c + 0.05 * beyond_c + 0.01 * n, a, b, c);
    CHECK(corner.feature == TriangleFeature::vertex);
    CHECK(corner.corner == 2);
    CHECK(corner.point == c);
}

TEST_CASE("mesh obstacle: the AABB tree finds the distance that testing every triangle finds", "[ex15.1]")
{
    const MeshObstacle mesh(bowl());
    REQUIRE(mesh.surface().F.rows() > 100);
    const Eigen::Vector3d low = mesh.surface().V.colwise().minCoeff(), high = mesh.surface().V.colwise().maxCoeff();
    const Eigen::Vector3d centre = 0.5 * (low + high), half = 0.75 * (high - low);
    int on_surface = 0;
    for (unsigned seed = 1; seed <= 2000; ++seed) {
        Eigen::Vector3d p = centre + half.cwiseProduct(random_vector(3, seed));
        if (seed % 4 == 0) {  // a quarter of them within 1 mm of the surface, where triangles compete closely
            const int v = static_cast<int>(seed % mesh.surface().V.rows());
            p = mesh.surface().V.row(v).transpose() + 1e-3 * random_vector(3, 9000 + seed);
            ++on_surface;
        }
        const MeshObstacle::Nearest tree = mesh.nearest(p), brute = mesh.nearest_brute_force(p);
        INFO("seed " << seed << ", p = " << p.transpose());
        REQUIRE(tree.triangle >= 0);
        CHECK(std::abs(tree.distance - brute.distance) <= 1e-15 * (1.0 + brute.distance));
        CHECK((tree.closest.point - brute.closest.point).norm() <= 1e-12);
        CHECK(mesh.local_distance(p) == tree.distance);
    }
    CHECK(on_surface == 500);
}

TEST_CASE("mesh obstacle: distance, gradient and Hessian, and the barrier on them, against central "
          "differences in the face, edge and vertex regions", "[ex15.1]")
{
    const MeshObstacle mesh(one_triangle());
    const TriMesh& t = mesh.surface();
    const Eigen::Vector3d a = t.V.row(0), b = t.V.row(1), c = t.V.row(2);
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    const double dhat = 1e-3, kappa = 1e4;
    struct Place {
        TriangleFeature feature;
        Eigen::Vector3d point;
    };
    const Eigen::Vector3d out_bc = (c - b).cross(n).normalized(), beyond_c = ((c - a).normalized() + (c - b).normalized()).normalized();
    const Place places[] = {{TriangleFeature::face, (a + b + c) / 3.0 + 4e-4 * n},
                            {TriangleFeature::face, (a + b + c) / 3.0 - 3e-4 * n},  // the other side: unsigned
                            {TriangleFeature::edge, 0.4 * b + 0.6 * c + 3e-4 * out_bc + 2e-4 * n},
                            {TriangleFeature::vertex, c + 3e-4 * beyond_c - 2e-4 * n}};
    for (const Place& place : places) {
        const Eigen::Vector3d& x = place.point;
        const MeshObstacle::Nearest nearest = mesh.nearest(x);
        REQUIRE(nearest.closest.feature == place.feature);
        REQUIRE(nearest.distance < dhat);
        // The barrier's energy of this vertex, κ b(d(x)), and its gradient and Hessian from ∇d, ∇²d.
        const auto energy = [&](const Eigen::Vector3d& y) { return kappa * barrier(mesh.local_distance(y), dhat).value; };
        const auto gradient = [&](const Eigen::Vector3d& y) {
            return Eigen::Vector3d(kappa * barrier(mesh.local_distance(y), dhat).first * mesh.local_gradient(y));
        };
        const BarrierValue bx = barrier(nearest.distance, dhat);
        const Eigen::Vector3d g = mesh.local_gradient(x);
        const Eigen::Matrix3d H = kappa * (bx.second * g * g.transpose() + bx.first * mesh.local_hessian(x));
        const double h = 1e-8;
        Eigen::Vector3d distance_fd, energy_fd;
        Eigen::Matrix3d unit_fd, energy_hessian_fd;
        for (int i = 0; i < 3; ++i) {
            const Eigen::Vector3d e = h * Eigen::Vector3d::Unit(i);
            distance_fd[i] = (mesh.local_distance(x + e) - mesh.local_distance(x - e)) / (2.0 * h);
            unit_fd.col(i) = (mesh.local_gradient(x + e) - mesh.local_gradient(x - e)) / (2.0 * h);
            energy_fd[i] = (energy(x + e) - energy(x - e)) / (2.0 * h);
            energy_hessian_fd.col(i) = (gradient(x + e) - gradient(x - e)) / (2.0 * h);
        }
        INFO("feature " << static_cast<int>(place.feature) << ", d = " << nearest.distance);
        CHECK((g - distance_fd).norm() < 1e-7);
        CHECK(std::abs(g.norm() - 1.0) < 1e-14);
        CHECK((mesh.local_hessian(x) - unit_fd).norm() < 1e-5 * (1.0 + unit_fd.norm()));
        CHECK((gradient(x) - energy_fd).norm() < 1e-6 * energy_fd.norm());
        CHECK((H - energy_hessian_fd).norm() < 1e-5 * energy_hessian_fd.norm());
    }
}

TEST_CASE("mesh obstacle: the time of impact is the first crossing of the path, nothing earlier, none missed",
          "[ex15.4]")
{
    const MeshObstacle mesh(bowl());
    int hits = 0, misses = 0;
    for (unsigned seed = 1; seed <= 400; ++seed) {
        const Eigen::Vector3d p = 0.2 * random_vector(3, seed) + Eigen::Vector3d(0.0, 0.0, 0.1);
        if (mesh.local_distance(p) < 1e-4)
            continue;
        const Eigen::Vector3d dp = 0.5 * random_vector(3, 500 + seed);
        const double s = mesh.local_time_of_impact(p, dp);
        INFO("seed " << seed << ", s = " << s);
        // A path that crosses the sheet within s ≤ 1 (the segment test, an independent formula) has an impact.
        if (mesh.crosses(p, p + dp))
            CHECK(s <= 1.0);
        if (std::isinf(s)) {
            ++misses;
            continue;
        }
        ++hits;
        CHECK(mesh.local_distance(p + s * dp) <= 1e-12);  // on the sheet
        for (int k = 0; k < 200; ++k)                      // and nowhere before it
            REQUIRE(mesh.local_distance(p + (s * k / 200.0) * dp) > 0.0);
    }
    CHECK(hits > 30);
    CHECK(misses > 30);
    // Head on at one triangle: s exact to round-off; along its plane but off it: no impact.
    const MeshObstacle triangle(one_triangle());
    const Eigen::Vector3d a = triangle.surface().V.row(0), b = triangle.surface().V.row(1), c = triangle.surface().V.row(2);
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized(), centroid = (a + b + c) / 3.0;
    CHECK(triangle.local_time_of_impact(centroid + 0.1 * n, -0.4 * n) == Approx(0.25).epsilon(1e-12));
    CHECK(std::isinf(triangle.local_time_of_impact(centroid + 0.1 * n, b - a)));
    // Through a shared edge of the tent-like pair of triangles below, exactly on it: caught.
    TriMesh pair;
    pair.V.resize(4, 3);
    pair.V << 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0;
    pair.F.resize(2, 3);
    pair.F << 0, 1, 2, 0, 2, 3;
    const MeshObstacle square(pair);
    for (double t : {0.1, 1.0 / 3.0, 0.5, 0.7})
        CHECK(square.local_time_of_impact(Eigen::Vector3d(t, t, 0.3), Eigen::Vector3d(0.0, 0.0, -0.6)) ==
              Approx(0.5).epsilon(1e-12));
    // The conservative advancement shared with the box: never past the first zero, at 5 % of the start.
    for (unsigned seed = 1; seed <= 100; ++seed) {
        const Eigen::Vector3d p = 0.2 * random_vector(3, seed) + Eigen::Vector3d(0.0, 0.0, 0.1);
        const Eigen::Vector3d dp = 0.5 * random_vector(3, 700 + seed);
        if (mesh.local_distance(p) < 1e-4)
            continue;
        const double conservative = conservative_time_of_impact(mesh, p, dp), exact = mesh.local_time_of_impact(p, dp);
        INFO("seed " << seed);
        CHECK(conservative <= exact);
    }
}

TEST_CASE("mesh obstacle: the time of impact is the earliest crossing over every triangle (brute force)", "[ex15.4]")
{
    // Each triangle's crossing of the path p + s dp on its own, by the plane's equation and the
    // barycentric coordinates of the crossing (independent of the tree): the earliest s of the
    // crossings clear of every edge (barycentrics ≥ 1e-9) bounds the mesh's answer from above, the
    // earliest of those within 1e-9 of the triangle from below. Paths through the bowl cross it
    // twice or more: they tell the earliest crossing from the first one found.
    const MeshObstacle mesh(bowl());
    const TriMesh& surface = mesh.surface();
    constexpr int printed = 5;
    int mismatches = 0, twice = 0;
    for (unsigned seed = 1; seed <= 1000; ++seed) {
        // Through a point m inside the bowl (0.28 m across, 0.1 m deep), from m − d to m + d.
        const Eigen::Vector3d m = Eigen::Vector3d(0.08, 0.08, 0.04).cwiseProduct(random_vector(3, seed)) +
                                  Eigen::Vector3d(0.0, 0.0, 0.05);
        const Eigen::Vector3d d = 0.3 * random_vector(3, 900 + seed);
        const Eigen::Vector3d p = m - d, dp = 2.0 * d;
        double clear = std::numeric_limits<double>::infinity(), near = clear;
        int crossings = 0;
        for (Eigen::Index f = 0; f < surface.F.rows(); ++f) {
            const Eigen::Vector3d a = surface.V.row(surface.F(f, 0)), b = surface.V.row(surface.F(f, 1)),
                                  c = surface.V.row(surface.F(f, 2));
            const Eigen::Vector3d n = (b - a).cross(c - a);
            const double towards = n.dot(dp);
            if (towards == 0.0)
                continue;
            const double s = n.dot(a - p) / towards;
            if (!(s >= 0.0 && s <= 1.0))
                continue;
            const Eigen::Vector3d q = p + s * dp;
            const double area = n.squaredNorm();
            const double alpha = (b - q).cross(c - q).dot(n) / area, beta = (c - q).cross(a - q).dot(n) / area;
            const double gamma = 1.0 - alpha - beta;
            const double least = std::min({alpha, beta, gamma});
            if (least >= -1e-9)
                near = std::min(near, s);
            if (least >= 1e-9) {
                clear = std::min(clear, s);
                ++crossings;
            }
        }
        twice += crossings >= 2 ? 1 : 0;
        if (mesh.local_distance(p) < 1e-6)
            continue;  // starting on the sheet: s = 0 either way
        // Beyond s = 1 the path's step is over: an answer there (up to s = 2, the function's reach)
        // counts as no impact, as the brute force's.
        const double answer = mesh.local_time_of_impact(p, dp);
        const double s = answer <= 1.0 ? answer : std::numeric_limits<double>::infinity();
        if (s <= clear + 1e-12 && (std::isinf(near) ? std::isinf(s) : s >= near - 1e-12))
            continue;
        if (++mismatches <= printed) {
            std::ostringstream out;
            out.precision(17);
            out << "seed " << seed << ": local_time_of_impact(p = (" << p.transpose() << "), dp = (" << dp.transpose()
                << ")) = " << answer << "; the earliest crossing over every triangle: " << clear << " (clear of the edges), "
                << near << " (within 1e-9)";
            UNSCOPED_INFO(out.str());
        }
    }
    INFO(mismatches << " of 1000 paths wrong (the first " << printed << " above), " << twice << " through two walls");
    CHECK(mismatches == 0);
    CHECK(twice > 100);  // enough paths through two walls to tell the earliest crossing from another
}

TEST_CASE("mesh obstacle: a path through a shared edge of two random triangles is caught there, whatever the round-off",
          "[ex15.4]")
{
    // Two triangles (a, b, c) and (b, a, d) sharing the edge ab, all corners random (not representable
    // in binary); a path from above through a random point q of ab, reaching it at s = 1/2. Without
    // the triangles grown at their edges, round-off puts q outside both on about a quarter of them.
    int missed = 0;
    for (unsigned seed = 1; seed <= 2000; ++seed) {
        const Eigen::Vector3d a = random_vector(3, seed), b = random_vector(3, 3000 + seed);
        const Eigen::Vector3d side = random_vector(3, 6000 + seed);
        const Eigen::Vector3d normal = (b - a).cross(side).normalized();
        // c and d on either side of ab, in planes tilted a little against each other (a crease).
        const Eigen::Vector3d across = normal.cross(b - a).normalized();
        const Eigen::Vector3d c = 0.5 * (a + b) + 0.7 * across + 0.1 * normal;
        const Eigen::Vector3d d = 0.5 * (a + b) - 0.7 * across + 0.1 * normal;
        TriMesh pair;
        pair.V.resize(4, 3);
        pair.V << a.transpose(), b.transpose(), c.transpose(), d.transpose();
        pair.F.resize(2, 3);
        pair.F << 0, 1, 2, 1, 0, 3;
        const MeshObstacle mesh(pair);
        const double t = 0.05 + 0.9 * (0.5 + 0.5 * random_vector(1, 9000 + seed)[0]);
        const Eigen::Vector3d q = a + t * (b - a);
        const Eigen::Vector3d wobble = random_vector(3, 12000 + seed);
        const Eigen::Vector3d p = q + 0.3 * normal + 0.1 * wobble.cross(b - a);
        const Eigen::Vector3d dp = 2.0 * (q - p);
        const double s = mesh.local_time_of_impact(p, dp);
        const bool caught = s >= 0.5 - 1e-9 && s <= 0.5 + 1e-9;
        if (!caught) {
            ++missed;
            UNSCOPED_INFO("seed " << seed << ": a = (" << a.transpose() << "), b = (" << b.transpose() << "), t = " << t
                                  << ", p = (" << p.transpose() << "), dp = (" << dp.transpose() << "): s = " << s
                                  << ", expected 0.5");
        }
    }
    CHECK(missed == 0);
}

TEST_CASE("mesh obstacle: degenerate and empty meshes are refused, naming the triangle")
{
    TriMesh flat = one_triangle();
    flat.V.row(2) = 0.5 * (flat.V.row(0) + flat.V.row(1));
    CHECK_THROWS_WITH(MeshObstacle(flat, 0.0, Eigen::Vector3d::Zero(), "stairs.obj"),
                      Catch::Contains("stairs.obj") && Catch::Contains("triangle 0") && Catch::Contains("zero area"));
    TriMesh empty;
    CHECK_THROWS_WITH(MeshObstacle(empty), Catch::Contains("empty"));
}

TEST_CASE("sampled distance grid: exact at its nodes, within sqrt(3) h everywhere, and finer with h", "[ex15.1]")
{
    const MeshObstacle mesh(bowl());
    double previous = 0.0;
    for (double spacing : {0.02, 0.01, 0.005}) {
        const DistanceGrid grid(mesh, spacing, 0.02);
        const double h = grid.spacing().maxCoeff();
        CHECK(h <= spacing);
        double largest = 0.0, mean = 0.0;
        const Eigen::Vector3d low = mesh.surface().V.colwise().minCoeff(), high = mesh.surface().V.colwise().maxCoeff();
        const int samples = 2000;
        for (int s = 0; s < samples; ++s) {
            const Eigen::Vector3d p = 0.5 * (low + high) + 0.5 * (high - low).cwiseProduct(random_vector(3, 77 + s));
            const double error = std::abs(grid.distance(p) - mesh.local_distance(p));
            largest = std::max(largest, error);
            mean += error / samples;
        }
        INFO("spacing " << spacing << ": largest error " << largest << ", mean " << mean);
        // Trilinear weights sum to 1 and d is 1-Lipschitz: |Σ wᵢ d(xᵢ) − d(p)| ≤ max |xᵢ − p| ≤ √3 h.
        CHECK(largest <= std::sqrt(3.0) * h);
        if (previous > 0.0)
            CHECK(mean < 0.6 * previous);  // first order at least (the kink at the surface), second away from it
        previous = mean;
    }
    // At a node the sample itself.
    const DistanceGrid grid(mesh, 0.01, 0.02);
    const Eigen::Vector3d node = mesh.surface().V.colwise().minCoeff().transpose().array() - 0.02;
    const Eigen::Vector3d at = node + 3.0 * grid.spacing();
    CHECK(std::abs(grid.distance(at) - mesh.local_distance(at)) < 1e-15);
    // The gradient: the interpolant's central differences inside a cell.
    const Eigen::Vector3d inside = at + 0.3 * grid.spacing();
    Eigen::Vector3d fd;
    for (int i = 0; i < 3; ++i) {
        const Eigen::Vector3d e = 1e-7 * Eigen::Vector3d::Unit(i);
        fd[i] = (grid.distance(inside + e) - grid.distance(inside - e)) / 2e-7;
    }
    CHECK((grid.gradient(inside) - fd).norm() < 1e-6);
    CHECK_THROWS_AS(DistanceGrid(mesh, 0.0, 0.02), Error);
    CHECK_THROWS_AS(DistanceGrid(mesh, 1e-5, 0.02), Error);
}

TEST_CASE("mesh obstacle: a segment through a triangle crosses it, one beside it or above it does not")
{
    const MeshObstacle mesh(one_triangle());
    const Eigen::Vector3d a = mesh.surface().V.row(0), b = mesh.surface().V.row(1), c = mesh.surface().V.row(2);
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized(), centroid = (a + b + c) / 3.0;
    CHECK(mesh.crosses(centroid + 0.1 * n, centroid - 0.1 * n));
    CHECK(mesh.crosses(centroid - 0.1 * n, centroid + 1e-9 * n));  // just through
    CHECK(!mesh.crosses(centroid - 0.1 * n, centroid - 1e-9 * n));  // just short
    CHECK(!mesh.crosses(centroid + 0.1 * n, centroid + 0.01 * n));
    const Eigen::Vector3d beside = c + 0.05 * ((c - a).normalized() + (c - b).normalized());
    CHECK(!mesh.crosses(beside + 0.1 * n, beside - 0.1 * n));
    // Across the bowl's wall from inside to outside, and from its rim's height down its axis (never through).
    const MeshObstacle bowl_mesh(bowl());
    CHECK(bowl_mesh.crosses(Eigen::Vector3d(0.0, 0.0, 0.05), Eigen::Vector3d(0.3, 0.0, 0.05)));
    CHECK(!bowl_mesh.crosses(Eigen::Vector3d(0.0, 0.0, 0.2), Eigen::Vector3d(0.0, 0.0, 0.01)));
}
