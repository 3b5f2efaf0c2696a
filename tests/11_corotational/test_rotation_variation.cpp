// Chapter 11: the derivative of the polar rotation, δR from δF, against finite differences of R.
// docs/11_corotational.md#the-derivative-of-r
#include "11_corotational/corotational.hpp"

#include "common/error.hpp"
#include "common/random.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <algorithm>

using namespace fem;
using namespace fem::corot;

namespace {

/// (R(F + h δF) − R(F − h δF)) / 2h at the step h that agrees best with dR (a sweep of h, so that
/// neither truncation nor round-off decides), and the relative error there.
double finite_difference_error(const Eigen::Matrix3d& F, const Eigen::Matrix3d& dF, const Eigen::Matrix3d& dR)
{
    double best = 1e300;
    for (double h = 1e-3; h > 1e-9; h /= 10.0) {
        const Eigen::Matrix3d fd = (polar_rotation(F + h * dF) - polar_rotation(F - h * dF)) / (2.0 * h);
        best = std::min(best, (fd - dR).norm() / std::max(fd.norm(), 1e-12));
    }
    return best;
}

}  // namespace

TEST_CASE("polar_rotation_variation: dR = R omega-hat against finite differences of the polar rotation",
          "[ex11.8]")
{
    std::vector<Eigen::Matrix3d> samples;
    for (unsigned seed = 1; seed <= 10; ++seed) {
        Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + 0.4 * Eigen::Matrix3d(random_matrix(3, 3, seed));
        if (F.determinant() <= 0.0)
            F.row(0) = -F.row(0);
        samples.push_back(F);
    }
    // A large rotation of a stretched element, and a nearly flat one (s = 1.5, 0.8, 0.05).
    const Eigen::Matrix3d Q = Eigen::AngleAxisd(2.5, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
    samples.push_back(Q * Eigen::Vector3d(1.5, 0.8, 0.05).asDiagonal());
    samples.push_back(3.0 * Q);
    for (std::size_t k = 0; k < samples.size(); ++k) {
        const Eigen::Matrix3d& F = samples[k];
        const Eigen::Matrix3d dF = random_matrix(3, 3, 100 + static_cast<unsigned>(k));
        const Eigen::Matrix3d dR = polar_rotation_variation(F, dF);
        const Eigen::Matrix3d omega_hat = polar_rotation(F).transpose() * dR;
        const double error = finite_difference_error(F, dF, dR);
        CAPTURE(k, F.determinant(), error);
        CHECK(error < 1e-7);
        CHECK((omega_hat + omega_hat.transpose()).norm() <= 1e-12 * std::max(1.0, omega_hat.norm()));
    }
    // A pure stretch changed symmetrically does not turn; a rotation's own change δF = ŵ F is all turn.
    const Eigen::Matrix3d stretch = Eigen::Vector3d(1.2, 0.9, 0.7).asDiagonal();
    CHECK(polar_rotation_variation(stretch, Eigen::Matrix3d(Eigen::Vector3d(1, 2, 3).asDiagonal())).norm() <= 1e-14);
    Eigen::Matrix3d w_hat;
    w_hat << 0, -0.3, 0.2, 0.3, 0, -0.1, -0.2, 0.1, 0;
    CHECK(polar_rotation_variation(Q, w_hat * Q).isApprox(w_hat * Q, 1e-12));
    // Two singular values zero: δR is unbounded.
    CHECK_THROWS_AS(polar_rotation_variation(Eigen::Vector3d(1.0, 0.0, 0.0).asDiagonal(), w_hat), Error);
}
