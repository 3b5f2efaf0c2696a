// Study 7 of ch10_linear_dynamics: two scenes for a lecture, written as .pvd time series and PNG
// frames: the beam released under gravity, and the coarse TetGen bunny pinned at its base and
// pushed sideways. docs/10_linear_dynamics.md#scenes
#include "studies.hpp"

#include "common/files.hpp"
#include "common/mesh_io.hpp"
#include "common/motion.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <iostream>

namespace fem::dynamics::study {
namespace {

/// Runs the scene with backward Euler and records every step; PNG frames every png_every steps,
/// the displacement exaggerated so that the largest one shows (MotionRecorder::visible_warp).
/// Returns one row for the scenes table.
std::vector<Cell> record(const RunContext& run, const std::string& name, const Scene& scene,
                         const Eigen::VectorXd& v0, int png_every, const fig::RenderOptions& render)
{
    Body body(scene);
    ThetaMethod integrator(1.0);
    Simulation simulation(body, integrator, initial_state(body, {}, v0));
    io::MotionRecorder recorder(run.file(name + ".pvd"), run.figures ? png_every : 0);
    double largest = 0.0, peak_stress = 0.0;
    Timer clock;
    simulation.run(step_count(scene.duration, scene.time_step), [&](const State& state, const StepRecord&) {
        const io::MeshData data = body_frame(body, state);
        largest = std::max(largest, io::vertex_rows(state.u).rowwise().norm().maxCoeff());
        peak_stress = std::max(peak_stress, data.field("von Mises stress").values.maxCoeff());
        recorder.add(state.time, data);
    });
    const double seconds = clock.seconds();
    recorder.render_png_frames(run.file(name), render, recorder.visible_warp());
    return {name, double(scene.mesh.V.rows()), double(scene.mesh.T.rows()), double(body.dofs().size()),
            double(recorder.frames()), largest, peak_stress, seconds};
}

}  // namespace

void demo_scenes(const RunContext& run, const Settings& settings)
{
    std::cout << "\n== 7. Scenes: the beam swinging and the bunny pushed, backward Euler at dt = 1/60 s\n\n";
    Table table("Time series written (.pvd of .vtu frames: displacement, velocity, von Mises stress)",
                {{"scene", Format::text}, {"vertices", Format::integer}, {"tets", Format::integer},
                 {"free dofs", Format::integer}, {"frames", Format::integer}, {"largest |u| (m)", Format::scientific, 3},
                 {"largest von Mises (Pa)", Format::scientific, 3}, {"time [s]", Format::scientific, 2}});

    Scene beam = cantilever_scene(settings.beam, run.quick ? 10 : 20);
    beam.duration = settings.duration;
    fig::RenderOptions beam_view;
    beam_view.title = "Cantilever released under gravity, backward Euler";
    beam_view.field = "displacement";
    beam_view.unit = "m";
    beam_view.view_direction = {0.35, 1.0, -0.25};
    beam_view.view_up = {0.0, 0.0, 1.0};
    beam_view.show_edges = true;
    beam_view.height = 520;
    table.add_row(record(run, "beam", beam, {}, 6, beam_view));

    // The bunny (TetGen's tets of data/bunny.obj, y up), scaled to 9.7 cm, its lowest 5 % pinned,
    // pushed sideways with a velocity growing with height (0.5 m/s at the top).
    TetMesh bunny_mesh = io::read_tet_mesh(data_path("bunny_coarse.node"));
    bunny_mesh.V *= 0.01;
    const double low = bunny_mesh.V.col(1).minCoeff(), high = bunny_mesh.V.col(1).maxCoeff();
    const Scene bunny = standing_scene(std::move(bunny_mesh), settings.bunny, low + 0.05 * (high - low), settings.duration);
    const Eigen::VectorXd push = sideways_push(bunny, low, high, 0.5);
    fig::RenderOptions bunny_view;
    bunny_view.title = "Rubber bunny pinned at its base, pushed sideways";
    bunny_view.field = "von Mises stress";
    bunny_view.unit = "Pa";
    bunny_view.view_direction = {0.2, -0.25, -1.0};
    bunny_view.view_up = {0.0, 1.0, 0.0};
    bunny_view.height = 600;
    table.add_row(record(run, "bunny", bunny, push, 6, bunny_view));
    table.print(std::cout);
    table.write_csv(run.file("scenes_table.csv"));
}

}  // namespace fem::dynamics::study
