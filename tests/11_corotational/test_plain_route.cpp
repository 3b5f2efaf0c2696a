// The plain route of the cost study's peers table (chapters/11_corotational/plain_routes.hpp): the
// same physics as the chapter's corotational step, so its timings compare like with like.
#include "11_corotational/corotational.hpp"
#include "11_corotational/plain_routes.hpp"

#include "10_linear_dynamics/time_integration.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

using namespace fem;
using namespace fem::corot;

namespace {

/// A soft cantilever of 4 cells, bent by its weight for 12 steps: its tets turned by up to ~0.3 rad.
dynamics::Scene bent_beam_scene()
{
    return dynamics::cantilever_scene(dynamics::Material{2e5, 0.45, 1100.0}, 4, 1.0);
}

dynamics::State run_steps(dynamics::Body& body, dynamics::ThetaMethod& integrator, int steps)
{
    dynamics::State state = dynamics::initial_state(body);
    for (int k = 0; k < steps; ++k)
        integrator.step(body, body.scene().time_step, state);
    return state;
}

double largest_angle(const std::vector<Eigen::Matrix3d>& rotations)
{
    double largest = 0.0;
    for (const Eigen::Matrix3d& R : rotations)
        largest = std::max(largest, Eigen::AngleAxisd(R).angle());
    return largest;
}

}  // namespace

TEST_CASE("plain corotational step: JacobiSVD, triplets and a fresh SimplicialLLT give our step to round-off",
          "[plain-route][ex11.6]")
{
    const dynamics::Scene scene = bent_beam_scene();
    dynamics::Body ours(scene, std::make_unique<CorotationalElasticity>(scene.mesh, scene.material));
    dynamics::ImplicitOptions our_options;
    our_options.solver = "ours-cholesky";
    dynamics::ThetaMethod our_step(1.0, our_options);
    const dynamics::State our_state = run_steps(ours, our_step, 12);
    // The steps turned the tets far enough that a wrong rotation (R transposed, a reflection left
    // in) would change the forces by far more than round-off.
    const double angle = largest_angle(dynamic_cast<CorotationalElasticity&>(ours.model()).rotations(our_state.u));
    CHECK(angle > 0.1);
    for (const plain::PlainRotation rotation : {plain::PlainRotation::jacobi_svd, plain::PlainRotation::polar_newton}) {
        dynamics::Body body(scene, std::make_unique<plain::PlainCorotational>(scene.mesh, scene.material, rotation));
        dynamics::ThetaMethod plain_step(1.0, plain::plain_step_options());
        const dynamics::State plain_state = run_steps(body, plain_step, 12);
        const double scale_u = our_state.u.lpNorm<Eigen::Infinity>(), scale_v = our_state.v.lpNorm<Eigen::Infinity>();
        CHECK(scale_u > 1e-3);
        CHECK((plain_state.u - our_state.u).lpNorm<Eigen::Infinity>() <= 1e-10 * scale_u);
        CHECK((plain_state.v - our_state.v).lpNorm<Eigen::Infinity>() <= 1e-10 * scale_v);
        CHECK(std::abs(plain_state.elastic_energy - our_state.elastic_energy) <= 1e-10 * our_state.elastic_energy);
    }
}

TEST_CASE("plain corotational model: forces and warped stiffness of the chapter's model at a bent state",
          "[plain-route][ex11.6]")
{
    const dynamics::Scene scene = bent_beam_scene();
    dynamics::Body body(scene, std::make_unique<CorotationalElasticity>(scene.mesh, scene.material));
    dynamics::ThetaMethod step(1.0);
    const dynamics::State state = run_steps(body, step, 12);
    CorotationalElasticity ours(scene.mesh, scene.material);
    plain::PlainCorotational plain_model(scene.mesh, scene.material);
    Eigen::VectorXd our_forces, plain_forces;
    const double our_energy = ours.evaluate(state.u, our_forces);
    const double plain_energy = plain_model.evaluate(state.u, plain_forces);
    CHECK(std::abs(plain_energy - our_energy) <= 1e-10 * our_energy);
    CHECK((plain_forces - our_forces).lpNorm<Eigen::Infinity>() <= 1e-10 * our_forces.lpNorm<Eigen::Infinity>());
    const Eigen::MatrixXd K_ours(ours.stiffness(state.u)), K_plain(plain_model.stiffness(state.u));
    CHECK((K_plain - K_ours).lpNorm<Eigen::Infinity>() <= 1e-10 * K_ours.lpNorm<Eigen::Infinity>());
    // The warped stiffness is not the rest stiffness: the rotations matter at this state.
    const Eigen::MatrixXd K_rest(plain_model.stiffness(Eigen::VectorXd::Zero(state.u.size())));
    CHECK((K_plain - K_rest).lpNorm<Eigen::Infinity>() > 1e-3 * K_rest.lpNorm<Eigen::Infinity>());
    CHECK_THROWS_AS(plain_model.stiffness(Eigen::VectorXd::Zero(3)), Error);
}

TEST_CASE("plain Cholesky: solves a step matrix to round-off, refuses an indefinite one", "[plain-route][ex11.6]")
{
    const dynamics::Scene scene = bent_beam_scene();
    dynamics::Body body(scene, std::make_unique<CorotationalElasticity>(scene.mesh, scene.material));
    const dynamics::SparseMatrix A = body.dofs().reduce(dynamics::step_matrix(
        body.mass_matrix(), body.model().stiffness(Eigen::VectorXd::Zero(body.dofs().full_size())), scene.damping,
        scene.time_step));
    const auto solver = plain::plain_cholesky();
    solver->prepare(A);
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(A.rows(), -1.0, 2.0);
    const Eigen::VectorXd x = solver->solve(b);
    CHECK((A * x - b).norm() <= 1e-12 * b.norm());
    const Eigen::VectorXd dense = Eigen::MatrixXd(A).ldlt().solve(b);
    CHECK((x - dense).lpNorm<Eigen::Infinity>() <= 1e-10 * dense.lpNorm<Eigen::Infinity>());
    dynamics::SparseMatrix indefinite = A;
    indefinite.coeffRef(0, 0) = -1.0;
    CHECK_THROWS_AS(solver->prepare(indefinite), Error);
}
