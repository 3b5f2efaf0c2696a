// Chapter 04: the deformation gradient F, the Jacobian matrix B (vec(F) = B q_e, row-major vec,
// vertex-major q_e), and inverted tets. docs/04_tet_jacobians.md
#include "04_tet_jacobians/tet_jacobians.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"

#include "04_tet_jacobians/tet_fixtures.hpp"
#include "common/test_support.hpp"
#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>
#include <random>

using namespace fem::tet;
using fem::test::skew_tet;
using fem::test::random_matrix;
using fem::test::row_major_vec;
using Catch::Matchers::Contains;
using fem::test::EntriesNear;
using fem::test::entries_of;

namespace {

/// The 4×3 vertex rows of a vertex-major 12-vector q_e = (x₀, y₀, z₀, x₁, …).
TetVertices rows_of(const Eigen::Matrix<double, 12, 1>& q)
{
    TetVertices x;
    for (int i = 0; i < 4; ++i)
        x.row(i) = q.segment<3>(3 * i).transpose();
    return x;
}

}  // namespace

TEST_CASE("deformation gradient: F = I at rest and after a translation", "[ex04.4]")
{
    const TetVertices X = skew_tet();
    CHECK((deformation_gradient(X, X) - Eigen::Matrix3d::Identity()).norm() == Approx(0.0).margin(1e-14));
    TetVertices moved = X;
    moved.rowwise() += Eigen::RowVector3d(3.0, -1.0, 0.5);
    CHECK((deformation_gradient(X, moved) - Eigen::Matrix3d::Identity()).norm() ==
          Approx(0.0).margin(1e-13));
}

TEST_CASE("deformation gradient: F = A for the affine map x = A X + b", "[ex04.4]")
{
    std::mt19937 random(11);
    const TetVertices X = skew_tet();
    for (int k = 0; k < 10; ++k) {
        const Eigen::Matrix3d A = random_matrix(random);
        const Eigen::RowVector3d b(0.3 * k, -0.2, 1.0);
        TetVertices x = X * A.transpose();  // rows: (A Xᵢ)ᵀ
        x.rowwise() += b;
        CHECK((deformation_gradient(X, x) - A).norm() == Approx(0.0).margin(1e-13));
    }
    // A rotation by 90° about z: F is that rotation and det F = 1.
    const Eigen::Matrix3d R = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Matrix3d F = deformation_gradient(X, X * R.transpose());
    CHECK((F - R).norm() == Approx(0.0).margin(1e-14));
    CHECK(F.determinant() == Approx(1.0).epsilon(1e-14));
}

TEST_CASE("deformation gradient: det F = deformed volume / rest volume, and an inverted tet has det F < 0",
          "[ex04.4]")
{
    const TetVertices X = skew_tet();
    // Push vertex 3 through the opposite face 012: the deformed tet is inverted.
    TetVertices x = X;
    const Eigen::Vector3d n = (X.row(1) - X.row(0)).cross(X.row(2) - X.row(0)).transpose().normalized();
    const double height = n.dot((X.row(3) - X.row(0)).transpose());
    x.row(3) -= 1.5 * height * n.transpose();
    const Eigen::Matrix3d F = deformation_gradient(X, x);
    CHECK(F.determinant() < 0.0);
    CHECK(F.determinant() == Approx(-0.5).epsilon(1e-12));  // the height went from h to −h/2
    CHECK(F.determinant() == Approx(edge_matrix(x).determinant() / edge_matrix(X).determinant()).epsilon(1e-12));

    // Validation of a mesh built from the deformed positions reports the inverted tet, and
    // reorientation (swapping its last two vertices) repairs the listing.
    fem::TetMesh mesh;
    mesh.V = x;
    mesh.T.resize(1, 4);
    mesh.T << 0, 1, 2, 3;
    CHECK_THROWS_AS(fem::validate(mesh, "deformed", fem::Inverted::reject), fem::Error);
    CHECK_THROWS_WITH(fem::validate(mesh, "deformed", fem::Inverted::reject), Contains("inverted"));
    fem::TetMesh repaired = mesh;
    CHECK(fem::validate(repaired, "deformed", fem::Inverted::reorient) == 1);
    CHECK(fem::tet_signed_volume6(repaired, 0) > 0.0);
}

