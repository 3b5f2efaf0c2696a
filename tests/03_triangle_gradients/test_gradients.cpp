// Chapter 03: barycentric coordinates, hat-function gradients, the gradient operator and the block
// Jacobian, checked against exact properties (linear functions, δ_ij relations) and independent
// solves. docs/03_triangle_gradients.md
#include "03_triangle_gradients/triangle_gradients.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"
#include "meshes.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Dense>

#include <random>

using namespace fem::tri;
using Catch::Matchers::Contains;
using Eigen::Vector3d;

namespace {

/// Random well-shaped triangles in 3D, with random orientations.
struct RandomTriangles {
    std::mt19937 random{11};
    std::uniform_real_distribution<double> coordinate{-2.0, 2.0};
    Vector3d point() { return Vector3d(coordinate(random), coordinate(random), coordinate(random)); }
    std::array<Vector3d, 3> next()
    {
        while (true) {
            std::array<Vector3d, 3> t{point(), point(), point()};
            if ((t[1] - t[0]).cross(t[2] - t[0]).norm() > 0.5)
                return t;
        }
    }
};

}  // namespace

TEST_CASE("barycentric coordinates: corners, centroid, reconstruction, projection", "[ex03.1]")
{
    RandomTriangles triangles;
    for (int trial = 0; trial < 20; ++trial) {
        const auto [a, b, c] = triangles.next();
        CHECK(barycentric_coordinates(a, a, b, c).isApprox(Vector3d(1, 0, 0), 1e-13));
        CHECK((barycentric_coordinates(b, a, b, c) - Vector3d(0, 1, 0)).norm() < 1e-13);
        CHECK((barycentric_coordinates(c, a, b, c) - Vector3d(0, 0, 1)).norm() < 1e-13);
        CHECK((barycentric_coordinates((a + b + c) / 3, a, b, c) - Vector3d::Constant(1.0 / 3)).norm() < 1e-13);

        // A point of the plane (inside or outside the triangle) from known weights, then lifted off
        // the plane along the normal: the coordinates are those of its projection.
        const Vector3d lambda(0.7 - 0.1 * trial, 0.2 + 0.05 * trial, 0.1 + 0.05 * trial);
        const Vector3d n = (b - a).cross(c - a).normalized();
        const Vector3d p = lambda[0] * a + lambda[1] * b + lambda[2] * c + 0.3 * n;
        const Vector3d got = barycentric_coordinates(p, a, b, c);
        CHECK((got - lambda).norm() < 1e-12);
        // Independently: least squares for (λ_b, λ_c) in [b − a, c − a] (λ_b, λ_c)ᵀ = p − a.
        Eigen::Matrix<double, 3, 2> edges;
        edges << b - a, c - a;
        const Eigen::Vector2d bc = edges.colPivHouseholderQr().solve(p - a);
        CHECK(got[1] == Approx(bc[0]).margin(1e-12));
        CHECK(got[2] == Approx(bc[1]).margin(1e-12));
    }
}

TEST_CASE("barycentric coordinates of a degenerate triangle are an error", "[ch03]")
{
    const Vector3d a(0, 0, 0), b(1, 1, 0), c(2, 2, 0);
    CHECK_THROWS_WITH(barycentric_coordinates(a, a, b, c), Contains("barycentric_coordinates") && Contains("zero area"));
}

TEST_CASE("hat gradients: the unit right triangle, by hand", "[ex03.2]")
{
    // φ_a = 1 − x − y, φ_b = x, φ_c = y.
    const Eigen::Matrix3d G = hat_gradients(Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(0, 1, 0));
    Eigen::Matrix3d expected;
    expected << -1, 1, 0, -1, 0, 1, 0, 0, 0;
    CHECK((G - expected).norm() < 1e-15);
    // Listed clockwise (seen from +z) the normal flips, and so does e⊥: the gradients stay the same.
    const Eigen::Matrix3d reversed = hat_gradients(Vector3d(0, 0, 0), Vector3d(0, 1, 0), Vector3d(1, 0, 0));
    CHECK((reversed.col(0) - expected.col(0)).norm() < 1e-15);
    CHECK((reversed.col(1) - expected.col(2)).norm() < 1e-15);
    CHECK((reversed.col(2) - expected.col(1)).norm() < 1e-15);
}

