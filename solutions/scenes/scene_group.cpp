// The scenes capstone: bodies that meet each other, grouped into solves, checked at the start.
// docs/scenes.md#bodies-against-bodies
#include "scenes/scene_group.hpp"

#include "15_body_contact/distances.hpp"
#include "15_body_contact/intersections.hpp"

#include "13_skinning/skinning.hpp"

#include "06_assembly/assembly.hpp"

#include "common/error.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace fem::scenes {

namespace {

using Box = Eigen::Matrix<double, 2, 3>;  // rows: lowest and highest corner

Box bounding_box(const MatrixX3d& x, double grow)
{
    Box box;
    box.row(0) = x.colwise().minCoeff().array() - grow;
    box.row(1) = x.colwise().maxCoeff().array() + grow;
    return box;
}

bool boxes_meet(const Box& a, const Box& b)
{
    return (a.row(0).array() <= b.row(1).array()).all() && (b.row(0).array() <= a.row(1).array()).all();
}

/// The body each vertex of a group's joined mesh belongs to (its index in members) and its own index.
struct Owner {
    std::vector<int> body, local;
};

Owner owners(const SceneSpec& scene, const std::vector<int>& members)
{
    Owner owner;
    for (std::size_t i = 0; i < members.size(); ++i)
        for (Eigen::Index v = 0; v < scene.bodies[members[i]].mesh.V.rows(); ++v) {
            owner.body.push_back(static_cast<int>(i));
            owner.local.push_back(static_cast<int>(v));
        }
    return owner;
}

}  // namespace

double travel_bound(const SceneSpec& scene, const BodySpec& body)
{
    const double T = scene.duration;
    const double mass = assembly::vertex_masses(body.mesh, body.material.density).sum();
    Eigen::Vector3d loads = Eigen::Vector3d::Zero();
    double surface_loads = 0.0;  // tractions [Pa] times the body's bounding box's surface: an upper bound of their force
    const Eigen::Vector3d extent = body.mesh.V.colwise().maxCoeff() - body.mesh.V.colwise().minCoeff();
    const double box_area = 2.0 * (extent.x() * extent.y() + extent.y() * extent.z() + extent.z() * extent.x());
    for (const Load& load : body.loads) {
        if (load.kind == Load::Kind::point)
            loads += load.value;
        else
            surface_loads += load.value.norm() * box_area;
    }
    double pins = 0.0;
    for (const Pin& pin : body.pins)
        for (int v : pin.select.vertices) {
            const Eigen::Vector3d X = body.mesh.V.row(v).transpose();
            if (pin.motion.kind == Motion::Kind::translate)
                pins = std::max(pins, pin.motion.displacement.norm());
            else if (pin.motion.kind == Motion::Kind::rotate) {
                const Eigen::Vector3d r = X - pin.motion.center;
                pins = std::max(pins, 2.0 * (r - r.dot(pin.motion.axis) * pin.motion.axis).norm() +
                                          pin.motion.displacement.norm());
            }
        }
    const double acceleration = scene.gravity.norm() + (mass > 0.0 ? (loads.norm() + surface_loads) / mass : 0.0);
    return body.initial_velocity.norm() * T + 0.5 * acceleration * T * T + pins;
}

std::vector<std::vector<int>> contact_groups(const SceneSpec& scene)
{
    const int n = static_cast<int>(scene.bodies.size());
    std::vector<int> group(static_cast<std::size_t>(n));
    std::iota(group.begin(), group.end(), 0);
    if (scene.contact.bodies) {
        std::vector<Box> boxes;
        for (const BodySpec& body : scene.bodies)
            boxes.push_back(bounding_box(body.mesh.V, scene.contact.activation_distance + travel_bound(scene, body)));
        // A pair that can meet gives every body of both their lower label.
        for (int i = 0; i < n; ++i)
            for (int j = i + 1; j < n; ++j)
                if (group[i] != group[j] && boxes_meet(boxes[i], boxes[j])) {
                    const int from = std::max(group[i], group[j]), to = std::min(group[i], group[j]);
                    std::replace(group.begin(), group.end(), from, to);
                }
    }
    std::vector<std::vector<int>> groups;
    std::vector<int> index_of(static_cast<std::size_t>(n), -1);  // a label's group
    for (int i = 0; i < n; ++i) {
        int& index = index_of[group[i]];
        if (index < 0) {
            index = static_cast<int>(groups.size());
            groups.emplace_back();
        }
        groups[index].push_back(i);
    }
    for (const std::vector<int>& members : groups)
        for (int i : members) {
            const BodySpec& a = scene.bodies[members.front()];
            const BodySpec& b = scene.bodies[i];
            if (a.damping.alpha != b.damping.alpha || a.damping.beta != b.damping.beta || a.mass != b.mass)
                throw Error(str(scene.file.string(), ": bodies '", a.name, "' and '", b.name, "' can meet, so they are "
                                "stepped as one solve ([contact] bodies = true), which has one damping and one mass "
                                "model: give them the same body.damping and body.mass"));
        }
    return groups;
}

