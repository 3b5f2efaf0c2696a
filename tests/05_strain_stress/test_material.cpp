// Chapter 05: Lamé parameters, the Voigt convention (D and C), stress, energy density, von Mises.
// Every check compares with the tensor formulas σ = λ tr(ε) I + 2μ ε and ψ = μ ε:ε + (λ/2) tr(ε)²,
// written out here independently of the Voigt code. docs/05_strain_stress.md
#include "05_strain_stress/strain_stress.hpp"
#include "rubber.hpp"

#include "common/error.hpp"

#include "04_tet_jacobians/tet_fixtures.hpp"
#include "common/test_support.hpp"
#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <cmath>
#include <random>

using namespace fem::elastic;
using fem::test::random_matrix;
using fem::test::row_major_vec;
using Catch::Matchers::Contains;
using fem::test::rubber;
using fem::test::EntriesNear;
using fem::test::entries_of;

namespace {

Eigen::Matrix3d tensor_stress(const Lame& m, const Eigen::Matrix3d& eps)
{
    return m.lambda * eps.trace() * Eigen::Matrix3d::Identity() + 2.0 * m.mu * eps;
}

double tensor_energy(const Lame& m, const Eigen::Matrix3d& eps)
{
    double contraction = 0.0;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
            contraction += eps(a, b) * eps(a, b);
    return m.mu * contraction + 0.5 * m.lambda * eps.trace() * eps.trace();
}

}  // namespace

TEST_CASE("Lamé parameters from Y and nu: known values and the inverse formulas", "[ex05.1]")
{
    const Lame r = lame_parameters(1e5, 0.45);
    CHECK(r.mu == Approx(1e5 / 2.9).epsilon(1e-14));
    CHECK(r.lambda == Approx(0.45e5 / (1.45 * 0.1)).epsilon(1e-13));
    const Lame zero = lame_parameters(2.0, 0.0);
    CHECK(zero.lambda == 0.0);
    CHECK(zero.mu == Approx(1.0).epsilon(1e-15));
    const Lame quarter = lame_parameters(1.0, 0.25);  // λ = μ = 0.4 Y
    CHECK(quarter.lambda == Approx(0.4).epsilon(1e-14));
    CHECK(quarter.mu == Approx(0.4).epsilon(1e-14));
    // Back to Y = μ(3λ + 2μ)/(λ + μ) and ν = λ / (2(λ + μ)), including auxetic ν < 0.
    for (double nu : {-0.9, -0.3, 0.1, 0.3, 0.49, 0.4999}) {
        const Lame m = lame_parameters(3e6, nu);
        CHECK(m.mu * (3 * m.lambda + 2 * m.mu) / (m.lambda + m.mu) == Approx(3e6).epsilon(1e-11));
        CHECK(m.lambda / (2 * (m.lambda + m.mu)) == Approx(nu).epsilon(1e-11));
    }
}

TEST_CASE("Lamé parameters: bad Y or nu is an fem::Error naming the parameter and its range", "[ex05.1]")
{
    CHECK_THROWS_AS(lame_parameters(0.0, 0.3), fem::Error);
    CHECK_THROWS_WITH(lame_parameters(-1e5, 0.3), Contains("Young's modulus") && Contains("> 0"));
    CHECK_THROWS_WITH(lame_parameters(std::nan(""), 0.3), Contains("Young's modulus"));
    for (double nu : {0.5, 0.7, -1.0, -2.0, std::nan("")}) {
        CHECK_THROWS_AS(lame_parameters(1e5, nu), fem::Error);
        CHECK_THROWS_WITH(lame_parameters(1e5, nu), Contains("Poisson's ratio") && Contains("(-1, 0.5)"));
    }
    // Just inside the range is fine, and λ/μ = 2ν/(1 − 2ν) grows without bound.
    const Lame m = lame_parameters(1e5, 0.49999);
    CHECK(m.lambda / m.mu == Approx(2 * 0.49999 / (1 - 2 * 0.49999)).epsilon(1e-9));
}

TEST_CASE("D picks the engineering strain out of the row-major vec(grad u)", "[ex05.2]")
{
    const StrainSelection D = strain_selection_matrix();
    for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 9; ++c)
            CHECK((D(r, c) == 0.0 || D(r, c) == 1.0));
    std::mt19937 random(3);
    for (int k = 0; k < 10; ++k) {
        const Eigen::Matrix3d grad_u = random_matrix(random);
        const Eigen::Matrix3d eps = 0.5 * (grad_u + grad_u.transpose());
        Vector6d want;
        want << eps(0, 0), eps(1, 1), eps(2, 2), 2 * eps(0, 1), 2 * eps(1, 2), 2 * eps(2, 0);
        CHECK((D * row_major_vec(grad_u) - want).norm() == Approx(0.0).margin(1e-14));
        // An infinitesimal rotation (skew gradient) has no strain.
        CHECK((D * row_major_vec(grad_u - grad_u.transpose())).norm() == Approx(0.0).margin(1e-14));
    }
}

