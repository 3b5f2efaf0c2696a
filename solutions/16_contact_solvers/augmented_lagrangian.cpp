#include "16_contact_solvers/augmented_lagrangian.hpp"

#include "15_body_contact/broad_phase.hpp"
#include "15_body_contact/ccd.hpp"
#include "15_body_contact/distances.hpp"

#include "12_hyperelastic_newton/materials.hpp"

#include "common/error.hpp"
#include "common/types.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <set>
#include <utility>

namespace fem::contact {
namespace {

/// The chapter 15 potential that bounds the line search: its barrier is never evaluated, only its
/// collision check, its start velocity, its smallest distance and (as a debug check) its referee.
BodyContactOptions collision_options(const AugmentedLagrangianOptions& options)
{
    BodyContactOptions ccd;
    ccd.activation_distance = options.gap;
    ccd.stiffness = 1.0;  // fixed: no adaptive κ to compute, the barrier is unused
    ccd.safety = options.safety;
    ccd.self_contact = options.self_contact;
    ccd.vertex_body = options.vertex_body;
    ccd.body_self_contact = options.body_self_contact;
    ccd.pattern_reach = 0.0;
    ccd.check_intersections = options.check_intersections;
    return ccd;
}

const AugmentedLagrangianOptions& checked(const AugmentedLagrangianOptions& options)
{
    require_positive(options.gap, "augmented Lagrangian: gap delta [m]");
    require_positive(options.penalty_scale, "augmented Lagrangian: penalty_scale");
    require_positive(options.violation_tolerance, "augmented Lagrangian: violation_tolerance");
    require_positive(options.dual_tolerance, "augmented Lagrangian: dual_tolerance");
    if (!std::isfinite(options.penalty_growth) || options.penalty_growth < 1.0)
        throw Error(str("augmented Lagrangian: penalty_growth must be a finite number >= 1, got ", options.penalty_growth));
    if (!std::isfinite(options.filter_gap) || options.filter_gap < 0.0)
        throw Error(str("augmented Lagrangian: filter_gap must be a finite number >= 0, got ", options.filter_gap));
    if (options.stale_steps < 1)
        throw Error(str("augmented Lagrangian: stale_steps must be >= 1, got ", options.stale_steps));
    if (options.max_outer_iterations < 1)
        throw Error(str("augmented Lagrangian: max_outer_iterations must be >= 1, got ", options.max_outer_iterations));
    if (!(options.safety > 0.0 && options.safety < 1.0))
        throw Error(str("augmented Lagrangian: safety must lie in (0, 1), got ", options.safety));
    require_positive(options.friction_velocity, "augmented Lagrangian: friction_velocity eps_v [m/s]");
    return options;
}

/// d = √(d²) with ∇d = ∇d²/(2d), ∇²d = ∇²d²/(2d) − ∇d² ∇d²ᵀ/(4d³).
PrimitiveFunction distance_from_squared(const PrimitiveFunction& squared, bool derivatives)
{
    PrimitiveFunction d;
    d.value = std::sqrt(std::max(squared.value, 0.0));
    if (derivatives && d.value > 0.0) {
        d.gradient = squared.gradient / (2.0 * d.value);
        d.hessian = squared.hessian / (2.0 * d.value) -
                    squared.gradient * squared.gradient.transpose() / (4.0 * d.value * d.value * d.value);
    }
    return d;
}

std::array<int, 5> key(const ContactConstraint& c)
{
    if (c.kind == ConstraintKind::vertex_obstacle)
        return {0, c.vertices[0], c.obstacle, 0, 0};
    return {c.kind == ConstraintKind::point_triangle ? 1 : 2, c.vertices[0], c.vertices[1], c.vertices[2], c.vertices[3]};
}

}  // namespace

std::string describe(const ContactConstraint& c)
{
    const auto point = [](int index) {
        return index >= 0 ? str("vertex ", index) : str("obstacle corner ", -1 - index);
    };
    switch (c.kind) {
    case ConstraintKind::vertex_obstacle:
        return str("vertex ", c.vertices[0], " against obstacle ", c.obstacle);
    case ConstraintKind::point_triangle:
        return str(point(c.vertices[0]), " against the triangle of vertices ", c.vertices[1], ", ", c.vertices[2], ", ",
                   c.vertices[3]);
    case ConstraintKind::edge_edge:
        break;
    }
    return str("the edge of vertices ", c.vertices[0], ", ", c.vertices[1], " against the edge of ", point(c.vertices[2]),
               ", ", point(c.vertices[3]));
}

struct AugmentedLagrangianContact::PairGeometry {
    int count = 1;  // 1 (a vertex against an obstacle) or 4 vertices
    int vertices[4] = {0, 0, 0, 0};
    double gap = 0.0;
    Vector12d gradient = Vector12d::Zero();
    Matrix12d hessian = Matrix12d::Zero();
};

AugmentedLagrangianContact::AugmentedLagrangianContact(const dynamics::Body& body,
                                                       std::vector<std::shared_ptr<const Obstacle>> obstacles,
                                                       AugmentedLagrangianOptions options)
    : obstacles_(obstacles), options_(checked(options)),
      ccd_(body_contact_potential(body, std::move(obstacles), collision_options(options_))),
      rest_(body.mesh().V), surface_(surface_primitives(body.mesh())), vertex_body_(options_.vertex_body)
{
    if (vertex_body_.empty())
        vertex_body_.assign(static_cast<std::size_t>(rest_.rows()), 0);
    for (std::size_t o = 0; o < obstacles_.size(); ++o) {
        const ObstacleFeatures features = obstacles_[o]->local_features();
        const int first = static_cast<int>(corners_.size());
        for (Eigen::Index k = 0; k < features.corners.rows(); ++k)
            corners_.push_back({static_cast<int>(o), features.corners.row(k).transpose()});
        for (Eigen::Index e = 0; e < features.edges.rows(); ++e)
            obstacle_edges_.push_back({first + features.edges(e, 0), first + features.edges(e, 1)});
    }
}

LaggedFriction AugmentedLagrangianContact::friction_of(const FrictionPair& pair, const Eigen::VectorXd& u) const
{
    const Eigen::Vector3d x = rest_.row(pair.vertex).transpose() + u.segment<3>(3 * pair.vertex);
    return lagged_friction(pair.tangent, x - pair.start, pair.coefficient * pair.normal_force,
                           options_.friction_velocity * time_step_);
}

Eigen::Vector3d AugmentedLagrangianContact::corner(int index) const
{
    const ObstacleCorner& c = corners_[static_cast<std::size_t>(-1 - index)];
    return c.rest + time_ * obstacles_[static_cast<std::size_t>(c.obstacle)]->velocity();
}

double AugmentedLagrangianContact::constraint_gap(const ContactConstraint& constraint, const Eigen::VectorXd& u) const
{
    return geometry(constraint, u, false).gap;
}

AugmentedLagrangianContact::PairGeometry AugmentedLagrangianContact::geometry(const ContactConstraint& c,
                                                                              const Eigen::VectorXd& u,
                                                                              bool derivatives) const
{
    PairGeometry pair;
    const auto x = [&](int vertex) -> Eigen::Vector3d {
        return rest_.row(vertex).transpose() + u.segment<3>(3 * vertex);
    };
    if (c.kind == ConstraintKind::vertex_obstacle) {
        const Obstacle& obstacle = *obstacles_[static_cast<std::size_t>(c.obstacle)];
        const Eigen::Vector3d p = x(c.vertices[0]);
        pair.vertices[0] = c.vertices[0];
        const double d = obstacle.distance(p, time_);
        pair.gap = d > 0.0 ? d - options_.gap : -infinity;
        if (derivatives && d > 0.0) {
            pair.gradient.head<3>() = obstacle.gradient(p, time_);
            pair.hessian.topLeftCorner<3, 3>() = obstacle.hessian(p, time_);
        }
        return pair;
    }
    pair.count = 4;
    std::copy(c.vertices, c.vertices + 4, pair.vertices);
    const auto point = [&](int index) -> Eigen::Vector3d { return index >= 0 ? x(index) : corner(index); };
    const Eigen::Vector3d x0 = point(c.vertices[0]), x1 = point(c.vertices[1]), x2 = point(c.vertices[2]),
                          x3 = point(c.vertices[3]);
    const PrimitiveFunction squared =
        c.kind == ConstraintKind::point_triangle
            ? point_triangle_squared_distance(x0, x1, x2, x3, point_triangle_type(x0, x1, x2, x3))
            : edge_edge_squared_distance(x0, x1, x2, x3, edge_edge_type(x0, x1, x2, x3));
    const PrimitiveFunction d = distance_from_squared(squared, derivatives);
    pair.gap = d.value > 0.0 ? d.value - options_.gap : -infinity;
    pair.gradient = d.gradient;
    pair.hessian = d.hessian;
    return pair;
}

void AugmentedLagrangianContact::begin_step(dynamics::Body& body, const dynamics::State& state, double time_step)
{
    if (!first_solve_) {  // a re-solve of the same step with new multipliers
        resolving_ = true;
        return;
    }
    first_solve_ = false;
    resolving_ = false;
    ccd_.begin_step(body, state, time_step);
    time_ = state.time + time_step;
    // Decay: a pair idle for stale_steps steps in a row leaves.
    std::erase_if(constraints_, [&](const ContactConstraint& c) { return c.idle_steps >= options_.stale_steps; });
    // The pairs the predicted motion's CCD finds (xᵗ → xᵗ + Δt vᵗ + Δt² g), or within 2δ, join at once.
    Eigen::VectorXd motion = time_step * state.v;
    for (Eigen::Index i = 0; i < motion.size(); i += 3)
        motion.segment<3>(i) += time_step * time_step * body.scene().gravity;
    add_pairs(state.u, motion, 2.0 * options_.gap, -infinity);
    // μ: at least penalty_scale × a vertex's mass block, and stiff enough that the penalty's energy at
    // a violation of δ/2, (μ/2)(δ/2)², holds the kinetic energy T of the active pairs' vertices at the
    // step's start: an impact is then stopped within δ of contact in the first solve, before the CCD
    // would have to (TOI locking).
    const Eigen::VectorXd& masses = body.dof_masses();
    std::vector<bool> in_pair(static_cast<std::size_t>(rest_.rows()), false);
    for (const ContactConstraint& c : constraints_)
        for (int i = 0; i < (c.kind == ConstraintKind::vertex_obstacle ? 1 : 4); ++i)
            if (c.vertices[i] >= 0)
                in_pair[static_cast<std::size_t>(c.vertices[i])] = true;
    double kinetic = 0.0;
    for (Eigen::Index v = 0; v < rest_.rows(); ++v)
        if (in_pair[static_cast<std::size_t>(v)])
            kinetic += 0.5 * masses[3 * v] * state.v.segment<3>(3 * v).squaredNorm();
    penalty_ = options_.penalty_scale * masses.mean() / (time_step * time_step);
    if (options_.kinetic_penalty)
        penalty_ = std::max(penalty_, 8.0 * kinetic / (options_.gap * options_.gap));
    last_violation_ = infinity;
    time_step_ = time_step;
    step_start_ = state.u;
    lag_friction(state.u, state.u);  // the multipliers the last step left: its contact forces
    if (!options_.warm_multipliers)  // the alternative: the solve starts from no force (friction keeps its lag)
        for (ContactConstraint& c : constraints_)
            c.multiplier = 0.0;
}

void AugmentedLagrangianContact::lag_friction(const Eigen::VectorXd& u, const Eigen::VectorXd& start)
{
    friction_.clear();
    for (const ContactConstraint& c : constraints_) {
        if (c.kind != ConstraintKind::vertex_obstacle || c.multiplier == 0.0)
            continue;
        const Obstacle& obstacle = *obstacles_[static_cast<std::size_t>(c.obstacle)];
        if (obstacle.friction() == 0.0)
            continue;
        const int v = c.vertices[0];
        FrictionPair pair;
        pair.vertex = v;
        pair.obstacle = c.obstacle;
        pair.normal_force = c.multiplier;
        pair.coefficient = obstacle.friction();
        pair.tangent = tangent_basis(obstacle.gradient(rest_.row(v).transpose() + u.segment<3>(3 * v), time_));
        pair.start = rest_.row(v).transpose() + start.segment<3>(3 * v) + time_step_ * obstacle.velocity();
        friction_.push_back(pair);
    }
}

double AugmentedLagrangianContact::relag_friction(const Eigen::VectorXd& u)
{
    if (!options_.converged_friction)
        return 0.0;
    const std::vector<FrictionPair> before = friction_;
    lag_friction(u, step_start_);
    double largest = 0.0, change = 0.0;
    for (const FrictionPair& pair : friction_)
        largest = std::max(largest, pair.normal_force);
    for (const FrictionPair& pair : friction_) {
        double old = 0.0;
        for (const FrictionPair& b : before)
            if (b.vertex == pair.vertex && b.obstacle == pair.obstacle)
                old = b.normal_force;
        change = std::max(change, std::abs(pair.normal_force - old));
    }
    for (const FrictionPair& b : before) {  // a pair that left
        bool kept = false;
        for (const FrictionPair& pair : friction_)
            kept = kept || (b.vertex == pair.vertex && b.obstacle == pair.obstacle);
        if (!kept)
            change = std::max(change, b.normal_force);
    }
    return largest > 0.0 ? change / largest : change;
}

int AugmentedLagrangianContact::add_pairs(const Eigen::VectorXd& u, const Eigen::VectorXd& du, double reach,
                                          double min_gap) const
{
    std::set<std::array<int, 5>> present;
    for (const ContactConstraint& c : constraints_)
        present.insert(key(c));
    int added = 0;
    const auto offer = [&](const ContactConstraint& c) {
        if (present.count(key(c)) > 0)
            return;
        if (constraint_gap(c, u) < min_gap)
            return;
        present.insert(key(c));
        constraints_.push_back(c);
        ++added;
    };
    const auto x = [&](const Eigen::VectorXd& displacement, int vertex) -> Eigen::Vector3d {
        return rest_.row(vertex).transpose() + displacement.segment<3>(3 * vertex);
    };
    for (std::size_t o = 0; o < obstacles_.size(); ++o)
        for (int v : surface_.vertices) {
            const Eigen::Vector3d p = x(u, v), dp = du.segment<3>(3 * v);
            const Obstacle& obstacle = *obstacles_[o];
            if (obstacle.distance(p, time_) < options_.gap + reach || obstacle.time_of_impact(p, dp, time_) <= 1.0) {
                ContactConstraint c;
                c.vertices[0] = v;
                c.obstacle = static_cast<int>(o);
                offer(c);
            }
        }
    if (!options_.self_contact && corners_.empty())
        return added;
    MatrixX3d start = rest_, end = rest_;
    for (Eigen::Index v = 0; v < rest_.rows(); ++v) {
        start.row(v) = x(u, static_cast<int>(v)).transpose();
        end.row(v) = start.row(v) + du.segment<3>(3 * v).transpose();
    }
    const auto point_at = [&](const MatrixX3d& at, int index) -> Eigen::Vector3d {
        return index >= 0 ? Eigen::Vector3d(at.row(index).transpose()) : corner(index);
    };
    const auto kept = [&](const int* vertices) {  // shares no vertex; two bodies, or one that holds itself off
        if (*std::min_element(vertices, vertices + 4) < 0)
            return true;  // against an obstacle's corner or edge
        for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j)
                if (vertices[i] == vertices[j])
                    return false;
        const int body = vertex_body_[static_cast<std::size_t>(vertices[0])];
        for (int i = 1; i < 4; ++i)
            if (vertex_body_[static_cast<std::size_t>(vertices[i])] != body)
                return true;
        return options_.body_self_contact.empty() || options_.body_self_contact[static_cast<std::size_t>(body)];
    };
    const auto consider = [&](ContactConstraint c) {
        if (!kept(c.vertices) || present.count(key(c)) > 0)
            return;
        if (!(geometry(c, u, false).gap < reach)) {
            PrimitiveMotion motion;
            for (int i = 0; i < 4; ++i) {
                motion.start.col(i) = point_at(start, c.vertices[i]);
                motion.end.col(i) = point_at(end, c.vertices[i]);
            }
            const PrimitivePair kind =
                c.kind == ConstraintKind::point_triangle ? PrimitivePair::point_triangle : PrimitivePair::edge_edge;
            if (!inclusion_ccd(kind, motion).collides)
                return;
        }
        offer(c);
    };
    // The obstacles' corners against the body's triangles, their edges against its edges: every
    // pair whose boxes (the body's swept over the motion, the obstacle's held at the step's end) meet.
    if (!corners_.empty()) {
        const double grow = options_.gap + reach;
        const auto box = [&](std::initializer_list<int> indices, Eigen::Vector3d& low, Eigen::Vector3d& high) {
            low.setConstant(infinity), high.setConstant(-infinity);
            for (int index : indices) {
                low = low.cwiseMin(point_at(start, index)).cwiseMin(point_at(end, index));
                high = high.cwiseMax(point_at(start, index)).cwiseMax(point_at(end, index));
            }
            low.array() -= grow, high.array() += grow;
        };
        const auto meet = [&](std::initializer_list<int> a, std::initializer_list<int> b) {
            Eigen::Vector3d low_a, high_a, low_b, high_b;
            box(a, low_a, high_a), box(b, low_b, high_b);
            return (low_a.array() <= high_b.array()).all() && (low_b.array() <= high_a.array()).all();
        };
        for (std::size_t k = 0; k < corners_.size(); ++k)
            for (Eigen::Index t = 0; t < surface_.triangles.rows(); ++t) {
                ContactConstraint c;
                c.kind = ConstraintKind::point_triangle;
                c.vertices[0] = -1 - static_cast<int>(k);
                for (int i = 0; i < 3; ++i)
                    c.vertices[1 + i] = surface_.triangles(t, i);
                if (meet({c.vertices[0]}, {c.vertices[1], c.vertices[2], c.vertices[3]}))
                    consider(c);
            }
        for (const auto& [k0, k1] : obstacle_edges_)
            for (Eigen::Index e = 0; e < surface_.edges.rows(); ++e) {
                ContactConstraint c;
                c.kind = ConstraintKind::edge_edge;
                c.vertices[0] = surface_.edges(e, 0), c.vertices[1] = surface_.edges(e, 1);
                c.vertices[2] = -1 - k0, c.vertices[3] = -1 - k1;
                if (meet({c.vertices[0], c.vertices[1]}, {c.vertices[2], c.vertices[3]}))
                    consider(c);
            }
    }
    if (!options_.self_contact)
        return added;
    const CandidatePairs candidates = tree_candidates(surface_, start, end, options_.gap + reach);
    for (const auto& [vertex, triangle] : candidates.point_triangle) {
        ContactConstraint c;
        c.kind = ConstraintKind::point_triangle;
        c.vertices[0] = vertex;
        for (int i = 0; i < 3; ++i)
            c.vertices[1 + i] = surface_.triangles(triangle, i);
        consider(c);
    }
    for (const auto& [a, b] : candidates.edge_edge) {
        ContactConstraint c;
        c.kind = ConstraintKind::edge_edge;
        c.vertices[0] = surface_.edges(a, 0), c.vertices[1] = surface_.edges(a, 1);
        c.vertices[2] = surface_.edges(b, 0), c.vertices[3] = surface_.edges(b, 1);
        consider(c);
    }
    return added;
}

