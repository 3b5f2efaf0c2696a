// Chapter 15: the surface primitives of a tet mesh and the broad phase of self-contact, three ways.
// docs/15_body_contact.md#bodies-against-bodies-and-self-contact
#include "15_body_contact/broad_phase.hpp"

#include "13_skinning/skinning.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <unordered_map>
#include <utility>

namespace fem::contact {
namespace {

using BoundingBox = Eigen::Matrix<double, 2, 3>;

/// The swept boxes of the primitives whose vertices are the rows of items (1, 2 or 3 columns).
template <class Items>
std::vector<BoundingBox> swept_boxes(const Items& items, const MatrixX3d& start, const MatrixX3d& end)
{
    std::vector<BoundingBox> boxes(static_cast<std::size_t>(items.rows()));
    for (Eigen::Index k = 0; k < items.rows(); ++k) {
        BoundingBox& box = boxes[static_cast<std::size_t>(k)];
        box.row(0) = start.row(items(k, 0)).cwiseMin(end.row(items(k, 0)));
        box.row(1) = start.row(items(k, 0)).cwiseMax(end.row(items(k, 0)));
        for (Eigen::Index c = 1; c < items.cols(); ++c)
            for (const MatrixX3d* x : {&start, &end}) {
                box.row(0) = box.row(0).cwiseMin(x->row(items(k, c)));
                box.row(1) = box.row(1).cwiseMax(x->row(items(k, c)));
            }
    }
    return boxes;
}

/// The boxes of both kinds of pairs, the first of each grown by the inflation.
struct SweptBoxes {
    std::vector<BoundingBox> vertices, edges, triangles, grown_vertices, grown_edges;
};

SweptBoxes checked_boxes(const SurfacePrimitives& surface, const MatrixX3d& start, const MatrixX3d& end,
                         double inflation)
{
    if (start.rows() != end.rows())
        throw Error(str("broad phase: start and end positions need one row per vertex, got ", start.rows(), " and ",
                        end.rows()));
    if (!start.allFinite() || !end.allFinite())
        throw Error("broad phase: a start or end position is not finite");
    if (!(inflation >= 0.0 && std::isfinite(inflation)))
        throw Error(str("broad phase: the inflation r must be a finite number >= 0 [m], got ", inflation));
    for (int v : surface.vertices)
        if (v < 0 || v >= start.rows())
            throw Error(str("broad phase: surface vertex ", v, " is outside the ", start.rows(), " positions given"));
    const Eigen::Map<const Eigen::VectorXi> vertices(surface.vertices.data(),
                                                     static_cast<Eigen::Index>(surface.vertices.size()));
    SweptBoxes boxes{swept_boxes(vertices, start, end), swept_boxes(surface.edges, start, end),
                     swept_boxes(surface.triangles, start, end), {}, {}};
    const auto grown = [&](std::vector<BoundingBox> list) {
        for (BoundingBox& box : list) {
            box.row(0).array() -= inflation;
            box.row(1).array() += inflation;
        }
        return list;
    };
    boxes.grown_vertices = grown(boxes.vertices);
    boxes.grown_edges = grown(boxes.edges);
    return boxes;
}

/// Whether two boxes meet (touching counts): skin::boxes_meeting's test.
bool meet(const BoundingBox& a, const BoundingBox& b)
{
    return !((a.row(0).array() > b.row(1).array()).any() || (a.row(1).array() < b.row(0).array()).any());
}

bool shares_vertex(const SurfacePrimitives& surface, int vertex, int triangle)
{
    return (surface.triangles.row(triangle).array() == vertex).any();
}

bool share_vertex(const SurfacePrimitives& surface, int a, int b)
{
    const auto ea = surface.edges.row(a), eb = surface.edges.row(b);
    return ea(0) == eb(0) || ea(0) == eb(1) || ea(1) == eb(0) || ea(1) == eb(1);
}

/// The pairs of one search: found(first kind, k) lists the candidates' second primitives (any
/// order, repeats allowed) for vertex k (point_triangle) or edge k (edge_edge); the box test, the
/// shared-vertex exclusion, a < b and the order are applied here, alike for every method.
template <class Found>
CandidatePairs collect(const SurfacePrimitives& surface, const SweptBoxes& boxes, Found found)
{
    CandidatePairs pairs;
    for (std::size_t k = 0; k < surface.vertices.size(); ++k) {
        const int vertex = surface.vertices[k];
        std::vector<int> triangles = found(true, static_cast<int>(k));
        std::sort(triangles.begin(), triangles.end());
        triangles.erase(std::unique(triangles.begin(), triangles.end()), triangles.end());
        for (int t : triangles)
            if (meet(boxes.grown_vertices[k], boxes.triangles[static_cast<std::size_t>(t)]) &&
                !shares_vertex(surface, vertex, t))
                pairs.point_triangle.push_back({vertex, t});
    }
    for (int a = 0; a < static_cast<int>(surface.edges.rows()); ++a) {
        std::vector<int> edges = found(false, a);
        std::sort(edges.begin(), edges.end());
        edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
        for (int b : edges)
            if (b > a &&
                meet(boxes.grown_edges[static_cast<std::size_t>(a)], boxes.edges[static_cast<std::size_t>(b)]) &&
                !share_vertex(surface, a, b))
                pairs.edge_edge.push_back({a, b});
    }
    return pairs;
}

}  // namespace

CandidatePairs brute_force_candidates(const SurfacePrimitives& surface, const MatrixX3d& start, const MatrixX3d& end,
                                      double inflation)
{
    const SweptBoxes boxes = checked_boxes(surface, start, end, inflation);
    std::vector<int> every_triangle(boxes.triangles.size()), every_edge(boxes.edges.size());
    for (std::size_t k = 0; k < every_triangle.size(); ++k)
        every_triangle[k] = static_cast<int>(k);
    for (std::size_t k = 0; k < every_edge.size(); ++k)
        every_edge[k] = static_cast<int>(k);
    return collect(surface, boxes, [&](bool point, int) { return point ? every_triangle : every_edge; });
}

CandidatePairs tree_candidates(const SurfacePrimitives& surface, const MatrixX3d& start, const MatrixX3d& end,
                               double inflation)
{
    const SweptBoxes boxes = checked_boxes(surface, start, end, inflation);
    CandidatePairs pairs;
    // BEGIN EXERCISE 15.5 tree_candidates #broad-phases
    // HINT: Build chapter 13's box tree (skin::box_hierarchy(boxes, 4)) over boxes.triangles and one
    // HINT: over boxes.edges. Then pairs = collect(surface, boxes, found): collect calls found(point, k)
    // HINT: for each surface vertex k (point = true) and each edge k (point = false), and wants the
    // HINT: triangles (edges) whose boxes meet that primitive's grown box, boxes.grown_vertices[k]
    // HINT: (boxes.grown_edges[k]): ask the tree with skin::boxes_meeting(tree, boxes, low, high).
    // HINT: collect itself applies the box test, leaves out pairs that share a vertex, and sorts.
    const skin::BoxHierarchy triangle_tree = skin::box_hierarchy(boxes.triangles, 4);
    const skin::BoxHierarchy edge_tree = skin::box_hierarchy(boxes.edges, 4);
    pairs = collect(surface, boxes, [&](bool point, int k) {
        const BoundingBox& query = point ? boxes.grown_vertices[static_cast<std::size_t>(k)]
                                         : boxes.grown_edges[static_cast<std::size_t>(k)];
        return skin::boxes_meeting(point ? triangle_tree : edge_tree, point ? boxes.triangles : boxes.edges,
                                   query.row(0).transpose(), query.row(1).transpose());
    });
    // END EXERCISE
    return pairs;
}

CandidatePairs hash_candidates(const SurfacePrimitives& surface, const MatrixX3d& start, const MatrixX3d& end,
                               double inflation)
{
    const SweptBoxes boxes = checked_boxes(surface, start, end, inflation);
    // The cell size: the mean longest side of the listed boxes, at least a quarter of the largest.
    double mean = 0.0, largest = 0.0;
    Eigen::RowVector3d origin = Eigen::RowVector3d::Constant(std::numeric_limits<double>::infinity());
    std::size_t listed = 0;
    for (const auto* list : {&boxes.triangles, &boxes.edges, &boxes.grown_vertices, &boxes.grown_edges})
        for (const BoundingBox& box : *list) {
            origin = origin.cwiseMin(box.row(0));
            if (list == &boxes.triangles || list == &boxes.edges) {
                const double side = (box.row(1) - box.row(0)).maxCoeff();
                mean += side;
                largest = std::max(largest, side);
                ++listed;
            }
        }
    if (listed == 0)
        return {};
    const double size = std::max(mean / static_cast<double>(listed), 0.25 * largest);
    const double spacing = size > 0.0 ? size : 1.0;
    const auto cell = [&](double x, int axis) {
        return static_cast<std::int64_t>(std::floor((x - origin[axis]) / spacing));
    };
    // A cell's key: its three indices, 21 bits each (a wrapped index only lists an item in one more
    // cell's bucket: the exact box test removes it again).
    const auto key = [](std::int64_t i, std::int64_t j, std::int64_t k) {
        const std::int64_t mask = (std::int64_t(1) << 21) - 1;
        return (i & mask) | ((j & mask) << 21) | ((k & mask) << 42);
    };
    const auto for_each_cell = [&](const BoundingBox& box, const auto& visit) {
        for (std::int64_t i = cell(box(0, 0), 0); i <= cell(box(1, 0), 0); ++i)
            for (std::int64_t j = cell(box(0, 1), 1); j <= cell(box(1, 1), 1); ++j)
                for (std::int64_t k = cell(box(0, 2), 2); k <= cell(box(1, 2), 2); ++k)
                    visit(key(i, j, k));
    };
    std::unordered_map<std::int64_t, std::vector<int>> triangle_cells, edge_cells;
    for (std::size_t t = 0; t < boxes.triangles.size(); ++t)
        for_each_cell(boxes.triangles[t], [&](std::int64_t c) { triangle_cells[c].push_back(static_cast<int>(t)); });
    for (std::size_t e = 0; e < boxes.edges.size(); ++e)
        for_each_cell(boxes.edges[e], [&](std::int64_t c) { edge_cells[c].push_back(static_cast<int>(e)); });
    return collect(surface, boxes, [&](bool point, int k) {
        const BoundingBox& query = point ? boxes.grown_vertices[static_cast<std::size_t>(k)]
                                         : boxes.grown_edges[static_cast<std::size_t>(k)];
        const auto& cells = point ? triangle_cells : edge_cells;
        std::vector<int> found;
        for_each_cell(query, [&](std::int64_t c) {
            const auto bucket = cells.find(c);
            if (bucket != cells.end())
                found.insert(found.end(), bucket->second.begin(), bucket->second.end());
        });
        return found;
    });
}

}  // namespace fem::contact
