// Chapter 15: the barrier between obstacles' edges and corners and the body's surface.
// docs/15_body_contact.md#edges-and-corners-of-obstacles
#include "15_body_contact/feature_barrier.hpp"

#include "15_body_contact/broad_phase.hpp"
#include "15_body_contact/ccd.hpp"
#include "15_body_contact/distances.hpp"
#include "15_body_contact/pair_barrier.hpp"

#include "12_hyperelastic_newton/materials.hpp"

#include "common/error.hpp"
#include "common/types.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace fem::contact {
namespace {

using BoundingBox = Eigen::Matrix<double, 2, 3>;

BoundingBox box_of(const Eigen::Vector3d& a, const Eigen::Vector3d& b)
{
    BoundingBox box;
    box.row(0) = a.cwiseMin(b).transpose();
    box.row(1) = a.cwiseMax(b).transpose();
    return box;
}

/// The boxes of a set of segments (rows of edges into points) or of points (edges empty).
std::vector<BoundingBox> boxes_of(const Eigen::MatrixX3d& points, const Eigen::MatrixX2i& edges)
{
    std::vector<BoundingBox> boxes;
    if (edges.rows() == 0)
        for (Eigen::Index i = 0; i < points.rows(); ++i)
            boxes.push_back(box_of(points.row(i).transpose(), points.row(i).transpose()));
    else
        for (Eigen::Index e = 0; e < edges.rows(); ++e)
            boxes.push_back(box_of(points.row(edges(e, 0)).transpose(), points.row(edges(e, 1)).transpose()));
    return boxes;
}

/// A rounded pair's squared gap (√s − r)² from its squared distance s (r > 0, √s > r), with its
/// derivatives by the chain rule: with q = √s, ∇ = (1 − r/q) ∇s, ∇² = (1 − r/q) ∇²s + r/(2q³) ∇s ∇sᵀ.
PrimitiveFunction rounded(const PrimitiveFunction& squared, double radius)
{
    const double q = std::sqrt(squared.value);
    PrimitiveFunction gap;
    gap.value = (q - radius) * (q - radius);
    gap.gradient = (1.0 - radius / q) * squared.gradient;
    gap.hessian = (1.0 - radius / q) * squared.hessian +
                  (radius / (2.0 * q * q * q)) * squared.gradient * squared.gradient.transpose();
    return gap;
}

}  // namespace

FeatureBarrier::FeatureBarrier(const TetMesh& mesh, const std::vector<std::shared_ptr<const Obstacle>>& obstacles,
                               double activation_distance)
    : rest_(mesh.V), activation_distance_(activation_distance)
{
    for (const auto& obstacle : obstacles) {
        ObstacleFeatures features = obstacle->local_features();
        if (features.corners.rows() == 0)
            features = obstacle->local_core();  // a sphere's centre, a capsule's segment, with their radius
        if (features.corners.rows() == 0)
            continue;
        Features entry;
        entry.obstacle = obstacle;
        entry.radius = features.radius;
        entry.vertices = std::move(features.corners);
        entry.edges = std::move(features.edges);
        entry.vertex_boxes = boxes_of(entry.vertices, Eigen::MatrixX2i());
        entry.vertex_tree = skin::box_hierarchy(entry.vertex_boxes, 4);
        if (entry.edges.rows() > 0) {
            entry.edge_boxes = boxes_of(entry.vertices, entry.edges);
            entry.edge_tree = skin::box_hierarchy(entry.edge_boxes, 4);
        }
        obstacles_.push_back(std::move(entry));
    }
    if (obstacles_.empty())
        return;
    SurfacePrimitives surface = surface_primitives(mesh);
    triangles_ = std::move(surface.triangles);
    edges_ = std::move(surface.edges);
}

