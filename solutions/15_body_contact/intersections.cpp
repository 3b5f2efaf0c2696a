// Chapter 15: the intersection check (intersections.hpp). docs/15_body_contact.md#never-an-intersection
#include "15_body_contact/intersections.hpp"

#include "15_body_contact/pair_barrier.hpp"

#include "13_skinning/skinning.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <array>
#include <set>
#include <cmath>
#include <limits>
#include <vector>

namespace fem::contact {

int certified_orientation(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                          const Eigen::Vector3d& d)
{
    // Shewchuk's orient3d, its first (a-priori) stage: the determinant of the differences from d and
    // the permanent of their magnitudes, which bounds the round-off of the whole computation.
    const Eigen::Vector3d ad = a - d, bd = b - d, cd = c - d;
    const double bc_x = bd.y() * cd.z() - bd.z() * cd.y(), ca_x = cd.y() * ad.z() - cd.z() * ad.y(),
                 ab_x = ad.y() * bd.z() - ad.z() * bd.y();
    const double determinant = ad.x() * bc_x + bd.x() * ca_x + cd.x() * ab_x;
    const double permanent = (std::abs(bd.y() * cd.z()) + std::abs(bd.z() * cd.y())) * std::abs(ad.x()) +
                             (std::abs(cd.y() * ad.z()) + std::abs(cd.z() * ad.y())) * std::abs(bd.x()) +
                             (std::abs(ad.y() * bd.z()) + std::abs(ad.z() * bd.y())) * std::abs(cd.x());
    constexpr double epsilon = std::numeric_limits<double>::epsilon() / 2.0;  // 2⁻⁵³
    const double bound = (7.0 + 56.0 * epsilon) * epsilon * permanent;
    // orient3d(a, b, c, d) in Shewchuk's convention is positive when d is below the plane of a, b, c
    // seen counter-clockwise: the opposite of (b − a) × (c − a) · (d − a).
    if (determinant > bound)
        return -1;
    if (determinant < -bound)
        return 1;
    return 0;
}

namespace {

/// The sign of (b − a) × (c − a) in the plane of coordinates (i, j) of a, b, c (each 3): ±1 when
/// certain (Shewchuk's orient2d bound (3 + 16ε) ε × the permanent), 0 within it.
int certified_orientation_2d(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, int i,
                             int j)
{
    const double left = (a[i] - c[i]) * (b[j] - c[j]), right = (a[j] - c[j]) * (b[i] - c[i]);
    const double determinant = left - right;  // (a − c) × (b − c) = (b − a) × (c − a)
    constexpr double epsilon = std::numeric_limits<double>::epsilon() / 2.0;
    const double bound = (3.0 + 16.0 * epsilon) * epsilon * (std::abs(left) + std::abs(right));
    return determinant > bound ? 1 : determinant < -bound ? -1 : 0;
}

/// Whether the shadows of segment (p, q) and triangle (a, b, c) on the plane of coordinates (i, j)
/// are proven apart: a separating line (the segment's line, or a line of a triangle edge with the
/// segment strictly beyond it) by certified 2D orientations. Apart shadows mean apart in space.
bool shadows_apart(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                   const Eigen::Vector3d& b, const Eigen::Vector3d& c, int i, int j)
{
    const int sa = certified_orientation_2d(p, q, a, i, j), sb = certified_orientation_2d(p, q, b, i, j),
              sc = certified_orientation_2d(p, q, c, i, j);
    if (sa != 0 && sa == sb && sb == sc)
        return true;  // the triangle strictly on one side of the segment's line
    const std::array<const Eigen::Vector3d*, 3> x{&a, &b, &c};
    for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d &from = *x[k], &to = *x[(k + 1) % 3], &third = *x[(k + 2) % 3];
        const int inside = certified_orientation_2d(from, to, third, i, j);
        if (inside != 0 && certified_orientation_2d(from, to, p, i, j) == -inside &&
            certified_orientation_2d(from, to, q, i, j) == -inside)
            return true;  // the segment strictly outside this edge's line
    }
    return false;
}

}  // namespace

