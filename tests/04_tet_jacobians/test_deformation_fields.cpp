// Chapter 04: the analytic deformation fields the executable (and later chapters) compare with:
// their gradients against central differences of their maps, and their known determinants.
#include "04_tet_jacobians/deformation_fields.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <Eigen/LU>

#include <cmath>

using namespace fem::tet;

namespace {

/// max over sample points of |gradient(X) − central difference of map at X|.
double gradient_mismatch(const DeformationField& field)
{
    double worst = 0.0;
    const double h = 1e-5;
    for (double x : {0.1, 0.45, 0.52, 0.9})
        for (double y : {0.0, 0.2})
            for (double z : {0.05, 0.25}) {
                const Eigen::Vector3d X(x, y, z);
                Eigen::Matrix3d numeric;
                for (int b = 0; b < 3; ++b)
                    numeric.col(b) = (field.map(X + h * Eigen::Vector3d::Unit(b)) -
                                      field.map(X - h * Eigen::Vector3d::Unit(b))) / (2 * h);
                worst = std::max(worst, (numeric - field.gradient(X)).norm());
            }
    return worst;
}

}  // namespace

TEST_CASE("deformation fields: analytic gradients match central differences of the maps", "[ch04]")
{
    Eigen::Matrix3d A;
    A << 1.2, 0.3, 0.0, -0.1, 0.9, 0.4, 0.2, 0.0, 1.1;
    CHECK(gradient_mismatch(affine_field("a", "affine", A, Eigen::Vector3d(1, 2, 3))) < 1e-9);
    CHECK(gradient_mismatch(twist_field(2.5, 0.125, 0.125)) < 1e-8);
    CHECK(gradient_mismatch(pinch_field(1.6, 0.1, 0.5, 0.125)) < 1e-7);
    // The twist keeps volume; the pinch scales it by σ, negative at its centre for depth > 1.
    CHECK(twist_field(2.5, 0.1, 0.2).gradient(Eigen::Vector3d(0.7, 0.3, -0.4)).determinant() ==
          Approx(1.0).epsilon(1e-14));
    CHECK(pinch_field(1.6, 0.1, 0.5, 0.125).gradient(Eigen::Vector3d(0.5, 0.0, 0.3)).determinant() ==
          Approx(-0.6).epsilon(1e-14));
    CHECK_THROWS_AS(pinch_field(1.0, 0.0, 0.5, 0.0), fem::Error);
    CHECK_THROWS_AS(twist_field(std::nan(""), 0.0, 0.0), fem::Error);
}
