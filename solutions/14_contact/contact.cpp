#include "14_contact/contact.hpp"

#include "14_contact/barrier.hpp"

#include "13_skinning/skinning.hpp"

#include "12_hyperelastic_newton/materials.hpp"

#include "common/error.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace fem::contact {
namespace {

constexpr double infinity = std::numeric_limits<double>::infinity();


}  // namespace

Eigen::Matrix<double, 3, 2> tangent_basis(const Eigen::Vector3d& normal)
{
    const Eigen::Vector3d n = normal.normalized();
    // The axis least aligned with n, crossed with it, gives a first tangent of length ≥ √(2/3).
    Eigen::Index axis = 0;
    n.cwiseAbs().minCoeff(&axis);
    const Eigen::Vector3d first = n.cross(Eigen::Vector3d::Unit(axis)).normalized();
    Eigen::Matrix<double, 3, 2> T;
    T.col(0) = first;
    T.col(1) = n.cross(first);
    return T;
}

double balancing_stiffness(const Eigen::VectorXd& g, const Eigen::VectorXd& h)
{
    if (g.size() != h.size())
        throw Error(str("balancing_stiffness: g and h must have one size, got ", g.size(), " and ", h.size()));
    const double norm = h.squaredNorm();
    return norm > 0.0 ? -g.dot(h) / norm : 0.0;
}

double smallest_stiffness(double average_mass, double time_step, double activation_distance)
{
    require_positive(average_mass, "average vertex mass [kg]");
    require_positive(time_step, "time step dt [s]");
    return average_mass / (time_step * time_step * barrier(0.5 * activation_distance, activation_distance).second);
}

ContactPotential::ContactPotential(const dynamics::Body& body, std::vector<std::shared_ptr<const Obstacle>> obstacles,
                                   ContactOptions options)
    : obstacles_(std::move(obstacles)), options_(options), rest_(body.mesh().V)
{
    if (obstacles_.empty())
        throw Error("contact: no obstacle given");
    for (const auto& obstacle : obstacles_)
        if (!obstacle)
            throw Error("contact: an obstacle is null");
    require_positive(options_.activation_distance, "contact activation distance d̂ [m]");
    if (!(std::isfinite(options_.stiffness) && options_.stiffness >= 0.0))
        throw Error(str("contact: the barrier stiffness kappa must be >= 0 (0: adaptive), got ", options_.stiffness));
    if (!(options_.safety > 0.0 && options_.safety < 1.0))
        throw Error(str("contact: the line search's safety factor must lie in (0, 1), got ", options_.safety));
    require_positive(options_.friction_velocity, "friction velocity eps_v [m/s]");
    if (!(std::isfinite(options_.doubling_distance) && options_.doubling_distance >= 0.0))
        throw Error(str("contact: the doubling distance must be >= 0, got ", options_.doubling_distance));
    const skin::Boundary boundary = skin::boundary_faces(body.mesh());
    std::vector<bool> on_surface(static_cast<std::size_t>(rest_.rows()), false);
    for (Eigen::Index f = 0; f < boundary.faces.rows(); ++f)
        for (int c = 0; c < 3; ++c)
            on_surface[static_cast<std::size_t>(boundary.faces(f, c))] = true;
    double mass = 0.0;
    for (int v = 0; v < static_cast<int>(on_surface.size()); ++v)
        if (on_surface[static_cast<std::size_t>(v)]) {
            surface_.push_back(v);
            mass += body.dof_masses()[3 * v];
        }
    average_mass_ = mass / static_cast<double>(surface_.size());
    diagonal_ = (rest_.colwise().maxCoeff() - rest_.colwise().minCoeff()).norm();
    stiffness_ = options_.stiffness;
    stiffness_set_ = options_.stiffness > 0.0;
}

Eigen::Vector3d ContactPotential::position(const Eigen::VectorXd& u, int vertex) const
{
    return rest_.row(vertex).transpose() + u.segment<3>(3 * vertex);
}

double ContactPotential::smallest_distance(const Eigen::VectorXd& u) const
{
    double smallest = infinity;
    for (int v : surface_)
        for (const auto& obstacle : obstacles_)
            smallest = std::min(smallest, obstacle->distance(position(u, v), time_));
    return smallest;
}

bool ContactPotential::out_of_contact(const Eigen::VectorXd& u, double time, const Eigen::VectorXd& u_end,
                                      double end_time) const
{
    if (u.size() != 3 * rest_.rows() || u_end.size() != u.size())
        throw Error(str("contact: out_of_contact needs u and u_end with 3n = ", 3 * rest_.rows(), " entries, got ",
                        u.size(), " and ", u_end.size()));
    const double reach = options_.activation_distance;
    for (int v : surface_) {
        const Eigen::Vector3d x = position(u, v), x_end = position(u_end, v);
        for (const auto& obstacle : obstacles_)
            if (obstacle->distance(x, time) < reach || obstacle->distance(x, end_time) < reach ||
                obstacle->distance(x_end, end_time) < reach || obstacle->time_of_impact(x, x_end - x, end_time) <= 1.0)
                return false;
    }
    return true;
}

