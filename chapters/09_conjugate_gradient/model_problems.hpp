#pragma once
// Chapter 09: what the chapter solves. The 2D and 3D grid Laplacians are chapter 08's
// (direct::laplacian_2d, direct::laplacian_3d); their condition number is known in closed form.
// The elastic box is chapter 08's box_stiffness with its mesh, pinning and load: a whole problem
// K u = f whose solution can be drawn. docs/09_conjugate_gradient.md#the-test-problems

#include "05_strain_stress/strain_stress.hpp"
#include "common/mesh.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <vector>

namespace fem::cg {

/// κ₂ = λ_max / λ_min of direct::laplacian_2d(n) and direct::laplacian_3d(n) (the same for both):
/// λ = (4/h²) Σ_d sin²(k_d π h / 2), so κ = cot²(π h / 2) ≈ (2 (n+1) / π)². fem::Error for n < 1.
/// docs/09_conjugate_gradient.md#the-test-problems
double laplacian_condition_number(int n);

/// A box of elastic material clamped on its face x = 0 and loaded by its weight: the reduced
/// system K u = f of chapter 06 (pinned dofs removed), K being chapter 08's box_stiffness.
struct ElasticBox {
    TetMesh mesh;                    ///< box_mesh(cells, cells, cells): a unit cube
    std::vector<int> pinned;         ///< the vertices on x = 0
    Eigen::SparseMatrix<double> P;   ///< 3n × 3n_free, q = P u (chapter 06)
    Eigen::SparseMatrix<double> K;   ///< Pᵀ K P = direct::box_stiffness, SPD, both triangles
    Eigen::VectorXd f;               ///< Pᵀ (gravity load), g = (0, 0, −9.81)
};

/// The unit cube cut into cells³ cubes (6 tets each), material (Y, ν), density ρ, clamped at x = 0:
/// 3 (cells+1)² cells unknowns. fem::Error unless 1 ≤ cells ≤ 200, for an unstable material or ρ ≤ 0.
/// docs/09_conjugate_gradient.md#the-test-problems
ElasticBox clamped_box(int cells, const elastic::Lame& material, double density);

}  // namespace fem::cg
