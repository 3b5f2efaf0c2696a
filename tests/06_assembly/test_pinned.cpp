// Chapter 06: pinned vertices through P, the reduced system PᵀAP (SPD once pinned), the map back,
// and a solve that refuses the singular free-floating K. docs/06_assembly.md#pinned-vertices
#include "06_assembly/assembly.hpp"

#include "test_meshes.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Cholesky>
#include <Eigen/SparseCholesky>

#include <algorithm>

using namespace fem::assembly;
using fem::TetMesh;
using Catch::Matchers::Contains;

namespace {

const double density = 1000.0;

// The dofs of the vertices not in `pinned`, ascending: the index list P encodes.
std::vector<int> free_dofs(int vertex_count, const std::vector<int>& pinned)
{
    std::vector<int> dofs;
    for (int v = 0; v < vertex_count; ++v)
        if (std::find(pinned.begin(), pinned.end(), v) == pinned.end())
            for (int c = 0; c < 3; ++c)
                dofs.push_back(3 * v + c);
    return dofs;
}

}  // namespace

TEST_CASE("P keeps the free dofs: columns of the identity, PᵀP = I", "[ex06.8]")
{
    const std::vector<int> pinned = {4, 0, 7};
    const SparseMatrix P = free_selection_matrix(9, pinned);
    REQUIRE(P.rows() == 27);
    REQUIRE(P.cols() == 18);
    const std::vector<int> dofs = free_dofs(9, pinned);
    const Eigen::MatrixXd Pd(P);
    for (int k = 0; k < 18; ++k) {
        CHECK(Pd.col(k).sum() == 1.0);
        CHECK(Pd(dofs[k], k) == 1.0);
    }
    CHECK(Eigen::MatrixXd(SparseMatrix(P.transpose() * P)).isIdentity(0.0));

    // The map back puts u at the free dofs and zero at the pinned ones.
    Eigen::VectorXd u(18);
    for (int k = 0; k < 18; ++k)
        u[k] = k + 1.0;
    const Eigen::VectorXd q = expand(P, u);
    REQUIRE(q.size() == 27);
    for (int v : pinned)
        CHECK(q.segment<3>(3 * v).isZero(0.0));
    for (int k = 0; k < 18; ++k)
        CHECK(q[dofs[k]] == u[k]);
    CHECK(free_selection_matrix(3, {}).isApprox(SparseMatrix(Eigen::MatrixXd::Identity(9, 9).sparseView())));
}

TEST_CASE("the reduced matrix PᵀAP is A with the pinned rows and columns removed", "[ex06.8]")
{
    const TetMesh mesh = fem::test::distorted_mesh(2, 2, 1);
    const SparseMatrix K = stiffness_matrix(mesh, fem::test::rubber);
    const std::vector<int> pinned = vertices_on_plane(mesh, 0, 0.0);
    const SparseMatrix P = free_selection_matrix(static_cast<int>(mesh.V.rows()), pinned);
    const Eigen::MatrixXd reduced(reduce(K, P));
    const std::vector<int> dofs = free_dofs(static_cast<int>(mesh.V.rows()), pinned);
    REQUIRE(reduced.rows() == static_cast<Eigen::Index>(dofs.size()));
    const Eigen::MatrixXd Kd(K);
    for (std::size_t r = 0; r < dofs.size(); ++r)
        for (std::size_t c = 0; c < dofs.size(); ++c)
            REQUIRE(reduced(r, c) == Kd(dofs[r], dofs[c]));
}

TEST_CASE("pinned: PᵀKP and PᵀKP + M are SPD, free-floating K is singular and the solve says so",
          "[ex06.8]")
{
    const TetMesh mesh = fem::test::distorted_mesh(4, 2, 2);
    const SparseMatrix K = stiffness_matrix(mesh, fem::test::rubber);
    const SparseMatrix M = lumped_mass_matrix(mesh, density);
    const Eigen::VectorXd f = gravity_load(mesh, density);

    // Free-floating: the solve must refuse (6 rigid modes), never return a silent wrong answer.
    CHECK_THROWS_WITH(solve_spd(K, f), Contains("singular") || Contains("not SPD"));

    const std::vector<int> pinned = vertices_on_plane(mesh, 0, 0.0);
    REQUIRE(pinned.size() == 3 * 3);
    const SparseMatrix P = free_selection_matrix(static_cast<int>(mesh.V.rows()), pinned);
    const SparseMatrix K_free = reduce(K, P);
    Eigen::SimplicialLLT<SparseMatrix> llt(K_free);
    CHECK(llt.info() == Eigen::Success);
    Eigen::SimplicialLLT<SparseMatrix> llt_with_mass(SparseMatrix(K_free + reduce(M, P)));
    CHECK(llt_with_mass.info() == Eigen::Success);

    // The pinned static solve K_free u = Pᵀ f, checked against Eigen's dense Cholesky.
    const Eigen::VectorXd f_free = P.transpose() * f;
    const Eigen::VectorXd u = solve_spd(K_free, f_free);
    const Eigen::VectorXd reference = Eigen::MatrixXd(K_free).llt().solve(f_free);
    CHECK((u - reference).norm() <= 1e-9 * reference.norm());
    const Eigen::VectorXd q = expand(P, u);
    for (int v : pinned)
        CHECK(q.segment<3>(3 * v).isZero(0.0));
    // Gravity pulls the free end down.
    double lowest = 0.0;
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
        lowest = std::min(lowest, q[3 * v + 2]);
    CHECK(lowest < 0.0);
}

TEST_CASE("solve_spd refuses indefinite and mismatched systems", "[ch06]")
{
    Eigen::MatrixXd A(2, 2);
    A << 1.0, 2.0, 2.0, 1.0;  // eigenvalues 3 and −1
    CHECK_THROWS_WITH(solve_spd(A.sparseView(), Eigen::VectorXd::Ones(2)), Contains("indefinite"));
    CHECK_THROWS_AS(solve_spd(A.sparseView(), Eigen::VectorXd::Ones(3)), fem::Error);
    A << 2.0, 0.0, 0.0, 3.0;
    CHECK(solve_spd(A.sparseView(), Eigen::Vector2d(2.0, 3.0)).isApprox(Eigen::Vector2d(1.0, 1.0)));
}

TEST_CASE("pinning rejects bad indices, and the reduce/expand sizes are checked", "[ex06.8]")
{
    CHECK_THROWS_WITH(free_selection_matrix(5, {1, 5}), Contains("pinned vertex 5") && Contains("[0, 5)"));
    CHECK_THROWS_AS(free_selection_matrix(5, {-1}), fem::Error);
    CHECK_THROWS_WITH(free_selection_matrix(5, {2, 3, 2}), Contains("vertex 2 is pinned twice"));
    CHECK_THROWS_AS(free_selection_matrix(0, {}), fem::Error);

    const TetMesh mesh = fem::box_mesh(1, 1, 1);
    CHECK_THROWS_AS(vertices_on_plane(mesh, 3, 0.0), fem::Error);
    CHECK_THROWS_AS(vertices_on_plane(mesh, 0, 0.0, -1.0), fem::Error);
    CHECK(vertices_on_plane(mesh, 2, 1.0) == std::vector<int>{4, 5, 6, 7});

    const SparseMatrix P = free_selection_matrix(8, {0});
    const SparseMatrix A = SparseMatrix(Eigen::MatrixXd::Identity(36, 36).sparseView());  // P has 24 rows
    CHECK_THROWS_AS(reduce(A, P), fem::Error);
    CHECK_THROWS_AS(expand(P, Eigen::VectorXd::Zero(24)), fem::Error);
}
