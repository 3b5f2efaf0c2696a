// Chapter 06: the selection matrices and the three routes to K, each checked against a dense
// index-loop assembly written here; the global K's symmetry, rigid modes and energy.
// docs/06_assembly.md
#include "06_assembly/assembly.hpp"

#include "test_meshes.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"
#include "common/random.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>

using namespace fem::assembly;
using fem::TetMesh;
using fem::random_vector;
using fem::test::dense_assembly;
using fem::test::distorted_mesh;
using fem::test::relative_difference;
using Catch::Matchers::Contains;
using fem::test::EntriesNear;
using fem::test::entries_of;

namespace {

Eigen::MatrixXd dense(const SparseMatrix& A) { return Eigen::MatrixXd(A); }
Eigen::MatrixXd dense(const CsrMatrix& A) { return Eigen::MatrixXd(A); }

// Meshes with each kind of bad index.
TetMesh with_index(int t, int corner, int value)
{
    TetMesh mesh = fem::box_mesh(2, 1, 1);
    mesh.T(t, corner) = value;
    return mesh;
}

}  // namespace

TEST_CASE("the distorted test mesh is valid", "[ch06]")
{
    TetMesh mesh = distorted_mesh(3, 2, 2);
    CHECK(fem::validate(mesh) == 0);  // rejects inverted or flat tets
}

TEST_CASE("E_t picks the element's 12 dofs out of q", "[ex06.1]")
{
    const TetMesh mesh = distorted_mesh(2, 2, 1);
    const Eigen::VectorXd q = random_vector(3 * mesh.V.rows(), 3);
    for (int t : {0, 5, static_cast<int>(mesh.T.rows()) - 1}) {
        const SparseMatrix E = selection_matrix(mesh, t);
        REQUIRE(E.rows() == 12);
        REQUIRE(E.cols() == 3 * mesh.V.rows());
        CHECK(E.nonZeros() == 12);
        Eigen::VectorXd expected(12);  // the coordinates of the tet's corners, vertex-major
        for (int i = 0; i < 4; ++i)
            expected.segment<3>(3 * i) = q.segment<3>(3 * mesh.T(t, i));
        INFO("tet " << t);
        CHECK_THAT(entries_of(E * q), EntriesNear(expected, 0.0));
        // E_t E_tᵀ = I₁₂: the four corners are different vertices.
        CHECK(dense(SparseMatrix(E * E.transpose())).isIdentity(0.0));
    }
}

TEST_CASE("Σ E_tᵀ K_t E_t by selection matrices equals the index loop", "[ex06.1]")
{
    const TetMesh mesh = distorted_mesh(2, 1, 1);
    const auto K_e = fem::test::random_element_matrices(mesh.T.rows(), 11);
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(3 * mesh.V.rows(), 3 * mesh.V.rows());
    for (int t = 0; t < mesh.T.rows(); ++t) {
        const Eigen::MatrixXd E = dense(selection_matrix(mesh, t));
        K += E.transpose() * K_e[t] * E;
    }
    CHECK(relative_difference(K, dense_assembly(mesh, K_e)) < 1e-14);
}

TEST_CASE("selection_matrix rejects a bad tet index and bad meshes", "[ch06]")
{
    const TetMesh mesh = fem::box_mesh(1, 1, 1);
    CHECK_THROWS_AS(selection_matrix(mesh, -1), fem::Error);
    CHECK_THROWS_WITH(selection_matrix(mesh, 6), Contains("tet index 6") && Contains("[0, 6)"));
    CHECK_THROWS_WITH(selection_matrix(with_index(3, 2, 99), 0),
                      Contains("tet 3") && Contains("corner 2") && Contains("99"));
}

