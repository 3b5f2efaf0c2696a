// Chapter 08: nested dissection with multilevel vertex separators (heavy-edge matching, level-
// structure bisection of the coarsest graph, Fiduccia–Mattheyses refinement while projecting back).
// docs/08_direct_solvers.md#nested-dissection
#include "08_direct_solvers/ordering_graphs.hpp"
#include "08_direct_solvers/orderings.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <queue>

namespace fem::direct {
namespace {

/// A graph with vertex weights (unknowns per vertex) and edge weights (edges merged by coarsening).
struct WeightedGraph {
    int n = 0;
    std::vector<int> pointers{0};
    std::vector<int> adjacency;
    std::vector<int> edge_weight;
    std::vector<int> vertex_weight;

    long long total_weight() const
    {
        return std::accumulate(vertex_weight.begin(), vertex_weight.end(), 0LL);
    }
};

enum Side : char { left = 0, right = 1, separator = 2 };

/// Vertex and edge counts below which a graph is not coarsened further.
constexpr int coarsest_size = 120;

/// A fixed pseudo-random visiting order (a linear congruential shuffle): matching in index order
/// would coarsen a grid along its rows only.
std::vector<int> shuffled(int n, std::uint64_t seed)
{
    std::vector<int> order(n);
    std::iota(order.begin(), order.end(), 0);
    std::uint64_t state = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    for (int i = n - 1; i > 0; --i) {
        state = state * 6364136223846793005ULL + 1442695040888963407ULL;
        const int j = static_cast<int>((state >> 33) % static_cast<std::uint64_t>(i + 1));
        std::swap(order[i], order[j]);
    }
    return order;
}

/// Heavy-edge matching: each unmatched vertex is paired with the unmatched neighbour joined by the
/// heaviest edge (if the pair is not too heavy), and each pair becomes one coarse vertex.
/// Returns the coarse graph; map[v] is the coarse vertex of fine vertex v.
WeightedGraph coarsen(const WeightedGraph& g, std::vector<int>& map, long long max_vertex_weight)
{
    std::vector<int> match(g.n, -1);
    for (int v : shuffled(g.n, static_cast<std::uint64_t>(g.n))) {
        if (match[v] >= 0)
            continue;
        int best = -1, best_weight = -1;
        for (int k = g.pointers[v]; k < g.pointers[v + 1]; ++k) {
            const int u = g.adjacency[k];
            if (match[u] < 0 && u != v && g.edge_weight[k] > best_weight &&
                g.vertex_weight[u] + g.vertex_weight[v] <= max_vertex_weight) {
                best = u;
                best_weight = g.edge_weight[k];
            }
        }
        match[v] = best < 0 ? v : best;
        if (best >= 0)
            match[best] = v;
    }
    map.assign(g.n, -1);
    int coarse_n = 0;
    for (int v = 0; v < g.n; ++v)
        if (map[v] < 0) {
            map[v] = coarse_n;
            map[match[v]] = coarse_n;
            ++coarse_n;
        }
    WeightedGraph c;
    c.n = coarse_n;
    c.vertex_weight.assign(coarse_n, 0);
    std::vector<int> fine_of(2 * coarse_n, -1);  // the (up to) two fine vertices of each coarse one
    for (int v = 0; v < g.n; ++v) {
        c.vertex_weight[map[v]] += g.vertex_weight[v];
        fine_of[2 * map[v] + (fine_of[2 * map[v]] < 0 ? 0 : 1)] = v;
    }
    c.pointers.assign(coarse_n + 1, 0);
    std::vector<int> where(coarse_n, -1);
    for (int cv = 0; cv < coarse_n; ++cv) {
        const int first = static_cast<int>(c.adjacency.size());
        for (int t = 0; t < 2; ++t) {
            const int v = fine_of[2 * cv + t];
            if (v < 0)
                continue;
            for (int k = g.pointers[v]; k < g.pointers[v + 1]; ++k) {
                const int cu = map[g.adjacency[k]];
                if (cu == cv)
                    continue;
                if (where[cu] >= first) {
                    c.edge_weight[where[cu]] += g.edge_weight[k];
                } else {
                    where[cu] = static_cast<int>(c.adjacency.size());
                    c.adjacency.push_back(cu);
                    c.edge_weight.push_back(g.edge_weight[k]);
                }
            }
        }
        c.pointers[cv + 1] = static_cast<int>(c.adjacency.size());
    }
    return c;
}

/// Fiduccia–Mattheyses refinement of a vertex separator. Moving separator vertex v to side s pulls
/// its neighbours on the other side into the separator: gain = w(v) − Σ w(those neighbours). Each
/// pass moves every separator vertex at most once, best gain first (negative gains allowed, to
/// climb out of local minima), within the balance limit, and keeps the best state seen.
class SeparatorRefiner {
public:
    SeparatorRefiner(const WeightedGraph& g, std::vector<char>& side, double max_fraction)
        : g_(g), side_(side), max_fraction_(max_fraction), locked_(g.n, 0), gain_{std::vector<long long>(g.n),
                                                                                  std::vector<long long>(g.n)}
    {
        weight_[0] = weight_[1] = weight_[2] = 0;
        for (int v = 0; v < g_.n; ++v)
            weight_[static_cast<int>(side_[v])] += g_.vertex_weight[v];
    }