TEST_CASE("C: sigma = C eps reproduces lambda tr(eps) I + 2 mu eps, and pure shear gives sigma_xy = 2 mu eps_xy",
          "[ex05.6]")
{
    const Matrix6d C = elasticity_matrix(rubber);
    CHECK((C - C.transpose()).norm() == 0.0);
    std::mt19937 random(8);
    for (int k = 0; k < 10; ++k) {
        const Eigen::Matrix3d A = random_matrix(random);
        const Eigen::Matrix3d eps = 0.5 * (A + A.transpose());
        const Eigen::Matrix3d sigma = stress_to_tensor(C * strain_to_voigt(eps));
        CHECK((sigma - tensor_stress(rubber, eps)).norm() ==
              Approx(0.0).margin(1e-9 * tensor_stress(rubber, eps).norm()));
    }
    // Pure shear ε_xy = ε_yx = g: σ_xy = 2μg, nothing else.
    const double g = 1e-3;
    Eigen::Matrix3d shear = Eigen::Matrix3d::Zero();
    shear(0, 1) = shear(1, 0) = g;
    const Vector6d s = stress(rubber, strain_to_voigt(shear));
    CHECK(s[3] == Approx(2.0 * rubber.mu * g).epsilon(1e-14));
    CHECK(s.norm() == Approx(2.0 * rubber.mu * g).epsilon(1e-14));
    // Its eigenvalues: 3λ + 2μ (volume), 2μ twice (normal deviatoric), μ three times (shear).
    Eigen::SelfAdjointEigenSolver<Matrix6d> eig(C);
    const Eigen::VectorXd values = eig.eigenvalues();
    const double mu = rubber.mu, lambda = rubber.lambda;
    const Vector6d want = (Vector6d() << mu, mu, mu, 2 * mu, 2 * mu, 3 * lambda + 2 * mu).finished();
    CHECK_THAT(entries_of(values), EntriesNear(want, 0.0, 1e-12));
}

TEST_CASE("C rejects unstable materials with fem::Error", "[ex05.6]")
{
    CHECK_THROWS_AS(elasticity_matrix(Lame{1.0, 0.0}), fem::Error);
    CHECK_THROWS_WITH(elasticity_matrix(Lame{1.0, -2.0}), Contains("mu"));
    CHECK_THROWS_WITH(elasticity_matrix(Lame{-1.0, 1.0}), Contains("lambda"));
    CHECK(elasticity_matrix(Lame{-0.5, 1.0})(0, 0) == Approx(1.5));  // ν < 0 is allowed
}

TEST_CASE("energy density: known states, and half sigma:eps from the tensor formulas", "[ex05.7]")
{
    const double mu = rubber.mu, lambda = rubber.lambda, e = 2e-3;
    Eigen::Matrix3d uniaxial = Eigen::Matrix3d::Zero();
    uniaxial(0, 0) = e;
    CHECK(energy_density(rubber, uniaxial) == Approx((mu + lambda / 2) * e * e).epsilon(1e-14));
    Eigen::Matrix3d shear = Eigen::Matrix3d::Zero();
    shear(1, 2) = shear(2, 1) = e;
    CHECK(energy_density(rubber, shear) == Approx(2 * mu * e * e).epsilon(1e-14));
    CHECK(energy_density(rubber, e * Eigen::Matrix3d::Identity()) ==
          Approx(4.5 * (lambda + 2 * mu / 3) * e * e).epsilon(1e-14));  // (9/2) K e², K the bulk modulus
    std::mt19937 random(12);
    for (int k = 0; k < 10; ++k) {
        const Eigen::Matrix3d A = random_matrix(random);
        const Eigen::Matrix3d eps = 0.5 * (A + A.transpose());
        const double half_contraction = 0.5 * (tensor_stress(rubber, eps).array() * eps.array()).sum();
        CHECK(energy_density(rubber, eps) == Approx(half_contraction).epsilon(1e-12));
        // The Voigt form ½ σᵀε with engineering shear is the same number.
        const Vector6d v = strain_to_voigt(eps);
        CHECK(0.5 * v.dot(elasticity_matrix(rubber) * v) == Approx(tensor_energy(rubber, eps)).epsilon(1e-12));
    }
    Eigen::Matrix3d skew = Eigen::Matrix3d::Zero();
    skew(0, 1) = 1e-3;
    CHECK_THROWS_AS(energy_density(rubber, skew), fem::Error);
    CHECK_THROWS_WITH(energy_density(rubber, skew), Contains("symmetric"));
}

TEST_CASE("von Mises stress: uniaxial, pressure, pure shear, and invariance under rotation", "[ex05.9]")
{
    Vector6d uniaxial = Vector6d::Zero();
    uniaxial[1] = -250.0;
    CHECK(von_mises(uniaxial) == Approx(250.0).epsilon(1e-14));
    Vector6d pressure;
    pressure << -7.0, -7.0, -7.0, 0.0, 0.0, 0.0;
    CHECK(von_mises(pressure) == Approx(0.0).margin(1e-13));
    Vector6d shear = Vector6d::Zero();
    shear[5] = 10.0;
    CHECK(von_mises(shear) == Approx(std::sqrt(3.0) * 10.0).epsilon(1e-14));
    // √(3/2 s:s), s = σ − tr(σ)/3 I, for random stresses, and unchanged by a rotation R σ Rᵀ.
    std::mt19937 random(21);
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, -0.5).normalized()).toRotationMatrix();
    for (int k = 0; k < 10; ++k) {
        const Eigen::Matrix3d A = random_matrix(random);
        const Eigen::Matrix3d sigma = A + A.transpose();
        const Eigen::Matrix3d s = sigma - sigma.trace() / 3.0 * Eigen::Matrix3d::Identity();
        Vector6d v, w;
        const Eigen::Matrix3d turned = R * sigma * R.transpose();
        v << sigma(0, 0), sigma(1, 1), sigma(2, 2), sigma(0, 1), sigma(1, 2), sigma(2, 0);
        w << turned(0, 0), turned(1, 1), turned(2, 2), turned(0, 1), turned(1, 2), turned(2, 0);
        CHECK(von_mises(v) == Approx(std::sqrt(1.5 * s.squaredNorm())).epsilon(1e-12));
        CHECK(von_mises(w) == Approx(von_mises(v)).epsilon(1e-12));
    }
}
