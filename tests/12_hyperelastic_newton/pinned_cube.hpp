#pragma once
// Chapter 12's tests: the rubber cube most of them step, shared by test_newton.cpp and
// test_volume_filter.cpp (one definition for the unity build).

#include "06_assembly/assembly.hpp"
#include "10_linear_dynamics/body.hpp"

#include "common/mesh.hpp"

#include <Eigen/Core>

namespace fem::test {

/// A 0.1 m cube of 2³ cells (density 1000 kg/m³, Young's modulus youngs [Pa], Poisson's ratio
/// poisson) pinned at its base z = 0, stepped at time_step [s]; gravity as dynamics::Scene's default.
inline dynamics::Scene pinned_cube(double youngs, double poisson, double time_step = 1.0 / 30.0)
{
    dynamics::Scene scene;
    scene.mesh = box_mesh(2, 2, 2, Eigen::Vector3d(0.1, 0.1, 0.1));
    scene.material = {youngs, poisson, 1000.0};
    scene.pinned = assembly::vertices_on_plane(scene.mesh, 2, 0.0);
    scene.time_step = time_step;
    return scene;
}

}  // namespace fem::test