bool segment_meets_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b, const Eigen::Vector3d& c)
{
    const int sp = certified_orientation(a, b, c, p), sq = certified_orientation(a, b, c, q);
    if (sp != 0 && sp == sq)
        return false;  // both strictly on one side of the plane
    const int e0 = certified_orientation(p, q, a, b), e1 = certified_orientation(p, q, b, c),
              e2 = certified_orientation(p, q, c, a);
    const bool some_positive = e0 > 0 || e1 > 0 || e2 > 0, some_negative = e0 < 0 || e1 < 0 || e2 < 0;
    if (some_positive && some_negative)
        return false;  // the line strictly outside an edge: apart
    // Undecided in space — a segment in (or within round-off of) the triangle's plane, as on a flat
    // face of a mesh — or truly meeting: apart if the shadows on a coordinate plane are.
    return !(shadows_apart(p, q, a, b, c, 1, 2) || shadows_apart(p, q, a, b, c, 2, 0) ||
             shadows_apart(p, q, a, b, c, 0, 1));
}

EdgeThroughTriangle first_edge_through_triangle(const MatrixX3d& x, const Eigen::MatrixX2i& edges,
                                                const MatrixX3i& triangles, const std::vector<int>& owner)
{
    const Eigen::Index n = x.rows();
    if (!owner.empty() && static_cast<Eigen::Index>(owner.size()) != n)
        throw Error(str("first_edge_through_triangle: ", owner.size(), " owners for ", n, " positions"));
    if (!x.allFinite())
        throw Error("first_edge_through_triangle: a position is not finite");
    if (edges.size() > 0 && (edges.minCoeff() < 0 || edges.maxCoeff() >= n))
        throw Error(str("first_edge_through_triangle: an edge's vertex is outside the ", n, " positions"));
    if (triangles.size() > 0 && (triangles.minCoeff() < 0 || triangles.maxCoeff() >= n))
        throw Error(str("first_edge_through_triangle: a triangle's vertex is outside the ", n, " positions"));
    EdgeThroughTriangle crossing;
    if (edges.rows() == 0 || triangles.rows() == 0)
        return crossing;
    std::vector<Eigen::Matrix<double, 2, 3>> boxes(static_cast<std::size_t>(triangles.rows()));
    for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
        Eigen::Matrix<double, 2, 3>& box = boxes[static_cast<std::size_t>(t)];
        box.row(0) = box.row(1) = x.row(triangles(t, 0));
        for (int k = 1; k < 3; ++k) {
            box.row(0) = box.row(0).cwiseMin(x.row(triangles(t, k)));
            box.row(1) = box.row(1).cwiseMax(x.row(triangles(t, k)));
        }
    }
    const skin::BoxHierarchy tree = skin::box_hierarchy(boxes, 4);
    for (Eigen::Index e = 0; e < edges.rows(); ++e) {
        const int i = edges(e, 0), j = edges(e, 1);
        const Eigen::Vector3d p = x.row(i).transpose(), q = x.row(j).transpose();
        std::vector<int> found = skin::boxes_meeting(tree, boxes, p.cwiseMin(q), p.cwiseMax(q));
        std::sort(found.begin(), found.end());
        for (int t : found) {
            const auto triangle = triangles.row(t);
            if ((triangle.array() == i).any() || (triangle.array() == j).any())
                continue;  // an edge of the triangle, or one meeting it at a corner
            if (!owner.empty() && owner[std::size_t(i)] == owner[std::size_t(triangle(0))])
                continue;  // one owner's own edge and triangle
            if (segment_meets_triangle(p, q, x.row(triangle(0)).transpose(), x.row(triangle(1)).transpose(),
                                       x.row(triangle(2)).transpose()))
                return {static_cast<int>(e), t};
        }
    }
    return crossing;
}

