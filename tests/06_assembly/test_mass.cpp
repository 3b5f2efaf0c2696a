// Chapter 06: lumped and consistent mass against volumes, quadrature and exact kinetic energies;
// Rayleigh damping; the gravity load. docs/06_assembly.md#lumped-mass
#include "06_assembly/assembly.hpp"

#include "test_meshes.hpp"

#include "04_tet_jacobians/tet_jacobians.hpp"
#include "common/error.hpp"
#include "common/mesh.hpp"
#include "common/random.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/SparseCholesky>

#include <cmath>
#include <limits>

using namespace fem::assembly;
using fem::TetMesh;
using fem::test::distorted_mesh;
using Catch::Matchers::Contains;
using fem::test::EntriesNear;
using fem::test::entries_of;

namespace {

const double rho = 1100.0;

fem::tet::TetVertices skew_tet()
{
    fem::tet::TetVertices X;
    X << 0.1, -0.2, 0.3,
         1.3, 0.1, -0.1,
         0.4, 1.1, 0.2,
         0.2, 0.3, 0.9;
    return X;
}

TetMesh one_tet(const fem::tet::TetVertices& X)
{
    TetMesh mesh;
    mesh.V = X;
    mesh.T.resize(1, 4);
    mesh.T << 0, 1, 2, 3;
    return mesh;
}

// The velocity field v(X) = (1 + 2Y, Z, X) at every vertex, vertex-major.
Eigen::VectorXd linear_velocity(const fem::MatrixX3d& V)
{
    Eigen::VectorXd v(3 * V.rows());
    for (Eigen::Index k = 0; k < V.rows(); ++k)
        v.segment<3>(3 * k) = Eigen::Vector3d(1.0 + 2.0 * V(k, 1), V(k, 2), V(k, 0));
    return v;
}

}  // namespace

TEST_CASE("lumped masses: a quarter of each tet's mass to each corner", "[ex06.6]")
{
    const fem::tet::TetVertices X = skew_tet();
    const double volume = std::abs(fem::tet::signed_volume(X));
    const Eigen::VectorXd m = vertex_masses(one_tet(X), rho);
    REQUIRE(m.size() == 4);
    for (int i = 0; i < 4; ++i)
        CHECK(m[i] == Approx(rho * volume / 4).epsilon(1e-14));

    const TetMesh mesh = distorted_mesh(3, 2, 2);
    const Eigen::VectorXd masses = vertex_masses(mesh, rho);
    CHECK(masses.sum() == Approx(rho * fem::total_volume(mesh)).epsilon(1e-13));
    CHECK(masses.sum() == Approx(rho * 1.3 * 0.8 * 0.6).epsilon(1e-13));  // the box's volume
    CHECK(masses.minCoeff() > 0.0);

    const SparseMatrix M = lumped_mass_matrix(mesh, rho);
    REQUIRE(M.rows() == 3 * mesh.V.rows());
    CHECK(M.nonZeros() == M.rows());
    const Eigen::VectorXd diagonal = masses.replicate(1, 3).transpose().reshaped();  // m_v three times
    CHECK_THAT(entries_of(M), EntriesNear(Eigen::MatrixXd(diagonal.asDiagonal()), 0.0));
}

TEST_CASE("the element consistent mass is ρ ∫ φ_i φ_j dV by quadrature", "[ex06.7]")
{
    // The 4-point rule exact for quadratics: barycentric (a, b, b, b) and permutations, weight V/4.
    const double a = 0.5854101966249685, b = 0.1381966011250105;
    const fem::tet::TetVertices X = skew_tet();
    const double volume = std::abs(fem::tet::signed_volume(X));
    Eigen::Matrix4d integral = Eigen::Matrix4d::Zero();
    for (int q = 0; q < 4; ++q) {
        Eigen::Vector4d weights = Eigen::Vector4d::Constant(b);
        weights[q] = a;
        const Eigen::Vector3d p = X.transpose() * weights;
        const Eigen::Vector4d phi = fem::tet::shape_functions(X, p);
        integral += volume / 4 * phi * phi.transpose();
    }
    const Matrix12d M = element_consistent_mass(X, rho);
    Matrix12d expected = Matrix12d::Zero();  // ρ ∫ φ_i φ_j dV · I₃ in block (i, j)
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            expected.block<3, 3>(3 * i, 3 * j) = rho * integral(i, j) * Eigen::Matrix3d::Identity();
    CHECK_THAT(entries_of(M), EntriesNear(expected, 1e-12 * rho * volume, 1e-12));
}

