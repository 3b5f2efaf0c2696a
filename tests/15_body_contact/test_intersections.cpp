// Chapter 15: the intersection check (intersections.hpp) — the certified orientation against exact
// integer arithmetic, the segment–triangle test against a parametric answer clear of its borders,
// and the first edge through a triangle against testing every pair.
// docs/15_body_contact.md#never-an-intersection
#include "15_body_contact/broad_phase.hpp"
#include "15_body_contact/body_contact.hpp"
#include "15_body_contact/intersections.hpp"
#include "14_contact/obstacles.hpp"

#include "10_linear_dynamics/body.hpp"

#include "contact_bodies.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"
#include "common/random.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

using namespace fem;
using namespace fem::contact;
using Catch::Matchers::Contains;

namespace {

/// A point of integer coordinates in [−512, 512], from seed.
Eigen::Vector3d integer_point(unsigned seed)
{
    return (512.0 * random_vector(3, seed)).array().round().matrix();
}

/// (b − a) × (c − a) · (d − a) in 64-bit integers: exact for coordinates of magnitude ≤ 512.
std::int64_t exact_orientation(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                               const Eigen::Vector3d& d)
{
    const Eigen::Matrix<std::int64_t, 3, 1> ia = a.cast<std::int64_t>(), ib = b.cast<std::int64_t>(),
                                            ic = c.cast<std::int64_t>(), id = d.cast<std::int64_t>();
    return (ib - ia).cross(ic - ia).dot(id - ia);
}

/// The first crossing by testing every edge against every triangle it shares no vertex with.
EdgeThroughTriangle brute_force_crossing(const MatrixX3d& x, const Eigen::MatrixX2i& edges, const MatrixX3i& triangles)
{
    for (Eigen::Index e = 0; e < edges.rows(); ++e)
        for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
            const auto tri = triangles.row(t);
            if ((tri.array() == edges(e, 0)).any() || (tri.array() == edges(e, 1)).any())
                continue;
            if (segment_meets_triangle(x.row(edges(e, 0)).transpose(), x.row(edges(e, 1)).transpose(),
                                       x.row(tri(0)).transpose(), x.row(tri(1)).transpose(), x.row(tri(2)).transpose()))
                return {static_cast<int>(e), static_cast<int>(t)};
        }
    return {};
}

/// Two one-cell boxes of size 0.1, the second's lowest corner at corner: one vertex array.
TetMesh two_boxes(const Eigen::Vector3d& corner)
{
    const Eigen::Vector3d size = Eigen::Vector3d::Constant(0.1);
    return test::two_bodies(test::box_at(Eigen::Vector3d::Zero(), size), test::box_at(corner, size));
}

}  // namespace

TEST_CASE("certified orientation: the exact sign on integer points, 0 exactly when coplanar")
{
    int zero = 0;
    for (unsigned seed = 1; seed <= 4000; ++seed) {
        const Eigen::Vector3d a = integer_point(seed), b = integer_point(10000 + seed), c = integer_point(20000 + seed);
        Eigen::Vector3d d = integer_point(30000 + seed);
        if (seed % 4 == 0)  // coplanar: an integer combination of a, b, c with weights summing to 1
            d = a + 2.0 * (b - a) - 3.0 * (c - a);
        const std::int64_t exact = exact_orientation(a, b, c, d);
        INFO("seed " << seed << ": exact " << exact);
        CHECK(certified_orientation(a, b, c, d) == (exact > 0) - (exact < 0));
        zero += exact == 0;
    }
    CHECK(zero >= 1000);
    // Far from the integers: a point a hair off a tilted plane is never given the wrong side.
    const Eigen::Vector3d a(0.1, 0.2, 0.3), b(1.7, -0.4, 0.9), c(-0.3, 1.1, 0.2);
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized(), centre = (a + b + c) / 3.0;
    for (double h : {1e-3, 1e-9, 1e-14}) {
        INFO("h = " << h);
        CHECK(certified_orientation(a, b, c, centre + h * n) >= 0);
        CHECK(certified_orientation(a, b, c, centre - h * n) <= 0);
    }
    CHECK(certified_orientation(a, b, c, centre + 1e-3 * n) == 1);
    CHECK(certified_orientation(a, b, c, centre - 1e-3 * n) == -1);
}

