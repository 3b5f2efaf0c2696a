// Chapter 08: the supernodal factorization and its solves on several threads give the same bits as
// on one (independent subtrees, split products in the top), and are right: residuals against the
// matrix, Eigen's SimplicialLLT, and the up-looking factorization's failed column.
// docs/08_direct_solvers.md#threads
#include "08_direct_solvers/model_problems.hpp"
#include "08_direct_solvers/orderings.hpp"
#include "08_direct_solvers/sparse_cholesky.hpp"
#include "08_direct_solvers/supernodal.hpp"

#include "direct_test_support.hpp"

#include "common/error.hpp"
#include "common/parallel.hpp"

#include <catch2/catch.hpp>

#include <Eigen/SparseCholesky>

#include <string>
#include <vector>

using namespace fem;
using namespace fem::direct;
using namespace fem::direct::test;

namespace {

/// Everything the factorization and the solves produce, to be compared bit for bit.
struct Results {
    sparse::CscMatrix L;
    std::vector<double> x, X, x_single;  // one right-hand side, 20 of them, in float
};

std::vector<double> entries(const Eigen::MatrixXd& X) { return {X.data(), X.data() + X.size()}; }

/// Factors A (nested dissection, supernodal) and solves on `threads` threads.
Results factor_and_solve(const sparse::CscMatrix& A, int threads, Ordering ordering = Ordering::nested_dissection)
{
    const ScopedThreadCount scope(threads);
    CholeskyOptions options{ordering, Factorization::supernodal};
    options.single_precision_copy = true;
    const SparseCholesky chol(A, options);
    const Eigen::MatrixXd B = random_matrix(A.rows, 20, 7);
    return {chol.factor(), entries(chol.solve(B.col(0))), entries(chol.solve_many(B)),
            entries(chol.solve_single_precision(B.col(1)))};
}

/// The subtrees and top supernodes the analysis of A makes.
SupernodalCholesky analysis(const sparse::CscMatrix& A, Ordering ordering = Ordering::nested_dissection)
{
    const Permutation p = SparseCholesky(A, {ordering, Factorization::supernodal}).permutation();
    return SupernodalCholesky(symbolic_cholesky(A, p), symmetric_permutation(A, p));
}

/// The normwise backward error ‖A x − b‖ / (‖A‖_F ‖x‖ + ‖b‖): a few ε for a stable solve,
/// however ill-conditioned A.
double backward_error(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& x, const Eigen::VectorXd& b)
{
    return (A * x - b).norm() / (A.norm() * x.norm() + b.norm());
}

/// On 1, 2 and 3 threads the same factor and solutions to the last bit, and right: a backward
/// error below 1e-15, and x as Eigen's SimplicialLLT's.
void check_identical_and_right(const std::string& name, const sparse::CscMatrix& A,
                               Ordering ordering = Ordering::nested_dissection)
{
    INFO(name);
    // below 100,000 stored entries of L the factorization and the solves stay on one thread
    CHECK(analysis(A, ordering).stored_entries() >= 100000);
    const Results one = factor_and_solve(A, 1, ordering);
    for (int threads : {2, 3}) {
        INFO(threads << " threads");
        const Results many = factor_and_solve(A, threads, ordering);
        CHECK(many.L.IA == one.L.IA);
        CHECK(many.L.JA == one.L.JA);
        CHECK(many.L.A == one.L.A);
        CHECK(many.x == one.x);
        CHECK(many.X == one.X);
        CHECK(many.x_single == one.x_single);
    }
    const Eigen::MatrixXd B = random_matrix(A.rows, 20, 7);
    const Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(one.x.data(), A.rows);
    const Eigen::Map<const Eigen::MatrixXd> X(one.X.data(), A.rows, 20);
    const Eigen::SparseMatrix<double> E = sparse::to_eigen(A);
    CHECK(backward_error(E, x, B.col(0)) < 1e-15);
    CHECK(backward_error(E, X.col(19), B.col(19)) < 1e-15);
    const Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> eigen(E);
    CHECK((x - eigen.solve(B.col(0))).norm() <= 1e-10 * x.norm());
    CHECK((X - eigen.solve(B)).norm() <= 1e-10 * X.norm());
}

/// The block-diagonal matrix of the given blocks: a forest, one tree per block.
sparse::CscMatrix block_diagonal(const std::vector<sparse::CscMatrix>& blocks)
{
    std::vector<Eigen::Triplet<double>> entries;
    int offset = 0;
    for (const sparse::CscMatrix& block : blocks) {
        const Eigen::SparseMatrix<double> E = sparse::to_eigen(block);
        for (int j = 0; j < E.outerSize(); ++j)
            for (Eigen::SparseMatrix<double>::InnerIterator it(E, j); it; ++it)
                entries.emplace_back(offset + static_cast<int>(it.row()), offset + j, it.value());
        offset += block.rows;
    }
    Eigen::SparseMatrix<double> D(offset, offset);
    D.setFromTriplets(entries.begin(), entries.end());
    return csc(D);
}

/// tridiag(−1, 3, −1), n×n: its elimination tree is a chain, and κ < 5 for any n.
sparse::CscMatrix shifted_laplacian_1d(int n)
{
    std::vector<Eigen::Triplet<double>> entries;
    for (int i = 0; i < n; ++i) {
        entries.emplace_back(i, i, 3.0);
        if (i + 1 < n) {
            entries.emplace_back(i + 1, i, -1.0);
            entries.emplace_back(i, i + 1, -1.0);
        }
    }
    Eigen::SparseMatrix<double> D(n, n);
    D.setFromTriplets(entries.begin(), entries.end());
    return csc(D);
}

/// `chains` chains of `length` unknowns (tridiag(−1, 3, −1)), each end coupled to its own few of a
/// shared dense SPD block of `shared` unknowns: the block is a clique, which minimum degree
/// eliminates last, so the factor's root is one supernode of `shared` rows over the chains.
sparse::CscMatrix chains_under_dense_block(int chains, int length, int shared)
{
    std::vector<sparse::CscMatrix> blocks(chains, shifted_laplacian_1d(length));
    blocks.push_back(csc(random_spd(shared, 5).sparseView()));
    const int n = chains * length + shared, base = chains * length;
    std::vector<Eigen::Triplet<double>> coupling;
    for (int c = 0; c < chains; ++c)
        for (int k = 0; k < 4; ++k) {
            const int chain_end = c * length + length - 1, block = base + (c * 4 + k) % shared;
            coupling.emplace_back(block, chain_end, -0.1);
            coupling.emplace_back(chain_end, block, -0.1);
        }
    Eigen::SparseMatrix<double> C(n, n);
    C.setFromTriplets(coupling.begin(), coupling.end());
    return csc(sparse::to_eigen(block_diagonal(blocks)) + C);
}

/// A copy of A with the diagonal entries of the given columns made negative.
sparse::CscMatrix with_negative_diagonal(const sparse::CscMatrix& A, const std::vector<int>& columns)
{
    sparse::CscMatrix B = A;
    for (const int j : columns)
        for (int k = B.IA[j]; k < B.IA[j + 1]; ++k)
            if (B.JA[k] == j)
                B.A[k] = -1.0;
    return B;
}

/// The column a "not symmetric positive definite" message names, or −1.
int failed_column(const std::string& message)
{
    // (no std::regex: g++ 12 warns about its internals at -O1 with the sanitizers)
    const std::string key = "pivot of column ";
    const std::size_t at = message.find(key);
    if (at == std::string::npos)
        return -1;
    const std::size_t first = at + key.size();
    std::size_t last = first;
    while (last < message.size() && message[last] >= '0' && message[last] <= '9')
        ++last;
    return last > first && last < message.size() && message[last] == ' ' ? std::stoi(message.substr(first, last - first))
                                                                           : -1;
}

}  // namespace

