// Chapter 08: permutations, the graph of a matrix, reverse Cuthill–McKee, minimum degree, and
// Eigen's AMD for comparison. docs/08_direct_solvers.md#orderings
#include "08_direct_solvers/orderings.hpp"

#include "08_direct_solvers/ordering_graphs.hpp"

#include "common/error.hpp"

#include <Eigen/OrderingMethods>

#include <algorithm>
#include <numeric>

namespace fem::direct {

std::string ordering_name(Ordering ordering)
{
    switch (ordering) {
    case Ordering::natural: return "natural";
    case Ordering::reverse_cuthill_mckee: return "RCM";
    case Ordering::minimum_degree: return "minimum degree";
    case Ordering::eigen_amd: return "Eigen AMD";
    case Ordering::nested_dissection: return "nested dissection";
    }
    throw Error("ordering_name: unknown ordering");
}

void validate_permutation(const Permutation& perm, int n)
{
    if (static_cast<long long>(perm.size()) != n)
        throw Error(str("permutation: it has ", perm.size(), " entries for ", n, " unknowns; it must list each of 0 … ",
                        n - 1, " once"));
    std::vector<char> seen(n, 0);
    for (int k = 0; k < n; ++k) {
        const int old = perm[k];
        if (old < 0 || old >= n)
            throw Error(str("permutation: entry ", k, " is ", old, ", outside [0, ", n, ")"));
        if (seen[old])
            throw Error(str("permutation: entry ", k, " repeats index ", old, "; each index must appear once"));
        seen[old] = 1;
    }
}

Permutation inverse_permutation(const Permutation& perm)
{
    const int n = static_cast<int>(perm.size());
    validate_permutation(perm, n);
    Permutation inverse(n);
    for (int k = 0; k < n; ++k)
        inverse[perm[k]] = k;
    return inverse;
}

AdjacencyGraph adjacency_graph(const sparse::CscMatrix& A)
{
    sparse::validate(A);
    if (A.rows != A.cols)
        throw Error(str("adjacency graph: the matrix is ", A.rows, "×", A.cols, "; it must be square"));
    const int n = A.cols;
    // Every off-diagonal entry gives the edge in both directions; duplicates (an entry stored in
    // both triangles) are removed after sorting each list.
    std::vector<int> count(n + 1, 0);
    for (int j = 0; j < n; ++j)
        for (int k = A.IA[j]; k < A.IA[j + 1]; ++k)
            if (A.JA[k] != j) {
                ++count[A.JA[k] + 1];
                ++count[j + 1];
            }
    std::partial_sum(count.begin(), count.end(), count.begin());
    std::vector<int> raw(count[n]);
    std::vector<int> next(count.begin(), count.end() - 1);
    for (int j = 0; j < n; ++j)
        for (int k = A.IA[j]; k < A.IA[j + 1]; ++k) {
            const int i = A.JA[k];
            if (i != j) {
                raw[next[i]++] = j;
                raw[next[j]++] = i;
            }
        }
    AdjacencyGraph g;
    g.vertices = n;
    g.pointers.assign(n + 1, 0);
    g.adjacency.reserve(raw.size());
    for (int i = 0; i < n; ++i) {
        const auto begin = raw.begin() + count[i], end = raw.begin() + count[i + 1];
        std::sort(begin, end);
        g.adjacency.insert(g.adjacency.end(), begin, std::unique(begin, end));
        g.pointers[i + 1] = static_cast<int>(g.adjacency.size());
    }
    return g;
}

int bandwidth(const AdjacencyGraph& graph, const Permutation& perm)
{
    const Permutation position = inverse_permutation(perm);
    if (static_cast<int>(perm.size()) != graph.vertices)
        throw Error(str("bandwidth: the permutation has ", perm.size(), " entries, the graph ", graph.vertices,
                        " vertices"));
    int width = 0;
    for (int i = 0; i < graph.vertices; ++i)
        for (int k = graph.pointers[i]; k < graph.pointers[i + 1]; ++k)
            width = std::max(width, std::abs(position[i] - position[graph.adjacency[k]]));
    return width;
}

int pseudo_peripheral_vertex(const AdjacencyGraph& graph, int start)
{
    if (start < 0 || start >= graph.vertices)
        throw Error(str("pseudo-peripheral vertex: start ", start, " is outside [0, ", graph.vertices, ")"));
    LevelStructure levels(graph.vertices);
    int root = start;
    int eccentricity = levels.build(graph, root);
    for (;;) {
        // the vertex of least degree in the last level
        int candidate = -1;
        for (int v : levels.last_level())
            if (candidate < 0 || graph.degree(v) < graph.degree(candidate))
                candidate = v;
        const int candidate_eccentricity = levels.build(graph, candidate);
        if (candidate_eccentricity <= eccentricity)
            return root;
        root = candidate;
        eccentricity = candidate_eccentricity;
    }
}

Permutation reverse_cuthill_mckee(const sparse::CscMatrix& A)
{
    const AdjacencyGraph graph = adjacency_graph(A);
    const int n = graph.vertices;
    Permutation order;
    order.reserve(n);
    std::vector<char> visited(n, 0);
    std::vector<int> neighbours;
    for (int s = 0; s < n; ++s) {
        if (visited[s])
            continue;
        // s is the first vertex of a component no search has reached yet
        const int root = pseudo_peripheral_vertex(graph, s);
        const std::size_t first = order.size();
        // BEGIN EXERCISE 08.8 reverse_cuthill_mckee #reverse-cuthill-mckee
        // HINT: a breadth-first search from root that appends to `order` (use order itself as the
        // HINT: queue, starting at position `first`); mark each vertex in `visited` when it is
        // HINT: appended. The unvisited neighbours of a vertex go in by increasing degree (ties: lower
        // HINT: index first). The reversal happens after the loop.
        order.push_back(root);
        visited[root] = 1;
        for (std::size_t head = first; head < order.size(); ++head) {
            const int v = order[head];
            neighbours.clear();
            for (int k = graph.pointers[v]; k < graph.pointers[v + 1]; ++k)
                if (!visited[graph.adjacency[k]])
                    neighbours.push_back(graph.adjacency[k]);
            std::sort(neighbours.begin(), neighbours.end(), [&](int a, int b) {
                return graph.degree(a) != graph.degree(b) ? graph.degree(a) < graph.degree(b) : a < b;
            });
            for (int w : neighbours) {
                visited[w] = 1;
                order.push_back(w);
            }
        }
        // END EXERCISE
    }
    if (static_cast<int>(order.size()) != n)
        throw Error(str("reverse Cuthill–McKee: the search numbered ", order.size(), " of ", n,
                        " unknowns; every vertex must be appended exactly once"));
    std::reverse(order.begin(), order.end());
    return order;
}

Permutation minimum_degree(const sparse::CscMatrix& A)
{
    const AdjacencyGraph graph = adjacency_graph(A);
    const CompressedGraph compressed = compress_indistinguishable(graph);
    return expand_ordering(compressed, minimum_degree_order(compressed.graph, compressed.weight));
}

Permutation eigen_amd(const sparse::CscMatrix& A)
{
    if (A.rows != A.cols)
        throw Error(str("Eigen AMD: the matrix is ", A.rows, "×", A.cols, "; it must be square"));
    const Eigen::SparseMatrix<double> M = sparse::to_eigen(A);
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> P;
    Eigen::AMDOrdering<int> amd;
    amd(M, P);  // the pattern of A + Aᵀ; P.indices()[new] = old, as SimplicialLLT uses it
    return Permutation(P.indices().data(), P.indices().data() + P.indices().size());
}

Permutation fill_reducing_ordering(const sparse::CscMatrix& A, Ordering ordering)
{
    switch (ordering) {
    case Ordering::natural: {
        if (A.rows != A.cols)
            throw Error(str("ordering: the matrix is ", A.rows, "×", A.cols, "; it must be square"));
        Permutation identity(A.cols);
        std::iota(identity.begin(), identity.end(), 0);
        return identity;
    }
    case Ordering::reverse_cuthill_mckee: return reverse_cuthill_mckee(A);
    case Ordering::minimum_degree: return minimum_degree(A);
    case Ordering::eigen_amd: return eigen_amd(A);
    case Ordering::nested_dissection: return nested_dissection(A);
    }
    throw Error("ordering: unknown ordering");
}

}  // namespace fem::direct