TEST_CASE("segment and triangle: meets where the parametric crossing is inside, apart where it is clearly "
          "outside, touching counts")
{
    int met = 0, apart = 0;
    for (unsigned seed = 1; seed <= 5000; ++seed) {
        const Eigen::Vector3d a = random_vector(3, seed), b = random_vector(3, 1000 + seed),
                              c = random_vector(3, 2000 + seed), p = 2.0 * random_vector(3, 3000 + seed),
                              q = 2.0 * random_vector(3, 4000 + seed);
        // p + s (q − p) = a + u (b − a) + v (c − a), solved by QR: the crossing of the line and the plane.
        Eigen::Matrix3d system;
        system << q - p, a - b, a - c;
        if (std::abs(system.determinant()) < 1e-3)
            continue;
        const Eigen::Vector3d suv = system.colPivHouseholderQr().solve(a - p);
        const double s = suv[0], u = suv[1], v = suv[2], margin = 1e-9;
        const bool inside = s > margin && s < 1.0 - margin && u > margin && v > margin && u + v < 1.0 - margin;
        const bool outside = s < -margin || s > 1.0 + margin || u < -margin || v < -margin || u + v > 1.0 + margin;
        INFO("seed " << seed << ": s = " << s << ", u = " << u << ", v = " << v);
        if (inside) {
            CHECK(segment_meets_triangle(p, q, a, b, c));
            CHECK(segment_meets_triangle(q, p, c, a, b));  // either direction, any corner first
            ++met;
        } else if (outside) {
            CHECK_FALSE(segment_meets_triangle(p, q, a, b, c));
            CHECK_FALSE(segment_meets_triangle(q, p, b, c, a));
            ++apart;
        }
    }
    CHECK(met > 100);
    CHECK(apart > 3000);
    // Touching: a segment ending on the face, one through a corner, one lying in the plane.
    const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
    CHECK(segment_meets_triangle(Eigen::Vector3d(0.25, 0.25, 1.0), Eigen::Vector3d(0.25, 0.25, 0.0), a, b, c));
    CHECK(segment_meets_triangle(Eigen::Vector3d(0.0, 0.0, 1.0), Eigen::Vector3d(0.0, 0.0, -1.0), a, b, c));
    CHECK(segment_meets_triangle(Eigen::Vector3d(-1.0, 0.2, 0.0), Eigen::Vector3d(2.0, 0.2, 0.0), a, b, c));
    // In the plane, beside the triangle (across its long edge, and parallel to it): apart.
    CHECK_FALSE(segment_meets_triangle(Eigen::Vector3d(0.6, 0.6, 0.0), Eigen::Vector3d(2.0, 0.6, 0.0), a, b, c));
    CHECK_FALSE(segment_meets_triangle(Eigen::Vector3d(1.1, 0.0, 0.0), Eigen::Vector3d(0.0, 1.1, 0.0), a, b, c));
    // A hair above the face, parallel: apart.
    CHECK_FALSE(segment_meets_triangle(Eigen::Vector3d(-1.0, 0.2, 1e-12), Eigen::Vector3d(2.0, 0.2, 1e-12), a, b, c));
}

TEST_CASE("segment and triangle: crossing, apart, touching, and in the triangle's plane")
{
    const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
    CHECK(segment_meets_triangle({0.2, 0.2, -1}, {0.2, 0.2, 1}, a, b, c));       // through the inside
    CHECK_FALSE(segment_meets_triangle({0.8, 0.8, -1}, {0.8, 0.8, 1}, a, b, c)); // past the long edge
    CHECK_FALSE(segment_meets_triangle({0.2, 0.2, 0.1}, {0.2, 0.2, 1}, a, b, c)); // above it
    CHECK(segment_meets_triangle({0.2, 0.2, 0.0}, {0.2, 0.2, 1}, a, b, c));      // an end on it
    CHECK(segment_meets_triangle({0.5, 0.0, -1}, {0.5, 0.0, 1}, a, b, c));       // through an edge
    // In the plane: inside, across an edge, apart, along an edge's line beyond it.
    CHECK(segment_meets_triangle({0.1, 0.1, 0}, {0.2, 0.2, 0}, a, b, c));
    CHECK(segment_meets_triangle({-1, 0.5, 0}, {1, 0.5, 0}, a, b, c));
    CHECK_FALSE(segment_meets_triangle({2, 2, 0}, {3, 2, 0}, a, b, c));
    CHECK_FALSE(segment_meets_triangle({1.5, 0, 0}, {2, 0, 0}, a, b, c));
    CHECK(segment_meets_triangle({1, 0, 0}, {2, 0, 0}, a, b, c));  // touching a corner
}

