// Obstacles in a scene (chapter 14): the reader's fields, chapter 14's obstacles made from them, and
// the rule that steps a body with contact only when it needs it. docs/scenes.md#obstacles
#include "scenes/frame_look.hpp"
#include "scenes/runner.hpp"
#include "scenes/scene_contact.hpp"
#include "scenes/scene_text.hpp"

#include "12_hyperelastic_newton/force_models.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <numbers>

using namespace fem;
using namespace fem::scenes;
using testing::gallery;
using testing::output;

namespace {

/// A 10 cm cube (2 cells) dropped from 2 cm onto the floor z = 0 (μ = 0.5), Δt = 1/100, a frame per
/// step, model auto; obstacle lines replace the floor when given.
std::filesystem::path drop_scene(const std::string& name, const std::string& obstacle = "")
{
    std::filesystem::create_directories(output);
    const std::filesystem::path file = output / (name + ".toml");
    std::ofstream out(file);
    out << "[[body]]\n"
           "name = \"block\"\n"
           "mesh = { generator = \"box\", size = [0.1, 0.1, 0.1], cells = [2, 2, 2], translate = [0.0, 0.0, 0.02] }\n"
           "material = { model = \"auto\", youngs_modulus = 1e5, poisson_ratio = 0.3, density = 1000.0 }\n"
           "[[obstacle]]\n"
        << (obstacle.empty() ? "type = \"half-space\"\nfriction = 0.5\n" : obstacle)
        << "[time]\nstep = 0.01\nduration = 0.4\n"
           "[output]\nframe_rate = 100\n";
    return file;
}

double lowest(const MatrixX3d& x) { return x.col(2).minCoeff(); }

}  // namespace

TEST_CASE("obstacles in the scene file: each type's fields, and chapter 14's obstacle made from them", "[scenes][contact]")
{
    const std::filesystem::path file = drop_scene(
        "obstacle_types", "type = \"box\"\ncenter = [0.05, 0.05, -1.0]\nsize = [4.0, 2.0, 1.0]\naxis = [0.0, 0.0, 1.0]\n"
                          "angle = 90.0\nfriction = 0.25\nvelocity = [0.01, 0.0, 0.0]\n"
                          "[[obstacle]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, -3.0]\nradius = 0.5\n"
                          "[[obstacle]]\ntype = \"half-space\"\npoint = [0.0, 0.0, -0.5]\nnormal = [0.0, 0.0, 2.0]\n"
                          "[contact]\nactivation_distance = 0.002\nfriction_velocity = 0.01\n");
    const SceneSpec scene = read_scene(file);
    REQUIRE(scene.obstacles.size() == 3);
    CHECK(scene.contact.activation_distance == 0.002);
    CHECK(scene.contact.friction_velocity == 0.01);
    const ObstacleSpec& box = scene.obstacles[0];
    CHECK(box.type == "box");
    CHECK(box.obstacle->name() == "box");
    // The box turned by 90° about z (degrees in the file): its 4 m edge lies along y, its 2 m edge along x.
    const auto& made = box.obstacle;
    CHECK(made->friction() == 0.25);
    CHECK(made->velocity() == Eigen::Vector3d(0.01, 0.0, 0.0));
    const Eigen::Vector3d centre(0.05, 0.05, -1.0);
    CHECK(made->distance(centre + Eigen::Vector3d(1.5, 0.0, 0.0), 0.0) == Approx(0.5).epsilon(1e-14));
    CHECK(made->distance(centre + Eigen::Vector3d(0.0, 1.5, 0.0), 0.0) == Approx(-0.5).epsilon(1e-14));
    CHECK(made->distance(centre + Eigen::Vector3d(1.5, 0.0, 0.0), 10.0) == Approx(0.4).epsilon(1e-13));  // moved by 10 w
    const auto& sphere = scene.obstacles[1].obstacle;
    CHECK(sphere->distance(Eigen::Vector3d(0.0, 0.0, 0.0), 0.0) == Approx(2.5).epsilon(1e-15));
    // The half-space's normal is normalised: d = n·(x − p) in metres.
    CHECK(scene.obstacles[2].obstacle->gradient(Eigen::Vector3d::Zero(), 0.0) == Eigen::Vector3d::UnitZ());
    CHECK(scene.obstacles[2].obstacle->distance(Eigen::Vector3d(3.0, 1.0, 0.25), 0.0) == Approx(0.75).epsilon(1e-15));
    // A scene without obstacles has none, and its runs meet none.
    CHECK(read_scene(gallery / "cantilever.toml").obstacles.empty());
}

