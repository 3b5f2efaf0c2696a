// The scenes runner: builds chapter 10's bodies from a scene and steps them with chapters 10–12.
// docs/scenes.md#the-runner
#include "scenes/runner.hpp"

#include "11_corotational/corotational.hpp"
#include "12_hyperelastic_newton/hyperelastic.hpp"
#include "12_hyperelastic_newton/newton.hpp"
#include "13_skinning/skinning.hpp"

#include "04_tet_jacobians/tet_jacobians.hpp"
#include "05_strain_stress/strain_stress.hpp"

#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/mesh_io.hpp"
#include "common/motion.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <Eigen/Eigenvalues>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <thread>
#include <unistd.h>

namespace fem::scenes {

Level level_of(const std::string& model)
{
    if (model == "linear")
        return Level::linear;
    if (model == "corotational")
        return Level::corotational;
    return Level::hyperelastic;
}

namespace {

const char* level_name(Level level, const std::string& hyperelastic)
{
    switch (level) {
    case Level::linear: return "linear";
    case Level::corotational: return "corotational";
    case Level::hyperelastic: return hyperelastic.c_str();
    }
    return "?";
}

volatile std::sig_atomic_t interrupted = 0;

extern "C" void on_interrupt(int)
{
    interrupted = 1;
    std::signal(SIGINT, SIG_DFL);  // a second Ctrl-C stops at once
}

}  // namespace

void catch_interrupt()
{
    interrupted = 0;
    std::signal(SIGINT, on_interrupt);
}

void request_stop()
{
    interrupted = 1;
}

DeformationMeasures deformation_measures(const TetMesh& mesh, const MatrixX3d& x)
{
    DeformationMeasures m;
    for (const Eigen::Matrix3d& F : tet::deformation_gradients(mesh, x)) {
        const Eigen::Matrix3d W = 0.5 * (F - F.transpose());
        const double sine = std::min(1.0, Eigen::Vector3d(W(2, 1), W(0, 2), W(1, 0)).norm());
        m.rotation = std::max(m.rotation, std::asin(sine));
        const Eigen::Vector3d principal =
            Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(elastic::green_strain(F), Eigen::EigenvaluesOnly).eigenvalues();
        m.strain = std::max(m.strain, principal.cwiseAbs().maxCoeff());
        m.volume_ratio = std::min(m.volume_ratio, F.determinant());
    }
    return m;
}

Level choose_level(const DeformationMeasures& m, Level current, const AutoThresholds& t)
{
    const auto needed = [&](double scale) {
        if (m.strain > scale * t.strain || m.volume_ratio < 1.0 - scale * (1.0 - t.volume_ratio))
            return Level::hyperelastic;
        if (m.rotation > scale * t.rotation)
            return Level::corotational;
        return Level::linear;
    };
    // Up at once; down only as far as the stricter (hysteresis-scaled) thresholds allow.
    return std::max(needed(1.0), std::min(current, needed(t.hysteresis)));
}

// --- SceneForces ----------------------------------------------------------------------------------

SceneForces::SceneForces(const TetMesh& mesh, const dynamics::Material& material, std::string hyperelastic, Level level)
    : mesh_(mesh), material_(material), hyperelastic_(std::move(hyperelastic)), level_(Level::linear),
      loads_(Eigen::VectorXd::Zero(3 * mesh.V.rows()))
{
    set_level(level);
}

void SceneForces::set_level(Level level)
{
    std::unique_ptr<dynamics::ForceModel>& model = models_[static_cast<int>(level)];
    if (model == nullptr) {  // built on first use: a linear run never pays for rotations
        if (level == Level::linear)
            model = std::make_unique<dynamics::LinearElasticity>(mesh_, material_);
        else if (level == Level::corotational)
            model = std::make_unique<corot::CorotationalElasticity>(  // the faster force form
                mesh_, material_, corot::RotationFit::polar, corot::PolarAlgorithm::newton,
                corot::ForceForm::shape_gradients);
        else
            model = std::make_unique<hyper::HyperelasticElasticity>(
                mesh_, hyper::make_material(hyperelastic_, material_.youngs_modulus, material_.poisson_ratio));
    }
    level_ = level;
}

double SceneForces::evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& forces)
{
    const double elastic = active().evaluate(u, forces);
    forces += loads_;
    return elastic - loads_.dot(u);
}