void ContactPotential::begin_step(dynamics::Body& body, const dynamics::State& state, double time_step)
{
    require_positive(time_step, "time step dt [s]");
    time_ = state.time + time_step;
    friction_step_ = options_.friction_velocity * time_step;
    // κ (after IPC): balanced at the first contact, doubled while the distance keeps falling below ε_d.
    if (options_.stiffness == 0.0) {
        const double low = smallest_stiffness(average_mass_, time_step, options_.activation_distance);
        const double high = 100.0 * low;
        const double smallest = smallest_distance(state.u);
        if (!stiffness_set_) {
            stiffness_ = 1.0;
            const Eigen::VectorXd unit_barrier = body.dofs().gather(-barrier_forces(state.u));
            const Eigen::VectorXd load = body.dofs().gather(-state.forces - body.external_forces());
            stiffness_ = std::clamp(balancing_stiffness(load, unit_barrier), low, high);
            stiffness_set_ = unit_barrier.norm() > 0.0;
        } else if (smallest < options_.doubling_distance * diagonal_ && smallest < last_smallest_) {
            stiffness_ = std::min(high, 2.0 * stiffness_);
        }
        stiffness_ = std::clamp(stiffness_, low, high);
        last_smallest_ = smallest;
    }
    // The friction pairs, lagged at the step's start (IPC), or where lag_friction_at said.
    const bool at_start = lag_u_.size() == 0;
    const Eigen::VectorXd& lag = at_start ? state.u : lag_u_;
    const double lag_time = at_start ? state.time : time_;
    pairs_.clear();
    for (int v : surface_)
        for (int o = 0; o < static_cast<int>(obstacles_.size()); ++o) {
            const Obstacle& obstacle = *obstacles_[static_cast<std::size_t>(o)];
            if (obstacle.friction() == 0.0)
                continue;
            const Eigen::Vector3d x = position(lag, v);
            const double d = obstacle.distance(x, lag_time);
            if (!(d > 0.0 && d < options_.activation_distance))
                continue;
            FrictionPair pair;
            pair.vertex = v;
            pair.obstacle = o;
            std::vector<DistancePiece> pieces;
            obstacle.pieces(x, lag_time, options_.activation_distance, pieces);
            for (const DistancePiece& piece : pieces)
                pair.normal_force += stiffness_ * std::abs(barrier(piece.distance, options_.activation_distance).first);
            pair.coefficient = obstacle.friction();
            pair.tangent = tangent_basis(obstacle.gradient(x, lag_time));
            pair.start = position(state.u, v) + time_step * obstacle.velocity();
            pairs_.push_back(pair);
        }
    lag_u_.resize(0);
}

void ContactPotential::lag_friction_at(const Eigen::VectorXd& u)
{
    if (u.size() != 3 * rest_.rows())
        throw Error(str("contact: the friction lag needs u with 3n = ", 3 * rest_.rows(), " entries, got ", u.size()));
    lag_u_ = u;
}

dynamics::StepInfo step_with_friction_updates(hyper::NewtonBackwardEuler& newton, ContactPotential& contact,
                                              dynamics::Body& body, double time_step, dynamics::State& state,
                                              int updates, int* solves)
{
    if (updates < 0)
        throw Error(str("contact: friction updates per step must be >= 0 (0: until converged), got ", updates));
    const bool until_converged = updates == 0;
    const double tolerance = friction_lag_tolerance * contact.options().friction_velocity * time_step;
    dynamics::State solution = state;
    dynamics::StepInfo info = newton.step(body, time_step, solution);
    int solved = 1;
    while (until_converged || solved < updates) {
        contact.lag_friction_at(solution.u);
        const Eigen::VectorXd last = solution.u;
        solution = state;
        const dynamics::StepInfo again = newton.step(body, time_step, solution);
        ++solved;
        info.newton_iterations += again.newton_iterations;
        info.solver_iterations += again.solver_iterations;
        info.damping_work = again.damping_work;
        info.boundary_work = again.boundary_work;
        if (until_converged) {
            const double moved = (solution.u - last).lpNorm<Eigen::Infinity>();
            if (moved <= tolerance)
                break;
            if (solved == most_friction_updates)
                throw Error(str("contact: the friction lag did not converge in ", most_friction_updates,
                                " solves of step ", state.step + 1, " (t = ", state.time + time_step,
                                " s): the last moved a vertex by ", moved, " m, above ", tolerance, " m"));
        }
    }
    if (solves != nullptr)
        *solves = solved;
    state = std::move(solution);
    return info;
}

double ContactPotential::barrier_energy(const Eigen::VectorXd& u, double time) const
{
    double total = 0.0;
    for (int v : surface_)
        for (const auto& obstacle : obstacles_) {
            const Eigen::Vector3d x = position(u, v);
            const double d = obstacle->distance(x, time);
            if (!(d > 0.0))
                return infinity;
            if (!(d < options_.activation_distance))
                continue;
            std::vector<DistancePiece> pieces;
            obstacle->pieces(x, time, options_.activation_distance, pieces);
            for (const DistancePiece& piece : pieces)
                total += stiffness_ * barrier(piece.distance, options_.activation_distance).value;
        }
    return total;
}

