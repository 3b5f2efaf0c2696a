#pragma once
// Chapter 05: strain, stress and the element stiffness of linear elasticity.
// docs/05_strain_stress.md
//
// The Voigt convention of the course (docs/05_strain_stress.md#the-voigt-convention):
//   strain vector ε = (ε_xx, ε_yy, ε_zz, γ_xy, γ_yz, γ_zx) with ENGINEERING shear γ_ab = 2 ε_ab,
//   stress vector σ = (σ_xx, σ_yy, σ_zz, σ_xy, σ_yz, σ_zx) (plain tensor entries),
//   C (6×6) with λ + 2μ, λ on the normal block and μ (not 2μ) on the shear diagonal,
// so that σ = C ε gives σ_xy = 2μ ε_xy, and σᵀε = σ : ε counts each shear pair twice, as the tensor
// contraction does. The lecture's D (½ on the shear rows) with μ on C's diagonal undercounts the
// shear energy by 4×; see the docs.
//
// Orderings from chapter 04: element displacements u_e = (u_x0, u_y0, u_z0, u_x1, …) are VERTEX-MAJOR;
// vec(∇u) is ROW-MAJOR (∂u_x/∂X, ∂u_x/∂Y, ∂u_x/∂Z, ∂u_y/∂X, …).

#include "04_tet_jacobians/tet_jacobians.hpp"

#include <Eigen/Core>

namespace fem::elastic {

using Vector6d = Eigen::Matrix<double, 6, 1>;                ///< a strain or stress in Voigt order
using Matrix6d = Eigen::Matrix<double, 6, 6>;                ///< C
using StrainSelection = Eigen::Matrix<double, 6, 9>;         ///< D
using StrainDisplacement = Eigen::Matrix<double, 6, 12>;     ///< B_e = D J_e
using Matrix12d = Eigen::Matrix<double, 12, 12>;             ///< K_e

/// The Lamé parameters of an isotropic material.
struct Lame {
    double lambda = 0.0;  ///< λ [Pa]
    double mu = 0.0;      ///< μ, the shear modulus [Pa]
};

/// Lamé parameters from Young's modulus Y and Poisson's ratio ν:
///   μ = Y / (2(1 + ν)),   λ = ν Y / ((1 + ν)(1 − 2ν)).
/// λ/μ = 2ν/(1 − 2ν) grows without bound as ν → ½ (incompressible). fem::Error, naming the parameter
/// and the allowed range, unless Y is finite and > 0 and −1 < ν < 0.5.
/// docs/05_strain_stress.md#lamé-parameters
Lame lame_parameters(double youngs_modulus, double poisson_ratio);

/// fem::Error unless μ > 0 and the bulk modulus λ + 2μ/3 > 0 (the range −1 < ν < ½), both finite.
void require_stable(const Lame& material);

/// D (6×9): picks the engineering strain out of the ROW-MAJOR vec(∇u):
///   ε_xx = ∂u_x/∂X = vec[0],  ε_yy = vec[4],  ε_zz = vec[8],
///   γ_xy = ∂u_x/∂Y + ∂u_y/∂X = vec[1] + vec[3],  γ_yz = vec[5] + vec[7],  γ_zx = vec[6] + vec[2].
/// Only 1s and 0s (the lecture writes 0.5 on the shear rows: tensor shear, see the docs).
/// docs/05_strain_stress.md#the-strain-selection-matrix-d
StrainSelection strain_selection_matrix();

/// B_e = D J_e (6×12), constant in the tet: ε = B_e u_e, with u_e VERTEX-MAJOR and J_e the 9×12
/// matrix of chapter 04 (tet::jacobian_matrix: vec(∇u) = J_e u_e, row-major vec). fem::Error for a
/// zero-volume tet. docs/05_strain_stress.md#the-strain-displacement-matrix-b_e
StrainDisplacement strain_displacement_matrix(const tet::TetVertices& X);

/// The small (linearised) strain from the deformation gradient F = I + ∇u:
///   ε = ½(∇u + ∇uᵀ) = ½(F + Fᵀ) − I   (3×3, symmetric).
/// Exact to first order in ∇u; NOT zero under a finite rotation (ε = (cos θ − 1)(I − n nᵀ) for F = R).
/// docs/05_strain_stress.md#linear-and-green-strain
Eigen::Matrix3d small_strain(const Eigen::Matrix3d& F);

/// The Green–Lagrange strain E = ½(FᵀF − I) (3×3, symmetric): zero for every rotation, and equal to
/// the small strain plus ½ ∇uᵀ∇u. docs/05_strain_stress.md#linear-and-green-strain
Eigen::Matrix3d green_strain(const Eigen::Matrix3d& F);

/// A symmetric strain tensor as a Voigt vector with engineering shear:
/// (e_xx, e_yy, e_zz, 2e_xy, 2e_yz, 2e_zx). docs/05_strain_stress.md#the-voigt-convention
Vector6d strain_to_voigt(const Eigen::Matrix3d& strain);

/// A Voigt stress vector (σ_xx, σ_yy, σ_zz, σ_xy, σ_yz, σ_zx) as the symmetric 3×3 tensor.
/// docs/05_strain_stress.md#the-voigt-convention
Eigen::Matrix3d stress_to_tensor(const Vector6d& stress);

/// C (6×6) for the engineering-strain Voigt convention: λ + 2μ on the normal diagonal, λ off it in
/// the normal block, μ on the shear diagonal, zero elsewhere. σ = C ε reproduces
/// σ = λ tr(ε) I + 2μ ε. fem::Error unless require_stable(material) passes.
/// docs/05_strain_stress.md#the-elasticity-matrix-c
Matrix6d elasticity_matrix(const Lame& material);

/// The stress σ = C ε (Voigt, engineering strain in, tensor-entry stress out).
/// docs/05_strain_stress.md#the-elasticity-matrix-c
Vector6d stress(const Lame& material, const Vector6d& strain);

/// The strain energy density of linear isotropic elasticity, from the 3×3 strain TENSOR:
///   ψ = μ ε:ε + (λ/2) tr(ε)² = ½ σ:ε   [J/m³]. ε must be symmetric (fem::Error otherwise).
/// docs/05_strain_stress.md#strain-energy
double energy_density(const Lame& material, const Eigen::Matrix3d& strain);

/// The element stiffness K_e = V B_eᵀ C B_e (12×12, symmetric positive semi-definite), V the rest
/// volume |signed volume|, so that the element's energy is U_e = ½ u_eᵀ K_e u_e = V ψ(ε) with u_e
/// VERTEX-MAJOR. Its null space is exactly the 6 rigid modes (3 translations, 3 infinitesimal
/// rotations). fem::Error for a zero-volume tet or an unstable material.
/// docs/05_strain_stress.md#the-element-stiffness-k_e
Matrix12d element_stiffness(const tet::TetVertices& X, const Lame& material);

/// The von Mises stress √(½[(σ_xx−σ_yy)² + (σ_yy−σ_zz)² + (σ_zz−σ_xx)²] + 3(σ_xy² + σ_yz² + σ_zx²))
/// of a Voigt stress vector: √(3/2 s:s) with s the deviatoric stress; zero under pure pressure.
/// docs/05_strain_stress.md#von-mises-stress
double von_mises(const Vector6d& stress);

}  // namespace fem::elastic