    void refine(int passes)
    {
        for (int pass = 0; pass < passes; ++pass)
            if (!one_pass())
                break;
    }

    long long separator_weight() const { return weight_[separator]; }

private:
    struct Entry {
        long long gain;
        int vertex;
        bool operator<(const Entry& other) const
        {
            return gain != other.gain ? gain < other.gain : vertex > other.vertex;
        }
    };
    struct Move {
        int vertex;
        char to;
        std::size_t pulled_begin;  // the vertices this move pulled into the separator
    };

    void compute_gains(int v)
    {
        long long into[2] = {g_.vertex_weight[v], g_.vertex_weight[v]};
        for (int k = g_.pointers[v]; k < g_.pointers[v + 1]; ++k) {
            const int u = g_.adjacency[k];
            if (side_[u] == left)
                into[right] -= g_.vertex_weight[u];
            else if (side_[u] == right)
                into[left] -= g_.vertex_weight[u];
        }
        for (int s = 0; s < 2; ++s) {
            gain_[s][v] = into[s];
            heap_[s].push({into[s], v});
        }
    }

    bool valid(int s, const Entry& e) const
    {
        return side_[e.vertex] == separator && !locked_[e.vertex] && gain_[s][e.vertex] == e.gain;
    }

    long long imbalance() const { return std::abs(weight_[left] - weight_[right]); }

    bool one_pass()
    {
        for (int s = 0; s < 2; ++s)
            heap_[s] = {};
        std::fill(locked_.begin(), locked_.end(), 0);
        for (int v = 0; v < g_.n; ++v)
            if (side_[v] == separator)
                compute_gains(v);
        const long long start_separator = weight_[separator], start_imbalance = imbalance();
        long long best_separator = start_separator, best_imbalance = start_imbalance;
        std::size_t best_moves = 0;
        moves_.clear();
        pulled_.clear();
        const std::size_t patience = std::max<std::size_t>(64, static_cast<std::size_t>(g_.n) / 20);
        const long long total = weight_[0] + weight_[1] + weight_[2];
        const long long max_part = static_cast<long long>(max_fraction_ * static_cast<double>(total));
        for (;;) {
            int chosen_side = -1;
            Entry chosen{0, -1};
            for (int s = 0; s < 2; ++s) {
                while (!heap_[s].empty() && !valid(s, heap_[s].top()))
                    heap_[s].pop();
                if (heap_[s].empty())
                    continue;
                const Entry top = heap_[s].top();
                if (weight_[s] + g_.vertex_weight[top.vertex] > max_part)
                    continue;
                if (chosen_side < 0 || top.gain > chosen.gain ||
                    (top.gain == chosen.gain && weight_[s] < weight_[chosen_side])) {
                    chosen_side = s;
                    chosen = top;
                }
            }
            if (chosen_side < 0)
                break;
            move(chosen.vertex, static_cast<char>(chosen_side));
            if (weight_[separator] < best_separator ||
                (weight_[separator] == best_separator && imbalance() < best_imbalance)) {
                best_separator = weight_[separator];
                best_imbalance = imbalance();
                best_moves = moves_.size();
            } else if (moves_.size() - best_moves > patience) {
                break;
            }
        }
        while (moves_.size() > best_moves)
            undo();
        return best_separator < start_separator || best_imbalance < start_imbalance;
    }

    void move(int v, char to)
    {
        const char other = static_cast<char>(1 - to);
        moves_.push_back({v, to, pulled_.size()});
        locked_[v] = 1;
        side_[v] = to;
        weight_[separator] -= g_.vertex_weight[v];
        weight_[static_cast<int>(to)] += g_.vertex_weight[v];
        for (int k = g_.pointers[v]; k < g_.pointers[v + 1]; ++k) {
            const int u = g_.adjacency[k];
            if (side_[u] == other) {
                side_[u] = separator;
                weight_[static_cast<int>(other)] -= g_.vertex_weight[u];
                weight_[separator] += g_.vertex_weight[u];
                pulled_.push_back(u);
            }
        }
        // New gains: the pulled vertices, and the separator vertices next to v or to them.
        for (std::size_t t = moves_.back().pulled_begin; t < pulled_.size(); ++t) {
            const int u = pulled_[t];
            if (!locked_[u])
                compute_gains(u);
            for (int k = g_.pointers[u]; k < g_.pointers[u + 1]; ++k) {
                const int x = g_.adjacency[k];
                if (side_[x] == separator && !locked_[x])
                    compute_gains(x);
            }
        }
        for (int k = g_.pointers[v]; k < g_.pointers[v + 1]; ++k) {
            const int x = g_.adjacency[k];
            if (side_[x] == separator && !locked_[x])
                compute_gains(x);
        }
    }

