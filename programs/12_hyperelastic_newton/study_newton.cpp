// Study 2 of ch12_hyperelastic_newton: Newton's method itself — the gradient norm per iteration
// (quadratic convergence), which Hessian to solve with (exact, projected by clamping or mirroring,
// exact with a projected fallback), the line search against plain Newton on a slammed cube, the
// projection by a numerical and by the analytic eigensystem on the ν = 0.49 swing, and the
// tolerance against the error it leaves. docs/12_hyperelastic_newton.md#newton-in-practice
#include "studies.hpp"

#include "06_assembly/assembly.hpp"

#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

namespace fem::hyper::study {
namespace {

/// A neo-Hookean cube 10 cm, pinned at its base, its top slammed down at 40 m/s (dt = 1/24 s): one
/// step would move the top sixteen heights down, through the base.
struct SlammedCube {
    dynamics::Scene scene;
    Eigen::VectorXd v0;
};

SlammedCube slammed_cube()
{
    SlammedCube cube;
    cube.scene.mesh = box_mesh(2, 2, 2, Eigen::Vector3d(0.1, 0.1, 0.1));
    cube.scene.material = {1e4, 0.4, 1000.0};
    cube.scene.gravity.setZero();
    cube.scene.pinned = assembly::vertices_on_plane(cube.scene.mesh, 2, 0.0);
    cube.scene.time_step = 1.0 / 24.0;
    cube.v0 = Eigen::VectorXd::Zero(3 * cube.scene.mesh.V.rows());
    for (Eigen::Index v = 0; v < cube.scene.mesh.V.rows(); ++v)
        cube.v0[3 * v + 2] = -400.0 * cube.scene.mesh.V(v, 2);
    return cube;
}

/// What one Newton step of the slammed cube did, in the tables' words.
struct SlamOutcome {
    std::string outcome;       ///< "converged" or "failed: …"
    NewtonResult newton;       ///< its iterations, fallbacks and step lengths
    double smallest_det = 0.0; ///< smallest det F of the converged step (0 if it failed)
};

/// One step of the slammed cube with `material` (Y = 1e4, ν = 0.4), the element Hessians projected
/// by `projection`, Newton with `options` (its cap raised to 200).
SlamOutcome slam(const SlammedCube& cube, const std::string& material, Projection projection, NewtonOptions options)
{
    auto model = std::make_unique<HyperelasticElasticity>(cube.scene.mesh, make_material(material, 1e4, 0.4), projection);
    const HyperelasticElasticity& view = *model;
    dynamics::Body body(cube.scene, std::move(model));
    options.max_iterations = 200;
    NewtonBackwardEuler newton(options);
    dynamics::State state = dynamics::initial_state(body, {}, cube.v0);
    SlamOutcome result{"converged", {}, 0.0};
    try {
        newton.step(body, cube.scene.time_step, state);
        result.smallest_det = view.smallest_volume_ratio(state.u);
    } catch (const Error& e) {
        const std::string what = e.what();
        result.outcome = what.find("squeezed") != std::string::npos            ? "refused: a tet squeezed flat"
                         : what.find("det F") != std::string::npos             ? "failed: a tet inverted"
                         : what.find("positive definite") != std::string::npos ? "failed: indefinite Hessian"
                                                                               : "failed: no convergence";
    }
    result.newton = newton.last();
    return result;
}

/// The ν = 0.49 swing (0.5 s) with stable neo-Hookean stepped with `hessian`, every element's ∂P/∂F
/// projected by `projection` through `eigensolver` where the Hessian is projected: Newton iterations,
/// the tip's path, time per step, and the element Hessians' assembly time per tet at the last state.
struct ProjectedSwing {
    double mean_iterations = 0.0;
    int most_iterations = 0;
    std::vector<Eigen::Vector3d> tip_path;
    double seconds_per_step = 0.0;
    double microseconds_per_tet = 0.0;
};

ProjectedSwing projected_swing(const dynamics::Scene& swing, HessianChoice hessian, Projection projection,
                               Eigensolver eigensolver, double seconds)
{
    const elastic::Lame lame = elastic::lame_parameters(swing.material.youngs_modulus, swing.material.poisson_ratio);
    auto model = std::make_unique<HyperelasticElasticity>(swing.mesh, std::make_unique<StableNeoHookean>(lame, eigensolver),
                                                          projection);
    HyperelasticElasticity& view = *model;
    dynamics::Body body(swing, std::move(model));
    NewtonOptions options;
    options.hessian = hessian;
    options.max_iterations = 500;  // projected everywhere, Newton converges only linearly here
    NewtonBackwardEuler newton(options);
    dynamics::Simulation simulation(body, newton, dynamics::initial_state(body));
    const int tip = dynamics::far_corner(swing.mesh), steps = dynamics::step_count(swing.duration, swing.time_step);
    ProjectedSwing result;
    Eigen::VectorXd last_u;
    Timer clock;
    simulation.run(steps, [&](const dynamics::State& state, const dynamics::StepRecord& record) {
        result.tip_path.push_back(body.positions(state.u).row(tip).transpose());
        result.mean_iterations += record.newton_iterations;
        result.most_iterations = std::max(result.most_iterations, record.newton_iterations);
        last_u = state.u;
    });
    result.seconds_per_step = clock.seconds() / steps;
    result.mean_iterations /= steps;
    const double assembly = hessian == HessianChoice::exact ? best_time([&] { (void)view.stiffness(last_u); }, seconds)
                                                            : best_time([&] { (void)view.definite_stiffness(last_u); }, seconds);
    result.microseconds_per_tet = 1e6 * assembly / double(swing.mesh.T.rows());
    return result;
}

/// The projection table: the exact Hessian, then clamp and absolute by the numerical and the
/// analytic eigensystem, on the ν = 0.49 swing.
void projection_study(const RunContext& run, const Settings& settings)
{
    dynamics::Material material = settings.soft;
    material.poisson_ratio = 0.49;
    const dynamics::Scene swing = dynamics::cantilever_scene(material, run.quick ? 10 : settings.swing_cells, 0.5);
    Table table("Every element Hessian projected on the swing (stable neo-Hookean, nu = 0.49, 0.5 s, dt = 1/60 s): "
                "numerical against analytic eigensystems",
                {{"Hessian", Format::text}, {"eigensystem", Format::text}, {"Newton iterations per step", Format::fixed, 2},
                 {"most Newton iterations", Format::integer}, {"max tip difference to numerical clamp [m]", Format::scientific, 2},
                 {"element Hessians into K per tet [us]", Format::fixed, 2}, {"time per step [s]", Format::scientific, 2}});
    struct Choice {
        std::string hessian;
        HessianChoice choice;
        Projection projection;
        Eigensolver eigensolver;
    };
    const std::vector<Choice> choices{{"projected (clamp)", HessianChoice::definite, Projection::clamp, Eigensolver::numerical},
                                      {"projected (absolute)", HessianChoice::definite, Projection::absolute, Eigensolver::numerical},
                                      {"projected (clamp)", HessianChoice::definite, Projection::clamp, Eigensolver::analytic},
                                      {"projected (absolute)", HessianChoice::definite, Projection::absolute, Eigensolver::analytic},
                                      {"exact", HessianChoice::exact, Projection::clamp, Eigensolver::analytic}};
    std::vector<Eigen::Vector3d> reference;
    for (const Choice& choice : choices) {
        const ProjectedSwing run_result = projected_swing(swing, choice.choice, choice.projection, choice.eigensolver, settings.seconds);
        if (reference.empty())
            reference = run_result.tip_path;
        double difference = 0.0;
        for (std::size_t k = 0; k < reference.size(); ++k)
            difference = std::max(difference, (run_result.tip_path[k] - reference[k]).norm());
        const std::string eigensystem = choice.choice == HessianChoice::exact           ? "none (not projected)"
                                        : choice.eigensolver == Eigensolver::numerical ? "numerical (9x9 solver)"
                                                                                       : "analytic (SVD)";
        table.add_row({choice.hessian, eigensystem, run_result.mean_iterations, double(run_result.most_iterations),
                       difference, run_result.microseconds_per_tet, run_result.seconds_per_step});
    }
    table.print(std::cout);
    table.write_csv(run.file("projection_table.csv"));
}

}  // namespace

void newton_study(const RunContext& run, const Settings& settings)
{
    std::cout << "\n== 2. Newton's method: convergence, the Hessian, the line search, the tolerance\n\n";
    const dynamics::Scene swing = dynamics::cantilever_scene(settings.soft, run.quick ? 10 : settings.swing_cells, settings.duration);

    // Why: quadratic convergence is Newton's promise; the gradient norms of a few steps show it.
    fig::LineChart history;
    history.title = "Newton on the swing (stable neo-Hookean, dt = 1/60 s): |grad E| per iteration";
    history.x_label = "Newton iteration";
    history.y_label = "|grad E| / momentum scale [no unit]";
    history.log_y = true;
    {
        dynamics::Body body(swing, make_force_model("stable-neo-hookean", swing.mesh, swing.material));
        NewtonOptions options;
        options.relative_tolerance = 1e-10;  // far below the default, above the round-off floor (~1e-12)
        NewtonBackwardEuler newton(options);
        dynamics::State state = dynamics::initial_state(body);
        for (int step = 1; step <= 40; ++step) {
            newton.step(body, swing.time_step, state);
            if (step == 1 || step == 15 || step == 40) {
                fig::Series series{str("step ", step), {}, newton.last().gradient_history};
                for (std::size_t k = 0; k < series.y.size(); ++k)
                    series.x.push_back(double(k));
                history.series.push_back(series);
            }
        }
    }
    history.legend = fig::Corner::top_right;
    fig::save_chart(history, run.file("newton_history"), run.figures);

    // Why: the exact Hessian converges quadratically but can be indefinite; projecting every element
    // Hessian is always safe but slows convergence where it changed K. The slammed cube shows both.
    const SlammedCube cube = slammed_cube();
    Table hessians("The slammed neo-Hookean cube, one step of 1/24 s: which Hessian, and the line search",
                   {{"Hessian", Format::text}, {"line search", Format::text}, {"outcome", Format::text},
                    {"Newton iterations", Format::integer}, {"fallbacks to the projected Hessian", Format::integer},
                    {"smallest det F", Format::fixed, 3}});
    struct Choice {
        std::string name;
        HessianChoice hessian;
        Projection projection;
        bool line_search;
    };
    for (const Choice& choice : {Choice{"exact, projected where needed (clamp)", HessianChoice::exact_then_definite, Projection::clamp, true},
                                 Choice{"projected (clamp)", HessianChoice::definite, Projection::clamp, true},
                                 Choice{"projected (absolute)", HessianChoice::definite, Projection::absolute, true},
                                 Choice{"exact", HessianChoice::exact, Projection::clamp, true},
                                 Choice{"exact, projected where needed (clamp)", HessianChoice::exact_then_definite, Projection::clamp, false}}) {
        NewtonOptions options;
        options.hessian = choice.hessian;
        options.line_search = choice.line_search;
        const SlamOutcome step = slam(cube, "neo-hookean", choice.projection, options);
        hessians.add_row({choice.name, std::string(choice.line_search ? "Armijo" : "none (plain Newton)"), step.outcome,
                          double(step.newton.iterations), double(step.newton.definite_fallbacks), step.smallest_det});
    }
    hessians.print(std::cout);
    hessians.write_csv(run.file("hessian_table.csv"));

    // Why: projecting every element's ∂P/∂F costs a 9×9 eigen-decomposition per tet; stable
    // neo-Hookean's eigensystem has a closed form (twists, flips, a 3×3 scaling block from F's SVD)
    // that must give the same matrix, so the same Newton iterations, for less time. Clamping and
    // mirroring (absolute) differ in the matrix, so in the iterations. The ν = 0.49 swing, where the
    // volume term dominates ∂P/∂F and the stretched beam's twists go negative.
    projection_study(run, settings);

    // Why: the tolerance decides what a step costs and how far it is from the exact backward Euler
    // step; the tip error against a 1e-10 run at the same Δt says where it stops mattering.
    Table tolerances("The tolerance on the swing (stable neo-Hookean, dt = 1/60 s): error left and time",
                     {{"relative tolerance", Format::scientific, 0}, {"Newton iterations per step", Format::fixed, 2},
                      {"max tip difference to tolerance 1e-10 [m]", Format::scientific, 2}, {"time per step [s]", Format::scientific, 2}});
    const auto tip_path = [&](double tolerance, double& iterations, double& seconds) {
        dynamics::Body body(swing, make_force_model("stable-neo-hookean", swing.mesh, swing.material));
        NewtonOptions options;
        options.relative_tolerance = tolerance;
        NewtonBackwardEuler newton(options);
        dynamics::Simulation simulation(body, newton, dynamics::initial_state(body));
        const int tip = dynamics::far_corner(swing.mesh), steps = dynamics::step_count(swing.duration, swing.time_step);
        std::vector<Eigen::Vector3d> path;
        iterations = 0.0;
        Timer clock;
        simulation.run(steps, [&](const dynamics::State& state, const dynamics::StepRecord& record) {
            path.push_back(body.positions(state.u).row(tip).transpose());
            iterations += record.newton_iterations;
        });
        seconds = clock.seconds() / steps;
        iterations /= steps;
        return path;
    };
    double iterations = 0.0, seconds = 0.0;
    const std::vector<Eigen::Vector3d> tight = tip_path(1e-10, iterations, seconds);
    for (const double tolerance : {1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8}) {
        const std::vector<Eigen::Vector3d> path = tip_path(tolerance, iterations, seconds);
        double difference = 0.0;
        for (std::size_t k = 0; k < path.size(); ++k)
            difference = std::max(difference, (path[k] - tight[k]).norm());
        tolerances.add_row({tolerance, iterations, difference, seconds});
    }
    tolerances.print(std::cout);
    tolerances.write_csv(run.file("tolerance_table.csv"));

    // Why: neo-Hookean's log J is undefined for an inverted tet, so only a line search that rejects
    // inverting steps (E = +∞ there) keeps it alive; the stable neo-Hookean is defined everywhere and
    // inverts where its minimum is inverted. The volume filter (NewtonOptions::kept_volume, on by
    // default) keeps every tet right side out whatever the material. Both materials on the same
    // slammed cube: with the filter, with Armijo alone, and with plain Newton.
    Table inversion("Inversion on the slammed cube: the volume filter, Armijo's line search alone, plain Newton",
                    {{"material", Format::text}, {"line search", Format::text}, {"outcome", Format::text},
                     {"Newton iterations", Format::integer}, {"steps shortened (alpha < 1)", Format::integer},
                     {"smallest det F", Format::fixed, 3}});
    for (const std::string material : {"neo-hookean", "stable-neo-hookean"})
        for (const char* search : {"Armijo + volume filter", "Armijo", "none (plain Newton)"}) {
            NewtonOptions options;
            options.line_search = search[0] == 'A';
            options.kept_volume = std::string(search) == "Armijo" ? 0.0 : options.kept_volume;
            const SlamOutcome step = slam(cube, material, Projection::clamp, options);
            const auto shortened = std::count_if(step.newton.step_lengths.begin(), step.newton.step_lengths.end(),
                                                 [](double alpha) { return alpha < 1.0; });
            inversion.add_row({material, std::string(search), step.outcome, double(step.newton.iterations),
                               double(shortened), step.smallest_det});
        }
    inversion.print(std::cout);
    inversion.write_csv(run.file("inversion_table.csv"));

    // Why: as ν → ½ the material resists any change of volume, and linear tets, which can bend only
    // by changing volume somewhere, lock: the beam sags less than its bending stiffness (Y I, with
    // no ν in it) says. Newton itself keeps converging; the iterations and the sag show the cost.
    Table locking("Locking: the swinging beam (stable neo-Hookean, 0.5 s) as the Poisson ratio nears 1/2",
                  {{"Poisson ratio", Format::fixed, 3}, {"Newton iterations per step", Format::fixed, 2},
                   {"most Newton iterations", Format::integer}, {"max tip drop [m]", Format::scientific, 3},
                   {"tip drop / tip drop at nu = 0.3", Format::fixed, 3}, {"max |V/V0 - 1|", Format::scientific, 2}});
    double reference_drop = 0.0;
    for (const double poisson : {0.3, 0.45, 0.49, 0.499}) {
        dynamics::Material material = settings.soft;
        material.poisson_ratio = poisson;
        const dynamics::Scene beam = dynamics::cantilever_scene(material, run.quick ? 10 : settings.swing_cells, 0.5);
        dynamics::Body body(beam, make_force_model("stable-neo-hookean", beam.mesh, beam.material));
        NewtonBackwardEuler newton;
        dynamics::Simulation simulation(body, newton, dynamics::initial_state(body));
        const int tip = dynamics::far_corner(beam.mesh);
        const double rest_volume = total_volume(beam.mesh);
        double drop = 0.0, volume_change = 0.0, mean = 0.0;
        int most = 0;
        simulation.run(dynamics::step_count(beam.duration, beam.time_step),
                       [&](const dynamics::State& state, const dynamics::StepRecord& record) {
                           const MatrixX3d x = body.positions(state.u);
                           drop = std::max(drop, beam.mesh.V(tip, 2) - x(tip, 2));
                           volume_change = std::max(volume_change, std::abs(total_volume(TetMesh{x, beam.mesh.T}) / rest_volume - 1.0));
                           mean += record.newton_iterations;
                           most = std::max(most, record.newton_iterations);
                       });
        if (poisson == 0.3)
            reference_drop = drop;
        locking.add_row({poisson, mean / dynamics::step_count(beam.duration, beam.time_step), double(most), drop,
                         drop / reference_drop, volume_change});
    }
    locking.print(std::cout);
    locking.write_csv(run.file("locking_table.csv"));
}

}  // namespace fem::hyper::study
