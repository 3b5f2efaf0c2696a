// Chapter 15: a triangle mesh as an obstacle — the distance to its nearest triangle by chapter 13's
// AABB tree, and the same distance sampled on a grid. docs/15_body_contact.md#mesh-obstacles
#include "15_body_contact/mesh_obstacle.hpp"

#include "15_body_contact/distances.hpp"

#include "common/error.hpp"
#include "common/types.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <utility>
#include <vector>

namespace fem::contact {
namespace {

/// The distance from p to the box (rows min and max; 0 inside).
double box_distance(const Eigen::Vector3d& low, const Eigen::Vector3d& high, const Eigen::Vector3d& p)
{
    return (low - p).cwiseMax(p - high).cwiseMax(0.0).norm();
}

/// Each edge of the mesh (as its sorted corner pair) with the triangles on it, each signed by the
/// direction it runs the edge in (+f + 1 from the lower corner to the higher, −f − 1 back).
std::map<std::pair<int, int>, std::vector<int>> edge_sides(const TriMesh& surface)
{
    std::map<std::pair<int, int>, std::vector<int>> sides;
    for (int f = 0; f < static_cast<int>(surface.F.rows()); ++f)
        for (int i = 0; i < 3; ++i) {
            const int a = surface.F(f, i), b = surface.F(f, (i + 1) % 3);
            sides[{std::min(a, b), std::max(a, b)}].push_back(a < b ? f + 1 : -f - 1);
        }
    return sides;
}

/// Whether an edge with these signed triangles (edge_sides) is flat: two triangles whose unit
/// normals n₁, n₂ (the second flipped when both run the edge the same way, that is when one of the
/// two is flipped) have n₁·n₂ ≥ 0 and |n₁ × n₂| ≤ flat_mesh_edge_sine.
bool flat_edge(const TriMesh& surface, const std::vector<int>& faces)
{
    if (faces.size() != 2)
        return false;  // a border edge, or one shared by three or more triangles
    const auto normal = [&](int f) {
        const Eigen::Vector3d a = surface.V.row(surface.F(f, 0)), b = surface.V.row(surface.F(f, 1)),
                              c = surface.V.row(surface.F(f, 2));
        return Eigen::Vector3d((b - a).cross(c - a).normalized());
    };
    // Oriented alike, two neighbours run their edge in opposite directions; else one is flipped.
    const Eigen::Vector3d n0 = normal(std::abs(faces[0]) - 1);
    const Eigen::Vector3d n1 = (faces[0] > 0) == (faces[1] > 0) ? Eigen::Vector3d(-normal(std::abs(faces[1]) - 1))
                                                                 : normal(std::abs(faces[1]) - 1);
    return n0.dot(n1) >= 0.0 && n0.cross(n1).norm() <= flat_mesh_edge_sine;
}

/// The distance from x to the segment from a to b.
double segment_distance(const Eigen::Vector3d& x, const Eigen::Vector3d& a, const Eigen::Vector3d& b)
{
    const Eigen::Vector3d e = b - a;
    const double t = std::clamp((x - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
    return (x - a - t * e).norm();
}

}  // namespace

TrianglePoint closest_triangle_point(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                     const Eigen::Vector3d& c)
{
    const std::array<Eigen::Vector3d, 3> x{a, b, c};
    const int type = static_cast<int>(point_triangle_type(p, a, b, c));
    TrianglePoint closest;
    if (type <= static_cast<int>(PointTriangleType::corner_c)) {  // corner_a, corner_b, corner_c: 0, 1, 2
        closest.feature = TriangleFeature::vertex;
        closest.corner = type;
        closest.point = x[type];
    } else if (type <= static_cast<int>(PointTriangleType::edge_ca)) {  // edge_ab, edge_bc, edge_ca: 3, 4, 5
        const int i = type - static_cast<int>(PointTriangleType::edge_ab);
        const Eigen::Vector3d edge = x[(i + 1) % 3] - x[i];
        closest.feature = TriangleFeature::edge;
        closest.corner = i;
        closest.point = x[i] + ((p - x[i]).dot(edge) / edge.squaredNorm()) * edge;
    } else {
        const Eigen::Vector3d n = (b - a).cross(c - a);
        closest.point = p - ((p - a).dot(n) / n.squaredNorm()) * n;
    }
    return closest;
}

// --- The mesh obstacle ------------------------------------------------------------------------------

MeshObstacle::MeshObstacle(TriMesh surface, double friction, const Eigen::Vector3d& velocity, const std::string& what)
    : Obstacle(velocity, friction), surface_(std::move(surface))
{
    validate(surface_, what);
    boxes_.resize(surface_.F.rows());
    for (Eigen::Index f = 0; f < surface_.F.rows(); ++f) {
        Eigen::Matrix<double, 2, 3>& box = boxes_[f];
        box.row(0) = box.row(1) = surface_.V.row(surface_.F(f, 0));
        for (int k = 1; k < 3; ++k) {
            box.row(0) = box.row(0).cwiseMin(surface_.V.row(surface_.F(f, k)));
            box.row(1) = box.row(1).cwiseMax(surface_.V.row(surface_.F(f, k)));
        }
    }
    tree_ = skin::box_hierarchy(boxes_, 4);
    same_point_ = 1e-7 * (surface_.V.colwise().maxCoeff() - surface_.V.colwise().minCoeff()).norm();

    // The neighbour across each flat edge, then each corner's flat fan: the triangles reached from
    // the corner's triangle by turning about the corner across flat edges.
    const int triangles = static_cast<int>(surface_.F.rows());
    flat_neighbour_.assign(3 * static_cast<std::size_t>(triangles), -1);
    for (const auto& [edge, faces] : edge_sides(surface_)) {
        if (!flat_edge(surface_, faces))
            continue;
        for (int side = 0; side < 2; ++side) {
            const int f = std::abs(faces[side]) - 1, other = std::abs(faces[1 - side]) - 1;
            for (int i = 0; i < 3; ++i) {
                const int a = surface_.F(f, i), b = surface_.F(f, (i + 1) % 3);
                if (std::min(a, b) == edge.first && std::max(a, b) == edge.second)
                    flat_neighbour_[3 * f + i] = other;
            }
        }
    }
    flat_fan_.assign(3 * static_cast<std::size_t>(triangles), {});
    for (int f = 0; f < triangles; ++f)
        for (int k = 0; k < 3; ++k) {
            const int vertex = surface_.F(f, k);
            std::vector<int> fan{f};
            for (std::size_t next = 0; next < fan.size(); ++next) {
                const int g = fan[next];
                const int corner = surface_.F(g, 0) == vertex ? 0 : surface_.F(g, 1) == vertex ? 1 : 2;
                for (int edge : {corner, (corner + 2) % 3}) {  // g's two edges at the vertex
                    const int across = flat_neighbour_[3 * g + edge];
                    if (across >= 0 && std::find(fan.begin(), fan.end(), across) == fan.end())
                        fan.push_back(across);
                }
            }
            flat_fan_[3 * f + k].assign(fan.begin() + 1, fan.end());
        }
}

TrianglePoint MeshObstacle::closest_on(int f, const Eigen::Vector3d& p) const
{
    return closest_triangle_point(p, surface_.V.row(surface_.F(f, 0)).transpose(),
                                  surface_.V.row(surface_.F(f, 1)).transpose(), surface_.V.row(surface_.F(f, 2)).transpose());
}

MeshObstacle::Nearest MeshObstacle::nearest(const Eigen::Vector3d& p) const
{
    Nearest best;
    best.distance = infinity;
    std::array<int, 128> stack;  // a median split keeps the depth near log2(#F / 4): 128 is never reached
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const skin::BoxNode& node = tree_.nodes[stack[--top]];
        if (box_distance(node.low, node.high, p) >= best.distance)
            continue;
        if (node.left < 0) {
            for (int k = node.first; k < node.first + node.count; ++k) {
                const int f = tree_.items[k];
                if (box_distance(boxes_[f].row(0).transpose(), boxes_[f].row(1).transpose(), p) >= best.distance)
                    continue;
                const TrianglePoint closest = closest_on(f, p);
                const double distance = (p - closest.point).norm();
                if (distance < best.distance)
                    best = Nearest{f, closest, distance};
            }
            continue;
        }
        const skin::BoxNode &left = tree_.nodes[node.left], &right = tree_.nodes[node.right];
        const bool left_first = box_distance(left.low, left.high, p) <= box_distance(right.low, right.high, p);
        stack[top++] = left_first ? node.right : node.left;  // the nearer child is popped first
        stack[top++] = left_first ? node.left : node.right;
    }
    return best;
}

MeshObstacle::Nearest MeshObstacle::nearest_brute_force(const Eigen::Vector3d& p) const
{
    Nearest best;
    best.distance = infinity;
    for (Eigen::Index f = 0; f < surface_.F.rows(); ++f) {
        const TrianglePoint closest = closest_on(static_cast<int>(f), p);
        const double distance = (p - closest.point).norm();
        if (distance < best.distance)
            best = Nearest{static_cast<int>(f), closest, distance};
    }
    return best;
}

std::vector<int> MeshObstacle::triangles_meeting(const Eigen::Vector3d& low, const Eigen::Vector3d& high) const
{
    return skin::boxes_meeting(tree_, boxes_, low, high);
}

ObstacleFeatures MeshObstacle::local_features() const
{
    std::vector<std::pair<int, int>> sharp;
    for (const auto& [edge, faces] : edge_sides(surface_))
        if (!flat_edge(surface_, faces))
            sharp.push_back(edge);
    ObstacleFeatures features;
    features.edges.resize(static_cast<Eigen::Index>(sharp.size()), 2);
    std::map<int, int> corner_of;  // mesh vertex → corner row
    for (std::size_t e = 0; e < sharp.size(); ++e)
        for (int end = 0; end < 2; ++end) {
            const int vertex = end == 0 ? sharp[e].first : sharp[e].second;
            const auto [slot, fresh] = corner_of.try_emplace(vertex, static_cast<int>(corner_of.size()));
            features.edges(static_cast<Eigen::Index>(e), end) = slot->second;
        }
    features.corners.resize(static_cast<Eigen::Index>(corner_of.size()), 3);
    for (const auto& [vertex, row] : corner_of)
        features.corners.row(row) = surface_.V.row(vertex);
    return features;
}

bool MeshObstacle::crosses(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1) const
{
    const auto volume = [](const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                           const Eigen::Vector3d& c) { return (a - p).dot((b - p).cross(c - p)); };
    for (int f : triangles_meeting(x0.cwiseMin(x1), x0.cwiseMax(x1))) {
        const Eigen::Vector3d a = surface_.V.row(surface_.F(f, 0)), b = surface_.V.row(surface_.F(f, 1)),
                              c = surface_.V.row(surface_.F(f, 2));
        const double v0 = volume(x0, a, b, c), v1 = volume(x1, a, b, c);
        if ((v0 > 0.0 && v1 > 0.0) || (v0 < 0.0 && v1 < 0.0))
            continue;  // both ends on one side of the triangle's plane
        const double ab = volume(x0, x1, a, b), bc = volume(x0, x1, b, c), ca = volume(x0, x1, c, a);
        if ((ab >= 0.0 && bc >= 0.0 && ca >= 0.0) || (ab <= 0.0 && bc <= 0.0 && ca <= 0.0))
            return true;
    }
    return false;
}

double MeshObstacle::local_distance(const Eigen::Vector3d& p) const
{
    return nearest(p).distance;
}

DistancePiece MeshObstacle::piece(int f, const TrianglePoint& closest, const Eigen::Vector3d& p) const
{
    DistancePiece piece;
    piece.distance = (p - closest.point).norm();
    if (!(piece.distance > 0.0)) {
        piece.gradient = Eigen::Vector3d::UnitZ();  // on the triangle, where the barrier never looks
        return piece;
    }
    const Eigen::Vector3d g = (p - closest.point) / piece.distance;
    piece.gradient = g;
    if (closest.feature == TriangleFeature::face)
        return piece;  // a plane: ∇²d = 0
    piece.hessian = Eigen::Matrix3d::Identity() - g * g.transpose();
    if (closest.feature == TriangleFeature::edge) {
        const int i = closest.corner, j = (i + 1) % 3;
        const Eigen::Vector3d e = (surface_.V.row(surface_.F(f, j)) - surface_.V.row(surface_.F(f, i))).transpose().normalized();
        piece.hessian -= e * e.transpose();
    }
    piece.hessian /= piece.distance;
    return piece;
}

Eigen::Vector3d MeshObstacle::local_gradient(const Eigen::Vector3d& p) const
{
    const Nearest n = nearest(p);
    return piece(n.triangle, n.closest, p).gradient;
}

Eigen::Matrix3d MeshObstacle::local_hessian(const Eigen::Vector3d& p) const
{
    const Nearest n = nearest(p);
    return piece(n.triangle, n.closest, p).hessian;
}

bool MeshObstacle::shadowed(int f, const Eigen::Vector3d& closest, const Eigen::Vector3d& p,
                            const std::vector<std::pair<int, TrianglePoint>>& known) const
{
    const double distance = (p - closest).norm();
    const auto point_of = [&](int other) {  // other's closest point: from known when it is there
        for (const auto& [g, point] : known)
            if (g == other)
                return point.point;
        return closest_on(other, p).point;
    };
    // A nearer point of other, or as near and a lower number: a strict order by (distance, number),
    // so that the piece kept is the nearest of its flat neighbourhood and the sum is its minimum's
    // barrier, continuous. (Two points that nearly coincide are still ranked by distance: over a
    // shared edge, the face piece of the triangle p stands over is nearer than the neighbour's edge
    // piece by δ²/2d at a lateral offset δ, and preferring the edge piece there by number put a
    // step of that size in the energy at δ = same_point_, where Newton's line search stalled.)
    const auto beats = [&](int other) {
        const double other_distance = (p - point_of(other)).norm();
        return other_distance < distance || (other_distance == distance && other < f);
    };
    // The neighbours compared: across the flat edges q lies on and in the flat fans of the corners q
    // is at. An edge or vertex piece's q lies there exactly; a face piece's q is matched in a plane
    // only by the same point (within same_point_ of the edge or corner), and over two triangles that
    // pass as flat at an angle of sine σ ≤ flat_mesh_edge_sine, in a valley, where their face regions
    // overlap, within σ d of it (2σd: a margin).
    const double near = same_point_ + 2.0 * flat_mesh_edge_sine * distance;
    for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d corner = surface_.V.row(surface_.F(f, k)), next = surface_.V.row(surface_.F(f, (k + 1) % 3));
        if ((closest - corner).norm() <= near) {
            for (int other : flat_fan_[3 * f + k])
                if (beats(other))
                    return true;
        }
        const int across = flat_neighbour_[3 * f + k];
        if (across >= 0 && segment_distance(closest, corner, next) <= near && beats(across))
            return true;
    }
    return false;
}

void MeshObstacle::local_pieces(const Eigen::Vector3d& p, double reach, std::vector<DistancePiece>& pieces) const
{
    // Each triangle's closest point once: the shadow test compares a triangle with its flat
    // neighbours, which are mostly among these.
    std::vector<std::pair<int, TrianglePoint>> closest;
    for (int f : triangles_meeting(p.array() - reach, p.array() + reach))
        closest.emplace_back(f, closest_on(f, p));
    for (const auto& [f, point] : closest)
        if ((p - point.point).norm() < reach && !shadowed(f, point.point, p, closest))
            pieces.push_back(piece(f, point, p));
}

double MeshObstacle::local_time_of_impact(const Eigen::Vector3d& p, const Eigen::Vector3d& dp) const
{
    if (!(local_distance(p) > 0.0))
        return 0.0;
    double first = infinity;
    // BEGIN EXERCISE 15.4 mesh_time_of_impact #mesh-obstacles
    // HINT: The smallest s in [0, 2] at which p + s dp meets one of the triangles whose boxes meet the
    // HINT: path's box (triangles_meeting), in `first` (docs/15_body_contact.md#time-of-impact-against-a-mesh):
    // HINT: solve for where the path crosses each triangle's plane and whether that point lies in the
    // HINT: triangle (Möller–Trumbore, as the docs name it). Count a hit on an edge as inside, with a
    // HINT: margin of 1e-9 of the barycentric range, so a path through a shared edge cannot slip between
    // HINT: two triangles by round-off. A path parallel to a plane misses it unless it lies in it; then
    // HINT: there is no root to solve for: answer conservative_time_of_impact.
    constexpr double far = 2.0;      // callers step at most s = 1: beyond this, no impact that matters
    constexpr double margin = 1e-9;  // each triangle tested grown by this fraction at its edges
    const Eigen::Vector3d end = p + far * dp;
    for (int f : triangles_meeting(p.cwiseMin(end), p.cwiseMax(end))) {
        const Eigen::Vector3d a = surface_.V.row(surface_.F(f, 0)), b = surface_.V.row(surface_.F(f, 1)),
                              c = surface_.V.row(surface_.F(f, 2));
        const Eigen::Vector3d e1 = b - a, e2 = c - a, h = dp.cross(e2);
        const double det = e1.dot(h);
        const Eigen::Vector3d r = p - a;
        if (!(std::abs(det) > 1e-12 * e1.norm() * e2.norm() * dp.norm())) {
            // Parallel to the plane: off it (by more than the path could close at this det), never
            // meets it; in it, no root to solve for: the conservative answer.
            if (std::abs(r.dot(e1.cross(e2).normalized())) > 1e-9 * dp.norm())
                continue;
            return conservative_time_of_impact(*this, p, dp);
        }
        const Eigen::Vector3d q = r.cross(e1);
        const double u = r.dot(h) / det, v = dp.dot(q) / det, s = e2.dot(q) / det;
        if (u >= -margin && v >= -margin && u + v <= 1.0 + margin && s >= 0.0 && s <= far)
            first = std::min(first, s);
    }
    // END EXERCISE
    return first;
}

// --- The sampled grid --------------------------------------------------------------------------------

DistanceGrid::DistanceGrid(const MeshObstacle& mesh, double spacing, double margin)
{
    if (!(std::isfinite(spacing) && spacing > 0.0))
        throw Error(str("DistanceGrid: the spacing must be a finite number > 0 [m], got ", spacing));
    if (!(std::isfinite(margin) && margin >= 0.0))
        throw Error(str("DistanceGrid: the margin must be a finite number >= 0 [m], got ", margin));
    const MatrixX3d& V = mesh.surface().V;
    low_ = V.colwise().minCoeff().transpose().array() - margin;
    high_ = V.colwise().maxCoeff().transpose().array() + margin;
    const Eigen::Vector3d extent = high_ - low_;
    double nodes = 1.0;
    for (int axis = 0; axis < 3; ++axis) {
        const double cells = std::max(1.0, std::ceil(extent[axis] / spacing));
        nodes *= cells + 1.0;
        if (nodes > 5e7)
            throw Error(str("DistanceGrid: a spacing of ", spacing, " m over a box of ", extent.transpose(),
                            " m needs more than 5e7 nodes; use a larger spacing"));
        dims_[axis] = static_cast<int>(cells) + 1;
        spacing_[axis] = extent[axis] > 0.0 ? extent[axis] / cells : spacing;
    }
    values_.resize(static_cast<std::size_t>(nodes));
    std::size_t index = 0;
    for (int k = 0; k < dims_.z(); ++k)
        for (int j = 0; j < dims_.y(); ++j)
            for (int i = 0; i < dims_.x(); ++i)
                values_[index++] = mesh.local_distance(low_ + Eigen::Vector3d(i, j, k).cwiseProduct(spacing_));
}

void DistanceGrid::locate(const Eigen::Vector3d& p, Eigen::Vector3i& cell, Eigen::Vector3d& t) const
{
    for (int axis = 0; axis < 3; ++axis) {
        const double x = std::clamp((p[axis] - low_[axis]) / spacing_[axis], 0.0, double(dims_[axis] - 1));
        cell[axis] = std::min(static_cast<int>(x), dims_[axis] - 2);
        t[axis] = x - cell[axis];
    }
}

double DistanceGrid::distance(const Eigen::Vector3d& p) const
{
    Eigen::Vector3i c;
    Eigen::Vector3d t;
    locate(p, c, t);
    double value = 0.0;
    for (int corner = 0; corner < 8; ++corner) {
        const int di = corner & 1, dj = (corner >> 1) & 1, dk = (corner >> 2) & 1;
        const double weight = (di ? t.x() : 1.0 - t.x()) * (dj ? t.y() : 1.0 - t.y()) * (dk ? t.z() : 1.0 - t.z());
        value += weight * node(c.x() + di, c.y() + dj, c.z() + dk);
    }
    return value + (p - p.cwiseMax(low_).cwiseMin(high_)).norm();
}

Eigen::Vector3d DistanceGrid::gradient(const Eigen::Vector3d& p) const
{
    Eigen::Vector3i c;
    Eigen::Vector3d t;
    locate(p, c, t);
    Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
    for (int corner = 0; corner < 8; ++corner) {
        const int d[3] = {corner & 1, (corner >> 1) & 1, (corner >> 2) & 1};
        const double value = node(c.x() + d[0], c.y() + d[1], c.z() + d[2]);
        for (int axis = 0; axis < 3; ++axis) {
            double weight = (d[axis] ? 1.0 : -1.0) / spacing_[axis];
            for (int other = 0; other < 3; ++other)
                if (other != axis)
                    weight *= d[other] ? t[other] : 1.0 - t[other];
            gradient[axis] += weight * value;
        }
    }
    return gradient;
}

}  // namespace fem::contact
