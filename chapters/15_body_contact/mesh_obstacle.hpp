#pragma once
// Chapter 15: a static triangle mesh as an obstacle (a bowl, stairs, any .obj surface), and its
// distance sampled on a grid, the cheaper and coarser alternative. docs/15_body_contact.md#mesh-obstacles
//
// The distance of a point x to a triangle surface is the distance to its nearest triangle,
//     d(x) = min_f |x − q_f(x)|,   q_f(x) the point of triangle f closest to x,
// found with chapter 13's AABB tree (box_hierarchy over the triangles' boxes). The distance is
// UNSIGNED (d ≥ 0 on both sides; IPC's convention): a mesh need not be closed (a bowl is a sheet),
// and the barrier keeps each vertex on the side it starts on, so no inside is ever needed. Its
// gradient and Hessian depend on the feature of the nearest triangle that holds q (d = |x − q|,
// g = (x − q)/d):
//     face:   ∇d = g (the triangle's normal, ±),   ∇²d = 0                      (a plane)
//     edge:   ∇d = g,   ∇²d = (I − e eᵀ − g gᵀ)/d   (e: the edge's unit direction; a cylinder)
//     vertex: ∇d = g,   ∇²d = (I − g gᵀ)/d                                     (a sphere)
// Its time of impact is where the vertex's straight path first meets a triangle (a ray cast:
// Möller–Trumbore on the triangles the tree finds along the path), each triangle grown by a relative
// 10⁻⁹ at its edges so that a path through a shared edge or corner is caught whatever the round-off.

#include "14_contact/obstacles.hpp"

#include "13_skinning/skinning.hpp"

#include "common/mesh.hpp"

#include <Eigen/Core>

#include <string>
#include <utility>
#include <vector>

namespace fem::contact {

/// The feature of a triangle that holds its point closest to p.
enum class TriangleFeature { face, edge, vertex };

/// The point of a triangle closest to p, and where it lies.
struct TrianglePoint {
    Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< q
    TriangleFeature feature = TriangleFeature::face;
    /// edge: its first corner i (the edge from corner i to corner (i + 1) mod 3); vertex: the corner
    /// (0, 1, 2 for a, b, c); face: 0.
    int corner = 0;
};

/// The point q of the triangle (a, b, c) closest to p, and its feature, by the feature that
/// point_triangle_type (distances.hpp, exercise 14.5) names: a corner; an edge's point
/// xᵢ + t (xⱼ − xᵢ), t = (p − xᵢ)·(xⱼ − xᵢ)/|xⱼ − xᵢ|²; or p's projection onto the triangle's plane
/// (face). fem::Error as point_triangle_type (a non-finite coordinate, a zero-area triangle).
/// docs/15_body_contact.md#distance-to-a-triangle
TrianglePoint closest_triangle_point(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                     const Eigen::Vector3d& c);

/// Below this sine of the angle between two neighbouring triangles' normals their shared edge is flat.
inline constexpr double flat_mesh_edge_sine = 1e-3;

/// A static (or translating) triangle surface as an obstacle, with the unsigned distance of the
/// header. docs/15_body_contact.md#mesh-obstacles
class MeshObstacle final : public Obstacle {
public:
    /// surface: the triangles where they stand (placed already) [m]. fem::Error (from validate, its
    /// messages starting with `what`) for an empty mesh, a non-finite coordinate, an index out of
    /// range or a degenerate triangle; as Obstacle for the friction and velocity.
    explicit MeshObstacle(TriMesh surface, double friction = 0.0,
                          const Eigen::Vector3d& velocity = Eigen::Vector3d::Zero(),
                          const std::string& what = "mesh obstacle");
    std::string name() const override { return "mesh"; }
    /// d₀(p) = min_f |p − q_f| ≥ 0 (unsigned: no inside) [m].
    double local_distance(const Eigen::Vector3d& p) const override;
    /// (p − q)/d of the nearest triangle's closest point q (unit; (0, 0, 1) at d = 0, where the
    /// barrier never looks).
    Eigen::Vector3d local_gradient(const Eigen::Vector3d& p) const override;
    /// By the feature of q (header): 0, (I − e eᵀ − g gᵀ)/d or (I − g gᵀ)/d.
    Eigen::Matrix3d local_hessian(const Eigen::Vector3d& p) const override;
    /// One piece per triangle within reach of p (by the tree): its distance |p − q_f|, (p − q_f)/d and
    /// the Hessian of q_f's feature — but for a piece whose q_f lies on a flat edge or a corner of a
    /// flat fan, which counts only when no triangle of that edge or fan has a nearer point (and, of
    /// triangles whose points coincide, the lowest-numbered). Summed, their barriers are smooth
    /// across the mesh's creases, and over a flat region p feels one plane's barrier, no lateral push.
    void local_pieces(const Eigen::Vector3d& p, double reach, std::vector<DistancePiece>& pieces) const override;
    /// The first s in [0, 2] where p + s·dp meets a triangle (Möller–Trumbore: the plane's root s with
    /// barycentric u, v ≥ −10⁻⁹, u + v ≤ 1 + 10⁻⁹), +∞ when none does; a path parallel to a
    /// triangle's plane misses it unless it runs in that plane, where conservative_time_of_impact
    /// answers; 0 when d₀(p) = 0.
    double local_time_of_impact(const Eigen::Vector3d& p, const Eigen::Vector3d& dp) const override;
    /// Its sharp edges — on the border (one triangle), shared by three or more, or where two
    /// triangles meet at an angle, |n₁ × n₂| > flat_mesh_edge_sine or n₁·n₂ < 0 (unit normals, of
    /// the two triangles oriented alike across the edge) — and
    /// the corners on them. An edge between two coplanar triangles is no feature: the triangles'
    /// own barriers already hold the body there.
    ObstacleFeatures local_features() const override;