double AugmentedLagrangianContact::energy(const Eigen::VectorXd& u) const
{
    if (options_.check_intersections)
        (void)ccd_.energy(u);  // the referee (chapter 15's IntersectionTerm) throws at an intersection
    double total = 0.0;
    for (const ContactConstraint& c : constraints_) {
        const double gap = constraint_gap(c, u);
        if (gap == -infinity)
            return infinity;
        total += augmented_term(gap, c.multiplier, penalty_).value;
    }
    for (const FrictionPair& pair : friction_)
        total += friction_of(pair, u).value;
    return total;
}

Eigen::VectorXd AugmentedLagrangianContact::gradient(const Eigen::VectorXd& u) const
{
    Eigen::VectorXd gradient = Eigen::VectorXd::Zero(u.size());
    for (const ContactConstraint& c : constraints_) {
        const PairGeometry pair = geometry(c, u, true);
        const AugmentedTerm term = augmented_term(pair.gap, c.multiplier, penalty_);
        if (term.slope == 0.0)
            continue;
        for (int i = 0; i < pair.count; ++i)
            if (pair.vertices[i] >= 0)
                gradient.segment<3>(3 * pair.vertices[i]) += term.slope * pair.gradient.segment<3>(3 * i);
    }
    for (const FrictionPair& pair : friction_)
        gradient.segment<3>(3 * pair.vertex) += friction_of(pair, u).gradient;
    return gradient;
}

