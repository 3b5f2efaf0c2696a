#include "12_hyperelastic_newton/materials.hpp"

#include "common/error.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include <cmath>
#include <limits>

namespace fem::hyper {
namespace {

/// The Levi-Civita symbol ε_ijk.
double levi_civita(int i, int j, int k)
{
    return 0.5 * double((j - i) * (k - i) * (k - j));
}

/// fem::Error unless F is finite.
void require_finite(const Eigen::Matrix3d& F, std::string_view material)
{
    if (!F.allFinite())
        throw Error(str(material, ": F has a non-finite entry"));
}

/// G = F⁻ᵀ and ln J for the neo-Hookean material; fem::Error for J ≤ 0.
Eigen::Matrix3d inverse_transpose(const Eigen::Matrix3d& F, double& log_J)
{
    require_finite(F, "neo-hookean");
    const double J = F.determinant();
    if (!(J > 0.0))
        throw Error(str("neo-hookean: det F = ", J, " <= 0 (an inverted or flat element), where ln J is undefined; "
                        "use stable-neo-hookean, or a line search that rejects inverting steps"));
    log_J = std::log(J);
    return F.inverse().transpose();
}

}  // namespace

Vector9d flatten(const Eigen::Matrix3d& F)
{
    Vector9d v;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
            v[3 * a + b] = F(a, b);
    return v;
}

Eigen::Matrix3d cofactor(const Eigen::Matrix3d& F)
{
    Eigen::Matrix3d C;
    C.row(0) = F.row(1).cross(F.row(2));
    C.row(1) = F.row(2).cross(F.row(0));
    C.row(2) = F.row(0).cross(F.row(1));
    return C;
}

// --- St. Venant–Kirchhoff -----------------------------------------------------------------------

double StVenantKirchhoff::energy_density(const Eigen::Matrix3d& F) const
{
    require_finite(F, name());
    const Eigen::Matrix3d E = elastic::green_strain(F);
    return lame().mu * E.squaredNorm() + 0.5 * lame().lambda * E.trace() * E.trace();
}

Eigen::Matrix3d StVenantKirchhoff::first_piola(const Eigen::Matrix3d& F) const
{
    require_finite(F, name());
    const Eigen::Matrix3d E = elastic::green_strain(F);
    const Eigen::Matrix3d S = 2.0 * lame().mu * E + lame().lambda * E.trace() * Eigen::Matrix3d::Identity();
    return F * S;
}

Matrix9d StVenantKirchhoff::piola_derivative(const Eigen::Matrix3d& F) const
{
    require_finite(F, name());
    const double mu = lame().mu, lambda = lame().lambda;
    const Eigen::Matrix3d E = elastic::green_strain(F);
    const Eigen::Matrix3d S = 2.0 * mu * E + lambda * E.trace() * Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d FFt = F * F.transpose();
    Matrix9d dP;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
            for (int c = 0; c < 3; ++c)
                for (int d = 0; d < 3; ++d)
                    dP(3 * a + b, 3 * c + d) = (a == c ? S(d, b) : 0.0) +
                                               mu * (F(a, d) * F(c, b) + (b == d ? FFt(a, c) : 0.0)) +
                                               lambda * F(a, b) * F(c, d);
    return dP;
}

// --- neo-Hookean ----------------------------------------------------------------------------------

double NeoHookean::energy_density(const Eigen::Matrix3d& F) const
{
    require_finite(F, name());
    const double J = F.determinant();
    if (!(J > 0.0))
        return std::numeric_limits<double>::infinity();
    const double log_J = std::log(J);
    return 0.5 * lame().mu * (F.squaredNorm() - 3.0) - lame().mu * log_J + 0.5 * lame().lambda * log_J * log_J;
}

Eigen::Matrix3d NeoHookean::first_piola(const Eigen::Matrix3d& F) const
{
    double log_J = 0.0;
    const Eigen::Matrix3d G = inverse_transpose(F, log_J);
    return lame().mu * (F - G) + lame().lambda * log_J * G;
}

Matrix9d NeoHookean::piola_derivative(const Eigen::Matrix3d& F) const
{
    double log_J = 0.0;
    const Eigen::Matrix3d G = inverse_transpose(F, log_J);
    const double mu = lame().mu, lambda = lame().lambda;
    Matrix9d dP;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
            for (int c = 0; c < 3; ++c)
                for (int d = 0; d < 3; ++d)
                    dP(3 * a + b, 3 * c + d) = (a == c && b == d ? mu : 0.0) +
                                               (mu - lambda * log_J) * G(a, d) * G(c, b) + lambda * G(a, b) * G(c, d);
    return dP;
}

// --- stable neo-Hookean -------------------------------------------------------------------------

double StableNeoHookean::energy_density(const Eigen::Matrix3d& F) const
{
    require_finite(F, name());
    const double lambda = lame().lambda + lame().mu, J = F.determinant();
    return 0.5 * lame().mu * (F.squaredNorm() - 3.0) - lame().mu * (J - 1.0) + 0.5 * lambda * (J - 1.0) * (J - 1.0);
}

Eigen::Matrix3d StableNeoHookean::first_piola(const Eigen::Matrix3d& F) const
{
    require_finite(F, name());
    const double lambda = lame().lambda + lame().mu, J = F.determinant();
    return lame().mu * F + (lambda * (J - 1.0) - lame().mu) * cofactor(F);
}

Matrix9d StableNeoHookean::piola_derivative(const Eigen::Matrix3d& F) const
{
    require_finite(F, name());
    const double mu = lame().mu, lambda = lame().lambda + mu, J = F.determinant();
    const Vector9d C = flatten(cofactor(F));
    Matrix9d dP = mu * Matrix9d::Identity() + lambda * C * C.transpose();
    const double weight = lambda * (J - 1.0) - mu;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
            for (int c = 0; c < 3; ++c)
                for (int d = 0; d < 3; ++d) {
                    double hessian_of_J = 0.0;  // ∂²J/∂F_ab∂F_cd = ε_ack ε_bdl F_kl
                    for (int k = 0; k < 3; ++k)
                        for (int l = 0; l < 3; ++l)
                            hessian_of_J += levi_civita(a, c, k) * levi_civita(b, d, l) * F(k, l);
                    dP(3 * a + b, 3 * c + d) += weight * hessian_of_J;
                }
    return dP;
}

// --- factory and projection ---------------------------------------------------------------------

std::vector<std::string> material_names()
{
    return {"stvk", "neo-hookean", "stable-neo-hookean"};
}

std::unique_ptr<Material> make_material(std::string_view name, double youngs_modulus, double poisson_ratio)
{
    const elastic::Lame lame = elastic::lame_parameters(youngs_modulus, poisson_ratio);
    if (name == "stvk")
        return std::make_unique<StVenantKirchhoff>(lame);
    if (name == "neo-hookean")
        return std::make_unique<NeoHookean>(lame);
    if (name == "stable-neo-hookean")
        return std::make_unique<StableNeoHookean>(lame);
    throw Error(str("unknown material '", name, "' (stvk, neo-hookean, stable-neo-hookean)"));
}

template <int N>
Eigen::Matrix<double, N, N> project_to_psd(const Eigen::Matrix<double, N, N>& A, Projection projection)
{
    using Matrix = Eigen::Matrix<double, N, N>;
    if (!A.allFinite())
        throw Error("project_to_psd: the matrix has a non-finite entry");
    const Eigen::SelfAdjointEigenSolver<Matrix> eigen(Matrix(0.5 * (A + A.transpose())));
    Eigen::Matrix<double, N, 1> values = eigen.eigenvalues();
    for (int i = 0; i < N; ++i)
        if (values[i] < 0.0)
            values[i] = projection == Projection::clamp ? 0.0 : -values[i];
    return eigen.eigenvectors() * values.asDiagonal() * eigen.eigenvectors().transpose();
}

template Eigen::Matrix<double, 9, 9> project_to_psd<9>(const Eigen::Matrix<double, 9, 9>&, Projection);
template Eigen::Matrix<double, 12, 12> project_to_psd<12>(const Eigen::Matrix<double, 12, 12>&, Projection);

}  // namespace fem::hyper
