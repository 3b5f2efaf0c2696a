// Chapter 13: barycentric weights, point location, the skinning matrix, the outside rule, normals.
// docs/13_skinning.md
#include "13_skinning/skinning.hpp"

#include "04_tet_jacobians/tet_jacobians.hpp"

#include "common/error.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>

namespace fem::skin {
namespace {

void require_tolerance(double tolerance, const char* where)
{
    if (!(tolerance >= 0.0 && tolerance < 0.5))
        throw Error(str(where, ": the tolerance must be a number in [0, 0.5) (a fraction of a tet's heights), got ",
                        tolerance));
}

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
    require_tolerance(tolerance, "BruteForce");
}

UniformGrid::UniformGrid(const BarycentricFrames& frames, double tolerance, double cells_per_tet)
    : frames_(frames), tolerance_(tolerance)
{
    require_tolerance(tolerance, "UniformGrid");
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
    require_tolerance(tolerance, "AabbTree");
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

// --- Points outside ------------------------------------------------------------------------------

Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c)
{
    // BEGIN EXERCISE 13.5 closest_point_on_triangle #points-outside
    // HINT: The point of triangle abc nearest to p (docs/13_skinning.md#points-outside): it lies in one of seven
    // HINT: Voronoi regions (three corners, three edges, the face). Ericson's Real-Time Collision Detection, §5.1.5
    // HINT: (the docs' references), tells the region from dot products with the edge vectors, without a square
    // HINT: root. The tests place a point in every region.
    const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0.0 && d2 <= 0.0)
        return a;
    const Eigen::Vector3d bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0.0 && d4 <= d3)
        return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
        return a + (d1 / (d1 - d3)) * ab;
    const Eigen::Vector3d cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0.0 && d5 <= d6)
        return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
        return a + (d2 / (d2 - d6)) * ac;
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
        return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
    const double denominator = 1.0 / (va + vb + vc);
    return a + ab * (vb * denominator) + ac * (vc * denominator);
    // END EXERCISE
}