TEST_CASE("deformation_gradients over a mesh: per-tet F, and bad input named", "[ex04.4]")
{
    fem::TetMesh box = fem::box_mesh(2, 2, 1);
    Eigen::Matrix3d A;
    A << 1.2, 0.1, 0.0, -0.3, 0.9, 0.2, 0.0, 0.4, 1.1;
    const fem::MatrixX3d x = box.V * A.transpose();
    const std::vector<Eigen::Matrix3d> F = deformation_gradients(box, x);
    REQUIRE(F.size() == static_cast<std::size_t>(box.T.rows()));
    for (const Eigen::Matrix3d& Ft : F)
        CHECK((Ft - A).norm() == Approx(0.0).margin(1e-13));
    CHECK_THROWS_AS(deformation_gradients(box, x.topRows(3)), fem::Error);
    CHECK_THROWS_WITH(deformation_gradients(box, x.topRows(3)), Contains("3 deformed positions"));
    box.V.row(box.T(5, 1)) = box.V.row(box.T(5, 0));
    CHECK_THROWS_AS(deformation_gradients(box, x), fem::Error);
    CHECK_THROWS_WITH(deformation_gradients(box, x), Contains("rest tetrahedron"));
}

TEST_CASE("jacobian matrix: B q_e = vec(F) (row-major) for random vertex-major q_e", "[ex04.5]")
{
    std::mt19937 random(5);
    std::uniform_real_distribution<double> u(-2.0, 2.0);
    const TetVertices X = skew_tet();
    const Jacobian B = jacobian_matrix(X);
    for (int k = 0; k < 20; ++k) {
        Eigen::Matrix<double, 12, 1> q;
        for (int i = 0; i < 12; ++i)
            q[i] = u(random);
        CHECK((B * q - row_major_vec(deformation_gradient(X, rows_of(q)))).norm() ==
              Approx(0.0).margin(1e-12));
    }
    // At rest, B maps the rest positions to vec(I).
    Eigen::Matrix<double, 12, 1> rest;
    for (int i = 0; i < 4; ++i)
        rest.segment<3>(3 * i) = X.row(i).transpose();
    CHECK((B * rest - row_major_vec(Eigen::Matrix3d::Identity())).norm() == Approx(0.0).margin(1e-13));
}

TEST_CASE("jacobian matrix: each column is the finite-difference derivative of vec(F) w.r.t. q_e",
          "[ex04.5]")
{
    const TetVertices X = skew_tet();
    Eigen::Matrix<double, 12, 1> q;
    for (int i = 0; i < 4; ++i)
        q.segment<3>(3 * i) = X.row(i).transpose() + Eigen::Vector3d(0.1 * i, -0.05, 0.2 * (i % 2));
    const Jacobian B = jacobian_matrix(X);
    const double h = 1e-5;
    for (int j = 0; j < 12; ++j) {
        Eigen::Matrix<double, 12, 1> plus = q, minus = q;
        plus[j] += h;
        minus[j] -= h;
        const Eigen::Matrix<double, 9, 1> column =
            (row_major_vec(deformation_gradient(X, rows_of(plus))) -
             row_major_vec(deformation_gradient(X, rows_of(minus)))) / (2.0 * h);
        CHECK((B.col(j) - column).norm() == Approx(0.0).margin(1e-9));
    }
    // The sparsity of the row-major / vertex-major layout: row 3a + b only touches coordinate a.
    for (int r = 0; r < 9; ++r)
        for (int c = 0; c < 12; ++c)
            if (c % 3 != r / 3)
                CHECK(B(r, c) == 0.0);
}

TEST_CASE("jacobian matrix: the lecture's coordinate-major J_e is B with permuted columns", "[ex04.5]")
{
    const TetVertices X = skew_tet();
    const Eigen::Matrix<double, 12, 12> P = coordinate_major_permutation();
    CHECK((P * P.transpose() - Eigen::Matrix<double, 12, 12>::Identity()).norm() == 0.0);
    // Vertex-major (x0, y0, z0, x1, …) = 0…11 becomes (x0, x1, x2, x3, y0, …).
    Eigen::Matrix<double, 12, 1> index;
    for (int i = 0; i < 12; ++i)
        index[i] = i;
    const Eigen::Matrix<double, 12, 1> reordered = P * index;
    const Eigen::Matrix<double, 12, 1> expected =
        (Eigen::Matrix<double, 12, 1>() << 0, 3, 6, 9, 1, 4, 7, 10, 2, 5, 8, 11).finished();
    CHECK_THAT(entries_of(reordered), EntriesNear(expected, 0.0));
    CHECK((jacobian_matrix(X) - coordinate_major_jacobian(X) * P).norm() == Approx(0.0).margin(1e-13));
}
