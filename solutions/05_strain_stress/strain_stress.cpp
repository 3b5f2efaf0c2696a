// Chapter 05: strain, stress, Lamé parameters and the element stiffness K_e.
// docs/05_strain_stress.md
#include "05_strain_stress/strain_stress.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <cmath>

namespace fem::elastic {

Lame lame_parameters(double youngs_modulus, double poisson_ratio)
{
    if (!(std::isfinite(youngs_modulus) && youngs_modulus > 0.0))
        throw Error(str("Young's modulus Y must be a finite number > 0 [Pa], got ", youngs_modulus));
    if (!(poisson_ratio > -1.0 && poisson_ratio < 0.5))
        throw Error(str("Poisson's ratio nu must lie in the open interval (-1, 0.5), got ", poisson_ratio,
                        " (nu = 0.5 is incompressible: lambda would be infinite)"));
    // BEGIN EXERCISE 05.1 lame_parameters #lamé-parameters
    // HINT: μ = Y / (2(1 + ν)) and λ = ν Y / ((1 + ν)(1 − 2ν)).
    const double mu = youngs_modulus / (2.0 * (1.0 + poisson_ratio));
    const double lambda = poisson_ratio * youngs_modulus / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio));
    return Lame{lambda, mu};
    // END EXERCISE
}

void require_stable(const Lame& material)
{
    if (!(std::isfinite(material.mu) && material.mu > 0.0))
        throw Error(str("the shear modulus mu must be a finite number > 0 [Pa], got ", material.mu));
    if (!(std::isfinite(material.lambda) && material.lambda + 2.0 * material.mu / 3.0 > 0.0))
        throw Error(str("the Lame parameter lambda must be finite with lambda + 2 mu / 3 > 0 (a positive bulk "
                        "modulus, -1 < nu < 0.5), got lambda = ", material.lambda, ", mu = ", material.mu));
}

StrainSelection strain_selection_matrix()
{
    // BEGIN EXERCISE 05.2 strain_selection_matrix #the-strain-selection-matrix-d
    // HINT: entry 3a + b of the row-major vec(∇u) is ∂u_a/∂X_b. Engineering shear γ_xy is the SUM
    // HINT: ∂u_x/∂Y + ∂u_y/∂X: two 1s, not two ½s.
    StrainSelection D = StrainSelection::Zero();
    const auto at = [](int a, int b) { return 3 * a + b; };
    D(0, at(0, 0)) = 1.0;
    D(1, at(1, 1)) = 1.0;
    D(2, at(2, 2)) = 1.0;
    D(3, at(0, 1)) = D(3, at(1, 0)) = 1.0;  // γ_xy
    D(4, at(1, 2)) = D(4, at(2, 1)) = 1.0;  // γ_yz
    D(5, at(2, 0)) = D(5, at(0, 2)) = 1.0;  // γ_zx
    return D;
    // END EXERCISE
}

StrainDisplacement strain_displacement_matrix(const tet::TetVertices& X)
{
    const tet::Jacobian J = tet::jacobian_matrix(X);  // validates X
    // BEGIN EXERCISE 05.3 strain_displacement_matrix #the-strain-displacement-matrix-b_e
    // HINT: one matrix product.
    return strain_selection_matrix() * J;
    // END EXERCISE
}

Eigen::Matrix3d small_strain(const Eigen::Matrix3d& F)
{
    // BEGIN EXERCISE 05.4 small_strain #linear-and-green-strain
    // HINT: ∇u = F − I; take its symmetric part.
    return 0.5 * (F + F.transpose()) - Eigen::Matrix3d::Identity();
    // END EXERCISE
}

Eigen::Matrix3d green_strain(const Eigen::Matrix3d& F)
{
    // BEGIN EXERCISE 05.5 green_strain #linear-and-green-strain
    // HINT: compare squared lengths: dxᵀdx − dXᵀdX = dXᵀ(FᵀF − I)dX.
    return 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
    // END EXERCISE
}

Vector6d strain_to_voigt(const Eigen::Matrix3d& e)
{
    Vector6d v;
    v << e(0, 0), e(1, 1), e(2, 2), e(0, 1) + e(1, 0), e(1, 2) + e(2, 1), e(2, 0) + e(0, 2);
    return v;
}

Eigen::Matrix3d stress_to_tensor(const Vector6d& s)
{
    Eigen::Matrix3d sigma;
    sigma << s[0], s[3], s[5],
             s[3], s[1], s[4],
             s[5], s[4], s[2];
    return sigma;
}

Matrix6d elasticity_matrix(const Lame& material)
{
    require_stable(material);
    // BEGIN EXERCISE 05.6 elasticity_matrix #the-elasticity-matrix-c
    // HINT: σ_xx = (λ + 2μ) ε_xx + λ ε_yy + λ ε_zz, and σ_xy = 2μ ε_xy = μ γ_xy.
    const double lambda = material.lambda, mu = material.mu;
    Matrix6d C = Matrix6d::Zero();
    C.topLeftCorner<3, 3>().setConstant(lambda);
    C.topLeftCorner<3, 3>().diagonal().array() += 2.0 * mu;
    C.bottomRightCorner<3, 3>().diagonal().setConstant(mu);
    return C;
    // END EXERCISE
}

Vector6d stress(const Lame& material, const Vector6d& strain)
{
    return elasticity_matrix(material) * strain;
}

double energy_density(const Lame& material, const Eigen::Matrix3d& strain)
{
    require_stable(material);
    const double scale = std::max(1.0, strain.cwiseAbs().maxCoeff());
    if (!((strain - strain.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * scale))
        throw Error("energy_density: the strain tensor must be symmetric (got entries that differ by more than "
                    "1e-12 across the diagonal); pass small_strain(F) or green_strain(F)");
    // BEGIN EXERCISE 05.7 energy_density #strain-energy
    // HINT: ε:ε = Σ_ab ε_ab² (all nine entries); tr(ε) = ε_xx + ε_yy + ε_zz.
    const double trace = strain.trace();
    return material.mu * strain.squaredNorm() + 0.5 * material.lambda * trace * trace;
    // END EXERCISE
}

Matrix12d element_stiffness(const tet::TetVertices& X, const Lame& material)
{
    const StrainDisplacement B = strain_displacement_matrix(X);  // validates X
    const Matrix6d C = elasticity_matrix(material);                // validates the material
    const double volume = std::abs(tet::signed_volume(X));
    // BEGIN EXERCISE 05.8 element_stiffness #the-element-stiffness-k_e
    // HINT: U_e = ½ V εᵀ C ε with ε = B_e u_e; K_e is the Hessian of U_e.
    return volume * B.transpose() * C * B;
    // END EXERCISE
}

double von_mises(const Vector6d& s)
{
    // BEGIN EXERCISE 05.9 von_mises #von-mises-stress
    // HINT: the normal-stress differences squared, halved, plus three times the shear stresses squared.
    const double normal = (s[0] - s[1]) * (s[0] - s[1]) + (s[1] - s[2]) * (s[1] - s[2]) + (s[2] - s[0]) * (s[2] - s[0]);
    const double shear = s[3] * s[3] + s[4] * s[4] + s[5] * s[5];
    return std::sqrt(0.5 * normal + 3.0 * shear);
    // END EXERCISE
}

}  // namespace fem::elastic
