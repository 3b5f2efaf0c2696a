#pragma once
// Chapter 14: obstacles — rigid shapes the body must stay out of, fixed or moving with a constant
// velocity, each with a signed distance d(x) (> 0 outside, < 0 inside), its gradient ∇d (the unit
// outward normal) and Hessian ∇²d, and the time of impact of a straight vertex path.
// docs/14_contact.md#obstacles
//
// A moving obstacle translates: at time t it is its rest placement shifted by t·w (w: its velocity),
// so d(x, t) = d₀(x − t w), where d₀ is the distance to the rest placement. Every function taking a
// point in the obstacle's rest frame is named local_*; the public ones take the time.

#include "common/mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace fem::contact {

/// One piece of an obstacle as a point sees it: the point's distance to the piece [m], its gradient
/// (3) and Hessian (3×3). The barrier is summed over the pieces within d̂ (IPC: one barrier per pair).
struct DistancePiece {
    double distance = 0.0;
    Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
    Eigen::Matrix3d hessian = Eigen::Matrix3d::Zero();
};

/// The sharp features of an obstacle at its rest placement: corners (#c×3) [m] and edges (#e×2, rows
/// of two corners), which chapter 14's FeatureBarrier keeps the body's surface triangles and edges
/// away from (feature_barrier.hpp). Empty for a smooth obstacle.
struct ObstacleFeatures {
    Eigen::MatrixX3d corners;
    Eigen::MatrixX2i edges;
    /// The rounding: the obstacle is the points within radius of its corners and edges [m] (a
    /// sphere's core is its centre, a capsule's its segment: Obstacle::local_core); 0 for sharp ones.
    double radius = 0.0;
};

/// A rigid obstacle. The body's vertices are kept at d > 0 by chapter 14's barrier.
class Obstacle {
public:
    /// velocity: w [m/s] (finite); friction: Coulomb's μ ≥ 0 between it and the body.
    /// fem::Error for a non-finite velocity or μ < 0 (or not finite).
    Obstacle(const Eigen::Vector3d& velocity, double friction);
    virtual ~Obstacle() = default;

    /// A short name for tables, e.g. "half-space".
    virtual std::string name() const = 0;

    /// d₀(p): the signed distance of p from the rest placement [m] (> 0 outside).
    virtual double local_distance(const Eigen::Vector3d& p) const = 0;
    /// ∇d₀(p) (3): the outward unit normal of the nearest surface point (outside).
    virtual Eigen::Vector3d local_gradient(const Eigen::Vector3d& p) const = 0;
    /// ∇²d₀(p) (3×3, symmetric) [1/m]: 0 for a plane or a box face, (I − n nᵀ)/|p − c| for a sphere.
    virtual Eigen::Matrix3d local_hessian(const Eigen::Vector3d& p) const = 0;
    /// The first s ≥ 0 at which the path p + s·dp (p outside, d₀(p) > 0) reaches d₀ = 0, or +∞ when
    /// it never does. Exact for a half-space, a sphere, a capsule and a box; a mesh's falls back to a
    /// conservative s (never beyond the true one) for a path in a triangle's plane.
    virtual double local_time_of_impact(const Eigen::Vector3d& p, const Eigen::Vector3d& dp) const = 0;

    /// The pieces p feels within reach, appended to pieces: a half-space, a sphere or a box is one
    /// piece, itself (when d₀(p) < reach); a mesh one per triangle within reach (over a flat region
    /// only the plane's one: MeshObstacle::local_pieces). Where the pieces meet at an angle (a mesh's
    /// creases) the nearest one's distance has a kink, the sum of their barriers does not.
    /// docs/15_body_contact.md#mesh-obstacles
    virtual void local_pieces(const Eigen::Vector3d& p, double reach, std::vector<DistancePiece>& pieces) const;

    /// Its corners and edges at the rest placement (ObstacleFeatures; default: none, a smooth shape).
    virtual ObstacleFeatures local_features() const { return {}; }
    /// A rounded obstacle's core at the rest placement: the points and segments it is the points
    /// within ObstacleFeatures::radius of (a sphere: its centre; a capsule: its segment), so that
    /// chapter 15's FeatureBarrier holds it off the body's triangles and edges, not only its
    /// vertices (docs/15_body_contact.md#edges-and-corners-of-obstacles); default: none.
    virtual ObstacleFeatures local_core() const { return {}; }

    /// The triangles it is drawn as at the rest placement (V #V×3 [m], F #F×3): a solid's surface, a
    /// mesh's own triangles. A half-space has no edge: it is drawn as the square of its plane under
    /// `around` = (xmin, xmax, ymin, ymax, zmin, zmax) [m] (the box's corners projected on the plane,
    /// grown by a fifth of the box's diagonal each way); the others ignore around.
    /// docs/14_contact.md#obstacles
    virtual TriMesh local_surface(const std::array<double, 6>& around) const = 0;

