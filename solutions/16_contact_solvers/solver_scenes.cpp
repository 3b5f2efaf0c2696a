#include "16_contact_solvers/solver_runs.hpp"

#include "15_body_contact/body_scenes.hpp"
#include "15_body_contact/mesh_obstacle.hpp"

#include "common/files.hpp"
#include "common/mesh.hpp"
#include "common/mesh_io.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace fem::contact {
namespace {

dynamics::Scene rubber_scene(TetMesh mesh, double gravity, double time_step)
{
    dynamics::Scene scene;
    scene.mesh = std::move(mesh);
    scene.material = {1e6, 0.3, 1000.0};
    scene.gravity = Eigen::Vector3d(0.0, 0.0, -gravity);
    scene.time_step = time_step;
    return scene;
}

TetMesh cube_at(double edge, int cells, const Eigen::Vector3d& corner)
{
    TetMesh cube = box_mesh(cells, cells, cells, Eigen::Vector3d::Constant(edge));
    cube.V.rowwise() += corner.transpose();
    return cube;
}

}  // namespace

SolverScene drop_scene(double height, int steps, int cells)
{
    SolverScene drop;
    drop.name = "block dropped on the floor";
    drop.scene = rubber_scene(cube_at(0.1, cells, Eigen::Vector3d(0.0, 0.0, height)), 9.81, 1.0 / 100.0);
    drop.obstacles = {std::make_shared<HalfSpace>(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ())};
    drop.steps = steps;
    return drop;
}

SolverScene slope_scene(double slope, double friction, int steps)
{
    SolverScene block;
    block.name = str("block on a slope of ", slope, " rad, mu = ", friction);
    block.scene = rubber_scene(cube_at(0.1, 1, Eigen::Vector3d(0.0, 0.0, 0.5e-3)), 9.81, 1.0 / 100.0);
    block.scene.gravity = 9.81 * Eigen::Vector3d(std::sin(slope), 0.0, -std::cos(slope));
    block.obstacles = {std::make_shared<HalfSpace>(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), friction)};
    block.steps = steps;
    block.newton_tolerance = 1e-9;
    return block;
}

SolverScene bowl_scene(int cells, int steps)
{
    SolverScene bowl;
    bowl.name = "block dropped into the bowl";
    bowl.scene = rubber_scene(cube_at(0.04, cells, Eigen::Vector3d(0.05, -0.02, 0.045)), 9.81, 1.0 / 100.0);
    bowl.scene.material = {1e5, 0.4, 1000.0};
    bowl.obstacles = {std::make_shared<MeshObstacle>(io::read_tri_mesh(data_path("bowl.obj")), 0.3,
                                                     Eigen::Vector3d::Zero(), "bowl.obj")};
    bowl.steps = steps;
    return bowl;
}

std::shared_ptr<const Obstacle> turned_box()
{
    return box_under_block(Eigen::AngleAxisd(0.6, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()).toRotationMatrix());
}

SolverScene fired_scene(std::shared_ptr<const Obstacle> obstacle, double speed)
{
    SolverScene fired;
    fired.name = str("block fired at ", speed, " m/s at the ", obstacle->name());
    fired.scene = rubber_scene(cube_at(0.1, 1, Eigen::Vector3d(0.0, 0.0, 0.2)), 0.0, 1.0 / 100.0);
    fired.obstacles = {std::move(obstacle)};
    fired.v0 = Eigen::VectorXd::Zero(3 * fired.scene.mesh.V.rows());
    for (Eigen::Index i = 2; i < fired.v0.size(); i += 3)
        fired.v0[i] = -speed;
    fired.steps = 10;
    return fired;
}

SolverScene stack_scene(double reach, int steps)
{
    BlockStack blocks = block_stack(reach);
    SolverScene stack;
    stack.name = "stack of three";
    stack.scene = rubber_scene(std::move(blocks.mesh), 9.81, 1.0 / 100.0);
    stack.obstacles = {std::make_shared<HalfSpace>(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ())};
    stack.self_contact = true;
    stack.vertex_body.resize(24);
    for (int v = 0; v < 24; ++v)
        stack.vertex_body[static_cast<std::size_t>(v)] = stack_block(v);
    stack.u0 = std::move(blocks.start);
    stack.steps = steps;
    stack.newton_tolerance = 1e-9;
    return stack;
}

SolverScene two_bodies_scene(TetMesh mesh, double size, double gap, double speed, double spin, int steps)
{
    const Eigen::RowVector3d low = mesh.V.colwise().minCoeff(), high = mesh.V.colwise().maxCoeff();
    mesh.V = ((mesh.V.rowwise() - low) * (size / (high - low).maxCoeff())).eval();
    // The copy moves along x by the largest x-extent of the mesh over 5 mm columns of (y, z) plus gap:
    // where moving it along x would first reach the first one's vertices after gap.
    const double cell = 5e-3;
    std::map<std::pair<int, int>, std::pair<double, double>> columns;
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
        const std::pair<int, int> key{int(std::floor(mesh.V(v, 1) / cell)), int(std::floor(mesh.V(v, 2) / cell))};
        auto [it, added] = columns.try_emplace(key, mesh.V(v, 0), mesh.V(v, 0));
        it->second = {std::max(it->second.first, mesh.V(v, 0)), std::min(it->second.second, mesh.V(v, 0))};
    }
    double shift = 0.0;
    for (const auto& [key, extent] : columns)
        shift = std::max(shift, extent.first - extent.second);
    const Eigen::Index n = mesh.V.rows();
    TetMesh both;
    both.V.resize(2 * n, 3);
    both.V << mesh.V, mesh.V.rowwise() + Eigen::RowVector3d(shift + gap, 0.0, 0.0);
    both.T.resize(2 * mesh.T.rows(), 4);
    both.T << mesh.T, (mesh.T.array() + static_cast<int>(n)).matrix();
    SolverScene two;
    two.name = "two bodies";
    two.scene = rubber_scene(both, 0.0, 1.0 / 400.0);
    two.scene.material = {1e5, 0.4, 1000.0};
    two.self_contact = true;
    two.vertex_body.assign(static_cast<std::size_t>(2 * n), 0);
    std::fill(two.vertex_body.begin() + n, two.vertex_body.end(), 1);
    two.v0 = Eigen::VectorXd::Zero(6 * n);
    const Eigen::RowVector3d centre = mesh.V.colwise().mean();
    for (Eigen::Index v = 0; v < 2 * n; ++v) {
        const double sign = v < n ? 1.0 : -1.0;
        const Eigen::RowVector3d arm = both.V.row(v) - centre - (v < n ? 0.0 : shift + gap) * Eigen::RowVector3d::UnitX();
        two.v0.segment<3>(3 * v) = sign * (speed * Eigen::Vector3d::UnitX() + spin * Eigen::Vector3d(-arm.y(), arm.x(), 0.0));
    }
    two.steps = steps;
    return two;
}

}  // namespace fem::contact