Boundary boundary_faces(const TetMesh& mesh)
{
    // The face opposite corner i, ordered so that its normal points away from corner i for a
    // positively oriented tet.
    static constexpr int opposite[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    std::map<std::array<int, 3>, int> count;
    for (Eigen::Index t = 0; t < mesh.T.rows(); ++t)
        for (const auto& face : opposite) {
            std::array<int, 3> key{mesh.T(t, face[0]), mesh.T(t, face[1]), mesh.T(t, face[2])};
            std::sort(key.begin(), key.end());
            ++count[key];
        }
    Boundary boundary;
    std::vector<std::array<int, 3>> faces;
    for (Eigen::Index t = 0; t < mesh.T.rows(); ++t)
        for (const auto& face : opposite) {
            std::array<int, 3> f{mesh.T(t, face[0]), mesh.T(t, face[1]), mesh.T(t, face[2])}, key = f;
            std::sort(key.begin(), key.end());
            if (count[key] == 1) {
                faces.push_back(f);
                boundary.tet.push_back(static_cast<int>(t));
            }
        }
    boundary.faces.resize(static_cast<Eigen::Index>(faces.size()), 3);
    for (std::size_t k = 0; k < faces.size(); ++k)
        for (int i = 0; i < 3; ++i)
            boundary.faces(static_cast<Eigen::Index>(k), i) = faces[k][i];
    return boundary;
}

Nearest nearest_boundary_tet(const TetMesh& mesh, const Boundary& boundary, const Eigen::Vector3d& p)
{
    Nearest nearest{-1, std::numeric_limits<double>::infinity()};
    for (Eigen::Index f = 0; f < boundary.faces.rows(); ++f) {
        const Eigen::Vector3d a = mesh.V.row(boundary.faces(f, 0)).transpose(), b = mesh.V.row(boundary.faces(f, 1)).transpose(),
                              c = mesh.V.row(boundary.faces(f, 2)).transpose();
        // A face whose bounding box is no nearer than the best so far cannot be nearer itself.
        const Eigen::Vector3d outside_box = (a.cwiseMin(b).cwiseMin(c) - p).cwiseMax(p - a.cwiseMax(b).cwiseMax(c)).cwiseMax(0.0);
        if (outside_box.norm() >= nearest.distance)
            continue;
        const double distance = (p - closest_point_on_triangle(p, a, b, c)).norm();
        if (distance < nearest.distance)
            nearest = Nearest{boundary.tet[f], distance};
    }
    return nearest;
}

// --- The skin ----------------------------------------------------------------------------------

double Skin::largest_outside_distance() const
{
    double largest = 0.0;
    for (const OutsidePoint& o : outside)
        largest = std::max(largest, o.distance);
    return largest;
}

sparse::CsrMatrix skinning_matrix(const TetMesh& coarse, const std::vector<int>& tet,
                                  const Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>& phi)
{
    if (static_cast<Eigen::Index>(tet.size()) != phi.rows())
        throw Error(str("skinning_matrix: ", tet.size(), " tets for ", phi.rows(), " rows of weights; give one of each per surface vertex"));
    for (std::size_t s = 0; s < tet.size(); ++s)
        if (tet[s] < 0 || tet[s] >= coarse.T.rows())
            throw Error(str("skinning_matrix: surface vertex ", s, " refers to tet ", tet[s], "; the coarse mesh has ",
                            coarse.T.rows(), " (numbered from 0)"));
    // BEGIN EXERCISE 13.4 skinning_matrix #the-skinning-matrix
    // HINT: W of docs/13_skinning.md#the-skinning-matrix, #V_skin × #V_sim (not three times either: the notes'
    // HINT: slip): row s holds phi.row(s) in the columns of the corners of tet tet[s] (coarse.T). Build it from
    // HINT: chapter 07's triplets (sparse::CooMatrix: rows, cols, add) and sparse::coo_to_csr, which sorts each
    // HINT: row's columns. A zero weight stays a stored entry: four a row.
    sparse::CooMatrix W;
    W.rows = static_cast<int>(tet.size());
    W.cols = static_cast<int>(coarse.V.rows());
    for (std::size_t s = 0; s < tet.size(); ++s)
        for (int i = 0; i < 4; ++i)
            W.add(static_cast<int>(s), coarse.T(tet[s], i), phi(static_cast<Eigen::Index>(s), i));
    return sparse::coo_to_csr(W);
    // END EXERCISE
}

Skin build_skin(const TetMesh& coarse, const TriMesh& surface, const SkinOptions& options)
{
    if (surface.V.rows() == 0 || surface.F.rows() == 0)
        throw Error(str("the surface to skin is empty (", surface.V.rows(), " vertices, ", surface.F.rows(),
                        " triangles); give a triangle mesh with at least one triangle"));
    validate(surface, "the surface to skin");
    require_tolerance(options.tolerance, "build_skin");
    if (!(options.max_outside_distance >= 0.0 && std::isfinite(options.max_outside_distance)))
        throw Error(str("build_skin: max_outside_distance must be a finite number ≥ 0, got ", options.max_outside_distance));
    const BarycentricFrames frames(coarse);
    const auto locator = make_locator(options.method, frames, options.tolerance);

    Skin skin;
    skin.surface = surface;
    const Eigen::Index n = surface.V.rows();
    skin.tet.resize(n);
    Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> phi(n, 4);
    Boundary boundary;  // built on the first vertex outside
    for (Eigen::Index s = 0; s < n; ++s) {
        const Eigen::Vector3d p = surface.V.row(s).transpose();
        Location found = locator->locate(p);
        if (found.tet < 0) {
            if (boundary.faces.rows() == 0)
                boundary = boundary_faces(frames.mesh());
            const Nearest nearest = nearest_boundary_tet(frames.mesh(), boundary, p);
            const double relative = nearest.distance / frames.longest_edge(nearest.tet);
            if (relative > options.max_outside_distance)
                throw Error(str("surface vertex ", s, " at (", p.x(), ", ", p.y(), ", ", p.z(), ") lies ", nearest.distance,
                                " outside the coarse mesh, ", relative, " times the longest edge of its nearest tet ",
                                nearest.tet, "; the outside rule extrapolates at most ", options.max_outside_distance,
                                " times (SkinOptions::max_outside_distance): enlarge the coarse mesh or raise the limit"));
            found = Location{nearest.tet, frames.weights(nearest.tet, p)};
            skin.outside.push_back(OutsidePoint{static_cast<int>(s), nearest.tet, nearest.distance, relative});
        }
        skin.tet[s] = found.tet;
        phi.row(s) = found.phi.transpose();
    }
    skin.W = skinning_matrix(frames.mesh(), skin.tet, phi);
    return skin;
}

MatrixX3d skinned_positions(const sparse::CsrMatrix& W, const MatrixX3d& Q)
{
    if (Q.rows() != W.cols)
        throw Error(str("skinned_positions: ", Q.rows(), " coarse positions for a skinning matrix of ", W.cols,
                        " columns; give one row per coarse vertex"));
    (void)sparse::view(W);  // checks the array sizes
    MatrixX3d x(W.rows, 3);
    // BEGIN EXERCISE 13.7 skinned_positions #the-skinned-surface
    // HINT: x = W Q (docs/13_skinning.md#the-skinned-surface): row s of x is the weighted sum of the rows of Q
    // HINT: that row s of W names. W is CSR (W.IA row offsets, W.JA columns, W.A values); x is sized. Read W once
    // HINT: for all three coordinates, not once per column (why: docs/13_skinning.md#making-it-fast).
    for (int s = 0; s < W.rows; ++s) {
        Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
        for (int k = W.IA[s]; k < W.IA[s + 1]; ++k)
            sum += W.A[k] * Q.row(W.JA[k]);
        x.row(s) = sum;
    }
    // END EXERCISE
    return x;
}

MatrixX3d vertex_normals(const MatrixX3i& F, const MatrixX3d& x)
{
    MatrixX3d normals = MatrixX3d::Zero(x.rows(), 3);
    for (Eigen::Index f = 0; f < F.rows(); ++f)
        for (int i = 0; i < 3; ++i)
            if (F(f, i) < 0 || F(f, i) >= x.rows())
                throw Error(str("vertex_normals: triangle ", f, " refers to vertex ", F(f, i), "; there are ", x.rows()));
    // BEGIN EXERCISE 13.6 vertex_normals #normals
    // HINT: Area-weighted unit vertex normals of the deformed surface x, in `normals`, zeroed above
    // HINT: (docs/13_skinning.md#normals): each triangle adds its normal, scaled by its area and oriented by its
    // HINT: corner order, to its three corners. A vertex in no triangle keeps a zero row (divide by no zero).
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
        const Eigen::Vector3d a = x.row(F(f, 0)), b = x.row(F(f, 1)), c = x.row(F(f, 2));
        const Eigen::RowVector3d n = (b - a).cross(c - a).transpose();
        for (int i = 0; i < 3; ++i)
            normals.row(F(f, i)) += n;
    }
    for (Eigen::Index v = 0; v < normals.rows(); ++v) {
        const double length = normals.row(v).norm();
        if (length > 0.0)
            normals.row(v) /= length;
    }
    // END EXERCISE
    return normals;
}