dynamics::SparseMatrix AugmentedLagrangianContact::hessian(const Eigen::VectorXd& u) const
{
    std::vector<Eigen::Triplet<double>> triplets;
    for (const ContactConstraint& c : constraints_) {
        const PairGeometry pair = geometry(c, u, true);
        const AugmentedTerm term = augmented_term(pair.gap, c.multiplier, penalty_);
        // A pair that exerts nothing still gives its blocks, as zeros: the matrix's pattern then
        // changes only with the active set, not each time a pair crosses ψ's kink (a new pattern
        // is a new fill-reducing ordering in chapter 09's direct solver).
        Matrix12d block = term.curvature * pair.gradient * pair.gradient.transpose() + term.slope * pair.hessian;
        if (term.slope == 0.0 && term.curvature == 0.0)
            block.setZero();
        else if (pair.count == 1)
            block.topLeftCorner<3, 3>() = hyper::project_to_psd<3>(Eigen::Matrix3d(block.topLeftCorner<3, 3>()),
                                                                   hyper::Projection::clamp);
        else
            block = hyper::project_to_psd<12>(block, hyper::Projection::clamp);
        for (int i = 0; i < pair.count; ++i)
            for (int j = 0; j < pair.count; ++j)
                for (int r = 0; r < 3 && pair.vertices[i] >= 0 && pair.vertices[j] >= 0; ++r)
                    for (int s = 0; s < 3; ++s)
                        triplets.emplace_back(3 * pair.vertices[i] + r, 3 * pair.vertices[j] + s,
                                              block(3 * i + r, 3 * j + s));
    }
    for (const FrictionPair& pair : friction_) {
        const Eigen::Matrix3d block = friction_of(pair, u).hessian;
        for (int r = 0; r < 3; ++r)
            for (int q = 0; q < 3; ++q)
                triplets.emplace_back(3 * pair.vertex + r, 3 * pair.vertex + q, block(r, q));
    }
    dynamics::SparseMatrix H(u.size(), u.size());
    H.setFromTriplets(triplets.begin(), triplets.end());
    return H;
}

