#pragma once
// Chapter 14: incremental potential contact (Li et al. 2020) against obstacles, as a chapter 12
// StepPotential: the barrier of every surface vertex against every obstacle, lagged smoothed Coulomb
// friction, the adaptive barrier stiffness κ, and the continuous collision check that cuts every
// Newton step before Armijo. docs/14_contact.md
//
// For a body with surface vertices x_v = X_v + u_v and obstacles o (at the step's end time t + Δt):
//
//   P(u) = Σ_v Σ_o Σ_p κ b(d_{o,p}(x_v))  +  Σ_k μ_k λ_k f₀(‖T_kᵀ (x_v − x_vᵗ − Δt w_o)‖)
//
// the barrier (b of barrier.hpp, active where d < d̂) over the pieces p of each obstacle within d̂
// (Obstacle::pieces: a half-space, sphere or box is one piece, a mesh one per triangle: IPC's one
// barrier per pair) and the friction of every pair k = (v, o) that was within d̂ at the step's start:
// λ_k = κ Σ_p |b'(d_{o,p}(x_vᵗ))| its lagged normal force [N], T_k (3×2)
// an orthonormal basis of the tangent plane ⟂ ∇d_o(x_vᵗ), w_o the obstacle's velocity (IPC: lagged friction).
// Added to it: the obstacles' edges and corners against the body's surface (feature_barrier.hpp) and,
// with ContactOptions::self_contact, the body's surface against itself — several bodies, one mesh of
// several components, against each other (self_barrier.hpp), with ContactOptions::body_friction > 0
// lagged friction on those pairs too (friction.hpp: Σ_k μ λ_k f₀(‖T_kᵀ Γ_k (x − xᵗ)‖) over the pairs within d̂ at the step's start).

#include "14_contact/feature_barrier.hpp"
#include "14_contact/friction.hpp"
#include "14_contact/intersections.hpp"
#include "14_contact/obstacles.hpp"
#include "14_contact/self_barrier.hpp"

#include "12_hyperelastic_newton/newton.hpp"

#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include <Eigen/Core>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace fem::contact {

