// The scene file: TOML read with toml++, every field checked where it is read: read_scene and its
// steps, in order (the parts' readers: scene_parts.hpp). docs/scenes.md#the-scene-file
#include "scenes/scene_file.hpp"

#include "scene_parts.hpp"

#include "12_hyperelastic_newton/force_models.hpp"
#include "12_hyperelastic_newton/materials.hpp"

#include "10_linear_dynamics/time_integration.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>

namespace fem::scenes {

const std::vector<std::string>& model_names()
{
    static const std::vector<std::string> names = [] {
        std::vector<std::string> all = hyper::force_model_names();  // chapter 12's factory: every model by name
        all.push_back("auto");
        return all;
    }();
    return names;
}

namespace {

using namespace detail;

/// The scene file's text: refused when it is no regular file, cannot be read or holds more than
/// max_scene_bytes.
std::string read_scene_text(const std::filesystem::path& path)
{
    const std::string file = path.string();
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(path, ec);
    if (!std::filesystem::is_regular_file(status))
        throw Error(str("scene file '", clipped(file), "': ",
                        ec && ec != std::errc::no_such_file_or_directory ? ec.message()
                        : std::filesystem::exists(status)                 ? "not a regular file"
                                                                          : "no such file"));
    std::ifstream in(path, std::ios::binary);
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (!in || size > max_scene_bytes)
        throw Error(str("scene file '", clipped(file), "': ", !in ? "cannot be read" : str("holds ", size, " bytes; at most "),
                        !in ? "" : str(max_scene_bytes, " are allowed (a scene is a few kilobytes)")));
    std::string text(static_cast<std::size_t>(size), '\0');
    in.seekg(0);
    if (!in.read(text.data(), size))
        throw Error(str("scene file '", clipped(file), "': cannot be read"));
    return text;
}

/// The TOML tree of a scene file's text (file names it in errors): its nesting checked first, then
/// parsed; a syntax error names the line and column.
toml::table parse_scene(const std::string& text, const std::string& file)
{
    check_nesting(text, file, true);
    try {
        return toml::parse(text, file);
    } catch (const toml::parse_error& e) {
        throw Error(str(file, ":", e.source().begin.line, ":", e.source().begin.column, ": TOML syntax error: ",
                        e.description()));
    }
}

/// [time]: the step (a number or a fraction), the duration (a whole number of steps), the integrator.
void read_time(const Fields& top, SceneSpec& scene)
{
    const toml::table* time_table = top.subtable("time");
    if (time_table == nullptr)
        return;
    const Fields time(*time_table, "time", top.source(), {"step", "duration", "integrator"});
    scene.time_step = time_step_field(time, "step", scene.time_step);
    scene.duration = time.number("duration", scene.duration, [](double d) { return d > 0.0 && d <= 3600.0; },
                                 "a number in (0, 3600] (seconds)");
    scene.integrator = time.text("integrator", scene.integrator, dynamics::integrator_names());
    try {
        dynamics::step_count(scene.duration, scene.time_step);
    } catch (const Error& e) {
        time.fail(time.has("duration") ? *time.get("duration") : *time_table, "duration", e.what());
    }
}

/// [solver]: chapter 09's solver name and Newton's tolerance.
void read_solver(const Fields& top, SceneSpec& scene)
{
    const toml::table* solver_table = top.subtable("solver");
    if (solver_table == nullptr)
        return;
    const Fields solver(*solver_table, "solver", top.source(), {"name", "newton_tolerance"});
    scene.solver = solver.text("name", scene.solver);
    scene.newton_tolerance = solver.number("newton_tolerance", scene.newton_tolerance,
                                           [](double t) { return t > 0.0 && t < 1.0; }, "a number in (0, 1)");
}

/// [auto]: the thresholds of model "auto" (the rotation in degrees).
void read_auto(const Fields& top, SceneSpec& scene)
{
    const toml::table* auto_table = top.subtable("auto");
    if (auto_table == nullptr)
        return;
    const Fields a(*auto_table, "auto", top.source(),
                   {"rotation", "ghost_ratio", "strain", "volume_ratio", "hysteresis", "hyperelastic"});
    const double degrees = std::acos(-1.0) / 180.0;
    scene.thresholds.rotation =
        a.number("rotation", scene.thresholds.rotation / degrees, [](double x) { return x > 0.0 && x < 90.0; },
                 "a number in (0, 90) (degrees)") * degrees;
    scene.thresholds.ghost_ratio = a.number("ghost_ratio", scene.thresholds.ghost_ratio,
                                            [](double x) { return x > 0.0 && x <= 1.0; }, "a number in (0, 1]");
    scene.thresholds.strain = a.number("strain", scene.thresholds.strain, [](double x) { return x > 0.0 && x < 1.0; },
                                       "a number in (0, 1)");
    scene.thresholds.volume_ratio = a.number("volume_ratio", scene.thresholds.volume_ratio,
                                             [](double x) { return x > 0.0 && x < 1.0; }, "a number in (0, 1)");
    scene.thresholds.hysteresis = a.number("hysteresis", scene.thresholds.hysteresis,
                                           [](double x) { return x > 0.0 && x <= 1.0; }, "a number in (0, 1]");
    scene.thresholds.hyperelastic =
        a.text("hyperelastic", scene.thresholds.hyperelastic, hyper::material_names());
}

/// [output]: what a run writes, each field checked against the others it needs.
void read_output(const Fields& top, SceneSpec& scene)
{
    const toml::table* output_table = top.subtable("output");
    if (output_table == nullptr)
        return;
    const Fields o(*output_table, "output", top.source(),
                   {"frame_rate", "pvd", "png", "video", "csv", "charts", "html", "frame_box", "colour_range", "fields", "colour", "view_direction", "view_up",
                    "warp", "width", "height"});
    OutputSpec& out = scene.output;
    out.frame_rate = o.number("frame_rate", out.frame_rate, [](double f) { return f > 0.0 && f <= 1000.0; },
                              "a number in (0, 1000] (frames per simulated second)");
    out.pvd = o.flag("pvd", out.pvd);
    out.png = o.flag("png", out.png);
    out.video = o.text("video", out.video, {"mp4", "gif", "none"});
    out.csv = o.flag("csv", out.csv);
    out.charts = o.flag("charts", out.charts);
    out.html = o.flag("html", out.html);
    if (out.charts && !out.csv)
        o.fail(*o.get(o.has("charts") ? "charts" : "csv"), "charts", "are drawn from steps.csv: set csv = true or charts = false");
    if (out.png && !out.pvd)
        o.fail(*o.get(o.has("png") ? "png" : "pvd"), "png", "frames are rendered from the .pvd frames: set pvd = true or png = false");
    const std::vector<std::string> fields{"displacement", "velocity", "von Mises stress", "model"};
    out.fields = o.texts("fields", out.fields, fields);
    out.colour = o.text("colour", out.colour, fields);
    out.view_direction = o.vector("view_direction", out.view_direction, true);
    out.view_up = o.vector("view_up", out.view_up, true);
    out.warp = o.positive("warp", out.warp);
    if (o.has("frame_box")) {
        const toml::array& corners = o.array("frame_box", 2, "two corners [[x0, y0, z0], [x1, y1, z1]]");
        const toml::table corner_table{{"low", *corners.get(0)}, {"high", *corners.get(1)}};
        const Fields corner(corner_table, o.field("frame_box"), o.source(), {"low", "high"});
        const Eigen::Vector3d low = corner.vector("low", Eigen::Vector3d::Zero());
        const Eigen::Vector3d high = corner.vector("high", Eigen::Vector3d::Zero());
        if ((low.array() >= high.array()).any())
            o.fail(*o.get("frame_box"), "frame_box", "the first corner must be below the second in x, y and z");
        out.frame_box = std::array<double, 6>{low.x(), high.x(), low.y(), high.y(), low.z(), high.z()};
    }
    if (o.has("colour_range")) {
        const toml::array& range = o.array("colour_range", 2, "[low, high] with low < high");
        const double low = o.number_of(*range.get(0), "colour_range[0]", [](double) { return true; }, "a finite number");
        const double high = o.number_of(*range.get(1), "colour_range[1]", [low](double h) { return h > low; },
                                        "a finite number above colour_range[0]");
        out.colour_range = std::make_pair(low, high);
    }
    out.width = o.integer("width", out.width, 64, 4096);
    out.height = o.integer("height", out.height, 64, 4096);
    if (out.colour != "displacement" && std::find(out.fields.begin(), out.fields.end(), out.colour) == out.fields.end())
        o.fail(*output_table, "colour", str("'", out.colour, "' must be one of the fields written (output.fields)"));
    if (!out.png && !o.has("video"))
        out.video = "none";  // the default video is made from the PNG frames: none without them
    if (out.video != "none" && !out.png)
        o.fail(*o.get("video"), "video", "is made from the PNG frames: set png = true or video = \"none\"");
}

/// The [[body]] array: at least one body, each read with its mesh built, names unique.
void read_bodies(const Fields& top, SceneSpec& scene)
{
    const toml::node* bodies = top.get("body");
    if (bodies == nullptr)
        top.missing("body", "give at least one [[body]] with its mesh and material");
    if (!bodies->is_array_of_tables())
        top.fail(*bodies, "body", str("must be an array of tables ([[body]]), got ", Fields::type_name(*bodies)));
    const toml::array& items = *bodies->as_array();
    std::set<std::string> names;
    for (std::size_t i = 0; i < items.size(); ++i) {
        const std::string name = str("body[", i, "]");
        scene.bodies.push_back(read_body(table_in_array(top, *items.get(i), "body"), name, top.source(), scene.file,
                                         scene.duration, scene.time_step, static_cast<int>(i)));
        if (!names.insert(scene.bodies.back().name).second)
            top.fail(*items.get(i), name + ".name", str("'", scene.bodies.back().name, "' is the name of an earlier body"));
    }
}

/// [contact]: the barrier's activation distance d̂, the friction's ε_v, whether bodies meet and the
/// friction between them, the solver.
void read_contact(const Fields& top, SceneSpec& scene)
{
    const toml::table* contact_table = top.subtable("contact");
    if (contact_table == nullptr)
        return;
    const Fields c(*contact_table, "contact", top.source(),
                   {"activation_distance", "friction_velocity", "bodies", "friction", "check_path", "solver"});
    scene.contact.activation_distance = c.positive("activation_distance", scene.contact.activation_distance);
    scene.contact.friction_velocity = c.positive("friction_velocity", scene.contact.friction_velocity);
    scene.contact.bodies = c.flag("bodies", scene.contact.bodies);
    scene.contact.check_path = c.flag("check_path", scene.contact.check_path);
    scene.contact.friction =
        c.number("friction", scene.contact.friction, [](double mu) { return mu >= 0.0 && mu <= 10.0; }, "a number in [0, 10]");
    scene.contact.solver = c.text("solver", scene.contact.solver, contact_solvers());
}

/// [contact] solver, refused at its field in a scene without contact, and with "augmented_lagrangian"
/// where the scene needs what chapter 16's solver does not have: friction between bodies, the path
/// check, a moving obstacle (it does not stage the obstacles' motion). docs/scenes.md#the-contact-solver
void check_contact_solver(const Fields& top, const SceneSpec& scene)
{
    const toml::table* given = top.subtable("contact");
    if (given == nullptr || given->get("solver") == nullptr)
        return;
    const Fields contact(*given, "contact", top.source(), {});
    if (!has_contact(scene))  // a setting never silently ignored
        contact.fail(*given->get("solver"), "solver",
                     "a contact solver needs contact: an [[obstacle]], [contact] bodies = true with two or more "
                     "bodies, or a body's self_contact = true");
    if (scene.contact.solver != "augmented_lagrangian")
        return;
    std::string missing;
    if (scene.contact.friction > 0.0)
        missing = str("friction between bodies (contact.friction = ", scene.contact.friction, ")");
    else if (scene.contact.check_path)
        missing = "the path check (contact.check_path = true)";
    for (std::size_t i = 0; i < scene.obstacles.size() && missing.empty(); ++i)
        if (scene.obstacles[i].obstacle->velocity().norm() > 0.0)
            missing = str("moving obstacles (obstacle[", i, "] moves: the solver does not stage their motion)");
    if (!missing.empty())
        contact.fail(*given->get("solver"), "solver",
                     str("'augmented_lagrangian' has no ", missing,
                         " (docs/16_contact_solvers.md#what-is-guaranteed): use solver = \"ipc\""));
}

/// With obstacles, the contact constants and gravity against the size D of the smallest body (the
/// diagonal of its rest bounding box), so that a value no contact step can work with is refused
/// before the run and not mid-run by Newton or CG: d̂ in [10⁻⁶ D, 0.1 D] (a smaller one asks for gaps
/// at the round-off of the positions, a larger one puts every body in contact with every obstacle
/// from the start); ε_v Δt ≥ 10⁻¹⁰ D (the sticking creep ε_v Δt, friction's stiffness ~1/(ε_v Δt),
/// above the round-off of a position); |g| Δt² ≤ D (from rest, gravity moves a body at most its own
/// size in one step, which the collision-free line search can still cut); and friction between
/// bodies only where bodies meet. docs/scenes.md#obstacles
void check_contact_scales(const Fields& top, const SceneSpec& scene)
{
    for (const char* key : {"friction", "check_path"})  // a setting never silently ignored
        if ((std::string(key) == "friction" ? scene.contact.friction > 0.0 : scene.contact.check_path) &&
            !bodies_meet(scene)) {
            const toml::table* given = top.subtable("contact");
            Fields(*given, "contact", top.source(), {})
                .fail(*given->get(key), key,
                      str(key == std::string("friction") ? "friction between bodies" : "the path check",
                          " needs bodies that meet: [contact] bodies = true with two or more bodies, or a body's "
                          "self_contact = true"));
        }
    if (!has_contact(scene))
        return;
    double size = std::numeric_limits<double>::infinity();
    std::string smallest;
    for (const BodySpec& body : scene.bodies) {
        const double diagonal = (body.mesh.V.colwise().maxCoeff() - body.mesh.V.colwise().minCoeff()).norm();
        if (diagonal < size) {
            size = diagonal;
            smallest = body.name;
        }
    }
    const std::string scale = str("the smallest body, '", smallest, "', is D = ", size, " m across");
    // A field the file (or --set) gave fails at its line; a default names the field to set.
    const auto refuse = [&](const char* table, const char* key, const std::string& message) {
        const toml::table* given = top.subtable(table);
        if (given != nullptr && given->get(key) != nullptr)
            Fields(*given, table, top.source(), {}).fail(*given->get(key), key, message);
        throw Error(str(scene.file.string(), ": ", table, ".", key, ": the default ", message, "; set it in [",
                        table, "]"));
    };
    const double dhat = scene.contact.activation_distance;
    if (dhat < 1e-6 * size || dhat > 0.1 * size)
        refuse("contact", "activation_distance",
               str(dhat, " m is outside [1e-6 D, 0.1 D] = [", 1e-6 * size, ", ", 0.1 * size, "] m: ", scale));
    const double creep = scene.contact.friction_velocity * scene.time_step;
    if (creep < 1e-10 * size)
        refuse("contact", "friction_velocity",
               str(scene.contact.friction_velocity, " m/s creeps ", creep, " m a step (time.step = ", scene.time_step,
                   " s), below the 1e-10 D = ", 1e-10 * size, " m that a position resolves: ", scale));
    const double fall = scene.gravity.norm() * scene.time_step * scene.time_step;
    if (!(fall <= size)) {
        const std::string message = str("|g| dt^2 = ", fall, " m: gravity moves a body farther than its size in one ",
                                        "step (time.step = ", scene.time_step, " s), more than contact can hold: ", scale);
        if (top.get("gravity") != nullptr)
            top.fail(*top.get("gravity"), "gravity", message);
        throw Error(str(scene.file.string(), ": time.step: ", message, "; use a smaller time.step"));
    }
}

/// The [[obstacle]] array: each read, the bodies' start clear of it; with obstacles the integrator
/// must be backward Euler (chapter 14's contact steps).
void read_obstacles(const Fields& top, SceneSpec& scene)
{
    const toml::node* obstacles = top.get("obstacle");
    if (obstacles == nullptr)
        return;
    if (!obstacles->is_array_of_tables())
        top.fail(*obstacles, "obstacle", str("must be an array of tables ([[obstacle]]), got ", Fields::type_name(*obstacles)));
    const toml::array& list = *obstacles->as_array();
    for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string name = str("obstacle[", i, "]");
        scene.obstacles.push_back(
            read_obstacle(table_in_array(top, *list.get(i), "obstacle"), name, top.source(), scene.file));
        check_obstacle_scale(top, *list.get(i), name, scene);
        check_bodies_clear(top, *list.get(i), name, scene);
        check_half_spaces_apart(top, *list.get(i), name, scene);
    }
    if (scene.integrator != "backward-euler") {
        const toml::table& time_table = *top.subtable("time");  // where a non-default integrator was set
        Fields(time_table, "time", top.source(), {})
            .fail(*time_table.get("integrator"), "integrator",
                  str("'", scene.integrator, "' is not for a scene with obstacles, whose contact steps are ",
                      "Newton backward Euler (chapter 14): use backward-euler"));
    }
}

/// [skin]: the fine surface file and the body that carries it.
void read_skin(const Fields& top, SceneSpec& scene)
{
    const toml::table* skin_table = top.subtable("skin");
    if (skin_table == nullptr)
        return;
    const Fields s(*skin_table, "skin", top.source(), {"file", "body"});
    SkinSpec skin;
    if (!s.has("file"))
        s.missing("file", "the fine surface (.obj, .stl, .ply) the tets carry");
    skin.file = existing_file(s, "file", scene.file);
    skin.body = s.text("body", scene.bodies.front().name);
    if (std::none_of(scene.bodies.begin(), scene.bodies.end(), [&](const BodySpec& b) { return b.name == skin.body; }))
        s.fail(*s.get("body"), "body", str("no body is called '", skin.body, "'"));
    scene.skin = skin;
}

/// Every body against the scene: a hyperelastic model needs backward Euler, and chapter 10's checks
/// of the body's dynamics scene (validate).
void check_bodies(const SceneSpec& scene)
{
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
        const BodySpec& body = scene.bodies[i];
        const bool hyperelastic = body.model != hyper::linear_model && body.model != hyper::corotational_model;
        if (hyperelastic && scene.integrator != "backward-euler")
            throw Error(str(scene.file.string(), ": time.integrator: '", scene.integrator, "' is not for body[", i,
                            "].material.model = '", body.model,
                            "', which steps with Newton backward Euler only: use backward-euler"));
        try {
            dynamics::validate(dynamics_scene(scene, body));
        } catch (const Error& e) {
            throw Error(str(scene.file.string(), ": ", body.name, ": ", e.what()));
        }
    }
}

}  // namespace

