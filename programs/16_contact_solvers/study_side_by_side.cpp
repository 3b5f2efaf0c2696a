// Study 2 of ch16_contact_solvers: IPC and the augmented Lagrangian side by side on the same scenes,
// in one run — what each costs (Newton iterations, linear solves, time against the free step) and
// what each keeps (the smallest distance, the constraint d ≥ δ, momentum); then the closed forms
// (a block at rest, the stack) against the weights; then the augmented Lagrangian's open choices
// against their alternatives. docs/16_contact_solvers.md#side-by-side
#include "studies.hpp"

#include "15_body_contact/body_scenes.hpp"

#include "common/figures.hpp"
#include "common/files.hpp"
#include "common/mesh.hpp"
#include "common/mesh_io.hpp"
#include "common/table.hpp"

#include <cmath>
#include <iostream>
#include <limits>

namespace fem::contact::study {
namespace {

/// A distance for a table: the number, or "-" when nothing came within δ (+∞).
Cell distance_cell(double distance)
{
    return std::isfinite(distance) ? Cell(distance) : Cell(std::string("-"));
}

/// The worst |F_z − W| / W over the last step, F the contact force on the vertices of each group
/// above a contact (the block at rest: all; the stack: the blocks above each interface).
double weight_error(const SolverScene& scene, ContactSolver solver)
{
    double error = 0.0;
    const SolverRun run = run_scene(scene, solver, {}, false,
                                    [&](const dynamics::Body& body, const dynamics::State&, const dynamics::State&,
                                        const Eigen::VectorXd& forces) {
                                        const int interfaces = scene.self_contact ? 2 : 1;
                                        error = 0.0;
                                        for (int k = 0; k < interfaces; ++k) {
                                            double weight = 0.0, force = 0.0;
                                            for (Eigen::Index v = 0; v < forces.size() / 3; ++v)
                                                if (!scene.self_contact || stack_block(static_cast<int>(v)) > k) {
                                                    weight += body.dof_masses()[3 * v] * 9.81;
                                                    force += forces[3 * v + 2];
                                                }
                                            error = std::max(error, std::abs(force - weight) / weight);
                                        }
                                    });
    return run.error.empty() ? error : std::numeric_limits<double>::quiet_NaN();
}

/// "-" for a run that completed, else "failed at step N" (the message is printed beside the table).
std::string failure(const SolverRun& run)
{
    return run.error.empty() ? std::string("-") : str("failed at ", run.error.substr(0, run.error.find(':')));
}

/// The block on slopes around tan θ = μ = 0.5 (60 steps, 30 with --quick) with IPC (chapter 14's lagged friction), the augmented
/// Lagrangian with lagged friction and with converged friction: below the threshold the creep speed
/// of the last 10 steps against the mollifier's bound ε_v and its closed form ε_v (1 − √(1 − tan θ/μ));
/// above it the acceleration of the last 10 steps against g (sin θ − μ cos θ); friction_table.csv.
void friction_table(const RunContext& run)
{
    const double mu = 0.5, g = 9.81, dt = 0.01, eps_v = AugmentedLagrangianOptions{}.friction_velocity;
    const int steps = run.quick ? 30 : 60;
    Table table(str("A block on a slope of friction mu = 0.5 near tan(theta) = mu, ", steps, " steps of 1/100 s: below it the creep "
                "speed (the last 10 steps' largest) against eps_v = 1 mm/s and the closed form eps_v (1 - sqrt(1 - tan/mu)); "
                "above it the acceleration's error (the last 10 steps' largest) / g"),
                {{"tan theta / mu", Format::fixed, 2}, {"solver", Format::text, 0}, {"friction", Format::text, 0},
                 {"creep speed / eps_v", Format::scientific, 2}, {"closed-form creep speed / eps_v", Format::scientific, 2},
                 {"acceleration error / g", Format::scientific, 1}, {"Newton iterations", Format::integer, 0}});
    struct Model {
        ContactSolver solver;
        bool converged;
        const char* name;
    };
    const Model models[] = {{ContactSolver::ipc, false, "lagged (IPC's one update)"},
                            {ContactSolver::augmented_lagrangian, false, "lagged"},
                            {ContactSolver::augmented_lagrangian, true, "converged"}};
    const std::vector<double> ratios = run.quick ? std::vector<double>{0.9, 1.2} : std::vector<double>{0.5, 0.9, 0.99, 1.2};
    for (double ratio : ratios) {
        const double slope = std::atan(ratio * mu);
        for (const Model& model : models) {
            AugmentedLagrangianOptions options;
            options.converged_friction = model.converged;
            std::vector<double> velocities;
            const SolverRun result = run_scene(slope_scene(slope, mu, steps), model.solver, options, false,
                                               [&](const dynamics::Body& body, const dynamics::State&,
                                                   const dynamics::State& after, const Eigen::VectorXd&) {
                                                   const Eigen::VectorXd& m = body.dof_masses();
                                                   double momentum = 0.0;
                                                   for (Eigen::Index i = 0; i < m.size(); i += 3)
                                                       momentum += m[i] * after.v[i];
                                                   velocities.push_back(momentum / (m.sum() / 3.0));
                                               });
            double creep = 0.0, error = 0.0;
            for (std::size_t s = velocities.size() - 10; s < velocities.size(); ++s) {
                creep = std::max(creep, std::abs(velocities[s]));
                error = std::max(error, std::abs((velocities[s] - velocities[s - 1]) / dt -
                                                 g * (std::sin(slope) - mu * std::cos(slope))));
            }
            const bool sticks = ratio < 1.0;
            table.add_row({ratio, solver_name(model.solver), std::string(model.name),
                           sticks ? Cell(creep / eps_v) : Cell(std::string("-")),
                           sticks ? Cell(1.0 - std::sqrt(1.0 - ratio)) : Cell(std::string("-")),
                           sticks ? Cell(std::string("-")) : Cell(error / g), double(result.newton_iterations)});
            if (!result.error.empty())
                std::cout << "slope " << ratio << ", " << model.name << ": " << result.error << "\n";
        }
    }
    table.print(std::cout);
    table.write_csv(run.file("friction_table.csv"));
}

}  // namespace

std::vector<SolverScene> comparison_scenes(const RunContext& run, bool bunnies)
{
    // The block dropped on the floor, fired at the turned box, the stack, the block in the bowl (0.15 s,
    // 0.6 s without --quick), fired at the mesh triangle (not with --quick) and two 10 cm blocks of 3³ cells (2³ with --quick) 5 mm apart closing at 1 m/s while each spins at ±5 rad/s about
    // its vertical axis; with bunnies, the coarse bunny (data/bunny_coarse: 2,199 vertices) scaled to
    // 20 cm in their place: chapter 15's study 4.
    const int cells = run.quick ? 2 : 3;  // --quick: 2³ cells, a fifth of the time (CI's sanitizer run)
    SolverScene two = two_bodies_scene(box_mesh(cells, cells, cells, Eigen::Vector3d::Constant(0.1)), 0.1, 5e-3, 0.5, 5.0, 8);
    two.name = "two blocks";
    SolverScene drop = drop_scene(0.05, 40);
    SolverScene stack = stack_scene(1e-3, run.quick ? 50 : 100);
    std::vector<SolverScene> scenes{drop,  fired_scene(turned_box(), 10.0), fired_scene(turned_box(), 100.0),
                                    stack, two, bowl_scene(1, run.quick ? 15 : 60)};
    // Chapter 15's single mesh triangle, its corner up under the fired block (the full run only:
    // the docs' table).
    for (double speed : {10.0, 100.0})
        if (!run.quick) {
            SolverScene fired = fired_scene(triangle_under_block(), speed);
            fired.name = str("block fired at ", speed, " m/s at the mesh triangle");
            scenes.push_back(fired);
        }
    if (bunnies) {
        SolverScene pair = two_bodies_scene(io::read_tet_mesh(data_path("bunny_coarse.node")), 0.2, 5e-3, 0.5, 5.0, 8);
        pair.name = "two bunnies";
        scenes.push_back(pair);
    }
    return scenes;
}

void side_by_side_study(const RunContext& run, const std::vector<SolverScene>& scenes)
{
    std::cout << "\n== Side by side: IPC and the augmented Lagrangian on the same scenes — the iterations of the steps\n"
                 "   in contact by kind, Newton iterations, linear solves, time against the free step, distances,\n"
                 "   the constraint, momentum\n\n";
    Table trace("Newton iterations of the steps in contact, by kind: the first trial cut by the time of impact, "
                "moving the surface by more than 1e-2 delta, Newton's tail (delta = d-hat = 1 mm)",
                {{"scene", Format::text, 0}, {"solver", Format::text, 0}, {"steps in contact", Format::integer, 0},
                 {"Newton iterations", Format::integer, 0}, {"cut by the time of impact", Format::integer, 0},
                 {"moving the surface", Format::integer, 0}, {"Newton's tail", Format::integer, 0}});
    Table table("IPC (chapter 14's contact_step, d-hat = 1 mm) and the augmented Lagrangian (delta = 1 mm) on the "
                "same scenes; a step is in contact when some pair comes within 1 mm at its start or end or a "
                "vertex's path meets an obstacle",
                {{"scene", Format::text, 0}, {"solver", Format::text, 0}, {"steps", Format::integer, 0},
                 {"steps in contact", Format::integer, 0}, {"Newton iterations", Format::integer, 0},
                 {"Newton iterations in contact", Format::integer, 0},
                 {"Newton iterations per step in contact", Format::fixed, 2},
                 {"linear solves", Format::integer, 0}, {"new matrix patterns", Format::integer, 0},
                 {"time per step [ms]", Format::fixed, 3},
                 {"time per step / free step [measured]", Format::fixed, 1},
                 {"collision check share [measured]", Format::fixed, 2},
                 {"smallest distance [m]", Format::scientific, 2}, {"largest violation below delta [m]", Format::scientific, 2},
                 {"momentum drift [round-off]", Format::scientific, 1}, {"error", Format::text, 0}});
    for (const SolverScene& scene : scenes) {
        const SolverRun free = run_scene(scene, ContactSolver::none);
        const double free_step = free.seconds / std::max<std::size_t>(1, free.steps.size());
        std::vector<fig::Series> series;
        for (ContactSolver solver : {ContactSolver::ipc, ContactSolver::augmented_lagrangian}) {
            const TracedRun traced = traced_run(scene, solver);
            const SolverRun& result = traced.run;
            trace.add_row({scene.name, solver_name(solver), double(result.contact_steps),
                           double(traced.cut + traced.moving + traced.tail), double(traced.cut), double(traced.moving),
                           double(traced.tail)});
            if (!result.error.empty())
                std::cout << scene.name << ", " << solver_name(solver) << ": " << result.error << "\n";
            const double per_step = result.seconds / std::max<std::size_t>(1, result.steps.size());
            const bool moving = scene.v0.size() > 0 && scene.scene.gravity.norm() == 0.0 && scene.obstacles.empty();
            table.add_row({scene.name, solver_name(solver), double(result.steps.size()), double(result.contact_steps),
                           double(result.newton_iterations), double(result.contact_iterations),
                           result.contact_steps > 0 ? double(result.contact_iterations) / result.contact_steps : 0.0,
                           double(result.factorizations), double(result.new_patterns), 1e3 * per_step,
                           per_step / free_step, result.seconds > 0.0 ? result.collision_seconds / result.seconds : 0.0,
                           distance_cell(result.smallest_distance), result.largest_violation,
                           moving ? Cell(result.momentum_drift) : Cell(std::string("-")),
                           failure(result)});
            fig::Series line{solver_name(solver), {}, {}};
            for (std::size_t s = 0; s < result.steps.size(); ++s) {
                line.x.push_back(double(s + 1));
                line.y.push_back(result.steps[s].newton_iterations);
            }
            series.push_back(line);
        }
        fig::LineChart chart;
        chart.title = str(scene.name, ": Newton iterations per step");
        chart.x_label = "step";
        chart.y_label = "Newton iterations";
        chart.series = series;
        std::string stem = scene.name;
        for (char& c : stem)
            c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
        fig::save_chart(chart, run.file("newton_per_step_" + stem), run.figures);
    }
    trace.print(std::cout);
    trace.write_csv(run.file("trace_table.csv"));
    table.print(std::cout);
    table.write_csv(run.file("side_by_side_table.csv"));

    std::cout << "\n   The closed forms: the contact forces against the weights they carry\n\n";
    Table forms("A block resting on the floor (placed 0.5 mm up, 100 steps of 1/100 s) and the stack of three: "
                "|F_z - W| / W after the last step, F the contact force on the blocks above each contact",
                {{"scene", Format::text, 0}, {"solver", Format::text, 0}, {"force error / weight", Format::scientific, 1}});
    SolverScene resting = drop_scene(0.5e-3, 100);
    resting.name = "block at rest";
    for (const SolverScene* scene : {static_cast<const SolverScene*>(&resting), &scenes[3]})
        for (ContactSolver solver : {ContactSolver::ipc, ContactSolver::augmented_lagrangian})
            forms.add_row({scene->name, solver_name(solver), weight_error(*scene, solver)});
    forms.print(std::cout);
    forms.write_csv(run.file("closed_forms_table.csv"));

    std::cout << "\n   Friction near the stick-slip threshold: lagged against converged\n\n";
    friction_table(run);

    std::cout << "\n   The augmented Lagrangian's open choices against their alternatives\n\n";
    Table choices("The augmented Lagrangian's choices (docs: the penalty, the active set, the warm start) against "
                  "their alternatives on the fired block at 10 m/s, the two bodies and the stack",
                  {{"scene", Format::text, 0}, {"variant", Format::text, 0}, {"Newton iterations", Format::integer, 0},
                   {"Newton iterations in contact", Format::integer, 0}, {"time per step [ms]", Format::fixed, 3},
                   {"error", Format::text, 0}});
    struct Variant {
        const char* name;
        AugmentedLagrangianOptions options;
    };
    std::vector<Variant> variants(5);
    variants[0].name = "default (mu from the kinetic energy, filter 1 delta, 2 stale steps)";
    variants[1].name = "mu = 100 m / dt^2 alone (no kinetic bound)";
    variants[1].options.kinetic_penalty = false;
    variants[2].name = "filter 10 delta (a larger active set)";
    variants[2].options.filter_gap = 10.0;
    variants[3].name = "penalty growth 1 (mu never raised)";
    variants[3].options.penalty_growth = 1.0;
    variants[4].name = "multipliers from 0 each step (no warm start)";
    variants[4].options.warm_multipliers = false;
    // The fired block at 10 m/s, and (not with --quick: most of its time) the two blocks and the
    // stack (resting contact, where the multipliers carry over from step to step).
    std::vector<const SolverScene*> chosen{&scenes[1]};
    if (!run.quick)
        chosen.insert(chosen.end(), {&scenes[4], &scenes[3]});
    for (const SolverScene* scene : chosen)
        for (const Variant& variant : variants) {
            const SolverRun result = run_scene(*scene, ContactSolver::augmented_lagrangian, variant.options);
            choices.add_row({scene->name, std::string(variant.name), double(result.newton_iterations),
                             double(result.contact_iterations),
                             1e3 * result.seconds / std::max<std::size_t>(1, result.steps.size()),
                             failure(result)});
            if (!result.error.empty())
                std::cout << scene->name << ", " << variant.name << ": " << result.error << "\n";
        }
    choices.print(std::cout);
    choices.write_csv(run.file("choices_table.csv"));
}

}  // namespace fem::contact::study
