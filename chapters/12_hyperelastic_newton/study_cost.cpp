// Study 4 of ch12_hyperelastic_newton: what a Newton iteration costs — ψ and P per element, the
// exact and the projected Hessian into the fixed pattern, the step matrix, the solve — on beams up
// to 36k dofs; a 10 000-vertex neo-Hookean step against Vega's StVK. docs/12_hyperelastic_newton.md#cost
#include "12_hyperelastic_newton/studies.hpp"

#include "11_corotational/frozen_preconditioner.hpp"

#include "10_linear_dynamics/time_integration.hpp"

#include "06_assembly/assembly.hpp"

#include "common/error.hpp"
#include "common/parallel.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <algorithm>
#include <iostream>

namespace fem::hyper::study {

void cost_study(const RunContext& run, const Settings& settings)
{
    std::cout << "\n== 4. Cost of a Newton iteration (neo-Hookean, backward Euler at dt = 1/60 s)\n\n";
    Table parts("The parts of one Newton iteration at a sagging state",
                {{"free dofs", Format::integer}, {"tets", Format::integer}, {"energy and forces [s]", Format::scientific, 2},
                 {"exact Hessian [s]", Format::scientific, 2}, {"projected Hessian [s]", Format::scientific, 2},
                 {"step matrix [s]", Format::scientific, 2}, {"factor and solve [s]", Format::scientific, 2}});
    for (int cells : settings.cost_cells) {
        dynamics::Scene scene = dynamics::cantilever_scene(dynamics::Material{1e6, 0.45, 1100.0}, cells, 1.0);
        dynamics::Body body(scene, make_force_model("neo-hookean", scene.mesh, scene.material));
        NewtonBackwardEuler newton;
        dynamics::State state = dynamics::initial_state(body);
        for (int k = 0; k < 3; ++k)
            newton.step(body, scene.time_step, state);
        auto& model = dynamic_cast<HyperelasticElasticity&>(body.model());
        Eigen::VectorXd forces;
        const double evaluate = best_time([&] { model.evaluate(state.u, forces); }, settings.seconds);
        const double exact = best_time([&] { (void)model.stiffness(state.u); }, settings.seconds);
        const double projected = best_time([&] { (void)model.definite_stiffness(state.u); }, settings.seconds);
        const dynamics::SparseMatrix K = model.stiffness(state.u);
        dynamics::ReducedStepMatrix reduced(body.mass_matrix(), K, body.dofs());  // what a Newton iteration refills
        const double matrix = best_time([&] {
            (void)reduced.assemble(body.mass_matrix(), K, scene.damping, scene.time_step, 1.0);
        }, settings.seconds);
        const dynamics::SparseMatrix A = reduced.assemble(body.mass_matrix(), K, scene.damping, scene.time_step, 1.0);
        const auto solver = cg::make_solver("default");
        const Eigen::VectorXd b = Eigen::VectorXd::Ones(A.rows());
        const double solve = best_time([&] {
            solver->prepare(A);
            (void)solver->solve(b);
        }, settings.seconds);
        parts.add_row({double(body.dofs().size()), double(scene.mesh.T.rows()), evaluate, exact, projected, matrix, solve});
    }
    parts.print(std::cout);
    parts.write_csv(run.file("parts_table.csv"));

    // Why: the per-element loops (energy, forces, Hessians) run on every core (common/parallel.hpp)
    // with the sums in tet order afterwards, so more threads must change the time and nothing else.
    Table threads("The element loops on 1 and 2 threads (OpenMP), the largest beam at its sagging state",
                  {{"threads", Format::integer}, {"energy and forces [s]", Format::scientific, 2},
                   {"projected Hessian [s]", Format::scientific, 2}, {"speed-up of the Hessian [measured]", Format::fixed, 2},
                   {"results identical to 1 thread", Format::text}});
    {
        const dynamics::Scene scene =
            dynamics::cantilever_scene(dynamics::Material{1e6, 0.45, 1100.0}, settings.cost_cells.back(), 1.0);
        dynamics::Body body(scene, make_force_model("neo-hookean", scene.mesh, scene.material));
        NewtonBackwardEuler newton;
        dynamics::State state = dynamics::initial_state(body);
        newton.step(body, scene.time_step, state);
        auto& model = dynamic_cast<HyperelasticElasticity&>(body.model());
        Eigen::VectorXd forces, first_forces;
        dynamics::SparseMatrix first_hessian;
        double first_time = 0.0;
        const int original = thread_count();
        for (const int count : {1, 2}) {
            set_thread_count(count);
            const double evaluate = best_time([&] { model.evaluate(state.u, forces); }, settings.seconds);
            const double hessian = best_time([&] { (void)model.definite_stiffness(state.u); }, settings.seconds);
            const dynamics::SparseMatrix& K = model.definite_stiffness(state.u);
            bool identical = true;
            if (count == 1) {
                first_forces = forces;
                first_hessian = K;
                first_time = hessian;
            } else {
                identical = forces == first_forces && K.nonZeros() == first_hessian.nonZeros() &&
                            std::equal(K.valuePtr(), K.valuePtr() + K.nonZeros(), first_hessian.valuePtr());
            }
            threads.add_row({double(count), evaluate, hessian, first_time / hessian, std::string(identical ? "yes" : "no")});
        }
        set_thread_count(original);
    }
    threads.print(std::cout);
    threads.write_csv(run.file("threads_table.csv"));

    // Why: a published reference point. Vega runs StVK on a 9 875-vertex mesh at 2 steps per second.
    dynamics::Scene vega = dynamics::cantilever_scene(dynamics::Material{1e6, 0.45, 1100.0}, 2, 1.0);
    vega.mesh = box_mesh(60, 12, 12, Eigen::Vector3d(0.2, 0.04, 0.04));  // 61 × 13 × 13 = 10 309 vertices
    vega.pinned = assembly::vertices_on_plane(vega.mesh, 0, 0.0);
    dynamics::Body body(vega, make_force_model("neo-hookean", vega.mesh, vega.material));
    Table goal("A 10,000-vertex neo-Hookean backward Euler step, converged (relative tolerance 1e-6), one core",
               {{"vertices", Format::integer}, {"free dofs", Format::integer}, {"Newton solver", Format::text},
                {"Newton iterations per step", Format::fixed, 1}, {"CG iterations per step", Format::fixed, 1},
                {"factorizations per step", Format::fixed, 2}, {"our step [s]", Format::scientific, 2},
                {"Vega's StVK step (published) (s)", Format::fixed, 2}, {"published / our time (other machine, StVK) [measured]", Format::fixed, 1}});
    // Why: each Newton iteration's matrix changes. Refactoring it every iteration is the plain way;
    // chapter 11's frozen factor (single precision, refreshed when CG needs more than 10
    // iterations) as CG's preconditioner, solved only as tightly as the gradient needs (inexact
    // Newton), keeps one factorization for several steps.
    const int threads_before = thread_count();
    set_thread_count(1);  // the goal is on one core
    for (const std::string solver : {"refactor", "frozen-factor-pcg"}) {
        NewtonOptions options;
        if (solver == "frozen-factor-pcg")
            options.make_solver = [] { return std::make_unique<corot::FrozenFactorPcg>(cg::SolverOptions{1e-8, 0},
                                                                                  corot::RefreshRule{.iterations_above = 10}); };
        NewtonBackwardEuler newton(options);
        dynamics::State state = dynamics::initial_state(body);
        newton.step(body, vega.time_step, state);  // the first step orders and factors: not counted
        const auto* frozen = dynamic_cast<const corot::FrozenFactorPcg*>(&newton.solver());
        const int steps = run.quick ? 2 : 8, factored_before = frozen != nullptr ? frozen->factorizations() : 0;
        int iterations = 0, cg_iterations = 0, factorizations = 0;
        Timer clock;
        for (int k = 0; k < steps; ++k) {
            const dynamics::StepInfo info = newton.step(body, vega.time_step, state);
            iterations += info.newton_iterations;
            cg_iterations += info.solver_iterations;
            factorizations += info.newton_iterations + newton.last().definite_fallbacks;  // refactoring: one per solve
        }
        const double ours = clock.seconds() / steps;
        if (frozen != nullptr)
            factorizations = frozen->factorizations() - factored_before;
        goal.add_row({double(vega.mesh.V.rows()), double(body.dofs().size()), solver, double(iterations) / steps,
                      double(cg_iterations) / steps, double(factorizations) / steps, ours, 0.5, 0.5 / ours});
    }
    set_thread_count(threads_before);
    goal.print(std::cout);
    goal.write_csv(run.file("vega_table.csv"));
}

}  // namespace fem::hyper::study
