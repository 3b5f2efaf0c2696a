// Chapter 08: level structures, graph compression and the minimum degree ordering on the quotient
// graph. docs/08_direct_solvers.md#minimum-degree
#include "08_direct_solvers/ordering_graphs.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <cstdint>
#include <numeric>

namespace fem::direct {

LevelStructure::LevelStructure(int n) : level_of_(n, -1)
{
    order_.reserve(n);
}

int LevelStructure::build(const AdjacencyGraph& graph, int root)
{
    if (graph.vertices > static_cast<int>(level_of_.size()))
        throw Error(str("level structure: the graph has ", graph.vertices, " vertices, the structure was made for ",
                        level_of_.size()));
    if (root < 0 || root >= graph.vertices)
        throw Error(str("level structure: root ", root, " is outside [0, ", graph.vertices, ")"));
    for (int v : order_)
        level_of_[v] = -1;
    order_.clear();
    order_.push_back(root);
    level_of_[root] = 0;
    level_start_.assign(1, 0);
    std::size_t begin = 0;
    for (int level = 0;; ++level) {
        const std::size_t end = order_.size();
        for (std::size_t k = begin; k < end; ++k) {
            const int v = order_[k];
            for (int e = graph.pointers[v]; e < graph.pointers[v + 1]; ++e) {
                const int w = graph.adjacency[e];
                if (level_of_[w] < 0) {
                    level_of_[w] = level + 1;
                    order_.push_back(w);
                }
            }
        }
        level_start_.push_back(static_cast<int>(end));
        if (order_.size() == end)
            break;
        begin = end;
    }
    return levels();
}

std::span<const int> LevelStructure::level(int l) const
{
    if (l < 0 || l >= levels())
        throw Error(str("level structure: level ", l, " does not exist (", levels(), " levels)"));
    return {order_.data() + level_start_[l], static_cast<std::size_t>(level_start_[l + 1] - level_start_[l])};
}

CompressedGraph compress_indistinguishable(const AdjacencyGraph& graph)
{
    const int n = graph.vertices;
    // A hash of the closed neighbourhood adj(v) ∪ {v}: equal neighbourhoods hash alike.
    const auto mix = [](std::uint64_t x) {
        x += 0x9e3779b97f4a7c15ULL;
        x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
        x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
        return x ^ (x >> 31);
    };
    std::vector<std::uint64_t> hash(n);
    for (int v = 0; v < n; ++v) {
        std::uint64_t h = mix(static_cast<std::uint64_t>(v));
        for (int k = graph.pointers[v]; k < graph.pointers[v + 1]; ++k)
            h += mix(static_cast<std::uint64_t>(graph.adjacency[k]));
        hash[v] = h;
    }
    std::vector<int> by_hash(n);
    std::iota(by_hash.begin(), by_hash.end(), 0);
    std::sort(by_hash.begin(), by_hash.end(), [&](int a, int b) {
        return hash[a] != hash[b] ? hash[a] < hash[b] : a < b;
    });
    // closed(v) == closed(w) for v ≠ w  ⇔  w ∈ adj(v) and adj(v) \ {w} == adj(w) \ {v}
    const auto same_closed = [&](int v, int w) {
        if (graph.degree(v) != graph.degree(w))
            return false;
        int a = graph.pointers[v], b = graph.pointers[w];
        const int a_end = graph.pointers[v + 1], b_end = graph.pointers[w + 1];
        bool w_in_v = false, v_in_w = false;
        while (a < a_end || b < b_end) {
            if (a < a_end && graph.adjacency[a] == w) { w_in_v = true; ++a; continue; }
            if (b < b_end && graph.adjacency[b] == v) { v_in_w = true; ++b; continue; }
            if (a == a_end || b == b_end || graph.adjacency[a] != graph.adjacency[b])
                return false;
            ++a;
            ++b;
        }
        return w_in_v && v_in_w;
    };
    std::vector<int> representative(n);
    std::iota(representative.begin(), representative.end(), 0);
    for (int start = 0; start < n;) {
        int end = start + 1;
        while (end < n && hash[by_hash[end]] == hash[by_hash[start]])
            ++end;
        for (int a = start; a < end; ++a) {
            const int v = by_hash[a];
            if (representative[v] != v)
                continue;
            for (int b = a + 1; b < end; ++b) {
                const int w = by_hash[b];
                if (representative[w] == w && same_closed(v, w))
                    representative[w] = v;  // v < w: the smallest member represents the group
            }
        }
        start = end;
    }
    CompressedGraph c;
    std::vector<int> group(n, -1);
    int groups = 0;
    for (int v = 0; v < n; ++v)
        if (representative[v] == v)
            group[v] = groups++;
    c.weight.assign(groups, 0);
    for (int v = 0; v < n; ++v) {
        group[v] = group[representative[v]];
        ++c.weight[group[v]];
    }
    c.member_start.assign(groups + 1, 0);
    for (int g = 0; g < groups; ++g)
        c.member_start[g + 1] = c.member_start[g] + c.weight[g];
    c.members.resize(n);
    std::vector<int> fill(c.member_start.begin(), c.member_start.end() - 1);
    for (int v = 0; v < n; ++v)
        c.members[fill[group[v]]++] = v;
    c.graph.vertices = groups;
    c.graph.pointers.assign(groups + 1, 0);
    std::vector<int> seen(groups, -1);
    for (int g = 0; g < groups; ++g) {
        const int v = c.members[c.member_start[g]];
        const std::size_t first = c.graph.adjacency.size();
        seen[g] = g;
        for (int k = graph.pointers[v]; k < graph.pointers[v + 1]; ++k) {
            const int h = group[graph.adjacency[k]];
            if (seen[h] != g) {
                seen[h] = g;
                c.graph.adjacency.push_back(h);
            }
        }
        std::sort(c.graph.adjacency.begin() + static_cast<std::ptrdiff_t>(first), c.graph.adjacency.end());
        c.graph.pointers[g + 1] = static_cast<int>(c.graph.adjacency.size());
    }
    return c;
}

Permutation expand_ordering(const CompressedGraph& compressed, const Permutation& group_order)
{
    validate_permutation(group_order, compressed.graph.vertices);
    Permutation perm;
    perm.reserve(compressed.members.size());
    for (int g : group_order)
        for (int k = compressed.member_start[g]; k < compressed.member_start[g + 1]; ++k)
            perm.push_back(compressed.members[k]);
    return perm;
}

AdjacencyGraph induced_subgraph(const AdjacencyGraph& graph, std::span<const int> vertices,
                                std::vector<int>& position)
{
    const int m = static_cast<int>(vertices.size());
    for (int k = 0; k < m; ++k)
        position[vertices[k]] = k;
    AdjacencyGraph sub;
    sub.vertices = m;
    sub.pointers.assign(m + 1, 0);
    for (int k = 0; k < m; ++k) {
        const int v = vertices[k];
        const std::size_t first = sub.adjacency.size();
        for (int e = graph.pointers[v]; e < graph.pointers[v + 1]; ++e)
            if (position[graph.adjacency[e]] >= 0)
                sub.adjacency.push_back(position[graph.adjacency[e]]);
        std::sort(sub.adjacency.begin() + static_cast<std::ptrdiff_t>(first), sub.adjacency.end());
        sub.pointers[k + 1] = static_cast<int>(sub.adjacency.size());
    }
    for (int v : vertices)
        position[v] = -1;
    return sub;
}

namespace {

/// The quotient graph of the elimination: live variables (not yet eliminated), elements (an
/// eliminated variable stands for the clique of its remaining neighbours), absorbed elements
/// (covered by a newer one) and merged variables (eliminated together with their principal).
class QuotientGraph {
public:
    QuotientGraph(const AdjacencyGraph& graph, const std::vector<int>& weight)
        : n_(graph.vertices), status_(n_, variable), nv_(weight), vars_(n_), elems_(n_), members_(n_),
          degree_(n_), element_weight_(n_, 0), next_(n_, -1), prev_(n_, -1), chain_next_(n_, -1),
          chain_tail_(n_), mark_(n_, 0), w_(n_, 0), w_tag_(n_, 0), compare_mark_(n_, 0)
    {
        if (static_cast<int>(weight.size()) != n_)
            throw Error(str("minimum degree: ", weight.size(), " weights for ", n_, " vertices"));
        for (int v = 0; v < n_; ++v) {
            if (weight[v] < 1)
                throw Error(str("minimum degree: vertex ", v, " has weight ", weight[v], "; weights must be ≥ 1"));
            total_ += weight[v];
        }
        head_.assign(static_cast<std::size_t>(total_) + 1, -1);
        std::iota(chain_tail_.begin(), chain_tail_.end(), 0);
        for (int v = 0; v < n_; ++v) {
            vars_[v].assign(graph.adjacency.begin() + graph.pointers[v], graph.adjacency.begin() + graph.pointers[v + 1]);
            long long d = 0;
            for (int w : vars_[v])
                d += nv_[w];
            degree_[v] = d;
            insert(v);
        }
    }