/// The constants of contact, named once (docs/14_contact.md#the-constants).
struct ContactOptions {
    double activation_distance = 1e-3;  ///< d̂ [m]: the barrier acts where d < d̂
    /// κ [N/m]: > 0 fixed; 0 adaptive (the rule of ContactPotential::begin_step, after IPC's).
    double stiffness = 0.0;
    double safety = 0.8;                ///< the line search starts at safety × the time of impact, in (0, 1)
    double friction_velocity = 1e-3;    ///< ε_v [m/s]: slower tangential motion is sticking (f₁ < 1)
    /// ε_d as a fraction of the body's bounding-box diagonal: κ doubles when the smallest distance
    /// is below it and still falling (IPC's value: 10⁻⁹).
    double doubling_distance = 1e-9;
    /// Whether the body's surface primitives hold each other off too (SelfContactBarrier: bodies
    /// against bodies, a body against itself; friction between them: body_friction). Off: the body passes
    /// through itself, as every run before it did. docs/14_contact.md#bodies-against-bodies-and-self-contact
    bool self_contact = false;
    /// μ between the body's surface primitives (bodies against bodies, a body against itself), with
    /// self_contact: lagged friction on its point–triangle and edge–edge pairs (BodyFriction); 0: none.
    /// docs/14_contact.md#friction-between-bodies
    double body_friction = 0.0;
    /// With self_contact, several bodies in one mesh: the body of each vertex (#V entries; empty:
    /// one body) and per body whether its own surface holds itself off (empty: every body's does);
    /// two bodies always hold each other off (SelfContactBarrier).
    std::vector<int> vertex_body;
    std::vector<bool> body_self_contact;
    /// With self_contact, the reach of the Hessian's anticipated pattern as a multiple of d̂: at each
    /// begin_step the pattern takes the vertex blocks of every pair of surface primitives whose boxes,
    /// swept over the step's predicted motion (xᵗ to xᵗ + Δt vᵗ), come within pattern_reach × d̂
    /// (SelfContactBarrier::anticipate; zeros where no pair is within d̂), so pairs that arrive
    /// during the step's Newton iterations find their blocks there and the matrix keeps its pattern
    /// (one ordering and symbolic analysis a step instead of one per arrival). The values do not
    /// change. 0: only the pairs within d̂. docs/14_contact.md#bodies-against-bodies-the-cost
    double pattern_reach = 1.0;
    /// How each barrier block of the Hessian is made PSD (a vertex's block against the obstacles, an
    /// edge or corner pair's, a self-contact pair's 12×12): chapter 12's project_to_psd, clamp (negative
    /// eigenvalues to 0) or absolute (to |λ|). docs/14_contact.md#bodies-against-bodies-the-cost
    hyper::Projection barrier_projection = hyper::Projection::clamp;
    /// What ContactPotential::exact_hessian holds, the Hessian chapter 12's Newton tries first
    /// (HessianChoice::exact_then_definite: kept where M + Δt² (K + ∇²P) factors and gives descent, else
    /// the definite one): true, the barrier's blocks as they are (∇²P itself, so that Newton converges
    /// quadratically wherever the whole step's Hessian is definite); false, projected as in hessian.
    /// docs/14_contact.md#bodies-against-bodies-the-cost
    bool exact_barrier_hessian = false;
    /// A debug check: at every configuration the energy is asked of (each Newton iterate and each
    /// line-search trial), no body edge meets a triangle of an obstacle with edges (a box, a mesh), no
    /// such obstacle's edge a body triangle, and, with self_contact, no body edge a body triangle
    /// (IntersectionCheck, intersections.hpp); fem::Error naming them otherwise. It costs a box tree a
    /// call: for tests and for finding a bug, not for runs. docs/14_contact.md#never-an-intersection
    bool check_intersections = false;
};

/// Where a ContactPotential's time goes, for the tables of what contact costs (study 6 of ch14_contact,
/// the scenes runner's contact_steps.csv): wall time summed over whole calls (one steady_clock read
/// at each call's start and end, common/timer.hpp; no clock per pair, so they cost nothing to keep),
/// since the potential's construction or its last reset_clocks. The calls contact_step makes of the
/// potential itself (has_free_start, its stages' obstacle_advance, the barrier energies it books as
/// work) and out_of_contact, smallest_distance are in neither clock.
/// docs/14_contact.md#bodies-against-bodies-the-cost
struct ContactClocks {
    /// begin_step (κ, the lagged friction pairs, the anticipated pattern) and every energy, gradient
    /// and Hessian: the barrier with its broad phase (a tree, or the last motion's candidates) and
    /// the friction terms [s].
    double barrier_seconds = 0.0;
    /// largest_safe_step (the line search's continuous collision check, with its own broad phase over
    /// the swept boxes) and start_velocity (the start's check against the obstacles) [s].
    double collision_seconds = 0.0;
    /// The trees the self-contact barrier built, whichever call asked (SelfContactBarrier::broad_phases,
    /// its check at rest in the constructor included; 0 without self_contact).
    long long broad_phases = 0;
};

/// The minimiser of ‖g + κ h‖ over κ: κ = −gᵀh/‖h‖² (g, h of one size), the κ whose barrier force
/// best balances the body's force (IPC's initial κ); 0 when h = 0. fem::Error on sizes.
double balancing_stiffness(const Eigen::VectorXd& g, const Eigen::VectorXd& h);

/// κ_min = m̄ / (Δt² b''(d̂/2)): the barrier's stiffness at d = d̂/2 equals the inertia m̄/Δt² of
/// the average vertex mass m̄ [kg] in backward Euler's Hessian (b'' of the unit barrier; the
/// course's counterpart of IPC's κ_min, which ties the barrier's Hessian to the mass in the same
/// way). fem::Error unless m̄, Δt, d̂ > 0.
double smallest_stiffness(double average_mass, double time_step, double activation_distance);