template <class Visit>
bool FeatureBarrier::for_each_pair(const Eigen::VectorXd& u, double time, double reach, bool with_derivatives,
                                   Visit visit) const
{
    const auto x = [&](int v) -> Eigen::Vector3d { return rest_.row(v).transpose() + u.segment<3>(3 * v); };
    for (int o = 0; o < static_cast<int>(obstacles_.size()); ++o) {
        const Features& features = obstacles_[static_cast<std::size_t>(o)];
        const double radius = features.radius;
        const Eigen::Vector3d grow = Eigen::Vector3d::Constant(reach + radius);
        // A pair's squared gap (d − r)² [m²] and its derivatives; false when it touches (d ≤ r).
        const auto gap_of = [&](const PrimitiveFunction& squared, PrimitiveFunction& gap) {
            if (radius == 0.0) {
                gap = squared;
                return squared.value > 0.0;
            }
            if (!(squared.value > radius * radius))
                return false;
            gap = rounded(squared, radius);
            return true;
        };
        const Eigen::Vector3d shift = time * features.obstacle->velocity();
        const auto corner = [&](int c) -> Eigen::Vector3d { return features.vertices.row(c).transpose() + shift; };
        // The body's surface edges against the obstacle's edges.
        if (features.edges.rows() > 0)
            for (Eigen::Index e = 0; e < edges_.rows(); ++e) {
                const int i = edges_(e, 0), j = edges_(e, 1);
                const Eigen::Vector3d a0 = x(i), a1 = x(j);
                const BoundingBox box = box_of(a0, a1);
                for (int k : skin::boxes_meeting(features.edge_tree, features.edge_boxes,
                                                 box.row(0).transpose() - shift - grow,
                                                 box.row(1).transpose() - shift + grow)) {
                    const int c0 = features.edges(k, 0), c1 = features.edges(k, 1);
                    const Eigen::Vector3d b0 = corner(c0), b1 = corner(c1);
                    const EdgeEdgeType type = edge_edge_type(a0, a1, b0, b1);
                    const PrimitiveFunction distance = edge_edge_squared_distance(a0, a1, b0, b1, type);
                    if (!(distance.value < (reach + radius) * (reach + radius)))
                        continue;
                    PrimitiveFunction squared;
                    if (!gap_of(distance, squared))
                        return false;
                    if (!(squared.value < reach * reach))
                        continue;
                    const double threshold = edge_edge_mollifier_threshold(
                        rest_.row(i).transpose(), rest_.row(j).transpose(), features.vertices.row(c0).transpose(),
                        features.vertices.row(c1).transpose());
                    const PrimitiveFunction m = edge_edge_mollifier(a0, a1, b0, b1, threshold);
                    const PrimitiveFunction f = mollified_barrier(squared, m, activation_distance_, with_derivatives);
                    Pair pair;
                    pair.obstacle = o;
                    pair.count = 2;
                    pair.vertices[0] = i;
                    pair.vertices[1] = j;
                    pair.distance = std::sqrt(squared.value);
                    pair.value = f.value;
                    if (with_derivatives) {
                        pair.gradient.setZero();
                        pair.hessian.setZero();
                        pair.gradient.head<6>() = f.gradient.head<6>();
                        pair.hessian.topLeftCorner<6, 6>() = f.hessian.topLeftCorner<6, 6>();
                    }
                    visit(pair);
                }
            }
        // The obstacle's corners against the body's surface triangles.
        for (Eigen::Index t = 0; t < triangles_.rows(); ++t) {
            const Eigen::Vector3d a = x(triangles_(t, 0)), b = x(triangles_(t, 1)), c = x(triangles_(t, 2));
            const Eigen::Vector3d low = a.cwiseMin(b).cwiseMin(c), high = a.cwiseMax(b).cwiseMax(c);
            for (int k : skin::boxes_meeting(features.vertex_tree, features.vertex_boxes, low - shift - grow,
                                             high - shift + grow)) {
                const Eigen::Vector3d p = corner(k);
                const PrimitiveFunction distance =
                    point_triangle_squared_distance(p, a, b, c, point_triangle_type(p, a, b, c));
                if (!(distance.value < (reach + radius) * (reach + radius)))
                    continue;
                PrimitiveFunction squared;
                if (!gap_of(distance, squared))
                    return false;
                if (!(squared.value < reach * reach))
                    continue;
                const PrimitiveFunction f =
                    mollified_barrier(squared, unit_mollifier(), activation_distance_, with_derivatives);
                Pair pair;
                pair.obstacle = o;
                pair.count = 3;
                for (int corner_index = 0; corner_index < 3; ++corner_index)
                    pair.vertices[corner_index] = triangles_(t, corner_index);
                pair.distance = std::sqrt(squared.value);
                pair.value = f.value;
                if (with_derivatives) {
                    pair.gradient = f.gradient.tail<9>();
                    pair.hessian = f.hessian.bottomRightCorner<9, 9>();
                }
                visit(pair);
            }
        }
    }
    return true;
}

