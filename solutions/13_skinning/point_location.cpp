// Chapter 13: barycentric weights and point location (brute force, a uniform grid, an AABB tree).
// docs/13_skinning.md#barycentric-weights, docs/13_skinning.md#point-location
#include "13_skinning/skinning.hpp"

#include "04_tet_jacobians/tet_jacobians.hpp"

#include "common/error.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

namespace fem::skin {
namespace {

/// True when every weight is ≥ −tolerance.
bool contains(const Eigen::Vector4d& phi, double tolerance)
{
    return phi.minCoeff() >= -tolerance;
}

/// The box of tet t grown by 3 × tolerance × its longest edge ℓ on every side. The points the
/// tolerance admits, {φᵢ ≥ −tolerance}, form the tet scaled by 1 + 4·tolerance about its centroid c
/// (φᵢ(c + s(X − c)) = ¼ + s(φᵢ(X) − ¼)), which reaches 4·tolerance·|Xᵢ − c| beyond corner i, and
/// |Xᵢ − c| = |Σⱼ (Xᵢ − Xⱼ)| / 4 ≤ ¾ ℓ: up to 3·tolerance·ℓ (a needle tet comes close), three
/// times the reach beyond a face.
Eigen::Matrix<double, 2, 3> padded_box(const BarycentricFrames& frames, int t, double tolerance)
{
    Eigen::Matrix<double, 2, 3> box = frames.box(t);
    const double pad = 3.0 * tolerance * frames.longest_edge(t);
    box.row(0).array() -= pad;
    box.row(1).array() += pad;
    return box;
}

/// Keeps the lower-numbered of the tet found so far and candidate t when t contains p.
void keep_lowest(const BarycentricFrames& frames, int t, const Eigen::Vector3d& p, double tolerance, Location& best)
{
    if (best.tet >= 0 && t >= best.tet)
        return;
    const Eigen::Vector4d phi = frames.weights(t, p);
    if (contains(phi, tolerance))
        best = Location{t, phi};
}

}  // namespace

void require_location_tolerance(double tolerance, const char* where)
{
    if (!(tolerance >= 0.0 && tolerance < 0.5))
        throw Error(str(where, ": the tolerance must be a number in [0, 0.5) (a fraction of a tet's heights), got ",
                        tolerance));
}

// --- Barycentric weights ---------------------------------------------------------------------

BarycentricFrames::BarycentricFrames(const TetMesh& mesh, const std::string& what) : mesh_(mesh)
{
    if (mesh_.T.rows() == 0)
        throw Error(str("the ", what, " has no tetrahedra; a skin needs at least one"));
    validate(mesh_, what, Inverted::reject);
    const Eigen::Index n = mesh_.T.rows();
    inverse_.resize(n);
    origin_.resize(n, 3);
    longest_edge_.resize(n);
    for (Eigen::Index t = 0; t < n; ++t) {
        const tet::TetVertices X = tet::tet_vertices(mesh_, mesh_.V, static_cast<int>(t));
        inverse_[t] = tet::edge_matrix(X).inverse();
        origin_.row(t) = X.row(0);
        double longest = 0.0;
        for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j)
                longest = std::max(longest, (X.row(i) - X.row(j)).norm());
        longest_edge_[t] = longest;
    }
}

Eigen::Vector4d BarycentricFrames::weights(int t, const Eigen::Vector3d& p) const
{
    // BEGIN EXERCISE 13.1 barycentric_weights #barycentric-weights
    // HINT: The four barycentric weights (φ₀, φ₁, φ₂, φ₃) of p in tet t (docs/13_skinning.md#barycentric-weights),
    // HINT: from what the constructor prepared: inverse_[t] (T⁻¹, T's columns the edges from corner 0) and
    // HINT: origin_.row(t) (corner 0, a row). Outside the tet a weight is negative: keep it (no clamping).
    const Eigen::Vector3d tail = inverse_[t] * (p - origin_.row(t).transpose());
    Eigen::Vector4d phi;
    phi << 1.0 - tail.sum(), tail;
    return phi;
    // END EXERCISE
}

