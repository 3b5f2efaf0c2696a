// Study 6 of ch10_linear_dynamics: what a simulated second costs, four ways, on beams up to 36k
// dofs; the prefactored step against its floor and against other libraries' sparse Cholesky (peers,
// like for like); SOFA's beam. docs/10_linear_dynamics.md#cost
#include "10_linear_dynamics/modes.hpp"
#include "studies.hpp"

#include "common/error.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <cmath>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

namespace fem::dynamics::study {
namespace {

/// Time per step of `integrator` on body, from rest under gravity: the best of `steps` steps after
/// one first step (which prepares the matrix; its time is returned in first_step). The state after
/// the 1 + steps steps is left in `final_state` when given.
double step_time(Body& body, Integrator& integrator, double time_step, int steps, double& first_step,
                 double& iterations, State* final_state = nullptr)
{
    State state = initial_state(body);
    Timer first;
    integrator.step(body, time_step, state);
    first_step = first.seconds();
    double best = 1e300, total_iterations = 0.0;
    for (int k = 0; k < steps; ++k) {
        Timer clock;
        const StepInfo info = integrator.step(body, time_step, state);
        best = std::min(best, clock.seconds());
        total_iterations += info.solver_iterations;
    }
    iterations = total_iterations / steps;
    if (final_state != nullptr)
        *final_state = std::move(state);
    return best;
}

}  // namespace

void cost_study(const RunContext& run, const Settings& settings)
{
    std::cout << "\n== 6. Cost: time per simulated second (dt = 1/60 s for the implicit steps)\n\n";
    // Why: the step matrix is constant, so a factorization made once serves every step; the
    // alternatives show what that saves and what explicit stepping would cost instead.
    const double dt = 1.0 / 60.0;
    const int steps = run.quick ? 5 : 20;
    Table cost("Backward Euler on the beam under gravity, four ways; explicit Euler at 0.9 of its limit",
               {{"free dofs", Format::integer}, {"method", Format::text}, {"setup time [s]", Format::scientific, 2},
                {"time per step [s]", Format::scientific, 2}, {"CG iterations per step", Format::fixed, 1},
                {"steps per simulated second", Format::integer}, {"time per simulated second [s]", Format::scientific, 2}});
    Table floor("The prefactored step against its floor: one product with K_ff plus one solve (two triangular solves)",
                {{"free dofs", Format::integer}, {"nnz(K_ff)", Format::integer},
                 {"floor [s]", Format::scientific, 2}, {"step, solve for dv [s]", Format::scientific, 2},
                 {"step, solve for v+ [s]", Format::scientific, 2}, {"dv step / floor [measured]", Format::fixed, 2},
                 {"v+ step / floor [measured]", Format::fixed, 2}});
    // Peers, like for like: the same prefactored step (same beam, Δt, exact solve), only the
    // factorization and the triangular solves from another library.
    Table peers("Peers, like for like: the prefactored backward Euler step on the beam with each library's sparse "
                "Cholesky (one core; the same steps from rest)",
                {{"free dofs", Format::integer}, {"solver", Format::text}, {"factorization [s]", Format::scientific, 2},
                 {"time per step [s]", Format::scientific, 2}, {"step / ours [measured]", Format::fixed, 2},
                 {"max |u - u_ours| / max |u_ours| [round-off]", Format::scientific, 1}});
    std::vector<std::pair<std::string, std::string>> peer_solvers{{"eigen-llt", "Eigen SimplicialLLT"}};
    if (cg::cholmod_available())
        peer_solvers.emplace_back("cholmod", "CHOLMOD supernodal LLT");
    else
        std::cout << "CHOLMOD: not in this build (install libsuitesparse-dev and configure again for its row)\n";
    for (int cells : settings.cost_cells) {
        Scene scene = cantilever_scene(settings.beam, cells);
        Body body(scene);
        const FreeDofs& dofs = body.dofs();
        const double free_dofs = double(dofs.size());
        const SparseMatrix K = dofs.reduce(body.model().stiffness(Eigen::VectorXd::Zero(dofs.full_size())));

        double first = 0.0, iterations = 0.0;
        ThetaMethod once(1.0);
        State ours_state;  // the default solver's (ours) state after the steps: the peers' reference
        const double once_step = step_time(body, once, dt, steps, first, iterations, &ours_state);
        peers.add_row({free_dofs, std::string("ours (supernodal, ch08)"), first - once_step, once_step, 1.0, 0.0});
        cost.add_row({free_dofs, std::string("factor once"), first - once_step, once_step, 0.0, 60.0,
                      first - once_step + 60.0 * once_step});

        ImplicitOptions every_options;
        every_options.refactor_every_step = true;
        ThetaMethod every(1.0, every_options);
        const double every_step = step_time(body, every, dt, std::max(2, steps / 4), first, iterations);
        cost.add_row({free_dofs, std::string("refactor every step"), 0.0, every_step, 0.0, 60.0, 60.0 * every_step});

        ImplicitOptions pcg_options;
        pcg_options.solver = "ours-pcg-ic0";
        ThetaMethod pcg(1.0, pcg_options);
        const double pcg_step = step_time(body, pcg, dt, steps, first, iterations);
        cost.add_row({free_dofs, std::string("PCG (IC0), warm start"), first - pcg_step, pcg_step, iterations, 60.0,
                      first - pcg_step + 60.0 * pcg_step});

        const double limit = explicit_stability_limit(highest_frequency(K, dofs.reduce(body.mass_matrix())));
        SymplecticEuler explicit_euler;
        const double explicit_step = step_time(body, explicit_euler, 0.9 * limit, steps, first, iterations);
        const double explicit_steps = std::ceil(1.0 / (0.9 * limit));
        cost.add_row({free_dofs, std::string("explicit, 0.9 x limit"), 0.0, explicit_step, 0.0, explicit_steps,
                      explicit_steps * explicit_step});

        // The floor: the same solver, prepared on the same matrix, and one product with K_ff.
        const std::unique_ptr<cg::LinearSolver> solver = cg::make_solver("default");
        solver->prepare(dofs.reduce(step_matrix(body.mass_matrix(), body.model().stiffness(Eigen::VectorXd::Zero(dofs.full_size())),
                                                scene.damping, dt)));
        const Eigen::VectorXd x = Eigen::VectorXd::Ones(dofs.size());
        Eigen::VectorXd y(dofs.size());
        const double floor_time = best_time([&] {
            y.noalias() = K * x;
            y = solver->solve(y);
        }, settings.seconds);
        ImplicitOptions lecture;
        lecture.form = StepForm::velocity;
        ThetaMethod lecture_step(1.0, lecture);
        const double lecture_time = step_time(body, lecture_step, dt, steps, first, iterations);
        floor.add_row({free_dofs, double(K.nonZeros()), floor_time, once_step, lecture_time, once_step / floor_time,
                       lecture_time / floor_time});

        for (const auto& [solver_name, label] : peer_solvers) {
            ImplicitOptions peer_options;
            peer_options.solver = solver_name;
            ThetaMethod peer(1.0, peer_options);
            State peer_state;
            const double peer_step = step_time(body, peer, dt, steps, first, iterations, &peer_state);
            peers.add_row({free_dofs, label, first - peer_step, peer_step, peer_step / once_step,
                           (peer_state.u - ours_state.u).lpNorm<Eigen::Infinity>() /
                               ours_state.u.lpNorm<Eigen::Infinity>()});
        }
    }
    cost.print(std::cout);
    cost.write_csv(run.file("cost_table.csv"));
    floor.print(std::cout);
    floor.write_csv(run.file("floor_table.csv"));
    peers.print(std::cout);
    peers.write_csv(run.file("peers_table.csv"));

    // Why: the whole step on 1 and 2 threads (the threads goal, 1.7× on 2 cores): the products of the
    // right-hand side and the two triangular solves with the factor made once; the same bits on any
    // number of threads.
    {
        const Scene scene = cantilever_scene(settings.beam, settings.cost_cells.back());
        Body body(scene);
        ThetaMethod integrator(1.0);
        State start = initial_state(body);
        for (int k = 0; k < 3; ++k)  // a moving, sagging beam; the step matrix is factored by now
            integrator.step(body, dt, start);
        const Table threads = step_threads_table(
            "The prefactored backward Euler step (right-hand side, two triangular solves)", body, integrator, start, dt,
            settings.seconds);
        threads.print(std::cout);
        threads.write_csv(run.file("threads_table.csv"));
    }

    // Why: a published reference point. SOFA's implicit Euler on its 1,664-vertex validation beam
    // takes 8.5 ms a step with CG capped at 20 iterations (an inexact solve).
    Scene sofa = cantilever_scene(settings.beam, 2);
    sofa.mesh = box_mesh(25, 7, 7, Eigen::Vector3d(0.2, 0.02, 0.02));  // 26 × 8 × 8 = 1,664 vertices
    sofa.pinned = assembly::vertices_on_plane(sofa.mesh, 0, 0.0);
    Body body(sofa);
    ThetaMethod integrator(1.0);
    double first = 0.0, iterations = 0.0;
    const double ours = step_time(body, integrator, dt, steps, first, iterations);
    const double sofa_ms = 8.5;
    Table goal("SOFA's beam (1,664 vertices): our prefactored backward Euler step, exact solve, one core",
               {{"vertices", Format::integer}, {"free dofs", Format::integer}, {"factorization [s]", Format::scientific, 2},
                {"our step [ms]", Format::fixed, 3}, {"SOFA's step (published) (ms)", Format::fixed, 1},
                {"published / our time (other machine, other model) [measured]", Format::fixed, 1}});
    goal.add_row({double(sofa.mesh.V.rows()), double(body.dofs().size()), first - ours, 1e3 * ours, sofa_ms,
                  sofa_ms / (1e3 * ours)});
    goal.print(std::cout);
    goal.write_csv(run.file("sofa_table.csv"));
}

}  // namespace fem::dynamics::study