    void undo()
    {
        const Move m = moves_.back();
        moves_.pop_back();
        const char other = static_cast<char>(1 - m.to);
        for (std::size_t t = m.pulled_begin; t < pulled_.size(); ++t) {
            const int u = pulled_[t];
            side_[u] = other;
            weight_[separator] -= g_.vertex_weight[u];
            weight_[static_cast<int>(other)] += g_.vertex_weight[u];
        }
        pulled_.resize(m.pulled_begin);
        side_[m.vertex] = separator;
        weight_[static_cast<int>(m.to)] -= g_.vertex_weight[m.vertex];
        weight_[separator] += g_.vertex_weight[m.vertex];
    }

    const WeightedGraph& g_;
    std::vector<char>& side_;
    double max_fraction_;
    std::vector<char> locked_;
    std::vector<long long> gain_[2];
    std::priority_queue<Entry> heap_[2];
    long long weight_[3];
    std::vector<Move> moves_;
    std::vector<int> pulled_;
};

/// The largest share of the weight either side may hold.
constexpr double max_side_fraction = 0.6;

AdjacencyGraph plain(const WeightedGraph& g)
{
    AdjacencyGraph a;
    a.vertices = g.n;
    a.pointers = g.pointers;
    a.adjacency = g.adjacency;
    return a;
}

/// A separator of a small connected graph: grow the left side breadth-first from a root until it
/// holds half the weight; the right-side vertices touching it form the separator; refine. The
/// best of a few roots (pseudo-peripheral ones from spread-out starts) wins.
std::vector<char> initial_separator(const WeightedGraph& g)
{
    const AdjacencyGraph a = plain(g);
    LevelStructure levels(g.n);
    const long long total = g.total_weight();
    std::vector<char> best;
    long long best_separator = 0, best_imbalance = 0;
    const int trials = std::min(g.n, 6);
    for (int t = 0; t < trials; ++t) {
        const int root = t == 0 ? pseudo_peripheral_vertex(a, 0) : static_cast<int>((static_cast<long long>(t) * g.n) / trials);
        levels.build(a, root);
        std::vector<char> side(g.n, right);
        long long grown = 0;
        for (int v : levels.order()) {
            if (2 * grown >= total)
                break;
            side[v] = left;
            grown += g.vertex_weight[v];
        }
        for (int v = 0; v < g.n; ++v)
            if (side[v] == right)
                for (int k = g.pointers[v]; k < g.pointers[v + 1]; ++k)
                    if (side[g.adjacency[k]] == left) {
                        side[v] = separator;
                        break;
                    }
        SeparatorRefiner refiner(g, side, max_side_fraction);
        refiner.refine(8);
        long long w[3] = {0, 0, 0};
        for (int v = 0; v < g.n; ++v)
            w[static_cast<int>(side[v])] += g.vertex_weight[v];
        const long long imbalance = std::abs(w[0] - w[1]);
        if (best.empty() || w[2] < best_separator || (w[2] == best_separator && imbalance < best_imbalance)) {
            best = side;
            best_separator = w[2];
            best_imbalance = imbalance;
        }
    }
    return best;
}

/// A vertex separator of a connected graph by the multilevel scheme.
std::vector<char> multilevel_separator(const WeightedGraph& g)
{
    std::vector<WeightedGraph> graphs;
    std::vector<std::vector<int>> maps;
    const WeightedGraph* current = &g;
    const long long max_vertex_weight = std::max<long long>(1, (3 * g.total_weight()) / (2 * coarsest_size));
    while (current->n > coarsest_size) {
        std::vector<int> map;
        WeightedGraph coarse = coarsen(*current, map, max_vertex_weight);
        if (coarse.n > 0.9 * current->n)
            break;  // hardly any pairs left to match
        maps.push_back(std::move(map));
        graphs.push_back(std::move(coarse));
        current = &graphs.back();
    }
    std::vector<char> side = initial_separator(*current);
    for (int level = static_cast<int>(graphs.size()) - 1; level >= 0; --level) {
        const WeightedGraph& finer = level == 0 ? g : graphs[level - 1];
        std::vector<char> projected(finer.n);
        for (int v = 0; v < finer.n; ++v)
            projected[v] = side[maps[level][v]];
        side = std::move(projected);
        SeparatorRefiner refiner(finer, side, max_side_fraction);
        refiner.refine(4);
    }
    return side;
}

WeightedGraph induced(const WeightedGraph& g, const std::vector<int>& vertices, std::vector<int>& position)
{
    const int m = static_cast<int>(vertices.size());
    for (int k = 0; k < m; ++k)
        position[vertices[k]] = k;
    WeightedGraph sub;
    sub.n = m;
    sub.pointers.assign(m + 1, 0);
    sub.vertex_weight.resize(m);
    for (int k = 0; k < m; ++k) {
        const int v = vertices[k];
        sub.vertex_weight[k] = g.vertex_weight[v];
        for (int e = g.pointers[v]; e < g.pointers[v + 1]; ++e)
            if (position[g.adjacency[e]] >= 0) {
                sub.adjacency.push_back(position[g.adjacency[e]]);
                sub.edge_weight.push_back(g.edge_weight[e]);
            }
        sub.pointers[k + 1] = static_cast<int>(sub.adjacency.size());
    }
    for (int v : vertices)
        position[v] = -1;
    return sub;
}

class Dissection {
public:
    Dissection(int n, long long leaf_size) : position_(n, -1), leaf_size_(leaf_size) { order_.reserve(n); }