double ContactPotential::energy(const Eigen::VectorXd& u) const
{
    double total = barrier_energy(u, time_);
    if (!std::isfinite(total))
        return total;
    for (const FrictionPair& pair : pairs_) {
        const double y = (pair.tangent.transpose() * (position(u, pair.vertex) - pair.start)).norm();
        total += pair.coefficient * pair.normal_force * friction_mollifier(y, friction_step_).f0;
    }
    return total;
}

Eigen::VectorXd ContactPotential::barrier_forces(const Eigen::VectorXd& u) const
{
    Eigen::VectorXd forces = Eigen::VectorXd::Zero(u.size());
    for (int v : surface_)
        for (const auto& obstacle : obstacles_) {
            std::vector<DistancePiece> pieces;
            obstacle->pieces(position(u, v), time_, options_.activation_distance, pieces);
            for (const DistancePiece& piece : pieces)
                forces.segment<3>(3 * v) -=
                    stiffness_ * barrier(piece.distance, options_.activation_distance).first * piece.gradient;
        }
    return forces;
}

Eigen::VectorXd ContactPotential::gradient(const Eigen::VectorXd& u) const
{
    Eigen::VectorXd gradient = -barrier_forces(u);
    for (const FrictionPair& pair : pairs_) {
        const Eigen::Vector2d s = pair.tangent.transpose() * (position(u, pair.vertex) - pair.start);
        const double y = s.norm();
        const MollifierValue f = friction_mollifier(y, friction_step_);
        // f₁(y)/y, finite at y = 0 where it tends to 2/ε.
        const double f1_over_y = y > 0.0 ? f.f1 / y : 2.0 / friction_step_;
        gradient.segment<3>(3 * pair.vertex) += pair.coefficient * pair.normal_force * f1_over_y * (pair.tangent * s);
    }
    return gradient;
}

dynamics::SparseMatrix ContactPotential::hessian(const Eigen::VectorXd& u) const
{
    // Every term of P acts on one vertex: the Hessian is block diagonal, each vertex's block the sum
    // of its barrier and friction terms, projected once (the nearest PSD matrix to the vertex's block).
    std::map<int, Eigen::Matrix3d> blocks;
    const auto add = [&](int vertex, const Eigen::Matrix3d& block) {
        auto [slot, fresh] = blocks.try_emplace(vertex, block);
        if (!fresh)
            slot->second += block;
    };
    for (int v : surface_)
        for (const auto& obstacle : obstacles_) {
            std::vector<DistancePiece> pieces;
            obstacle->pieces(position(u, v), time_, options_.activation_distance, pieces);
            for (const DistancePiece& piece : pieces) {
                const BarrierValue b = barrier(piece.distance, options_.activation_distance);
                const Eigen::Vector3d& n = piece.gradient;
                add(v, stiffness_ * (b.second * n * n.transpose() + b.first * piece.hessian));
            }
        }
    for (const FrictionPair& pair : pairs_) {
        const Eigen::Vector2d s = pair.tangent.transpose() * (position(u, pair.vertex) - pair.start);
        const double y = s.norm();
        const MollifierValue f = friction_mollifier(y, friction_step_);
        const double f1_over_y = y > 0.0 ? f.f1 / y : 2.0 / friction_step_;
        // (f₁'y − f₁)/y³ s sᵀ: bounded as y → 0 (it is −s sᵀ/(y ε²) below ε), 0 at y = 0.
        const Eigen::Matrix2d radial =
            y > 0.0 ? Eigen::Matrix2d((f.f1_derivative * y - f.f1) / (y * y * y) * s * s.transpose())
                    : Eigen::Matrix2d::Zero();
        const Eigen::Matrix2d inner = radial + f1_over_y * Eigen::Matrix2d::Identity();
        add(pair.vertex, pair.coefficient * pair.normal_force * pair.tangent * inner * pair.tangent.transpose());
    }
    std::vector<Eigen::Triplet<double>> triplets;
    for (const auto& [vertex, block] : blocks) {
        const Eigen::Matrix3d projected = hyper::project_to_psd<3>(block, hyper::Projection::clamp);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                triplets.emplace_back(3 * vertex + i, 3 * vertex + j, projected(i, j));
    }
    dynamics::SparseMatrix H(u.size(), u.size());
    H.setFromTriplets(triplets.begin(), triplets.end());
    return H;
}

double ContactPotential::largest_safe_step(const Eigen::VectorXd& u, const Eigen::VectorXd& du) const
{
    double step = 1.0;
    for (int v : surface_) {
        const Eigen::Vector3d change = du.segment<3>(3 * v);
        if (change.isZero(0.0))
            continue;
        for (const auto& obstacle : obstacles_)
            step = std::min(step, options_.safety * obstacle->time_of_impact(position(u, v), change, time_));
    }
    return step;
}

}  // namespace fem::contact