TEST_CASE("hat gradients: ∇φ_i·(x_j − x_k) = δ_ij − δ_ik, tangent, summing to zero", "[ex03.2]")
{
    RandomTriangles triangles;
    for (int trial = 0; trial < 50; ++trial) {
        const std::array<Vector3d, 3> x = triangles.next();
        const Eigen::Matrix3d G = hat_gradients(x[0], x[1], x[2]);
        const Vector3d n = (x[1] - x[0]).cross(x[2] - x[0]).normalized();
        CHECK(G.rowwise().sum().norm() < 1e-13 * G.norm());
        for (int i = 0; i < 3; ++i) {
            CHECK(std::abs(G.col(i).dot(n)) < 1e-13 * G.col(i).norm());
            // It points from the opposite edge towards corner i.
            CHECK(G.col(i).dot(x[i] - x[(i + 1) % 3]) > 0.0);
            for (int j = 0; j < 3; ++j)
                for (int k = 0; k < 3; ++k)
                    CHECK(G.col(i).dot(x[j] - x[k]) == Approx(double(i == j) - double(i == k)).margin(1e-12));
        }
        // The gradient of a linear function u(x) = g·x + 5 is g's tangential part, exactly.
        const Vector3d g(1.5, -2.0, 0.25);
        const Vector3d u(g.dot(x[0]) + 5, g.dot(x[1]) + 5, g.dot(x[2]) + 5);
        CHECK((G * u - (g - g.dot(n) * n)).norm() < 1e-12);
    }
}

TEST_CASE("hat gradients of a degenerate triangle are an error", "[ch03]")
{
    CHECK_THROWS_WITH(hat_gradients(Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(3, 0, 0)),
                      Contains("hat_gradients") && Contains("zero area"));
    CHECK_THROWS_AS(hat_gradients(Vector3d(0, 0, 0), Vector3d(0, 0, 0), Vector3d(0, 1, 0)), fem::Error);
}

TEST_CASE("the gradient operator G: shape, constants, linear functions exact on jittered meshes", "[ex03.3]")
{
    for (double jitter : {0.0, 0.24}) {
        const fem::TriMesh mesh = fem::square_mesh(9, jitter, 5);
        const SparseMatrix G = gradient_operator(mesh.V, mesh.F);
        REQUIRE(G.rows() == 3 * mesh.F.rows());
        REQUIRE(G.cols() == mesh.V.rows());
        CHECK(G.nonZeros() == 9 * mesh.F.rows());
        CHECK((G * Eigen::VectorXd::Ones(mesh.V.rows())).norm() < 1e-11);
        // u = 3 − 2x + 7y: the gradient (−2, 7, 0) on every triangle, to round-off.
        const Eigen::VectorXd u = (3.0 - 2.0 * mesh.V.col(0).array() + 7.0 * mesh.V.col(1).array()).matrix();
        const Eigen::VectorXd Gu = G * u;
        for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
            CHECK((Gu.segment<3>(3 * f) - Vector3d(-2, 7, 0)).norm() < 1e-11);
        const fem::MatrixX3d per_face = face_gradients(mesh.V, mesh.F, u);
        CHECK(per_face.rows() == mesh.F.rows());
        CHECK((per_face.row(17).transpose() - Vector3d(-2, 7, 0)).norm() < 1e-11);
    }
}

TEST_CASE("the gradient operator on a curved closed surface: tangential gradients of linear functions",
          "[ex03.3]")
{
    const fem::TriMesh sphere = fem::test::bumpy_sphere();
    const SparseMatrix G = gradient_operator(sphere.V, sphere.F);
    const Vector3d g(0.3, -1.1, 2.0);
    const Eigen::VectorXd u = sphere.V * g;
    const Eigen::VectorXd Gu = G * u;
    for (Eigen::Index f = 0; f < sphere.F.rows(); ++f)
        CHECK((Gu.segment<3>(3 * f) - fem::test::tangential(sphere.V, sphere.F, f, g)).norm() < 1e-12);
}

TEST_CASE("the gradient operator names a degenerate triangle", "[ch03]")
{
    fem::TriMesh mesh = fem::square_mesh(3);
    mesh.V.row(mesh.F(7, 2)) = 0.5 * (mesh.V.row(mesh.F(7, 0)) + mesh.V.row(mesh.F(7, 1)));
    CHECK_THROWS_WITH(gradient_operator(mesh.V, mesh.F), Contains("triangle 7") && Contains("zero area"));
    CHECK_THROWS_WITH(face_gradients(mesh.V, mesh.F, Eigen::VectorXd::Zero(3)), Contains("one per vertex"));
}