TEST_CASE("a capsule obstacle: read from its type's fields, made, drawn, and its foreign fields refused", "[scenes][contact]")
{
    const std::filesystem::path file = drop_scene(
        "obstacle_capsule", "type = \"capsule\"\nstart = [-1.0, 0.05, -0.5]\nend = [1.0, 0.05, -0.5]\nradius = 0.25\n"
                            "friction = 0.4\nvelocity = [0.0, 0.0, -0.1]\n");
    const SceneSpec scene = read_scene(file);
    REQUIRE(scene.obstacles.size() == 1);
    const ObstacleSpec& capsule = scene.obstacles[0];
    CHECK(capsule.type == "capsule");
    CHECK(capsule.file.empty());
    const auto& made = capsule.obstacle;
    CHECK(made->name() == "capsule");
    CHECK(made->friction() == 0.4);
    CHECK(made->velocity() == Eigen::Vector3d(0.0, 0.0, -0.1));
    // 0.75 m above the axis: 0.5 m from its surface; 2 m beyond its end b along the axis: 1.75 m.
    CHECK(made->distance(Eigen::Vector3d(0.3, 0.05, 0.25), 0.0) == Approx(0.5).epsilon(1e-15));
    CHECK(made->distance(Eigen::Vector3d(3.0, 0.05, -0.5), 0.0) == Approx(1.75).epsilon(1e-15));
    // Drawn where it stands at t = 1: moved 0.1 m down.
    const std::vector<fig::Prop> props = obstacle_props(scene, {0.0, 0.1, 0.0, 0.1, 0.0, 0.1}, 1.0);
    REQUIRE(props.size() == 1);
    for (Eigen::Index v = 0; v < props[0].shape.points.rows(); ++v)
        CHECK(std::abs(made->distance(props[0].shape.points.row(v).transpose(), 1.0)) < 1e-14);
    // A sphere's or a box's field is not a capsule's: refused at the field, naming its type.
    const std::filesystem::path foreign = drop_scene(
        "obstacle_capsule_foreign", "type = \"capsule\"\nstart = [-1.0, 0.05, -0.5]\nend = [1.0, 0.05, -0.5]\n"
                                    "radius = 0.25\ncenter = [0.0, 0.0, -0.5]\n");
    CHECK_THROWS_WITH(read_scene(foreign), Catch::Contains("obstacle[0].center") &&
                                               Catch::Contains("belongs to type = \"sphere\", not to type = \"capsule\""));
    const std::filesystem::path missing = drop_scene("obstacle_capsule_missing", "type = \"capsule\"\nradius = 0.25\n");
    CHECK_THROWS_WITH(read_scene(missing), Catch::Contains("obstacle[0].start: missing"));
}