TEST_CASE("supernodal threads: 3D stiffness and Laplacians split into subtrees give the same bits on 1, 2 "
          "and 3 threads",
          "[ex08.6]")
{
    const sparse::CscMatrix K = box_stiffness(9, rubber), L3 = laplacian_3d(20);
    // the split happens: several subtrees, and the top holds at least the root separator
    for (const sparse::CscMatrix* A : {&K, &L3}) {
        const SupernodalCholesky s = analysis(*A);
        CHECK(s.subtrees() >= 2);
        CHECK(s.top_supernodes() >= 1);
    }
    check_identical_and_right("3D stiffness, 3000 unknowns", K);
    check_identical_and_right("3D Laplacian, 8000 unknowns", L3);
    // minimum degree: an unbalanced tree, more of it in the top
    check_identical_and_right("3D Laplacian, minimum degree", laplacian_3d(16), Ordering::minimum_degree);
}

TEST_CASE("supernodal threads: one supernode, a chain and a forest give the same bits on 1, 2 and 3 threads",
          "[ex08.6]")
{
    // a dense matrix: one supernode, one subtree and an empty top
    const sparse::CscMatrix dense = csc(random_spd(600, 3).sparseView());
    CHECK(analysis(dense).supernodes() == 1);
    check_identical_and_right("dense 600×600", dense);
    // tridiagonal in its own order: a chain of supernodes
    check_identical_and_right("tridiagonal (a chain)", shifted_laplacian_1d(60000), Ordering::natural);
    // several roots of very different weights
    const sparse::CscMatrix forest = block_diagonal(
        {laplacian_3d(14), laplacian_2d(5), box_stiffness(4, rubber), laplacian_3d(9), laplacian_2d(1)});
    const SupernodalCholesky s = analysis(forest);
    CHECK(s.subtrees() >= 5);
    check_identical_and_right("a forest of five blocks", forest);
}

