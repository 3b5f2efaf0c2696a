#pragma once
// Chapter 15's tests: bodies against bodies — boxes placed in space, several bodies joined into one
// mesh of several components, and such a mesh stepped with contact.
// docs/15_body_contact.md#bodies-against-bodies-and-self-contact

#include "15_body_contact/body_contact.hpp"

#include "12_hyperelastic_newton/force_models.hpp"
#include "12_hyperelastic_newton/newton.hpp"

#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include "common/mesh.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <memory>
#include <utility>
#include <vector>

namespace fem::test {

/// One mesh of two components: a's vertices first, then b's (b's tets renumbered).
inline TetMesh two_bodies(const TetMesh& a, const TetMesh& b)
{
    TetMesh both;
    both.V.resize(a.V.rows() + b.V.rows(), 3);
    both.V << a.V, b.V;
    both.T.resize(a.T.rows() + b.T.rows(), 4);
    both.T << a.T, (b.T.array() + static_cast<int>(a.V.rows())).matrix();
    return both;
}

/// A box of cells³ cells of the given size (3) [m] with its lowest corner at corner (3) [m].
inline TetMesh box_at(const Eigen::Vector3d& corner, const Eigen::Vector3d& size, int cells = 1)
{
    TetMesh box = box_mesh(cells, cells, cells, size);
    box.V.rowwise() += corner.transpose();
    return box;
}

/// Bodies in one mesh (several components) and their start velocity (3n).
struct ThrownBodies {
    TetMesh mesh;
    Eigen::VectorXd velocity;
};

/// A free plate one tet thick (0.2 × 0.2 m, 8 × 8 cells, thickness [m], its top face at z = 0) and a
/// one-cell block of edge 5 cm turned by turn [rad] about x (π/4: on its edge), its lowest point
/// 2 mm above the plate, its centre over the plate's, the block moving down at speed [m/s]: one mesh,
/// the plate's vertices first. The block's corners lie over the plate's vertices and grid lines.
inline ThrownBodies block_over_plate(double speed, double thickness = 0.002, double turn = 0.0)
{
    TetMesh plate = box_mesh(8, 8, 1, Eigen::Vector3d(0.2, 0.2, thickness));
    plate.V.rowwise() -= Eigen::RowVector3d(0.1, 0.1, thickness);
    TetMesh block = box_at(Eigen::Vector3d::Constant(-0.025), Eigen::Vector3d::Constant(0.05));
    const Eigen::Matrix3d rotation = Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitX()).toRotationMatrix();
    block.V = (block.V * rotation.transpose()).eval();
    block.V.col(2).array() += 0.002 - block.V.col(2).minCoeff();
    ThrownBodies scene{two_bodies(plate, block), {}};
    scene.velocity = Eigen::VectorXd::Zero(3 * scene.mesh.V.rows());
    for (Eigen::Index v = plate.V.rows(); v < scene.mesh.V.rows(); ++v)
        scene.velocity[3 * v + 2] = -speed;
    return scene;
}

/// The scene of bodies thrown at each other: mesh of a soft rubber (Y = 10⁵ Pa, ν = 0.3, ρ = 1000
/// kg/m³), nothing pinned, no gravity, Δt = 1/400 s.
inline dynamics::Scene free_scene(const TetMesh& mesh)
{
    dynamics::Scene scene;
    scene.mesh = mesh;
    scene.material = {1e5, 0.3, 1000.0};
    scene.gravity.setZero();
    scene.time_step = 1.0 / 400.0;
    return scene;
}

/// The body of scene (stable neo-Hookean), its contact potential (options, obstacles), chapter 12's
/// Newton backward Euler with it as potential (relative tolerance, 200 iterations at most), and the
/// state from u0 and v0 (3n each, or empty: zero).
struct ContactRun {
    std::unique_ptr<dynamics::Body> body;
    std::unique_ptr<contact::ContactPotential> contact;
    std::unique_ptr<hyper::NewtonBackwardEuler> newton;
    dynamics::State state;
    double time_step = 0.0;

    ContactRun(const dynamics::Scene& scene, const contact::BodyContactOptions& options,
               std::vector<std::shared_ptr<const contact::Obstacle>> obstacles = {}, const Eigen::VectorXd& u0 = {},
               const Eigen::VectorXd& v0 = {}, double tolerance = 1e-9)
        : body(std::make_unique<dynamics::Body>(
              scene, hyper::make_force_model("stable-neo-hookean", scene.mesh, scene.material))),
          contact(std::make_unique<contact::ContactPotential>(contact::body_contact_potential(*body, std::move(obstacles), options))),
          time_step(scene.time_step)
    {
        hyper::NewtonOptions newton_options;
        newton_options.relative_tolerance = tolerance;
        newton_options.max_iterations = 200;
        newton = std::make_unique<hyper::NewtonBackwardEuler>(newton_options);
        newton->set_potential(contact.get());
        state = dynamics::initial_state(*body, u0, v0);
    }
    /// One contact_step of Δt.
    void step() { contact::contact_step(*newton, *contact, *body, time_step, state); }
};

/// Σ m_v v_v over vertices first … first + count − 1 (3) [kg m/s]; a body's momentum with first 0,
/// count n.
inline Eigen::Vector3d momentum(const dynamics::Body& body, const Eigen::VectorXd& v, Eigen::Index first,
                                Eigen::Index count)
{
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (Eigen::Index i = first; i < first + count; ++i)
        p += body.dof_masses()[3 * i] * v.segment<3>(3 * i);
    return p;
}

}  // namespace fem::test