TEST_CASE("S stacks the E_tᵀ: S times the stacked f_t is Σ E_tᵀ f_t", "[ex06.2]")
{
    const TetMesh mesh = distorted_mesh(2, 2, 1);
    const Eigen::Index m = mesh.T.rows();
    const SparseMatrix S = scatter_matrix(mesh);
    REQUIRE(S.rows() == 3 * mesh.V.rows());
    REQUIRE(S.cols() == 12 * m);
    CHECK(S.nonZeros() == 12 * m);
    const Eigen::VectorXd stacked = random_vector(12 * m, 5);
    Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * mesh.V.rows());
    for (Eigen::Index t = 0; t < m; ++t)
        for (int i = 0; i < 4; ++i)
            f.segment<3>(3 * mesh.T(t, i)) += stacked.segment<3>(12 * t + 3 * i);
    CHECK((S * stacked - f).norm() <= 1e-14 * f.norm());
}

TEST_CASE("block_diagonal puts K_t at rows and columns 12t … 12t+11", "[ch06]")
{
    const auto K_e = fem::test::random_element_matrices(3, 2);
    const Eigen::MatrixXd K = dense(block_diagonal(K_e));
    REQUIRE(K.rows() == 36);
    Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(36, 36);
    for (int t = 0; t < 3; ++t)
        expected.block<12, 12>(12 * t, 12 * t) = K_e[t];
    CHECK(K == expected);
    CHECK_THROWS_AS(block_diagonal({}), fem::Error);
}

TEST_CASE("route (a), composition S K' Sᵀ, equals the index loop", "[ex06.2]")
{
    const TetMesh mesh = distorted_mesh(3, 2, 2);
    const auto K_e = fem::test::random_element_matrices(mesh.T.rows(), 1);
    CHECK(relative_difference(dense(assemble_by_composition(mesh, K_e)), dense_assembly(mesh, K_e)) < 1e-13);
}

TEST_CASE("route (b), triplets, equals the index loop", "[ex06.3]")
{
    const TetMesh mesh = distorted_mesh(3, 2, 2);
    const auto K_e = fem::test::random_element_matrices(mesh.T.rows(), 2);
    const auto triplets = element_triplets(mesh, K_e);
    CHECK(triplets.size() == 144 * static_cast<std::size_t>(mesh.T.rows()));
    CHECK(relative_difference(dense(assemble_by_triplets(mesh, K_e)), dense_assembly(mesh, K_e)) < 1e-13);
}

TEST_CASE("route (c), the pattern, has exactly the structure of K", "[ex06.4]")
{
    const TetMesh mesh = distorted_mesh(3, 2, 2);
    const AssemblyPattern pattern(mesh);
    REQUIRE(pattern.dof_count() == 3 * mesh.V.rows());
    REQUIRE(pattern.element_count() == mesh.T.rows());
    // The structure of the triplet route (setFromTriplets keeps every entry it was given).
    const auto K_e = fem::test::random_element_matrices(mesh.T.rows(), 3);
    CsrMatrix reference = CsrMatrix(assemble_by_triplets(mesh, K_e));
    reference.makeCompressed();
    const CsrMatrix& K = pattern.zero_matrix();
    REQUIRE(K.nonZeros() == reference.nonZeros());
    for (Eigen::Index r = 0; r <= K.rows(); ++r)
        REQUIRE(K.outerIndexPtr()[r] == reference.outerIndexPtr()[r]);
    for (Eigen::Index k = 0; k < K.nonZeros(); ++k)
        REQUIRE(K.innerIndexPtr()[k] == reference.innerIndexPtr()[k]);
    // Every block offset points into row 3 T(t, i) at column 3 T(t, j).
    for (int t = 0; t < mesh.T.rows(); ++t)
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) {
                const int v = mesh.T(t, i);
                const int offset = pattern.block_offset(t, i, j);
                CHECK(offset >= K.outerIndexPtr()[3 * v]);
                CHECK(offset + 2 < K.outerIndexPtr()[3 * v + 1]);
                CHECK(K.innerIndexPtr()[offset] == 3 * mesh.T(t, j));
                CHECK(pattern.row_length(v) == K.outerIndexPtr()[3 * v + 1] - K.outerIndexPtr()[3 * v]);
            }
    CHECK(pattern.memory_bytes() > static_cast<std::size_t>(K.nonZeros()) * 12);
}