namespace {

/// Whether the distance bound of first_crossing_on_segment proves the primitives of motion apart on
/// the whole of [0, 1] (header).
bool apart_by_distance_bound(PrimitivePair kind, const PrimitiveMotion& motion)
{
    double first_move = 0.0, second_move = 0.0;
    const int split = kind == PrimitivePair::point_triangle ? 1 : 2;
    for (int k = 0; k < 4; ++k) {
        double& side = k < split ? first_move : second_move;
        side = std::max(side, (motion.end.col(k) - motion.start.col(k)).norm());
    }
    const double speed = first_move + second_move;
    const auto distance = [&](double s) { return std::sqrt(squared_distance_at(kind, motion, s)); };
    struct Piece {
        double a, b, d_a, d_b;
    };
    std::vector<Piece> pieces = {{0.0, 1.0, distance(0.0), distance(1.0)}};
    for (int evaluated = 0; !pieces.empty();) {
        const Piece piece = pieces.back();
        pieces.pop_back();
        const double change = speed * (piece.b - piece.a);
        // Round-off of the distances: 10⁻¹² of the sizes compared.
        if (piece.d_a + piece.d_b - change > 1e-12 * (piece.d_a + piece.d_b + change))
            continue;
        if (++evaluated > path_check_pieces || !(piece.d_a > 0.0 && piece.d_b > 0.0))
            return false;
        const double middle = 0.5 * (piece.a + piece.b), d_middle = distance(middle);
        pieces.push_back({middle, piece.b, d_middle, piece.d_b});
        pieces.push_back({piece.a, middle, piece.d_a, d_middle});
    }
    return true;
}

}  // namespace

SegmentCrossing first_crossing_on_segment(const SurfacePrimitives& surface, const CandidatePairs& candidates,
                                          const MatrixX3d& start, const MatrixX3d& end, long long* tested)
{
    if (start.rows() != end.rows())
        throw Error(str("path check: the segment's start has ", start.rows(), " vertices, its end ", end.rows()));
    SegmentCrossing crossing;
    PrimitiveMotion motion;
    const auto meets = [&](PrimitivePair kind, const int (&v)[4]) {
        for (int k = 0; k < 4; ++k) {
            motion.start.col(k) = start.row(v[k]).transpose();
            motion.end.col(k) = end.row(v[k]).transpose();
        }
        if (tested != nullptr)
            ++*tested;
        // Cleared first where it is cheap: every point of a primitive moves at most as far as its
        // farthest vertex, so on [a, b] the distance changes at most M (b − a), M = the first's
        // farthest move + the second's, and stays ≥ (d(a) + d(b) − M (b − a))/2 > 0 when that is
        // positive; [0, 1] is bisected (at most path_check_pieces pieces) until every piece is.
        if (apart_by_distance_bound(kind, motion))
            return false;
        const CcdResult inclusion =
            inclusion_ccd(kind, motion, {.tolerance = path_check_tolerance, .max_boxes = path_check_boxes});
        const CcdResult cubic = cubic_ccd(kind, motion);
        if (!inclusion.collides && !cubic.collides)
            return false;
        crossing.kind = kind;
        std::copy(v, v + 4, crossing.vertices);
        crossing.time = std::min(inclusion.time_of_impact, cubic.time_of_impact);
        crossing.proven = !inclusion.stopped_at_limit || cubic.collides;
        return true;
    };
    for (const auto& [vertex, triangle] : candidates.point_triangle)
        if (meets(PrimitivePair::point_triangle, {vertex, surface.triangles(triangle, 0), surface.triangles(triangle, 1),
                                                  surface.triangles(triangle, 2)}))
            return crossing;
    for (const auto& [first, second] : candidates.edge_edge)
        if (meets(PrimitivePair::edge_edge, {surface.edges(first, 0), surface.edges(first, 1), surface.edges(second, 0),
                                             surface.edges(second, 1)}))
            return crossing;
    return crossing;
}

