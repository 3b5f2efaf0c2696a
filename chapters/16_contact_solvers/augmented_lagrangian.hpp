#pragma once
// Chapter 16: contact without a barrier — an augmented Lagrangian (Powell–Hestenes–Rockafellar) on
// the constraints g_k(x) = d_k(x) − δ ≥ 0 of the contact pairs, after Zheng, Luo and Li, "Robust
// and Efficient Penetration-Free Elastodynamics without Barriers" (TOG 2026), derived here from the
// issue's description and standard augmented-Lagrangian theory (their code is not public).
// Read chapter 14 (IPC's barrier, the CCD-bounded line search) and 15 (distances, CCD, broad phase)
// first. docs/16_contact_solvers.md
//
// One backward Euler step minimises chapter 12's E(v) subject to g_k(qᵗ + Δt v) ≥ 0. The outer loop
// (augmented_lagrangian_step) holds multipliers λ_k ≥ 0 and a penalty μ > 0 and solves, by chapter
// 12's Newton with the continuous collision check of chapters 14/15 cutting every line search (so no
// iterate crosses), the inner problem
//
//   min_v  E(v) + Σ_k ψ(g_k(qᵗ + Δt v), λ_k, μ),   ψ(g, λ, μ) = (μ/2) max(0, λ/μ − g)² − λ²/(2μ),
//
// then updates λ_k ← max(0, λ_k − μ g_k) (augmented_multiplier). ψ is C¹ in g, convex, and its
// slope −max(0, λ − μg) is the pair's contact force along ∇g: at a fixed point of the update
// either λ = 0 and g ≥ 0 or g = 0 and λ > 0 — the KKT conditions of the constrained step.
// The pairs k (the active set): a surface vertex against an obstacle, an obstacle's corner against
// a surface triangle and its edge against a surface edge, and, with self-contact, the point–triangle
// and edge–edge pairs of the body's surface (chapter 15's distances) — those the step's CCD finds
// along the step's predicted motion xᵗ → xᵗ + Δt vᵗ + Δt² g at its start (added at once, λ = 0),
// along each Newton direction the CCD cuts, and within 2δ of each inner solution; a filter drops a
// pair with λ = 0 and g above filter_gap · δ, and a pair idle (λ = 0) for stale_steps steps in a row
// decays away. docs/16_contact_solvers.md#the-active-set

#include "15_body_contact/body_contact.hpp"

#include "14_contact/contact.hpp"
#include "14_contact/friction.hpp"
#include "14_contact/obstacles.hpp"
#include "14_contact/surface.hpp"

#include "12_hyperelastic_newton/newton.hpp"

