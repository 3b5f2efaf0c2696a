// The scene file's obstacles: read and checked ([[obstacle]]), the bodies' start clear of them, and
// chapter 14's obstacle of each. docs/scenes.md#obstacles
#include "scenes/scene_parts.hpp"

#include "14_contact/mesh_obstacle.hpp"

#include "common/mesh_io.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <memory>

namespace fem::scenes {
namespace detail {

ObstacleSpec read_obstacle(const toml::table& table, const std::string& name, const Source& source,
                           const std::filesystem::path& scene_file)
{
    const std::vector<std::string> types{"half-space", "sphere", "box", "mesh"};
    const std::vector<std::vector<std::string>> own{
        {"point", "normal"}, {"center", "radius"}, {"center", "size", "axis", "angle"}, {"file", "scale", "translate"}};
    const Fields fields(table, name, source, {"type", "point", "normal", "center", "radius", "size", "axis", "angle",
                                              "file", "scale", "translate", "velocity", "friction"});
    if (!fields.has("type"))
        fields.missing("type", "one of half-space, sphere, box, mesh");
    const std::string type = fields.text("type", "", types);
    const std::size_t index = static_cast<std::size_t>(std::find(types.begin(), types.end(), type) - types.begin());
    for (std::size_t other = 0; other < types.size(); ++other)
        for (const std::string& key : own[other])
            if (fields.has(key) && std::find(own[index].begin(), own[index].end(), key) == own[index].end())
                fields.fail(*fields.get(key), key, str("belongs to type = \"", types[other], "\", not to type = \"", type, "\""));
    ObstacleSpec o;
    o.kind = static_cast<ObstacleSpec::Kind>(index);
    if (o.kind == ObstacleSpec::Kind::half_space) {
        o.point = fields.vector("point", o.point);
        o.normal = fields.vector("normal", o.normal, true).normalized();
    } else if (o.kind != ObstacleSpec::Kind::mesh) {
        o.center = fields.vector("center", o.center);
    }
    if (o.kind == ObstacleSpec::Kind::sphere) {
        if (!fields.has("radius"))
            fields.missing("radius", "a sphere needs radius = r (m)");
        o.radius = fields.positive("radius", o.radius);
    }
    if (o.kind == ObstacleSpec::Kind::box) {
        if (!fields.has("size"))
            fields.missing("size", "a box needs size = [x, y, z] (its edge lengths, m)");
        o.size = fields.vector("size", o.size);
        if ((o.size.array() <= 0.0).any())
            fields.fail(*fields.get("size"), "size", "must be three edge lengths > 0 (m)");
        o.axis = fields.vector("axis", o.axis, true).normalized();
        o.angle = fields.finite("angle", 0.0) * std::acos(-1.0) / 180.0;
    }
    if (o.kind == ObstacleSpec::Kind::mesh) {
        if (!fields.has("file"))
            fields.missing("file", "a mesh needs file = \"….obj\" (a triangle surface: .obj, .stl, .ply or .vtu)");
        const toml::node& node = *fields.get("file");
        o.file = existing_file(fields, "file", scene_file);
        const std::string extension = o.file.extension().string();
        if (extension != ".obj" && extension != ".stl" && extension != ".ply" && extension != ".vtu")
            fields.fail(node, "file", str("has the extension '", extension, "'; a mesh obstacle is a triangle surface: .obj, .stl, .ply or .vtu"));
        try {
            o.surface = io::read_tri_mesh(o.file);
        } catch (const Error& e) {
            fields.fail(node, "file", str("must be a surface of triangles, none degenerate: ", e.what()));
        }
        o.scale = fields.positive("scale", o.scale);
        o.translate = fields.vector("translate", o.translate);
        o.surface.V = ((o.surface.V * o.scale).rowwise() + o.translate.transpose()).eval();
    }
    o.friction = fields.number("friction", 0.0, [](double mu) { return mu >= 0.0 && mu <= 10.0; }, "a number in [0, 10]");
    o.velocity = fields.vector("velocity", o.velocity);
    return o;
}

void check_bodies_clear(const Fields& top, const toml::node& node, const std::string& name, const SceneSpec& scene)
{
    const auto obstacle = make_obstacle(scene.obstacles.back());
    const auto* mesh = dynamic_cast<const contact::MeshObstacle*>(obstacle.get());
    const double clearance = mesh ? scene.contact.activation_distance : 0.0;
    for (const BodySpec& body : scene.bodies) {
        for (Eigen::Index v = 0; v < body.mesh.V.rows(); ++v) {
            const double d = obstacle->distance(body.mesh.V.row(v).transpose(), 0.0);
            if (!(d > clearance))
                top.fail(node, name,
                         mesh ? str("body '", body.name, "' starts within contact.activation_distance = ", clearance,
                                    " m of it (vertex ", v, " at ", d, " m from its triangles; a mesh's distance ",
                                    "is unsigned, so a body must start clear of it): move the body or the obstacle")
                              : str("body '", body.name, "' starts inside it (vertex ", v, " at ", d,
                                    " m from its surface): move the body or the obstacle"));
        }
        for (Eigen::Index t = 0; mesh && t < body.mesh.T.rows(); ++t)
            for (int j = 0; j < 4; ++j)
                for (int k = j + 1; k < 4; ++k)
                    if (mesh->crosses(body.mesh.V.row(body.mesh.T(t, j)).transpose(),
                                      body.mesh.V.row(body.mesh.T(t, k)).transpose()))
                        top.fail(node, name,
                                 str("body '", body.name, "' starts through it (the edge of tet ", t, " from vertex ",
                                     body.mesh.T(t, j), " to ", body.mesh.T(t, k), " crosses a triangle): ",
                                     "move the body or the obstacle"));
    }
}

}  // namespace detail

std::shared_ptr<const contact::Obstacle> make_obstacle(const ObstacleSpec& spec)
{
    switch (spec.kind) {
    case ObstacleSpec::Kind::half_space:
        return std::make_shared<contact::HalfSpace>(spec.point, spec.normal, spec.friction, spec.velocity);
    case ObstacleSpec::Kind::sphere:
        return std::make_shared<contact::Sphere>(spec.center, spec.radius, spec.friction, spec.velocity);
    case ObstacleSpec::Kind::mesh:
        return std::make_shared<contact::MeshObstacle>(spec.surface, spec.friction, spec.velocity, spec.file.string());
    case ObstacleSpec::Kind::box:
        break;
    }
    const Eigen::Matrix3d rotation = Eigen::AngleAxisd(spec.angle, spec.axis).toRotationMatrix();
    return std::make_shared<contact::Box>(spec.center, 0.5 * spec.size, rotation, spec.friction, spec.velocity);
}

}  // namespace fem::scenes
