// Study 1b of ch15_body_contact (run by the mesh study): a rubber block dropped into the bowl, the mesh
// obstacle of data/bowl.obj (the gallery's bowl_drop scene, on this chapter's Newton with contact in
// every step) — a .pvd of the drop, PNG frames of the block in the bowl, and a row of what it cost
// and how close it came. docs/15_body_contact.md#the-block-in-the-bowl
#include "15_body_contact/body_contact.hpp"
#include "15_body_contact/mesh_obstacle.hpp"
#include "studies.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh_io.hpp"
#include "common/motion.hpp"
#include "common/table.hpp"

#include <algorithm>
#include <array>
#include <iostream>
#include <limits>
#include <memory>

namespace fem::contact::study {

void bowl_study(const RunContext& run)
{
    // The gallery's scene (scenes/bowl_drop.toml): a 4 cm block of soft rubber, its lowest corner
    // 1.3 cm above the wall 6 cm off the axis, slides down the wall (μ = 0.3) to the bottom.
    auto bowl = std::make_shared<MeshObstacle>(io::read_tri_mesh(data_path("bowl.obj")), 0.3, Eigen::Vector3d::Zero(),
                                               "bowl.obj");
    BlockSettings setup;
    setup.edge = 0.04;
    setup.cells = run.quick ? 1 : 3;
    setup.corner = {0.05, -0.02};
    setup.height = 0.045;
    setup.material = {1e5, 0.4, 1000.0};
    setup.obstacles = {bowl};
    setup.terms = body_contact_term_maker();
    BlockScene block = block_scene(setup);
    const double duration = run.quick ? 0.15 : 1.5;
    const int steps = dynamics::step_count(duration, setup.time_step);
    std::cout << "\n   The block dropped into the bowl: " << setup.edge << " m, " << block.body->mesh().T.rows()
              << " tets, " << steps << " steps of " << time_step_label(setup.time_step) << " s\n\n";

    io::MotionRecorder recorder(run.file("bowl.pvd"), run.figures ? 5 : 0);
    double smallest = std::numeric_limits<double>::infinity(), seconds = 0.0;
    int iterations = 0, most = 0;
    dynamics::Simulation simulation(*block.body, *block.stepper, block.state);
    simulation.run(steps, [&](const dynamics::State& state, const dynamics::StepRecord& record) {
        recorder.add(state.time, dynamics::body_frame(*block.body, state));
        if (state.step == 0)
            return;  // the start: no step yet
        seconds += record.seconds;
        iterations += record.newton_iterations;
        most = std::max(most, record.newton_iterations);
        smallest = std::min(smallest, block.contact->smallest_distance(state.u));
    });
    block.state = simulation.state();
    const Eigen::Vector3d centre = block.body->positions(block.state.u).colwise().mean().transpose();
    Table table("The block dropped into the bowl: cost, the smallest distance, where it ends",
                {{"tets", Format::integer}, {"steps", Format::integer}, {"Newton iterations per step", Format::fixed, 2},
                 {"most Newton iterations", Format::integer}, {"smallest distance / dhat", Format::scientific, 3},
                 {"final distance of the centre from the axis [m]", Format::scientific, 3},
                 {"final speed [m/s]", Format::scientific, 3}, {"time per step [ms]", Format::fixed, 3}});
    table.add_row({double(block.body->mesh().T.rows()), double(steps), double(iterations) / steps, double(most),
                   smallest / setup.contact.activation_distance, centre.head<2>().norm(),
                   mean_velocity(*block.body, block.state.v).norm(), 1e3 * seconds / steps});
    table.print(std::cout);
    table.write_csv(run.file("bowl_table.csv"));

    fig::RenderOptions view;
    view.title = "Rubber block dropped into a bowl (a triangle mesh obstacle)";
    view.field = "velocity";
    view.unit = "m/s";
    view.view_direction = {0.3, 1.0, -1.0};  // from above the rim: the wall hides the block from lower
    view.view_up = {0.0, 0.0, 1.0};
    view.width = 960;
    view.height = 540;
    view.data_under_title = true;
    // The bowl as the barrier sees it: its triangles, shaded, with their edges drawn over them.
    fig::Prop surface, edges;
    surface.shape.points = bowl->surface().V;
    surface.shape.cells = bowl->surface().F;
    edges.shape = surface.shape;
    edges.wireframe = true;
    edges.colour = {0.35, 0.35, 0.38};
    // The camera on the half of the bowl the block moves in (the wall it lands on to the bottom).
    view.frame_bounds = std::array<double, 6>{-0.06, 0.15, -0.1, 0.1, 0.0, 0.1};
    io::FrameExtras extras;
    extras.props = [&](std::size_t, double) { return std::vector<fig::Prop>{surface, edges}; };
    recorder.render_png_frames(run.file("bowl"), view, 1.0, extras);
}

}  // namespace fem::contact::study
