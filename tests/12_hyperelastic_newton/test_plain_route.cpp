// The plain route of the cost study's peers table (chapters/12_hyperelastic_newton/plain_routes.hpp):
// the same physics and the same Newton step as the chapter's, so its timings compare like with like.
#include "12_hyperelastic_newton/force_models.hpp"
#include "12_hyperelastic_newton/hyperelastic.hpp"
#include "12_hyperelastic_newton/newton.hpp"
#include "12_hyperelastic_newton/plain_routes.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace fem;
using namespace fem::hyper;

namespace {

/// A soft stable neo-Hookean cantilever of 4 cells at Δt = 1/30 s: it sags by several of its own
/// thicknesses in a few steps, far outside the linear range.
dynamics::Scene soft_beam()
{
    dynamics::Scene scene = dynamics::cantilever_scene(dynamics::Material{1e5, 0.45, 1000.0}, 4, 1.0);
    scene.time_step = 1.0 / 30.0;
    return scene;
}

std::unique_ptr<plain::PlainHyperelastic> plain_model(const dynamics::Scene& scene)
{
    return std::make_unique<plain::PlainHyperelastic>(
        scene.mesh, make_material("stable-neo-hookean", scene.material.youngs_modulus, scene.material.poisson_ratio));
}

}  // namespace

TEST_CASE("plain Newton step: dense element products, triplets and a fresh SimplicialLLT give our steps to round-off",
          "[plain-route][ex12.9]")
{
    const dynamics::Scene scene = soft_beam();
    dynamics::Body ours(scene, make_force_model("stable-neo-hookean", scene.mesh, scene.material));
    dynamics::Body plain_body(scene, plain_model(scene));
    NewtonBackwardEuler our_step, plain_step(plain::plain_newton_options());
    dynamics::State our_state = dynamics::initial_state(ours), plain_state = dynamics::initial_state(plain_body);
    int iterations = 0;
    for (int k = 0; k < 6; ++k) {
        const int our_iterations = our_step.step(ours, scene.time_step, our_state).newton_iterations;
        CHECK(plain_step.step(plain_body, scene.time_step, plain_state).newton_iterations == our_iterations);
        iterations += our_iterations;
    }
    CHECK(iterations > 6);  // nonlinear: more than one Newton iteration per step
    const double scale_u = our_state.u.lpNorm<Eigen::Infinity>();
    CHECK(scale_u > 0.01);  // a 2 cm thick beam sagging by more than 1 cm
    CHECK((plain_state.u - our_state.u).lpNorm<Eigen::Infinity>() <= 1e-9 * scale_u);
    CHECK((plain_state.v - our_state.v).lpNorm<Eigen::Infinity>() <= 1e-9 * our_state.v.lpNorm<Eigen::Infinity>());
}

TEST_CASE("plain hyperelastic model: energy, forces, Hessian and definite Hessian of the chapter's model, the Hessian "
          "against central differences of the forces", "[plain-route][ex12.9]")
{
    const dynamics::Scene scene = soft_beam();
    dynamics::Body body(scene, make_force_model("stable-neo-hookean", scene.mesh, scene.material));
    NewtonBackwardEuler step;
    dynamics::State state = dynamics::initial_state(body);
    for (int k = 0; k < 4; ++k)
        step.step(body, scene.time_step, state);
    const Eigen::VectorXd& u = state.u;
    HyperelasticElasticity ours(scene.mesh,
                                make_material("stable-neo-hookean", scene.material.youngs_modulus, scene.material.poisson_ratio),
                                Projection::clamp);
    const auto plain_body = plain_model(scene);
    Eigen::VectorXd our_forces, plain_forces;
    const double our_energy = ours.evaluate(u, our_forces);
    CHECK(std::abs(plain_body->evaluate(u, plain_forces) - our_energy) <= 1e-10 * std::abs(our_energy));
    CHECK(std::abs(plain_body->energy(u) - our_energy) <= 1e-10 * std::abs(our_energy));
    CHECK((plain_forces - our_forces).lpNorm<Eigen::Infinity>() <= 1e-10 * our_forces.lpNorm<Eigen::Infinity>());
    const Eigen::MatrixXd K_ours(ours.stiffness(u)), K_plain(plain_body->stiffness(u));
    CHECK((K_plain - K_ours).lpNorm<Eigen::Infinity>() <= 1e-10 * K_ours.lpNorm<Eigen::Infinity>());
    const Eigen::MatrixXd D_ours(ours.definite_stiffness(u)), D_plain(plain_body->definite_stiffness(u));
    CHECK((D_plain - D_ours).lpNorm<Eigen::Infinity>() <= 1e-9 * D_ours.lpNorm<Eigen::Infinity>());
    // K = −∂f/∂u, by central differences along a smooth direction.
    const Eigen::VectorXd direction = Eigen::VectorXd::LinSpaced(u.size(), -1.0, 1.0).array().sin().matrix();
    const double h = 1e-7;
    Eigen::VectorXd f_plus, f_minus;
    plain_body->evaluate(u + h * direction, f_plus);
    plain_body->evaluate(u - h * direction, f_minus);
    const Eigen::VectorXd Kd = K_plain * direction;
    CHECK((Kd + (f_plus - f_minus) / (2.0 * h)).norm() <= 1e-6 * Kd.norm());
    CHECK_THROWS_AS(plain_body->evaluate(Eigen::VectorXd::Zero(3), plain_forces), Error);
}
