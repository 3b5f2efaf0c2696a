#pragma once
// Chapter 03: the FEM Laplacian of a triangle mesh, its cotangent form, and the lumped mass.
// docs/03_triangle_gradients.md#the-fem-laplacian
//
// Sign convention: L is the stiffness matrix L_ij = ∫ ∇φ_i·∇φ_j, symmetric positive semi-definite
// with L_ii > 0 and zero row sums. It discretises −Δ (weakly): −Δu ≈ M⁻¹ L u, and the Poisson
// problem −Δu = f becomes L u = M f.

#include "03_triangle_gradients/triangle_gradients.hpp"

#include <vector>

namespace fem::tri {

/// The FEM Laplacian L = Gᵀ A G (|V|×|V|, sparse), with G = gradient_operator(V, F) and
/// A = diag(A_0, A_0, A_0, A_1, …) the area of each triangle repeated for its three gradient rows:
/// uᵀ L u = Σ_f A_f |∇u_f|² = ∫ |∇u|². Validates the mesh (fem::Error names a bad triangle).
/// docs/03_triangle_gradients.md#the-fem-laplacian
SparseMatrix fem_laplacian(const MatrixX3d& V, const MatrixX3i& F);

/// The same matrix from the classical cotangent formula, assembled triangle by triangle: the
/// corner k of a triangle, with angle θ_k, adds w = ½ cot θ_k to the edge (i, j) opposite it:
///   L_ij −= w,  L_ji −= w,  L_ii += w,  L_jj += w.
/// So L_ij = −½ (cot α_ij + cot β_ij) over the (one or two) triangles at edge ij. An obtuse angle
/// has a negative cotangent: an edge opposite obtuse angles can get a negative weight, i.e. a
/// positive off-diagonal L_ij. Validates the mesh like fem_laplacian.
/// docs/03_triangle_gradients.md#cotangent-weights
SparseMatrix cotangent_laplacian(const MatrixX3d& V, const MatrixX3i& F);

/// The lumped (barycentric) mass of every vertex, m_v = Σ_{f ∋ v} A_f / 3: each triangle gives a
/// third of its area to each corner. Σ m_v is the total area; it equals the row sums of the
/// consistent mass ∫ φ_i φ_j. Validates the mesh. docs/03_triangle_gradients.md#lumped-mass
Eigen::VectorXd lumped_mass(const MatrixX3d& V, const MatrixX3i& F);

/// The vertices on the boundary of the mesh (on an edge used by exactly one triangle), ascending;
/// empty for a closed surface. fem::Error for an index outside [0, vertex_count) or an edge used by
/// more than two triangles (not a manifold).
std::vector<int> boundary_vertices(const MatrixX3i& F, int vertex_count);

/// The number of edges whose cotangent weight ½(cot α + cot β) is negative (positive
/// off-diagonal L_ij): where the maximum principle of the discrete Laplacian can fail.
int negative_weight_edges(const SparseMatrix& L);

}  // namespace fem::tri
