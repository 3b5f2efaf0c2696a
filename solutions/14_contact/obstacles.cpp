#include "14_contact/obstacles.hpp"

#include "common/error.hpp"
#include "common/types.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace fem::contact {
namespace {

void require_finite_point(const Eigen::Vector3d& p, const char* what)
{
    if (!p.allFinite())
        throw Error(str("obstacle: the ", what, " must be finite, got (", p.x(), ", ", p.y(), ", ", p.z(), ")"));
}

}  // namespace

Obstacle::Obstacle(const Eigen::Vector3d& velocity, double friction) : velocity_(velocity), friction_(friction)
{
    require_finite_point(velocity, "velocity [m/s]");
    if (!(std::isfinite(friction) && friction >= 0.0))
        throw Error(str("obstacle: the friction coefficient mu must be a finite number >= 0, got ", friction));
}

TriMesh Obstacle::surface_at(const std::array<double, 6>& around, double time) const
{
    const Eigen::Vector3d shift = time * velocity_;
    std::array<double, 6> local = around;
    for (int axis = 0; axis < 3; ++axis) {
        local[2 * axis] -= shift[axis];
        local[2 * axis + 1] -= shift[axis];
    }
    TriMesh drawn = local_surface(local);
    drawn.V.rowwise() += shift.transpose();
    return drawn;
}

void Obstacle::local_pieces(const Eigen::Vector3d& p, double reach, std::vector<DistancePiece>& pieces) const
{
    const double d = local_distance(p);
    if (d < reach)
        pieces.push_back(DistancePiece{d, local_gradient(p), local_hessian(p)});
}

// --- Half-space ------------------------------------------------------------------------------------

HalfSpace::HalfSpace(const Eigen::Vector3d& point, const Eigen::Vector3d& normal, double friction,
                     const Eigen::Vector3d& velocity)
    : Obstacle(velocity, friction)
{
    require_finite_point(point, "point of the plane");
    require_finite_point(normal, "normal of the plane");
    const double largest = normal.cwiseAbs().maxCoeff();  // scaled first: |n|² of [1e308, 1e308, 0] overflows
    if (!(largest > 0.0))
        throw Error("half-space: the normal of the plane must not be zero");
    normal_ = (normal / largest).normalized();
    // The plane's point nearest the origin, (n·p) n: d = n·(x − p) with a point far along the plane
    // (p = (0, 10⁹, −10⁹) for the plane y + z = 0) lost x's digits in x − p, and Newton stalled on
    // a distance that moved in steps of 10⁻⁷ m; from this point only the plane's offset is rounded.
    point_ = normal_.dot(point) * normal_;
}

double HalfSpace::local_distance(const Eigen::Vector3d& p) const
{
    return normal_.dot(p - point_);
}

Eigen::Vector3d HalfSpace::local_gradient(const Eigen::Vector3d&) const
{
    return normal_;
}

Eigen::Matrix3d HalfSpace::local_hessian(const Eigen::Vector3d&) const
{
    return Eigen::Matrix3d::Zero();
}

double HalfSpace::local_time_of_impact(const Eigen::Vector3d& p, const Eigen::Vector3d& dp) const
{
    double s = infinity;
    // BEGIN EXERCISE 14.2 plane_time_of_impact #continuous-collision-detection
    // HINT: d(p + s dp) = d(p) + s n·dp is linear in s: it reaches 0 at s = d(p)/(−n·dp) when the
    // HINT: path approaches the plane (n·dp < 0), never otherwise (s stays +∞).
    const double rate = normal_.dot(dp);
    if (rate < 0.0)
        s = local_distance(p) / -rate;
    // END EXERCISE
    return s;
}

TriMesh HalfSpace::local_surface(const std::array<double, 6>& around) const
{
    const Eigen::Vector3d other = std::abs(normal_.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    const Eigen::Vector3d u = normal_.cross(other).normalized(), v = normal_.cross(u);
    double lo_u = infinity, hi_u = -infinity, lo_v = infinity, hi_v = -infinity;
    for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d c(around[(corner & 1) ? 1 : 0], around[(corner & 2) ? 3 : 2], around[(corner & 4) ? 5 : 4]);
        lo_u = std::min(lo_u, u.dot(c - point_));
        hi_u = std::max(hi_u, u.dot(c - point_));
        lo_v = std::min(lo_v, v.dot(c - point_));
        hi_v = std::max(hi_v, v.dot(c - point_));
    }
    const double margin =
        0.2 * Eigen::Vector3d(around[1] - around[0], around[3] - around[2], around[5] - around[4]).norm();
    TriMesh patch;
    patch.V.resize(4, 3);
    int row = 0;
    for (double a : {lo_u - margin, hi_u + margin})
        for (double b : {lo_v - margin, hi_v + margin})
            patch.V.row(row++) = (point_ + a * u + b * v).transpose();
    patch.F.resize(2, 3);
    patch.F << 0, 1, 3, 0, 3, 2;
    return patch;
}