namespace {

/// A deformation field u(x) = A x + b sampled at the corners of a triangle, and what its Jacobian
/// on the triangle must be: A restricted to the triangle's plane, A Π with Π = I − n̂n̂ᵀ, as the
/// row-major vec (its three rows one after the other).
struct LinearField {
    Eigen::Matrix3d A;
    Vector3d b;
    Eigen::Matrix<double, 9, 1> vertex_major(const std::array<Vector3d, 3>& x) const
    {
        Eigen::Matrix<double, 9, 1> q;
        for (int v = 0; v < 3; ++v)
            q.segment<3>(3 * v) = A * x[v] + b;
        return q;
    }
    Eigen::Matrix<double, 9, 1> coordinate_major(const std::array<Vector3d, 3>& x) const
    {
        Eigen::Matrix<double, 9, 1> q;
        for (int c = 0; c < 3; ++c)
            for (int v = 0; v < 3; ++v)
                q[3 * c + v] = (A * x[v] + b)[c];
        return q;
    }
    Eigen::Matrix<double, 9, 1> jacobian_rows(const std::array<Vector3d, 3>& x) const
    {
        const Vector3d n = (x[1] - x[0]).cross(x[2] - x[0]).normalized();
        const Eigen::Matrix3d J = A * (Eigen::Matrix3d::Identity() - n * n.transpose());
        Eigen::Matrix<double, 9, 1> rows;
        for (int r = 0; r < 3; ++r)
            rows.segment<3>(3 * r) = J.row(r).transpose();
        return rows;
    }
};

}  // namespace

TEST_CASE("the block Jacobian diag(G, G, G) maps a linear field to its Jacobian rows", "[ex03.4]")
{
    RandomTriangles triangles;
    for (int trial = 0; trial < 20; ++trial) {
        const std::array<Vector3d, 3> x = triangles.next();
        LinearField field{Eigen::Matrix3d::Random(), Vector3d::Random()};
        const Matrix9d J = block_jacobian(x[0], x[1], x[2]);
        CHECK((J * field.coordinate_major(x) - field.jacobian_rows(x)).norm() < 1e-12);
        // Sanity check of the lecture: a 9×9 matrix whose off-diagonal 3×3 blocks are zero.
        CHECK(J.block<3, 3>(0, 3).norm() == 0.0);
        CHECK(J.block<3, 3>(6, 0).norm() == 0.0);
        // A rigid translation has zero Jacobian.
        LinearField shift{Eigen::Matrix3d::Zero(), Vector3d(1, 2, 3)};
        CHECK((J * shift.coordinate_major(x)).norm() < 1e-12);
    }
    CHECK_THROWS_AS(block_jacobian(Vector3d(0, 0, 0), Vector3d(1, 1, 1), Vector3d(2, 2, 2)), fem::Error);
}

TEST_CASE("the permutation from vertex-major to coordinate-major order", "[ex03.5]")
{
    for (int n : {1, 3, 7}) {
        const SparseMatrix P = coordinate_major_permutation(n);
        REQUIRE(P.rows() == 3 * n);
        REQUIRE(P.cols() == 3 * n);
        Eigen::VectorXd q(3 * n), expected(3 * n);
        for (int v = 0; v < n; ++v)
            for (int c = 0; c < 3; ++c) {
                q[3 * v + c] = 10 * v + c;        // vertex v, coordinate c
                expected[c * n + v] = 10 * v + c;
            }
        CHECK(P * q == expected);
        const Eigen::MatrixXd PtP = Eigen::MatrixXd(P.transpose() * P);
        CHECK(PtP.isIdentity(0.0));
    }
    CHECK_THROWS_AS(coordinate_major_permutation(0), fem::Error);
}

TEST_CASE("the block Jacobian in our vertex-major ordering is J P", "[ex03.5]")
{
    RandomTriangles triangles;
    const SparseMatrix P = coordinate_major_permutation(3);
    for (int trial = 0; trial < 10; ++trial) {
        const std::array<Vector3d, 3> x = triangles.next();
        LinearField field{Eigen::Matrix3d::Random(), Vector3d::Random()};
        const Eigen::Matrix<double, 9, 1> q = field.vertex_major(x);
        const Eigen::Matrix<double, 9, 1> Pq = P * q;
        CHECK((block_jacobian(x[0], x[1], x[2]) * Pq - field.jacobian_rows(x)).norm() < 1e-12);
    }
}
