// Chapter 08: orderings: the graph of a matrix, reverse Cuthill–McKee, minimum degree, nested
// dissection and Eigen's AMD; fill with each on 2D and 3D matrices.
// docs/08_direct_solvers.md#orderings
#include "08_direct_solvers/model_problems.hpp"
#include "08_direct_solvers/ordering_graphs.hpp"
#include "08_direct_solvers/orderings.hpp"
#include "08_direct_solvers/sparse_cholesky.hpp"

#include "direct_test_support.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <map>

using namespace fem;
using namespace fem::direct;
using namespace fem::direct::test;
using Catch::Matchers::Contains;

namespace {

/// A path 0 — 1 — … — (n−1) with a dominant diagonal, then renumbered by perm (new = position).
sparse::CscMatrix path_matrix(int n, const std::vector<int>& perm)
{
    Eigen::MatrixXd D = 3.0 * Eigen::MatrixXd::Identity(n, n);
    for (int i = 0; i + 1 < n; ++i)
        D(perm[i], perm[i + 1]) = D(perm[i + 1], perm[i]) = -1.0;
    return csc(D.sparseView());
}

bool is_permutation(const Permutation& p, int n)
{
    try {
        validate_permutation(p, n);
        return true;
    } catch (const fem::Error&) {
        return false;
    }
}

/// nnz(L) of the Cholesky factor of P A Pᵀ, counted by Eigen's own analysis: the orderings are
/// judged without the chapter's symbolic factorization (exercises 08.5 and 08.6).
long long fill(const sparse::CscMatrix& A, const Permutation& p)
{
    const Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::NaturalOrdering<int>> llt(
        eigen_permuted(sparse::to_eigen(A), p));
    REQUIRE(llt.info() == Eigen::Success);
    return llt.matrixL().nestedExpression().nonZeros();
}

}  // namespace

TEST_CASE("adjacency graph: both triangles read, no diagonal, sorted, symmetric", "[graph]")
{
    Eigen::MatrixXd D = Eigen::MatrixXd::Identity(4, 4);
    D(2, 0) = 1.0;  // only below the diagonal
    D(1, 3) = 1.0;  // only above it
    D(3, 2) = D(2, 3) = 1.0;
    const AdjacencyGraph g = adjacency_graph(csc(D.sparseView()));
    CHECK(g.vertices == 4);
    CHECK(g.pointers == std::vector<int>{0, 1, 2, 4, 6});
    CHECK(g.adjacency == std::vector<int>{2, 3, 0, 3, 1, 2});
    CHECK_THROWS_AS(adjacency_graph(csc(Eigen::MatrixXd::Ones(2, 3).sparseView())), fem::Error);
}

TEST_CASE("permutations: validation and inverse", "[graph]")
{
    CHECK(inverse_permutation({2, 0, 1}) == std::vector<int>{1, 2, 0});
    CHECK_THAT(fem_error_message([&] { (void)validate_permutation({0, 2, 2}, 3); }),
               Contains("entry 2") && Contains("repeats"));
    CHECK_THAT(fem_error_message([&] { (void)validate_permutation({0, 3, 1}, 3); }),
               Contains("entry 1"));
    CHECK_THROWS_AS(validate_permutation({0, 1}, 3), fem::Error);
}

TEST_CASE("graph compression: the three unknowns of a mesh vertex are indistinguishable", "[graph]")
{
    const sparse::CscMatrix K = box_stiffness(3, rubber);
    const CompressedGraph c = compress_indistinguishable(adjacency_graph(K));
    CHECK(c.graph.vertices * 3 == K.rows);
    for (int g = 0; g < c.graph.vertices; ++g) {
        REQUIRE(c.weight[g] == 3);
        const int first = c.members[c.member_start[g]];
        CHECK(first % 3 == 0);  // the group is (3v, 3v+1, 3v+2)
        CHECK(c.members[c.member_start[g] + 2] == first + 2);
    }
    // a 2D Laplacian has no two equal neighbourhoods
    CHECK(compress_indistinguishable(adjacency_graph(laplacian_2d(6))).graph.vertices == 36);
}