TetMesh joined_mesh(const SceneSpec& scene, const std::vector<int>& members)
{
    Eigen::Index vertices = 0, tets = 0;
    for (int i : members) {
        vertices += scene.bodies[i].mesh.V.rows();
        tets += scene.bodies[i].mesh.T.rows();
    }
    TetMesh joined;
    joined.V.resize(vertices, 3);
    joined.T.resize(tets, 4);
    Eigen::Index v = 0, t = 0;
    for (int i : members) {
        const TetMesh& mesh = scene.bodies[i].mesh;
        joined.V.middleRows(v, mesh.V.rows()) = mesh.V;
        joined.T.middleRows(t, mesh.T.rows()) = mesh.T.array() + static_cast<int>(v);
        v += mesh.V.rows();
        t += mesh.T.rows();
    }
    return joined;
}

void check_start_gaps(const SceneSpec& scene)
{
    if (!scene.contact.bodies || scene.bodies.size() < 2)
        return;
    std::vector<int> all(scene.bodies.size());
    std::iota(all.begin(), all.end(), 0);
    const TetMesh mesh = joined_mesh(scene, all);
    const Owner owner = owners(scene, all);
    const contact::SurfacePrimitives surface = contact::surface_primitives(mesh);
    const double d_hat = scene.contact.activation_distance;
    const auto name = [&](int v) { return str("body '", scene.bodies[owner.body[v]].name, "'"); };
    const auto local = [&](std::initializer_list<int> vertices) {
        std::string out;
        for (int v : vertices)
            out += str(out.empty() ? "(" : ", ", owner.local[v]);
        return out + ")";
    };
    const auto at = [&](int v) -> Eigen::Vector3d { return mesh.V.row(v).transpose(); };
    // Bodies closer than d̂ would feel the barrier at rest: the gap must grow by d̂ − d. A smaller d̂
    // helps only when they do not touch (d > 0).
    const auto refuse = [&](const std::string& what, double distance) {
        throw Error(str(scene.file.string(), ": ", what, " is ", distance, " m away, closer than d̂ = ", d_hat,
                        " m ([contact] activation_distance): bodies must start at least d̂ apart; move them apart by at "
                        "least ", d_hat - distance, " m (d̂ minus the gap)",
                        distance > 0.0 ? str(", or set d̂ below the gap, ", distance, " m") : std::string(
                            " (they touch: no smaller d̂ helps)")));
    };
    // Pierced or nested first: their pairs are 0 m apart, and the advice differs.
    const contact::EdgeThroughTriangle crossing =
        contact::first_edge_through_triangle(mesh.V, surface.edges, surface.triangles, owner.body);
    if (crossing.found()) {
        const int e0 = surface.edges(crossing.edge, 0), e1 = surface.edges(crossing.edge, 1);
        const auto tri = surface.triangles.row(crossing.triangle);
        throw Error(str(scene.file.string(), ": ", name(e0), " and ", name(tri(0)), " start intersecting: ", name(e0),
                        " edge ", local({e0, e1}), " passes through ", name(tri(0)), " triangle ",
                        local({tri(0), tri(1), tri(2)}), " (each body's own vertex numbers); move them apart until ",
                        "no surface crosses the other and they are at least d̂ = ", d_hat, " m apart"));
    }
    // A body wholly inside another crosses no surface: its first surface vertex against each other body.
    for (std::size_t i = 0; i < scene.bodies.size(); ++i)
        for (std::size_t j = 0; j < scene.bodies.size(); ++j) {
            if (i == j)
                continue;
            const TetMesh& inner = scene.bodies[i].mesh;
            const TetMesh& outer = scene.bodies[j].mesh;
            const TriMesh outer_surface{outer.V, skin::boundary_faces(outer).faces};
            const int first = contact::surface_primitives(inner).vertices.front();
            if (skin::winding_number(outer_surface, inner.V.row(first).transpose()) > 0.5)
                throw Error(str(scene.file.string(), ": body '", scene.bodies[i].name, "' vertex ", first,
                                " starts inside body '", scene.bodies[j].name, "' (body '", scene.bodies[i].name,
                                "' lies wholly inside it): move them apart until they are at least d̂ = ", d_hat,
                                " m apart"));
        }
    const contact::CandidatePairs pairs = contact::tree_candidates(surface, mesh.V, mesh.V, d_hat);
    for (const auto& [v, t] : pairs.point_triangle) {
        const auto tri = surface.triangles.row(t);
        if (owner.body[v] == owner.body[tri(0)])
            continue;
        const Eigen::Vector3d p = at(v), a = at(tri(0)), b = at(tri(1)), c = at(tri(2));
        const double d = std::sqrt(
            contact::point_triangle_squared_distance(p, a, b, c, contact::point_triangle_type(p, a, b, c)).value);
        if (d < d_hat)
            refuse(str(name(v), " vertex ", owner.local[v], " from ", name(tri(0)), " triangle ",
                       local({tri(0), tri(1), tri(2)})), d);
    }
    for (const auto& [ea, eb] : pairs.edge_edge) {
        const int a0 = surface.edges(ea, 0), a1 = surface.edges(ea, 1), b0 = surface.edges(eb, 0), b1 = surface.edges(eb, 1);
        if (owner.body[a0] == owner.body[b0])
            continue;
        const double d = std::sqrt(contact::edge_edge_squared_distance(
                                       at(a0), at(a1), at(b0), at(b1), contact::edge_edge_type(at(a0), at(a1), at(b0), at(b1)))
                                       .value);
        if (d < d_hat)
            refuse(str(name(a0), " edge ", local({a0, a1}), " from ", name(b0), " edge ", local({b0, b1})), d);
    }
}

