// Chapter 04: signed volume, shape functions, their gradients, and locating points.
// docs/04_tet_jacobians.md
#include "04_tet_jacobians/tet_jacobians.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"

#include "04_tet_jacobians/tet_fixtures.hpp"
#include "common/test_support.hpp"
#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <random>

using namespace fem::tet;
using fem::test::skew_tet;
using Catch::Matchers::Contains;
using fem::test::EntriesNear;
using fem::test::entries_of;

namespace {

/// Random barycentric coordinates strictly inside the tet (all ≥ 0.02).
Eigen::Vector4d random_inside_phi(std::mt19937& random)
{
    std::uniform_real_distribution<double> u(0.02, 1.0);
    Eigen::Vector4d phi(u(random), u(random), u(random), u(random));
    return phi / phi.sum();
}

}  // namespace

TEST_CASE("signed volume: the unit corner tet, scaling, orientation, and the mesh's own volume",
          "[ex04.1]")
{
    TetVertices unit;
    unit << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
    CHECK(signed_volume(unit) == Approx(1.0 / 6.0).epsilon(1e-15));

    // Swapping two vertices inverts the tet; scaling by s multiplies the volume by s³.
    TetVertices swapped = unit;
    swapped.row(2).swap(swapped.row(3));
    CHECK(signed_volume(swapped) == Approx(-1.0 / 6.0).epsilon(1e-15));
    CHECK(signed_volume(2.0 * unit) == Approx(8.0 / 6.0).epsilon(1e-15));

    // Translation does not change it, and it agrees with common's tet_signed_volume6 on a mesh.
    TetVertices moved = skew_tet();
    moved.rowwise() += Eigen::RowVector3d(5.0, -3.0, 2.0);
    CHECK(signed_volume(moved) == Approx(signed_volume(skew_tet())).epsilon(1e-12));
    const fem::TetMesh box = fem::box_mesh(2, 1, 1, Eigen::Vector3d(2.0, 0.5, 0.7));
    double sum = 0.0;
    for (int t = 0; t < box.T.rows(); ++t) {
        const double v = signed_volume(tet_vertices(box, box.V, t));
        CHECK(v == Approx(fem::tet_signed_volume6(box, t) / 6.0).epsilon(1e-13));
        sum += v;
    }
    CHECK(sum == Approx(2.0 * 0.5 * 0.7).epsilon(1e-13));
}

TEST_CASE("shape functions: Kronecker delta at the vertices, partition of unity, linear reproduction",
          "[ex04.2]")
{
    const TetVertices X = skew_tet();
    for (int i = 0; i < 4; ++i) {
        const Eigen::Vector4d phi = shape_functions(X, X.row(i).transpose());
        INFO("at vertex " << i);
        CHECK_THAT(entries_of(phi), EntriesNear(Eigen::Vector4d::Unit(i), 1e-14));
    }
    std::mt19937 random(4);
    std::uniform_real_distribution<double> coordinate(-1.0, 2.0);
    for (int k = 0; k < 50; ++k) {
        const Eigen::Vector3d p(coordinate(random), coordinate(random), coordinate(random));
        const Eigen::Vector4d phi = shape_functions(X, p);
        CHECK(phi.sum() == Approx(1.0).margin(1e-13));                       // partition of unity
        CHECK((X.transpose() * phi - p).norm() == Approx(0.0).margin(1e-13));  // p = Σ φᵢ Xᵢ
    }
    // A point given by its barycentric coordinates gets them back.
    const Eigen::Vector4d want = random_inside_phi(random);
    CHECK((shape_functions(X, X.transpose() * want) - want).norm() == Approx(0.0).margin(1e-14));
    // The centroid has φ = ¼ each; a point beyond face 123 has φ₀ < 0.
    CHECK((shape_functions(X, X.colwise().mean().transpose()) - Eigen::Vector4d::Constant(0.25)).norm() ==
          Approx(0.0).margin(1e-14));
    const Eigen::Vector3d beyond = X.row(1).transpose() + X.row(2).transpose() + X.row(3).transpose() -
                                   2.0 * X.row(0).transpose();  // φ = (−2, 1, 1, 1)
    CHECK(shape_functions(X, beyond)[0] == Approx(-2.0).epsilon(1e-13));
}

TEST_CASE("shape gradients: rows sum to zero, and each is the inward face normal over the height",
          "[ex04.3]")
{
    const TetVertices X = skew_tet();
    const ShapeGradients G = shape_gradients(X);
    CHECK(G.colwise().sum().norm() == Approx(0.0).margin(1e-14));
    // Σ Xᵢ ∇φᵢᵀ = I: the gradient of the identity map x = X.
    CHECK((X.transpose() * G - Eigen::Matrix3d::Identity()).norm() == Approx(0.0).margin(1e-14));

    // Independent geometry: ∇φᵢ = n / h, n the unit normal of the face opposite vertex i pointing
    // towards vertex i, h the distance from vertex i to that face.
    for (int i = 0; i < 4; ++i) {
        Eigen::Vector3d face[3];
        int k = 0;
        for (int j = 0; j < 4; ++j)
            if (j != i)
                face[k++] = X.row(j).transpose();
        Eigen::Vector3d n = (face[1] - face[0]).cross(face[2] - face[0]).normalized();
        double height = n.dot(X.row(i).transpose() - face[0]);
        if (height < 0.0) {
            n = -n;
            height = -height;
        }
        CHECK((G.row(i).transpose() - n / height).norm() == Approx(0.0).margin(1e-13));
    }

    // A gradient matches the finite difference of the shape functions (exact: they are linear).
    const Eigen::Vector3d p(0.3, 0.2, 0.25);
    for (int b = 0; b < 3; ++b) {
        const Eigen::Vector3d step = 1e-3 * Eigen::Vector3d::Unit(b);
        const Eigen::Vector4d slope = (shape_functions(X, p + step) - shape_functions(X, p - step)) / 2e-3;
        CHECK((slope - G.col(b)).norm() == Approx(0.0).margin(1e-10));
    }
}

