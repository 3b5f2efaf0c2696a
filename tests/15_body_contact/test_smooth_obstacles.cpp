// Chapter 15: a sphere is a point with a radius and a capsule a segment with one — their barrier
// against the body's triangles and edges (FeatureBarrier on Obstacle::local_core, the pairs' distance
// d − r) holds every point of the body's surface outside them, not only its vertices: its
// derivatives against central differences, and blocks fired at a small sphere and a thin capsule
// between their vertices at 6, 60 and 600 m/s (issue 48, item 6c).
// docs/15_body_contact.md#edges-and-corners-of-obstacles
#include "15_body_contact/body_contact.hpp"
#include "15_body_contact/feature_barrier.hpp"
#include "14_contact/contact_scenes.hpp"
#include "14_contact/obstacles.hpp"
#include "14_contact/surface.hpp"
#include "../14_contact/one_thread.hpp"

#include "common/mesh.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Sparse>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

using namespace fem;
using namespace fem::contact;

namespace smooth_obstacles {

/// The smallest distance from the obstacle's core (its centre, or its segment) minus its radius to
/// 21 × 21 points of every surface triangle of the body at positions x (#V×3) [m]: < 0 where the
/// surface is inside.
double smallest_surface_gap(const TetMesh& mesh, const MatrixX3d& x, const Obstacle& obstacle)
{
    const SurfacePrimitives surface = surface_primitives(mesh);
    double smallest = INFINITY;
    constexpr int n = 20;
    for (Eigen::Index t = 0; t < surface.triangles.rows(); ++t) {
        const Eigen::Vector3d a = x.row(surface.triangles(t, 0)), b = x.row(surface.triangles(t, 1)),
                              c = x.row(surface.triangles(t, 2));
        for (int i = 0; i <= n; ++i)
            for (int j = 0; i + j <= n; ++j)
                smallest = std::min(smallest, obstacle.distance(a + (b - a) * i / n + (c - a) * j / n, 0.0));
    }
    return smallest;
}

}  // namespace smooth_obstacles

using namespace smooth_obstacles;

TEST_CASE("smooth obstacles: the barrier of a sphere's and a capsule's core against the body's triangles and edges "
          "has the derivatives central differences give", "[obstacles][ex15.2]")
{
    const TetMesh mesh = box_mesh(1, 1, 1, Eigen::Vector3d::Constant(0.1));
    const double dhat = 1e-2;
    // Each 6 mm from the bottom face z = 0, under it between its vertices; the capsule across it.
    const std::vector<std::shared_ptr<const Obstacle>> obstacles{
        std::make_shared<Sphere>(Eigen::Vector3d(0.06, 0.03, -0.026), 0.02),
        std::make_shared<Capsule>(Eigen::Vector3d(-0.2, 0.04, -0.016), Eigen::Vector3d(0.2, 0.07, -0.016), 0.01)};
    for (const auto& obstacle : obstacles) {
        const FeatureBarrier barrier(mesh, {obstacle}, dhat);
        REQUIRE(barrier.active());
        Eigen::VectorXd u(3 * mesh.V.rows());
        for (Eigen::Index k = 0; k < u.size(); ++k)
            u[k] = 1e-3 * std::sin(1.7 * static_cast<double>(k));  // a little off the box's symmetries
        const double kappa = 10.0, h = 1e-7;
        REQUIRE(barrier.energy(u, 0.0, kappa) > 0.0);
        Eigen::VectorXd gradient = Eigen::VectorXd::Zero(u.size());
        barrier.add_gradient(u, 0.0, kappa, gradient);
        std::vector<Eigen::Triplet<double>> triplets;
        barrier.add_hessian(u, 0.0, kappa, triplets, std::nullopt);
        Eigen::SparseMatrix<double> hessian(u.size(), u.size());
        hessian.setFromTriplets(triplets.begin(), triplets.end());
        const Eigen::MatrixXd dense(hessian);
        Eigen::VectorXd energy_fd(u.size());
        Eigen::MatrixXd hessian_fd(u.size(), u.size());
        for (Eigen::Index k = 0; k < u.size(); ++k) {
            Eigen::VectorXd plus = u, minus = u;
            plus[k] += h;
            minus[k] -= h;
            energy_fd[k] = (barrier.energy(plus, 0.0, kappa) - barrier.energy(minus, 0.0, kappa)) / (2.0 * h);
            Eigen::VectorXd g_plus = Eigen::VectorXd::Zero(u.size()), g_minus = Eigen::VectorXd::Zero(u.size());
            barrier.add_gradient(plus, 0.0, kappa, g_plus);
            barrier.add_gradient(minus, 0.0, kappa, g_minus);
            hessian_fd.col(k) = (g_plus - g_minus) / (2.0 * h);
        }
        INFO(obstacle->name());
        CHECK((gradient - energy_fd).norm() <= 1e-6 * gradient.norm());
        CHECK((dense - hessian_fd).norm() <= 1e-5 * dense.norm());
    }
}

TEST_CASE("smooth obstacles: a block fired at a small sphere or a thin capsule between its vertices at 6, 60 and "
          "600 m/s (6 cm a step) keeps every point of its surface outside", "[obstacles][ex15.2]")
{
    struct Target {
        std::string what;
        std::shared_ptr<const Obstacle> obstacle;
    };
    // The block's bottom face (10 cm, one cell) 1 cm above each; the sphere of 2 cm under its middle,
    // the rod of 1 cm across it: both between the face's vertices.
    const std::vector<Target> targets{
        {"sphere", std::make_shared<Sphere>(Eigen::Vector3d(0.05, 0.05, -0.02), 0.02)},
        {"capsule", std::make_shared<Capsule>(Eigen::Vector3d(-0.3, 0.05, -0.01), Eigen::Vector3d(0.4, 0.05, -0.01), 0.01)}};
    for (const Target& target : targets)
        for (const double speed : {6.0, 60.0, 600.0}) {
            BlockSettings settings;
            settings.terms = body_contact_term_maker();
            settings.model = "neo-hookean";
            settings.height = 0.01;
            settings.newton.max_iterations = 1000;
            settings.time_step = 0.06 / speed;      // 6 cm a step, 3 times the sphere's radius
            settings.obstacles = {target.obstacle};
            BlockScene block = block_scene(settings);
            for (Eigen::Index v = 0; v < block.state.v.size() / 3; ++v)
                block.state.v.segment<3>(3 * v) = Eigen::Vector3d(0.0, 0.0, -speed);
            double smallest = INFINITY;
            INFO(target.what << " at " << speed << " m/s");
            for (int step = 0; step < 10; ++step) {
                REQUIRE_NOTHROW(block.step());
                smallest = std::min(smallest, smallest_surface_gap(block.body->mesh(), block.body->positions(block.state.u),
                                                                   *target.obstacle));
            }
            INFO("the smallest gap of a sampled surface point " << smallest << " m");
            CHECK(smallest > 0.0);
        }
}