io::MeshData skin_frame(const Skin& skin, const MatrixX3d& Q)
{
    const MatrixX3d x = skinned_positions(skin.W, Q);
    io::MeshData frame = io::displaced_mesh(skin.surface.V, MatrixXiR(skin.surface.F), x - skin.surface.V);
    frame.point_data.push_back(io::Field{"normal", vertex_normals(skin.surface.F, x)});
    return frame;
}

// --- Meshes for skinning ---------------------------------------------------------------------------

double winding_number(const TriMesh& surface, const Eigen::Vector3d& p)
{
    double total = 0.0;
    for (Eigen::Index f = 0; f < surface.F.rows(); ++f) {
        const Eigen::Vector3d a = surface.V.row(surface.F(f, 0)).transpose() - p,
                              b = surface.V.row(surface.F(f, 1)).transpose() - p,
                              c = surface.V.row(surface.F(f, 2)).transpose() - p;
        const double la = a.norm(), lb = b.norm(), lc = c.norm();
        const double numerator = a.dot(b.cross(c));
        const double denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        total += 2.0 * std::atan2(numerator, denominator);
    }
    return total / (4.0 * std::numbers::pi);
}

TetMesh enclosing_lattice(const TriMesh& surface, int cells)
{
    if (cells < 1)
        throw Error(str("enclosing_lattice: cells must be ≥ 1, got ", cells));
    validate(surface, "the surface to enclose");
    const Eigen::Vector3d low = surface.V.colwise().minCoeff().transpose(), high = surface.V.colwise().maxCoeff().transpose();
    const double side = (high - low).maxCoeff() / cells;
    // Cubes of one side; the lattice centred on the surface's box, one cube wider than needed where
    // the box is not a whole number of cubes.
    Eigen::Vector3i n;
    for (int c = 0; c < 3; ++c)
        n[c] = std::max(1, static_cast<int>(std::ceil((high[c] - low[c]) / side * (1.0 + 1e-9))));
    const Eigen::Vector3d origin = 0.5 * (low + high) - 0.5 * side * n.cast<double>();
    TetMesh lattice = box_mesh(n[0], n[1], n[2], side * n.cast<double>());
    lattice.V.rowwise() += origin.transpose();

    const auto cube_of = [&](const Eigen::Vector3d& p) {
        Eigen::Vector3i cube;
        for (int c = 0; c < 3; ++c)
            cube[c] = std::clamp(static_cast<int>(std::floor((p[c] - origin[c]) / side)), 0, n[c] - 1);
        return cube;
    };
    std::vector<char> keep(static_cast<std::size_t>(n[0] * n[1] * n[2]), 0);
    const auto index = [&](int i, int j, int k) { return i + std::size_t(n[0]) * (j + std::size_t(n[1]) * k); };
    for (Eigen::Index f = 0; f < surface.F.rows(); ++f) {
        Eigen::Vector3d a = surface.V.row(surface.F(f, 0)).transpose(), b = a;
        for (int i = 1; i < 3; ++i) {
            a = a.cwiseMin(surface.V.row(surface.F(f, i)).transpose());
            b = b.cwiseMax(surface.V.row(surface.F(f, i)).transpose());
        }
        const Eigen::Vector3i from = cube_of(a), to = cube_of(b);
        for (int k = from[2]; k <= to[2]; ++k)
            for (int j = from[1]; j <= to[1]; ++j)
                for (int i = from[0]; i <= to[0]; ++i)
                    keep[index(i, j, k)] = 1;
    }
    for (int k = 0; k < n[2]; ++k)
        for (int j = 0; j < n[1]; ++j)
            for (int i = 0; i < n[0]; ++i)
                if (!keep[index(i, j, k)]) {
                    const Eigen::Vector3d centre = origin + side * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
                    keep[index(i, j, k)] = winding_number(surface, centre) > 0.5;
                }
    // box_mesh numbers cube (i, j, k)'s six tets 6c … 6c + 5, c = i + nx (j + ny k).
    std::vector<int> renumber(lattice.V.rows(), -1);
    std::vector<std::array<int, 4>> tets;
    for (std::size_t c = 0; c < keep.size(); ++c)
        if (keep[c])
            for (int t = 6 * static_cast<int>(c); t < 6 * static_cast<int>(c) + 6; ++t)
                tets.push_back({lattice.T(t, 0), lattice.T(t, 1), lattice.T(t, 2), lattice.T(t, 3)});
    TetMesh kept;
    int used = 0;
    for (const auto& t : tets)
        for (int v : t)
            if (renumber[v] < 0)
                renumber[v] = used++;
    kept.V.resize(used, 3);
    for (Eigen::Index v = 0; v < lattice.V.rows(); ++v)
        if (renumber[v] >= 0)
            kept.V.row(renumber[v]) = lattice.V.row(v);
    kept.T.resize(static_cast<Eigen::Index>(tets.size()), 4);
    for (std::size_t t = 0; t < tets.size(); ++t)
        for (int i = 0; i < 4; ++i)
            kept.T(static_cast<Eigen::Index>(t), i) = renumber[tets[t][i]];
    return kept;
}