TEST_CASE("a flat (zero-volume) tet is an fem::Error naming the problem", "[ex04.3]")
{
    TetVertices flat = skew_tet();
    flat.row(3) = 0.5 * (flat.row(1) + flat.row(2));  // vertex 3 on the edge 12: all four coplanar
    CHECK(std::abs(signed_volume(skew_tet())) > 0.0);
    CHECK_THROWS_AS(shape_functions(flat, Eigen::Vector3d::Zero()), fem::Error);
    CHECK_THROWS_WITH(shape_functions(flat, Eigen::Vector3d::Zero()), Contains("flat"));
    CHECK_THROWS_AS(shape_gradients(flat), fem::Error);
    CHECK_THROWS_WITH(shape_gradients(flat), Contains("non-zero volume"));
    CHECK_THROWS_AS(jacobian_matrix(flat), fem::Error);
    CHECK_THROWS_AS(deformation_gradient(flat, skew_tet()), fem::Error);
    TetVertices point = TetVertices::Zero();  // all four vertices in one point
    CHECK_THROWS_AS(shape_gradients(point), fem::Error);
    TetVertices broken = skew_tet();
    broken(2, 1) = std::nan("");
    CHECK_THROWS_AS(shape_gradients(broken), fem::Error);
    CHECK_THROWS_WITH(shape_gradients(broken), Contains("vertex 2"));
    // A tiny but valid tet is fine: the test is relative to its size.
    CHECK(shape_gradients(1e-4 * skew_tet()).allFinite());
}

TEST_CASE("locate_point: random points in a box mesh are found with their barycentric coordinates",
          "[ex04.6]")
{
    const fem::TetMesh box = fem::box_mesh(3, 2, 2, Eigen::Vector3d(1.5, 1.0, 1.0));
    std::mt19937 random(7);
    std::uniform_int_distribution<int> pick(0, static_cast<int>(box.T.rows()) - 1);
    for (int k = 0; k < 40; ++k) {
        const int t = pick(random);
        const Eigen::Vector4d phi = random_inside_phi(random);
        const Eigen::Vector3d p = tet_vertices(box, box.V, t).transpose() * phi;
        const PointLocation where = locate_point(box, p);
        REQUIRE(where.inside);
        CHECK(where.tet == t);  // strictly inside: no other tet contains it
        CHECK((where.phi - phi).norm() == Approx(0.0).margin(1e-13));
    }
    // A vertex of the mesh lies in (the closure of) some tet that has it as a corner.
    const PointLocation corner = locate_point(box, box.V.row(5).transpose());
    REQUIRE(corner.inside);
    CHECK(corner.phi.maxCoeff() == Approx(1.0).epsilon(1e-13));
    CHECK((box.T.row(corner.tet).array() == 5).any());
}

TEST_CASE("locate_point: a point outside the mesh is reported outside, with the nearest tet", "[ex04.6]")
{
    const fem::TetMesh box = fem::box_mesh(2, 2, 2);
    const PointLocation out = locate_point(box, Eigen::Vector3d(1.2, 0.5, 0.5));
    CHECK_FALSE(out.inside);
    REQUIRE(out.tet >= 0);
    CHECK(out.phi.minCoeff() < 0.0);
    CHECK(out.phi.sum() == Approx(1.0).margin(1e-13));
    // The nearest tet touches the face x = 1 the point is beyond.
    const TetVertices X = tet_vertices(box, box.V, out.tet);
    CHECK(X.col(0).maxCoeff() == Approx(1.0));
    // Just outside within the tolerance counts as inside; just beyond it does not.
    CHECK(locate_point(box, Eigen::Vector3d(1.0 + 1e-14, 0.3, 0.6), 1e-12).inside);
    CHECK_FALSE(locate_point(box, Eigen::Vector3d(1.0 + 1e-6, 0.3, 0.6), 1e-12).inside);
}

TEST_CASE("locate_point rejects bad input with fem::Error", "[ch04]")
{
    const fem::TetMesh box = fem::box_mesh(1, 1, 1);
    CHECK_THROWS_AS(locate_point(box, Eigen::Vector3d(0.5, std::nan(""), 0.5)), fem::Error);
    CHECK_THROWS_WITH(locate_point(box, Eigen::Vector3d(0.5, std::nan(""), 0.5)), Contains("finite"));
    CHECK_THROWS_AS(locate_point(box, Eigen::Vector3d::Zero(), -1.0), fem::Error);
    CHECK_THROWS_WITH(locate_point(box, Eigen::Vector3d::Zero(), -1.0), Contains("tolerance"));
    fem::TetMesh flat = box;
    flat.V.row(flat.T(4, 3)) = flat.V.row(flat.T(4, 0));  // collapses every tet using that vertex
    CHECK_THROWS_AS(locate_point(flat, Eigen::Vector3d::Zero()), fem::Error);
    CHECK_THROWS_WITH(locate_point(flat, Eigen::Vector3d::Zero()), Contains("tetrahedron"));
    CHECK_THROWS_AS(locate_point(fem::TetMesh{}, Eigen::Vector3d::Zero()), fem::Error);
    CHECK_THROWS_WITH(locate_point(fem::TetMesh{}, Eigen::Vector3d::Zero()), Contains("no tetrahedra"));
}