/// The contact potential of a body against obstacles (a chapter 12 StepPotential: hand it to
/// NewtonBackwardEuler::set_potential). docs/14_contact.md#the-contact-potential
class ContactPotential final : public hyper::StepPotential {
public:
    /// The surface vertices of body's mesh (chapter 13's boundary faces) against every obstacle, and,
    /// with options.self_contact, its surface primitives against each other (SelfContactBarrier).
    /// fem::Error for no obstacle without self_contact, d̂ ≤ 0, κ < 0, a safety outside (0, 1),
    /// ε_v ≤ 0, ε_d < 0, a body_friction < 0 or > 0 without self_contact, and, with self_contact,
    /// two surface primitives that share no vertex closer than d̂ at rest (their barrier would push the body at rest: a smaller d̂ is needed),
    /// or a pattern_reach not a finite number ≥ 0.
    ContactPotential(const dynamics::Body& body, std::vector<std::shared_ptr<const Obstacle>> obstacles,
                     ContactOptions options = {});

    /// Fixes the step: the obstacles at t + Δt; κ (adaptive: κ_min = smallest_stiffness, κ_max =
    /// 100 κ_min; at the first step with a vertex within d̂, κ = balancing_stiffness(−f − f_ext,
    /// ∇B) clamped to [κ_min, κ_max] (B: the unit-κ barrier sum, over free dofs); later κ doubles,
    /// up to κ_max, when the smallest distance is below ε_d and smaller than at the last step); the
    /// friction pairs from x_vᵗ (FrictionPair) and, with body_friction, the body's own pairs within d̂
    /// (BodyFriction::lag, sticking to xᵗ); with self_contact, the Hessian's anticipated pattern
    /// (ContactOptions::pattern_reach).
    void begin_step(dynamics::Body& body, const dynamics::State& state, double time_step) override;

    /// P(u) of the header [J] (+∞ when some surface vertex has d ≤ 0).
    double energy(const Eigen::VectorXd& u) const override;
    /// ∇P (3n): κ b'(d) ∇d per active pair and piece, plus μλ f₁(y) T ŷ per friction pair (ŷ = Tᵀ(x − start)/y),
    /// plus the body friction pairs' (BodyFriction::add_gradient).
    Eigen::VectorXd gradient(const Eigen::VectorXd& u) const override;
    /// ∇²P made PSD (3n×3n, vertex blocks only): each vertex's block is the sum of κ (b'' ∇d ∇dᵀ + b' ∇²d)
    /// over its active pairs and, per friction pair with s = Tᵀ(x − start), y = ‖s‖,
    /// μλ T [ (f₁'(y) y − f₁(y))/y³ · s sᵀ + f₁(y)/y · I₂ ] Tᵀ; the sum is projected once
    /// (chapter 12's project_to_psd, ContactOptions::barrier_projection): b' ∇²d of a sphere is negative semi-definite; plus the
    /// features' and self-contact's pair blocks (each projected) and the body friction pairs' 12×12
    /// blocks (PSD as they are, BodyFriction::add_hessian); with self_contact in the step's anticipated
    /// pattern (explicit zeros, SelfContactBarrier::anticipated_pattern: no value changes).
    dynamics::SparseMatrix hessian(const Eigen::VectorXd& u) const override;
    /// ∇²P itself when ContactOptions::exact_barrier_hessian (hessian's blocks unprojected: each
    /// vertex's barrier and friction block, the features' and self-contact's pair blocks; the body
    /// friction pairs' as in hessian), else hessian(u): what Newton tries first (chapter 12's
    /// HessianChoice::exact_then_definite). docs/14_contact.md#bodies-against-bodies-the-cost
    dynamics::SparseMatrix exact_hessian(const Eigen::VectorXd& u) const override;
    /// min(1, safety × the earliest time of impact of any surface vertex's path x_v + s·Δx_v, of the
    /// features' pairs and (self_contact) of the surface pairs, SelfContactBarrier::time_of_impact).
    double largest_safe_step(const Eigen::VectorXd& u, const Eigen::VectorXd& du) const override;
    /// The step's start velocity (3n) for Newton: a stage's start (stage_next_step), else the first of v = 0 (the body stays put) and
    /// v = w_o (the body carried along with moving obstacle o, in the obstacles' order; the pins
    /// keep their own velocity) whose motion reaches no obstacle: every surface vertex's path
    /// relative to every obstacle o', from x_v at t to x_v + Δt v_v at t + Δt, stays outside o'
    /// (time_of_impact(x_v, Δt (v_v − w_o'), t) > 1). So an obstacle may move any distance in a
    /// step. fem::Error "the obstacles leave the body no room", naming for each candidate a vertex
    /// and the obstacle that reaches it, when none does (a body squeezed between obstacles).
    /// docs/14_contact.md#moving-obstacles
    Eigen::VectorXd start_velocity(const dynamics::Body& body, const dynamics::State& state,
                                   double time_step) const override;