void check_groups_apart(const SceneSpec& scene, const std::vector<std::vector<int>>& groups,
                        const std::vector<MatrixX3d>& positions)
{
    if (groups.size() < 2)
        return;
    std::vector<int> group_of(scene.bodies.size());
    for (std::size_t g = 0; g < groups.size(); ++g)
        for (int i : groups[g])
            group_of[i] = static_cast<int>(g);
    const double d_hat = scene.contact.activation_distance;
    for (std::size_t i = 0; i < positions.size(); ++i)
        for (std::size_t j = i + 1; j < positions.size(); ++j)
            if (group_of[i] != group_of[j] &&
                boxes_meet(bounding_box(positions[i], d_hat), bounding_box(positions[j], 0.0)))
                throw Error(str("bodies '", scene.bodies[i].name, "' and '", scene.bodies[j].name,
                                "' were stepped as separate solves (their rest boxes grown by how far each could "
                                "travel did not meet; docs/scenes.md#bodies-against-bodies) but have come within d̂ of "
                                "each other's bounding box: a pin or an elastic motion drove one further than the bound"));
}

dynamics::Scene joined_scene(const SceneSpec& scene, const std::vector<int>& members)
{
    const BodySpec& first = scene.bodies[members.front()];
    dynamics::Scene joined = dynamics_scene(scene, first);
    joined.mesh = joined_mesh(scene, members);
    joined.pinned.clear();
    joined.densities.clear();
    double volume = 0.0, mass = 0.0, stiffness_volume = 0.0;
    int offset = 0;
    for (int i : members) {
        const BodySpec& body = scene.bodies[i];
        for (int v : body.pinned)
            joined.pinned.push_back(v + offset);
        joined.densities.insert(joined.densities.end(), static_cast<std::size_t>(body.mesh.T.rows()),
                                body.material.density);
        const double v_i = assembly::vertex_masses(body.mesh, 1.0).sum();
        volume += v_i;
        mass += body.material.density * v_i;
        stiffness_volume += body.material.youngs_modulus * v_i;
        offset += static_cast<int>(body.mesh.V.rows());
    }
    joined.material.youngs_modulus = stiffness_volume / volume;
    joined.material.density = mass / volume;
    return joined;
}

