// What a scene changes between steps: loads, moving pins, auto's model. docs/scenes.md#the-runner
#include "scenes/scene_conditions.hpp"

#include "scenes/scene_contact.hpp"

#include "13_skinning/skinning.hpp"

#include "common/error.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace fem::scenes {

namespace {

/// Adds one load at full value, times scale, to f (3n): a point load spread equally over its
/// vertices, a traction lumped a third of each selected boundary triangle's force to its corners.
void add_load(const Load& load, const TetMesh& mesh, const MatrixX3i& boundary, double scale, Eigen::VectorXd& f)
{
    const std::vector<int>& vertices = load.select.vertices;
    if (load.kind == Load::Kind::point) {
        const Eigen::Vector3d share = scale * load.value / static_cast<double>(vertices.size());
        for (int v : vertices)
            f.segment<3>(3 * v) += share;
        return;
    }
    std::vector<char> selected(static_cast<std::size_t>(mesh.V.rows()), 0);
    for (int v : vertices)
        selected[static_cast<std::size_t>(v)] = 1;
    for (Eigen::Index i = 0; i < boundary.rows(); ++i) {
        const int a = boundary(i, 0), b = boundary(i, 1), c = boundary(i, 2);
        if (!selected[a] || !selected[b] || !selected[c])
            continue;
        const Eigen::Vector3d A = mesh.V.row(a), B = mesh.V.row(b), C = mesh.V.row(c);
        const double area = 0.5 * (B - A).cross(C - A).norm();
        for (int v : {a, b, c})
            f.segment<3>(3 * v) += (scale * area / 3.0) * load.value;
    }
}

}  // namespace

Eigen::VectorXd applied_loads(const BodySpec& body, const MatrixX3i& boundary, double t)
{
    Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * body.mesh.V.rows());
    for (const Load& load : body.loads) {
        const double scale = t > load.until ? 0.0 : load.ramp > 0.0 ? std::min(1.0, t / load.ramp) : 1.0;
        if (scale != 0.0)
            add_load(load, body.mesh, boundary, scale, f);
    }
    return f;
}

double default_pull_stiffness(const dynamics::Body& body)
{
    const double mass = body.dof_masses().sum() / 3.0;
    return mass * std::pow(2.0 * std::numbers::pi * 1.0, 2);
}

Pull make_pull(const dynamics::Body& body, int vertex, const Eigen::Vector3d& target, double stiffness)
{
    const MatrixX3d& rest = body.mesh().V;
    if (vertex < 0 || vertex >= rest.rows())
        throw Error(str("pull: vertex ", vertex, " is not a vertex of the body (0 to ", rest.rows() - 1, ")"));
    if (!(stiffness > 0.0) || !std::isfinite(stiffness))
        throw Error(str("pull: the stiffness must be a number > 0 N/m, got ", stiffness));
    Pull pull;
    pull.vertex = vertex;
    pull.target = target;
    pull.stiffness = stiffness;
    const double radius = pull_radius * (rest.colwise().maxCoeff() - rest.colwise().minCoeff()).norm();
    std::vector<double> masses;
    for (Eigen::Index v = 0; v < rest.rows(); ++v)
        if ((rest.row(v) - rest.row(vertex)).norm() <= radius) {
            pull.vertices.push_back(static_cast<int>(v));
            masses.push_back(body.dof_masses()[3 * v]);
        }
    pull.shares = Eigen::Map<const Eigen::VectorXd>(masses.data(), static_cast<Eigen::Index>(masses.size()));
    pull.shares /= pull.shares.sum();
    return pull;
}

Eigen::VectorXd pull_load(const Pull& pull, const dynamics::Body& body, const Eigen::VectorXd& u)
{
    Eigen::VectorXd f = Eigen::VectorXd::Zero(u.size());
    if (pull.vertex < 0)
        return f;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < pull.vertices.size(); ++i) {
        const int v = pull.vertices[i];
        centre += pull.shares[static_cast<Eigen::Index>(i)] *
                  (body.mesh().V.row(v).transpose() + u.segment<3>(3 * v));
    }
    const Eigen::Vector3d force = pull.stiffness * (pull.target - centre);
    for (std::size_t i = 0; i < pull.vertices.size(); ++i)
        f.segment<3>(3 * pull.vertices[i]) += pull.shares[static_cast<Eigen::Index>(i)] * force;
    return f;
}

SceneConditions::SceneConditions(const BodySpec& body, const SceneSpec& scene, SceneForces* forces, bool automatic,
                                 const ContactIntegrator* contact, std::shared_ptr<const Pull> pull)
    : body_(&body), scene_(&scene), forces_(forces), automatic_(automatic && forces != nullptr), contact_(contact),
      pull_(std::move(pull))
{
    for (const Pin& pin : body.pins)
        pins_move_ = pins_move_ || pin.motion.kind != Motion::Kind::fixed;
    for (const Load& load : body.loads)
        loads_change_ = loads_change_ || load.ramp > 0.0 || std::isfinite(load.until);
    if (!body.loads.empty())
        boundary_ = skin::boundary_faces(body.mesh).faces;
    // A surface load must cover at least one boundary triangle: one that covers none applies nothing.
    for (const Load& load : body.loads) {
        if (load.kind != Load::Kind::surface || load.value.norm() == 0.0)
            continue;
        Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * body.mesh.V.rows());
        add_load(load, body.mesh, boundary_, 1.0, f);
        if (f.cwiseAbs().maxCoeff() == 0.0)
            throw Error(str(load.select.where, ": this surface load's vertices span no boundary triangle of body '",
                            body.name, "' (all three corners of a boundary triangle must be selected), so it would "
                            "apply nothing; select a whole face of the surface"));
    }
    initial_loads_ = applied_loads(body, boundary_, 0.0);
}

bool SceneConditions::operator()(dynamics::Body& body, const dynamics::State& state, double step_end)
{
    bool changed = false;
    const bool pulled = pull_ != nullptr && pull_->vertex >= 0;
    if (loads_change_ || pulled || pulled_) {  // pulled_: the pull's load ends with it
        Eigen::VectorXd loads = loads_change_ ? applied_loads(*body_, boundary_, step_end) : initial_loads_;
        if (pulled)
            loads += pull_load(*pull_, body, state.u);
        body.set_applied_loads(loads);
        changed = true;
    }
    pulled_ = pulled;
    if (pins_move_) {
        const double dt = step_end - state.time;
        Eigen::VectorXd velocity = Eigen::VectorXd::Zero(state.u.size());
        for (const Pin& pin : body_->pins) {
            if (pin.motion.kind == Motion::Kind::fixed)
                continue;
            for (int v : pin.select.vertices) {
                const Eigen::Vector3d g = prescribed_displacement(pin.motion, body_->mesh.V.row(v).transpose(), step_end);
                velocity.segment<3>(3 * v) = (g - state.u.segment<3>(3 * v)) / dt;
            }
        }
        body.set_pin_velocity(velocity);
    }
    if (automatic_) {
        Level next = choose_level(deformation_measures(body_->mesh, body.positions(state.u), scene_->thresholds),
                                  forces_->level(), scene_->thresholds);
        if (contact_ != nullptr && contact_->last_contact())
            next = std::max(next, Level::corotational);
        if (next != forces_->level()) {
            forces_->set_level(next);
            changed = true;
        }
    }
    return changed;
}

}  // namespace fem::scenes