TEST_CASE("first edge through a triangle: none between two boxes apart, the one the tree and every pair find "
          "when a box is pushed into the other, edges of one triangle never")
{
    const Eigen::Vector3d size = Eigen::Vector3d::Constant(0.1);
    for (const double gap : {1e-3, 1e-9}) {
        const TetMesh apart = two_boxes(Eigen::Vector3d(0.0, 0.0, 0.1 + gap));
        const SurfacePrimitives surface = surface_primitives(apart);
        INFO("gap " << gap);
        CHECK_FALSE(first_edge_through_triangle(apart.V, surface.edges, surface.triangles).found());
    }
    // The upper box sunk 1 cm into the lower one and shifted off its corners: its lower edges cut the
    // lower box's upper face's triangles, and the lower box's vertical edges its lower face.
    for (unsigned seed = 1; seed <= 50; ++seed) {
        const Eigen::Vector3d shift = 0.03 * random_vector(3, seed);
        const TetMesh sunk = two_boxes(Eigen::Vector3d(shift.x(), shift.y(), 0.09 + 0.005 * shift.z()));
        const SurfacePrimitives surface = surface_primitives(sunk);
        const EdgeThroughTriangle tree = first_edge_through_triangle(sunk.V, surface.edges, surface.triangles);
        const EdgeThroughTriangle brute = brute_force_crossing(sunk.V, surface.edges, surface.triangles);
        INFO("seed " << seed << ": " << describe(tree, surface.edges, surface.triangles));
        REQUIRE(tree.found());
        CHECK(tree.edge == brute.edge);
        CHECK(tree.triangle == brute.triangle);
        CHECK_THAT(describe(tree, surface.edges, surface.triangles), Contains("meets triangle"));
    }
    // Flat faces of finer boxes, moved rigidly by offsets that are not binary fractions: an edge and a
    // triangle of one face lie in one plane (their orientations are round-off), apart in that plane.
    for (unsigned seed = 1; seed <= 20; ++seed) {
        TetMesh box = box_mesh(3, 2, 2, Eigen::Vector3d(0.1, 0.07, 0.03));
        const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.1 * seed, Eigen::Vector3d::UnitZ()).toRotationMatrix();
        box.V = (box.V * turn.transpose()).rowwise() + 0.1 * random_vector(3, 500 + seed).transpose();
        const SurfacePrimitives surface = surface_primitives(box);
        INFO("seed " << seed);
        CHECK_FALSE(first_edge_through_triangle(box.V, surface.edges, surface.triangles).found());
    }
    // One box alone, however distorted within reason, has no edge through its own triangles.
    for (unsigned seed = 1; seed <= 20; ++seed) {
        TetMesh box = box_mesh(3, 3, 3, size);
        box.V += 0.003 * random_matrix(box.V.rows(), 3, seed);
        const SurfacePrimitives surface = surface_primitives(box);
        CHECK_FALSE(first_edge_through_triangle(box.V, surface.edges, surface.triangles).found());
        CHECK_FALSE(brute_force_crossing(box.V, surface.edges, surface.triangles).found());
    }
}

TEST_CASE("first edge through a triangle: an index outside the positions or a non-finite position is refused")
{
    MatrixX3d x = MatrixX3d::Zero(4, 3);
    x.row(1) << 1, 0, 0;
    x.row(2) << 0, 1, 0;
    x.row(3) << 0, 0, 1;
    Eigen::MatrixX2i edges(1, 2);
    edges << 0, 4;
    MatrixX3i triangles(1, 3);
    triangles << 1, 2, 3;
    CHECK_THROWS_WITH(first_edge_through_triangle(x, edges, triangles), Contains("edge") && Contains("outside"));
    edges << 0, 3;
    triangles << 1, 2, -1;
    CHECK_THROWS_WITH(first_edge_through_triangle(x, edges, triangles), Contains("triangle") && Contains("outside"));
    triangles << 1, 2, 3;
    x(2, 1) = std::numeric_limits<double>::quiet_NaN();
    CHECK_THROWS_WITH(first_edge_through_triangle(x, edges, triangles), Contains("not finite"));
}

TEST_CASE("the contact potential's debug check: an edge through a face of the body or of a box obstacle is "
          "refused at the energy, naming both, and apart it is quiet", "[self][ex15.5]")
{
    dynamics::Scene scene;
    scene.mesh = two_boxes(Eigen::Vector3d(0.0, 0.0, 0.1 + 1e-2));
    const dynamics::Body body(scene);
    BodyContactOptions options;
    options.self_contact = true;
    options.check_intersections = true;
    const std::vector<std::shared_ptr<const Obstacle>> none;
    const ContactPotential bodies = body_contact_potential(body, none, options);
    Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * scene.mesh.V.rows());
    CHECK(std::isfinite(bodies.energy(u)));
    // The upper box (vertices 8 to 15) moved 2 cm down and 3 cm across: 1 cm into the lower one.
    for (Eigen::Index v = 8; v < 16; ++v) {
        u[3 * v] = 0.03;
        u[3 * v + 2] = -0.02;
    }
    CHECK_THROWS_WITH(bodies.energy(u), Contains("intersection check") && Contains("meets triangle"));

    // One box above a box obstacle turned about z, its corner pushed down through the obstacle's top face.
    dynamics::Scene one;
    one.mesh = box_mesh(1, 1, 1, Eigen::Vector3d::Constant(0.1));
    one.mesh.V.rowwise() += Eigen::RowVector3d(0.0, 0.0, 0.01);
    const dynamics::Body block(one);
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const std::vector<std::shared_ptr<const Obstacle>> box{
        std::make_shared<Box>(Eigen::Vector3d(0.05, 0.05, -0.5), Eigen::Vector3d(1.0, 1.0, 0.5), turn)};
    options.self_contact = false;
    const ContactPotential on_box = body_contact_potential(block, box, options);
    Eigen::VectorXd w = Eigen::VectorXd::Zero(24);
    CHECK(std::isfinite(on_box.energy(w)));
    w[2] = -0.02;  // vertex 0, 1 cm below the obstacle's top face: its edges cross the face
    CHECK_THROWS_WITH(on_box.energy(w), Contains("intersection check") && Contains("obstacle 0"));
}
