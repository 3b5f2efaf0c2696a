#include "16_contact_solvers/solver_runs.hpp"

#include "15_body_contact/body_contact.hpp"
#include "15_body_contact/timed_solver.hpp"

#include "12_hyperelastic_newton/force_models.hpp"
#include "12_hyperelastic_newton/newton.hpp"

#include "09_conjugate_gradient/linear_solver.hpp"

#include "common/error.hpp"
#include "common/timer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fem::contact {

std::string solver_name(ContactSolver solver)
{
    switch (solver) {
    case ContactSolver::ipc:
        return "IPC";
    case ContactSolver::augmented_lagrangian:
        return "augmented Lagrangian";
    case ContactSolver::none:
        break;
    }
    return "free";
}

SolverRun run_scene(const SolverScene& scene, ContactSolver solver, AugmentedLagrangianOptions options,
                    bool check_intersections, const StepObserver& observer, const PotentialWrapper& wrap)
{
    dynamics::Body body(scene.scene, hyper::make_force_model("stable-neo-hookean", scene.scene.mesh, scene.scene.material));
    TimedSolver* timed = nullptr;
    hyper::NewtonOptions newton_options;
    newton_options.relative_tolerance = scene.newton_tolerance;
    newton_options.max_iterations = 500;
    newton_options.make_solver = [&timed] {
        auto made = std::make_unique<TimedSolver>(cg::make_solver("default"));
        timed = made.get();
        return made;
    };
    hyper::NewtonBackwardEuler newton(newton_options);
    options.self_contact = scene.self_contact;
    options.vertex_body = scene.vertex_body;
    options.check_intersections = check_intersections;
    std::unique_ptr<AugmentedLagrangianContact> al;
    std::unique_ptr<ContactPotential> ipc;
    if (solver == ContactSolver::augmented_lagrangian) {
        al = std::make_unique<AugmentedLagrangianContact>(body, scene.obstacles, options);
        newton.set_potential(wrap ? &wrap(*al) : al.get());
    } else if (solver == ContactSolver::ipc) {
        BodyContactOptions ipc_options;
        ipc_options.activation_distance = options.gap;
        ipc_options.self_contact = scene.self_contact;
        ipc_options.vertex_body = scene.vertex_body;
        ipc_options.check_intersections = check_intersections;
        ipc = std::make_unique<ContactPotential>(body_contact_potential(body, scene.obstacles, ipc_options));
        newton.set_potential(wrap ? &wrap(*ipc) : ipc.get());
    }
    const ContactPotential* distances = al ? &al->collision_check() : ipc.get();
    dynamics::State state = dynamics::initial_state(body, scene.u0, scene.v0);
    const Eigen::VectorXd& m = body.dof_masses();
    const auto momentum = [&](const Eigen::VectorXd& v) {
        Eigen::Vector3d p = Eigen::Vector3d::Zero();
        for (Eigen::Index i = 0; i < v.size(); i += 3)
            p += m[i] * v.segment<3>(i);
        return p;
    };
    const Eigen::Vector3d start_momentum = momentum(state.v);
    double momentum_size = 0.0;
    for (Eigen::Index i = 0; i < state.v.size(); i += 3)
        momentum_size += m[i] * state.v.segment<3>(i).norm();
    SolverRun run;
    run.smallest_distance = std::numeric_limits<double>::infinity();
    for (int s = 0; s < scene.steps; ++s) {
        SolverStep step;
        const dynamics::State before = state;
        const int prepares_before = timed != nullptr ? timed->prepares : 0;
        const Timer timer;
        try {
            if (solver == ContactSolver::augmented_lagrangian) {
                AugmentedLagrangianReport report;
                step.newton_iterations =
                    augmented_lagrangian_step(newton, *al, body, scene.scene.time_step, state, &report).newton_iterations;
                step.outer_iterations = report.outer_iterations;
            } else if (solver == ContactSolver::ipc) {
                step.newton_iterations = contact_step(newton, *ipc, body, scene.scene.time_step, state).newton_iterations;
            } else {
                step.newton_iterations = newton.step(body, scene.scene.time_step, state).newton_iterations;
            }
        } catch (const Error& e) {
            run.error = str("step ", s + 1, ": ", e.what());
            break;
        }
        step.seconds = timer.seconds();
        step.factorizations = (timed != nullptr ? timed->prepares : 0) - prepares_before;
        step.smallest_distance = distances != nullptr ? distances->smallest_distance(state.u)
                                                      : std::numeric_limits<double>::infinity();
        step.in_contact = distances != nullptr &&
                          !distances->out_of_contact(before.u, before.time, state.u, state.time);
        if (step.smallest_distance < options.gap)
            run.largest_violation = std::max(run.largest_violation, options.gap - step.smallest_distance);
        run.smallest_distance = std::min(run.smallest_distance, step.smallest_distance);
        if (momentum_size > 0.0)
            run.momentum_drift = std::max(run.momentum_drift, (momentum(state.v) - start_momentum).norm() / momentum_size);
        run.newton_iterations += step.newton_iterations;
        run.factorizations += step.factorizations;
        run.seconds += step.seconds;
        if (step.in_contact) {
            ++run.contact_steps;
            run.contact_iterations += step.newton_iterations;
        }
        run.steps.push_back(step);
        if (observer) {
            const Eigen::VectorXd forces = al    ? al->contact_forces(state.u)
                                           : ipc ? ipc->barrier_forces(state.u)
                                                 : Eigen::VectorXd::Zero(state.u.size());
            observer(body, before, state, forces);
        }
    }
    run.end = state;
    run.new_patterns = timed != nullptr ? timed->new_patterns : 0;
    run.collision_seconds = distances != nullptr ? distances->clocks().collision_seconds : 0.0;
    return run;
}

}  // namespace fem::contact