TEST_CASE("supernodal threads: a top front of 1100 rows, whose column loops and products run on all threads, "
          "gives the same bits on 1, 2 and 3 threads",
          "[ex08.6]")
{
    const sparse::CscMatrix A = chains_under_dense_block(16, 400, 1100);
    // minimum degree eliminates the chains first and the block last, as the root supernode
    const SupernodalCholesky s = analysis(A, Ordering::minimum_degree);
    CHECK(s.subtrees() >= 2);
    CHECK(s.top_supernodes() >= 1);
    CHECK(s.rows(s.supernodes() - 1) >= 1100);
    check_identical_and_right("16 chains under a dense block of 1100", A, Ordering::minimum_degree);
}

TEST_CASE("supernodal threads: a matrix that is not SPD fails at the same column on any number of threads, the "
          "first one in the elimination order",
          "[ex08.7]")
{
    const sparse::CscMatrix forest = block_diagonal({laplacian_3d(14), laplacian_2d(20), laplacian_3d(12)});
    const int n = forest.rows;  // 2744 + 400 + 1728
    CHECK(analysis(forest).stored_entries() >= 100000);
    // pairs of negative pivots: in two subtrees, in a subtree and the top, in two trees
    const std::vector<std::vector<int>> broken{{0, n - 1}, {5, 2900}, {2743, 2744}, {300, 3500}, {1372, 4000},
                                               {n - 1}, {17}};
    for (const std::vector<int>& columns : broken) {
        const sparse::CscMatrix A = with_negative_diagonal(forest, columns);
        INFO("negative diagonal at " << columns.front() << " and " << columns.back());
        // the up-looking factorization meets the columns one by one in the same order
        const std::string reference = fem_error_message(
            [&] { (void)SparseCholesky(A, {Ordering::nested_dissection, Factorization::up_looking}); });
        const int expected = failed_column(reference);
        REQUIRE(expected >= 0);
        for (int threads : {1, 2, 3}) {
            const ScopedThreadCount scope(threads);
            const std::string message = fem_error_message(
                [&] { (void)SparseCholesky(A, {Ordering::nested_dissection, Factorization::supernodal}); });
            INFO(threads << " threads: " << message);
            CHECK(failed_column(message) == expected);
        }
    }
}