TEST_CASE("a mesh obstacle: its file found in data/, placed by scale then translate, and read by the runner's input list",
          "[scenes][contact]")
{
    // The bowl (its lowest vertex at the origin, R = 0.15 m) scaled by 2 and moved to (0.05, 0.05, −0.5).
    const std::filesystem::path file = drop_scene(
        "obstacle_mesh", "type = \"mesh\"\nfile = \"bowl.obj\"\nscale = 2.0\ntranslate = [0.05, 0.05, -0.5]\nfriction = 0.3\n");
    const SceneSpec scene = read_scene(file);
    REQUIRE(scene.obstacles.size() == 1);
    const ObstacleSpec& bowl = scene.obstacles[0];
    CHECK(bowl.type == "mesh");
    CHECK(bowl.file.filename() == "bowl.obj");
    const auto& made = bowl.obstacle;
    const TriMesh surface = made->local_surface({});
    CHECK(surface.V.row(0) == Eigen::RowVector3d(0.05, 0.05, -0.5));  // the lowest vertex, placed
    CHECK(surface.V.col(0).maxCoeff() - surface.V.col(0).minCoeff() == Approx(2.0 * 2.0 * 0.15 * std::sin(70.0 * std::acos(-1.0) / 180.0)).epsilon(1e-12));
    CHECK(made->friction() == 0.3);
    // 0.1 m straight below the lowest vertex: that vertex is the nearest point (the bowl curves up).
    CHECK(made->distance(Eigen::Vector3d(0.05, 0.05, -0.6), 0.0) == Approx(0.1).epsilon(1e-12));
    const auto files = input_files(scene);
    CHECK(std::find(files.begin(), files.end(), bowl.file) != files.end());
}

TEST_CASE("an obstacle override is checked like the file and named by its option", "[scenes][contact]")
{
    const std::filesystem::path file = drop_scene("obstacle_override");
    try {
        read_scene(file, {"obstacle.0.friction=-1"});
        FAIL("no error");
    } catch (const Error& e) {
        CHECK_THAT(e.what(), Catch::Contains("--set obstacle.0.friction=-1") && Catch::Contains("obstacle[0].friction"));
    }
}

TEST_CASE("contact only where needed: the run is the free run, bit for bit, until a vertex comes within d-hat",
          "[scenes][contact]")
{
    const SceneSpec scene = read_scene(drop_scene("drop_floor"));
    SceneSpec free = scene;
    free.obstacles.clear();
    const RunResult with = run_positions(scene), without = run_positions(free);
    REQUIRE(with.frames[0].size() == without.frames[0].size());  // a frame per step, step 0 first
    const double reach = scene.contact.activation_distance;
    // The first step whose free end comes within d̂ of the floor (independently of the runner's rule).
    int first = -1;
    for (std::size_t k = 0; k < without.frames[0].size() && first < 0; ++k)
        if (lowest(without.frames[0][k]) < reach)
            first = static_cast<int>(k);
    REQUIRE(first > 1);
    for (int k = 0; k < first; ++k)
        CHECK((with.frames[0][static_cast<std::size_t>(k)].array() == without.frames[0][static_cast<std::size_t>(k)].array()).all());
    // From there on the block stays within d̂ (it lands and rests): every later step needs contact.
    CHECK(with.contact_steps[0] == with.steps - first + 1);
    CHECK(without.contact_steps[0] == 0);
    // Never a penetration, and at the end at rest on the floor, within d̂ of it.
    for (const MatrixX3d& x : with.frames[0])
        CHECK(lowest(x) > 0.0);
    CHECK(lowest(with.frames[0].back()) < reach);
    CHECK(lowest(without.frames[0].back()) < -0.1);  // the free block fell through where the floor would be
    // auto: linear until the first contact step, at least corotational from it on (the contact step
    // itself too: the linear energy of the block 2 cm below its rest place is round-off).
    for (const Segment& s : with.segments[0]) {
        CAPTURE(s.first_step, s.last_step, s.model, first);
        if (s.level == Level::linear)
            CHECK(s.last_step < first);
    }
    CHECK(with.segments[0].front().level == Level::linear);
}

TEST_CASE("an obstacle no vertex comes near adds nothing: the run is the free run, bit for bit", "[scenes][contact]")
{
    const SceneSpec scene = read_scene(drop_scene("drop_far", "type = \"sphere\"\ncenter = [5.0, 0.0, 0.0]\nradius = 1.0\n"));
    SceneSpec free = scene;
    free.obstacles.clear();
    const RunResult with = run_positions(scene), without = run_positions(free);
    CHECK(with.contact_steps[0] == 0);
    REQUIRE(with.frames[0].size() == without.frames[0].size());
    for (std::size_t k = 0; k < with.frames[0].size(); ++k)
        CHECK((with.frames[0][k].array() == without.frames[0][k].array()).all());
}