TEST_CASE("consistent mass: total ρ·volume, rows sum to the lumped masses, exact kinetic energy",
          "[ex06.7]")
{
    const TetMesh mesh = distorted_mesh(3, 2, 2);
    const SparseMatrix M = consistent_mass_matrix(mesh, rho);
    const Eigen::VectorXd lumped = vertex_masses(mesh, rho);
    REQUIRE(M.rows() == 3 * mesh.V.rows());

    const Eigen::VectorXd ones = Eigen::VectorXd::Ones(M.rows());
    const Eigen::VectorXd row_sums = M * ones;
    const Eigen::VectorXd lumped_diagonal = lumped.replicate(1, 3).transpose().reshaped();  // m_v three times
    CHECK_THAT(entries_of(row_sums), EntriesNear(lumped_diagonal, 0.0, 1e-12));
    // A rigid translation along x: kinetic energy ½ (ρ·volume) · 1².
    Eigen::VectorXd along_x = Eigen::VectorXd::Zero(M.rows());
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
        along_x[3 * v] = 1.0;
    CHECK(along_x.dot(M * along_x) == Approx(rho * 1.3 * 0.8 * 0.6).epsilon(1e-12));

    // A linear velocity field is interpolated exactly, so ½ vᵀ M v = ½ ρ ∫ |v|² dV over the box:
    // ∫ (1 + 2Y)² + Z² + X² = L_x L_y L_z (1 + 2 L_y + 4 L_y²/3 + L_z²/3 + L_x²/3).
    const double Lx = 1.3, Ly = 0.8, Lz = 0.6;
    const double exact = rho * Lx * Ly * Lz * (1 + 2 * Ly + 4 * Ly * Ly / 3 + Lz * Lz / 3 + Lx * Lx / 3);
    const Eigen::VectorXd v = linear_velocity(mesh.V);
    CHECK(v.dot(M * v) == Approx(exact).epsilon(1e-12));

    // Symmetric positive definite: a Cholesky succeeds.
    CHECK((Eigen::MatrixXd(M) - Eigen::MatrixXd(M).transpose()).norm() <= 1e-14 * Eigen::MatrixXd(M).norm());
    Eigen::SimplicialLLT<SparseMatrix> llt(M);
    CHECK(llt.info() == Eigen::Success);
}

TEST_CASE("the lumped mass is not exact for a linear velocity field, the consistent one is", "[ex06.6]")
{
    // Documents the difference (docs/06_assembly.md#consistent-mass): the lumped kinetic energy of
    // v = (1 + 2Y, Z, X) is off by O(h²), a few per cent on this coarse mesh.
    const TetMesh mesh = fem::box_mesh(2, 2, 2, Eigen::Vector3d(1.3, 0.8, 0.6));
    const Eigen::VectorXd v = linear_velocity(mesh.V);
    const double lumped = v.dot(lumped_mass_matrix(mesh, rho) * v);
    const double Lx = 1.3, Ly = 0.8, Lz = 0.6;
    const double exact = rho * Lx * Ly * Lz * (1 + 2 * Ly + 4 * Ly * Ly / 3 + Lz * Lz / 3 + Lx * Lx / 3);
    CHECK(std::abs(lumped - exact) > 1e-3 * exact);
    CHECK(std::abs(lumped - exact) < 0.2 * exact);
}

TEST_CASE("gravity load: m_v g at each vertex", "[ex06.6]")
{
    const TetMesh mesh = distorted_mesh(3, 2, 2);
    const Eigen::Vector3d g(0.5, 0.0, -9.81);
    const Eigen::VectorXd f = gravity_load(mesh, rho, g);
    REQUIRE(f.size() == 3 * mesh.V.rows());
    const Eigen::VectorXd m = vertex_masses(mesh, rho);
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
        INFO("vertex " << v);
        CHECK((f.segment<3>(3 * v) - m[v] * g).norm() <= 1e-12 * m[v] * g.norm());
    }
    Eigen::Vector3d total = Eigen::Vector3d::Zero();
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
        total += f.segment<3>(3 * v);
    const double mass = rho * 1.3 * 0.8 * 0.6;
    CHECK((total - mass * g).norm() <= 1e-12 * mass * g.norm());
    CHECK(gravity_load(mesh, rho)[2] < 0.0);  // default g points down z
}

