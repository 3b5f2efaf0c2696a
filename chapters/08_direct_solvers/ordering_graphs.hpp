#pragma once
// Chapter 08: the graph machinery behind the orderings (shared by reverse Cuthill–McKee, minimum
// degree and nested dissection). A student needs only orderings.hpp; this header shows how the
// orderings work on graphs with vertex weights. docs/08_direct_solvers.md#orderings

#include "08_direct_solvers/orderings.hpp"

#include <span>
#include <vector>

namespace fem::direct {

/// The breadth-first level structure rooted at a vertex: level 0 is the root, level l+1 the
/// unvisited neighbours of level l. Reusable for many roots of graphs with up to n vertices.
class LevelStructure {
public:
    explicit LevelStructure(int n);
    /// Builds the levels of root's connected component; returns their number (the eccentricity of
    /// root + 1). fem::Error if root is outside the graph or the graph has more than n vertices.
    int build(const AdjacencyGraph& graph, int root);
    int levels() const { return static_cast<int>(level_start_.size()) - 1; }
    /// The vertices of level l, in the order the search found them.
    std::span<const int> level(int l) const;
    std::span<const int> last_level() const { return level(levels() - 1); }
    /// level_of(v): the level of v in the last build, −1 if v was not reached.
    int level_of(int v) const { return level_of_[v]; }
    /// Every reached vertex, level by level.
    std::span<const int> order() const { return {order_.data(), order_.size()}; }

private:
    std::vector<int> order_;
    std::vector<int> level_start_;
    std::vector<int> level_of_;
};

/// A graph whose vertices stand for groups of indistinguishable vertices of an original graph:
/// vertices with the same closed neighbourhood adj(v) ∪ {v} (the 3 unknowns of one mesh vertex in
/// an elasticity matrix). Eliminating one of them makes the others' degree drop to the same value,
/// so an ordering can treat the group as one vertex of weight = its size.
struct CompressedGraph {
    AdjacencyGraph graph;          ///< one vertex per group, an edge where the groups are adjacent
    std::vector<int> weight;       ///< the size of each group
    std::vector<int> member_start; ///< group g holds members[member_start[g] … member_start[g+1]−1]
    std::vector<int> members;      ///< original vertices, ascending within a group
};

/// Groups indistinguishable vertices (hashing each closed neighbourhood, then comparing the lists
/// that hash alike). O(nnz) expected.
CompressedGraph compress_indistinguishable(const AdjacencyGraph& graph);

/// An ordering of the original vertices from an ordering of the groups: each group's members
/// consecutively, in ascending order. fem::Error if order is not a permutation of the groups.
Permutation expand_ordering(const CompressedGraph& compressed, const Permutation& group_order);

/// The minimum degree ordering (see minimum_degree in orderings.hpp) of a graph whose vertex v
/// stands for weight[v] unknowns: degrees count unknowns, not vertices. Returns perm[new] = old
/// over the vertices of the graph.
Permutation minimum_degree_order(const AdjacencyGraph& graph, const std::vector<int>& weight);

/// The subgraph induced by `vertices` (its vertex k is vertices[k]), keeping the edges between
/// them. `position` must have graph.vertices entries equal to −1; it is used as scratch and left so.
AdjacencyGraph induced_subgraph(const AdjacencyGraph& graph, std::span<const int> vertices,
                                std::vector<int>& position);

}  // namespace fem::direct
