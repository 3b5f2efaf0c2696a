#pragma once
// Chapter 08: fill-reducing orderings of a sparse symmetric matrix. docs/08_direct_solvers.md#orderings
//
// The Cholesky factor of A is much denser than A: eliminating unknown k connects all of its
// not-yet-eliminated neighbours (the "fill"). Renumbering the unknowns first, C = P A Pᵀ, does not
// change the solution but changes the fill enormously. A permutation is stored as the list
//     perm[new] = old    (the k-th unknown of C is unknown perm[k] of A),  C(k, l) = A(perm[k], perm[l]);
// its inverse is inverse[old] = new. Only the sparsity pattern of A matters here: the graph with
// an edge i — j for every stored A_ij ≠ A_ji off the diagonal (both triangles are read, so a
// matrix stored as one triangle and one stored as both give the same graph).

#include "07_sparse_storage/sparse_formats.hpp"

#include <string>
#include <vector>

namespace fem::direct {

/// perm[new] = old: a renumbering of 0 … n−1.
using Permutation = std::vector<int>;

/// The fill-reducing orderings this chapter offers.
enum class Ordering {
    natural,                 ///< the identity: the numbering the matrix came with
    reverse_cuthill_mckee,   ///< small bandwidth (a banded/profile solver's ordering)
    minimum_degree,          ///< eliminate the least-connected unknown first (ours, by hand)
    eigen_amd,               ///< Eigen's approximate minimum degree (for comparison)
    nested_dissection,       ///< separators last, recursively (ours, by hand)
};

/// "natural", "RCM", "minimum degree", "Eigen AMD", "nested dissection".
std::string ordering_name(Ordering ordering);

/// fem::Error unless perm holds every index 0 … n−1 exactly once (names the first bad entry).
void validate_permutation(const Permutation& perm, int n);

/// inverse[perm[k]] = k. fem::Error if perm is not a permutation.
Permutation inverse_permutation(const Permutation& perm);

/// The symmetric adjacency structure of A without the diagonal, in CSR-like arrays: the
/// neighbours of vertex i are adjacency[pointers[i] … pointers[i+1]−1], sorted, each edge stored in
/// both directions, whichever triangle(s) of A held it. fem::Error for a non-square or invalid A.
/// docs/08_direct_solvers.md#the-graph-of-a-matrix
struct AdjacencyGraph {
    int vertices = 0;
    std::vector<int> pointers{0};
    std::vector<int> adjacency;

    int degree(int i) const { return pointers[i + 1] - pointers[i]; }
};
AdjacencyGraph adjacency_graph(const sparse::CscMatrix& A);

/// The bandwidth max |perm⁻¹(i) − perm⁻¹(j)| over the edges of A's graph in the new numbering
/// (0 for a diagonal matrix). fem::Error for a bad permutation.
/// docs/08_direct_solvers.md#reverse-cuthill-mckee
int bandwidth(const AdjacencyGraph& graph, const Permutation& perm);

/// A pseudo-peripheral vertex of the connected component of `start` (George–Liu): repeatedly
/// take a vertex of least degree in the last level of the breadth-first level structure rooted at
/// the current vertex, while the number of levels (the eccentricity) grows.
/// docs/08_direct_solvers.md#reverse-cuthill-mckee
int pseudo_peripheral_vertex(const AdjacencyGraph& graph, int start);

/// Reverse Cuthill–McKee: for each connected component, a breadth-first search from a
/// pseudo-peripheral vertex that visits the unvisited neighbours of each vertex in increasing
/// order of degree (ties: lower index first); the whole order is then reversed. Keeps every
/// nonzero close to the diagonal (small bandwidth and profile), which bounds the fill by the
/// envelope, but is not a good fill-reducing ordering in 2D and 3D. O(nnz log Δ).
/// docs/08_direct_solvers.md#reverse-cuthill-mckee
Permutation reverse_cuthill_mckee(const sparse::CscMatrix& A);

/// Minimum degree on the quotient graph: eliminate, one after the other, an unknown of least
/// (approximate external) degree, where each elimination merges the unknown and its element
/// neighbours into a new element instead of adding fill edges explicitly. Indistinguishable
/// unknowns (the 3 displacements of a vertex) are merged into supervariables and eliminated
/// together; elements covered by the new one are absorbed. The degree of a neighbour i of the
/// pivot is the upper bound |A_i \ i| + |L_p \ i| + Σ_{e ∈ E_i, e ≠ p} |L_e \ L_p| of
/// Amestoy, Davis and Duff (exact for most i, and cheap: no set unions).
/// docs/08_direct_solvers.md#minimum-degree
Permutation minimum_degree(const sparse::CscMatrix& A);

/// Eigen's AMD ordering (Eigen::AMDOrdering, a port of Davis' AMD), as a Permutation.
/// docs/08_direct_solvers.md#minimum-degree
Permutation eigen_amd(const sparse::CscMatrix& A);

/// Nested dissection: find a small vertex separator S that splits the graph into two halves of
/// similar size, number the halves first (recursively) and S last, so that no fill crosses from
/// one half to the other. Separators come from a multilevel scheme: the graph is coarsened by
/// heavy-edge matching, the coarsest graph is split by breadth-first level structures, and the
/// separator is projected back and improved level by level with Fiduccia–Mattheyses moves.
/// Pieces of at most `leaf_size` unknowns are ordered by minimum_degree. Deterministic (a fixed
/// pseudo-random matching order). fem::Error for leaf_size < 1.
/// docs/08_direct_solvers.md#nested-dissection
Permutation nested_dissection(const sparse::CscMatrix& A, int leaf_size = 128);

/// The ordering of the given kind (Ordering::natural: the identity).
Permutation fill_reducing_ordering(const sparse::CscMatrix& A, Ordering ordering);

}  // namespace fem::direct