    /// The nearest triangle of p (the lowest-numbered one of equal distance found first), its
    /// closest point and the distance.
    struct Nearest {
        int triangle = -1;
        TrianglePoint closest;
        double distance = 0.0;
    };
    /// By the AABB tree: depth first from the root, nearer child first, skipping every node and
    /// triangle whose box is no nearer than the nearest triangle found so far.
    Nearest nearest(const Eigen::Vector3d& p) const;
    /// By testing every triangle (the reference the tree is checked and timed against).
    Nearest nearest_brute_force(const Eigen::Vector3d& p) const;

    /// Whether the segment from x0 to x1 (rest frame) meets a triangle, touching included: the signed
    /// volumes of (x0, triangle) and (x1, triangle) differ in sign (or one is 0) and the line x0 x1
    /// passes through the triangle (the three volumes (x0, x1, edge) agree in sign). The triangles
    /// whose boxes meet the segment's box are found with the tree. What a scene reader uses to
    /// refuse a body that starts through a sheet, where every vertex may be far from it.
    bool crosses(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1) const override;
    /// False: its distance is unsigned (a sheet).
    bool has_inside() const override { return false; }

    /// Its triangles, as surface() (around is not needed).
    TriMesh local_surface(const std::array<double, 6>& /*around*/) const override { return surface_; }

    /// The triangles at the rest placement [m] (at time t the obstacle stands at V + t·velocity()).
    const TriMesh& surface() const { return surface_; }
    /// The nodes of its AABB tree.
    int tree_nodes() const { return static_cast<int>(tree_.nodes.size()); }

private:
    /// The triangles whose boxes meet the box [low, high] (by the tree).
    std::vector<int> triangles_meeting(const Eigen::Vector3d& low, const Eigen::Vector3d& high) const;
    /// Triangle f's piece at p, from its closest point.
    DistancePiece piece(int f, const TrianglePoint& closest, const Eigen::Vector3d& p) const;
    /// The closest point of triangle f to p.
    TrianglePoint closest_on(int f, const Eigen::Vector3d& p) const;
    /// Whether triangle f's piece at p, of closest point q, is left out: q lies on (within same_point_,
    /// or, where flat triangles meet at a small angle, 2 flat_mesh_edge_sine |p − q|) an edge of f
    /// shared with a flat neighbour g, or at a corner of f whose flat fan holds g, and g's closest
    /// point to p is nearer (|p − q_g| < |p − q|), or as near and g < f. known: the
    /// closest points to p already computed (triangle, point); g's is taken from there when it is.
    bool shadowed(int f, const Eigen::Vector3d& closest, const Eigen::Vector3d& p,
                  const std::vector<std::pair<int, TrianglePoint>>& known) const;

    TriMesh surface_;
    std::vector<Eigen::Matrix<double, 2, 3>> boxes_;  // per triangle, rows min and max
    skin::BoxHierarchy tree_;
    /// Per triangle f and edge i (from corner i to corner i + 1), at 3f + i: the triangle across the
    /// edge when the edge is flat (two triangles, coplanar by flat_mesh_edge_sine), else −1.
    std::vector<int> flat_neighbour_;
    /// Per triangle f and corner k, at 3f + k: the other triangles of the corner's flat fan, those
    /// reached from f by turning about the corner across flat edges.
    std::vector<std::vector<int>> flat_fan_;
    double same_point_ = 0.0;  // a closest point this near an edge or corner is on it [m]: 10⁻⁷ of the mesh's box diagonal
};

/// The unsigned distance of a mesh obstacle sampled at the nodes of a regular grid (spacing h at
/// most the given one) over its bounding box grown by a margin, trilinear in between: one cell
/// lookup a query, whatever the mesh, but only approximate — O(h²) where d is smooth, up to about
/// h/2 near the surface, where |x − q| has its kink (the interpolant of a V does not reach 0).
/// docs/15_body_contact.md#a-sampled-distance-grid
class DistanceGrid {
public:
    /// Samples mesh.local_distance at every node (by the tree). fem::Error for spacing or margin
    /// not a finite number > 0 (margin ≥ 0), or a grid of more than 5e7 nodes.
    DistanceGrid(const MeshObstacle& mesh, double spacing, double margin);
    /// The trilinear interpolant at p [m]; outside the grid, its value at the nearest point of the
    /// grid's box plus the distance to that point (an upper bound, by the triangle inequality).
    double distance(const Eigen::Vector3d& p) const;
    /// The interpolant's gradient inside the grid (3; piecewise, as trilinear interpolation is).
    Eigen::Vector3d gradient(const Eigen::Vector3d& p) const;
    /// Nodes along x, y, z.
    const Eigen::Vector3i& dims() const { return dims_; }
    /// The spacing along x, y, z [m].
    const Eigen::Vector3d& spacing() const { return spacing_; }

private:
    /// The cell of p (clamped to the grid) and p's coordinates in it, each in [0, 1].
    void locate(const Eigen::Vector3d& p, Eigen::Vector3i& cell, Eigen::Vector3d& t) const;
    double node(int i, int j, int k) const { return values_[(static_cast<std::size_t>(k) * dims_.y() + j) * dims_.x() + i]; }

    Eigen::Vector3d low_, high_, spacing_;
    Eigen::Vector3i dims_;
    std::vector<double> values_;
};

}  // namespace fem::contact