TEST_CASE("reverse Cuthill–McKee: a path in any numbering becomes a band of width 1", "[ex08.8]")
{
    const std::vector<int> identity{0, 1, 2, 3, 4};
    // the natural path: the search runs 0, 1, …, 4 from the pseudo-peripheral end 0, then is reversed
    CHECK(reverse_cuthill_mckee(path_matrix(5, identity)) == std::vector<int>{4, 3, 2, 1, 0});
    for (unsigned seed = 1; seed <= 5; ++seed) {
        const sparse::CscMatrix A = path_matrix(40, random_permutation(40, seed));
        const AdjacencyGraph g = adjacency_graph(A);
        std::vector<int> natural(40);
        std::iota(natural.begin(), natural.end(), 0);
        CHECK(bandwidth(g, natural) > 1);
        const Permutation p = reverse_cuthill_mckee(A);
        REQUIRE(is_permutation(p, 40));
        CHECK(bandwidth(g, p) == 1);
    }
}

TEST_CASE("reverse Cuthill–McKee: neighbours by increasing degree, each component separately", "[ex08.8]")
{
    // a star: centre 2 with leaves 0 and 1 and a tail 2 — 3 — 4. From 0 the farthest vertex is 4
    // (3 steps), and from 4 the farthest is again 3 steps away: 0 stays the root. The search runs
    // 0, 2, then 2's unvisited neighbours by degree, 1 (degree 1) before 3 (degree 2), then 4.
    Eigen::MatrixXd D = 5.0 * Eigen::MatrixXd::Identity(6, 6);
    for (auto [i, j] : std::vector<std::pair<int, int>>{{2, 0}, {2, 1}, {3, 2}, {4, 3}})
        D(i, j) = D(j, i) = -1.0;
    // vertex 5 is alone: its own component, found last
    CHECK(reverse_cuthill_mckee(csc(D.sparseView())) == std::vector<int>{5, 4, 3, 1, 2, 0});
}

TEST_CASE("reverse Cuthill–McKee: a scrambled grid gets back a bandwidth of about n", "[ex08.8]")
{
    const int n = 20;
    const sparse::CscMatrix grid = laplacian_2d(n);
    const std::vector<int> scramble = random_permutation(n * n, 7);
    const sparse::CscMatrix A = csc(eigen_permuted(sparse::to_eigen(grid), scramble));
    const AdjacencyGraph g = adjacency_graph(A);
    std::vector<int> identity(n * n);
    std::iota(identity.begin(), identity.end(), 0);
    const Permutation p = reverse_cuthill_mckee(A);
    REQUIRE(is_permutation(p, n * n));
    CHECK(bandwidth(g, identity) > 10 * n);  // scrambled: the band is almost the whole matrix
    CHECK(bandwidth(g, p) <= 2 * n);         // level sets of a grid are its anti-diagonals
    // the fill stays within the band: below that of the grid's own row-by-row numbering
    CHECK(fill(A, p) < fill(grid, identity));
    CHECK(fill(A, p) < fill(A, identity) / 2);
}

TEST_CASE("orderings reduce fill on a 3D mesh: RCM, minimum degree, nested dissection, Eigen AMD",
          "[ex08.8][orderings]")
{
    const sparse::CscMatrix K = box_stiffness(6, rubber);  // 882 unknowns
    const long long natural = fill(K, fill_reducing_ordering(K, Ordering::natural));
    std::map<Ordering, long long> nnz;
    for (Ordering o : {Ordering::reverse_cuthill_mckee, Ordering::minimum_degree, Ordering::eigen_amd,
                       Ordering::nested_dissection}) {
        const Permutation p = fill_reducing_ordering(K, o);
        REQUIRE(is_permutation(p, K.rows));
        nnz[o] = fill(K, p);
        INFO(ordering_name(o) << ": nnz(L) = " << nnz[o] << ", natural " << natural);
        CHECK(nnz[o] < natural);
    }
    // the fill-reducing ones are much better than a band
    CHECK(nnz[Ordering::minimum_degree] < nnz[Ordering::reverse_cuthill_mckee]);
    CHECK(nnz[Ordering::nested_dissection] < nnz[Ordering::reverse_cuthill_mckee]);
    // our minimum degree is as good as Eigen's AMD (within 10 %)
    CHECK(nnz[Ordering::minimum_degree] <= 1.1 * nnz[Ordering::eigen_amd]);
}