double SceneForces::energy(const Eigen::VectorXd& u)
{
    return active().energy(u) - loads_.dot(u);
}

Eigen::VectorXd applied_loads(const BodySpec& body, const MatrixX3i& boundary, double t)
{
    Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * body.mesh.V.rows());
    for (const Load& load : body.loads) {
        const double scale = t > load.until ? 0.0 : load.ramp > 0.0 ? std::min(1.0, t / load.ramp) : 1.0;
        if (scale == 0.0)
            continue;
        const std::vector<int>& vertices = load.select.vertices;
        if (load.kind == Load::Kind::point) {
            const Eigen::Vector3d share = scale * load.value / static_cast<double>(vertices.size());
            for (int v : vertices)
                f.segment<3>(3 * v) += share;
            continue;
        }
        std::vector<char> selected(static_cast<std::size_t>(body.mesh.V.rows()), 0);
        for (int v : vertices)
            selected[static_cast<std::size_t>(v)] = 1;
        for (Eigen::Index i = 0; i < boundary.rows(); ++i) {
            const int a = boundary(i, 0), b = boundary(i, 1), c = boundary(i, 2);
            if (!selected[a] || !selected[b] || !selected[c])
                continue;
            const Eigen::Vector3d A = body.mesh.V.row(a), B = body.mesh.V.row(b), C = body.mesh.V.row(c);
            const double area = 0.5 * (B - A).cross(C - A).norm();
            for (int v : {a, b, c})
                f.segment<3>(3 * v) += (scale * area / 3.0) * load.value;
        }
    }
    return f;
}

namespace {

/// Chapter 13's skin: W bound once to the body's rest tets (point location, barycentric weights,
/// the outside rule), and each frame the surface at x = W (X + u) with its normals.
class ChapterSkin final : public SkinObserver {
public:
    ChapterSkin(const SkinSpec& spec, const BodySpec& body) : rest_(body.mesh.V)
    {
        try {
            // The skin's file is in the coordinates of its body's mesh file: the same scale and shift.
            TriMesh surface = io::read_tri_mesh(spec.file);
            surface.V *= body.mesh_spec.scale;
            surface.V.rowwise() += body.mesh_spec.translate.transpose();
            skin_ = skin::build_skin(body.mesh, surface);
        } catch (const Error& e) {
            throw Error(str("skin '", spec.file.string(), "' of body '", spec.body, "': ", e.what()));
        }
    }
    io::MeshData frame(const Eigen::VectorXd& u) const override
    {
        return skin::skin_frame(skin_, rest_ + io::vertex_rows(u));
    }

private:
    MatrixX3d rest_;
    skin::Skin skin_;
};

}  // namespace

std::unique_ptr<SkinObserver> make_skin_observer(const SkinSpec& skin, const BodySpec& body)
{
    return std::make_unique<ChapterSkin>(skin, body);
}

std::size_t skin_body(const SceneSpec& scene)
{
    if (!scene.skin)
        throw Error("skin_body: the scene has no skin");
    for (std::size_t i = 0; i < scene.bodies.size(); ++i)
        if (scene.bodies[i].name == scene.skin->body)
            return i;
    throw Error(str("skin: no body is called '", scene.skin->body, "'"));
}

