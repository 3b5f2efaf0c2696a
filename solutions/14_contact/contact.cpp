// Chapter 14: the contact potential of one body against its obstacles (plus its contact terms) —
// the barriers, lagged friction and the obstacles' motion as one term of chapter 12's Newton step
// (value, gradient, Hessian, the largest safe step) — and contact_step, the backward Euler step that
// runs it. docs/14_contact.md#the-contact-potential
#include "14_contact/contact.hpp"

#include "14_contact/barrier.hpp"
#include "14_contact/surface.hpp"

#include "12_hyperelastic_newton/materials.hpp"

#include "04_tet_jacobians/tet_jacobians.hpp"

#include "common/error.hpp"
#include "common/types.hpp"
#include "common/timer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <utility>

namespace fem::contact {
double ContactTerm::smallest_distance(const Eigen::VectorXd& /*u*/, double /*time*/, double /*reach*/) const
{
    return infinity;
}

double ContactTerm::time_of_impact(const Eigen::VectorXd& /*u*/, const Eigen::VectorXd& /*du*/, double /*time*/,
                                   double /*end_time*/) const
{
    return infinity;
}

double ContactTerm::obstacle_time_of_impact(const Eigen::VectorXd& /*u*/, double /*time*/, double /*end_time*/) const
{
    return infinity;
}

ContactPotential::ContactPotential(const dynamics::Body& body, std::vector<std::shared_ptr<const Obstacle>> obstacles,
                                   ContactOptions options, std::vector<std::unique_ptr<ContactTerm>> terms)
    : obstacles_(std::move(obstacles)), options_(options), terms_(std::move(terms)), rest_(body.mesh().V)
{
    if (obstacles_.empty() && terms_.empty())
        throw Error("contact: no obstacle and no contact term given: nothing to hold off");
    for (const auto& obstacle : obstacles_)
        if (!obstacle)
            throw Error("contact: an obstacle is null");
    for (const auto& term : terms_)
        if (!term)
            throw Error("contact: a contact term is null");
    require_positive(options_.activation_distance, "contact activation distance d̂ [m]");
    if (!(std::isfinite(options_.stiffness) && options_.stiffness >= 0.0))
        throw Error(str("contact: the barrier stiffness kappa must be >= 0 (0: adaptive), got ", options_.stiffness));
    if (!(options_.safety > 0.0 && options_.safety < 1.0))
        throw Error(str("contact: the line search's safety factor must lie in (0, 1), got ", options_.safety));
    require_positive(options_.friction_velocity, "friction velocity eps_v [m/s]");
    if (!(std::isfinite(options_.doubling_distance) && options_.doubling_distance >= 0.0))
        throw Error(str("contact: the doubling distance must be >= 0, got ", options_.doubling_distance));
    surface_ = surface_primitives(body.mesh()).vertices;
    double mass = 0.0;
    for (int v : surface_)
        mass += body.dof_masses()[3 * v];
    const double average_mass = mass / static_cast<double>(surface_.size());
    const double diagonal = (rest_.colwise().maxCoeff() - rest_.colwise().minCoeff()).norm();
    stiffness_ = options_.stiffness;
    if (options_.stiffness == 0.0)
        adaptive_.emplace(average_mass, diagonal, options_.activation_distance, options_.doubling_distance);
}

Eigen::Vector3d ContactPotential::position(const Eigen::VectorXd& u, int vertex) const
{
    return rest_.row(vertex).transpose() + u.segment<3>(3 * vertex);
}

double ContactPotential::smallest_distance(const Eigen::VectorXd& u) const
{
    double smallest = infinity;
    for (const auto& term : terms_)
        smallest = std::min(smallest, term->smallest_distance(u, time_, options_.activation_distance));
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
                obstacle->distance(x_end, end_time) < reach ||
                obstacle->time_of_impact(x, x_end - x - (end_time - time) * obstacle->velocity(), time) <= 1.0)
                return false;
    }
    return std::all_of(terms_.begin(), terms_.end(),
                       [&](const auto& term) { return term->out_of_contact(u, time, u_end, end_time, reach); });
}

