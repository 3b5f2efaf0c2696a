// The scene file's obstacles: the registry of [[obstacle]] types (one entry a type: its name, its
// own fields, and how they are read, checked and built into chapter 14's obstacle), the bodies'
// start clear of them. docs/scenes.md#obstacles
#include "scene_parts.hpp"

#include "15_body_contact/intersections.hpp"
#include "15_body_contact/mesh_obstacle.hpp"

#include "14_contact/surface.hpp"

#include "12_hyperelastic_newton/force_models.hpp"

#include "common/mesh_io.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>

namespace fem::scenes {
namespace detail {
namespace {

/// The smallest size of a box's edge or a capsule's segment, as a fraction of its coordinates.
constexpr double resolvable = 1e-9;

/// v as a unit vector, scaled first by its largest component (|v|² of [1e308, 1e308, 0] overflows).
Eigen::Vector3d direction(const Eigen::Vector3d& v)
{
    return (v / v.cwiseAbs().maxCoeff()).normalized();
}

/// What a type's own fields build, once μ and w are read: chapter 14's obstacle.
using Build = std::function<std::shared_ptr<const contact::Obstacle>(double friction, const Eigen::Vector3d& velocity)>;

/// A half-space: point (default the origin) and normal (not 0, normalised; default +z).
Build read_half_space(const Fields& fields, const std::filesystem::path&, std::filesystem::path&)
{
    const Eigen::Vector3d point = fields.vector("point", Eigen::Vector3d::Zero());
    const Eigen::Vector3d normal = fields.vector("normal", Eigen::Vector3d::UnitZ(), true);  // HalfSpace normalises it
    return [=](double friction, const Eigen::Vector3d& velocity) {
        return std::make_shared<contact::HalfSpace>(point, normal, friction, velocity);
    };
}

/// A sphere: center (default the origin) and radius > 0 (required).
Build read_sphere(const Fields& fields, const std::filesystem::path&, std::filesystem::path&)
{
    const Eigen::Vector3d center = fields.vector("center", Eigen::Vector3d::Zero());
    if (!fields.has("radius"))
        fields.missing("radius", "a sphere needs radius = r (m)");
    const double radius = fields.positive("radius", 1.0);
    return [=](double friction, const Eigen::Vector3d& velocity) {
        return std::make_shared<contact::Sphere>(center, radius, friction, velocity);
    };
}

/// A box: center, size (three edge lengths > 0, required), its axes the world's turned by angle
/// (degrees in the file) about axis (not 0; default +z): Box(center, size/2, R).
Build read_box(const Fields& fields, const std::filesystem::path&, std::filesystem::path&)
{
    const Eigen::Vector3d center = fields.vector("center", Eigen::Vector3d::Zero());
    if (!fields.has("size"))
        fields.missing("size", "a box needs size = [x, y, z] (its edge lengths, m)");
    const Eigen::Vector3d size = fields.vector("size", Eigen::Vector3d::Ones());
    if ((size.array() <= 0.0).any())
        fields.fail(*fields.get("size"), "size", "must be three edge lengths > 0 (m)");
    const Eigen::Vector3d axis = direction(fields.vector("axis", Eigen::Vector3d::UnitZ(), true));
    // Reduced to (−360°, 360°) first (exactly: fmod is): 1.7e308° in radians overflows.
    const double angle = std::fmod(fields.finite("angle", 0.0), 360.0) * std::acos(-1.0) / 180.0;
    const Eigen::Matrix3d rotation = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    // Its corners must be apart in double: chapter 15's edge and corner barrier refuses an edge
    // shorter than 10⁻¹⁴ of its coordinates.
    const double reach = center.cwiseAbs().maxCoeff() + 0.5 * size.norm();
    if (size.minCoeff() < resolvable * reach)
        fields.fail(*fields.get("size"), "size",
                    str("must be at least ", resolvable, " times the box's reach from the origin (|center| + half ",
                        "its diagonal = ", reach, " m) on each edge, or its corners are round-off of each other; got ",
                        size.transpose()));
    return [=](double friction, const Eigen::Vector3d& velocity) {
        return std::make_shared<contact::Box>(center, 0.5 * size, rotation, friction, velocity);
    };
}

/// A mesh: file (required; beside the scene file, then in data/), its coordinates × scale (> 0) +
/// translate. file is set to the surface file read.
Build read_mesh(const Fields& fields, const std::filesystem::path& scene_file, std::filesystem::path& file)
{
    if (!fields.has("file"))
        fields.missing("file", "a mesh needs file = \"….obj\" (a triangle surface: .obj, .stl, .ply or .vtu)");
    const toml::node& node = *fields.get("file");
    file = existing_file(fields, "file", scene_file);
    const std::string extension = file.extension().string();
    if (extension != ".obj" && extension != ".stl" && extension != ".ply" && extension != ".vtu")
        fields.fail(node, "file", str("has the extension '", extension, "'; a mesh obstacle is a triangle surface: .obj, .stl, .ply or .vtu"));
    TriMesh surface;
    try {
        surface = io::read_tri_mesh(file);
    } catch (const Error& e) {
        fields.fail(node, "file", str("must be a surface of triangles, none degenerate: ", e.what()));
    }
    check_obstacle_memory(fields, node, "file", surface.F.rows());
    const double scale = fields.positive("scale", 1.0);
    const Eigen::Vector3d translate = fields.vector("translate", Eigen::Vector3d::Zero());
    surface.V = ((surface.V * scale).rowwise() + translate.transpose()).eval();
    try {
        validate(surface, file.string());
    } catch (const Error& e) {
        const std::string placed = fields.has("scale") ? "scale" : fields.has("translate") ? "translate" : "file";
        fields.fail(*fields.get(placed), placed,
                    str("places the mesh (× scale ", scale, ", + translate [", translate.transpose(),
                        "]) where its triangles are round-off: ", e.what(), "; choose a scale and translate that keep ",
                        "each triangle's size well above 10⁻¹⁶ of its coordinates"));
    }
    return [surface, what = file.string()](double friction, const Eigen::Vector3d& velocity) {
        return std::make_shared<contact::MeshObstacle>(surface, friction, velocity, what);
    };
}

/// A capsule: start and end (its segment's ends, required, apart) and radius > 0 (required).
Build read_capsule(const Fields& fields, const std::filesystem::path&, std::filesystem::path&)
{
    for (const char* end : {"start", "end"})
        if (!fields.has(end))
            fields.missing(end, "a capsule needs start = [x, y, z] and end = [x, y, z] (its segment's ends, m)");
    const Eigen::Vector3d start = fields.vector("start", Eigen::Vector3d::Zero());
    const Eigen::Vector3d end = fields.vector("end", Eigen::Vector3d::Zero());
    const double reach = std::max(start.cwiseAbs().maxCoeff(), end.cwiseAbs().maxCoeff());
    if (!((end - start).cwiseAbs().maxCoeff() > resolvable * reach))
        fields.fail(*fields.get("end"), "end",
                    str("must differ from start: a capsule's segment has a length > 0 (m), by more than ", resolvable,
                        " times the ends' distance from the origin (", reach, " m), or round-off swallows it"));
    if (!fields.has("radius"))
        fields.missing("radius", "a capsule needs radius = r (m)");
    const double radius = fields.positive("radius", 1.0);
    return [=](double friction, const Eigen::Vector3d& velocity) {
        return std::make_shared<contact::Capsule>(start, end, radius, friction, velocity);
    };
}

/// One [[obstacle]] type: its name, its own fields, and its reader (the fields read and checked;
/// a mesh's file returned in the last argument).
struct ObstacleType {
    std::string name;
    std::vector<std::string> fields;
    Build (*read)(const Fields& fields, const std::filesystem::path& scene_file, std::filesystem::path& file);
};

/// Every type a scene file may name: adding an obstacle type is one entry here (and its class in
/// chapter 14, which also draws it). docs/scenes.md#obstacles
const std::vector<ObstacleType>& registry()
{
    static const std::vector<ObstacleType> types{
        {"half-space", {"point", "normal"}, read_half_space},
        {"sphere", {"center", "radius"}, read_sphere},
        {"box", {"center", "size", "axis", "angle"}, read_box},
        {"mesh", {"file", "scale", "translate"}, read_mesh},
        {"capsule", {"start", "end", "radius"}, read_capsule},
    };
    return types;
}

}  // namespace
}  // namespace detail

std::vector<std::string> obstacle_types()
{
    std::vector<std::string> names;
    for (const detail::ObstacleType& type : detail::registry())
        names.push_back(type.name);
    return names;
}

namespace detail {

ObstacleSpec read_obstacle(const toml::table& table, const std::string& name, const Source& source,
                           const std::filesystem::path& scene_file)
{
    const std::vector<std::string> types = obstacle_types();
    std::vector<std::string> allowed{"type"};
    for (const ObstacleType& type : registry())
        for (const std::string& key : type.fields)
            if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
                allowed.push_back(key);
    allowed.insert(allowed.end(), {"velocity", "friction"});
    const Fields fields(table, name, source, allowed);
    if (!fields.has("type"))
        fields.missing("type", str("one of ", joined(types)));
    ObstacleSpec o;
    o.type = fields.text("type", "", types);
    const ObstacleType& own = *std::find_if(registry().begin(), registry().end(),
                                            [&](const ObstacleType& type) { return type.name == o.type; });
    for (const std::string& key : allowed)
        if (fields.has(key) && key != "type" && key != "velocity" && key != "friction" &&
            std::find(own.fields.begin(), own.fields.end(), key) == own.fields.end()) {
            const ObstacleType& other = *std::find_if(registry().begin(), registry().end(), [&](const ObstacleType& type) {
                return std::find(type.fields.begin(), type.fields.end(), key) != type.fields.end();
            });
            fields.fail(*fields.get(key), key, str("belongs to type = \"", other.name, "\", not to type = \"", o.type, "\""));
        }
    const Build build = own.read(fields, scene_file, o.file);
    const double friction = fields.number("friction", 0.0, [](double mu) { return mu >= 0.0 && mu <= 10.0; }, "a number in [0, 10]");
    const Eigen::Vector3d velocity = fields.vector("velocity", Eigen::Vector3d::Zero());
    try {
        o.obstacle = build(friction, velocity);
    } catch (const Error& e) {  // chapter 14's own checks: named at the obstacle's table
        throw Error(str(fields.where(table), ": ", name, " (", o.type, "): ", e.what()));
    }
    return o;
}

void check_obstacle_scale(const Fields& top, const toml::node& node, const std::string& name, const SceneSpec& scene)
{
    const contact::Obstacle& obstacle = *scene.obstacles.back().obstacle;
    const Fields fields(*node.as_table(), name, top.source(), {});
    const double limit = obstacle_reach_limit * scene.contact.activation_distance;
    const double travel = obstacle.velocity().norm() * scene.duration;
    if (!(travel <= limit))
        fields.fail(*fields.get("velocity"), "velocity",
                    str("moves it ", travel, " m in the run (|velocity| × time.duration = ", scene.duration,
                        " s), more than ", obstacle_reach_limit, " d̂ = ", limit, " m, where positions are resolved ",
                        "to no better than 10⁻⁸ d̂: slow it to at most ", limit / scene.duration, " m/s"));
    // How far from the origin it reaches: a half-space its plane's offset, a solid or a mesh its
    // drawn triangles (a sphere's and a capsule's within their exact shape).
    const double reach = obstacle.name() == "half-space"
                             ? std::abs(obstacle.local_distance(Eigen::Vector3d::Zero()))
                             : obstacle.local_surface({}).V.cwiseAbs().maxCoeff();
    if (!(reach <= limit)) {
        // Blamed on its own field of the largest magnitude (a radius, a center, a translate, …).
        std::string blamed;
        double largest = -1.0;
        for (auto&& [key, value] : fields.table()) {
            if (key.str() == "velocity" || key.str() == "friction" || key.str() == "angle")
                continue;
            double magnitude = value.is_number() ? std::abs(*value.value<double>()) : -1.0;
            if (const toml::array* numbers = value.as_array())
                for (const toml::node& x : *numbers)
                    if (x.is_number())
                        magnitude = std::max(magnitude, std::abs(*x.value<double>()));
            if (magnitude > largest) {
                largest = magnitude;
                blamed = std::string(key.str());
            }
        }
        const std::string message =
            str("places the ", obstacle.name(), " ", reach, " m from the origin, more than ", obstacle_reach_limit,
                " d̂ = ", limit, " m (contact.activation_distance d̂ = ", scene.contact.activation_distance,
                " m): there a position is resolved to no better than 10⁻⁸ d̂, and the barrier's distance jumps; ",
                "keep every obstacle within ", limit, " m of the origin (a far plane: move its point along its ",
                "normal; a huge sphere: a half-space)");
        if (blamed.empty())
            top.fail(node, name, message);
        fields.fail(*fields.get(blamed), blamed, message);
    }
}

namespace {

/// The node of body[i].material.model in the scene (nullptr when the body's material sets none).
const toml::node* model_node(const Fields& top, std::size_t i)
{
    const toml::array* bodies = top.get("body") != nullptr ? top.get("body")->as_array() : nullptr;
    const toml::table* body = bodies != nullptr && i < bodies->size() ? bodies->get(i)->as_table() : nullptr;
    const toml::table* material = body != nullptr && body->get("material") != nullptr ? body->get("material")->as_table() : nullptr;
    return material != nullptr ? material->get("model") : nullptr;
}

/// Whether p lies in a tet of mesh (barycentric coordinates ≥ 0, touching included); its index, or −1.
int tet_holding(const TetMesh& mesh, const Eigen::Vector3d& p)
{
    for (Eigen::Index t = 0; t < mesh.T.rows(); ++t) {
        Eigen::Matrix3d edges;
        const Eigen::Vector3d x0 = mesh.V.row(mesh.T(t, 0));
        for (int k = 1; k < 4; ++k)
            edges.col(k - 1) = mesh.V.row(mesh.T(t, k)).transpose() - x0;
        const Eigen::Vector3d lambda = edges.partialPivLu().solve(p - x0);
        if ((lambda.array() >= 0.0).all() && lambda.sum() <= 1.0)
            return static_cast<int>(t);
    }
    return -1;
}

/// Refuses a squeeze the prescribed motions make impossible: the obstacle (scene.obstacles.back())
/// moving onto a pinned vertex of body i (at its velocity field), or a pin's prescribed motion
/// driving a vertex into the obstacle (at its table): neither can give way. A pinned vertex
/// moves as the contact step moves it, on the chord between its prescribed places at two step ends
/// (one chord over the run for a fixed pin), and the obstacle at its velocity w: their relative path
/// x(t₁) − x(t₀) − (t₁ − t₀) w against the obstacle at t₀ (Obstacle::time_of_impact).
void check_pins_clear(const Fields& top, const toml::node& node, const std::string& name, const SceneSpec& scene,
                      std::size_t i)
{
    const contact::Obstacle& obstacle = *scene.obstacles.back().obstacle;
    const Eigen::Vector3d& w = obstacle.velocity();
    const BodySpec& body = scene.bodies[i];
    const Fields fields(*node.as_table(), name, top.source(), {});
    const int steps = static_cast<int>(std::lround(scene.duration / scene.time_step));
    for (std::size_t j = 0; j < body.pins.size(); ++j) {
        const Motion& motion = body.pins[j].motion;
        if (motion.kind == Motion::Kind::fixed && w.isZero(0.0))
            continue;  // a still pin clear of a still obstacle at the start (check_bodies_clear) stays clear
        const int chords = motion.kind == Motion::Kind::fixed ? 1 : steps;
        for (int v : select_vertices(body.mesh, body.pins[j].select)) {
            const Eigen::Vector3d X = body.mesh.V.row(v).transpose();
            for (int k = 0; k < chords; ++k) {
                const double t0 = scene.duration * k / chords, t1 = scene.duration * (k + 1) / chords;
                const Eigen::Vector3d x0 = X + prescribed_displacement(motion, X, t0),
                                      x1 = X + prescribed_displacement(motion, X, t1);
                const double s = obstacle.time_of_impact(x0, x1 - x0 - (t1 - t0) * w, t0);
                if (s <= 1.0 && w.isZero(0.0))
                    top.fail(node, name,
                             str("is reached by pinned vertex ", v, " of body '", body.name, "' (body[", i, "].pin[", j,
                                 "], its prescribed motion) at t = ", t0 + s * (t1 - t0), " s: the obstacle cannot ",
                                 "give way, so no motion of the body can make room; end the run before ",
                                 "(time.duration), or move the pin's path or the obstacle"));
                if (s <= 1.0)
                    fields.fail(*fields.get("velocity"), "velocity",
                                str("moves the ", obstacle.name(), " onto pinned vertex ", v, " of body '", body.name,
                                    "' (body[", i, "].pin[", j, "]) at t = ", t0 + s * (t1 - t0),
                                    " s: a pinned vertex cannot give way, so no motion of the body can make room; ",
                                    "end the run before (time.duration), slow or turn the obstacle, or unpin the ",
                                    "vertex"));
            }
        }
    }
}

}  // namespace

void check_half_spaces_apart(const Fields& top, const toml::node& node, const std::string& name, const SceneSpec& scene)
{
    const auto* last = dynamic_cast<const contact::HalfSpace*>(scene.obstacles.back().obstacle.get());
    if (last == nullptr)
        return;
    const double room = 2.0 * scene.contact.activation_distance;
    for (std::size_t a = 0; a + 1 < scene.obstacles.size(); ++a) {
        const auto* other = dynamic_cast<const contact::HalfSpace*>(scene.obstacles[a].obstacle.get());
        if (other == nullptr || other->normal().dot(last->normal()) > -1.0 + 1e-12)
            continue;  // a wedge or parallel floors: a body can leave through the open side
        // A point of the other's plane at t = 0 (the one nearest the origin), moved with it.
        const Eigen::Vector3d on_other = -other->distance(Eigen::Vector3d::Zero(), 0.0) * other->normal();
        const auto gap = [&](double t) { return last->distance(on_other + t * other->velocity(), t); };
        const double start = gap(0.0), end = gap(scene.duration);
        if (!(start > room) || end > room)
            continue;  // no room at the start is check_bodies_clear's refusal; a gap that stays is the run's
        const double t = scene.duration * (start - room) / (start - end);
        const std::string closes =
            str("the gap between the half-spaces obstacle[", a, "] and ", name, " (facing each other) to ", room,
                " m = 2 d̂ at t = ", t, " s: a body between them would have to flatten below that or pass through ",
                "one; end the run before (time.duration), slow the obstacles, or let them stop farther apart");
        if (!last->velocity().isZero(0.0))
            Fields(*node.as_table(), name, top.source(), {})
                .fail(*node.as_table()->get("velocity"), "velocity", "closes " + closes);
        top.fail(node, name, str("the motion of obstacle[", a, "] closes ", closes));
    }
}

void check_bodies_clear(const Fields& top, const toml::node& node, const std::string& name, const SceneSpec& scene)
{
    const contact::Obstacle& obstacle = *scene.obstacles.back().obstacle;
    const std::string what = str(name, " (", obstacle.name(), ")");
    const bool sheet = !obstacle.has_inside();
    // A solid's barrier at d: its curvature grows as d̂²/d², past a double's range below 10⁻⁸ d̂.
    const double clearance = sheet ? scene.contact.activation_distance : closest_start * scene.contact.activation_distance;
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
        const BodySpec& body = scene.bodies[i];
        if (body.model == hyper::linear_model) {
            const std::string message =
                str("model linear cannot meet obstacles (its energy of a body at rest far from where it started is ",
                    "round-off; docs/scenes.md#obstacles), and the scene has ", what, ": use auto, corotational or a ",
                    "hyperelastic model");
            const toml::node* model = model_node(top, i);
            if (model != nullptr)
                Fields(*top.get("body")->as_array()->get(i)->as_table()->get("material")->as_table(),
                       str("body[", i, "].material"), top.source(), {})
                    .fail(*model, "model", message);
            top.fail(*top.get("body")->as_array()->get(i), str("body[", i, "]"),
                     str("material.model is linear when not given; ", message));
        }
        for (Eigen::Index v = 0; v < body.mesh.V.rows(); ++v) {
            const double d = obstacle.distance(body.mesh.V.row(v).transpose(), 0.0);
            if (!(d > clearance))
                top.fail(node, name,
                         sheet ? str("body '", body.name, "' starts within contact.activation_distance = ", clearance,
                                    " m of it (vertex ", v, " at ", d, " m from its triangles; a mesh's distance ",
                                    "is unsigned, so a body must start clear of it): move the body or the obstacle")
                         : d > 0.0
                             ? str("body '", body.name, "' starts ", d, " m from it (vertex ", v, "), closer than ",
                                   closest_start, " d̂ = ", clearance, " m, where the barrier's curvature leaves a ",
                                   "double's range: move the body or the obstacle at least that far apart")
                             : str("body '", body.name, "' starts inside it (vertex ", v, " at ", d,
                                   " m from its surface): move the body or the obstacle"));
        }
        for (Eigen::Index t = 0; sheet && t < body.mesh.T.rows(); ++t)
            for (int j = 0; j < 4; ++j)
                for (int k = j + 1; k < 4; ++k)
                    if (obstacle.crosses(body.mesh.V.row(body.mesh.T(t, j)).transpose(),
                                      body.mesh.V.row(body.mesh.T(t, k)).transpose()))
                        top.fail(node, name,
                                 str("body '", body.name, "' starts through it (the edge of tet ", t, " from vertex ",
                                     body.mesh.T(t, j), " to ", body.mesh.T(t, k), " crosses a triangle): ",
                                     "move the body or the obstacle"));
        // With every vertex outside, a solid may still pass through an edge of the body (a slab
        // through a block, a rod through it), or an obstacle's edge through a face of the body (a
        // spike), or the whole obstacle lie inside the body (a sphere in it).
        const contact::SurfacePrimitives surface = contact::surface_primitives(body.mesh);
        for (Eigen::Index e = 0; !sheet && e < surface.edges.rows(); ++e) {
            const Eigen::Vector3d x0 = body.mesh.V.row(surface.edges(e, 0)), x1 = body.mesh.V.row(surface.edges(e, 1));
            if (obstacle.time_of_impact(x0, x1 - x0, 0.0) <= 1.0)
                top.fail(node, name,
                         str("body '", body.name, "' starts with its surface edge from vertex ", surface.edges(e, 0),
                             " to ", surface.edges(e, 1), " through it (both ends outside): move the body or the ",
                             "obstacle so that they start apart"));
        }
        check_pins_clear(top, node, name, scene, i);
        if (obstacle.name() == "half-space")
            continue;  // a body apart from a plane has every vertex above it
        const TriMesh drawn = obstacle.local_surface({});
        if (obstacle.local_features().corners.rows() > 0 || sheet) {  // its triangles are its exact surface
            const std::string crossing = contact::first_crossing(body.mesh.V, surface, drawn);
            if (!crossing.empty())
                top.fail(node, name,
                         str("body '", body.name, "' starts through it (", crossing, ", the obstacle's vertices ",
                             "numbered from ", body.mesh.V.rows(), "): move the body or the obstacle so that they ",
                             "start apart"));
        }
        const int tet = tet_holding(body.mesh, drawn.V.row(0).transpose());
        if (tet >= 0)
            top.fail(node, name,
                     str("starts inside body '", body.name, "' (its point (", drawn.V.row(0), ") in tet ", tet,
                         ", vertices ", body.mesh.T.row(tet), "): move the body or the obstacle so that they start apart"));
    }
}

}  // namespace detail

}  // namespace fem::scenes