TEST_CASE("gravity load: the same from the consistent mass, M g", "[ex06.7]")
{
    const TetMesh mesh = distorted_mesh(3, 2, 2);
    const Eigen::Vector3d g(0.5, 0.0, -9.81);
    const Eigen::VectorXd f = gravity_load(mesh, rho, g);
    Eigen::VectorXd g_everywhere(f.size());
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
        g_everywhere.segment<3>(3 * v) = g;
    const Eigen::VectorXd consistent = consistent_mass_matrix(mesh, rho) * g_everywhere;
    CHECK((consistent - f).norm() <= 1e-12 * f.norm());
}

TEST_CASE("Rayleigh damping D = αM + βK, α and β in the lecture's range", "[ch06]")
{
    // Any diagonal M and symmetric K of one size will do (the chapter's own are exercises 06.4–06.6).
    const Eigen::Index n = 24;
    const SparseMatrix M = SparseMatrix(Eigen::VectorXd::LinSpaced(n, 1.0, 2.0).asDiagonal());
    const Eigen::MatrixXd A = fem::random_matrix(n, n, 3);
    const SparseMatrix K = (A + A.transpose()).sparseView();
    const SparseMatrix D = rayleigh_damping(M, K, 0.01, 0.002);
    const Eigen::MatrixXd expected = 0.01 * Eigen::MatrixXd(M) + 0.002 * Eigen::MatrixXd(K);
    CHECK((Eigen::MatrixXd(D) - expected).norm() <= 1e-15 * expected.norm());
    CHECK(Eigen::MatrixXd(rayleigh_damping(M, K, 0.0, 0.0)).isZero(0.0));
    CHECK_NOTHROW(rayleigh_damping(M, K, max_rayleigh_coefficient, max_rayleigh_coefficient));

    CHECK_THROWS_WITH(rayleigh_damping(M, K, -0.001, 0.0), Contains("α") && Contains("[0, 0.02]"));
    CHECK_THROWS_WITH(rayleigh_damping(M, K, 0.0, 0.5), Contains("β") && Contains("0.5"));
    CHECK_THROWS_AS(rayleigh_damping(M, K, std::nan(""), 0.0), fem::Error);
    CHECK_THROWS_AS(rayleigh_damping(M, K, 0.0, std::numeric_limits<double>::infinity()), fem::Error);
    const SparseMatrix small = M.topLeftCorner(n - 3, n - 3);
    CHECK_THROWS_WITH(rayleigh_damping(small, K, 0.01, 0.01), Contains("same size"));
}

TEST_CASE("bad density and bad meshes are rejected by the mass functions", "[ch06]")
{
    const TetMesh mesh = fem::box_mesh(1, 1, 1);
    for (double density : {0.0, -1000.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
        CHECK_THROWS_AS(vertex_masses(mesh, density), fem::Error);
        CHECK_THROWS_AS(lumped_mass_matrix(mesh, density), fem::Error);
        CHECK_THROWS_AS(consistent_mass_matrix(mesh, density), fem::Error);
        CHECK_THROWS_AS(gravity_load(mesh, density), fem::Error);
        CHECK_THROWS_AS(element_consistent_mass(skew_tet(), density), fem::Error);
    }
    CHECK_THROWS_WITH(vertex_masses(mesh, -2.0), Contains("density"));
    CHECK_THROWS_AS(gravity_load(mesh, rho, Eigen::Vector3d(0, std::nan(""), 0)), fem::Error);

    TetMesh bad = mesh;
    bad.T(5, 1) = 8;
    CHECK_THROWS_WITH(vertex_masses(bad, rho), Contains("tet 5") && Contains("8"));
    CHECK_THROWS_AS(consistent_mass_matrix(bad, rho), fem::Error);

    TetMesh flat = mesh;
    flat.V.row(flat.T(0, 3)) = flat.V.row(flat.T(0, 0));  // tet 0 collapses (and its neighbours)
    CHECK_THROWS_WITH(vertex_masses(flat, rho), Contains("zero volume"));
    fem::tet::TetVertices X = skew_tet();
    X.row(3) = X.row(0) + 0.3 * (X.row(1) - X.row(0)) + 0.2 * (X.row(2) - X.row(0));
    CHECK_THROWS_AS(element_consistent_mass(X, rho), fem::Error);
}