    /// The barrier's part of P: Σ_v Σ_o Σ_p κ b(d_{o,p}(x_v, time)) with the current step's κ [J] (+∞ when
    /// some surface vertex has d ≤ 0), plus the features' and (self_contact) the self-contact
    /// barrier's. Its change over a step, with the obstacles at the step's start and end times, is
    /// the work the obstacles did on the body (the scenes runner books it), and, with self_contact,
    /// the energy the body's own barrier stored or gave back.
    double barrier_energy(const Eigen::VectorXd& u, double time) const;
    /// The barrier's force on every vertex, −κ b'(d) ∇d summed over obstacles, their features and
    /// (self_contact) the body's own surface pairs (3n) [N].
    Eigen::VectorXd barrier_forces(const Eigen::VectorXd& u) const;
    /// The work the moving obstacles do on the body over the step by carrying their forces along:
    /// Δt Σ_o w_o · F_o(u) [J], F_o the force of obstacle o's barrier and friction pairs on the body
    /// at u (3n; the step's end: backward Euler's quadrature). With the change of the barrier's
    /// energy, −(B(u⁺, t + Δt) − B(uᵗ, t)), it is the work of the barrier's forces on the body
    /// (∂B/∂t = −∇B·w); 0 when no obstacle moves. docs/14_contact.md#moving-obstacles
    double obstacle_work(const Eigen::VectorXd& u, double time_step) const;
    /// The smallest d_o(x_v) over surface vertices and obstacles at the step's end time [m], and over
    /// the features' and (self_contact) the surface pairs within d̂.
    double smallest_distance(const Eigen::VectorXd& u) const;

    /// Whether the step from u at time t to u_end at t_end (3n each) is out of contact: every surface
    /// vertex is at d ≥ d̂ from every obstacle at its start (the obstacle at t and at t_end) and at its
    /// end (at t_end), and no straight path meets an obstacle: x_v + s (x_v⁺ − x_v − (t_end − t) w_o),
    /// s ∈ [0, 1], the vertex's path relative to the obstacle, against the obstacle held at t; with
    /// self_contact also no surface pair within d̂ at u or u_end nor meeting on the way u → u_end.
    /// Then P and ∇P are zero at u_end and no friction pair forms at u: the step solved
    /// without the potential solves it with the potential too (the scenes runner's rule, docs/scenes.md#obstacles).
    /// fem::Error on the sizes.
    bool out_of_contact(const Eigen::VectorXd& u, double time, const Eigen::VectorXd& u_end, double end_time) const;