void ContactPotential::begin_step(dynamics::Body& body, const dynamics::State& state, double time_step)
{
    const ScopeTimer clock(barrier_seconds_);
    require_positive(time_step, "time step dt [s]");
    fraction_ = std::exchange(next_fraction_, 1.0);
    start_ = std::exchange(next_start_, Eigen::VectorXd());
    time_ = state.time + fraction_ * time_step;
    friction_step_ = options_.friction_velocity * time_step;
    // κ (after IPC): balanced at the first contact, doubled while the distance keeps falling below ε_d.
    if (adaptive_)
        stiffness_ = adaptive_->next(time_step, smallest_distance(state.u), [&] {
            stiffness_ = 1.0;
            return std::pair(body.dofs().gather(-state.forces - body.external_forces()),
                             body.dofs().gather(-barrier_forces(state.u)));
        });
    // The friction pairs, lagged at the step's start (IPC), or where lag_friction_at said.
    const bool at_start = lag_u_.size() == 0;
    const Eigen::VectorXd& lag = at_start ? state.u : lag_u_;
    pairs_ = obstacle_friction_pairs(obstacles_, rest_, surface_, lag, at_start ? state.time : time_, state.u, time_step,
                                     stiffness_, options_.activation_distance);
    for (const auto& term : terms_)
        term->begin_step({state, lag, time_step, stiffness_});
    lag_u_.resize(0);
}

ContactClocks ContactPotential::clocks() const
{
    return {barrier_seconds_, collision_seconds_, broad_phases() - broad_phases_before_};
}

void ContactPotential::reset_clocks()
{
    barrier_seconds_ = collision_seconds_ = 0.0;
    broad_phases_before_ = broad_phases();
}

long long ContactPotential::broad_phases() const
{
    long long count = 0;
    for (const auto& term : terms_)
        count += term->broad_phases();
    return count;
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
    for (const auto& term : terms_) {
        if (!std::isfinite(total))
            break;
        total += term->barrier_energy(u, time, stiffness_);
    }
    return total;
}

double ContactPotential::energy(const Eigen::VectorXd& u) const
{
    const ScopeTimer clock(barrier_seconds_);
    for (const auto& term : terms_)
        term->check(u, time_);
    double total = barrier_energy(u, time_);
    if (!std::isfinite(total))
        return total;
    for (const FrictionPair& pair : pairs_)
        total += pair_friction(pair, u).value;
    for (const auto& term : terms_)
        total += term->friction_energy(u, friction_step_);
    return total;
}

Eigen::Vector3d ContactPotential::barrier_force(const Obstacle& obstacle, const Eigen::Vector3d& x) const
{
    std::vector<DistancePiece> pieces;
    obstacle.pieces(x, time_, options_.activation_distance, pieces);
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
    for (const DistancePiece& piece : pieces)
        force -= stiffness_ * barrier(piece.distance, options_.activation_distance).first * piece.gradient;
    return force;
}

LaggedFriction ContactPotential::pair_friction(const FrictionPair& pair, const Eigen::VectorXd& u) const
{
    return lagged_friction(pair.tangent, position(u, pair.vertex) - pair.start, pair.coefficient * pair.normal_force,
                           friction_step_);
}

Eigen::VectorXd ContactPotential::barrier_forces(const Eigen::VectorXd& u) const
{
    Eigen::VectorXd forces = Eigen::VectorXd::Zero(u.size());
    for (int v : surface_)
        for (const auto& obstacle : obstacles_)
            forces.segment<3>(3 * v) += barrier_force(*obstacle, position(u, v));
    Eigen::VectorXd term_gradient = Eigen::VectorXd::Zero(u.size());
    for (const auto& term : terms_)
        term->add_barrier_gradient(u, time_, stiffness_, term_gradient);
    return forces - term_gradient;
}

