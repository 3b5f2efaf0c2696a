#pragma once
// Chapter 08: the sparse symmetric positive definite matrices the chapter factors, from the
// earlier chapters. docs/08_direct_solvers.md#the-test-matrices

#include "05_strain_stress/strain_stress.hpp"
#include "07_sparse_storage/sparse_formats.hpp"

namespace fem::direct {

/// −L of chapter 02 (heat::laplacian_matrix) for n×n unknowns: the 5-point Laplacian with zero
/// Dirichlet values, made positive definite by the sign: 4/h² on the diagonal, −1/h² for each
/// unknown neighbour, h = 1/(n+1), unknown k = i + n j. Both triangles stored.
/// fem::Error unless 1 ≤ n ≤ 20000. docs/08_direct_solvers.md#the-test-matrices
sparse::CscMatrix laplacian_2d(int n);

/// The 7-point Laplacian on n×n×n unknowns of the unit cube with zero Dirichlet values, positive
/// definite: 6/h² on the diagonal, −1/h² for each unknown neighbour, h = 1/(n+1), unknown
/// k = i + n (j + n l). Both triangles stored. Built from COO triplets with chapter 07's
/// conversions. fem::Error unless 1 ≤ n ≤ 1000. docs/08_direct_solvers.md#the-test-matrices
sparse::CscMatrix laplacian_3d(int n);

/// The stiffness matrix K (chapter 06) of the unit cube cut into cells³ cubes (6 tets each, box_mesh),
/// with the vertices of the face x = 0 pinned (removed from the unknowns): 3·cells·(cells+1)²
/// unknowns, vertex-major. Symmetric positive definite. fem::Error unless 1 ≤ cells ≤ 200 or for
/// an unstable material. docs/08_direct_solvers.md#the-test-matrices
sparse::CscMatrix box_stiffness(int cells, const elastic::Lame& material);

}  // namespace fem::direct
