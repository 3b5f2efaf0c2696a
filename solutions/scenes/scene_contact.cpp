// The scenes capstone: a body's steps with obstacles. docs/scenes.md#obstacles
#include "scenes/scene_contact.hpp"

#include "15_body_contact/body_contact.hpp"

#include "12_hyperelastic_newton/force_models.hpp"

#include "common/error.hpp"

#include <algorithm>

namespace fem::scenes {

std::vector<std::shared_ptr<const contact::Obstacle>> scene_obstacles(const SceneSpec& scene)
{
    std::vector<std::shared_ptr<const contact::Obstacle>> obstacles;
    for (const ObstacleSpec& spec : scene.obstacles)
        obstacles.push_back(spec.obstacle);
    return obstacles;
}

namespace {

contact::BodyContactOptions contact_options(const SceneSpec& scene, bool self_contact, std::vector<int> vertex_body,
                                            std::vector<bool> self_contacts, std::vector<std::string> body_names)
{
    contact::BodyContactOptions options;
    options.self_contact = self_contact;
    options.vertex_body = std::move(vertex_body);
    options.body_self_contact = std::move(self_contacts);
    options.body_friction = self_contact ? scene.contact.friction : 0.0;
    options.activation_distance = scene.contact.activation_distance;
    options.friction_velocity = scene.contact.friction_velocity;
    options.check_path = self_contact && scene.contact.check_path;
    options.body_names = std::move(body_names);
    return options;
}

/// Chapter 16's augmented Lagrangian for the scene: δ = d̂, the scene's ε_v, bodies and self-contact
/// as contact_options.
contact::AugmentedLagrangianOptions multiplier_options(const SceneSpec& scene, bool self_contact,
                                                      std::vector<int> vertex_body, std::vector<bool> self_contacts)
{
    contact::AugmentedLagrangianOptions options;
    options.gap = scene.contact.activation_distance;
    options.friction_velocity = scene.contact.friction_velocity;
    options.self_contact = self_contact;
    options.vertex_body = std::move(vertex_body);
    options.body_self_contact = std::move(self_contacts);
    return options;
}

/// Newton's options for a contact step: the scene's solver, made timed (*timed receives it when
/// Newton makes it) and its tolerance, contact_newton_iterations.
hyper::NewtonOptions contact_newton_options(const SceneSpec& scene, contact::TimedSolver** timed)
{
    hyper::NewtonOptions options =
        hyper::newton_options_for({.solver = scene.solver, .newton_tolerance = scene.newton_tolerance});
    options.max_iterations = contact_newton_iterations;
    options.make_solver = [make = options.make_solver, name = options.solver, timed] {
        auto solver = std::make_unique<contact::TimedSolver>(make ? make() : cg::make_solver(name));
        *timed = solver.get();
        return solver;
    };
    return options;
}

}  // namespace

ContactIntegrator::ContactIntegrator(dynamics::Integrator& own, std::vector<SceneForces*> levels,
                                     const dynamics::Body& body,
                                     std::vector<std::shared_ptr<const contact::Obstacle>> obstacles,
                                     const SceneSpec& scene, bool self_contact, std::vector<int> vertex_body,
                                     std::vector<bool> self_contacts, std::vector<std::string> body_names)
    : own_(own),
      levels_(std::move(levels)),
      obstacles_(obstacles),
      newton_(contact_newton_options(scene, &solver_)),
      surface_(contact::surface_primitives(body.mesh())),
      rest_(body.mesh().V)
{
    if (scene.contact.solver == "augmented_lagrangian") {
        multipliers_ = std::make_unique<contact::AugmentedLagrangianContact>(
            body, std::move(obstacles),
            multiplier_options(scene, self_contact, std::move(vertex_body), std::move(self_contacts)));
        checks_ = &multipliers_->collision_check();
        newton_.set_potential(multipliers_.get());
    } else {
        barrier_ = std::make_unique<contact::ContactPotential>(contact::body_contact_potential(
            body, std::move(obstacles),
            contact_options(scene, self_contact, std::move(vertex_body), std::move(self_contacts), std::move(body_names))));
        checks_ = barrier_.get();
        newton_.set_potential(barrier_.get());
    }
}

ContactPairs ContactIntegrator::pairs(const Eigen::VectorXd& u, double time) const
{
    if (u.size() != 3 * rest_.rows())
        throw Error(str("ContactIntegrator::pairs: u has ", u.size(), " entries, expected 3 x ", rest_.rows(),
                        " vertices"));
    ContactPairs counted;
    if (const auto* bodies = checks_->term<contact::BodyContactTerm>())
        for (const contact::SurfacePair& pair : bodies->barrier().pairs(u, false))
            ++(pair.kind == contact::PrimitivePair::point_triangle ? counted.point_triangle : counted.edge_edge);
    const double reach = checks_->options().activation_distance;
    for (int v : surface_.vertices) {
        const Eigen::Vector3d x = rest_.row(v).transpose() + u.segment<3>(3 * v);
        for (const auto& obstacle : obstacles_)
            counted.vertex_obstacle += obstacle->distance(x, time) < reach ? 1 : 0;
    }
    return counted;
}

int ContactIntegrator::surface_primitives() const
{
    return static_cast<int>(surface_.vertices.size() + surface_.edges.rows() + surface_.triangles.rows());
}

dynamics::StepInfo ContactIntegrator::step(dynamics::Body& body, double time_step, dynamics::State& state)
{
    const double end = state.time + time_step;
    last_cost_ = {};
    // Near an obstacle at the start already: contact at once, without trying the own step.
    if (checks_->out_of_contact(state.u, state.time, state.u, end)) {
        dynamics::State trial = state;
        const dynamics::StepInfo info = own_.step(body, time_step, trial);
        if (checks_->out_of_contact(state.u, state.time, trial.u, end)) {
            state = std::move(trial);
            last_contact_ = false;
            return info;
        }
    }
    last_contact_ = true;
    ++contact_steps_;
    // A linear body is raised to corotational first (scene_contact.hpp), booked as chapter 10's step
    // hook books a change of model: the jump of H at the same (u, v) is work put in, and the state's
    // forces and elastic energy are the new model's before the step reads them.
    double model_change = 0.0;
    if (std::any_of(levels_.begin(), levels_.end(), [](const SceneForces* f) { return f->level() == Level::linear; }))
        model_change = dynamics::apply_step_hook(
            [this](dynamics::Body&, const dynamics::State&, double) {
                for (SceneForces* forces : levels_)
                    if (forces->level() == Level::linear)
                        forces->set_level(Level::corotational);
                return true;
            },
            body, state, end);
    const contact::ContactClocks before = checks_->clocks();
    const double solves = solver_->seconds;
    const int patterns = solver_->new_patterns;
    dynamics::StepInfo info = multipliers_ ? contact::augmented_lagrangian_step(newton_, *multipliers_, body, time_step, state)
                                           : contact::contact_step(newton_, *barrier_, body, time_step, state);
    info.boundary_work += model_change;
    const contact::ContactClocks after = checks_->clocks();
    last_cost_ = {after.barrier_seconds - before.barrier_seconds, after.collision_seconds - before.collision_seconds,
                  solver_->seconds - solves, solver_->new_patterns - patterns};
    return info;
}

}  // namespace fem::scenes