double AugmentedLagrangianContact::largest_safe_step(const Eigen::VectorXd& u, const Eigen::VectorXd& du) const
{
    if (skip_start_move_) {  // a re-solve starts where the last solve ended, not moved toward q̇ᵗ
        skip_start_move_ = false;
        return 0.0;
    }
    const double safe = ccd_.largest_safe_step(u, du);
    last_cut_ = safe < 1.0;
    if (last_cut_)  // TOI locking's cure: the pairs that cut the step join now (g ≥ 0 at u: E(u) unchanged)
        add_pairs(u, du, options_.gap, 0.0);
    return safe;
}

Eigen::VectorXd AugmentedLagrangianContact::start_velocity(const dynamics::Body& body, const dynamics::State& state,
                                                           double time_step) const
{
    if (!resolving_)
        return ccd_.start_velocity(body, state, time_step);
    skip_start_move_ = true;
    return warm_v_;
}

OuterResiduals AugmentedLagrangianContact::update_multipliers(const Eigen::VectorXd& u, const Eigen::VectorXd& v)
{
    OuterResiduals residuals;
    residuals.impact_complete = !last_cut_;
    add_pairs(u, Eigen::VectorXd::Zero(u.size()), 2.0 * options_.gap, -infinity);
    std::vector<ContactConstraint> kept;
    kept.reserve(constraints_.size());
    for (ContactConstraint c : constraints_) {
        const double gap = constraint_gap(c, u);
        if (-gap > residuals.violation)
            residuals.worst_pair = describe(c);
        residuals.violation = std::max(residuals.violation, -gap);
        c.multiplier = augmented_multiplier(gap, c.multiplier, penalty_);
        residuals.complementarity =
            std::max(residuals.complementarity, std::min(c.multiplier / penalty_, std::max(gap, 0.0)));
        if (keeps_constraint(gap, c.multiplier, options_.gap, options_.filter_gap))
            kept.push_back(c);
    }
    constraints_ = std::move(kept);
    if (residuals.violation > options_.violation_tolerance * options_.gap && residuals.violation > 0.25 * last_violation_)
        penalty_ *= options_.penalty_growth;
    last_violation_ = residuals.violation;
    warm_v_ = v;
    return residuals;
}