    /// Appends the ordering of g (whose vertex k is ids[k]) to order_.
    void dissect(const WeightedGraph& g, const std::vector<int>& ids)
    {
        // Components separately: no separator is needed between them.
        const AdjacencyGraph a = plain(g);
        LevelStructure levels(g.n);
        std::vector<char> seen(g.n, 0);
        std::vector<std::vector<int>> components;
        for (int v = 0; v < g.n; ++v)
            if (!seen[v]) {
                levels.build(a, v);
                components.emplace_back(levels.order().begin(), levels.order().end());
                for (int u : components.back())
                    seen[u] = 1;
            }
        if (components.size() > 1) {
            for (std::vector<int>& component : components) {
                std::sort(component.begin(), component.end());
                const WeightedGraph piece = induced(g, component, position_);
                std::vector<int> piece_ids(component.size());
                for (std::size_t k = 0; k < component.size(); ++k)
                    piece_ids[k] = ids[component[k]];
                dissect(piece, piece_ids);
            }
            return;
        }
        const long long total = g.total_weight();
        if (total <= leaf_size_ || g.n <= 3) {
            leaf(g, ids);
            return;
        }
        const std::vector<char> side = multilevel_separator(g);
        std::vector<int> parts[3];
        for (int v = 0; v < g.n; ++v)
            parts[static_cast<int>(side[v])].push_back(v);
        if (parts[left].empty() || parts[right].empty()) {
            leaf(g, ids);  // no useful separator (a clique-like piece)
            return;
        }
        for (int s = 0; s < 2; ++s) {
            const WeightedGraph piece = induced(g, parts[s], position_);
            std::vector<int> piece_ids(parts[s].size());
            for (std::size_t k = 0; k < parts[s].size(); ++k)
                piece_ids[k] = ids[parts[s][k]];
            dissect(piece, piece_ids);
        }
        for (int v : parts[separator])
            order_.push_back(ids[v]);
    }

    Permutation take() { return std::move(order_); }

private:
    void leaf(const WeightedGraph& g, const std::vector<int>& ids)
    {
        for (int v : minimum_degree_order(plain(g), g.vertex_weight))
            order_.push_back(ids[v]);
    }

    std::vector<int> position_;
    long long leaf_size_;
    Permutation order_;
};

}  // namespace

Permutation nested_dissection(const sparse::CscMatrix& A, int leaf_size)
{
    if (leaf_size < 1)
        throw Error(str("nested dissection: leaf_size = ", leaf_size, "; it must be ≥ 1"));
    const AdjacencyGraph graph = adjacency_graph(A);
    if (graph.vertices == 0)
        return {};
    const CompressedGraph compressed = compress_indistinguishable(graph);
    WeightedGraph g;
    g.n = compressed.graph.vertices;
    g.pointers = compressed.graph.pointers;
    g.adjacency = compressed.graph.adjacency;
    g.edge_weight.assign(g.adjacency.size(), 1);
    g.vertex_weight = compressed.weight;
    std::vector<int> ids(g.n);
    std::iota(ids.begin(), ids.end(), 0);
    Dissection dissection(g.n, leaf_size);
    dissection.dissect(g, ids);
    return expand_ordering(compressed, dissection.take());
}

}  // namespace fem::direct