std::string describe(const EdgeThroughTriangle& crossing, const Eigen::MatrixX2i& edges, const MatrixX3i& triangles)
{
    if (!crossing.found())
        return {};
    const auto t = triangles.row(crossing.triangle);
    return str("edge (", edges(crossing.edge, 0), ", ", edges(crossing.edge, 1), ") meets triangle (", t(0), ", ",
               t(1), ", ", t(2), ")");
}

namespace {

/// The edges of triangles (#F×3), each once, lower index first.
Eigen::MatrixX2i triangle_edges(const MatrixX3i& triangles)
{
    std::set<std::array<int, 2>> unique;
    for (Eigen::Index f = 0; f < triangles.rows(); ++f)
        for (int k = 0; k < 3; ++k) {
            const int i = triangles(f, k), j = triangles(f, (k + 1) % 3);
            unique.insert({std::min(i, j), std::max(i, j)});
        }
    Eigen::MatrixX2i edges(static_cast<Eigen::Index>(unique.size()), 2);
    Eigen::Index row = 0;
    for (const auto& [i, j] : unique)
        edges.row(row++) << i, j;
    return edges;
}

}  // namespace

std::string first_crossing(const MatrixX3d& x, const SurfacePrimitives& surface, const TriMesh& other)
{
    // One array: the body's vertices, then other's, its indices offset by #V.
    const int n = static_cast<int>(x.rows());
    MatrixX3d both(x.rows() + other.V.rows(), 3);
    both << x, other.V;
    const MatrixX3i other_triangles = (other.F.array() + n).matrix();
    const Eigen::MatrixX2i other_edges = triangle_edges(other_triangles);
    const EdgeThroughTriangle body_edge = first_edge_through_triangle(both, surface.edges, other_triangles);
    if (body_edge.found())
        return "body " + describe(body_edge, surface.edges, other_triangles);
    const EdgeThroughTriangle other_edge = first_edge_through_triangle(both, other_edges, surface.triangles);
    if (other_edge.found()) {
        const std::string text = describe(other_edge, other_edges, surface.triangles);
        return text.substr(0, text.find("triangle")) + "body " + text.substr(text.find("triangle"));
    }
    return {};
}

IntersectionCheck::IntersectionCheck(const TetMesh& mesh, const std::vector<std::shared_ptr<const Obstacle>>& obstacles,
                                     bool self_contact)
    : surface_(surface_primitives(mesh)), self_contact_(self_contact)
{
    for (std::size_t o = 0; o < obstacles.size(); ++o) {
        const ObstacleFeatures features = obstacles[o]->local_features();
        if (features.edges.rows() > 0 || features.corners.rows() > 0)
            obstacles_.emplace_back(static_cast<int>(o), obstacles[o]);
    }
}

void IntersectionCheck::require_none(const MatrixX3d& x, double time) const
{
    if (self_contact_) {
        const EdgeThroughTriangle crossing = first_edge_through_triangle(x, surface_.edges, surface_.triangles);
        if (crossing.found())
            throw Error(str("intersection check at t = ", time, " s: the body's ",
                            describe(crossing, surface_.edges, surface_.triangles)));
    }
    if (obstacles_.empty())
        return;
    const Eigen::Vector3d low = x.colwise().minCoeff(), high = x.colwise().maxCoeff();
    const std::array<double, 6> around{low.x(), high.x(), low.y(), high.y(), low.z(), high.z()};
    for (const auto& [index, obstacle] : obstacles_) {
        const std::string crossing = first_crossing(x, surface_, obstacle->surface_at(around, time));
        if (!crossing.empty())
            throw Error(str("intersection check at t = ", time, " s: obstacle ", index, " (", obstacle->name(),
                            ") and the body: ", crossing));
    }
}

}  // namespace fem::contact
