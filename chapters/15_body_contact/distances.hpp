#pragma once
// Chapter 15: the squared distances between surface primitives that incremental potential contact
// (IPC, Li et al. 2020) puts under its barrier — a point and a triangle, two edges — each with its
// gradient and Hessian, and the mollifier of nearly parallel edges.
// docs/15_body_contact.md#distances-between-primitives
//
// Classify first, then compute: the type says which features hold the closest points (a corner, the
// inside of an edge, the inside of the triangle), read from the closest point's barycentric or
// parametric coordinates; each type's d² is one smooth closed form, the squared distance from a
// point w₀ to the span of k = 0, 1 or 2 directions v₁, v₂:
//     k = 0:  |w₀|²                         point–point
//     k = 1:  |w₀ × v₁|² / |v₁|²            point–line    (w₀ = p − a, v₁ = b − a)
//     k = 2:  (w₀·(v₁ × v₂))² / |v₁ × v₂|²  point–plane, line–line
// and its gradient and Hessian come from the same form (w₀ and the v's are differences of the
// stacked points x; the minimiser y of F(x, y) = |w₀ + Σ y_k v_k|² gives ∇d² = F_x and
// ∇²d² = F_xx − F_xy F_yy⁻¹ F_yx, the implicit function theorem). Across a type's border d² and ∇d²
// are continuous (the closest points move continuously); ∇²d² jumps.
//
// Every function refuses (fem::Error, naming the argument) a non-finite coordinate, a zero-length
// edge (|e| ≤ 10⁻¹⁴ × its endpoints' largest coordinate) and a zero-area triangle (twice its area
// ≤ 2·10⁻¹⁴ × its longest edge², the rule of fem::validate).

#include <Eigen/Core>

namespace fem::contact {

using Vector12d = Eigen::Matrix<double, 12, 1>;
using Matrix12d = Eigen::Matrix<double, 12, 12>;

/// A function of two primitives' 12 stacked coordinates (p, a, b, c or ea0, ea1, eb0, eb1, each 3),
/// with its gradient (12) and Hessian (12×12).
struct PrimitiveFunction {
    double value = 0.0;
    Vector12d gradient = Vector12d::Zero();
    Matrix12d hessian = Matrix12d::Zero();
};

/// Which features of a triangle (a, b, c) hold the point closest to p: a corner (point–point), the
/// inside of an edge (point–line; edge_ab runs from a to b) or the inside of the triangle
/// (point–plane).
enum class PointTriangleType { corner_a, corner_b, corner_c, edge_ab, edge_bc, edge_ca, face };

/// The type of the point of triangle (a, b, c) closest to p (each 3): with t_ij = (p − x_i)·(x_j −
/// x_i)/|x_j − x_i|² (p's parameter along edge ij) and λ_k p's barycentric coordinate of the corner
/// opposite edge ij (of its projection onto the plane), corner i when t_ij ≤ 0 and t_ki ≥ 1; edge
/// ij when λ_k < 0 and 0 < t_ij < 1; else the face. fem::Error for a non-finite coordinate or a
/// zero-area triangle. docs/15_body_contact.md#distances-between-primitives
PointTriangleType point_triangle_type(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                      const Eigen::Vector3d& c);

/// d² of the given type between p and the triangle (a, b, c) (each 3), with its gradient and
/// Hessian with respect to (p, a, b, c) [12]: |p − x_i|² (corner i), |(p − x_i) × (x_j − x_i)|² /
/// |x_j − x_i|² (edge ij), ((p − a)·n)²/|n|², n = (b − a) × (c − a) (face). Smooth for any p:
/// outside its region a type gives the distance to its feature's line or plane, a lower bound (or,
/// for a corner, an upper one). fem::Error as point_triangle_type.
/// docs/15_body_contact.md#distances-between-primitives
PrimitiveFunction point_triangle_squared_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                                  const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                                  PointTriangleType type);

