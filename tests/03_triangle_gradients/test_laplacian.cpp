// Chapter 03: the FEM Laplacian GᵀAG and the cotangent formula against an independent cotangent
// computation, the 5-point stencil, the Dirichlet energy of linear functions, obtuse triangles,
// and the lumped mass against the consistent one. docs/03_triangle_gradients.md#the-fem-laplacian
#include "03_triangle_gradients/laplacian.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"
#include "meshes.hpp"
#include "common/bunny_meshes.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <random>

using namespace fem::tri;
using Catch::Matchers::Contains;
using fem::test::EntriesNear;
using fem::test::entries_of;

namespace {

/// Checks that L is the classical cotangent Laplacian of the mesh, computed independently:
/// L_ij = −w_ij on every edge, L_ii = Σ_j w_ij, nothing else.
void check_is_cotangent_laplacian(const SparseMatrix& L, const fem::TriMesh& mesh)
{
    const auto weights = fem::test::reference_cotangent_weights(mesh.V, mesh.F);
    const double scale = L.diagonal().cwiseAbs().maxCoeff();
    Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(mesh.V.rows());
    for (const auto& [edge, w] : weights) {
        CHECK(L.coeff(edge.first, edge.second) == Approx(-w).margin(1e-12 * scale));
        CHECK(L.coeff(edge.second, edge.first) == Approx(-w).margin(1e-12 * scale));
        diagonal[edge.first] += w;
        diagonal[edge.second] += w;
    }
    CHECK_THAT(entries_of(L.diagonal()), EntriesNear(diagonal, 1e-12 * scale));
    // No entry outside the diagonal and the edges.
    int off_edge = 0;
    for (int col = 0; col < L.outerSize(); ++col)
        for (SparseMatrix::InnerIterator it(L, col); it; ++it)
            if (it.row() != col && !weights.count({std::min<int>(it.row(), col), std::max<int>(it.row(), col)}) &&
                std::abs(it.value()) > 1e-12 * scale)
                ++off_edge;
    CHECK(off_edge == 0);
}

/// Symmetric, zero row sums, positive diagonal, positive semi-definite on random vectors.
void check_laplacian_properties(const SparseMatrix& L)
{
    const double scale = L.diagonal().cwiseAbs().maxCoeff();
    CHECK(SparseMatrix(L - SparseMatrix(L.transpose())).coeffs().cwiseAbs().maxCoeff() < 1e-13 * scale);
    CHECK((L * Eigen::VectorXd::Ones(L.cols())).cwiseAbs().maxCoeff() < 1e-12 * scale);
    CHECK(L.diagonal().minCoeff() > 0.0);
    std::mt19937 random(3);
    std::normal_distribution<double> normal;
    for (int trial = 0; trial < 5; ++trial) {
        Eigen::VectorXd x(L.cols());
        for (auto& value : x)
            value = normal(random);
        CHECK(x.dot(L * x) >= 0.0);
    }
}

/// Two triangles sharing the edge (0, 1) from (0,0) to (2,0), their apexes at (1, ±height): the
/// angles opposite the edge are 2·atan(1/height), obtuse for height < 1.
fem::TriMesh kite(double height)
{
    fem::TriMesh mesh;
    mesh.V.resize(4, 3);
    mesh.V << 0, 0, 0, 2, 0, 0, 1, height, 0, 1, -height, 0;
    mesh.F.resize(2, 3);
    mesh.F << 0, 1, 2, 1, 0, 3;
    return mesh;
}

}  // namespace

TEST_CASE("GᵀAG is symmetric, with zero row sums, and equals the cotangent formula", "[ex03.6]")
{
    for (const fem::TriMesh& mesh : {fem::square_mesh(8, 0.24, 9), fem::test::bumpy_sphere(), fem::test::bunny_surface()}) {
        const SparseMatrix L = fem_laplacian(mesh.V, mesh.F);
        REQUIRE(L.rows() == mesh.V.rows());
        check_laplacian_properties(L);
        check_is_cotangent_laplacian(L, mesh);
    }
}

TEST_CASE("uᵀ L u is the Dirichlet energy ∫|∇u|², exact for linear functions", "[ex03.6]")
{
    // On the unit square ∫ |∇(2x − 3y + 1)|² = 4 + 9 = 13, on any triangulation.
    const fem::TriMesh square = fem::square_mesh(7, 0.2, 4);
    const Eigen::VectorXd u = (2.0 * square.V.col(0).array() - 3.0 * square.V.col(1).array() + 1.0).matrix();
    CHECK(u.dot(fem_laplacian(square.V, square.F) * u) == Approx(13.0).epsilon(1e-12));
}

TEST_CASE("the classical cotangent Laplacian: the independent formula and the FEM properties", "[ex03.7]")
{
    for (const fem::TriMesh& mesh : {fem::square_mesh(8, 0.24, 9), fem::test::bumpy_sphere(), fem::test::bunny_surface()}) {
        const SparseMatrix L = cotangent_laplacian(mesh.V, mesh.F);
        check_laplacian_properties(L);
        check_is_cotangent_laplacian(L, mesh);
    }
}