// --- Sphere ----------------------------------------------------------------------------------------

Sphere::Sphere(const Eigen::Vector3d& centre, double radius, double friction, const Eigen::Vector3d& velocity)
    : Obstacle(velocity, friction), centre_(centre), radius_(radius)
{
    require_finite_point(centre, "centre of the sphere");
    require_positive(radius, "sphere radius [m]");
}

double Sphere::local_distance(const Eigen::Vector3d& p) const
{
    return (p - centre_).norm() - radius_;
}

Eigen::Vector3d Sphere::local_gradient(const Eigen::Vector3d& p) const
{
    const Eigen::Vector3d r = p - centre_;
    const double length = r.norm();
    return length > 0.0 ? Eigen::Vector3d(r / length) : Eigen::Vector3d::UnitZ();
}

Eigen::Matrix3d Sphere::local_hessian(const Eigen::Vector3d& p) const
{
    const double length = (p - centre_).norm();
    if (!(length > 0.0))
        return Eigen::Matrix3d::Zero();
    const Eigen::Vector3d n = local_gradient(p);
    return (Eigen::Matrix3d::Identity() - n * n.transpose()) / length;
}

double Sphere::local_time_of_impact(const Eigen::Vector3d& p, const Eigen::Vector3d& dp) const
{
    double s = infinity;
    // BEGIN EXERCISE 14.3 sphere_time_of_impact #continuous-collision-detection
    // HINT: |p + s dp − c|² = r² is a s² + b s + k = 0 with a = dp·dp, b = 2 dp·(p − c),
    // HINT: k = |p − c|² − r² > 0 (outside). The path hits when it approaches (b < 0) and the
    // HINT: discriminant b² − 4ak ≥ 0; the first root is s = 2k / (−b + √(b² − 4ak)) (no cancellation).
    const Eigen::Vector3d r = p - centre_;
    const double a = dp.squaredNorm(), b = 2.0 * dp.dot(r), k = r.squaredNorm() - radius_ * radius_;
    const double discriminant = b * b - 4.0 * a * k;
    if (b < 0.0 && discriminant >= 0.0)
        s = 2.0 * k / (-b + std::sqrt(discriminant));
    // END EXERCISE
    return s;
}

TriMesh Sphere::local_surface(const std::array<double, 6>&) const
{
    return swept_ball_surface(centre_, centre_, radius_);
}

// --- Box -------------------------------------------------------------------------------------------