TEST_CASE("minimum degree: a hub is eliminated last, so an arrow matrix has no fill", "[orderings]")
{
    const int n = 30;
    Eigen::MatrixXd D = (2.0 * n) * Eigen::MatrixXd::Identity(n, n);
    for (int i = 1; i < n; ++i)
        D(i, 0) = D(0, i) = -1.0;  // unknown 0 couples to everything
    const sparse::CscMatrix A = csc(D.sparseView());
    for (Ordering o : {Ordering::minimum_degree, Ordering::nested_dissection, Ordering::eigen_amd}) {
        const Permutation p = fill_reducing_ordering(A, o);
        // the hub goes last (or next to last: with one leaf left, both have degree 1)
        CHECK((p[n - 1] == 0 || p[n - 2] == 0));
        CHECK(fill(A, p) == 2 * n - 1);  // nnz of the lower triangle of A: no fill
    }
    std::vector<int> identity(n);
    std::iota(identity.begin(), identity.end(), 0);
    CHECK(fill(A, identity) == n * (n + 1) / 2);  // the hub first fills L completely
}

TEST_CASE("nested dissection: on a 3D grid of 24³ unknowns it beats minimum degree and AMD", "[orderings]")
{
    const sparse::CscMatrix A = laplacian_3d(24);
    const long long md = fill(A, minimum_degree(A));
    const long long nd = fill(A, nested_dissection(A));
    const long long amd = fill(A, eigen_amd(A));
    INFO("minimum degree " << md << ", nested dissection " << nd << ", Eigen AMD " << amd);
    CHECK(nd < amd);
    CHECK(nd < md);
    const sparse::CscMatrix small = laplacian_3d(6);
    CHECK(is_permutation(nested_dissection(small, 1), small.rows));  // dissected down to single unknowns
    CHECK_THROWS_AS(nested_dissection(A, 0), fem::Error);
}

TEST_CASE("orderings: a matrix with several components and a diagonal matrix", "[orderings]")
{
    Eigen::MatrixXd D = 4.0 * Eigen::MatrixXd::Identity(7, 7);
    D(1, 0) = D(0, 1) = D(5, 6) = D(6, 5) = -1.0;
    const sparse::CscMatrix A = csc(D.sparseView());
    for (Ordering o : {Ordering::natural, Ordering::minimum_degree, Ordering::eigen_amd, Ordering::nested_dissection})
        CHECK(is_permutation(fill_reducing_ordering(A, o), 7));
    const sparse::CscMatrix I = csc(Eigen::MatrixXd::Identity(5, 5).sparseView());
    CHECK(is_permutation(minimum_degree(I), 5));
    CHECK(is_permutation(nested_dissection(I), 5));
}

TEST_CASE("reverse Cuthill–McKee: a matrix with several components and a diagonal matrix", "[ex08.8]")
{
    Eigen::MatrixXd D = 4.0 * Eigen::MatrixXd::Identity(7, 7);
    D(1, 0) = D(0, 1) = D(5, 6) = D(6, 5) = -1.0;
    CHECK(is_permutation(reverse_cuthill_mckee(csc(D.sparseView())), 7));
    CHECK(is_permutation(reverse_cuthill_mckee(csc(Eigen::MatrixXd::Identity(5, 5).sparseView())), 5));
}