    /// Whether some start of the step from state (start_velocity's candidates, the obstacles at
    /// t + Δt) reaches no obstacle: else contact_step takes the step in stages.
    bool has_free_start(const dynamics::Body& body, const dynamics::State& state, double time_step) const;
    /// The largest fraction f ≤ 1 of the step's obstacle motion (Δt w_o) that, beyond the fraction
    /// `from` already made, reaches no surface vertex held at u (3n): f = from + safety s* (1 − from),
    /// s* the earliest time of impact of the paths x_v − s (1 − from) Δt w_o, s ∈ [0, 1], against each
    /// obstacle o held at time + from·Δt; 1 when none reaches (time: the step's start t).
    double obstacle_advance(const Eigen::VectorXd& u, double time, double time_step, double from) const;
    /// Holds the obstacles of the next step (the next begin_step) at t + fraction·Δt instead of t + Δt,
    /// and starts its search from the velocity start (3n) instead of start_velocity's candidates:
    /// the stages of contact_step. fem::Error for a fraction outside (0, 1] or a start of wrong size.
    void stage_next_step(double fraction, const Eigen::VectorXd& start);

    /// Lags the next step's friction at u (3n) instead of the step's start: λ and T of each pair
    /// from the vertex at u (the obstacles at the step's end), the sticking point still x_vᵗ + Δt w_o.
    /// Used once, by the next begin_step (step_with_friction_updates). fem::Error on u's size.
    void lag_friction_at(const Eigen::VectorXd& u);

    /// The clocks since construction or the last reset_clocks (ContactClocks).
    ContactClocks clocks() const;
    /// Sets the clocks to zero: a step's clocks, read after it, are that step's alone.
    void reset_clocks();

    /// The constants it was made with.
    const ContactOptions& options() const { return options_; }
    /// κ [N/m] of the current step (the fixed one, or the adaptive rule's).
    double stiffness() const { return stiffness_; }
    /// The current step's lagged friction pairs (set by begin_step).
    const std::vector<FrictionPair>& friction_pairs() const { return pairs_; }
    /// The current step's lagged friction pairs between the body's surface primitives (body_friction).
    const std::vector<BodyFrictionPair>& body_friction_pairs() const { return body_friction_.pairs(); }
    /// The barrier between the body's surface primitives (self_contact), else null: its pairs and
    /// their forces (SelfContactBarrier::pairs) with the step's stiffness().
    const SelfContactBarrier* self_barrier() const { return self_.get(); }

private:
    Eigen::Vector3d position(const Eigen::VectorXd& u, int vertex) const;
    /// hessian's matrix with every barrier block projected as projection says (none: as it is).
    dynamics::SparseMatrix assembled_hessian(const Eigen::VectorXd& u, std::optional<hyper::Projection> projection) const;
    /// The first of start_velocity's candidates that reaches no obstacle held at obstacle_time, or an
    /// empty vector (blocked, when given, receives each candidate's first vertex and obstacle met).
    Eigen::VectorXd free_start(const dynamics::Body& body, const dynamics::State& state, double time_step,
                               double obstacle_time, std::string* blocked) const;
    /// −κ Σ_p b'(d_p) ∇d_p: the barrier force of one obstacle on the surface vertex at x, time time_.
    Eigen::Vector3d barrier_force(const Obstacle& obstacle, const Eigen::Vector3d& x) const;
    /// One obstacle pair's lagged friction at u: lagged_friction of r = x_v − start with μλ (its
    /// gradient is minus the friction force on the vertex).
    LaggedFriction pair_friction(const FrictionPair& pair, const Eigen::VectorXd& u) const;

