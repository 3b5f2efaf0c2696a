// Chapter 08: the symbolic factorization: symmetric permutation, elimination tree, postorder and
// column counts, against hand-made cases and the pattern of Eigen's Cholesky factor.
// docs/08_direct_solvers.md#symbolic-factorization
#include "08_direct_solvers/model_problems.hpp"
#include "08_direct_solvers/orderings.hpp"
#include "08_direct_solvers/sparse_cholesky.hpp"

#include "direct_test_support.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

using namespace fem;
using namespace fem::direct;
using namespace fem::direct::test;
using Catch::Matchers::Contains;

namespace {

/// The elimination tree read off a factor's pattern: parent[j] = min{ i > j : L_ij ≠ 0 }.
std::vector<int> tree_of_factor(const Eigen::SparseMatrix<double>& L)
{
    std::vector<int> parent(L.cols(), -1);
    for (int j = 0; j < L.cols(); ++j)
        for (Eigen::SparseMatrix<double>::InnerIterator it(L, j); it; ++it)
            if (it.row() > j && (parent[j] < 0 || it.row() < parent[j]))
                parent[j] = static_cast<int>(it.row());
    return parent;
}

/// The stored entries of each column of a factor (Eigen stores the exact symbolic pattern).
std::vector<int> counts_of_factor(const Eigen::SparseMatrix<double>& L)
{
    std::vector<int> counts(L.cols());
    for (int j = 0; j < L.cols(); ++j)
        counts[j] = L.outerIndexPtr()[j + 1] - L.outerIndexPtr()[j];
    return counts;
}

/// A symmetric matrix from a dense pattern (lower triangle given by `entries` (i, j), i > j), with
/// a dominant diagonal so that it is SPD.
sparse::CscMatrix from_edges(int n, const std::vector<std::pair<int, int>>& entries)
{
    Eigen::MatrixXd D = Eigen::MatrixXd::Zero(n, n);
    for (auto [i, j] : entries)
        D(i, j) = D(j, i) = -1.0;
    for (int i = 0; i < n; ++i)
        D(i, i) = n + 1.0;
    return csc(D.sparseView());
}

/// Test matrices in a scrambled numbering: a 2D Laplacian and a small 3D stiffness matrix.
std::vector<Eigen::SparseMatrix<double>> scrambled_matrices()
{
    const Eigen::SparseMatrix<double> lap = sparse::to_eigen(laplacian_2d(9));
    const Eigen::SparseMatrix<double> K = sparse::to_eigen(box_stiffness(2, elastic::lame_parameters(1e5, 0.3)));
    return {lap, eigen_permuted(lap, random_permutation(81, 1)), K,
            eigen_permuted(K, random_permutation(static_cast<int>(K.rows()), 2))};
}

}  // namespace

TEST_CASE("symmetric permutation: C(k, l) = A(perm[k], perm[l]), upper triangle, rows sorted", "[permute]")
{
    const Eigen::SparseMatrix<double> A = sparse::to_eigen(laplacian_2d(5));
    const std::vector<int> perm = random_permutation(25, 3);
    const sparse::CscMatrix C = symmetric_permutation(csc(A), perm);
    sparse::validate(C);  // canonical: sorted rows
    const Eigen::MatrixXd dense_A = A, dense_C = sparse::to_eigen(C);
    for (int k = 0; k < 25; ++k)
        for (int l = 0; l < 25; ++l)
            CHECK(dense_C(k, l) == (k <= l ? dense_A(perm[k], perm[l]) : 0.0));
    // only A's lower triangle is read
    const sparse::CscMatrix C_lower = symmetric_permutation(lower_only(csc(A)), perm);
    CHECK(C_lower.IA == C.IA);
    CHECK(C_lower.JA == C.JA);
    CHECK(C_lower.A == C.A);
    CHECK_THROWS_AS(symmetric_permutation(csc(A), std::vector<int>(25, 0)), fem::Error);
}

TEST_CASE("elimination tree: hand-made patterns", "[ex08.5]")
{
    const int n = 6;
    // tridiagonal: a path, every column's parent is the next one
    std::vector<std::pair<int, int>> path;
    for (int i = 1; i < n; ++i)
        path.push_back({i, i - 1});
    CHECK(elimination_tree(symmetric_permutation(from_edges(n, path), fill_reducing_ordering(from_edges(n, path), Ordering::natural))) ==
          std::vector<int>{1, 2, 3, 4, 5, -1});
    // diagonal: a forest of roots
    CHECK(elimination_tree(symmetric_permutation(from_edges(n, {}), {0, 1, 2, 3, 4, 5})) ==
          std::vector<int>{-1, -1, -1, -1, -1, -1});
    // an arrow pointing at the last unknown: every column hangs directly below it
    std::vector<std::pair<int, int>> arrow_last, arrow_first;
    for (int i = 0; i + 1 < n; ++i)
        arrow_last.push_back({n - 1, i});
    for (int i = 1; i < n; ++i)
        arrow_first.push_back({i, 0});
    const std::vector<int> identity{0, 1, 2, 3, 4, 5};
    CHECK(elimination_tree(symmetric_permutation(from_edges(n, arrow_last), identity)) ==
          std::vector<int>{5, 5, 5, 5, 5, -1});
    // an arrow at the first unknown fills L completely: a chain
    CHECK(elimination_tree(symmetric_permutation(from_edges(n, arrow_first), identity)) ==
          std::vector<int>{1, 2, 3, 4, 5, -1});
    // two blocks that never meet: two trees ({0,1,2} and {3,4,5}), 1 — 0 — 2 makes 2 the root above 1
    CHECK(elimination_tree(symmetric_permutation(from_edges(n, {{1, 0}, {2, 0}, {4, 3}, {5, 4}}), identity)) ==
          std::vector<int>{1, 2, -1, 4, 5, -1});
}