    Permutation order()
    {
        Permutation order;
        order.reserve(n_);
        long long eliminated = 0;
        while (eliminated < total_) {
            while (head_[min_degree_] < 0)
                ++min_degree_;
            const int p = head_[min_degree_];
            remove(p);
            for (int v = p; v >= 0; v = chain_next_[v])  // p and the variables merged into it
                order.push_back(v);
            eliminated += nv_[p];
            eliminate(p, eliminated);
        }
        return order;
    }

private:
    enum Status : char { variable, element, absorbed, merged };

    void insert(int v)
    {
        const long long d = degree_[v];
        prev_[v] = -1;
        next_[v] = head_[d];
        if (head_[d] >= 0)
            prev_[head_[d]] = v;
        head_[d] = v;
        min_degree_ = std::min(min_degree_, d);
    }

    void remove(int v)
    {
        if (prev_[v] >= 0)
            next_[prev_[v]] = next_[v];
        else
            head_[degree_[v]] = next_[v];
        if (next_[v] >= 0)
            prev_[next_[v]] = prev_[v];
    }

    bool live(int v) const { return status_[v] == variable; }

    /// Turns variable p into an element: L_p = (A_p ∪ ⋃_{e ∈ E_p} L_e) \ {p}; the elements of E_p
    /// are absorbed; the neighbours in L_p get new lists and (approximate) degrees; equal
    /// neighbours are merged.
    void eliminate(int p, long long eliminated)
    {
        const int stamp = ++stamp_;
        mark_[p] = stamp;
        std::vector<int> Lp;
        for (int j : vars_[p])
            if (live(j) && mark_[j] != stamp) {
                mark_[j] = stamp;
                Lp.push_back(j);
            }
        for (int e : elems_[p]) {
            if (status_[e] != element)
                continue;
            for (int j : members_[e])
                if (live(j) && mark_[j] != stamp) {
                    mark_[j] = stamp;
                    Lp.push_back(j);
                }
            absorb(e);
        }
        release(vars_[p]);
        release(elems_[p]);
        status_[p] = element;
        long long lp_weight = 0;
        for (int j : Lp) {
            lp_weight += nv_[j];
            remove(j);
        }
        element_weight_[p] = lp_weight;

        // w(e) = |L_e \ L_p| for every element next to L_p: start from |L_e| and subtract the
        // members that are in L_p.
        ++w_stamp_;
        for (int i : Lp)
            for (int e : elems_[i]) {
                if (status_[e] != element)
                    continue;
                if (w_tag_[e] != w_stamp_) {
                    w_tag_[e] = w_stamp_;
                    w_[e] = element_weight_[e];
                }
                w_[e] -= nv_[i];
            }

        const long long remaining = total_ - eliminated;
        for (int i : Lp) {
            long long sum_elements = 0;
            std::size_t out = 0;
            for (int e : elems_[i]) {
                if (status_[e] != element)
                    continue;
                if (w_[e] == 0) {  // L_e ⊆ L_p: the new element covers e (aggressive absorption)
                    absorb(e);
                    continue;
                }
                sum_elements += w_[e];
                elems_[i][out++] = e;
            }
            elems_[i].resize(out);
            elems_[i].push_back(p);
            long long sum_variables = 0;
            out = 0;
            for (int j : vars_[i])
                if (live(j) && mark_[j] != stamp) {  // drop eliminated, merged and L_p variables
                    vars_[i][out++] = j;
                    sum_variables += nv_[j];
                }
            vars_[i].resize(out);
            const long long external = lp_weight - nv_[i];
            long long d = sum_variables + sum_elements + external;
            d = std::min(d, degree_[i] + external);
            d = std::min(d, remaining - nv_[i]);
            degree_[i] = std::max(d, 0LL);
        }

        merge_indistinguishable(Lp);

        std::size_t out = 0;
        for (int i : Lp)
            if (live(i)) {
                insert(i);
                Lp[out++] = i;
            }
        Lp.resize(out);
        members_[p] = std::move(Lp);
    }