void AugmentedLagrangianContact::end_step()
{
    for (ContactConstraint& c : constraints_)
        c.idle_steps = c.multiplier > 0.0 ? 0 : c.idle_steps + 1;
}

Eigen::VectorXd AugmentedLagrangianContact::contact_forces(const Eigen::VectorXd& u,
                                                           const std::function<bool(const ContactConstraint&)>& which) const
{
    Eigen::VectorXd forces = Eigen::VectorXd::Zero(u.size());
    for (const ContactConstraint& c : constraints_) {
        if (c.multiplier == 0.0 || (which && !which(c)))
            continue;
        const PairGeometry pair = geometry(c, u, true);
        for (int i = 0; i < pair.count; ++i)
            if (pair.vertices[i] >= 0)
                forces.segment<3>(3 * pair.vertices[i]) += c.multiplier * pair.gradient.segment<3>(3 * i);
    }
    return forces;
}

dynamics::StepInfo augmented_lagrangian_step(hyper::NewtonBackwardEuler& newton, AugmentedLagrangianContact& al,
                                             dynamics::Body& body, double time_step, dynamics::State& state,
                                             AugmentedLagrangianReport* report)
{
    AugmentedLagrangianReport local;
    AugmentedLagrangianReport& r = report != nullptr ? *report : local;
    r = {};
    al.prepare_step();
    dynamics::StepInfo total;
    const AugmentedLagrangianOptions& options = al.options();
    for (int outer = 1; outer <= options.max_outer_iterations; ++outer) {
        dynamics::State solution = state;
        const dynamics::StepInfo info = newton.step(body, time_step, solution);
        total.newton_iterations += info.newton_iterations;
        total.solver_iterations += info.solver_iterations;
        total.damping_work = info.damping_work;
        total.boundary_work = info.boundary_work;
        total.prepared = total.prepared || info.prepared;
        r.inner_iterations.push_back(info.newton_iterations);
        r.outer_iterations = outer;
        r.newton_iterations = total.newton_iterations;
        r.residuals = al.update_multipliers(solution.u, solution.v);
        r.active_pairs = static_cast<int>(al.constraints().size());
        const bool friction_settled = al.relag_friction(solution.u) <= 1e-6;
        if (outer_converged(r.residuals, options.gap, options.violation_tolerance, options.dual_tolerance) &&
            friction_settled) {
            al.end_step();
            // The contact forces' work, as backward Euler takes it: the forces at the step's end
            // (Σ λ⁺ ∇g, λ⁺ what each pair exerted there) along the step's displacement.
            total.boundary_work += al.contact_forces(solution.u).dot(solution.u - state.u);
            state = std::move(solution);
            return total;
        }
    }
    throw Error(str("augmented Lagrangian: step ", state.step + 1, " (t = ", state.time + time_step, " s) did not converge in ",
                    options.max_outer_iterations, " outer iterations: largest violation ", r.residuals.violation,
                    " m, complementarity ", r.residuals.complementarity, " m (tolerances ",
                    options.violation_tolerance * options.gap, ", ", options.dual_tolerance * options.gap, " m), ",
                    r.residuals.impact_complete ? "the step complete" : "the last Newton step still cut by the time of impact",
                    ", ", r.active_pairs, " active pairs",
                    r.residuals.worst_pair.empty() ? std::string() : ", the worst: " + r.residuals.worst_pair));
}

}  // namespace fem::contact