Eigen::Matrix<double, 2, 3> BarycentricFrames::box(int t) const
{
    Eigen::Matrix<double, 2, 3> box;
    box.row(0) = mesh_.V.row(mesh_.T(t, 0));
    box.row(1) = box.row(0);
    for (int i = 1; i < 4; ++i) {
        box.row(0) = box.row(0).cwiseMin(mesh_.V.row(mesh_.T(t, i)));
        box.row(1) = box.row(1).cwiseMax(mesh_.V.row(mesh_.T(t, i)));
    }
    return box;
}

// --- Point location ----------------------------------------------------------------------------

std::string method_name(LocateMethod method)
{
    switch (method) {
    case LocateMethod::brute_force: return "brute-force";
    case LocateMethod::grid: return "grid";
    case LocateMethod::tree: return "tree";
    }
    return "?";
}

LocateMethod parse_method(const std::string& name)
{
    for (LocateMethod m : {LocateMethod::brute_force, LocateMethod::grid, LocateMethod::tree})
        if (method_name(m) == name)
            return m;
    throw Error(str("unknown point-location method '", name, "'; use brute-force, grid or tree"));
}

Location locate_brute_force(const BarycentricFrames& frames, const Eigen::Vector3d& p, double tolerance)
{
    for (int t = 0; t < frames.tets(); ++t) {
        const Eigen::Vector4d phi = frames.weights(t, p);
        if (contains(phi, tolerance))
            return Location{t, phi};
    }
    return Location{};
}

BruteForce::BruteForce(const BarycentricFrames& frames, double tolerance) : frames_(frames), tolerance_(tolerance)
{
    require_location_tolerance(tolerance, "BruteForce");
}

UniformGrid::UniformGrid(const BarycentricFrames& frames, double tolerance, double cells_per_tet)
    : frames_(frames), tolerance_(tolerance)
{
    require_location_tolerance(tolerance, "UniformGrid");
    if (!(cells_per_tet > 0.0 && std::isfinite(cells_per_tet)))
        throw Error(str("UniformGrid: cells_per_tet must be a finite number > 0, got ", cells_per_tet));
    const Eigen::Index n = frames.tets();
    std::vector<Eigen::Matrix<double, 2, 3>> boxes(n);
    Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), high = -low;
    for (Eigen::Index t = 0; t < n; ++t) {
        boxes[t] = padded_box(frames, static_cast<int>(t), tolerance);
        low = low.cwiseMin(boxes[t].row(0).transpose());
        high = high.cwiseMax(boxes[t].row(1).transpose());
    }
    // Cubic cells, about cells_per_tet × #T of them over the box (at least one along each side).
    const Eigen::Vector3d extent = (high - low).cwiseMax(1e-300);
    const double side = std::cbrt(extent.prod() / (cells_per_tet * double(n)));
    for (int c = 0; c < 3; ++c)
        dims_[c] = std::clamp(static_cast<int>(std::ceil(extent[c] / side)), 1, 1024);
    origin_ = low;
    cell_size_ = extent.cwiseQuotient(dims_.cast<double>());
    // BEGIN EXERCISE 13.2 uniform_grid #a-uniform-grid
    // HINT: The grid's cell lists in CSR form (docs/13_skinning.md#a-uniform-grid): cell c's tets are
    // HINT: tets_[offsets_[c] … offsets_[c+1]−1], every tet whose padded box boxes[t] meets the cell, in ascending
    // HINT: t (locate() stops at the first hit). The construction is chapter 07's triplets-to-CSR
    // HINT: (docs/07_sparse_storage.md#from-triplets-to-csr). cell_of(point) gives a point's cell (i, j, k),
    // HINT: clamped to the grid; number the cells as locate() does.
    const std::size_t cells = std::size_t(dims_[0]) * dims_[1] * dims_[2];
    const auto cell_index = [&](int i, int j, int k) { return i + dims_[0] * (j + std::size_t(dims_[1]) * k); };
    const auto for_cells_of = [&](Eigen::Index t, const auto& visit) {
        const Eigen::Vector3i a = cell_of(boxes[t].row(0).transpose()), b = cell_of(boxes[t].row(1).transpose());
        for (int k = a[2]; k <= b[2]; ++k)
            for (int j = a[1]; j <= b[1]; ++j)
                for (int i = a[0]; i <= b[0]; ++i)
                    visit(cell_index(i, j, k));
    };
    offsets_.assign(cells + 1, 0);
    for (Eigen::Index t = 0; t < n; ++t)
        for_cells_of(t, [&](std::size_t c) { ++offsets_[c + 1]; });
    std::partial_sum(offsets_.begin(), offsets_.end(), offsets_.begin());
    tets_.resize(offsets_.back());
    std::vector<int> next(offsets_.begin(), offsets_.end() - 1);
    for (Eigen::Index t = 0; t < n; ++t)
        for_cells_of(t, [&](std::size_t c) { tets_[next[c]++] = static_cast<int>(t); });
    // END EXERCISE
}