TEST_CASE("a linear body cannot meet obstacles: the reader refuses it at its model field, the run (--model linear) "
          "before any step", "[scenes][contact]")
{
    CHECK_THROWS_WITH(read_scene(drop_scene("drop_linear"), {"body.material.model=\"linear\""}),
                      Catch::Contains("drop_linear.toml: --set body.material.model=\"linear\": body[0].material.model: "
                                      "model linear cannot meet obstacles"));
    std::ofstream(output / "drop_linear_in_file.toml")
        << "[[body]]\nmesh = { generator = \"box\", cells = [1, 1, 1], translate = [0.0, 0.0, 0.02] }\n"
           "material = { model = \"linear\", youngs_modulus = 1e5, poisson_ratio = 0.3, density = 1000.0 }\n"
           "[[obstacle]]\ntype = \"half-space\"\n[time]\nstep = 0.01\nduration = 0.1\n";
    CHECK_THROWS_WITH(read_scene(output / "drop_linear_in_file.toml"),
                      Catch::Contains("drop_linear_in_file.toml:3:22:") && Catch::Contains("body[0].material.model: model linear"));
    CHECK_THROWS_WITH(run_positions(read_scene(drop_scene("drop_linear_option")), "linear"),
                      Catch::Contains("model linear cannot meet obstacles"));
}

TEST_CASE("the gallery's slopes: the block slides with g (sin - mu cos) when tan > mu, and sticks when tan < mu",
          "[scenes][contact][slow]")
{
    // slope_slide.toml and slope_stick.toml: 30°, μ = 0.3 and 0.8 (tan 30° = 0.577), gravity tilted
    // along +x over the floor z = 0; one cube (cells = 1) for speed, a frame per step.
    const std::vector<std::string> small{"body.mesh.cells=[1, 1, 1]", "output.frame_rate=100"};
    const auto mean_x = [](const MatrixX3d& x) { return x.col(0).mean(); };
    const double g = 9.81, theta = std::acos(-1.0) / 6.0;
    {
        const SceneSpec scene = read_scene(gallery / "slope_slide.toml", small);
        REQUIRE(scene.obstacles.size() == 1);
        const double mu = scene.obstacles[0].obstacle->friction();
        REQUIRE(std::tan(theta) > mu);
        const RunResult run = run_positions(scene);
        const std::vector<MatrixX3d>& x = run.frames[0];
        // The acceleration from the second difference of the mean position over 0.2 s spans, after
        // the first landing (0.5 mm above the slope at t = 0): exact for a constant acceleration.
        const double h = 0.2;
        const double a = (mean_x(x[60]) - 2.0 * mean_x(x[40]) + mean_x(x[20])) / (h * h);
        const double closed = g * (std::sin(theta) - mu * std::cos(theta));
        CAPTURE(a, closed);
        CHECK(std::abs(a - closed) < 1e-3 * closed);  // measured: 1e-8
    }
    {
        const SceneSpec scene = read_scene(gallery / "slope_stick.toml", small);
        REQUIRE(std::tan(theta) < scene.obstacles[0].obstacle->friction());
        const RunResult run = run_positions(scene);
        const std::vector<MatrixX3d>& x = run.frames[0];
        // Sticking with the smoothed friction: slower than eps_v, a creep of at most eps_v dt per step.
        for (std::size_t k = 21; k < x.size(); ++k)
            CHECK(std::abs(mean_x(x[k]) - mean_x(x[k - 1])) < scene.contact.friction_velocity * scene.time_step);
    }
}

