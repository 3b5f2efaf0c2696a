// The scene file's obstacles: the registry of [[obstacle]] types (one entry a type: its name, its
// own fields, and how they are read, checked and built into chapter 14's obstacle), the bodies'
// start clear of them. docs/scenes.md#obstacles
#include "scene_parts.hpp"

#include "15_body_contact/mesh_obstacle.hpp"

#include "common/mesh_io.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>

namespace fem::scenes {
namespace detail {
namespace {

/// What a type's own fields build, once μ and w are read: chapter 14's obstacle.
using Build = std::function<std::shared_ptr<const contact::Obstacle>(double friction, const Eigen::Vector3d& velocity)>;

/// A half-space: point (default the origin) and normal (not 0, normalised; default +z).
Build read_half_space(const Fields& fields, const std::filesystem::path&, std::filesystem::path&)
{
    const Eigen::Vector3d point = fields.vector("point", Eigen::Vector3d::Zero());
    const Eigen::Vector3d normal = fields.vector("normal", Eigen::Vector3d::UnitZ(), true).normalized();
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
    const Eigen::Vector3d axis = fields.vector("axis", Eigen::Vector3d::UnitZ(), true).normalized();
    const double angle = fields.finite("angle", 0.0) * std::acos(-1.0) / 180.0;
    const Eigen::Matrix3d rotation = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
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
    const double scale = fields.positive("scale", 1.0);
    const Eigen::Vector3d translate = fields.vector("translate", Eigen::Vector3d::Zero());
    surface.V = ((surface.V * scale).rowwise() + translate.transpose()).eval();
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
    if (!((end - start).norm() > 0.0))
        fields.fail(*fields.get("end"), "end", "must differ from start: a capsule's segment has a length > 0 (m)");
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
    o.obstacle = build(friction, velocity);
    return o;
}

void check_bodies_clear(const Fields& top, const toml::node& node, const std::string& name, const SceneSpec& scene)
{
    const contact::Obstacle& obstacle = *scene.obstacles.back().obstacle;
    const bool sheet = !obstacle.has_inside();
    const double clearance = sheet ? scene.contact.activation_distance : 0.0;
    for (const BodySpec& body : scene.bodies) {
        for (Eigen::Index v = 0; v < body.mesh.V.rows(); ++v) {
            const double d = obstacle.distance(body.mesh.V.row(v).transpose(), 0.0);
            if (!(d > clearance))
                top.fail(node, name,
                         sheet ? str("body '", body.name, "' starts within contact.activation_distance = ", clearance,
                                    " m of it (vertex ", v, " at ", d, " m from its triangles; a mesh's distance ",
                                    "is unsigned, so a body must start clear of it): move the body or the obstacle")
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
    }
}

}  // namespace detail

}  // namespace fem::scenes