Box::Box(const Eigen::Vector3d& centre, const Eigen::Vector3d& half_extents, const Eigen::Matrix3d& rotation,
         double friction, const Eigen::Vector3d& velocity)
    : Obstacle(velocity, friction), centre_(centre), half_(half_extents), rotation_(rotation)
{
    require_finite_point(centre, "centre of the box");
    for (int axis = 0; axis < 3; ++axis)
        require_positive(half_extents[axis], "box half extent [m]");
    if (!rotation.allFinite() || (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm() > 1e-9 ||
        std::abs(rotation.determinant() - 1.0) > 1e-9)
        throw Error("box: the rotation must be orthonormal with determinant +1 (to 1e-9)");
}

double Box::local_distance(const Eigen::Vector3d& p) const
{
    const Eigen::Vector3d excess = (rotation_.transpose() * (p - centre_)).cwiseAbs() - half_;
    const double outside = excess.cwiseMax(0.0).norm();
    return outside > 0.0 ? outside : excess.maxCoeff();
}

Eigen::Vector3d Box::local_gradient(const Eigen::Vector3d& p) const
{
    const Eigen::Vector3d q = rotation_.transpose() * (p - centre_);
    const Eigen::Vector3d excess = q.cwiseAbs() - half_;
    const Eigen::Vector3d sign = q.unaryExpr([](double x) { return x < 0.0 ? -1.0 : 1.0; });
    const Eigen::Vector3d outside = excess.cwiseMax(0.0);
    const double length = outside.norm();
    if (length > 0.0)
        return rotation_ * sign.cwiseProduct(outside) / length;
    Eigen::Index axis = 0;
    excess.maxCoeff(&axis);
    return rotation_.col(axis) * sign[axis];
}

Eigen::Matrix3d Box::local_hessian(const Eigen::Vector3d& p) const
{
    const Eigen::Vector3d q = rotation_.transpose() * (p - centre_);
    const Eigen::Vector3d outside = (q.cwiseAbs() - half_).cwiseMax(0.0);
    const double length = outside.norm();
    if (!(length > 0.0))
        return Eigen::Matrix3d::Zero();  // inside: d is piecewise linear
    const Eigen::Vector3d sign = q.unaryExpr([](double x) { return x < 0.0 ? -1.0 : 1.0; });
    const Eigen::Vector3d n = sign.cwiseProduct(outside) / length;
    const Eigen::Vector3d active = outside.unaryExpr([](double x) { return x > 0.0 ? 1.0 : 0.0; });
    const Eigen::Matrix3d local = (Eigen::Matrix3d(active.asDiagonal()) - n * n.transpose()) / length;
    return rotation_ * local * rotation_.transpose();
}

double Box::local_time_of_impact(const Eigen::Vector3d& p, const Eigen::Vector3d& dp) const
{
    if (!(local_distance(p) > 0.0))
        return 0.0;
    // The box is the meet of three slabs |q_i| ≤ h_i (q = Rᵀ(x − c)): the path is inside slab i for
    // s between the roots of q_i + s w_i = ±h_i, inside the box from the latest entry to the earliest
    // exit, and it meets the box when that entry comes no later than the exit.
    const Eigen::Vector3d q = rotation_.transpose() * (p - centre_), w = rotation_.transpose() * dp;
    double entry = 0.0, exit = infinity;
    for (int axis = 0; axis < 3; ++axis) {
        if (w[axis] == 0.0) {
            if (std::abs(q[axis]) > half_[axis])
                return infinity;  // parallel to the slab and outside it
            continue;
        }
        const double low = (-half_[axis] - q[axis]) / w[axis], high = (half_[axis] - q[axis]) / w[axis];
        entry = std::max(entry, std::min(low, high));
        exit = std::min(exit, std::max(low, high));
    }
    return entry <= exit ? entry : infinity;
}

// --- Conservative advancement ------------------------------------------------------------------------

double conservative_time_of_impact(const Obstacle& obstacle, const Eigen::Vector3d& p, const Eigen::Vector3d& dp)
{
    // From s, the path cannot reach the obstacle before s + d(p + s dp)/|dp|.
    const double start = obstacle.local_distance(p), length = dp.norm();
    if (!(start > 0.0))
        return 0.0;
    if (!(length > 0.0))
        return infinity;
    constexpr double far = 2.0;  // callers step at most s = 1: beyond this, no impact that matters
    double s = 0.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
        const double d = obstacle.local_distance(p + s * dp);
        if (d <= 0.05 * start)
            return s;
        s += d / length;
        if (s > far)
            return infinity;
    }
    return s;
}

ObstacleFeatures Box::local_features() const
{
    ObstacleFeatures features;
    features.corners.resize(8, 3);
    // Corner k has the sign pattern of k's bits: bit i set → +h_i.
    for (int k = 0; k < 8; ++k) {
        const Eigen::Vector3d sign((k & 1) ? 1.0 : -1.0, (k & 2) ? 1.0 : -1.0, (k & 4) ? 1.0 : -1.0);
        features.corners.row(k) = (centre_ + rotation_ * sign.cwiseProduct(half_)).transpose();
    }
    // An edge joins two corners that differ in one bit.
    features.edges.resize(12, 2);
    int e = 0;
    for (int k = 0; k < 8; ++k)
        for (int bit = 1; bit < 8; bit <<= 1)
            if ((k & bit) == 0)
                features.edges.row(e++) << k, k | bit;
    return features;
}

TriMesh Box::local_surface(const std::array<double, 6>&) const
{
    TriMesh box;
    box.V = local_features().corners;
    box.F.resize(12, 3);
    box.F << 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5;
    return box;
}

// --- Capsule ---------------------------------------------------------------------------------------

Capsule::Capsule(const Eigen::Vector3d& start, const Eigen::Vector3d& end, double radius, double friction,
                 const Eigen::Vector3d& velocity)
    : Obstacle(velocity, friction), start_(start), end_(end), length_((end - start).norm()), radius_(radius)
{
    require_finite_point(start, "start of the capsule's segment");
    require_finite_point(end, "end of the capsule's segment");
    require_positive(radius, "capsule radius [m]");
    if (!(length_ > 0.0))
        throw Error("capsule: the segment's start and end must differ (a capsule around a point is a sphere)");
    axis_ = (end - start) / length_;
}

Eigen::Vector3d Capsule::closest(const Eigen::Vector3d& p) const
{
    return start_ + std::clamp(axis_.dot(p - start_), 0.0, length_) * axis_;
}

double Capsule::local_distance(const Eigen::Vector3d& p) const
{
    return (p - closest(p)).norm() - radius_;
}

