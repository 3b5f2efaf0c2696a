// Study 3 of ch11_corotational: what a corotational step costs — the rotations, the forces, the
// warped stiffness, the step matrix and the solve — on beams up to 36k dofs, with four ways to
// solve a matrix that changes every step; SOFA's corotational beam as the goal; the plain route
// (plain_routes.hpp) against ours, like for like, and what each speed-up adds.
// docs/11_corotational.md#cost
#include "11_corotational/frozen_preconditioner.hpp"
#include "11_corotational/plain_routes.hpp"
#include "studies.hpp"

#include "06_assembly/assembly.hpp"
#include "09_conjugate_gradient/conjugate_gradient.hpp"
#include "09_conjugate_gradient/linear_operator.hpp"

#include "common/error.hpp"
#include "common/parallel.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <functional>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

namespace fem::corot::study {
namespace {

/// The relative residual every solver of this study converges to (the goal's "converged solve").
constexpr double solve_tolerance = 1e-8;

/// Mean time per step and CG iterations per step of `steps` backward Euler steps from `start`
/// (the first step, which makes the solver, is not counted).
struct StepCost {
    double seconds = 0.0, iterations = 0.0;
    int factorizations = 0;
};

StepCost step_cost(dynamics::Body& body, const dynamics::ImplicitOptions& options, const dynamics::State& start,
                   int steps)
{
    dynamics::ThetaMethod integrator(1.0, options);
    dynamics::State state = start;
    const double dt = body.scene().time_step;
    integrator.step(body, dt, state);
    StepCost cost;
    Timer clock;
    for (int k = 0; k < steps; ++k)
        cost.iterations += integrator.step(body, dt, state).solver_iterations;
    cost.seconds = clock.seconds() / steps;
    cost.iterations /= steps;
    if (const auto* frozen = dynamic_cast<const FrozenFactorPcg*>(&integrator.solver()))
        cost.factorizations = frozen->factorizations();
    return cost;
}

/// One route of the peers table: a force model and the options of its step.
struct Route {
    std::string name;
    std::function<std::unique_ptr<dynamics::ForceModel>(const dynamics::Scene&)> model;
    std::function<dynamics::ImplicitOptions(dynamics::Body&)> options;
};

/// The plain route, then one speed-up of the chapter added per row (the last row is the fastest
/// step the chapter has, the one the SOFA goal times).
std::vector<Route> ladder()
{
    const auto plain_model = [](plain::PlainRotation rotation) {
        return [rotation](const dynamics::Scene& scene) -> std::unique_ptr<dynamics::ForceModel> {
            return std::make_unique<plain::PlainCorotational>(scene.mesh, scene.material, rotation);
        };
    };
    const auto our_model = [](ForceForm form) {
        return [form](const dynamics::Scene& scene) -> std::unique_ptr<dynamics::ForceModel> {
            return std::make_unique<CorotationalElasticity>(scene.mesh, scene.material, RotationFit::polar,
                                                            PolarAlgorithm::newton, form);
        };
    };
    const auto plain_solver = [](dynamics::Body&) { return plain::plain_step_options(); };
    const auto named = [](const std::string& name) {
        return [name](dynamics::Body& body) { return solver_option(name, solve_tolerance, body); };
    };
    return {{"plain: JacobiSVD per tet, triplets, SimplicialLLT refactored", plain_model(plain::PlainRotation::jacobi_svd),
             plain_solver},
            {"+ polar iteration (Newton) for the rotations", plain_model(plain::PlainRotation::polar_newton), plain_solver},
            {"+ K_R into the fixed pattern, step matrix refilled", our_model(ForceForm::stiffness_matrix), plain_solver},
            {"+ supernodal Cholesky, symbolic analysis reused", our_model(ForceForm::stiffness_matrix), named("refactor")},
            {"+ frozen factor turned with the body, PCG to 1e-8", our_model(ForceForm::stiffness_matrix),
             named("rotated-frozen-factor-pcg")},
            {"+ shape-gradient forces (ours, fastest)", our_model(ForceForm::shape_gradients),
             named("rotated-frozen-factor-pcg")}};
}

/// Mean time per step of `steps` backward Euler steps from `start` by one route, every step counted
/// (the first one makes the solver and factors: a route's setup is part of its cost), the best of
/// `repeats` runs (on a shared machine another job's burst slows one run, not all); the state
/// after them in `final_state`.
double route_time(const dynamics::Scene& scene, const Route& route, const dynamics::State& start, int steps,
                  int repeats, dynamics::State& final_state)
{
    double best = 1e300;
    for (int r = 0; r < repeats; ++r) {
        dynamics::Body body(scene, route.model(scene));
        dynamics::ThetaMethod integrator(1.0, route.options(body));
        dynamics::State state = dynamics::initial_state(body, start.u, start.v);
        Timer clock;
        for (int k = 0; k < steps; ++k)
            integrator.step(body, scene.time_step, state);
        best = std::min(best, clock.seconds() / steps);
        final_state = std::move(state);
    }
    return best;
}

/// The state after `steps` backward Euler steps from rest: a beam bent by its weight, its
/// elements rotated, still moving.
dynamics::State sagging_state(dynamics::Body& body, int steps)
{
    dynamics::ThetaMethod integrator(1.0);
    dynamics::State state = dynamics::initial_state(body);
    for (int k = 0; k < steps; ++k)
        integrator.step(body, body.scene().time_step, state);
    return state;
}

/// Plain PCG (chapter 09's preconditioned_conjugate_gradient, β = r_{k+1}ᵀz_{k+1} / r_kᵀz_k), and
/// flexible PCG (the same with CgBeta::polak_ribiere, β = z_{k+1}ᵀ(r_{k+1} − r_k) / r_kᵀz_k), on the
/// step matrix A = Pᵀ(M + Δt D + Δt² K_R(u))P at `state`, from x₀ = 0 with the lecture's right-hand
/// side b = Pᵀ(M v + Δt (f + f_ext)), preconditioned by a stale factor: the Cholesky factor of the
/// step matrix at an earlier state, A₀ = Pᵀ(M + Δt D + Δt² K_R(u₀))P, applied in single precision (z = A₀⁻¹ r through
/// the float copy of L, which is neither exactly linear nor exactly symmetric) and in double
/// precision (plain PCG only). One row per run and iteration k = 0 … `iterations`: the residual CG updates,
/// ‖r_k‖₂/‖b‖₂, and the true one, ‖b − A x_k‖₂/‖b‖₂, computed afresh from x_k.
/// docs/11_corotational.md#a-single-precision-preconditioner
Table residual_table(dynamics::Body& body, const dynamics::State& earlier, const dynamics::State& state, int iterations)
{
    const dynamics::Scene& scene = body.scene();
    dynamics::ForceModel& model = body.model();
    const dynamics::SparseMatrix& M = body.mass_matrix();
    dynamics::ReducedStepMatrix reduced(M, model.stiffness(earlier.u), body.dofs());
    const dynamics::SparseMatrix A0 =
        reduced.assemble(M, model.stiffness(earlier.u), scene.damping, scene.time_step, 1.0);
    Eigen::VectorXd forces;
    model.evaluate(state.u, forces);
    const dynamics::SparseMatrix A = reduced.assemble(M, model.stiffness(state.u), scene.damping, scene.time_step, 1.0);
    const Eigen::VectorXd b = body.dofs().gather(
        dynamics::step_right_hand_side(M, state.v, forces, body.external_forces(), scene.time_step));
    direct::CholeskyOptions factor_options;
    factor_options.single_precision_copy = true;
    const direct::SparseCholesky factor(A0, factor_options);

    Table table("PCG on the bent beam's step matrix with a stale factor (the step matrix 5 steps "
                "earlier): the residual CG updates and the true one, per iteration",
                {{"factor", Format::text}, {"iteration", Format::integer},
                 {"updated |r_k| / |b|", Format::scientific, 2}, {"true |b - A x_k| / |b|", Format::scientific, 2}});
    const cg::FunctionOperator product(A.rows(), [&](const Eigen::VectorXd& v, Eigen::VectorXd& Av) {
        Av.noalias() = A * v;
    });
    struct Variant {
        std::string name;
        bool single, flexible;
    };
    for (const Variant& run : {Variant{"single precision", true, false}, Variant{"double precision", false, false},
                               Variant{"single precision, flexible PCG", true, true}}) {
        const cg::FunctionOperator preconditioner(A.rows(), [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
            z = run.single ? factor.solve_single_precision(r) : factor.solve(r);
        });
        cg::CgSettings settings;
        settings.relative_tolerance = 1e-15;  // below round-off: the cap ends every run
        settings.max_iterations = iterations;
        settings.observer = [&](int k, const Eigen::VectorXd& x, double updated) {
            table.add_row({run.name, double(k), updated, (b - A * x).norm() / b.norm()});
        };
        settings.beta = run.flexible ? cg::CgBeta::polak_ribiere : cg::CgBeta::fletcher_reeves;
        Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
        (void)cg::preconditioned_conjugate_gradient(product, preconditioner, b, x, settings);
    }
    return table;
}

/// The largest beam (cells along it) of the peers table.
constexpr int largest_peer_cells = 60;

/// Peers, like for like: the plain route and every rung of the ladder on the cost study's beams of
/// at most largest_peer_cells cells, from the same bent state, the same Δt and number of steps, on
/// one core.
void peers_study(const RunContext& run, const Settings& settings)
{
    const int steps = run.quick ? 3 : 5, repeats = 2;
    Table peers(str("Peers, like for like: the plain corotational step against ours (the same ", steps,
                    " backward Euler steps from a bent state, dt = 1/60 s, one core, the best of ", repeats, " runs)"),
                {{"free dofs", Format::integer}, {"tets", Format::integer}, {"plain step [s]", Format::scientific, 2},
                 {"our step [s]", Format::scientific, 2}, {"plain / ours [measured]", Format::fixed, 1},
                 {"max |u - u_plain| / max |u_plain| [±1e-7]", Format::scientific, 1}});
    Table rungs("From the plain step to ours, one speed-up at a time (each row adds one to the row above; same run, "
                "same steps)",
                {{"free dofs", Format::integer}, {"route", Format::text}, {"time per step [s]", Format::scientific, 2},
                 {"row above / this row [measured]", Format::fixed, 2}, {"plain / this row [measured]", Format::fixed, 1},
                 {"max |u - u_plain| / max |u_plain| [±1e-7]", Format::scientific, 1}});
    const ScopedThreadCount one_core(1);  // like for like: the plain route runs on one core
    for (int cells : settings.cost_cells) {
        if (cells > largest_peer_cells)
            continue;  // the plain route's fresh factorizations take seconds a step beyond it
        const dynamics::Scene scene = dynamics::cantilever_scene(settings.sofa, cells, 1.0);
        dynamics::Body body(scene, force_model("corotational", scene));
        const dynamics::State start = sagging_state(body, 10);
        const double free_dofs = double(body.dofs().size());
        dynamics::State plain_state;
        double plain_time = 0.0, previous = 0.0, deviation = 0.0, ours = 0.0;
        for (const Route& route : ladder()) {
            dynamics::State state;
            const double seconds = route_time(scene, route, start, steps, repeats, state);
            if (plain_state.u.size() == 0) {
                plain_state = state;
                plain_time = previous = seconds;
            }
            deviation = (state.u - plain_state.u).lpNorm<Eigen::Infinity>() / plain_state.u.lpNorm<Eigen::Infinity>();
            rungs.add_row({free_dofs, route.name, seconds, previous / seconds, plain_time / seconds, deviation});
            previous = ours = seconds;
        }
        peers.add_row({free_dofs, double(scene.mesh.T.rows()), plain_time, ours, plain_time / ours, deviation});
    }
    peers.print(std::cout);
    peers.write_csv(run.file("peers_table.csv"));
    rungs.print(std::cout);
    rungs.write_csv(run.file("ladder_table.csv"));
}

}  // namespace

void cost_study(const RunContext& run, const Settings& settings)
{
    std::cout << "\n== 3. Cost of a corotational step (backward Euler, dt = 1/60 s, relative residual "
              << solve_tolerance << ")\n\n";
    const int steps = run.quick ? 4 : 20;
    Table parts("The parts of a step at a bent state: one SVD per tet, forces, K_R into the fixed pattern, "
                "the step matrix",
                {{"free dofs", Format::integer}, {"tets", Format::integer}, {"rotations [s]", Format::scientific, 2},
                 {"forces [s]", Format::scientific, 2}, {"forces, shape gradients [s]", Format::scientific, 2},
                 {"K_R assembly [s]", Format::scientific, 2},
                 {"step matrix [s]", Format::scientific, 2}, {"rotations per second [measured]", Format::scientific, 2}});
    Table solvers("A step matrix that changes every step, solved four ways (whole steps, from a bent state)",
                  {{"free dofs", Format::integer}, {"solver", Format::text}, {"time per step [s]", Format::scientific, 2},
                   {"CG iterations per step", Format::fixed, 1}, {"factorizations", Format::integer}});
    for (int cells : settings.cost_cells) {
        // Why: which part of a step to make faster depends on the size; the table shows each.
        const dynamics::Scene scene = dynamics::cantilever_scene(settings.sofa, cells, 1.0);
        dynamics::Body body(scene, force_model("corotational", scene));
        auto& model = dynamic_cast<CorotationalElasticity&>(body.model());
        const dynamics::State start = sagging_state(body, 10);
        const Eigen::VectorXd& u = start.u;
        Eigen::VectorXd forces;
        const double rotations = best_time([&] { (void)model.rotations(u); }, settings.seconds);
        model.evaluate(u, forces);  // the rotations at u are now kept: the next calls time the rest
        const double force_time = best_time([&] { model.evaluate(u, forces); }, settings.seconds);
        CorotationalElasticity fast(scene.mesh, scene.material, RotationFit::polar, PolarAlgorithm::newton,
                                    ForceForm::shape_gradients);
        fast.evaluate(u, forces);
        const double gradient_form_time = best_time([&] { fast.evaluate(u, forces); }, settings.seconds);
        const double assembly = best_time([&] { (void)model.stiffness(u); }, settings.seconds);
        const dynamics::SparseMatrix& K = model.stiffness(u);
        dynamics::ReducedStepMatrix reduced(body.mass_matrix(), K, body.dofs());  // what the step refills
        const double matrix = best_time([&] {
            (void)reduced.assemble(body.mass_matrix(), K, scene.damping, scene.time_step, 1.0);
        }, settings.seconds);
        const double tets = double(scene.mesh.T.rows());
        parts.add_row({double(body.dofs().size()), tets, rotations, force_time, gradient_form_time, assembly, matrix,
                       tets / rotations});

        for (const std::string& name : solver_option_names()) {
            if (name.rfind("pcg-ic0", 0) == 0 && name != "pcg-ic0 dv from last dv" && cells > settings.cost_cells.front())
                continue;  // the PCG starts compared on the smallest beam only
            const StepCost cost = step_cost(body, solver_option(name, solve_tolerance, body), start, steps);
            solvers.add_row({double(body.dofs().size()), name, cost.seconds, cost.iterations, double(cost.factorizations)});
        }
    }
    parts.print(std::cout);
    parts.write_csv(run.file("parts_table.csv"));
    solvers.print(std::cout);
    solvers.write_csv(run.file("solvers_table.csv"));

    // Why: the whole step on 1 and 2 threads (the threads goal, 1.7× on 2 cores): rotations, forces, K_R and
    // the step matrix, the factorization and the solve, the same bits on any number of threads. The
    // integrator is kept across calls: "refactor" factors afresh every step, reusing only the symbolic
    // analysis.
    {
        const dynamics::Scene scene = dynamics::cantilever_scene(settings.sofa, settings.cost_cells.back(), 1.0);
        dynamics::Body body(scene, force_model("corotational", scene));
        const dynamics::State start = sagging_state(body, 10);
        dynamics::ThetaMethod integrator(1.0, solver_option("refactor", solve_tolerance, body));
        dynamics::State first = start;
        integrator.step(body, scene.time_step, first);  // makes the solver and its symbolic analysis
        const Table threads = dynamics::step_threads_table(
            "The corotational backward Euler step from a bent state (rotations, forces, K_R, step matrix, Cholesky "
            "factorization, solve)", body, integrator, start, scene.time_step, settings.seconds);
        threads.print(std::cout);
        threads.write_csv(run.file("threads_table.csv"));
    }

    // Why: a published reference point. SOFA's TetrahedralCorotationalFEMForceField on a 1,664-vertex
    // beam: 14 ms a step, 5.8 ms in its "fast" variant with CG capped at 20 iterations (inexact).
    dynamics::Scene sofa = dynamics::cantilever_scene(settings.sofa, 2, 1.0);
    sofa.mesh = box_mesh(25, 7, 7, Eigen::Vector3d(0.2, 0.02, 0.02));  // 26 × 8 × 8 = 1,664 vertices
    sofa.pinned = assembly::vertices_on_plane(sofa.mesh, 0, 0.0);
    dynamics::Body body(sofa, force_model("corotational", sofa));
    const dynamics::State start = sagging_state(body, 10);
    Table goal("SOFA's corotational beam (1,664 vertices): our backward Euler step, converged solve, one core",
               {{"vertices", Format::integer}, {"free dofs", Format::integer}, {"solver", Format::text},
                {"our step [ms]", Format::fixed, 2}, {"CG iterations per step", Format::fixed, 1},
                {"SOFA's fast step (published) (ms)", Format::fixed, 1}, {"published / our time (other machine, inexact CG) [measured]", Format::fixed, 1}});
    const double sofa_fast_ms = 5.8;
    // Long enough for the balanced refresh to refactor the frozen factor a few times: its cost is in
    // the mean, as it would be in a long run.
    const int goal_steps = run.quick ? 4 : 300;
    const ScopedThreadCount one_core(1);  // the goal is on one core
    for (const std::string& name : solver_option_names()) {
        if (name.rfind("pcg-ic0", 0) == 0 && name != "pcg-ic0 dv from last dv")
            continue;
        const StepCost cost = step_cost(body, solver_option(name, solve_tolerance, body), start, goal_steps);
        goal.add_row({double(sofa.mesh.V.rows()), double(body.dofs().size()), name, 1e3 * cost.seconds,
                      cost.iterations, sofa_fast_ms, sofa_fast_ms / (1e3 * cost.seconds)});
    }
    // The fastest solver with the forces in their shape-gradient form (the same step to round-off).
    dynamics::Body fast(sofa, std::make_unique<CorotationalElasticity>(sofa.mesh, sofa.material, RotationFit::polar,
                                                                       PolarAlgorithm::newton, ForceForm::shape_gradients));
    const StepCost cost = step_cost(fast, solver_option("rotated-frozen-factor-pcg", solve_tolerance, fast),
                                    sagging_state(fast, 10), goal_steps);
    goal.add_row({double(sofa.mesh.V.rows()), double(fast.dofs().size()),
                  std::string("rotated-frozen-factor-pcg, shape-gradient forces"), 1e3 * cost.seconds, cost.iterations,
                  sofa_fast_ms, sofa_fast_ms / (1e3 * cost.seconds)});
    goal.print(std::cout);
    goal.write_csv(run.file("sofa_table.csv"));

    peers_study(run, settings);

    // Why: the float factor is not an exactly linear, symmetric M⁻¹, so PCG's theory does not cover
    // it; the true residual shows whether plain PCG still converges with it.
    const Table residuals = residual_table(body, sagging_state(body, 5), start, 16);
    residuals.print(std::cout);
    residuals.write_csv(run.file("residual_table.csv"));
}

}  // namespace fem::corot::study