TriMesh midpoint_subdivision(const TriMesh& surface, int levels)
{
    if (levels < 0)
        throw Error(str("midpoint_subdivision: levels must be ≥ 0, got ", levels));
    TriMesh mesh = surface;
    for (int level = 0; level < levels; ++level) {
        std::map<std::pair<int, int>, int> midpoint;
        std::vector<Eigen::RowVector3d> points;
        for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
            points.push_back(mesh.V.row(v));
        const auto middle = [&](int a, int b) {
            const auto key = std::minmax(a, b);
            const auto [it, added] = midpoint.try_emplace(key, static_cast<int>(points.size()));
            if (added)
                points.push_back(0.5 * (mesh.V.row(a) + mesh.V.row(b)));
            return it->second;
        };
        MatrixX3i F(4 * mesh.F.rows(), 3);
        for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
            const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
            const int ab = middle(a, b), bc = middle(b, c), ca = middle(c, a);
            F.row(4 * f) << a, ab, ca;
            F.row(4 * f + 1) << ab, b, bc;
            F.row(4 * f + 2) << ca, bc, c;
            F.row(4 * f + 3) << ab, bc, ca;
        }
        MatrixX3d V(static_cast<Eigen::Index>(points.size()), 3);
        for (std::size_t v = 0; v < points.size(); ++v)
            V.row(static_cast<Eigen::Index>(v)) = points[v];
        mesh = TriMesh{V, F};
    }
    return mesh;
}

}  // namespace fem::skin
