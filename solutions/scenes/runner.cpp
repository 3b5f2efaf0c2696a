// The scenes runner: one chapter 10 Simulation per body, stepped together. docs/scenes.md#the-runner
#include "scenes/runner.hpp"

#include "scenes/run_outputs.hpp"
#include "scenes/scene_contact.hpp"
#include "scenes/scene_conditions.hpp"
#include "scenes/web_page.hpp"

#include "12_hyperelastic_newton/force_models.hpp"

#include "common/error.hpp"
#include "common/interrupt.hpp"
#include "common/motion.hpp"

#include <array>
#include <cmath>
#include <iostream>
#include <optional>

namespace fem::scenes {

std::string describe_segments(const std::vector<Segment>& segments)
{
    std::string out;
    for (const Segment& s : segments)
        out += str(out.empty() ? "" : ", ", s.model, " ", s.first_step, "-", s.last_step);
    return out;
}

namespace {

/// The integrator of a body whose model may change level: chapter 12's factory makes the one each
/// level needs (on first use) and each step goes to the current level's.
class LevelIntegrator final : public dynamics::Integrator {
public:
    LevelIntegrator(const SceneForces& forces, const SceneSpec& scene) : forces_(forces)
    {
        settings_.integrator = scene.integrator;
        settings_.solver = scene.solver;
        settings_.newton_tolerance = scene.newton_tolerance;
    }
    std::string name() const override { return current().name(); }
    int order() const override { return current().order(); }
    bool is_explicit() const override { return current().is_explicit(); }
    dynamics::StepInfo step(dynamics::Body& body, double time_step, dynamics::State& state) override
    {
        return current().step(body, time_step, state);
    }

private:
    dynamics::Integrator& current() const
    {
        std::unique_ptr<dynamics::Integrator>& integrator = integrators_[static_cast<int>(forces_.level())];
        if (integrator == nullptr) {
            hyper::StepSettings settings = settings_;
            if (forces_.level() == Level::hyperelastic)
                settings.integrator = "backward-euler";  // chapter 12's Newton steps backward Euler only
            integrator = hyper::make_integrator_for(forces_.level_model(), settings);
        }
        return *integrator;
    }
    const SceneForces& forces_;
    hyper::StepSettings settings_;
    mutable std::array<std::unique_ptr<dynamics::Integrator>, 3> integrators_;
};

/// One body of a running scene.
struct BodyRun {
    const BodySpec* spec = nullptr;
    SceneForces* forces = nullptr;  // owned by body
    std::unique_ptr<dynamics::Body> body;
    std::unique_ptr<LevelIntegrator> integrator;
    std::unique_ptr<ContactIntegrator> contact;  // null: the scene has no obstacles
    std::unique_ptr<dynamics::Simulation> simulation;
    bool automatic = false;  // the model is auto's choice of the moment
    std::shared_ptr<Pull> pull = std::make_shared<Pull>();  // what pulls it now (read by its step hook)
    std::vector<Segment> segments;
    std::vector<dynamics::StepRecord> records;