TEST_CASE("a frictionless drop: the barrier's energy is booked as the floor's work, so H - W_in never rises",
          "[scenes][contact]")
{
    // Backward Euler only removes energy; the barrier stores the fall's energy at impact and gives it
    // back on the rebound. Booked as work in (ContactIntegrator), the balance H − W_in falls or stays;
    // unbooked, the rebound would show as a rise of H.
    const SceneSpec scene = read_scene(drop_scene("drop_frictionless", "type = \"half-space\"\n"), {"time.duration=1.0"});
    const RunResult run = run_positions(scene);
    const std::vector<dynamics::StepRecord>& records = run.records[0];
    REQUIRE(run.contact_steps[0] > 10);
    double scale = 0.0, largest_exchange = 0.0;
    for (const dynamics::StepRecord& r : records) {
        scale = std::max(scale, r.energies.magnitude());
        largest_exchange = std::max(largest_exchange, std::abs(r.work_in));
    }
    CHECK(largest_exchange > 0.0);  // the barrier did exchange energy with the body
    for (std::size_t k = 1; k < records.size(); ++k) {
        const double before = records[k - 1].energies.total() - records[k - 1].work_in;
        const double after = records[k].energies.total() - records[k].work_in;
        CAPTURE(k, before, after);
        CHECK(after - before <= 1e-12 * scale);
    }
}

TEST_CASE("a rising floor lifts the block through the scene file, its push booked as work, so H - W_in never rises",
          "[scenes][contact][slow]")
{
    // The floor's push Δt Σ F·w is work put in (contact::contact_step): unbooked, the lift read as a
    // rise of H − W_in, and at 2 mm/s the run ended as "diverged".
    const double rise = GENERATE(0.002, 0.05, 1.0);  // [m/s]: 1 m/s is 10 mm a step, 10 d̂
    const std::string floor = str("type = \"half-space\"\nfriction = 0.5\nvelocity = [0.0, 0.0, ", rise, "]\n");
    const SceneSpec scene = read_scene(drop_scene(str("rising_floor_", rise), floor), {"time.duration=0.8"});
    const RunResult run = run_positions(scene);
    const std::vector<dynamics::StepRecord>& records = run.records[0];
    double scale = 0.0;
    for (const dynamics::StepRecord& r : records)
        scale = std::max(scale, r.energies.magnitude());
    for (std::size_t k = 1; k < records.size(); ++k) {
        const double before = records[k - 1].energies.total() - records[k - 1].work_in;
        const double after = records[k].energies.total() - records[k].work_in;
        CAPTURE(rise, k, before, after);
        CHECK(after - before <= 1e-9 * scale);
    }
    // A frame per step of 0.01 s: the block's mean rise over the last step.
    const std::vector<MatrixX3d>& frames = run.frames[0];
    REQUIRE(frames.size() >= 2);
    const double mean = (frames.back().col(2).mean() - frames[frames.size() - 2].col(2).mean()) / 0.01;
    CAPTURE(rise, mean);
    CHECK(std::abs(mean - rise) <= 1e-2 * rise);
}