double FeatureBarrier::energy(const Eigen::VectorXd& u, double time, double stiffness) const
{
    double total = 0.0;
    if (!for_each_pair(u, time, activation_distance_, false, [&](const Pair& pair) { total += pair.value; }))
        return infinity;
    return stiffness * total;
}

void FeatureBarrier::add_gradient(const Eigen::VectorXd& u, double time, double stiffness,
                                  Eigen::VectorXd& gradient) const
{
    const bool apart = for_each_pair(u, time, activation_distance_, true, [&](const Pair& pair) {
        for (int k = 0; k < pair.count; ++k)
            gradient.segment<3>(3 * pair.vertices[k]) += stiffness * pair.gradient.segment<3>(3 * k);
    });
    if (!apart)
        throw Error("contact: the gradient of the edge and corner barrier was asked where an obstacle's edge or "
                    "corner touches the body's surface (d = 0)");
}

void FeatureBarrier::add_hessian(const Eigen::VectorXd& u, double time, double stiffness,
                                 std::vector<Eigen::Triplet<double>>& triplets,
                                 std::optional<hyper::Projection> projection) const
{
    const bool apart = for_each_pair(u, time, activation_distance_, true, [&](const Pair& pair) {
        // Each pair's block is made PSD on its own (a sum of PSD blocks is PSD), or left as it is; a
        // two-vertex pair (count 2) uses the top-left 6×6 only.
        Eigen::Matrix<double, 9, 9> block = pair.hessian;
        if (projection && pair.count == 2)
            block.topLeftCorner<6, 6>() =
                hyper::project_to_psd<6>(Eigen::Matrix<double, 6, 6>(pair.hessian.topLeftCorner<6, 6>()), *projection);
        else if (projection)
            block = hyper::project_to_psd<9>(pair.hessian, *projection);
        for (int a = 0; a < pair.count; ++a)
            for (int b = 0; b < pair.count; ++b)
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 3; ++j)
                        triplets.emplace_back(3 * pair.vertices[a] + i, 3 * pair.vertices[b] + j,
                                              stiffness * block(3 * a + i, 3 * b + j));
    });
    if (!apart)
        throw Error("contact: the Hessian of the edge and corner barrier was asked where an obstacle's edge or "
                    "corner touches the body's surface (d = 0)");
}

double FeatureBarrier::obstacle_power(const Eigen::VectorXd& u, double time, double stiffness) const
{
    double power = 0.0;
    for_each_pair(u, time, activation_distance_, true, [&](const Pair& pair) {
        // The pair's force on the body is −κ ∇(m b); the obstacle carries it along at w.
        const Eigen::Vector3d& w = obstacles_[static_cast<std::size_t>(pair.obstacle)].obstacle->velocity();
        for (int k = 0; k < pair.count; ++k)
            power -= stiffness * w.dot(pair.gradient.segment<3>(3 * k));
    });
    return power;
}

double FeatureBarrier::smallest_distance(const Eigen::VectorXd& u, double time, double reach) const
{
    double smallest = infinity;
    if (!for_each_pair(u, time, reach, false, [&](const Pair& pair) { smallest = std::min(smallest, pair.distance); }))
        return 0.0;
    return smallest;
}