Eigen::VectorXd ContactPotential::gradient(const Eigen::VectorXd& u) const
{
    const ScopeTimer clock(barrier_seconds_);
    Eigen::VectorXd gradient = -barrier_forces(u);
    for (const FrictionPair& pair : pairs_)
        gradient.segment<3>(3 * pair.vertex) += pair_friction(pair, u).gradient;
    for (const auto& term : terms_)
        term->add_friction_gradient(u, friction_step_, gradient);
    return gradient;
}

double ContactPotential::obstacle_work(const Eigen::VectorXd& u, double time_step) const
{
    require_positive(time_step, "time step dt [s]");
    double work = 0.0;
    for (const auto& obstacle : obstacles_) {
        if (obstacle->velocity().isZero(0.0))
            continue;
        for (int v : surface_)
            work += obstacle->velocity().dot(barrier_force(*obstacle, position(u, v)));
    }
    for (const FrictionPair& pair : pairs_)
        work -= obstacles_[static_cast<std::size_t>(pair.obstacle)]->velocity().dot(pair_friction(pair, u).gradient);
    for (const auto& term : terms_)
        work += term->obstacle_power(u, time_, stiffness_);
    return time_step * work;
}

dynamics::SparseMatrix ContactPotential::hessian(const Eigen::VectorXd& u) const
{
    const ScopeTimer clock(barrier_seconds_);
    return assembled_hessian(u, options_.barrier_projection);
}

dynamics::SparseMatrix ContactPotential::exact_hessian(const Eigen::VectorXd& u) const
{
    const ScopeTimer clock(barrier_seconds_);
    return assembled_hessian(u, options_.exact_barrier_hessian ? std::nullopt
                                                               : std::optional<hyper::Projection>(options_.barrier_projection));
}

dynamics::SparseMatrix ContactPotential::assembled_hessian(const Eigen::VectorXd& u,
                                                           std::optional<hyper::Projection> projection) const
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
    for (const FrictionPair& pair : pairs_)
        add(pair.vertex, pair_friction(pair, u).hessian);
    std::vector<Eigen::Triplet<double>> triplets;
    for (const auto& [vertex, block] : blocks) {
        const Eigen::Matrix3d projected = projection ? hyper::project_to_psd<3>(block, *projection) : block;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                triplets.emplace_back(3 * vertex + i, 3 * vertex + j, projected(i, j));
    }
    for (const auto& term : terms_)
        term->add_barrier_hessian(u, time_, stiffness_, triplets, projection);
    for (const auto& term : terms_)
        term->add_friction_hessian(u, friction_step_, triplets);
    dynamics::SparseMatrix H(u.size(), u.size());
    H.setFromTriplets(triplets.begin(), triplets.end());
    for (const auto& term : terms_)
        if (const dynamics::SparseMatrix* pattern = term->pattern(); pattern != nullptr && pattern->nonZeros() > 0)
            H += *pattern;  // explicit zeros: the step's pattern, every value as it was
    return H;
}

double ContactPotential::largest_safe_step(const Eigen::VectorXd& u, const Eigen::VectorXd& du) const
{
    const ScopeTimer clock(collision_seconds_);
    double step = 1.0;
    for (int v : surface_) {
        const Eigen::Vector3d change = du.segment<3>(3 * v);
        if (change.isZero(0.0))
            continue;
        for (const auto& obstacle : obstacles_)
            step = std::min(step, options_.safety * obstacle->time_of_impact(position(u, v), change, time_));
    }
    for (const auto& term : terms_)
        step = std::min(step, options_.safety * term->time_of_impact(u, du, time_, time_));
    return step;
}