Eigen::Vector3i UniformGrid::cell_of(const Eigen::Vector3d& p) const
{
    Eigen::Vector3i cell;
    for (int c = 0; c < 3; ++c) {
        const double at = std::floor((p[c] - origin_[c]) / cell_size_[c]);
        cell[c] = static_cast<int>(std::clamp(at, 0.0, double(dims_[c] - 1)));
    }
    return cell;
}

Location UniformGrid::locate(const Eigen::Vector3d& p) const
{
    const Eigen::Vector3i cell = cell_of(p);
    const std::size_t c = cell[0] + dims_[0] * (cell[1] + std::size_t(dims_[1]) * cell[2]);
    Location best;
    // The cell's tets are listed in ascending order: the first that contains p is the lowest.
    for (int k = offsets_[c]; k < offsets_[c + 1] && best.tet < 0; ++k)
        keep_lowest(frames_, tets_[k], p, tolerance_, best);
    return best;
}

double UniformGrid::mean_tets_per_cell() const
{
    return double(tets_.size()) / double(offsets_.size() - 1);
}

AabbTree::AabbTree(const BarycentricFrames& frames, double tolerance, int leaf_size)
    : frames_(frames), tolerance_(tolerance)
{
    require_location_tolerance(tolerance, "AabbTree");
    if (leaf_size < 1)
        throw Error(str("AabbTree: leaf_size must be ≥ 1, got ", leaf_size));
    boxes_.resize(frames.tets());
    for (Eigen::Index t = 0; t < frames.tets(); ++t)
        boxes_[t] = padded_box(frames, static_cast<int>(t), tolerance);
    BoxHierarchy tree = box_hierarchy(boxes_, leaf_size);
    nodes_ = std::move(tree.nodes);
    tets_ = std::move(tree.items);
}

namespace {

/// The node over items[first … first + count − 1] and, below it, its subtree (box_hierarchy).
int build_node(BoxHierarchy& tree, int first, int count, int leaf_size,
               const std::vector<Eigen::Matrix<double, 2, 3>>& boxes, const std::vector<Eigen::Vector3d>& centres)
{
    BoxNode node;
    node.low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    node.high = -node.low;
    for (int k = first; k < first + count; ++k) {
        node.low = node.low.cwiseMin(boxes[tree.items[k]].row(0).transpose());
        node.high = node.high.cwiseMax(boxes[tree.items[k]].row(1).transpose());
    }
    const int index = static_cast<int>(tree.nodes.size());
    tree.nodes.push_back(node);
    if (count <= leaf_size) {
        tree.nodes[index].first = first;
        tree.nodes[index].count = count;
        return index;
    }
    int axis = 0;
    (node.high - node.low).maxCoeff(&axis);
    const auto begin = tree.items.begin() + first, middle = begin + count / 2, end = begin + count;
    std::nth_element(begin, middle, end, [&](int a, int b) { return centres[a][axis] < centres[b][axis]; });
    const int left = build_node(tree, first, count / 2, leaf_size, boxes, centres);
    const int right = build_node(tree, first + count / 2, count - count / 2, leaf_size, boxes, centres);
    tree.nodes[index].left = left;
    tree.nodes[index].right = right;
    return index;
}

}  // namespace