namespace {

/// One body of a running scene.
struct BodyRun {
    const BodySpec* spec = nullptr;
    SceneForces* forces = nullptr;  // owned by body
    std::unique_ptr<dynamics::Body> body;
    std::array<std::unique_ptr<dynamics::Integrator>, 3> integrators;
    dynamics::State state;
    MatrixX3i boundary;
    bool automatic = false;
    bool time_dependent = false;     // moving pins or loads that change in time
    double energy_in = 0.0;          // work put in by pins, changing loads and model switches [J]
    double initial_total = 0.0, largest = 0.0;
    std::vector<Segment> segments;
    int newton_iterations = 0, solver_iterations = 0;
    double step_seconds = 0.0;
};

dynamics::Integrator& integrator_for(BodyRun& b, const SceneSpec& scene)
{
    std::unique_ptr<dynamics::Integrator>& integrator = b.integrators[static_cast<int>(b.forces->level())];
    if (integrator == nullptr) {
        if (b.forces->level() == Level::hyperelastic) {
            hyper::NewtonOptions options;
            options.relative_tolerance = scene.newton_tolerance;
            options.solver = scene.solver;
            integrator = std::make_unique<hyper::NewtonBackwardEuler>(options);
        } else {
            dynamics::ImplicitOptions options;
            options.solver = scene.solver;
            integrator = dynamics::make_integrator(scene.integrator, options);
        }
    }
    return *integrator;
}

/// The energies of a body in a scene [J]: chapter 10's T, U and W with the applied loads' potential
/// −f_aᵀu moved from U (where SceneForces puts it) to W, so that U is the elastic energy alone.
dynamics::Energies scene_energies(const BodyRun& b)
{
    dynamics::Energies e = dynamics::energies(*b.body, b.state);
    const double load_potential = -b.forces->loads().dot(b.state.u);
    e.elastic -= load_potential;
    e.gravitational += load_potential;
    return e;
}

BodyRun start_body(const BodySpec& spec, const SceneSpec& scene, const std::string& model)
{
    BodyRun b;
    b.spec = &spec;
    const std::string chosen = model.empty() ? spec.model : model;
    b.automatic = chosen == "auto";
    const std::string hyperelastic = b.automatic || level_of(chosen) != Level::hyperelastic ? scene.thresholds.hyperelastic : chosen;
    auto forces = std::make_unique<SceneForces>(spec.mesh, spec.material, hyperelastic,
                                                b.automatic ? Level::linear : level_of(chosen));
    b.forces = forces.get();
    b.body = std::make_unique<dynamics::Body>(dynamics_scene(scene, spec), std::move(forces));
    for (const Pin& pin : spec.pins)
        b.time_dependent = b.time_dependent || pin.motion.kind != Motion::Kind::fixed;
    for (const Load& load : spec.loads)
        b.time_dependent = b.time_dependent || load.ramp > 0.0 || std::isfinite(load.until);
    if (!spec.loads.empty()) {
        b.boundary = boundary_faces(spec.mesh);
        b.forces->set_loads(applied_loads(spec, b.boundary, 0.0));
    }
    Eigen::VectorXd v0 = Eigen::VectorXd::Zero(3 * spec.mesh.V.rows());
    if (spec.initial_velocity.norm() > 0.0) {
        for (Eigen::Index v = 0; v < spec.mesh.V.rows(); ++v)
            v0.segment<3>(3 * v) = spec.initial_velocity;
        for (int v : spec.pinned)
            v0.segment<3>(3 * v).setZero();
    }
    b.state = dynamics::initial_state(*b.body, {}, v0);
    const dynamics::Energies e = scene_energies(b);
    b.initial_total = e.total();
    b.largest = e.magnitude();
    b.segments.push_back({0, 0, b.forces->level()});
    return b;
}

/// Steps one body from t to t + Δt (header comment of runner.hpp, steps 1–4).
void step_body(BodyRun& b, const SceneSpec& scene)
{
    dynamics::Body& body = *b.body;
    dynamics::State& state = b.state;
    const double dt = scene.time_step, t_next = state.time + dt;
    bool changed = false;
    // The energy before a change of boundary conditions or model, to book what the change put in
    // (a body with neither pays for no energy evaluation here).
    const double before = b.time_dependent || b.automatic ? scene_energies(b).total() : 0.0;
    if (b.time_dependent) {
        if (!b.spec->loads.empty())
            b.forces->set_loads(applied_loads(*b.spec, b.boundary, t_next));
        for (const Pin& pin : b.spec->pins) {
            if (pin.motion.kind == Motion::Kind::fixed)
                continue;
            for (int v : pin.select.vertices) {
                state.u.segment<3>(3 * v) = prescribed_displacement(pin.motion, b.spec->mesh.V.row(v).transpose(), t_next);
                state.v.segment<3>(3 * v).setZero();
            }
        }
        changed = true;
    }
    if (b.automatic) {
        const Level next =
            choose_level(deformation_measures(b.spec->mesh, body.positions(state.u)), b.forces->level(), scene.thresholds);
        if (next != b.forces->level()) {
            b.forces->set_level(next);
            changed = true;
        }
    }
    if (changed) {
        state.elastic_energy = body.model().evaluate(state.u, state.forces);
        b.energy_in += scene_energies(b).total() - before;
    }
    Timer clock;
    const dynamics::StepInfo info = integrator_for(b, scene).step(body, dt, state);
    b.step_seconds = clock.seconds();
    b.newton_iterations = info.newton_iterations;
    b.solver_iterations = info.solver_iterations;

    const dynamics::Energies e = scene_energies(b);
    const double total = e.total();
    const std::string where = str("body '", b.spec->name, "' at step ", state.step, " (t = ", state.time, " s, model ",
                                  body.model().name(), ")");
    if (!std::isfinite(total) || !state.u.allFinite() || !state.v.allFinite())
        throw Error(str("the run diverged: ", where, ": the state is no longer finite; use a smaller time step"));
    b.largest = std::max(b.largest, e.magnitude());
    const double rise = total - b.energy_in - b.initial_total;
    if (rise > dynamics::divergence_energy_fraction * b.largest)
        throw Error(str("the run diverged: ", where, ": the energy balance H - W_in rose by ", rise / b.largest,
                        " of the largest energy in play (the limit is ", dynamics::divergence_energy_fraction,
                        "); use a smaller time step or a model that holds this deformation"));
    Segment& last = b.segments.back();
    if (last.level == b.forces->level())
        last.last_step = state.step;
    else
        b.segments.push_back({state.step, state.step, b.forces->level()});
}

/// The frame of every body in one mesh (points, cells and fields concatenated), with the fields
/// the scene asks for.
io::MeshData scene_frame(const std::vector<BodyRun>& bodies, const OutputSpec& output)
{
    const auto wanted = [&](const std::string& name) {
        return name == io::displacement_field ||
               std::find(output.fields.begin(), output.fields.end(), name) != output.fields.end();
    };
    io::MeshData merged;
    Eigen::Index points = 0, cells = 0;
    std::vector<io::MeshData> parts;
    for (const BodyRun& b : bodies) {
        io::MeshData frame = dynamics::body_frame(*b.body, b.state);
        if (wanted("model"))
            frame.cell_data.push_back(
                {"model", Eigen::MatrixXd::Constant(frame.cells.rows(), 1, static_cast<double>(b.forces->level()))});
        points += frame.points.rows();
        cells += frame.cells.rows();
        parts.push_back(std::move(frame));
    }
    merged.points.resize(points, 3);
    merged.cells.resize(cells, 4);
    Eigen::Index p = 0, c = 0;
    for (const io::MeshData& part : parts) {
        merged.points.middleRows(p, part.points.rows()) = part.points;
        merged.cells.middleRows(c, part.cells.rows()) = part.cells.array() + static_cast<int>(p);
        p += part.points.rows();
        c += part.cells.rows();
    }
    const auto concat = [&](bool point_fields) {
        std::vector<io::Field> out;
        for (const io::Field& first : point_fields ? parts.front().point_data : parts.front().cell_data) {
            if (!wanted(first.name))
                continue;
            io::Field field{first.name, Eigen::MatrixXd(point_fields ? points : cells, first.values.cols())};
            Eigen::Index row = 0;
            for (const io::MeshData& part : parts) {
                const io::Field& own = part.field(first.name);
                field.values.middleRows(row, own.values.rows()) = own.values;
                row += own.values.rows();
            }
            out.push_back(std::move(field));
        }
        return out;
    };
    merged.point_data = concat(true);
    merged.cell_data = concat(false);
    return merged;
}

/// A one-line progress bar on stderr: done, time left, steps per second, Newton iterations.
class Progress {
public:
    Progress(int steps, bool enabled) : steps_(steps), enabled_(enabled && ::isatty(STDERR_FILENO)) {}
    void update(int step, int newton)
    {
        newton_ += newton;
        if (!enabled_ || (clock_.seconds() - shown_ < 0.1 && step < steps_))
            return;
        shown_ = clock_.seconds();
        const double rate = step / std::max(shown_, 1e-9);
        const int width = 30, filled = steps_ > 0 ? width * step / steps_ : width;
        std::fprintf(stderr, "\r[%s%s] %3d%%  step %d/%d  %.0f steps/s  %.1f s left  Newton %.1f/step ",
                     std::string(static_cast<std::size_t>(filled), '#').c_str(),
                     std::string(static_cast<std::size_t>(width - filled), ' ').c_str(), steps_ > 0 ? 100 * step / steps_ : 100,
                     step, steps_, rate, (steps_ - step) / std::max(rate, 1e-9), step > 0 ? double(newton_) / step : 0.0);
        if (step == steps_)
            std::fprintf(stderr, "\n");
        std::fflush(stderr);
    }
    void finish()
    {
        if (enabled_)
            std::fprintf(stderr, "\n");
    }

private:
    int steps_;
    bool enabled_;
    long newton_ = 0;
    Timer clock_;
    double shown_ = -1.0;
};

/// ffmpeg is on the PATH.
bool have_ffmpeg()
{
    return std::system("command -v ffmpeg >/dev/null 2>&1") == 0;
}

void make_video(const RunContext& run, const std::string& stem, const OutputSpec& output)
{
    if (!have_ffmpeg()) {
        std::cout << "video: skipped, ffmpeg is not installed (tools/setup.sh installs Debian's ffmpeg)\n";
        return;
    }
    const std::filesystem::path input = run.file(stem + "_%04d.png");
    const std::filesystem::path video = run.file(stem + "." + output.video);
    const std::string filter = output.video == "mp4" ? "-pix_fmt yuv420p -vf 'scale=trunc(iw/2)*2:trunc(ih/2)*2'"
                                                     : "-vf 'scale=iw/2:-1:flags=lanczos'";
    const std::string command = str("ffmpeg -loglevel error -nostdin -y -framerate ", output.frame_rate, " -i '",
                                    input.string(), "' ", filter, " '", video.string(), "' >/dev/null 2>&1");
    if (std::system(command.c_str()) != 0) {
        // The frames are there; a failed video costs the run nothing else.
        std::cout << "video: skipped, ffmpeg could not make " << video.filename().string() << " from the PNG frames\n";
        std::filesystem::remove(video);
        return;
    }
    std::cout << "video: " << video.filename().string() << '\n';
}

std::string describe_segments(const std::vector<Segment>& segments, const std::string& hyperelastic)
{
    std::string out;
    for (const Segment& s : segments)
        out += str(out.empty() ? "" : ", ", level_name(s.level, hyperelastic), " ", s.first_step, "-", s.last_step);
    return out;
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
    for (const BodySpec& spec : scene.bodies)
        bodies.push_back(start_body(spec, scene, options.model));

    const int steps = dynamics::step_count(scene.duration, scene.time_step);
    const int frame_every = std::max(1, static_cast<int>(std::lround(1.0 / (scene.output.frame_rate * scene.time_step))));
    const std::string stem = scene.file.stem().string();
    const bool png = run != nullptr && run->figures && scene.output.png;
    std::optional<io::MotionRecorder> recorder;
    if (run != nullptr && scene.output.pvd)
        recorder.emplace(run->file(stem + ".pvd"), png ? 1 : 0);
    std::optional<io::MotionRecorder> skin_recorder;  // the skin's .vtp frames beside the tets' .vtu
    if (run != nullptr && scene.output.pvd && skin)
        skin_recorder.emplace(run->file(stem + "_skin.pvd"), png ? 1 : 0, io::FrameFile::surface);
    Table history("Steps", {{"step", Format::integer}, {"time (s)", Format::fixed, 4}, {"body", Format::text},
                            {"model", Format::text}, {"kinetic (J)", Format::scientific, 6},
                            {"elastic (J)", Format::scientific, 6}, {"load potential (J)", Format::scientific, 6},
                            {"work in (J)", Format::scientific, 6}, {"balance H - W_in (J)", Format::scientific, 6},
                            {"Newton iterations", Format::integer}, {"solver iterations", Format::integer},
                            {"step time [s]", Format::scientific, 2}});
    RunResult result;
    result.frames.resize(bodies.size());
    const auto frame = [&] {
        if (recorder || options.on_frame) {
            const io::MeshData data = scene_frame(bodies, scene.output);
            if (recorder)
                recorder->add(bodies.front().state.time, data);
            if (skin_recorder)
                skin_recorder->add(bodies[skinned].state.time, skin->frame(bodies[skinned].state.u));
            if (options.on_frame)
                options.on_frame(data, bodies.front().state.step, bodies.front().state.time);
        }
        if (options.keep_positions)
            for (std::size_t i = 0; i < bodies.size(); ++i)
                result.frames[i].push_back(bodies[i].body->positions(bodies[i].state.u));
        ++result.frame_count;
    };
    const auto log_step = [&] {
        if (run == nullptr || !scene.output.csv)
            return;
        for (const BodyRun& b : bodies) {
            const dynamics::Energies e = scene_energies(b);
            history.add_row({double(b.state.step), b.state.time, b.spec->name, b.body->model().name(), e.kinetic,
                             e.elastic, e.gravitational, b.energy_in, e.total() - b.energy_in,
                             double(b.newton_iterations), double(b.solver_iterations), b.step_seconds});
        }
    };
    log_step();
    frame();
    Progress progress(steps, options.progress);
    Timer clock;
    for (int k = 1; k <= steps; ++k) {
        if (interrupted) {
            result.interrupted = true;
            break;
        }
        int newton = 0;
        for (BodyRun& b : bodies) {
            step_body(b, scene);
            newton += b.newton_iterations;
        }
        result.newton_iterations += newton;
        result.steps = k;
        log_step();
        if (k % frame_every == 0 || k == steps)
            frame();
        progress.update(k, newton);
    }
    result.seconds = clock.seconds();
    if (result.interrupted)
        progress.finish();
    for (const BodyRun& b : bodies)
        result.segments.push_back(b.segments);

    if (options.print_models) {
        for (const BodyRun& b : bodies)
            std::cout << "body " << b.spec->name << ": " << describe_segments(b.segments, scene.thresholds.hyperelastic)
                      << " (steps per model)\n";
    }
    if (run == nullptr)
        return result;
    if (result.interrupted)
        std::cout << "interrupted after step " << result.steps << ": " << result.frame_count
                  << " frames written, the .pvd lists them; no PNGs or video\n";
    if (scene.output.csv)
        history.write_csv(run->file("steps.csv"));
    if (scene.output.charts) {
        const auto chart = [&](const std::string& what, const std::string& y_label) {
            fig::LineChart c;
            c.title = str(scene.title, ": ", what);
            c.x_label = "time (s)";
            c.y_label = y_label;
            return c;
        };
        fig::LineChart energies = chart("energies", "energy (J)");
        fig::LineChart cost = chart("wall time per step", "time per step [ms]");
        fig::LineChart newton = chart("Newton iterations per step", "iterations");
        bool any_newton = false;
        for (std::size_t i = 0; i < bodies.size(); ++i) {
            fig::Series kinetic{bodies[i].spec->name + " kinetic", {}, {}}, elastic{bodies[i].spec->name + " elastic", {}, {}},
                balance{bodies[i].spec->name + " H - W_in", {}, {}}, time{bodies[i].spec->name, {}, {}},
                iterations{bodies[i].spec->name, {}, {}};
            for (std::size_t row = i; row < history.rows(); row += bodies.size()) {
                const double t = std::get<double>(history.cell(row, 1));
                kinetic.x.push_back(t);
                kinetic.y.push_back(std::get<double>(history.cell(row, 4)));
                elastic.x.push_back(t);
                elastic.y.push_back(std::get<double>(history.cell(row, 5)));
                balance.x.push_back(t);
                balance.y.push_back(std::get<double>(history.cell(row, 8)));
                if (row < bodies.size())
                    continue;  // step 0 took no time
                time.x.push_back(t);
                time.y.push_back(1e3 * std::get<double>(history.cell(row, 11)));
                iterations.x.push_back(t);
                iterations.y.push_back(std::get<double>(history.cell(row, 9)));
                any_newton = any_newton || iterations.y.back() > 0.0;
            }
            energies.series.insert(energies.series.end(), {kinetic, elastic, balance});
            cost.series.push_back(time);
            newton.series.push_back(iterations);
        }
        fig::save_chart(energies, run->file("energies"), run->figures);
        fig::save_chart(cost, run->file("step_time"), run->figures);
        if (any_newton)
            fig::save_chart(newton, run->file("newton_iterations"), run->figures);
    }
    if (recorder && png && !result.interrupted) {
        const int written = recorder->render_png_frames(run->file(stem), frame_view(scene), scene.output.warp);
        // A skinned scene's picture is its skin (the bunny, not the lattice that carries it), coloured
        // by its displacement, the one field a skin frame has besides its normals; the video shows it.
        int skin_written = 0;
        if (skin_recorder) {
            fig::RenderOptions view = frame_view(scene);
            view.field = "displacement";
            view.range.reset();
            skin_written = skin_recorder->render_png_frames(run->file(stem + "_skin"), view, scene.output.warp);
        }
        if (written > 0 && scene.output.video != "none")
            make_video(*run, skin_written > 0 ? stem + "_skin" : stem, scene.output);
    }
    return result;
}

fig::RenderOptions frame_view(const SceneSpec& scene)
{
    const OutputSpec& out = scene.output;
    fig::RenderOptions view;
    view.title = scene.title;
    view.field = out.colour;
    view.view_direction = {out.view_direction.x(), out.view_direction.y(), out.view_direction.z()};
    view.view_up = {out.view_up.x(), out.view_up.y(), out.view_up.z()};
    view.width = out.width;
    view.height = out.height;
    view.frame_bounds = out.frame_box;
    view.range = out.colour_range;
    return view;
}

std::string frame_title(const SceneSpec& scene, double time)
{
    // As io::MotionRecorder::render_png_frames titles a frame.
    const double warp = scene.output.warp;
    const std::string scale = warp == 1.0 ? std::string() : str(" (displacement x ", warp, ")");
    return str(scene.title, scale, ", t = ", time, " s");
}

// --- LiveView -------------------------------------------------------------------------------------

LiveView::LiveView(const SceneSpec& scene, std::filesystem::path screenshot, int screenshot_step)
    : scene_(scene), window_(frame_view(scene), str("fem_scene: ", scene.title)), screenshot_(std::move(screenshot)),
      screenshot_step_(screenshot_step)
{
    fields_ = {scene.output.colour};
    for (const std::string& field : scene.output.fields)
        if (field != scene.output.colour)
            fields_.push_back(field);
    if (scene.output.colour != io::displacement_field)
        fields_.push_back(io::displacement_field);
}

void LiveView::frame(const io::MeshData& frame, int step, double time)
{
    const io::MeshData shown = io::warped(frame, scene_.output.warp);
    const auto draw = [&] {
        fig::RenderOptions view = frame_view(scene_);
        view.field = fields_[field_];
        if (field_ != 0)
            view.range.reset();  // the fixed range belongs to the scene's colour field
        view.title = frame_title(scene_, time);
        if (!view.frame_bounds) {  // no box fixed: the rest shape, grown by half its size each way
            std::array<double, 6> box{};
            for (int axis = 0; axis < 3; ++axis) {
                const double low = frame.points.col(axis).minCoeff(), high = frame.points.col(axis).maxCoeff();
                const double margin = 0.5 * (frame.points.colwise().maxCoeff() - frame.points.colwise().minCoeff()).norm();
                box[2 * axis] = low - margin;
                box[2 * axis + 1] = high + margin;
            }
            view.frame_bounds = box;
        }
        window_.show(shown, view);
    };
    draw();
    if (step == screenshot_step_)
        window_.save_png(screenshot_);
    // Real time: the next frame comes no sooner than one frame interval after this one.
    while (!paused_ && clock_.seconds() < 1.0 / scene_.output.frame_rate)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    clock_.restart();
    bool advance = false, announced = false;
    do {
        for (char key : window_.poll_keys()) {
            if (key == ' ') {
                paused_ = !paused_;
                if (!paused_)
                    std::cout << "resumed" << std::endl;
            } else if (key == '>' && paused_)
                advance = true;
            else if (key == 'r')
                throw Restart{};
            else if (key == 'q')
                request_stop();
            else if (key == 'c') {
                field_ = (field_ + 1) % fields_.size();
                draw();
            }
        }
        if (paused_ && !advance && !announced) {
            // Said once per frame it waits on, when this frame's files are written and it is shown:
            // a script driving the window waits for the line (tests/scenes/test_runner.cpp).
            std::cout << "paused at step " << step << " (t = " << time << " s)" << std::endl;
            announced = true;
        }
        if (paused_ && !advance)
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
    } while (paused_ && !advance && !interrupted);
}

void compare_models(const SceneSpec& scene, const RunContext& run)
{
    for (const BodySpec& body : scene.bodies)
        if (body.damping.alpha != 0.0 || body.damping.beta != 0.0)
            throw Error(str("--compare: body '", body.name, "' is damped; the stable neo-Hookean reference steps without "
                            "damping (chapter 12), so the comparison needs damping = 0"));
    const std::vector<std::string> models{"stable-neo-hookean", "linear", "corotational", "stvk", "neo-hookean", "auto"};
    Table table(str("Each model against the stable neo-Hookean reference at dt = ", scene.time_step, " s (", scene.title, ")"),
                {{"model", Format::text}, {"tet RMS error (m)", Format::scientific, 2},
                 {"tet max error (m)", Format::scientific, 2}, {"surface RMS error (m)", Format::scientific, 2},
                 {"surface max error (m)", Format::scientific, 2}, {"max error / max |u|", Format::scientific, 2},
                 {"Newton iterations", Format::integer}, {"time per step [ms]", Format::scientific, 2},
                 {"total [s]", Format::scientific, 2}, {"models used (steps)", Format::text}});
    std::vector<MatrixX3i> boundaries;
    for (const BodySpec& body : scene.bodies)
        boundaries.push_back(boundary_faces(body.mesh));
    RunResult reference;
    for (const std::string& model : models) {
        RunOptions options;
        options.model = model;
        options.keep_positions = true;
        options.print_models = false;
        RunResult result;
        try {
            result = run_scene(scene, options);
        } catch (const Error& e) {
            std::cout << "model " << model << " failed: " << e.what() << '\n';
            if (model == models.front())
                throw Error(str("--compare: the reference run failed: ", e.what()));
            table.add_row({model, "failed", "failed", "failed", "failed", "failed", "-", "-", "-", "-"});
            continue;
        }
        if (model == models.front())
            reference = result;
        double tet_sum = 0.0, tet_max = 0.0, surf_sum = 0.0, surf_max = 0.0, largest = 0.0;
        long tet_count = 0, surf_count = 0;
        for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
            std::vector<char> on_surface(static_cast<std::size_t>(scene.bodies[b].mesh.V.rows()), 0);
            for (Eigen::Index i = 0; i < boundaries[b].size(); ++i)
                on_surface[static_cast<std::size_t>(boundaries[b](i / 3, i % 3))] = 1;
            for (std::size_t f = 0; f < reference.frames[b].size(); ++f) {
                const Eigen::VectorXd error = (result.frames[b][f] - reference.frames[b][f]).rowwise().norm();
                largest = std::max(largest, (reference.frames[b][f] - scene.bodies[b].mesh.V).rowwise().norm().maxCoeff());
                for (Eigen::Index v = 0; v < error.size(); ++v) {
                    tet_sum += error[v] * error[v];
                    tet_max = std::max(tet_max, error[v]);
                    ++tet_count;
                    if (on_surface[static_cast<std::size_t>(v)]) {
                        surf_sum += error[v] * error[v];
                        surf_max = std::max(surf_max, error[v]);
                        ++surf_count;
                    }
                }
            }
        }
        std::string used;
        const std::string hyperelastic = model == "auto" ? scene.thresholds.hyperelastic : model;
        for (std::size_t b = 0; b < result.segments.size(); ++b)
            used += (b ? "; " : "") + describe_segments(result.segments[b], hyperelastic);
        table.add_row({model, std::sqrt(tet_sum / std::max(tet_count, 1L)), tet_max,
                       std::sqrt(surf_sum / std::max(surf_count, 1L)), surf_max, largest > 0.0 ? tet_max / largest : 0.0,
                       double(result.newton_iterations), 1e3 * result.seconds / std::max(result.steps, 1), result.seconds,
                       used});
    }
    table.print(std::cout);
    table.write_csv(run.file("models_" + scene.file.stem().string() + ".csv"));
}

}  // namespace fem::scenes
