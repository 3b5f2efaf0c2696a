#pragma once
// Chapter 04: tetrahedral shape functions and Jacobians. docs/04_tet_jacobians.md
//
// One linear tetrahedron with rest vertices X₀…X₃ (the rows of a 4×3 matrix X) and deformed
// vertices x₀…x₃ (the rows of x). Its shape functions φ₀…φ₃ are the barycentric coordinates, their
// gradients dφ/dX are constant, and so is the deformation gradient F = ∂x/∂X = Σᵢ xᵢ ∇φᵢᵀ.
//
// Orderings used everywhere in the course (docs/04_tet_jacobians.md#orderings):
//   q_e   = (x₀, y₀, z₀, x₁, y₁, z₁, …, z₃)          12 entries, VERTEX-MAJOR (like the global q);
//   vec(F) = (F₀₀, F₀₁, F₀₂, F₁₀, F₁₁, F₁₂, F₂₀, …)   9 entries, ROW-MAJOR (as in the notes 001).
// The lecture's J_e takes the COORDINATE-MAJOR blocks (u_x; u_y; u_z) instead; it is the same map
// with its columns permuted (coordinate_major_jacobian, coordinate_major_permutation).

#include "common/mesh.hpp"

#include <Eigen/Core>

#include <vector>

namespace fem::tet {

using TetVertices = Eigen::Matrix<double, 4, 3>;      ///< one vertex per row: X₀ … X₃
using ShapeGradients = Eigen::Matrix<double, 4, 3>;   ///< row i is ∇φᵢᵀ = dφᵢ/dX
using Jacobian = Eigen::Matrix<double, 9, 12>;         ///< vec(F) = B q_e (row-major vec, vertex-major q_e)

/// The four vertices of tetrahedron t of the mesh, taken from positions (#V×3: the rest positions
/// mesh.V or any deformed positions x), one per row. fem::Error if t is out of range or positions
/// has the wrong number of rows.
TetVertices tet_vertices(const TetMesh& mesh, const MatrixX3d& positions, int t);

/// Signed volume V = (X₁−X₀)·((X₂−X₀)×(X₃−X₀)) / 6 = det(T) / 6: positive for a positively
/// oriented tet (the convention of common/mesh.hpp), negative for an inverted one, zero for a flat
/// one. docs/04_tet_jacobians.md#signed-volume
double signed_volume(const TetVertices& X);

/// The edge matrix T = [X₁−X₀ | X₂−X₀ | X₃−X₀] (3×3, edges as columns), so that a point
/// X = X₀ + T (φ₁, φ₂, φ₃)ᵀ. docs/04_tet_jacobians.md#shape-functions
Eigen::Matrix3d edge_matrix(const TetVertices& X);

/// The barycentric coordinates (φ₀, φ₁, φ₂, φ₃) of point p: (φ₁, φ₂, φ₃) = T⁻¹ (p − X₀) and
/// φ₀ = 1 − φ₁ − φ₂ − φ₃ (notes 001). They sum to 1, reproduce p = Σ φᵢ Xᵢ, and are all in [0, 1]
/// exactly when p lies in the tet. fem::Error for a zero-volume tet (|6V| ≤ 1e-12·(longest edge)³).
/// docs/04_tet_jacobians.md#shape-functions
Eigen::Vector4d shape_functions(const TetVertices& X, const Eigen::Vector3d& p);

/// The constant gradients of the shape functions, dφ/dX (4×3, row i = ∇φᵢᵀ): rows 1…3 are the rows
/// of T⁻¹ and row 0 is −(sum of the rows of T⁻¹), so the rows sum to zero. ∇φᵢ is normal to the face
/// opposite vertex i, points towards vertex i and has length 1/(height over that face).
/// fem::Error for a zero-volume tet. docs/04_tet_jacobians.md#shape-function-gradients
ShapeGradients shape_gradients(const TetVertices& X);

/// The deformation gradient F = ∂x/∂X = Σᵢ xᵢ ∇φᵢᵀ = xᵀ (dφ/dX) (3×3), constant in the tet: rest
/// vertices X, deformed vertices x (both 4×3). F = I at rest; F = A for x = A X + b; det F < 0 when
/// the deformed tet is inverted. fem::Error for a zero-volume rest tet or non-finite x.
/// docs/04_tet_jacobians.md#deformation-gradient
Eigen::Matrix3d deformation_gradient(const TetVertices& X, const TetVertices& x);

/// B (9×12), the constant matrix with vec(F) = B q_e, where vec(F) is ROW-MAJOR
/// (F₀₀, F₀₁, F₀₂, F₁₀, …) and q_e = (x₀, y₀, z₀, x₁, …) is VERTEX-MAJOR. Its entries are
/// B(3a + b, 3i + a) = (dφᵢ/dX)(i, b) for a, b ∈ {0,1,2}, i ∈ {0…3}; zero elsewhere. The same matrix
/// maps displacements u_e to vec(∇u) = vec(F − I). This is the lecture's J_e with vertex-major
/// columns. fem::Error for a zero-volume tet. docs/04_tet_jacobians.md#the-jacobian-matrix
Jacobian jacobian_matrix(const TetVertices& X);

/// The lecture's J_e = diag(G, G, G) (9×12) with G = (dφ/dX)ᵀ (3×4): it takes the
/// COORDINATE-MAJOR vector (u_x₀…u_x₃, u_y₀…u_y₃, u_z₀…u_z₃) to the ROW-MAJOR vec(∇u)
/// = (∇u_x; ∇u_y; ∇u_z). It equals jacobian_matrix(X) · Pᵀ with P = coordinate_major_permutation().
/// docs/04_tet_jacobians.md#orderings
Jacobian coordinate_major_jacobian(const TetVertices& X);

/// The 12×12 permutation P that reorders a vertex-major q_e = (x₀, y₀, z₀, x₁, …) into the
/// coordinate-major (x₀, x₁, x₂, x₃, y₀, …, z₃): (P q_e)(4a + i) = q_e(3i + a).
/// docs/04_tet_jacobians.md#orderings
Eigen::Matrix<double, 12, 12> coordinate_major_permutation();

/// Where a point lies in a tet mesh.
struct PointLocation {
    bool inside = false;      ///< the point lies in tet `tet` (every φᵢ ≥ −tolerance)
    int tet = -1;             ///< the containing tet; if !inside, the tet whose smallest φᵢ is largest
    Eigen::Vector4d phi = Eigen::Vector4d::Zero();  ///< the barycentric coordinates of p in `tet`
};

/// Finds a tet of the mesh (rest positions mesh.V) that contains p, by testing each tet's
/// barycentric coordinates: the first tet with min φᵢ ≥ −tolerance. A point outside the mesh gets
/// inside = false and the tet it is "closest" to in the barycentric sense (largest min φᵢ), whose
/// φ extrapolates. O(#T) per point (chapter 13 locates many points). fem::Error for an empty mesh,
/// a zero-volume tet, a non-finite p or a negative tolerance.
/// docs/04_tet_jacobians.md#locating-a-point
PointLocation locate_point(const TetMesh& mesh, const Eigen::Vector3d& p, double tolerance = 1e-12);

/// The deformation gradient of every tet: F_t = deformation_gradient(rest tet t, deformed tet t),
/// with rest positions mesh.V and deformed positions x (#V×3). fem::Error if x has the wrong
/// number of rows or a rest tet is flat (naming the tet). docs/04_tet_jacobians.md#deformation-gradient
std::vector<Eigen::Matrix3d> deformation_gradients(const TetMesh& mesh, const MatrixX3d& x);

}  // namespace fem::tet