TEST_CASE("elimination tree: the first off-diagonal nonzero of each column of Eigen's L", "[ex08.5]")
{
    for (const Eigen::SparseMatrix<double>& A : scrambled_matrices()) {
        std::vector<int> identity(A.rows());
        std::iota(identity.begin(), identity.end(), 0);
        const std::vector<int> parent = elimination_tree(symmetric_permutation(csc(A), identity));
        CHECK(parent == tree_of_factor(eigen_factor_natural(A)));
    }
}

TEST_CASE("postorder: children before parents, subtrees contiguous", "[postorder]")
{
    // 6 has the children 2 and 5; 2 has the children 0 and 1; 5 — 4 — 3 is a chain.
    const std::vector<int> parent{2, 2, 6, 4, 5, 6, -1};
    CHECK(tree_postorder(parent) == std::vector<int>{0, 1, 2, 3, 4, 5, 6});
    // the same tree numbered differently
    const std::vector<int> scrambled{-1, 0, 1, 4, 0, 1, 3};  // 0 root; 1, 4 children of 0; …
    const std::vector<int> post = tree_postorder(scrambled);
    std::vector<int> position(7);
    for (int k = 0; k < 7; ++k)
        position[post[k]] = k;
    for (int v = 0; v < 7; ++v)
        if (scrambled[v] >= 0)
            CHECK(position[v] < position[scrambled[v]]);
    CHECK(post == std::vector<int>{2, 5, 1, 6, 3, 4, 0});
    CHECK_THROWS_AS(tree_postorder({1, 0}), fem::Error);   // a cycle
    CHECK_THROWS_AS(tree_postorder({3, -1}), fem::Error);  // out of range
}

TEST_CASE("column counts: hand-made patterns", "[ex08.6]")
{
    const int n = 6;
    const std::vector<int> identity{0, 1, 2, 3, 4, 5};
    std::vector<std::pair<int, int>> path, arrow_first;
    for (int i = 1; i < n; ++i) {
        path.push_back({i, i - 1});
        arrow_first.push_back({i, 0});
    }
    const sparse::CscMatrix P = symmetric_permutation(from_edges(n, path), identity);
    CHECK(column_counts(P, elimination_tree(P)) == std::vector<int>{2, 2, 2, 2, 2, 1});
    const sparse::CscMatrix F = symmetric_permutation(from_edges(n, arrow_first), identity);
    CHECK(column_counts(F, elimination_tree(F)) == std::vector<int>{6, 5, 4, 3, 2, 1});  // full
    const sparse::CscMatrix D = symmetric_permutation(from_edges(n, {}), identity);
    CHECK(column_counts(D, elimination_tree(D)) == std::vector<int>(n, 1));
}

TEST_CASE("column counts: the column sizes of Eigen's L, in several orderings", "[ex08.6]")
{
    for (const Eigen::SparseMatrix<double>& A : scrambled_matrices()) {
        std::vector<int> identity(A.rows());
        std::iota(identity.begin(), identity.end(), 0);
        const sparse::CscMatrix C = symmetric_permutation(csc(A), identity);
        CHECK(column_counts(C, elimination_tree(C)) == counts_of_factor(eigen_factor_natural(A)));
    }
}

TEST_CASE("symbolic factorization: nnz(L) and pointers, as Eigen's SimplicialLLT with AMD", "[ex08.6]")
{
    for (const Eigen::SparseMatrix<double>& A : scrambled_matrices()) {
        const sparse::CscMatrix M = csc(A);
        const SymbolicCholesky S = symbolic_cholesky(M, eigen_amd(M));
        const Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> llt(A);  // AMD by default
        CHECK(S.nonzeros == llt.matrixL().nestedExpression().nonZeros());
        CHECK(S.pointers.back() == S.nonzeros);
        double flops = 0.0;
        for (int c : S.counts)
            flops += double(c) * c;
        CHECK(S.flops == flops);
        CHECK(S.perm == eigen_amd(M));
    }
}