    const dynamics::State& state() const { return simulation->state(); }
};

BodyRun start_body(const BodySpec& spec, const SceneSpec& scene, const std::string& model,
                   const std::vector<std::shared_ptr<const contact::Obstacle>>& obstacles)
{
    BodyRun b;
    b.spec = &spec;
    const std::string chosen = model.empty() ? spec.model : model;
    const bool automatic = chosen == "auto";
    b.automatic = automatic;
    const std::string hyperelastic = hyper::is_hyperelastic(chosen) ? chosen : scene.thresholds.hyperelastic;
    auto forces = std::make_unique<SceneForces>(spec.mesh, spec.material, hyperelastic,
                                                automatic ? Level::linear : level_of(chosen));
    b.forces = forces.get();
    b.body = std::make_unique<dynamics::Body>(dynamics_scene(scene, spec), std::move(forces));
    if (!obstacles.empty() && chosen == "linear")
        throw Error(str("body '", spec.name, "': model linear cannot meet obstacles (its energy of a body at rest ",
                        "far from where it started is round-off; docs/scenes.md#obstacles): use auto, corotational or a ",
                        "hyperelastic model"));
    b.integrator = std::make_unique<LevelIntegrator>(*b.forces, scene);
    if (!obstacles.empty())
        b.contact = std::make_unique<ContactIntegrator>(*b.integrator, *b.forces, *b.body, obstacles, scene);
    SceneConditions conditions(spec, scene, b.forces, automatic, b.contact.get(), b.pull);
    b.body->set_applied_loads(conditions.initial_loads());
    Eigen::VectorXd v0 = Eigen::VectorXd::Zero(3 * spec.mesh.V.rows());
    if (spec.initial_velocity.norm() > 0.0) {
        for (Eigen::Index v = 0; v < spec.mesh.V.rows(); ++v)
            v0.segment<3>(3 * v) = spec.initial_velocity;
        for (int v : spec.pinned)
            v0.segment<3>(3 * v).setZero();  // pins start at rest: their motions ramp up from zero speed
    }
    dynamics::Integrator& integrator = b.contact ? static_cast<dynamics::Integrator&>(*b.contact) : *b.integrator;
    b.simulation = std::make_unique<dynamics::Simulation>(*b.body, integrator, dynamics::initial_state(*b.body, {}, v0));
    b.simulation->set_before_step(std::move(conditions));
    b.segments.push_back({0, 0, b.forces->level(), b.forces->level_model()});
    return b;
}

/// One step of one body, with its record and the segment of the model it used.
void step_body(BodyRun& b)
{
    try {
        b.simulation->run(1);
    } catch (const Error& e) {
        throw Error(str("body '", b.spec->name, "': ", e.what()));
    }
    b.records.push_back(b.simulation->last());
    const int step = b.simulation->state().step;
    Segment& last = b.segments.back();
    if (last.level == b.forces->level())
        last.last_step = step;
    else
        b.segments.push_back({step, step, b.forces->level(), b.forces->level_model()});
}

/// Sets each body's pull from request (stiffness 0: the body's default), printing a line when a
/// pull starts, moves to another vertex or ends.
void update_pulls(std::vector<BodyRun>& bodies, const PullRequest& request, double stiffness)
{
    for (std::size_t i = 0; i < bodies.size(); ++i) {
        BodyRun& b = bodies[i];
        Pull& pull = *b.pull;
        if (request.body == static_cast<int>(i)) {
            if (pull.vertex != request.vertex) {
                pull = make_pull(*b.body, request.vertex, request.target,
                                 stiffness != 0.0 ? stiffness : default_pull_stiffness(*b.body));
                std::cout << "pulling vertex " << pull.vertex << " of body '" << b.spec->name << "' (k = "
                          << pull.stiffness << " N/m on " << pull.vertices.size() << " vertices)" << std::endl;
            }
            pull.target = request.target;
        } else if (pull.vertex >= 0) {
            const Eigen::Vector3d x = b.body->positions(b.state().u).row(pull.vertex).transpose();
            std::cout << "released vertex " << pull.vertex << " of body '" << b.spec->name << "' "
                      << (x - pull.target).norm() << " m from the pointer's point" << std::endl;
            pull = Pull{};
        }
    }
}

/// The frame of every body, merged, with the fields the scene asks for (and "model": each tet's level).
io::MeshData scene_frame(const std::vector<BodyRun>& bodies, const OutputSpec& output)
{
    std::vector<io::MeshData> parts;
    for (const BodyRun& b : bodies) {
        io::MeshData frame = dynamics::body_frame(*b.body, b.state());
        frame.cell_data.push_back(
            {"model", Eigen::MatrixXd::Constant(frame.cells.rows(), 1, static_cast<double>(b.forces->level()))});
        parts.push_back(std::move(frame));
    }
    return merged_frame(parts, output);
}

/// The models the bodies use now, for a frame's caption: "stable neo-Hookean", "auto: corotational"
/// for auto's choice, and with several bodies each named ("stiff corotational, soft stable neo-Hookean").
std::string frame_models(const std::vector<BodyRun>& bodies)
{
    std::string out;
    for (const BodyRun& b : bodies) {
        const std::string model = str(b.automatic ? "auto: " : "", model_label(b.forces->level_model()));
        out += bodies.size() == 1 ? model : str(out.empty() ? "" : ", ", b.spec->name, " ", model);
    }
    return out;
}

/// The lattice of a skinned body drawn around its skin: the body's frame k (warped as the skin is),
/// its surface's edges coloured by the skin's field on the skin's colour scale.
fig::Prop lattice_prop(const io::MotionRecorder& bodies, std::size_t k, double warp)
{
    fig::Prop lattice;
    lattice.shape = io::warped(bodies.kept_frame(k), warp);
    lattice.by_field = true;
    lattice.wireframe = true;
    return lattice;
}

}  // namespace

RunResult run_scene(const SceneSpec& scene, const RunOptions& options)
{
    // The skin (chapter 13) is bound before anything runs or is written: a bad one is refused early.
    const RunContext* run = options.run;
    const std::size_t skinned = scene.skin ? skin_body(scene) : 0;
    std::shared_ptr<const SkinObserver> skin = options.skin;
    if (scene.skin && !skin && run != nullptr && scene.output.pvd)
        skin = make_skin_observer(*scene.skin, scene.bodies[skinned]);
    std::vector<BodyRun> bodies;
    const auto obstacles = scene_obstacles(scene);
    for (const BodySpec& spec : scene.bodies)
        bodies.push_back(start_body(spec, scene, options.model, obstacles));

    const int steps = dynamics::step_count(scene.duration, scene.time_step);
    const int frame_every = steps_per_frame(scene);
    const std::string stem = scene.file.stem().string();
    const bool png = run != nullptr && run->figures && scene.output.png;
    std::optional<io::MotionRecorder> recorder;
    if (run != nullptr && scene.output.pvd)
        recorder.emplace(run->file(stem + ".pvd"), png ? 1 : 0);
    std::optional<io::MotionRecorder> skin_recorder;  // the skin's .vtp frames beside the tets' .vtu
    if (run != nullptr && scene.output.pvd && skin)
        skin_recorder.emplace(run->file(stem + "_skin.pvd"), png ? 1 : 0, io::FrameFile::surface);
    std::optional<WebPage> page;  // the web page <stem>.html (web_page.hpp)
    if (run != nullptr && scene.output.html)
        page.emplace(scene);
    StepHistory history;
    RunResult result;
    result.frames.resize(bodies.size());
    std::vector<std::string> models;  // per frame, for its caption
    const auto frame = [&] {
        const dynamics::State& first = bodies.front().state();
        models.push_back(frame_models(bodies));
        if (recorder || options.on_frame || page) {
            const io::MeshData data = scene_frame(bodies, scene.output);
            if (recorder)
                recorder->add(first.time, data);
            if (page)
                page->add_frame(data, first.time, models.back());
            if (skin_recorder)
                skin_recorder->add(first.time, skin->frame(bodies[skinned].state().u));
            if (options.on_frame)
                options.on_frame(data, first.step, first.time, models.back());
        }
        if (options.keep_positions)
            for (std::size_t i = 0; i < bodies.size(); ++i)
                result.frames[i].push_back(bodies[i].body->positions(bodies[i].state().u));
        ++result.frame_count;
    };
    const auto log_step = [&] {
        for (const BodyRun& b : bodies)
            history.add(b.spec->name, b.body->model().name(), b.records.back());
    };
    for (BodyRun& b : bodies) {
        b.simulation->run(0);  // step 0's record: the energies at the start
        b.records.push_back(b.simulation->last());
    }
    log_step();
    frame();
    Progress progress(steps, options.progress);
    Timer clock;
    for (int k = 1; options.forever || k <= steps; ++k) {
        if (stop_requested()) {
            result.interrupted = true;
            break;
        }
        if (options.pull)
            update_pulls(bodies, options.pull(), options.pull_stiffness);
        int newton = 0;
        for (BodyRun& b : bodies) {
            step_body(b);
            newton += b.records.back().newton_iterations;
        }
        result.newton_iterations += newton;
        result.steps = k;
        log_step();
        if (k % frame_every == 0 || k == steps)
            frame();
        if (!options.forever)
            progress.update(k, newton);
    }
    result.seconds = clock.seconds();
    if (result.interrupted)
        progress.finish();
    for (BodyRun& b : bodies) {
        result.segments.push_back(b.segments);
        result.contact_steps.push_back(b.contact ? b.contact->contact_steps() : 0);
        result.records.push_back(std::move(b.records));
    }

    if (options.print_models)
        for (const BodyRun& b : bodies)
            std::cout << "body " << b.spec->name << ": " << describe_segments(b.segments) << " (steps per model)"
                      << (b.contact ? str("; contact in ", b.contact->contact_steps(), " of ", result.steps, " steps") : "")
                      << "\n";
    if (run == nullptr)
        return result;
    if (result.interrupted)
        std::cout << "interrupted after step " << result.steps << ": " << result.frame_count
                  << " frames written, the .pvd lists them; no PNGs or video\n";
    if (scene.output.csv)
        history.write_csv(run->file("steps.csv"));
    if (scene.output.charts)
        history.save_charts(scene, bodies.size(), *run);
    if (page) {
        const std::filesystem::path file = run->file(stem + ".html");
        const Eigen::Vector3d bound = page->write(file, result.records);
        std::cout << "web page: " << file.filename().string() << " (" << result.frame_count << " frames, "
                  << std::lround(std::filesystem::file_size(file) / 1e4) / 100.0 << " MB; positions to within "
                  << bound.maxCoeff() << " m)\n";
    }
    if (recorder && png && !result.interrupted) {
        // Every frame captioned with the models of its moment; the obstacles drawn at its time under
        // the box the camera frames (the scene's, as the live view takes it, or the motion's).
        const double warp = scene.output.warp;
        const std::array<double, 6> box = scene.output.frame_box.value_or(recorder->motion_bounds(warp));
        io::FrameExtras extras;
        extras.title = [&](std::size_t k, double time) { return frame_title(scene, models.at(k), time); };
        extras.props = [&](std::size_t, double time) { return obstacle_props(scene, box, time); };
        const int written = recorder->render_png_frames(run->file(stem), frame_view(scene), warp, extras);
        // A skinned scene's picture is its skin (the bunny), coloured by its displacement, the one
        // field a skin frame has besides its normals, with the lattice that carries it drawn around it
        // as edges on the same colour scale; the video shows it.
        int skin_written = 0;
        if (skin_recorder) {
            fig::RenderOptions view = frame_view(scene);
            view.field = "displacement";
            view.unit = "m";
            view.clip_percentile = 100.0;
            view.range.reset();
            view.smooth = true;  // a render surface: shaded smooth by its normals, no facets or edges
            view.show_edges = false;
            io::FrameExtras skin_extras = extras;
            skin_extras.props = [&](std::size_t k, double time) {
                std::vector<fig::Prop> props = obstacle_props(scene, box, time);
                props.push_back(lattice_prop(*recorder, k, warp));
                return props;
            };
            skin_written = skin_recorder->render_png_frames(run->file(stem + "_skin"), view, warp, skin_extras);
        }
        if (written > 0 && scene.output.video != "none")
            make_video(*run, skin_written > 0 ? stem + "_skin" : stem, scene.output);
    }
    return result;
}

int steps_per_frame(const SceneSpec& scene)
{
    return std::max(1, static_cast<int>(std::lround(1.0 / (scene.output.frame_rate * scene.time_step))));
}

int frame_count(const SceneSpec& scene)
{
    const int steps = dynamics::step_count(scene.duration, scene.time_step), every = steps_per_frame(scene);
    return 1 + steps / every + (steps % every != 0 ? 1 : 0);
}

RunResult run_positions(const SceneSpec& scene, const std::string& model)
{
    RunOptions options;
    options.model = model;
    options.keep_positions = true;
    options.print_models = false;
    return run_scene(scene, options);
}

}  // namespace fem::scenes
