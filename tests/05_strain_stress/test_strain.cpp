// Chapter 05: linear (small) strain against Green strain, especially under rotation.
// docs/05_strain_stress.md#linear-and-green-strain
#include "05_strain_stress/strain_stress.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>
#include <random>

using namespace fem::elastic;

namespace {

Eigen::Matrix3d random_matrix(std::mt19937& random, double scale)
{
    std::uniform_real_distribution<double> u(-scale, scale);
    Eigen::Matrix3d A;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
            A(a, b) = u(random);
    return A;
}

const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -1.0, 0.6).normalized();

Eigen::Matrix3d rotation(double angle) { return Eigen::AngleAxisd(angle, axis).toRotationMatrix(); }

}  // namespace

TEST_CASE("small strain: the symmetric part of grad u, and zero for a translation, exact for a stretch",
          "[ex05.4]")
{
    std::mt19937 random(1);
    for (int k = 0; k < 10; ++k) {
        const Eigen::Matrix3d grad_u = random_matrix(random, 0.1);
        const Eigen::Matrix3d eps = small_strain(Eigen::Matrix3d::Identity() + grad_u);
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                CHECK(eps(a, b) == Approx(0.5 * (grad_u(a, b) + grad_u(b, a))).margin(1e-15));
    }
    CHECK(small_strain(Eigen::Matrix3d::Identity()).norm() == 0.0);
    const Eigen::Matrix3d stretch = Eigen::Vector3d(1.1, 0.95, 1.0).asDiagonal();
    CHECK((small_strain(stretch) - Eigen::Vector3d(0.1, -0.05, 0.0).asDiagonal().toDenseMatrix()).norm() ==
          Approx(0.0).margin(1e-15));
}

TEST_CASE("small strain is NOT zero under a finite rotation: eps = (cos t - 1)(I - n n^T)", "[ex05.4]")
{
    for (double degrees : {1.0, 10.0, 45.0, 90.0, 180.0}) {
        const double t = degrees * std::numbers::pi / 180.0;
        const Eigen::Matrix3d eps = small_strain(rotation(t));
        const Eigen::Matrix3d want = (std::cos(t) - 1.0) * (Eigen::Matrix3d::Identity() - axis * axis.transpose());
        CHECK((eps - want).norm() == Approx(0.0).margin(1e-14));
        CHECK(eps.norm() == Approx(std::sqrt(2.0) * (1.0 - std::cos(t))).epsilon(1e-12));
    }
    // For small angles the spurious strain is second order: |ε| ≈ θ²/√2.
    const double t = 1e-3;
    CHECK(small_strain(rotation(t)).norm() / (t * t / std::sqrt(2.0)) == Approx(1.0).epsilon(1e-6));
}

TEST_CASE("Green strain: zero under any rotation, invariant under a rotation after the deformation",
          "[ex05.5]")
{
    for (double degrees : {1.0, 10.0, 45.0, 90.0, 180.0})
        CHECK(green_strain(rotation(degrees * std::numbers::pi / 180.0)).norm() == Approx(0.0).margin(1e-15));
    std::mt19937 random(2);
    for (int k = 0; k < 10; ++k) {
        const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + random_matrix(random, 0.3);
        const Eigen::Matrix3d E = green_strain(F);
        CHECK((E - E.transpose()).norm() == 0.0);
        CHECK((green_strain(rotation(0.4 + k) * F) - E).norm() == Approx(0.0).margin(1e-14));
        // E = ε + ½ ∇uᵀ∇u, written entry by entry.
        const Eigen::Matrix3d G = F - Eigen::Matrix3d::Identity();
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) {
                double quadratic = 0.0;
                for (int c = 0; c < 3; ++c)
                    quadratic += G(c, a) * G(c, b);
                CHECK(E(a, b) == Approx(0.5 * (G(a, b) + G(b, a)) + 0.5 * quadratic).margin(1e-15));
            }
    }
    // A stretch by s along x: E_xx = (s² − 1)/2, the change of squared length over twice the squared length.
    const double s = 1.3;
    CHECK(green_strain(Eigen::Vector3d(s, 1.0, 1.0).asDiagonal())(0, 0) == Approx((s * s - 1) / 2).epsilon(1e-15));
}

TEST_CASE("Green and small strain agree to first order: the gap is quadratic in grad u", "[ex05.5]")
{
    std::mt19937 random(4);
    const Eigen::Matrix3d direction = random_matrix(random, 1.0);
    double previous = 0.0;
    for (double size : {1e-1, 1e-2, 1e-3}) {
        const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + size * direction;
        const double gap = (green_strain(F) - small_strain(F)).norm();
        const double quadratic = 0.5 * (direction.transpose() * direction).norm() * size * size;
        CHECK(gap == Approx(quadratic).epsilon(1e-10));
        if (previous > 0.0)
            CHECK(previous / gap == Approx(100.0).epsilon(1e-9));
        previous = gap;
    }
}