BodyGroups::BodyGroups(const SceneSpec& scene) : scene_(scene)
{
    check_start_gaps(scene);
    members_ = contact_groups(scene);
    for (const BodySpec& body : scene.bodies)
        body_scenes_.push_back(dynamics_scene(scene, body));
    for (const std::vector<int>& members : members_)
        joint_scenes_.push_back(members.size() > 1 ? std::optional(joined_scene(scene, members)) : std::nullopt);
}

void BodyGroups::check_apart(const std::vector<MatrixX3d>& positions) const
{
    check_groups_apart(scene_, members_, positions);
}

// --- JointForces ---------------------------------------------------------------------------------

JointForces::JointForces(std::vector<dynamics::ForceModel*> parts, std::vector<Eigen::Index> vertex_counts)
    : parts_(std::move(parts)), counts_(std::move(vertex_counts))
{
    if (parts_.size() != counts_.size() || parts_.empty())
        throw Error(str("JointForces: ", parts_.size(), " models for ", counts_.size(), " vertex counts"));
    Eigen::Index offset = 0;
    for (Eigen::Index count : counts_) {
        offsets_.push_back(offset);
        offset += count;
    }
}

std::string JointForces::name() const
{
    std::string out;
    bool same = true;
    for (const dynamics::ForceModel* part : parts_) {
        same = same && part->name() == parts_.front()->name();
        out += str(out.empty() ? "" : "+", part->name());
    }
    return same ? parts_.front()->name() : out;
}

Eigen::VectorXd JointForces::slice(const Eigen::VectorXd& u, std::size_t i) const
{
    return u.segment(3 * offsets_[i], 3 * counts_[i]);
}

double JointForces::evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& forces)
{
    forces.resize(u.size());
    double energy = 0.0;
    Eigen::VectorXd part_forces;
    for (std::size_t i = 0; i < parts_.size(); ++i) {
        energy += parts_[i]->evaluate(slice(u, i), part_forces);
        forces.segment(3 * offsets_[i], 3 * counts_[i]) = part_forces;
    }
    return energy;
}

double JointForces::energy(const Eigen::VectorXd& u)
{
    double energy = 0.0;
    for (std::size_t i = 0; i < parts_.size(); ++i)
        energy += parts_[i]->energy(slice(u, i));
    return energy;
}

template <class Matrix>
const dynamics::SparseMatrix& JointForces::block_diagonal(const Eigen::VectorXd& u, Matrix matrix)
{
    std::vector<Eigen::Triplet<double>> triplets;
    for (std::size_t i = 0; i < parts_.size(); ++i) {
        const dynamics::SparseMatrix& K = matrix(*parts_[i], slice(u, i));
        const Eigen::Index shift = 3 * offsets_[i];
        for (Eigen::Index column = 0; column < K.outerSize(); ++column)
            for (dynamics::SparseMatrix::InnerIterator it(K, column); it; ++it)
                triplets.emplace_back(it.row() + shift, it.col() + shift, it.value());
    }
    K_.resize(u.size(), u.size());
    K_.setFromTriplets(triplets.begin(), triplets.end());
    return K_;
}

const dynamics::SparseMatrix& JointForces::stiffness(const Eigen::VectorXd& u)
{
    return block_diagonal(u, [](dynamics::ForceModel& part, const Eigen::VectorXd& x) -> const dynamics::SparseMatrix& {
        return part.stiffness(x);
    });
}

const dynamics::SparseMatrix& JointForces::definite_stiffness(const Eigen::VectorXd& u)
{
    return block_diagonal(u, [](dynamics::ForceModel& part, const Eigen::VectorXd& x) -> const dynamics::SparseMatrix& {
        return part.definite_stiffness(x);
    });
}

bool JointForces::constant_stiffness() const
{
    return std::all_of(parts_.begin(), parts_.end(), [](const dynamics::ForceModel* p) { return p->constant_stiffness(); });
}

Eigen::VectorXd JointForces::von_mises_stress(const Eigen::VectorXd& u) const
{
    std::vector<Eigen::VectorXd> stresses;
    Eigen::Index tets = 0;
    for (std::size_t i = 0; i < parts_.size(); ++i) {
        stresses.push_back(parts_[i]->von_mises_stress(slice(u, i)));
        tets += stresses.back().size();
    }
    Eigen::VectorXd out(tets);
    Eigen::Index at = 0;
    for (const Eigen::VectorXd& s : stresses) {
        out.segment(at, s.size()) = s;
        at += s.size();
    }
    return out;
}

}  // namespace fem::scenes