double ContactPotential::obstacle_advance(const Eigen::VectorXd& u, double time, double time_step, double from) const
{
    require_positive(time_step, "time step dt [s]");
    double earliest = infinity;
    for (const auto& obstacle : obstacles_) {
        if (obstacle->velocity().isZero(0.0))
            continue;
        const Eigen::Vector3d travel = -(1.0 - from) * time_step * obstacle->velocity();
        for (int v : surface_)
            earliest = std::min(earliest, obstacle->time_of_impact(position(u, v), travel, time + from * time_step));
    }
    for (const auto& term : terms_)
        earliest = std::min(earliest, term->obstacle_time_of_impact(u, time + from * time_step, time + time_step));
    return earliest > 1.0 ? 1.0 : from + options_.safety * earliest * (1.0 - from);
}

void ContactPotential::stage_next_step(double fraction, const Eigen::VectorXd& start)
{
    if (!(fraction > 0.0 && fraction <= 1.0))
        throw Error(str("contact: a stage's fraction of the obstacles' motion must lie in (0, 1], got ", fraction));
    if (start.size() != 3 * rest_.rows())
        throw Error(str("contact: a stage's start velocity needs 3n = ", 3 * rest_.rows(), " entries, got ",
                        start.size()));
    next_fraction_ = fraction;
    next_start_ = start;
}

Eigen::VectorXd ContactPotential::free_start(const dynamics::Body& body, const dynamics::State& state,
                                             double time_step, double obstacle_time, std::string* blocked) const
{
    require_positive(time_step, "time step dt [s]");
    // The candidates: stay put, or ride along with each moving obstacle (the pins keep theirs).
    std::vector<Eigen::VectorXd> candidates{Eigen::VectorXd::Zero(state.v.size())};
    std::vector<std::string> names{"staying put"};
    for (std::size_t o = 0; o < obstacles_.size(); ++o)
        if (!obstacles_[o]->velocity().isZero(0.0)) {
            Eigen::VectorXd carried(state.v.size());
            for (Eigen::Index v = 0; v < carried.size() / 3; ++v)
                carried.segment<3>(3 * v) = obstacles_[o]->velocity();
            candidates.push_back(std::move(carried));
            names.push_back(str("moving with obstacle ", o, " (", obstacles_[o]->name(), ")"));
        }
    for (std::size_t c = 0; c < candidates.size(); ++c) {
        Eigen::VectorXd v = body.pin_velocity();
        body.dofs().scatter(body.dofs().gather(candidates[c]), v);
        // Fixed obstacles and a body at rest, pins included: nothing moves relative to anything, so
        // staying put reaches nothing (every contact step with fixed obstacles, without a search).
        if (candidates.size() == 1 && v.isZero(0.0))
            return v;
        const auto reached = [&]() -> std::string {
            for (int vertex : surface_) {
                const Eigen::Vector3d x = position(state.u, vertex);
                for (std::size_t o = 0; o < obstacles_.size(); ++o) {
                    const Obstacle& obstacle = *obstacles_[o];
                    const Eigen::Vector3d relative =
                        time_step * v.segment<3>(3 * vertex) - (obstacle_time - state.time) * obstacle.velocity();
                    if (obstacle.time_of_impact(x, relative, state.time) <= 1.0)
                        return str("vertex ", vertex, " at (", x.transpose(), ") meets obstacle ", o, " (",
                                   obstacle.name(), ")");
                }
            }
            const Eigen::VectorXd motion = time_step * v;
            for (const auto& term : terms_)
                if (term->time_of_impact(state.u, motion, state.time, obstacle_time) <= 1.0)
                    return term->meeting();
            return {};
        }();
        if (reached.empty())
            return v;
        if (blocked != nullptr)
            *blocked += str(c == 0 ? "" : "; ", names[c], ": ", reached);
    }
    return {};
}

bool ContactPotential::has_free_start(const dynamics::Body& body, const dynamics::State& state, double time_step) const
{
    return free_start(body, state, time_step, state.time + time_step, nullptr).size() > 0;
}

