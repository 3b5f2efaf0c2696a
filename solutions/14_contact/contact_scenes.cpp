#include "14_contact/contact_scenes.hpp"

#include "12_hyperelastic_newton/force_models.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"

#include <cmath>
#include <numbers>

namespace fem::contact {

ContactStep::ContactStep(hyper::NewtonBackwardEuler& newton, ContactPotential& contact, int updates)
    : newton_(newton), contact_(contact), updates_(updates)
{
}

std::string ContactStep::name() const
{
    return newton_.name() + " with contact";
}

dynamics::StepInfo ContactStep::step(dynamics::Body& body, double time_step, dynamics::State& state)
{
    return contact_step(newton_, contact_, body, time_step, state, updates_, &last_solves_);
}

dynamics::StepInfo BlockScene::step(int* solves)
{
    const dynamics::StepInfo info = stepper->step(*body, time_step, state);
    if (solves != nullptr)
        *solves = stepper->last_solves();
    return info;
}

BlockScene block_scene(const BlockSettings& settings)
{
    require_positive(settings.edge, "block edge [m]");
    if (settings.cells < 1)
        throw Error(str("block: cells along an edge must be >= 1, got ", settings.cells));
    if (!(settings.height >= 0.0 && std::isfinite(settings.height)))
        throw Error(str("block: the height above the floor must be a finite number >= 0, got ", settings.height));
    if (!(settings.slope >= 0.0 && settings.slope < 0.5 * std::numbers::pi))
        throw Error(str("block: the slope angle must lie in [0, pi/2), got ", settings.slope));
    dynamics::Scene scene;
    scene.mesh = box_mesh(settings.cells, settings.cells, settings.cells, Eigen::Vector3d::Constant(settings.edge));
    scene.mesh.V.col(0).array() += settings.corner.x();
    scene.mesh.V.col(1).array() += settings.corner.y();
    scene.mesh.V.col(2).array() += settings.height;
    scene.material = settings.material;
    scene.gravity = settings.gravity * Eigen::Vector3d(std::sin(settings.slope), 0.0, -std::cos(settings.slope));
    scene.time_step = settings.time_step;
    BlockScene block;
    block.time_step = settings.time_step;
    block.body = std::make_unique<dynamics::Body>(scene, hyper::make_force_model(settings.model, scene.mesh, scene.material));
    std::vector<std::shared_ptr<const Obstacle>> obstacles = settings.obstacles;
    if (obstacles.empty())
        obstacles.push_back(std::make_shared<HalfSpace>(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), settings.friction));
    std::vector<std::unique_ptr<ContactTerm>> terms;
    if (settings.terms)
        terms = settings.terms(*block.body, obstacles, settings.contact);
    block.contact = std::make_unique<ContactPotential>(*block.body, obstacles, settings.contact, std::move(terms));
    block.integrator = std::make_unique<hyper::NewtonBackwardEuler>(settings.newton);
    block.integrator->set_potential(block.contact.get());
    block.stepper = std::make_unique<ContactStep>(*block.integrator, *block.contact, settings.friction_updates);
    block.state = dynamics::initial_state(*block.body);
    return block;
}

Eigen::Vector3d mean_velocity(const dynamics::Body& body, const Eigen::VectorXd& v)
{
    const Eigen::VectorXd& m = body.dof_masses();
    Eigen::Vector3d momentum = Eigen::Vector3d::Zero();
    double mass = 0.0;
    for (Eigen::Index vertex = 0; vertex < m.size() / 3; ++vertex) {
        momentum += m[3 * vertex] * v.segment<3>(3 * vertex);
        mass += m[3 * vertex];
    }
    return momentum / mass;
}

double lowest_height(const dynamics::Body& body, const Eigen::VectorXd& u)
{
    return body.positions(u).col(2).minCoeff();
}

std::string time_step_label(double time_step)
{
    return str("1/", static_cast<int>(std::lround(1.0 / time_step)));
}

double slope_acceleration(double gravity, double slope, double friction)
{
    return std::tan(slope) > friction ? gravity * (std::sin(slope) - friction * std::cos(slope)) : 0.0;
}

double drop_speed(double gravity, double height)
{
    return std::sqrt(2.0 * gravity * height);
}

double sticking_creep(double slope, double friction)
{
    const double load = std::tan(slope) / friction;
    if (!(load < 1.0))
        throw Error(str("sticking_creep: tan(theta) / mu = ", load, " >= 1: the block slides, it does not creep"));
    return 1.0 - std::sqrt(1.0 - load);
}

}  // namespace fem::contact