    /// Whether d₀ has an inside (< 0): true for a solid (the default); false for a sheet of triangles,
    /// whose distance is unsigned, so that a body must start beyond d̂ of it, and an edge of a body
    /// may pass through it with both ends clear (crosses).
    virtual bool has_inside() const { return true; }
    /// Whether the segment from x0 to x1 (rest frame) passes through a sheet of the obstacle (see
    /// MeshObstacle::crosses); false for a solid (the default), whose start is checked at the vertices.
    virtual bool crosses(const Eigen::Vector3d& /*x0*/, const Eigen::Vector3d& /*x1*/) const { return false; }

    /// d(x, t) = d₀(x − t w) [m].
    double distance(const Eigen::Vector3d& x, double time) const { return local_distance(x - time * velocity_); }
    /// ∇d(x, t) (3).
    Eigen::Vector3d gradient(const Eigen::Vector3d& x, double time) const { return local_gradient(x - time * velocity_); }
    /// ∇²d(x, t) (3×3).
    Eigen::Matrix3d hessian(const Eigen::Vector3d& x, double time) const { return local_hessian(x - time * velocity_); }
    /// The pieces x feels within reach at time t (local_pieces), appended to pieces.
    void pieces(const Eigen::Vector3d& x, double time, double reach, std::vector<DistancePiece>& pieces) const
    {
        local_pieces(x - time * velocity_, reach, pieces);
    }
    /// The time of impact of x + s·dx against the obstacle held at time t (s ≥ 0, +∞: none).
    double time_of_impact(const Eigen::Vector3d& x, const Eigen::Vector3d& dx, double time) const
    {
        return local_time_of_impact(x - time * velocity_, dx);
    }
    /// Its drawn triangles at time t: local_surface(around − t w) moved by t w (around: as there, at t).
    TriMesh surface_at(const std::array<double, 6>& around, double time) const;

    const Eigen::Vector3d& velocity() const { return velocity_; }
    double friction() const { return friction_; }

private:
    Eigen::Vector3d velocity_;
    double friction_;
};

/// Conservative advancement along p + s·dp for an obstacle whose d₀ is 1-Lipschitz (|∇d₀| ≤ 1: a
/// mesh's): from s = 0, s ← s + d₀(p + s dp)/|dp| — the path cannot lose more distance
/// than its length, so no s it reaches lies beyond the first zero of d₀ — stopped at the first s
/// where d₀ has fallen to 5 % of its start (or after 100 advances); +∞ when the path does not reach
/// the obstacle by s = 2 (callers step at most s = 1); 0 when d₀(p) ≤ 0.
/// docs/14_contact.md#continuous-collision-detection
double conservative_time_of_impact(const Obstacle& obstacle, const Eigen::Vector3d& p, const Eigen::Vector3d& dp);

/// The half-space {x : n·(x − p) < 0} below the plane through p with unit normal n (a floor, a
/// slope): d = n·(x − p), ∇d = n, ∇²d = 0; time of impact d/(−n·dx) when n·dx < 0.
class HalfSpace final : public Obstacle {
public:
    /// fem::Error for a zero or non-finite normal (it is normalised, of any finite size) or a
    /// non-finite point. The plane is kept by its point nearest the origin, (n·p) n, so that a point
    /// given far along the plane costs no digits of d.
    HalfSpace(const Eigen::Vector3d& point, const Eigen::Vector3d& normal, double friction = 0.0,
              const Eigen::Vector3d& velocity = Eigen::Vector3d::Zero());
    std::string name() const override { return "half-space"; }
    double local_distance(const Eigen::Vector3d& p) const override;
    Eigen::Vector3d local_gradient(const Eigen::Vector3d& p) const override;
    Eigen::Matrix3d local_hessian(const Eigen::Vector3d& p) const override;
    double local_time_of_impact(const Eigen::Vector3d& p, const Eigen::Vector3d& dp) const override;
    /// The square of its plane under around (two triangles).
    TriMesh local_surface(const std::array<double, 6>& around) const override;
    const Eigen::Vector3d& normal() const { return normal_; }

private:
    Eigen::Vector3d point_, normal_;
};

/// A solid ball of centre c and radius r: d = |x − c| − r, ∇d = n = (x − c)/|x − c|,
/// ∇²d = (I − n nᵀ)/|x − c|; the time of impact is the smaller root of |x + s dx − c|² = r².
class Sphere final : public Obstacle {
public:
    /// fem::Error for r ≤ 0 or a non-finite centre.
    Sphere(const Eigen::Vector3d& centre, double radius, double friction = 0.0,
           const Eigen::Vector3d& velocity = Eigen::Vector3d::Zero());
    std::string name() const override { return "sphere"; }
    double local_distance(const Eigen::Vector3d& p) const override;
    Eigen::Vector3d local_gradient(const Eigen::Vector3d& p) const override;
    Eigen::Matrix3d local_hessian(const Eigen::Vector3d& p) const override;
    double local_time_of_impact(const Eigen::Vector3d& p, const Eigen::Vector3d& dp) const override;
    /// A triangulated ball (swept_ball_surface(c, c, r)).
    TriMesh local_surface(const std::array<double, 6>& around) const override;
    /// Its centre, radius r.
    ObstacleFeatures local_core() const override;

private:
    Eigen::Vector3d centre_;
    double radius_;
};