Eigen::VectorXd ContactPotential::start_velocity(const dynamics::Body& body, const dynamics::State& state,
                                                 double time_step) const
{
    const ScopeTimer clock(collision_seconds_);
    if (start_.size() > 0) {  // a stage of contact_step: the last stage's solution, free by obstacle_advance
        Eigen::VectorXd v = body.pin_velocity();
        body.dofs().scatter(body.dofs().gather(start_), v);
        return v;
    }
    std::string blocked;
    Eigen::VectorXd v = free_start(body, state, time_step, time_, &blocked);
    if (v.size() == 0)
        throw Error(str("contact: step ", state.step + 1, " (t = ", state.time + time_step,
                        " s): the obstacles leave the body no room: every start of the step reaches an obstacle (",
                        blocked, ")"));
    return v;
}

namespace {

/// The first tet whose signed volume is > 0 at u_start and ≤ 0 at u_end, or −1.
int first_turned_tet(const dynamics::Body& body, const Eigen::VectorXd& u_start, const Eigen::VectorXd& u_end,
                     double* volume)
{
    const TetMesh& mesh = body.mesh();
    const MatrixX3d start = body.positions(u_start), end = body.positions(u_end);
    for (int t = 0; t < static_cast<int>(mesh.T.rows()); ++t) {
        const double after = tet::signed_volume(tet::tet_vertices(mesh, end, t));
        if (after <= 0.0 && tet::signed_volume(tet::tet_vertices(mesh, start, t)) > 0.0) {
            *volume = after;
            return t;
        }
    }
    return -1;
}

}  // namespace

dynamics::StepInfo contact_step(hyper::NewtonBackwardEuler& newton, ContactPotential& contact, dynamics::Body& body,
                                double time_step, dynamics::State& state, int updates, int* solves, int* stages)
{
    dynamics::State next = state;
    dynamics::StepInfo info;
    int staged = 1;
    if (contact.has_free_start(body, state, time_step)) {
        info = step_with_friction_updates(newton, contact, body, time_step, next, updates, solves);
    } else {
        // The stages: the obstacles moved part of the way, the body pushed there, and so on to t + Δt.
        double fraction = 0.0;
        Eigen::VectorXd start = Eigen::VectorXd::Zero(state.v.size());
        for (staged = 1;; ++staged) {
            const double advance = contact.obstacle_advance(state.u + time_step * start, state.time, time_step, fraction);
            if (advance - fraction < 1e-9 || staged > most_obstacle_stages)
                throw Error(str("contact: step ", state.step + 1, " (t = ", state.time + time_step,
                                " s): the obstacles leave the body no room: after ", staged - 1,
                                " stages they have made ", fraction, " of the step's motion and can advance no further",
                                " without reaching a surface vertex"));
            contact.stage_next_step(advance, start);
            next = state;
            try {
                info = step_with_friction_updates(newton, contact, body, time_step, next, updates, solves);
            } catch (const Error& e) {
                throw Error(str("contact: step ", state.step + 1, " (t = ", state.time + time_step,
                                " s): the obstacles leave the body no room: stage ", staged, ", with ", advance,
                                " of the step's obstacle motion made, cannot be solved: ", e.what()));
            }
            fraction = advance;
            start = next.v;
            if (fraction == 1.0)
                break;
        }
    }
    if (stages != nullptr)
        *stages = staged;
    double volume = 0.0;
    const int turned = first_turned_tet(body, state.u, next.u, &volume);
    if (turned >= 0)
        throw Error(str("contact: step ", state.step + 1, " (t = ", next.time, " s) would turn tet ", turned,
                        " inside out (volume ", volume, " m^3): only the surface vertices carry the barrier, and ",
                        "Newton's volume filter is off; turn it on (chapter 12's NewtonOptions::kept_volume, 0.1 by ",
                        "default), which keeps every tet's volume positive at every iterate"));
    // κ is the step's now (begin_step set it): B at the start with it, against B at the end.
    info.boundary_work += contact.barrier_energy(state.u, state.time) - contact.barrier_energy(next.u, next.time) +
                          contact.obstacle_work(next.u, time_step);
    state = std::move(next);
    return info;
}

}  // namespace fem::contact