std::vector<int> boxes_meeting(const BoxHierarchy& tree, const std::vector<Eigen::Matrix<double, 2, 3>>& boxes,
                               const Eigen::Vector3d& low, const Eigen::Vector3d& high)
{
    const auto apart = [&](const Eigen::Vector3d& box_low, const Eigen::Vector3d& box_high) {
        return (box_low.array() > high.array()).any() || (box_high.array() < low.array()).any();
    };
    std::vector<int> found;
    if (tree.nodes.empty())
        return found;
    std::vector<int> stack{0};
    while (!stack.empty()) {
        const BoxNode& node = tree.nodes[static_cast<std::size_t>(stack.back())];
        stack.pop_back();
        if (apart(node.low, node.high))
            continue;
        if (node.left >= 0) {
            stack.push_back(node.left);
            stack.push_back(node.right);
            continue;
        }
        for (int k = node.first; k < node.first + node.count; ++k) {
            const int item = tree.items[static_cast<std::size_t>(k)];
            const Eigen::Matrix<double, 2, 3>& box = boxes[static_cast<std::size_t>(item)];
            if (!apart(box.row(0).transpose(), box.row(1).transpose()))
                found.push_back(item);
        }
    }
    return found;
}

BoxHierarchy box_hierarchy(const std::vector<Eigen::Matrix<double, 2, 3>>& boxes, int leaf_size)
{
    if (leaf_size < 1)
        throw Error(str("box_hierarchy: leaf_size must be ≥ 1, got ", leaf_size));
    if (boxes.empty())
        throw Error("box_hierarchy: no boxes; give at least one");
    const std::size_t n = boxes.size();
    std::vector<Eigen::Vector3d> centres(n);
    for (std::size_t i = 0; i < n; ++i)
        centres[i] = 0.5 * (boxes[i].row(0) + boxes[i].row(1)).transpose();
    BoxHierarchy tree;
    tree.items.resize(n);
    std::iota(tree.items.begin(), tree.items.end(), 0);
    tree.nodes.reserve(2 * n / leaf_size + 2);
    build_node(tree, 0, static_cast<int>(n), leaf_size, boxes, centres);
    return tree;
}

Location AabbTree::locate(const Eigen::Vector3d& p) const
{
    Location best;
    // BEGIN EXERCISE 13.3 aabb_tree_locate #an-aabb-tree
    // HINT: The lowest-numbered tet containing p, in `best` (docs/13_skinning.md#an-aabb-tree, #point-location):
    // HINT: visit every node whose box [low, high] holds p, from the root nodes_[0]. A leaf (left < 0) lists
    // HINT: tets_[first … first + count − 1]; keep_lowest(frames_, t, p, tolerance_, best) tests one tet's
    // HINT: weights and keeps the lower number; boxes_[t], the tet's padded box, is a cheaper test first. The depth
    // HINT: is about log₂(#T/4), so a small fixed stack serves.
    std::array<int, 128> stack;
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& node = nodes_[stack[--top]];
        if ((p.array() < node.low.array()).any() || (p.array() > node.high.array()).any())
            continue;
        if (node.left < 0) {
            for (int k = node.first; k < node.first + node.count; ++k) {
                const int t = tets_[k];
                if ((p.transpose().array() >= boxes_[t].row(0).array()).all() &&
                    (p.transpose().array() <= boxes_[t].row(1).array()).all())
                    keep_lowest(frames_, t, p, tolerance_, best);
            }
        } else {
            stack[top++] = node.left;
            stack[top++] = node.right;
        }
    }
    // END EXERCISE
    return best;
}

int AabbTree::depth() const
{
    std::vector<std::pair<int, int>> stack{{0, 1}};
    int deepest = 0;
    while (!stack.empty()) {
        const auto [n, d] = stack.back();
        stack.pop_back();
        deepest = std::max(deepest, d);
        if (nodes_[n].left >= 0) {
            stack.push_back({nodes_[n].left, d + 1});
            stack.push_back({nodes_[n].right, d + 1});
        }
    }
    return deepest;
}

std::unique_ptr<PointLocator> make_locator(LocateMethod method, const BarycentricFrames& frames, double tolerance)
{
    switch (method) {
    case LocateMethod::brute_force: return std::make_unique<BruteForce>(frames, tolerance);
    case LocateMethod::grid: return std::make_unique<UniformGrid>(frames, tolerance);
    case LocateMethod::tree: return std::make_unique<AabbTree>(frames, tolerance);
    }
    throw Error("make_locator: unknown method");
}

}  // namespace fem::skin