/// A solid box: centre c, axes the columns of the rotation R, half extents h. In box coordinates
/// q = Rᵀ(x − c), with e = |q| − h (per axis): outside d = |max(e, 0)| (the nearest face, edge or
/// corner), inside d = max eᵢ. ∇d = R (sign(q) ∘ max(e, 0))/d outside; ∇²d = R (P_A − n nᵀ)/d Rᵀ with
/// P_A the diagonal of the axes where eᵢ > 0 (0 on a face, a cylinder's on an edge, a sphere's at a
/// corner). Its time of impact is exact, by the slab test (local_time_of_impact).
class Box final : public Obstacle {
public:
    /// fem::Error for a half extent ≤ 0, a rotation that is not orthonormal with det +1 (to 1e-9),
    /// or a non-finite centre.
    Box(const Eigen::Vector3d& centre, const Eigen::Vector3d& half_extents,
        const Eigen::Matrix3d& rotation = Eigen::Matrix3d::Identity(), double friction = 0.0,
        const Eigen::Vector3d& velocity = Eigen::Vector3d::Zero());
    std::string name() const override { return "box"; }
    double local_distance(const Eigen::Vector3d& p) const override;
    Eigen::Vector3d local_gradient(const Eigen::Vector3d& p) const override;
    Eigen::Matrix3d local_hessian(const Eigen::Vector3d& p) const override;
    /// Exact (the slab test): with q = Rᵀ(p − c), w = Rᵀ dp, the path is in slab i, |q_i + s w_i| ≤ h_i,
    /// between s = (±h_i − q_i)/w_i; the first s ≥ 0 in all three (the latest entry, when no later
    /// than the earliest exit), +∞ when there is none; 0 when d₀(p) ≤ 0.
    double local_time_of_impact(const Eigen::Vector3d& p, const Eigen::Vector3d& dp) const override;
    /// Its 8 corners c + R (±h₀, ±h₁, ±h₂) and 12 edges.
    ObstacleFeatures local_features() const override;
    /// Its 6 faces (12 triangles, outward).
    TriMesh local_surface(const std::array<double, 6>& around) const override;

private:
    Eigen::Vector3d centre_, half_;
    Eigen::Matrix3d rotation_;
};

/// A solid capsule: the points within r of the segment from a to b (a rod, a rail, a pipe). With
/// e = (b − a)/|b − a| and c(x) = a + clamp((x − a)·e, 0, |b − a|) e the segment's closest point:
/// d = |x − c| − r, ∇d = n = (x − c)/|x − c|; ∇²d = (I − e eᵀ − n nᵀ)/|x − c| beside the segment (a
/// cylinder's) and (I − n nᵀ)/|x − c| beyond an end (a sphere's). The time of impact is exact: the
/// earliest of the side's root (the infinite cylinder's, where it lies between the ends) and each
/// end ball's (Sphere's). Smooth: no features. docs/14_contact.md#obstacles
class Capsule final : public Obstacle {
public:
    /// fem::Error for r ≤ 0 (or not finite), a non-finite end, or a <= 0 segment length |b − a|.
    Capsule(const Eigen::Vector3d& start, const Eigen::Vector3d& end, double radius, double friction = 0.0,
            const Eigen::Vector3d& velocity = Eigen::Vector3d::Zero());
    std::string name() const override { return "capsule"; }
    double local_distance(const Eigen::Vector3d& p) const override;
    Eigen::Vector3d local_gradient(const Eigen::Vector3d& p) const override;
    Eigen::Matrix3d local_hessian(const Eigen::Vector3d& p) const override;
    double local_time_of_impact(const Eigen::Vector3d& p, const Eigen::Vector3d& dp) const override;
    /// A triangulated tube with a half ball at each end (swept_ball_surface(a, b, r)).
    TriMesh local_surface(const std::array<double, 6>& around) const override;

    /// Its segment (two corners, one edge), radius r.
    ObstacleFeatures local_core() const override;

private:
    /// The closest point of the segment to p.
    Eigen::Vector3d closest(const Eigen::Vector3d& p) const;
    Eigen::Vector3d start_, end_, axis_;  // axis_: the unit e
    double length_, radius_;
};

/// The surface swept by a ball of radius r from a to b, drawn with 48 points a ring: 13 rings of a
/// half ball around b (polar angles 0 … π/2 from e = (b − a)/|b − a|), 13 of a half ball around a
/// (π/2 … π), joined by a tube; one ball when a = b (e = z then). V ((26 or 25)·48 × 3) [m], F outward.
TriMesh swept_ball_surface(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius);

}  // namespace fem::contact