Eigen::Vector3d Capsule::local_gradient(const Eigen::Vector3d& p) const
{
    const Eigen::Vector3d r = p - closest(p);
    const double length = r.norm();
    if (length > 0.0)
        return r / length;
    // On the segment itself, where the barrier never looks: any direction across it.
    const Eigen::Vector3d other = std::abs(axis_.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    return axis_.cross(other).normalized();
}

Eigen::Matrix3d Capsule::local_hessian(const Eigen::Vector3d& p) const
{
    const double along = axis_.dot(p - start_);
    const double length = (p - closest(p)).norm();
    if (!(length > 0.0))
        return Eigen::Matrix3d::Zero();
    const Eigen::Vector3d n = local_gradient(p);
    Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - n * n.transpose();
    if (along > 0.0 && along < length_)  // beside the segment: no curvature along the axis
        across -= axis_ * axis_.transpose();
    return across / length;
}

double Capsule::local_time_of_impact(const Eigen::Vector3d& p, const Eigen::Vector3d& dp) const
{
    // The first s where |p + s dp − c|² = r² (c a ball's centre): 2k/(−b + √(b² − 4ak)), as Sphere's.
    const auto ball = [&](const Eigen::Vector3d& centre) {
        const Eigen::Vector3d r = p - centre;
        const double a = dp.squaredNorm(), b = 2.0 * dp.dot(r), k = r.squaredNorm() - radius_ * radius_;
        const double discriminant = b * b - 4.0 * a * k;
        return b < 0.0 && discriminant >= 0.0 ? 2.0 * k / (-b + std::sqrt(discriminant)) : infinity;
    };
    double s = std::min(ball(start_), ball(end_));
    // The side: the same quadratic across the axis (the components of p − a and dp normal to e),
    // from outside the infinite cylinder, counted where its root lies between the ends.
    const Eigen::Vector3d w = (p - start_) - axis_.dot(p - start_) * axis_, v = dp - axis_.dot(dp) * axis_;
    const double a = v.squaredNorm(), b = 2.0 * v.dot(w), k = w.squaredNorm() - radius_ * radius_;
    const double discriminant = b * b - 4.0 * a * k;
    if (k > 0.0 && b < 0.0 && discriminant >= 0.0) {
        const double side = 2.0 * k / (-b + std::sqrt(discriminant));
        const double along = axis_.dot(p + side * dp - start_);
        if (along >= 0.0 && along <= length_)
            s = std::min(s, side);
    }
    return s;
}

TriMesh Capsule::local_surface(const std::array<double, 6>&) const
{
    return swept_ball_surface(start_, end_, radius_);
}

TriMesh swept_ball_surface(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius)
{
    constexpr int rings = 24, segments = 48;  // polar steps over π, points a ring
    const bool tube = (b - a).norm() > 0.0;
    const Eigen::Vector3d e = tube ? Eigen::Vector3d((b - a).normalized()) : Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d other = std::abs(e.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    const Eigen::Vector3d u = tube ? Eigen::Vector3d(e.cross(other).normalized()) : Eigen::Vector3d::UnitX();
    const Eigen::Vector3d w = e.cross(u);
    // Ring j's polar angle and centre: 0 … π/2 around b, then (a tube's second equator) π/2 … π around a.
    std::vector<std::pair<double, Eigen::Vector3d>> ring;
    for (int i = 0; i <= rings; ++i) {
        if (tube && 2 * i == rings)
            ring.emplace_back(M_PI * i / rings, b);
        ring.emplace_back(M_PI * i / rings, 2 * i < rings ? b : a);
    }
    const int count = static_cast<int>(ring.size());
    TriMesh surface;
    surface.V.resize(count * segments, 3);
    for (int i = 0; i < count; ++i)
        for (int j = 0; j < segments; ++j) {
            const double polar = ring[i].first, around = 2.0 * M_PI * j / segments;
            surface.V.row(i * segments + j) =
                (ring[i].second + radius * (std::sin(polar) * std::cos(around) * u +
                                            std::sin(polar) * std::sin(around) * w + std::cos(polar) * e)).transpose();
        }
    surface.F.resize(2 * (count - 1) * segments, 3);
    int row = 0;
    for (int i = 0; i + 1 < count; ++i)
        for (int j = 0; j < segments; ++j) {
            const int p = i * segments + j, q = i * segments + (j + 1) % segments;
            surface.F.row(row++) << p, p + segments, q + segments;
            surface.F.row(row++) << p, q + segments, q;
        }
    return surface;
}

ObstacleFeatures Sphere::local_core() const
{
    ObstacleFeatures core;
    core.corners = centre_.transpose();
    core.radius = radius_;
    return core;
}

ObstacleFeatures Capsule::local_core() const
{
    ObstacleFeatures core;
    core.corners.resize(2, 3);
    core.corners << start_.transpose(), end_.transpose();
    core.edges.resize(1, 2);
    core.edges << 0, 1;
    core.radius = radius_;
    return core;
}

}  // namespace fem::contact
