#pragma once
// Chapter 03: gradients on triangle meshes. docs/03_triangle_gradients.md
//
// A function given by its values u_v at the vertices is interpolated linearly over every triangle
// with the hat functions φ_v (barycentric coordinates inside a triangle), so its gradient is
// constant on each triangle: ∇u = Σ_i u_i ∇φ_i with the lecture's ∇φ_i = e_i⊥ / (2A). Triangles
// live in 3D (V is #V×3), so everything here works on curved surfaces (the bunny) as well as in
// the plane; a gradient is then tangent to its triangle.
//
// Orientation: triangle (a, b, c) has the unit normal n̂ = (b − a) × (c − a) / |…|, so it is
// counter-clockwise seen from n̂. The edge opposite a corner is taken in that counter-clockwise
// order (e_a = c − b, e_b = a − c, e_c = b − a), and e⊥ = n̂ × e turns it by +90° in the
// triangle's plane: towards the corner it faces.

#include "common/types.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace fem::tri {

using SparseMatrix = Eigen::SparseMatrix<double>;  ///< column-major, built from triplets
using Matrix9d = Eigen::Matrix<double, 9, 9>;

/// Barycentric coordinates (λ_a, λ_b, λ_c) of point p in triangle abc (in 3D): the weights with
/// λ_a + λ_b + λ_c = 1 and λ_a a + λ_b b + λ_c c = p', the orthogonal projection of p onto the
/// triangle's plane (p' = p for a point in the plane). With n = (b − a) × (c − a):
///   λ_a = ((c − b) × (p − b))·n / |n|²,  λ_b = ((a − c) × (p − c))·n / |n|²,  λ_c = 1 − λ_a − λ_b
/// (signed area ratios). Inside the triangle all three lie in [0, 1]; λ_a is the hat function
/// φ_a at p. fem::Error for a triangle of zero area. docs/03_triangle_gradients.md#barycentric-coordinates
Eigen::Vector3d barycentric_coordinates(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                        const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// The lecture's local gradient matrix G_abc (3×3): column i is ∇φ_i = (n̂ × e_i) / (2A) for the
/// corners i = a, b, c, with e_a = c − b, e_b = a − c, e_c = b − a and A the triangle's area.
/// So G_abc (u_a, u_b, u_c)ᵀ = ∇u on the triangle. The columns sum to zero (the gradient of the
/// constant φ_a + φ_b + φ_c = 1), each is tangent to the triangle, and ∇φ_i·(x_j − x_k) = δ_ij − δ_ik.
/// fem::Error for a triangle of zero area. docs/03_triangle_gradients.md#hat-function-gradients
Eigen::Matrix3d hat_gradients(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// The area A_f of every triangle (#F). Validates the mesh (fem::Error names a bad triangle).
Eigen::VectorXd triangle_areas(const MatrixX3d& V, const MatrixX3i& F);

/// The global gradient operator G (3|F| × |V|, sparse, 9 entries per triangle): rows 3f, 3f+1,
/// 3f+2 hold G_f = hat_gradients of triangle f in the columns of its three vertices, so
/// (G u)_{3f+d} = ∂u/∂x_d on triangle f. Validates the mesh first: fem::Error names a degenerate
/// triangle (zero area), an index out of range or a non-finite vertex.
/// docs/03_triangle_gradients.md#the-gradient-operator
SparseMatrix gradient_operator(const MatrixX3d& V, const MatrixX3i& F);

/// The gradient of the piecewise-linear function u (one value per vertex) on every triangle,
/// #F×3: row f is ∇u on triangle f (G u, one row per triangle). fem::Error if u has not #V values.
MatrixX3d face_gradients(const MatrixX3d& V, const MatrixX3i& F, const Eigen::VectorXd& u);

/// The lecture's block Jacobian J_abc = diag(G_abc, G_abc, G_abc) (9×9) of a deformation (or
/// displacement) field u on triangle abc. It acts on the coordinate-major vector
/// (u_x,a, u_x,b, u_x,c, u_y,a, …, u_z,c) and returns (∇u_xᵀ, ∇u_yᵀ, ∇u_zᵀ): the rows of the
/// 3×3 Jacobian ∂u/∂x, i.e. vec(∂u/∂x) in row-major order. In the course's vertex-major ordering
/// (u_a, u_b, u_c, each xyz) the same map is J_abc P with P = coordinate_major_permutation(3).
/// fem::Error for a triangle of zero area. docs/03_triangle_gradients.md#the-block-jacobian
Matrix9d block_jacobian(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// The permutation matrix P (3n × 3n) that reorders a vertex-major vector q = (x_0, y_0, z_0,
/// x_1, …) of n vertices into the lecture's coordinate-major order (x_0, …, x_{n−1}, y_0, …,
/// y_{n−1}, z_0, …): (P q)_{c·n + v} = q_{3v + c}. P is orthogonal, P⁻¹ = Pᵀ.
/// fem::Error for n < 1. docs/03_triangle_gradients.md#the-block-jacobian
SparseMatrix coordinate_major_permutation(int n);

}  // namespace fem::tri