TEST_CASE("route (c), the pattern, equals the index loop", "[ex06.5]")
{
    const TetMesh mesh = distorted_mesh(3, 2, 2);
    const auto K_e = fem::test::random_element_matrices(mesh.T.rows(), 4);
    const AssemblyPattern pattern(mesh);
    CHECK(relative_difference(dense(pattern.assemble(K_e)), dense_assembly(mesh, K_e)) < 1e-13);
}

TEST_CASE("the pattern is reused: a second assembly overwrites, never accumulates", "[ex06.5]")
{
    const TetMesh mesh = distorted_mesh(2, 2, 2);
    const AssemblyPattern pattern(mesh);
    auto K_e = fem::test::random_element_matrices(mesh.T.rows(), 5);
    CsrMatrix K = pattern.zero_matrix();
    const double* values = K.valuePtr();
    pattern.assemble(K_e, K);
    for (auto& k : K_e)
        k *= -3.0;
    pattern.assemble(K_e, K);
    CHECK(K.valuePtr() == values);  // the same storage: nothing reallocated
    CHECK(relative_difference(dense(K), dense_assembly(mesh, K_e)) < 1e-13);
}

TEST_CASE("the three routes agree to 1e-12 on the global stiffness", "[ex06.5]")
{
    const TetMesh mesh = distorted_mesh(4, 3, 2);
    const ElementMatrices K_e = element_stiffnesses(mesh, fem::test::rubber);
    const Eigen::MatrixXd a = dense(assemble_by_composition(mesh, K_e));
    const Eigen::MatrixXd b = dense(assemble_by_triplets(mesh, K_e));
    const Eigen::MatrixXd c = dense(AssemblyPattern(mesh).assemble(K_e));
    CHECK(relative_difference(a, b) < 1e-12);
    CHECK(relative_difference(c, b) < 1e-12);
    CHECK(relative_difference(dense(stiffness_matrix(mesh, fem::test::rubber)), b) < 1e-12);
}

TEST_CASE("csc_of_symmetric reads the CSR arrays of a symmetric matrix as CSC", "[ex06.5]")
{
    const TetMesh mesh = distorted_mesh(2, 1, 1);
    const auto K_e = fem::test::random_element_matrices(mesh.T.rows(), 6);
    const CsrMatrix K = AssemblyPattern(mesh).assemble(K_e);
    CHECK(dense(csc_of_symmetric(K)) == dense(K));
}

TEST_CASE("the global K is symmetric, annihilates the rigid modes, and sums the element energies",
          "[ex06.5]")
{
    const TetMesh mesh = distorted_mesh(3, 3, 2);
    const SparseMatrix K = stiffness_matrix(mesh, fem::test::rubber);
    const Eigen::MatrixXd Kd = dense(K);
    CHECK((Kd - Kd.transpose()).norm() <= 1e-14 * Kd.norm());

    const Eigen::MatrixXd R = fem::test::rigid_modes(mesh.V);
    CHECK((K * R).norm() <= 1e-11 * Kd.norm() * R.norm());

    // ½ qᵀ K q = Σ_t ½ q_tᵀ K_t q_t for any q.
    const ElementMatrices K_e = element_stiffnesses(mesh, fem::test::rubber);
    const Eigen::VectorXd q = random_vector(K.rows(), 8);
    double sum = 0.0;
    for (int t = 0; t < mesh.T.rows(); ++t) {
        Eigen::Matrix<double, 12, 1> q_t;
        for (int i = 0; i < 4; ++i)
            q_t.segment<3>(3 * i) = q.segment<3>(3 * mesh.T(t, i));
        sum += 0.5 * q_t.dot(K_e[t] * q_t);
    }
    CHECK(0.5 * q.dot(K * q) == Approx(sum).epsilon(1e-12));

    // Positive semi-definite with exactly the six rigid modes as its null space.
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(Kd);
    const Eigen::VectorXd lambda = eigen.eigenvalues();
    const double largest = lambda.maxCoeff();
    for (int k = 0; k < 6; ++k)
        CHECK(std::abs(lambda[k]) < 1e-12 * largest);
    CHECK(lambda[6] > 1e-6 * largest);
}