/// Which features of edges a = (ea0, ea1) and b = (eb0, eb1) hold their closest points: two
/// endpoints (a0_b0: ea0 and eb0, …), an endpoint and the inside of the other edge (a0_edge_b: ea0
/// and a point inside edge b, …), or the insides of both (edge_edge: line–line).
enum class EdgeEdgeType { a0_b0, a0_b1, a1_b0, a1_b1, a0_edge_b, a1_edge_b, b0_edge_a, b1_edge_a, edge_edge };

/// sin² of the angle θ between two edges at or below which they count as parallel (10⁻¹⁰) and take
/// an endpoint type: its d² is then within 2 sin²θ min(|e_a|², |e_b|²) of the true one, while the
/// line–line form's round-off grows as ε_mach/sinθ (its n = e_a × e_b has an absolute error
/// ~ε_mach |e_a||e_b|). The two meet near sin³θ ≈ 2 ε_mach; at sin²θ = 10⁻¹⁰ each is ~10⁻¹⁰ |e|².
inline constexpr double parallel_edges_sin2 = 1e-10;

/// The type of the closest points of edges (ea0, ea1) and (eb0, eb1) (each 3): edge_edge when the
/// edges are not parallel (|e_a × e_b|² > parallel_edges_sin2 |e_a|²|e_b|², e_a = ea1 − ea0) and the
/// lines' closest points ea0 + s e_a, eb0 + t e_b have 0 < s, t < 1; otherwise the closest points lie
/// on the border of the square 0 ≤ s, t ≤ 1: at an endpoint y and its closest point q on the other
/// edge (its parameter (y − x₀)·e/|e|² clamped: an endpoint at 0 or 1, the edge inside), the first
/// of the four where (y − q)·(y' − y) ≥ 0 (y' the other end of y's edge: the optimality condition).
/// Parallel edges thus always take an endpoint type. fem::Error for a non-finite coordinate or a
/// zero-length edge. docs/15_body_contact.md#distances-between-primitives
EdgeEdgeType edge_edge_type(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1, const Eigen::Vector3d& eb0,
                            const Eigen::Vector3d& eb1);

/// d² of the given type between edges (ea0, ea1) and (eb0, eb1) (each 3), with its gradient and
/// Hessian with respect to (ea0, ea1, eb0, eb1) [12]: |x − y|² (two endpoints), the point–line
/// form (an endpoint and an edge), ((ea0 − eb0)·(e_a × e_b))²/|e_a × e_b|² (edge_edge). fem::Error as
/// edge_edge_type, and for edge_edge of parallel edges (sin² ≤ parallel_edges_sin2).
/// docs/15_body_contact.md#distances-between-primitives
PrimitiveFunction edge_edge_squared_distance(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                                             const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1, EdgeEdgeType type);

/// IPC's threshold of the edge–edge mollifier, ε_x = 10⁻³ |ea1 − ea0|² |eb1 − eb0|² of the edges at
/// rest (each 3) [m⁴]. fem::Error for a non-finite coordinate or a zero-length edge.
/// docs/15_body_contact.md#distances-between-primitives
double edge_edge_mollifier_threshold(const Eigen::Vector3d& ea0_rest, const Eigen::Vector3d& ea1_rest,
                                     const Eigen::Vector3d& eb0_rest, const Eigen::Vector3d& eb1_rest);

/// IPC's edge–edge mollifier m(c) = −c²/ε_x² + 2c/ε_x for c < ε_x, 1 from ε_x on, of
/// c = |(ea1 − ea0) × (eb1 − eb0)|² (each point 3), with its gradient m'(c) ∇c and Hessian
/// m''(c) ∇c ∇cᵀ + m'(c) ∇²c with respect to (ea0, ea1, eb0, eb1) [12]: C¹ at c = ε_x (m = 1,
/// m' = 0 from both sides; m'' jumps from −2/ε_x² to 0), 0 for parallel edges. Multiplying the
/// edges' barrier by it takes the barrier away smoothly as they turn parallel, where the edge–edge
/// distance is not smooth (its line–line form divides by c → 0). fem::Error for a non-finite coordinate or
/// ε_x not a finite number > 0. docs/15_body_contact.md#distances-between-primitives
PrimitiveFunction edge_edge_mollifier(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                                      const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1, double threshold);

}  // namespace fem::contact