    void absorb(int e)
    {
        status_[e] = absorbed;
        release(members_[e]);
    }

    static void release(std::vector<int>& list) { std::vector<int>().swap(list); }

    /// Variables of L_p with the same element and variable lists are indistinguishable: merge
    /// each into the first of its kind (it is eliminated together with it, mass elimination).
    void merge_indistinguishable(const std::vector<int>& Lp)
    {
        std::vector<std::pair<std::uint64_t, int>> keyed;
        keyed.reserve(Lp.size());
        for (int i : Lp) {
            std::uint64_t h = 0;
            for (int e : elems_[i])
                h += static_cast<std::uint64_t>(e) * 0x9e3779b97f4a7c15ULL + 1;
            for (int j : vars_[i])
                h += static_cast<std::uint64_t>(j) * 0xbf58476d1ce4e5b9ULL + 7;
            keyed.emplace_back(h, i);
        }
        std::sort(keyed.begin(), keyed.end());
        for (std::size_t a = 0; a < keyed.size();) {
            std::size_t b = a + 1;
            while (b < keyed.size() && keyed[b].first == keyed[a].first)
                ++b;
            for (std::size_t x = a; x < b; ++x) {
                const int i = keyed[x].second;
                if (!live(i))
                    continue;
                for (std::size_t y = x + 1; y < b; ++y) {
                    const int j = keyed[y].second;
                    if (live(j) && same_lists(i, j)) {
                        degree_[i] -= nv_[j];  // j no longer counts towards i's external degree
                        nv_[i] += nv_[j];
                        nv_[j] = 0;
                        status_[j] = merged;
                        chain_next_[chain_tail_[i]] = j;
                        chain_tail_[i] = chain_tail_[j];
                        release(vars_[j]);
                        release(elems_[j]);
                    }
                }
            }
            a = b;
        }
    }