SceneSpec read_scene(const std::filesystem::path& path, const std::vector<std::string>& overrides, bool quick,
                     const ReadLimits& limits)
{
    const std::string file = path.string();
    toml::table root = parse_scene(read_scene_text(path), file);
    Source source{file, {}, limits};
    if (quick)
        apply_quick_table(root, source);
    apply_set_options(root, overrides, source);

    const Fields top(root, "", source, {"title", "gravity", "body", "time", "solver", "auto", "output", "skin", "obstacle",
                                        "contact", "quick"});
    SceneSpec scene;
    scene.file = path;
    scene.title = top.text("title", path.stem().string());
    scene.gravity = top.vector("gravity", scene.gravity);
    read_time(top, scene);
    read_solver(top, scene);
    read_auto(top, scene);
    read_output(top, scene);
    read_bodies(top, scene);
    read_contact(top, scene);
    read_obstacles(top, scene);
    check_contact_scales(top, scene);
    check_contact_solver(top, scene);
    read_skin(top, scene);
    check_bodies(scene);
    return scene;
}

std::vector<std::filesystem::path> input_files(const SceneSpec& scene)
{
    std::vector<std::filesystem::path> files{scene.file};
    for (const BodySpec& body : scene.bodies) {
        const std::filesystem::path& mesh = body.mesh_spec.file;
        if (mesh.empty())
            continue;
        files.push_back(mesh);
        if (mesh.extension() == ".node" || mesh.extension() == ".ele")
            files.push_back(std::filesystem::path(mesh).replace_extension(mesh.extension() == ".node" ? ".ele" : ".node"));
    }
    if (scene.skin)
        files.push_back(scene.skin->file);
    for (const ObstacleSpec& obstacle : scene.obstacles)
        if (!obstacle.file.empty())
            files.push_back(obstacle.file);
    return files;
}

std::vector<std::string> contact_solvers()
{
    return {"ipc", "augmented_lagrangian"};
}

bool bodies_meet(const SceneSpec& scene)
{
    return (scene.contact.bodies && scene.bodies.size() >= 2) ||
           std::any_of(scene.bodies.begin(), scene.bodies.end(), [](const BodySpec& b) { return b.self_contact; });
}

bool has_contact(const SceneSpec& scene)
{
    return !scene.obstacles.empty() || bodies_meet(scene);
}

dynamics::Scene dynamics_scene(const SceneSpec& scene, const BodySpec& body)
{
    return dynamics::Scene{.mesh = body.mesh, .material = body.material, .pinned = body.pinned,
                           .gravity = scene.gravity, .damping = body.damping, .mass = body.mass,
                           .time_step = scene.time_step, .duration = scene.duration, .densities = {}};
}

}  // namespace fem::scenes