    std::vector<std::shared_ptr<const Obstacle>> obstacles_;
    ContactOptions options_;
    FeatureBarrier features_;  // the obstacles' edges and corners against the body's surface
    std::unique_ptr<SelfContactBarrier> self_;  // the body's surface against itself (self_contact), else null
    std::unique_ptr<IntersectionCheck> check_;   // check_intersections, else null
    BodyFriction body_friction_;                // the lagged friction of self_'s pairs (body_friction)
    Eigen::MatrixX3d rest_;            // X (#V × 3)
    std::vector<int> surface_;
    double average_mass_ = 0.0, diagonal_ = 0.0;
    double time_ = 0.0, stiffness_ = 0.0, friction_step_ = 0.0;  // friction_step_: ε = ε_v Δt
    double last_smallest_ = 0.0;
    bool stiffness_set_ = false;
    std::vector<FrictionPair> pairs_;
    Eigen::VectorXd lag_u_;  // empty: lag at the step's start
    double next_fraction_ = 1.0, fraction_ = 1.0;  // of the step's obstacle motion: the next step's, this one's
    Eigen::VectorXd next_start_, start_;           // the start velocity set for the next step, this one's (empty: none)
    mutable double barrier_seconds_ = 0.0, collision_seconds_ = 0.0;  // ContactClocks' sums
    long long broad_phases_before_ = 0;  // the self barrier's broad phases at the last reset_clocks
};

/// The friction lag iterated to convergence (step_with_friction_updates with updates = 0) stops when
/// no vertex moved more than this × ε_v Δt between two solves (ε_v Δt: the creep of a sticking vertex).
inline constexpr double friction_lag_tolerance = 1e-2;
/// … or fails (fem::Error) after this many solves of one step.
inline constexpr int most_friction_updates = 20;

/// One backward Euler step with contact whose friction is lagged `updates` times: the step is
/// solved with λ, T from its start (IPC's one lagged update), then, updates − 1 times, solved again
/// from the same start with λ, T from the last solution (lag_friction_at), which approaches friction
/// that is implicit in λ and T. updates = 0: until converged, solved again until no vertex moves
/// more than friction_lag_tolerance ε_v Δt between two solves (fem::Error after
/// most_friction_updates solves). newton must have contact set as its potential. The StepInfo's
/// Newton and solver iterations are summed over the solves; solves (when set) receives their number.
/// fem::Error for updates < 0. docs/14_contact.md#friction
dynamics::StepInfo step_with_friction_updates(hyper::NewtonBackwardEuler& newton, ContactPotential& contact,
                                              dynamics::Body& body, double time_step, dynamics::State& state,
                                              int updates, int* solves = nullptr);

/// contact_step gives up (fem::Error "no room") after this many stages of one step.
inline constexpr int most_obstacle_stages = 200;

/// One backward Euler step with contact as a body's integrator takes it: step_with_friction_updates,
/// in stages when no start of the step is free (start_velocity: a body that must be compressed or
/// pushed by obstacles moving more than its gaps in one step) — the obstacles moved part of the way
/// (obstacle_advance), the step solved with them there, its solution the start of the next stage,
/// until they stand at t + Δt, where the last stage solves the step itself (fem::Error "no room"
/// when a stage advances them by less than 10⁻⁹ of the step, after most_obstacle_stages, or when a
/// stage cannot be solved);
/// its StepInfo::boundary_work raised by the obstacles' work on the body, −(B(u⁺, t + Δt) − B(uᵗ, t))
/// + obstacle_work(u⁺, Δt) (B: barrier_energy with the step's κ), so that chapter 10's energy books,
/// which do not hold B, count the barrier's store and the moving obstacles' push as work put in
/// (friction's sliding stays dissipation). Only surface vertices carry the barrier, so the step is
/// refused (fem::Error naming the tet and its volume, the state left at the step's start) when it
/// would turn a tet of positive volume at its start inside out: an impact or a squeeze the mesh
/// cannot resolve. docs/14_contact.md#what-is-guaranteed
/// stages (when set) receives their number (1: the step was solved at once).
dynamics::StepInfo contact_step(hyper::NewtonBackwardEuler& newton, ContactPotential& contact, dynamics::Body& body,
                                double time_step, dynamics::State& state, int updates = 1, int* solves = nullptr,
                                int* stages = nullptr);

}  // namespace fem::contact