double FeatureBarrier::earliest_impact(const MatrixX3d& x0, const MatrixX3d& x1, double time, double shift) const
{
    double earliest = infinity;
    for (const Features& features : obstacles_) {
        const Eigen::Vector3d at = time * features.obstacle->velocity();
        // The body's motion relative to the obstacle: its end moved back by shift × w.
        const Eigen::Vector3d back = shift * features.obstacle->velocity();
        const auto start = [&](int v) -> Eigen::Vector3d { return x0.row(v).transpose(); };
        const auto end = [&](int v) -> Eigen::Vector3d { return x1.row(v).transpose() - back; };
        const auto corner = [&](int c) -> Eigen::Vector3d { return features.vertices.row(c).transpose() + at; };
        // A rounded core's reach, and the minimum separation's: a pair whose swept boxes stay apart
        // but come within its gap ≤ d̂/10 may still end nearer than that (line_search_time_of_impact).
        const Eigen::Vector3d round = Eigen::Vector3d::Constant(features.radius + 0.1 * activation_distance_);
        PrimitiveMotion motion;
        if (features.edges.rows() > 0)
            for (Eigen::Index e = 0; e < edges_.rows(); ++e) {
                const int i = edges_(e, 0), j = edges_(e, 1);
                const Eigen::Vector3d low = start(i).cwiseMin(start(j)).cwiseMin(end(i)).cwiseMin(end(j));
                const Eigen::Vector3d high = start(i).cwiseMax(start(j)).cwiseMax(end(i)).cwiseMax(end(j));
                for (int k : skin::boxes_meeting(features.edge_tree, features.edge_boxes, low - at - round, high - at + round)) {
                    const Eigen::Vector3d b0 = corner(features.edges(k, 0)), b1 = corner(features.edges(k, 1));
                    motion.start << start(i), start(j), b0, b1;
                    motion.end << end(i), end(j), b0, b1;
                    earliest = std::min(earliest, features.radius > 0.0
                                                      ? additive_time_of_impact(PrimitivePair::edge_edge, motion, features.radius)
                                                      : line_search_time_of_impact(PrimitivePair::edge_edge, motion, activation_distance_));
                }
            }
        for (Eigen::Index t = 0; t < triangles_.rows(); ++t) {
            const int a = triangles_(t, 0), b = triangles_(t, 1), c = triangles_(t, 2);
            const Eigen::Vector3d low =
                start(a).cwiseMin(start(b)).cwiseMin(start(c)).cwiseMin(end(a)).cwiseMin(end(b)).cwiseMin(end(c));
            const Eigen::Vector3d high =
                start(a).cwiseMax(start(b)).cwiseMax(start(c)).cwiseMax(end(a)).cwiseMax(end(b)).cwiseMax(end(c));
            for (int k : skin::boxes_meeting(features.vertex_tree, features.vertex_boxes, low - at - round, high - at + round)) {
                const Eigen::Vector3d p = corner(k);
                motion.start << p, start(a), start(b), start(c);
                motion.end << p, end(a), end(b), end(c);
                earliest = std::min(earliest, features.radius > 0.0
                                                  ? additive_time_of_impact(PrimitivePair::point_triangle, motion, features.radius)
                                                  : line_search_time_of_impact(PrimitivePair::point_triangle, motion, activation_distance_));
            }
        }
    }
    return earliest;
}

double FeatureBarrier::time_of_impact(const Eigen::VectorXd& u, const Eigen::VectorXd& du, double time) const
{
    if (obstacles_.empty())
        return infinity;
    MatrixX3d x0 = rest_, x1 = rest_;
    for (Eigen::Index v = 0; v < rest_.rows(); ++v) {
        x0.row(v) += u.segment<3>(3 * v).transpose();
        x1.row(v) = x0.row(v) + du.segment<3>(3 * v).transpose();
    }
    return earliest_impact(x0, x1, time, 0.0);
}

double FeatureBarrier::relative_time_of_impact(const Eigen::VectorXd& u, double time, const Eigen::VectorXd& u_end,
                                               double end_time) const
{
    if (obstacles_.empty())
        return infinity;
    MatrixX3d x0 = rest_, x1 = rest_;
    for (Eigen::Index v = 0; v < rest_.rows(); ++v) {
        x0.row(v) += u.segment<3>(3 * v).transpose();
        x1.row(v) += u_end.segment<3>(3 * v).transpose();
    }
    return earliest_impact(x0, x1, time, end_time - time);
}

}  // namespace fem::contact
