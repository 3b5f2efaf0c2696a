// The scene file's selectors of vertices and the pins' prescribed motions: read, resolved on a
// mesh, and evaluated in time. docs/scenes.md#selecting-vertices
#include "scene_parts.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <set>

namespace fem::scenes {
namespace detail {

Selector read_selector(const Fields& fields)
{
    Selector s;
    s.where = str(fields.where(fields.table()), ": ", fields.name());
    const int given = int(fields.has("box")) + int(fields.has("plane")) + int(fields.has("vertices"));
    if (given != 1)
        throw Error(str(s.where, ": give exactly one of box = [[x0, y0, z0], [x1, y1, z1]], ",
                        "plane = { point = [...], normal = [...] } or vertices = [...]"));
    if (fields.has("box")) {
        s.kind = Selector::Kind::box;
        const toml::array& corners = fields.array("box", 2, "two corners [[x0, y0, z0], [x1, y1, z1]]");
        const toml::table corner_table{{"low", *corners.get(0)}, {"high", *corners.get(1)}};
        const Fields corner(corner_table, fields.field("box"), fields.source(), {"low", "high"});
        s.low = corner.vector("low", Eigen::Vector3d::Zero());
        s.high = corner.vector("high", Eigen::Vector3d::Zero());
        if ((s.low.array() > s.high.array()).any())
            fields.fail(*fields.get("box"), "box", "the first corner must be below the second in x, y and z");
    } else if (fields.has("plane")) {
        s.kind = Selector::Kind::plane;
        const Fields plane(*fields.subtable("plane"), fields.field("plane"), fields.source(), {"point", "normal", "side"});
        s.point = plane.vector("point", Eigen::Vector3d::Zero());
        s.normal = plane.vector("normal", Eigen::Vector3d::UnitX(), true).normalized();
        s.below = plane.text("side", "on", {"on", "below"}) == "below";
    } else {
        s.kind = Selector::Kind::vertices;
        s.vertices = fields.integers("vertices");
    }
    return s;
}

Motion read_motion(const Fields& fields, double duration)
{
    Motion m;
    const std::string kind = fields.text("motion", "fixed", {"fixed", "rotate", "translate"});
    m.start = fields.non_negative("start", 0.0);
    m.end = fields.positive("end", std::max(duration, m.start + 1e-9));
    if (m.end <= m.start)
        fields.fail(*fields.get("end"), "end", str("must be after start = ", m.start, " s"));
    const bool rotate = kind == "rotate", translate = kind == "translate";
    for (const std::string key : {"axis", "center", "angle"})
        if (!rotate && fields.has(key))
            fields.fail(*fields.get(key), key, "belongs to motion = \"rotate\"");
    if (!translate && !rotate && fields.has("displacement"))
        fields.fail(*fields.get("displacement"), "displacement",
                    "belongs to motion = \"translate\" (or \"rotate\", the axis carried along)");
    if (kind == "fixed") {
        for (const std::string key : {"start", "end"})
            if (fields.has(key))
                fields.fail(*fields.get(key), key, "belongs to a moving pin (motion = \"rotate\" or \"translate\")");
        return m;
    }
    if (rotate) {
        m.kind = Motion::Kind::rotate;
        m.axis = fields.vector("axis", Eigen::Vector3d::UnitX(), true).normalized();
        m.center = fields.vector("center", Eigen::Vector3d::Zero());
        m.angle = fields.finite("angle", 0.0) * std::acos(-1.0) / 180.0;
        m.displacement = fields.vector("displacement", Eigen::Vector3d::Zero());
    } else {
        m.kind = Motion::Kind::translate;
        m.displacement = fields.vector("displacement", Eigen::Vector3d::Zero());
    }
    return m;
}

}  // namespace detail

std::vector<int> select_vertices(const TetMesh& mesh, const Selector& selector)
{
    std::vector<int> out;
    const Eigen::Index n = mesh.V.rows();
    const double diagonal = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm();
    const double tolerance = 1e-6 * diagonal;
    if (selector.kind == Selector::Kind::vertices) {
        std::set<int> unique;
        for (int v : selector.vertices) {
            if (v < 0 || v >= n)
                throw Error(str(selector.where, ": vertex ", v, " does not exist (the mesh has ", n, " vertices)"));
            unique.insert(v);
        }
        out.assign(unique.begin(), unique.end());
    }
    for (Eigen::Index v = 0; v < n && selector.kind != Selector::Kind::vertices; ++v) {
        const Eigen::Vector3d x = mesh.V.row(v).transpose();
        bool in = false;
        if (selector.kind == Selector::Kind::box) {
            in = ((x.array() >= selector.low.array() - tolerance) && (x.array() <= selector.high.array() + tolerance)).all();
        } else {
            const double distance = selector.normal.dot(x - selector.point);
            in = selector.below ? distance <= tolerance : std::abs(distance) <= tolerance;
        }
        if (in)
            out.push_back(static_cast<int>(v));
    }
    if (out.empty()) {
        const Eigen::RowVector3d low = mesh.V.colwise().minCoeff(), high = mesh.V.colwise().maxCoeff();
        throw Error(str(selector.where, ": selects no vertex of the mesh, which spans [", low.x(), ", ", high.x(),
                        "] x [", low.y(), ", ", high.y(), "] x [", low.z(), ", ", high.z(), "] m"));
    }
    return out;
}

Eigen::Vector3d prescribed_displacement(const Motion& motion, const Eigen::Vector3d& X, double t)
{
    if (motion.kind == Motion::Kind::fixed)
        return Eigen::Vector3d::Zero();
    const double tau = std::clamp((t - motion.start) / (motion.end - motion.start), 0.0, 1.0);
    const double s = tau * tau * (3.0 - 2.0 * tau);
    if (motion.kind == Motion::Kind::translate)
        return s * motion.displacement;
    const Eigen::Matrix3d R = Eigen::AngleAxisd(s * motion.angle, motion.axis).toRotationMatrix();
    return R * (X - motion.center) + motion.center - X + s * motion.displacement;
}

}  // namespace fem::scenes