#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include <Eigen/Core>
#include <Eigen/Sparse>

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace fem::contact {

/// ψ(g, λ, μ) of the header and its first and second derivatives in g.
struct AugmentedTerm {
    double value = 0.0;      ///< ψ [J]
    double slope = 0.0;      ///< ∂ψ/∂g = −max(0, λ − μ g) [N]: minus the pair's contact force
    double curvature = 0.0;  ///< ∂²ψ/∂g² = μ where λ − μ g > 0, else 0 [N/m]
};

/// ψ(g, λ, μ) = (μ/2) max(0, λ/μ − g)² − λ²/(2μ) with its derivatives in g (AugmentedTerm): the
/// Powell–Hestenes–Rockafellar term of an inequality g ≥ 0 with multiplier λ ≥ 0 and penalty μ > 0.
/// fem::Error for μ ≤ 0 or λ < 0 (or either not finite). docs/16_contact_solvers.md#the-augmented-lagrangian
AugmentedTerm augmented_term(double gap, double multiplier, double penalty);

/// The multiplier update of g ≥ 0: λ⁺ = max(0, λ − μ g) [N] (the force the term exerted at g).
/// fem::Error as augmented_term. docs/16_contact_solvers.md#the-multiplier-update
double augmented_multiplier(double gap, double multiplier, double penalty);

/// Which primitives a constraint holds.
enum class ConstraintKind {
    vertex_obstacle,  ///< vertices[0] a surface vertex, obstacle its obstacle: d = d_o(x_v)
    point_triangle,   ///< p, a, b, c: the body's surface, p possibly an obstacle's corner (chapter 15's distances)
    edge_edge,        ///< ea0, ea1, eb0, eb1: the body's surface edges, eb possibly an obstacle's edge
};

/// One pair of the active set with its multiplier.
struct ContactConstraint {
    ConstraintKind kind = ConstraintKind::vertex_obstacle;
    /// Mesh vertices (only [0] for vertex_obstacle); an entry −1 − k < 0 is the obstacles' corner k
    /// (an obstacle's corner against a body triangle: p; its edge against a body edge: eb0, eb1).
    int vertices[4] = {0, 0, 0, 0};
    int obstacle = -1;               ///< the obstacle's index (vertex_obstacle), else −1
    double multiplier = 0.0;         ///< λ ≥ 0 [N]
    int idle_steps = 0;              ///< the steps in a row it ended with λ = 0
};

/// The pair for messages, e.g. "vertex 12 against obstacle 0", "the edge (3, 4) against the edge (9, 11)".
std::string describe(const ContactConstraint& constraint);

/// Every constant of the augmented Lagrangian solver, named once
/// (docs/16_contact_solvers.md#the-constants).
struct AugmentedLagrangianOptions {
    double gap = 1e-3;            ///< δ [m]: the constraint d ≥ δ (IPC's d̂, so that both keep bodies as far apart)
    /// μ's scale: at a step's start μ = max(penalty_scale × m̄ / Δt², 8 T / δ²) (m̄ the mean vertex
    /// mass, T = Σ ½ m_v |v_vᵗ|² over the vertices of the active pairs once the predicted motion's
    /// pairs have joined): the penalty's Hessian Δt² μ ∇g∇gᵀ at least penalty_scale × a vertex's
    /// mass block, and its energy at a violation of δ/2, (μ/2)(δ/2)², at least T, so that an impact
    /// is held within δ by the first solve.
    double penalty_scale = 100.0;
    /// Whether μ takes the kinetic bound 8 T / δ² (else penalty_scale's alone: the alternative the
    /// study measures, docs/16_contact_solvers.md#the-penalty).
    bool kinetic_penalty = true;
    /// μ ← penalty_growth × μ after an outer iteration whose largest violation did not fall below
    /// a quarter of the last one's (standard AL practice), ≥ 1.
    double penalty_growth = 10.0;
    double violation_tolerance = 1e-2;  ///< stop when max_k max(0, −g_k) ≤ this × δ
    double dual_tolerance = 1e-2;       ///< … and max_k min(λ_k/μ, max(g_k, 0)) ≤ this × δ
    double filter_gap = 1.0;            ///< drop a pair with λ = 0 and g > this × δ (ActiveSetFilter)
    /// Whether a step starts from the multipliers the last step left (its contact forces: a warm
    /// start), else from λ = 0 on every pair (the alternative the study measures,
    /// docs/16_contact_solvers.md#the-choices).
    bool warm_multipliers = true;
    int stale_steps = 2;                ///< drop a pair ending this many steps in a row with λ = 0, ≥ 1
    int max_outer_iterations = 30;      ///< outer iterations per step before fem::Error
    double safety = 0.9;                ///< the line search starts at safety × the time of impact, in (0, 1)
    bool self_contact = false;          ///< the body's surface pairs too (bodies against bodies)
    std::vector<int> vertex_body;       ///< as BodyContactOptions: the body of each vertex (empty: one)
    std::vector<bool> body_self_contact;  ///< as BodyContactOptions
    bool check_intersections = false;   ///< chapter 15's referee at every configuration E is asked of
    /// ε_v [m/s]: chapter 14's friction smoothing (ε = ε_v Δt), for the obstacles with μ > 0.
    double friction_velocity = 1e-3;
    /// Friction on the vertex–obstacle pairs (chapter 14's lagged_friction with normal force λ_k):
    /// false, lagged — λ_k and the tangent basis from the step's start (IPC's lag); true, converged —
    /// both updated after every outer iteration, and the step ends only when no pair's normal force
    /// changed by more than 10⁻⁶ of the largest. docs/16_contact_solvers.md#friction
    bool converged_friction = false;
};

/// The filter of the active set: a pair stays when λ > 0 or g ≤ filter_gap · δ (a pair that pushes,
/// or one close enough to push in the next solve). docs/16_contact_solvers.md#the-active-set
bool keeps_constraint(double gap, double multiplier, double separation, double filter_gap);

/// What one outer iteration measured, for the stopping rule.
struct OuterResiduals {
    double violation = 0.0;      ///< max_k max(0, −g_k) [m] (before the update)
    double complementarity = 0.0;  ///< max_k min(λ_k⁺/μ, max(g_k, 0)) [m] (λ⁺ after the update)
    /// Whether the last inner solve's last Newton direction was not cut by the time of impact: the
    /// cumulative time of impact reached the end of the step (its locking is over).
    bool impact_complete = true;
    std::string worst_pair;  ///< the pair of the largest violation (describe), empty when none is violated
};

/// The stopping rule: violation ≤ violation_tolerance · δ, complementarity ≤ dual_tolerance · δ and
/// the step complete. docs/16_contact_solvers.md#the-stopping-rule
bool outer_converged(const OuterResiduals& residuals, double separation, double violation_tolerance,
                     double dual_tolerance);

/// The augmented Lagrangian of the header as a chapter 12 StepPotential: P(u) = Σ_k ψ(g_k(u), λ_k, μ)
/// over the active set plus chapter 14's lagged friction of its vertex–obstacle pairs with λ_k > 0
/// against obstacles with μ > 0 (normal force λ_k), its line search cut by the CCD of a chapter 15 ContactPotential of the same
/// body and obstacles (its barrier never used: only largest_safe_step, start_velocity,
/// smallest_distance). Driven by augmented_lagrangian_step.
class AugmentedLagrangianContact final : public hyper::StepPotential {
public:
    /// fem::Error for no obstacle without self_contact, δ ≤ 0, penalty_scale ≤ 0, penalty_growth < 1,
    /// a tolerance ≤ 0, filter_gap < 0, stale_steps < 1, max_outer_iterations < 1, safety outside
    /// (0, 1), ε_v ≤ 0, and what chapter 15's potential refuses.
    AugmentedLagrangianContact(const dynamics::Body& body, std::vector<std::shared_ptr<const Obstacle>> obstacles,
                               AugmentedLagrangianOptions options = {});

    /// The first solve of a step (prepare_step): the CCD's potential begins the step, stale pairs
    /// decay, the pairs the predicted motion's CCD finds join, μ (AugmentedLagrangianOptions::
    /// penalty_scale), and the friction pairs lagged from the multipliers the last step left.
    /// A re-solve of the same step: nothing.
    void begin_step(dynamics::Body& body, const dynamics::State& state, double time_step) override;
    /// Σ_k ψ(g_k(u), λ_k, μ) + the friction pairs' μ_o λ_k f₀ [J]; +∞ where some pair has d ≤ 0.
    double energy(const Eigen::VectorXd& u) const override;
    /// Σ_k ∂ψ/∂g ∇g_k + the friction pairs' gradients (3n) [N].
    Eigen::VectorXd gradient(const Eigen::VectorXd& u) const override;
    /// Σ_k [∂²ψ/∂g² ∇g ∇gᵀ + ∂ψ/∂g ∇²g] per pair block (3×3 or 12×12), each projected to PSD (clamp;
    /// zeros where the pair exerts nothing, so the pattern follows the active set), plus the friction
    /// pairs' PSD blocks.
    dynamics::SparseMatrix hessian(const Eigen::VectorXd& u) const override;
    /// The CCD potential's safe step (safety × the time of impact over every pair, the obstacles'
    /// edges too); when it cuts (< 1), the pairs whose CCD along u → u + du hits, at g ≥ 0 at u, join
    /// with λ = 0 (so E and ∇E at u do not change). On a re-solve's first call (the start's move
    /// toward q̇ᵗ): 0, so that the re-solve starts at the last solution.
    double largest_safe_step(const Eigen::VectorXd& u, const Eigen::VectorXd& du) const override;
    /// The first solve: the CCD potential's (v = 0 or carried by moving obstacles); a re-solve: the
    /// last solution's velocity (3n).
    Eigen::VectorXd start_velocity(const dynamics::Body& body, const dynamics::State& state,
                                   double time_step) const override;

    /// Marks the next begin_step as a step's first solve.
    void prepare_step() { first_solve_ = true; }
    /// After an inner solve ending at u (3n) with velocity v: the residuals before the update, then
    /// λ_k ← max(0, λ_k − μ g_k), the filter, pairs within 2δ of u joining, μ raised when the
    /// violation did not fall below a quarter of the last one's. Returns the residuals.
    OuterResiduals update_multipliers(const Eigen::VectorXd& u, const Eigen::VectorXd& v);
    /// Ends the step: idle counts of the pairs with λ = 0.
    void end_step();
    /// With converged_friction: the friction pairs' normal forces and bases from the multipliers and
    /// u (3n) after an update; returns the largest change of a normal force relative to the largest
    /// normal force (0 without friction or with lagged friction).
    double relag_friction(const Eigen::VectorXd& u);

    /// g_k(u) = d_k(u) − δ [m] of a pair.
    double constraint_gap(const ContactConstraint& constraint, const Eigen::VectorXd& u) const;
    /// The active set and its multipliers.
    const std::vector<ContactConstraint>& constraints() const { return constraints_; }
    /// The contact forces on the body at u with the multipliers the last update left (3n) [N]:
    /// Σ_k λ_k ∇g_k(u) (after an update at u, λ_k is the force max(0, λ − μ g) the pair exerted there).
    /// which (if set) picks the pairs summed.
    Eigen::VectorXd contact_forces(const Eigen::VectorXd& u,
                                   const std::function<bool(const ContactConstraint&)>& which = {}) const;
    /// The smallest distance of any pair within d̂ of the CCD potential (its vertices against the
    /// obstacles, its terms' pairs) [m]; +∞ when none is within δ.
    double smallest_distance(const Eigen::VectorXd& u) const { return ccd_.smallest_distance(u); }
    /// μ [N/m] of the current step.
    double penalty() const { return penalty_; }
    const AugmentedLagrangianOptions& options() const { return options_; }
    /// The chapter 15 potential whose CCD bounds the line search.
    const ContactPotential& collision_check() const { return ccd_; }

private:
    struct PairGeometry;  // g, ∇g, ∇²g of one pair, in its 1 or 4 vertices' coordinates
    PairGeometry geometry(const ContactConstraint& constraint, const Eigen::VectorXd& u, bool derivatives) const;
    /// Adds the pairs found along u → u + du (CCD) or within reach of u, not yet in the set and with
    /// g(u) ≥ min_gap, with λ = 0. Returns how many joined.
    int add_pairs(const Eigen::VectorXd& u, const Eigen::VectorXd& du, double reach, double min_gap) const;
    /// Sets friction_ from the vertex–obstacle pairs with λ > 0 against obstacles with μ > 0 at u
    /// (3n): normal force λ, basis ⟂ ∇d(x_v), sticking to start (3n) + Δt w_o.
    void lag_friction(const Eigen::VectorXd& u, const Eigen::VectorXd& start);
    /// A friction pair's lagged friction at u (3n).
    LaggedFriction friction_of(const FrictionPair& pair, const Eigen::VectorXd& u) const;
    /// The position of obstacle corner −1 − index at the step's end time (index < 0) [m].
    Eigen::Vector3d corner(int index) const;
    struct ObstacleCorner {
        int obstacle = 0;
        Eigen::Vector3d rest = Eigen::Vector3d::Zero();
    };

    std::vector<std::shared_ptr<const Obstacle>> obstacles_;
    AugmentedLagrangianOptions options_;
    ContactPotential ccd_;
    MatrixX3d rest_;
    SurfacePrimitives surface_;
    std::vector<int> vertex_body_;
    std::vector<ObstacleCorner> corners_;             // every obstacle's corners, in the obstacles' order
    std::vector<std::array<int, 2>> obstacle_edges_;  // their edges, in indices of corners_
    mutable std::vector<ContactConstraint> constraints_;
    std::vector<FrictionPair> friction_;  // the friction pairs of the step
    Eigen::VectorXd step_start_;          // uᵗ (3n)
    double time_ = 0.0, time_step_ = 0.0, penalty_ = 0.0, last_violation_ = 0.0;
    bool first_solve_ = true, resolving_ = false;
    mutable bool skip_start_move_ = false, last_cut_ = false;
    Eigen::VectorXd warm_v_;
};

/// What augmented_lagrangian_step did.
struct AugmentedLagrangianReport {
    int outer_iterations = 0, newton_iterations = 0;
    std::vector<int> inner_iterations;   ///< Newton iterations of each inner solve
    OuterResiduals residuals;            ///< the last outer iteration's
    int active_pairs = 0;                ///< the active set at the end
};

/// One backward Euler step with the augmented Lagrangian contact: inner solves (newton.step from
/// the step's start with al as potential, warm-started from the last solution) and multiplier
/// updates (then, with converged_friction, relag_friction) until outer_converged and no friction
/// normal force moved by more than 10⁻⁶ of the largest; StepInfo's Newton and solver iterations
/// summed over the solves, its boundary_work the last solve's (the pins') plus the contact forces'
/// work f_c(u⁺)·(u⁺ − uᵗ), f_c = Σ λ⁺ ∇g at the step's end (a body pushed out to δ is given that
/// energy; chapter 10's loop books it as work in, as contact_step books the barrier's).
/// fem::Error (the state left at the step's start) when max_outer_iterations pass, naming the pair
/// with the largest violation. newton must have al set as its potential.
/// docs/16_contact_solvers.md#the-algorithm
dynamics::StepInfo augmented_lagrangian_step(hyper::NewtonBackwardEuler& newton, AugmentedLagrangianContact& al,
                                             dynamics::Body& body, double time_step, dynamics::State& state,
                                             AugmentedLagrangianReport* report = nullptr);

}  // namespace fem::contact
