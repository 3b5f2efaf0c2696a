// Study 3 of ch13_skinning: the pushed rubber bunny simulated on coarse lattices and skinned, against
// the same bunny simulated on TetGen's fine tets (whose surface is the bunny's): the surface error,
// the cost of a step and of a skin, the cost of a frame's skin on 10⁵ vertices, a .pvd of the skin
// beside the coarse tets and PNG frames. docs/13_skinning.md#skinning-against-simulation
#include "studies.hpp"

#include "07_sparse_storage/sparse_formats.hpp"

#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/motion.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <tuple>
#include <utility>

namespace fem::skin::study {
namespace {

/// What one simulated and skinned run reports.
struct SkinnedRun {
    double seconds_per_step = 0.0;
    std::vector<MatrixX3d> surface;  ///< the skinned surface at every frame
};

/// Runs the pushed bunny on mesh and skins surface with it every frame; records the coarse frames
/// and the skin's when recorders are given.
SkinnedRun simulate(const TetMesh& mesh, const TriMesh& surface, const Settings& settings, io::MotionRecorder* coarse = nullptr,
                    io::MotionRecorder* skin_series = nullptr, const std::vector<int>* pinned = nullptr)
{
    Run run = bunny_run(mesh, surface, settings, pinned);
    const Skin skin = build_skin(mesh, surface);
    dynamics::Body& body = *run.body;
    dynamics::Simulation simulation(body, *run.integrator, dynamics::initial_state(body, {}, run.push));
    SkinnedRun result;
    double observing = 0.0;  // the skin and the files, taken out of the step's time
    const int steps = dynamics::step_count(body.scene().duration, body.scene().time_step);
    Timer clock;
    simulation.run(steps, [&](const dynamics::State& state, const dynamics::StepRecord&) {
        Timer observer_clock;
        const MatrixX3d Q = body.positions(state.u);
        result.surface.push_back(skinned_positions(skin.W, Q));
        if (coarse != nullptr)
            coarse->add(state.time, dynamics::body_frame(body, state));
        if (skin_series != nullptr)
            skin_series->add(state.time, skin_frame(skin, Q));
        observing += observer_clock.seconds();
    });
    result.seconds_per_step = (clock.seconds() - observing) / steps;
    return result;
}

/// The largest distance between two surfaces over their first `frames` frames (all by default).
double largest_distance(const std::vector<MatrixX3d>& a, const std::vector<MatrixX3d>& b,
                        std::size_t frames = std::size_t(-1))
{
    double largest = 0.0;
    for (std::size_t k = 0; k < std::min(a.size(), frames); ++k)
        largest = std::max(largest, (a[k] - b[k]).rowwise().norm().maxCoeff());
    return largest;
}

/// The vertices of `lattice` on the ground (y ≤ ground) that lie within `radius` of a vertex of
/// `reference` on the ground, measured in the ground plane (x, z): the lattice held only under the
/// reference's pinned feet instead of over its whole bottom face. With radius = cell/√2 every
/// pinned vertex of the reference has a pinned lattice vertex near it.
std::vector<int> pins_under(const TetMesh& lattice, const TetMesh& reference, double ground, double radius)
{
    std::vector<int> pins;
    for (Eigen::Index i = 0; i < lattice.V.rows(); ++i) {
        if (lattice.V(i, 1) > ground)
            continue;
        for (Eigen::Index j = 0; j < reference.V.rows(); ++j) {
            if (reference.V(j, 1) <= ground && std::hypot(lattice.V(i, 0) - reference.V(j, 0),
                                                          lattice.V(i, 2) - reference.V(j, 2)) <= radius) {
                pins.push_back(static_cast<int>(i));
                break;
            }
        }
    }
    return pins;
}

}  // namespace

void simulation_study(const RunContext& run, const Settings& settings)
{
    std::cout << "\n== 3. Skinning against simulation: the pushed rubber bunny (" << settings.model
              << ", backward Euler, dt = 1/60 s, " << settings.duration << " s)\n\n";
    TriMesh bunny = bunny_surface();
    bunny.V *= 0.01;  // a 9.7 cm bunny, as in chapter 10
    TetMesh fine = bunny_tets();
    fine.V *= 0.01;

    // Why: the reference is the bunny simulated on TetGen's tets, whose boundary is the bunny's
    // surface itself: its skin is a selection (W has one weight 1 a row) and carries no error.
    const SkinnedRun reference = simulate(fine, bunny, settings);
    double motion = 0.0;
    for (const MatrixX3d& x : reference.surface)
        motion = std::max(motion, (x - bunny.V).rowwise().norm().maxCoeff());

    Table sweep(str("Coarse lattices against TetGen's fine bunny (", fine.T.rows(), " tets, ", reference.seconds_per_step,
                    " s a step; the surface moves up to ", motion, " m)"),
                {{"coarse mesh", Format::text}, {"vertices", Format::integer}, {"tets", Format::integer},
                 {"step [s]", Format::scientific, 2}, {"skin W q [s]", Format::scientific, 2},
                 {"step + skin / fine step [measured]", Format::fixed, 3}, {"surface error (m)", Format::scientific, 3},
                 {"error / largest motion", Format::scientific, 3}, {"first 0.1 s: error / largest motion", Format::scientific, 3}});
    // One marker per lattice, each named (a line through them would double back where a busy
    // machine times a finer lattice faster), and the fine bunny's own cost as a vertical line.
    fig::LineChart pareto{"Skinned coarse lattices: surface error against the cost of a frame", "step + skin [s]",
                          "surface error against the fine simulation [m]", true, true, {}};
    const int png_every = run.figures ? (run.quick ? 5 : 10) : 0;
    io::MotionRecorder coarse_series(run.file("coarse.pvd"), png_every);
    io::MotionRecorder skin_series(run.file("skin.pvd"), png_every, io::FrameFile::surface);
    // One row of the sweep for a lattice and its run; returns (skin time, surface error).
    const auto sweep_row = [&](const std::string& label, const TetMesh& lattice, const SkinnedRun& coarse) {
        const Skin skin = build_skin(lattice, bunny);
        const MatrixX3d Q = lattice.V;
        const double skinning = best_time([&] { (void)skinned_positions(skin.W, Q); }, settings.seconds);
        const double error = largest_distance(coarse.surface, reference.surface);
        // Why: the error of the first swing, before a difference in frequency adds up.
        const double early = largest_distance(coarse.surface, reference.surface, 7);
        sweep.add_row({label, double(lattice.V.rows()), double(lattice.T.rows()), coarse.seconds_per_step, skinning,
                       (coarse.seconds_per_step + skinning) / reference.seconds_per_step, error, error / motion, early / motion});
        return std::pair{skinning, error};
    };
    std::vector<int> cells = settings.cells;
    if (std::find(cells.begin(), cells.end(), settings.shown_cells) == cells.end())
        cells.push_back(settings.shown_cells);
    for (int n : cells) {
        const TetMesh lattice = enclosing_lattice(bunny, n);
        const bool shown = n == settings.shown_cells;
        const SkinnedRun coarse = simulate(lattice, bunny, settings, shown ? &coarse_series : nullptr, shown ? &skin_series : nullptr);
        if (std::find(settings.cells.begin(), settings.cells.end(), n) == settings.cells.end())
            continue;
        const auto [skinning, error] = sweep_row(str("lattice ", n), lattice, coarse);
        pareto.series.push_back({str("lattice ", n, " + skin"), {coarse.seconds_per_step + skinning}, {error}, true});
    }
    // Why: the lattice stands on the whole bottom face of its cubes, the reference on its feet (its
    // lowest 5 %). The same lattice held only under the reference's pinned vertices separates the
    // pins' share of the error from the lattice's shape and stiffness.
    {
        const int n = settings.shown_cells;
        const TetMesh lattice = enclosing_lattice(bunny, n);
        const double cell = (lattice.V.colwise().maxCoeff() - lattice.V.colwise().minCoeff()).maxCoeff() / n;
        const std::vector<int> pins = pins_under(lattice, fine, ground_height(bunny), cell / std::sqrt(2.0));
        (void)sweep_row(str("lattice ", n, ", pinned under the feet"), lattice,
                        simulate(lattice, bunny, settings, nullptr, nullptr, &pins));
    }
    sweep.print(std::cout);
    sweep.write_csv(run.file("sweep_table.csv"));

    if (!pareto.series.empty()) {
        double low = std::numeric_limits<double>::infinity(), high = 0.0;
        for (const fig::Series& s : pareto.series) {
            low = std::min(low, s.y.front());
            high = std::max(high, s.y.front());
        }
        // A vertical line at its cost over the errors' range and a little more (13 points: more
        // than figures.hpp's short series, so it is drawn without markers).
        fig::Series full{"TetGen bunny in full (its cost; the reference, error 0)", {}, {}};
        for (int k = 0; k <= 12; ++k) {
            full.x.push_back(reference.seconds_per_step);
            full.y.push_back(0.5 * low * std::pow(4.0 * high / low, k / 12.0));
        }
        pareto.series.push_back(full);
    }
    pareto.legend = fig::Corner::top_right;
    fig::save_chart(pareto, run.file("skinning_pareto"), run.figures);

    // Why: what a frame costs beside a step: the product W Q by hand and by Eigen, the normals, on the
    // bunny and on the upsampled bunny, carried by the lattice shown and by TetGen's tets.
    const TriMesh upsampled = midpoint_subdivision(bunny, settings.levels);
    Table frame("One frame: the skin against the step of the mesh that carries it",
                {{"coarse mesh", Format::text}, {"tets", Format::integer}, {"surface vertices", Format::integer},
                 {"W nonzeros", Format::integer}, {"build skin [s]", Format::scientific, 2},
                 {"W Q by hand [s]", Format::scientific, 2}, {"W Q by Eigen [s]", Format::scientific, 2},
                 {"normals [s]", Format::scientific, 2}, {"step [s]", Format::scientific, 2},
                 {"outside", Format::integer}, {"largest outside distance (m)", Format::scientific, 3}});
    const std::vector<std::tuple<std::string, TetMesh, const TriMesh*>> carriers{
        {str("lattice ", settings.shown_cells), enclosing_lattice(bunny, settings.shown_cells), &bunny},
        {str("lattice ", settings.shown_cells), enclosing_lattice(bunny, settings.shown_cells), &upsampled},
        {"TetGen bunny", fine, &upsampled}};
    for (const auto& [name, mesh, surface] : carriers) {
        Run carrier = bunny_run(mesh, bunny, settings);
        dynamics::State state = dynamics::initial_state(*carrier.body, {}, carrier.push);
        const double step = best_time([&] { carrier.integrator->step(*carrier.body, carrier.body->scene().time_step, state); },
                                      settings.seconds, 10);
        const MatrixX3d Q = carrier.body->positions(state.u);
        Skin skin;
        const double build = best_time([&, &mesh = mesh, &surface = surface] { skin = build_skin(mesh, *surface); }, settings.seconds, 3);
        const Eigen::SparseMatrix<double, Eigen::RowMajor> W = sparse::to_eigen(skin.W);
        MatrixX3d x;
        const double hand = best_time([&] { x = skinned_positions(skin.W, Q); }, settings.seconds);
        const double eigen = best_time([&] { x = W * Q; }, settings.seconds);
        const double normals = best_time([&, &surface = surface] { (void)vertex_normals(surface->F, x); }, settings.seconds);
        frame.add_row({name, double(mesh.T.rows()), double(surface->V.rows()), double(skin.W.nonzeros()), build, hand, eigen,
                       normals, step, double(skin.outside.size()), skin.largest_outside_distance()});
    }
    frame.print(std::cout);
    frame.write_csv(run.file("frame_table.csv"));

    // The pair sits side by side on a slide: one field, one colour range, one exaggeration.
    fig::RenderOptions view;
    view.title = str("Rubber bunny skinned on lattice ", settings.shown_cells, ", ", settings.model);
    view.field = "displacement";
    view.unit = "m";
    const auto [skin_low, skin_high] = skin_series.field_range(view.field);
    const auto [coarse_low, coarse_high] = coarse_series.field_range(view.field);
    view.range = std::make_pair(std::min(skin_low, coarse_low), std::max(skin_high, coarse_high));
    view.range_note = "range of all frames of both";
    view.view_direction = {0.2, -0.25, -1.0};
    view.view_up = {0.0, 1.0, 0.0};
    view.show_edges = false;
    view.smooth = true;  // the skin's recomputed normals, not its facets
    view.height = 600;
    const double warp = skin_series.visible_warp();
    skin_series.render_png_frames(run.file("skin"), view, warp);
    // Why: the same frames of the lattice that carries the skin, for the slide beside it.
    view.title = str("The coarse lattice that carries it (", settings.shown_cells, " cubes along the bunny)");
    view.show_edges = true;
    view.smooth = false;
    coarse_series.render_png_frames(run.file("coarse"), view, warp);
}

}  // namespace fem::skin::study