TEST_CASE("auto raised to corotational for a contact step books the jump of H, as the step hook books a model change",
          "[scenes][contact]")
{
    // The block turned 30° about the floor's normal, 0.5 mm above it (within d̂: contact at once), at
    // rest, at Level::linear: the linear energy of the rotation is its ghost strain, the corotational
    // one is zero. The contact step raises the level; the jump U_corot − U_lin is work put in at the
    // step's start, beside the barrier's B(start) − B(end).
    const SceneSpec scene = read_scene(drop_scene("raise_booked", "type = \"half-space\"\n"));
    const BodySpec& spec = scene.bodies.at(0);
    auto owned = std::make_unique<SceneForces>(spec.mesh, spec.material, "stable-neo-hookean", Level::linear);
    SceneForces& levels = *owned;
    dynamics::Body body(dynamics_scene(scene, spec), std::move(owned));
    const std::unique_ptr<dynamics::Integrator> own = dynamics::make_integrator("backward-euler");
    ContactIntegrator integrator(*own, {&levels}, body, scene_obstacles(scene), scene);

    const Eigen::Vector3d centre = spec.mesh.V.colwise().mean().transpose();
    const Eigen::Matrix3d R = Eigen::AngleAxisd(std::numbers::pi / 6.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    Eigen::VectorXd u(3 * spec.mesh.V.rows());
    for (Eigen::Index v = 0; v < spec.mesh.V.rows(); ++v) {
        const Eigen::Vector3d X = spec.mesh.V.row(v).transpose();
        u.segment<3>(3 * v) = centre + R * (X - centre) - X;
    }
    u(Eigen::seqN(2, spec.mesh.V.rows(), 3)).array() += 5e-4 - spec.mesh.V.col(2).minCoeff();
    dynamics::State state = dynamics::initial_state(body, u);
    const double linear = state.elastic_energy;
    const double corotational = hyper::make_force_model("corotational", spec.mesh, spec.material)->energy(u);
    REQUIRE(linear > 1e3 * std::abs(corotational));  // a jump worth booking
    const Eigen::VectorXd start = state.u;
    const double start_time = state.time;

    const dynamics::StepInfo info = integrator.step(body, scene.time_step, state);
    CHECK(integrator.last_contact());
    CHECK(levels.level() == Level::corotational);
    const double barrier = integrator.potential().barrier_energy(start, start_time) -
                           integrator.potential().barrier_energy(state.u, state.time);
    CAPTURE(linear, corotational, barrier, info.boundary_work);
    CHECK(std::abs(info.boundary_work - (corotational - linear + barrier)) <= 1e-9 * linear);
}

TEST_CASE("[contact] solver: ipc by default, augmented_lagrangian read, an unknown name and what the augmented "
          "Lagrangian lacks refused at the field", "[scenes][contact]")
{
    CHECK(read_scene(drop_scene("solver_default")).contact.solver == "ipc");
    CHECK(read_scene(drop_scene("solver_al", "type = \"half-space\"\nfriction = 0.5\n"
                                             "[contact]\nsolver = \"augmented_lagrangian\"\n"))
              .contact.solver == "augmented_lagrangian");
    // The file, the field's line and column, the value and the names allowed.
    CHECK_THROWS_WITH(read_scene(drop_scene("solver_unknown", "type = \"half-space\"\n[contact]\nsolver = \"barrier\"\n")),
                      Catch::Matches(".*solver_unknown\\.toml:8:10: contact\\.solver: must be one of .*ipc.*"
                                     "augmented_lagrangian.*, got 'barrier'.*"));
    // A moving obstacle (the augmented Lagrangian does not stage the obstacles' motion), at the solver field.
    CHECK_THROWS_WITH(read_scene(drop_scene("solver_moving", "type = \"half-space\"\nvelocity = [0.0, 0.0, 0.01]\n"
                                                             "[contact]\nsolver = \"augmented_lagrangian\"\n")),
                      Catch::Matches(".*solver_moving\\.toml:9:10: contact\\.solver: 'augmented_lagrangian' has no "
                                     "moving obstacles.*use solver = \"ipc\".*"));
    // Without contact the field would be ignored: refused at its line.
    {
        const std::filesystem::path file = output / "solver_no_contact.toml";
        std::ofstream(file) << "[[body]]\nmesh = { generator = \"box\" }\n"
                               "material = { model = \"auto\", youngs_modulus = 1e5, poisson_ratio = 0.3, density = 1000.0 }\n"
                               "[contact]\nsolver = \"ipc\"\n";
        CHECK_THROWS_WITH(read_scene(file), Catch::Matches(".*solver_no_contact\\.toml:5:10: contact\\.solver: a contact solver "
                                                           "needs contact.*"));
    }
    // The same scene with IPC runs (chapter 14 stages the obstacles' motion).
    CHECK(read_scene(drop_scene("solver_moving_ipc", "type = \"half-space\"\nvelocity = [0.0, 0.0, 0.01]\n"
                                                     "[contact]\nsolver = \"ipc\"\n"))
              .obstacles.size() == 1);
}