TEST_CASE("on the regular right-triangle mesh both Laplacians are the 5-point stencil", "[ex03.7]")
{
    // Diagonal edges face two right angles (cot 90° = 0), axis edges two 45° angles (½(1 + 1) = 1).
    const int n = 6;
    const fem::TriMesh square = fem::square_mesh(n);
    for (const SparseMatrix& L : {fem_laplacian(square.V, square.F), cotangent_laplacian(square.V, square.F)}) {
        const int v = 2 * (n + 1) + 3;  // an interior vertex, (i, j) = (3, 2)
        CHECK(L.coeff(v, v) == Approx(4.0).epsilon(1e-13));
        for (int neighbour : {v - 1, v + 1, v - (n + 1), v + (n + 1)})
            CHECK(L.coeff(v, neighbour) == Approx(-1.0).epsilon(1e-13));
        for (int diagonal : {v - n - 2, v + n + 2})  // the diagonal neighbours of the split
            CHECK(L.coeff(v, diagonal) == Approx(0.0).margin(1e-13));
        CHECK(negative_weight_edges(L) == 0);
    }
}

TEST_CASE("obtuse angles give negative cotangent weights: a positive off-diagonal entry", "[ex03.7]")
{
    for (double height : {0.2, 0.5, 0.9, 1.0, 2.0}) {
        const fem::TriMesh mesh = kite(height);
        const SparseMatrix L = cotangent_laplacian(mesh.V, mesh.F);
        const double angle = 2.0 * std::atan(1.0 / height);  // at both apexes, opposite edge (0, 1)
        CHECK(L.coeff(0, 1) == Approx(-1.0 / std::tan(angle)).margin(1e-14));
        CHECK((L.coeff(0, 1) > 1e-14) == (height < 1.0));  // obtuse: cot < 0, so L_01 = −½(cot + cot) > 0
        CHECK(negative_weight_edges(L) == (height < 1.0 ? 1 : 0));
        CHECK(negative_weight_edges(fem_laplacian(mesh.V, mesh.F)) == (height < 1.0 ? 1 : 0));
    }
}

TEST_CASE("the Laplacians name a degenerate triangle", "[ch03]")
{
    fem::TriMesh mesh = fem::square_mesh(3);
    mesh.V.row(mesh.F(4, 1)) = mesh.V.row(mesh.F(4, 0));
    CHECK_THROWS_WITH(fem_laplacian(mesh.V, mesh.F), Contains("triangle"));
    CHECK_THROWS_WITH(cotangent_laplacian(mesh.V, mesh.F), Contains("triangle"));
    CHECK_THROWS_WITH(lumped_mass(mesh.V, mesh.F), Contains("triangle"));
}

TEST_CASE("lumped mass: a third of each area per corner, the row sums of the consistent mass", "[ex03.8]")
{
    const int n = 5;
    const double h = 1.0 / n;
    const fem::TriMesh square = fem::square_mesh(n);
    const Eigen::VectorXd m = lumped_mass(square.V, square.F);
    CHECK(m.sum() == Approx(1.0).epsilon(1e-14));
    CHECK(m[(n + 1) + 1] == Approx(h * h).epsilon(1e-13));        // interior: 6 triangles of h²/2
    CHECK(m[0] == Approx(h * h / 3).epsilon(1e-13));              // corner (0,0): 2 triangles
    CHECK(m[n] == Approx(h * h / 6).epsilon(1e-13));              // corner (1,0): 1 triangle

    // The consistent mass ∫ φ_i φ_j = A/12 (1 + δ_ij) per triangle; its row sums are the lumped mass.
    for (const fem::TriMesh& mesh : {fem::square_mesh(6, 0.2, 2), fem::test::bunny_surface()}) {
        Eigen::VectorXd row_sums = Eigen::VectorXd::Zero(mesh.V.rows());
        for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
            const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
            const double area = 0.5 * (b - a).cross(c - a).norm();
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    row_sums[mesh.F(f, i)] += area / 12.0 * (i == j ? 2.0 : 1.0);
        }
        CHECK_THAT(entries_of(lumped_mass(mesh.V, mesh.F)), EntriesNear(row_sums, 1e-13 * row_sums.maxCoeff()));
    }
}

TEST_CASE("boundary vertices: the square's outline, none on a closed surface", "[ch03]")
{
    const int n = 4;
    const fem::TriMesh square = fem::square_mesh(n);
    const std::vector<int> boundary = boundary_vertices(square.F, static_cast<int>(square.V.rows()));
    CHECK(boundary.size() == 4u * n);
    for (int v : boundary) {
        const double x = square.V(v, 0), y = square.V(v, 1);
        CHECK((x == 0.0 || x == 1.0 || y == 0.0 || y == 1.0));
    }
    CHECK(boundary_vertices(fem::test::bumpy_sphere().F, 2 + 12 * 24).empty());
    CHECK(boundary_vertices(fem::test::bunny_surface().F, 1839).empty());
    fem::MatrixX3i three(3, 3);
    three << 0, 1, 2, 1, 0, 3, 0, 1, 4;
    CHECK_THROWS_WITH(boundary_vertices(three, 5), Contains("more than two triangles"));
    fem::MatrixX3i out_of_range(2, 3);
    out_of_range << 0, 1, 2, 2, 1, 4;
    CHECK_THROWS_WITH(boundary_vertices(out_of_range, 4), Contains("vertex 4") && Contains("0 to 3"));
}