TEST_CASE("element_stiffnesses are chapter 05's K_e of each tet", "[ch06]")
{
    const TetMesh mesh = distorted_mesh(2, 1, 1);
    const ElementMatrices K_e = element_stiffnesses(mesh, fem::test::rubber);
    REQUIRE(K_e.size() == static_cast<std::size_t>(mesh.T.rows()));
    for (int t = 0; t < mesh.T.rows(); ++t) {
        INFO("tet " << t);
        CHECK_THAT(entries_of(K_e[t]), EntriesNear(fem::elastic::element_stiffness(
                                                       fem::tet::tet_vertices(mesh, mesh.V, t), fem::test::rubber),
                                                   0.0));
    }
}

TEST_CASE("every route rejects bad indices and a wrong number of element matrices", "[ex06.4]")
{
    const TetMesh good = fem::box_mesh(2, 1, 1);
    const auto K_e = fem::test::random_element_matrices(good.T.rows(), 9);
    for (const TetMesh& bad : {with_index(1, 0, -1), with_index(4, 3, 18), with_index(2, 1, 0)}) {
        CHECK_THROWS_AS(require_valid_indices(bad), fem::Error);
        CHECK_THROWS_AS(scatter_matrix(bad), fem::Error);
        CHECK_THROWS_AS(assemble_by_composition(bad, K_e), fem::Error);
        CHECK_THROWS_AS(element_triplets(bad, K_e), fem::Error);
        CHECK_THROWS_AS(assemble_by_triplets(bad, K_e), fem::Error);
        CHECK_THROWS_AS(AssemblyPattern(bad), fem::Error);
        CHECK_THROWS_AS(stiffness_matrix(bad, fem::test::rubber), fem::Error);
    }
    CHECK_THROWS_WITH(require_valid_indices(with_index(4, 3, 18)),
                      Contains("tet 4") && Contains("18") && Contains("[0, 12)"));
    CHECK_THROWS_WITH(require_valid_indices(with_index(2, 1, 0)), Contains("twice"));
    TetMesh empty;
    CHECK_THROWS_AS(require_valid_indices(empty), fem::Error);

    const ElementMatrices too_few(K_e.begin(), K_e.end() - 1);
    CHECK_THROWS_WITH(assemble_by_composition(good, too_few), Contains("11 element matrices"));
    CHECK_THROWS_AS(assemble_by_triplets(good, too_few), fem::Error);
    const AssemblyPattern pattern(good);
    CHECK_THROWS_AS(pattern.assemble(too_few), fem::Error);
    CsrMatrix wrong(3, 3);
    CHECK_THROWS_AS(pattern.assemble(K_e, wrong), fem::Error);
    CHECK_THROWS_AS(pattern.block_offset(12, 0, 0), fem::Error);
    CHECK_THROWS_AS(pattern.block_offset(0, 4, 0), fem::Error);
    CHECK_THROWS_AS(pattern.row_length(12), fem::Error);
}

TEST_CASE("a flat tet is reported with its index", "[ch06]")
{
    TetMesh mesh;
    mesh.V.resize(5, 3);
    mesh.V << 0, 0, 0,  1, 0, 0,  0, 1, 0,  0, 0, 1,  1, 1, 0;
    mesh.T.resize(2, 4);
    mesh.T << 0, 1, 2, 3,
              1, 2, 4, 0;  // all four corners in the plane z = 0
    CHECK_THROWS_WITH(element_stiffnesses(mesh, fem::test::rubber), Contains("tet 1"));
    CHECK_THROWS_WITH(stiffness_matrix(mesh, fem::test::rubber), Contains("tet 1"));
}
