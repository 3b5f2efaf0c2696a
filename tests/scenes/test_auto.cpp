// Model "auto": the deformation measures and the level they choose. docs/scenes.md#model-auto
#include "scenes/runner.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

using namespace fem;
using namespace fem::scenes;

TEST_CASE("deformation measures of a rigid rotation: the angle, no strain, volume kept", "[scenes]")
{
    const TetMesh mesh = box_mesh(2, 1, 1, Eigen::Vector3d(0.2, 0.1, 0.1));
    for (double degrees : {1.0, 10.0, 45.0, 80.0}) {
        const double angle = degrees * std::acos(-1.0) / 180.0;
        const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
        const MatrixX3d x = mesh.V * R.transpose();
        const DeformationMeasures m = deformation_measures(mesh, x);
        CHECK(m.rotation == Approx(angle).epsilon(1e-12));
        CHECK(m.strain < 1e-13);
        CHECK(m.volume_ratio == Approx(1.0).epsilon(1e-13));
    }
}
