// Study 3 of ch12_hyperelastic_newton: chapter 11's soft cantilever swinging through fifty degrees,
// for every model under backward Euler solved by Newton: the tip against a fine stable neo-Hookean
// reference, Newton iterations per step, time per step, the volume; a .pvd time series and PNG
// frames. docs/12_hyperelastic_newton.md#the-swing
#include "studies.hpp"

#include "10_linear_dynamics/time_integration.hpp"
#include "10_linear_dynamics/tip_path.hpp"

#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/motion.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <cmath>
#include <iostream>

namespace fem::hyper::study {
namespace {

/// One run: the tip's path (chapter 10's TipPath) and what the table reports.
struct SwingRun {
    std::string model;
    dynamics::TipPath path;
    double mean_iterations = 0.0, seconds_per_step = 0.0;
    int most_iterations = 0;
};

SwingRun swing(const dynamics::Scene& base, const std::string& model, double time_step, double tolerance,
               io::MotionRecorder* recorder = nullptr)
{
    dynamics::Scene scene = base;
    scene.time_step = time_step;
    dynamics::Body body(scene, make_force_model(model, scene.mesh, scene.material));
    NewtonOptions options;
    options.relative_tolerance = tolerance;
    NewtonBackwardEuler newton(options);
    dynamics::Simulation simulation(body, newton, dynamics::initial_state(body));
    const int steps = dynamics::step_count(scene.duration, time_step);
    SwingRun run{model, {}, 0.0, 0.0, 0};
    run.path.tip = dynamics::far_corner(scene.mesh);
    run.path.time_step = time_step;
    Timer clock;
    simulation.run(steps, [&](const dynamics::State& state, const dynamics::StepRecord& record) {
        run.path.record(body, state);
        run.mean_iterations += record.newton_iterations;
        run.most_iterations = std::max(run.most_iterations, record.newton_iterations);
        if (recorder != nullptr)
            recorder->add(state.time, dynamics::body_frame(body, state));
    });
    run.seconds_per_step = clock.seconds() / steps;
    run.mean_iterations /= steps;
    return run;
}

}  // namespace

void swing_study(const RunContext& run, const Settings& settings)
{
    const dynamics::Scene scene = dynamics::cantilever_scene(settings.soft, run.quick ? 10 : settings.swing_cells, settings.duration);
    std::cout << "\n== 3. The swing: chapter 11's soft cantilever, " << scene.mesh.T.rows()
              << " tets, every model under backward Euler by Newton (relative tolerance 1e-6)\n\n";
    std::vector<double> steps_per_second{30.0, 60.0, 120.0};
    if (run.quick)
        steps_per_second = {30.0, 60.0};
    // Why: a reference whose own error is far below every run's: the most robust material at an
    // eighth of the smallest step, Newton converged ten thousand times tighter.
    const double reference_rate = 8.0 * steps_per_second.back();
    const SwingRun reference = swing(scene, "stable-neo-hookean", 1.0 / reference_rate, 1e-10);
    Table table(str("Every model on the swing: the tip against stable neo-Hookean at dt = 1/", std::lround(reference_rate), " s"),
                {{"model", Format::text}, {"steps per second", Format::integer}, {"max tip error [m]", Format::scientific, 2},
                 {"Newton iterations per step", Format::fixed, 2}, {"most Newton iterations", Format::integer},
                 {"max |V/V0 - 1|", Format::scientific, 2}, {"time per step [s]", Format::scientific, 2}});
    std::vector<SwingRun> runs;
    for (const std::string& model : force_model_names())
        for (const double rate : steps_per_second) {
            runs.push_back(swing(scene, model, 1.0 / rate, 1e-6));
            const SwingRun& r = runs.back();
            table.add_row({model, rate, dynamics::largest_tip_distance(r.path, reference.path), r.mean_iterations,
                           double(r.most_iterations),
                           r.path.largest_volume_change, r.seconds_per_step});
        }
    table.print(std::cout);
    table.write_csv(run.file("swing_table.csv"));

    fig::LineChart pareto;
    pareto.title = "Speed against error on the swing: tip error against the wall time of the run";
    pareto.x_label = "wall time of the swing [s]";
    pareto.y_label = "max tip error [m]";
    pareto.log_x = pareto.log_y = true;
    for (const std::string& model : force_model_names()) {
        fig::Series series{model_in_words(model), {}, {}};
        for (const SwingRun& r : runs)
            if (r.model == model) {
                series.x.push_back(r.seconds_per_step * double(r.path.times.size() - 1));
                series.y.push_back(dynamics::largest_tip_distance(r.path, reference.path));
            }
        pareto.series.push_back(series);
    }
    fig::save_chart(pareto, run.file("swing_pareto"), run.figures);

    // Why: the picture — the stable neo-Hookean beam at 1/60 s, as a time series and PNG frames.
    io::MotionRecorder recorder(run.file("swing.pvd"), run.figures ? 9 : 0);
    swing(scene, "stable-neo-hookean", 1.0 / 60.0, 1e-6, &recorder);
    fig::RenderOptions view;
    view.title = "Stable neo-Hookean cantilever, backward Euler by Newton";
    view.field = "displacement";
    view.unit = "m";
    view.view_direction = {0.0, 1.0, -0.2};
    view.view_up = {0.0, 0.0, 1.0};
    view.height = 560;
    recorder.render_png_frames(run.file("swing"), view);
}

}  // namespace fem::hyper::study