    bool same_lists(int i, int j)
    {
        if (elems_[i].size() != elems_[j].size() || vars_[i].size() != vars_[j].size())
            return false;
        const int stamp = ++compare_stamp_;
        for (int e : elems_[i])
            compare_mark_[e] = stamp;
        for (int v : vars_[i])
            compare_mark_[v] = stamp;
        for (int e : elems_[j])
            if (compare_mark_[e] != stamp)
                return false;
        for (int v : vars_[j])
            if (compare_mark_[v] != stamp)
                return false;
        return true;
    }

    int n_;
    long long total_ = 0;
    std::vector<char> status_;
    std::vector<int> nv_;                      // supervariable weights (0: merged)
    std::vector<std::vector<int>> vars_;       // A_i: variable neighbours of variable i
    std::vector<std::vector<int>> elems_;      // E_i: element neighbours of variable i
    std::vector<std::vector<int>> members_;    // L_e: the variables of element e
    std::vector<long long> degree_;            // approximate external degree (in unknowns)
    std::vector<long long> element_weight_;    // |L_e| (in unknowns)
    std::vector<int> head_;                    // degree lists
    std::vector<int> next_, prev_;
    long long min_degree_ = 0;
    std::vector<int> chain_next_, chain_tail_; // variables merged into a principal one
    std::vector<int> mark_;
    int stamp_ = 0;
    std::vector<long long> w_;
    std::vector<int> w_tag_;
    int w_stamp_ = 0;
    std::vector<int> compare_mark_;
    int compare_stamp_ = 0;
};

}  // namespace

Permutation minimum_degree_order(const AdjacencyGraph& graph, const std::vector<int>& weight)
{
    QuotientGraph quotient(graph, weight);
    return quotient.order();
}

}  // namespace fem::direct
