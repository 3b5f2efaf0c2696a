#pragma once
// Chapter 14: incremental potential contact (Li et al. 2020) against obstacles, as a chapter 12
// StepPotential: the barrier of every surface vertex against every obstacle, lagged smoothed Coulomb
// friction, the adaptive barrier stiffness κ (adaptive_stiffness.hpp), and the continuous collision
// check that cuts every Newton step before Armijo. docs/14_contact.md
//
// For a body with surface vertices x_v = X_v + u_v and obstacles o (at the step's end time t + Δt):
//
//   P(u) = Σ_v Σ_o Σ_p κ b(d_{o,p}(x_v))  +  Σ_k μ_k λ_k f₀(‖T_kᵀ (x_v − x_vᵗ − Δt w_o)‖)  +  Σ_c P_c(u)
//
// the barrier (b of barrier.hpp, active where d < d̂) over the pieces p of each obstacle within d̂
// (Obstacle::pieces: a half-space, sphere or box is one piece, a mesh one per triangle: IPC's one
// barrier per pair) and the friction of every pair k = (v, o) that was within d̂ at the step's start
// (obstacle_friction_pairs, friction.hpp): λ_k = κ Σ_p |b'(d_{o,p}(x_vᵗ))| its lagged normal force [N],
// T_k (3×2) an orthonormal basis of the tangent plane ⟂ ∇d_o(x_vᵗ), w_o the obstacle's velocity
// (IPC: lagged friction).
// P_c are the potential's contact terms (ContactTerm below): what a later chapter adds to the sum
// with the same κ, d̂ and step — chapter 15 the obstacles' edges and corners against the body's
// edges, the body's surface against itself and friction between bodies (15_body_contact/body_contact.hpp).

#include "14_contact/adaptive_stiffness.hpp"
#include "14_contact/friction.hpp"
#include "14_contact/obstacles.hpp"

#include "12_hyperelastic_newton/newton.hpp"

#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include <Eigen/Core>
#include <Eigen/Sparse>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace fem::contact {

/// The constants of contact, named once (docs/14_contact.md#the-constants).
struct ContactOptions {
    double activation_distance = 1e-3;  ///< d̂ [m]: the barrier acts where d < d̂
    /// κ [N/m]: > 0 fixed; 0 adaptive (AdaptiveStiffness, after IPC's rule).
    double stiffness = 0.0;
    double safety = 0.8;                ///< the line search starts at safety × the time of impact, in (0, 1)
    double friction_velocity = 1e-3;    ///< ε_v [m/s]: slower tangential motion is sticking (f₁ < 1)
    /// ε_d as a fraction of the body's bounding-box diagonal: κ doubles when the smallest distance
    /// is below it and still falling (IPC's value: 10⁻⁹).
    double doubling_distance = 1e-9;
    /// How each barrier block of the Hessian is made PSD (a vertex's block against the obstacles, and
    /// each contact term's pair blocks): chapter 12's project_to_psd, clamp (negative eigenvalues to 0)
    /// or absolute (to |λ|). docs/15_body_contact.md#the-cost-of-contact
    hyper::Projection barrier_projection = hyper::Projection::clamp;
    /// What ContactPotential::exact_hessian holds, the Hessian chapter 12's Newton tries first
    /// (HessianChoice::exact_then_definite: kept where M + Δt² (K + ∇²P) factors and gives descent, else
    /// the definite one): true, the barrier's blocks as they are (∇²P itself, so that Newton converges
    /// quadratically wherever the whole step's Hessian is definite); false, projected as in hessian.
    /// docs/15_body_contact.md#the-cost-of-contact
    bool exact_barrier_hessian = false;
};

/// What a ContactTerm is told when a step begins (ContactPotential::begin_step), κ already fixed.
struct ContactStepStart {
    const dynamics::State& state;  ///< the step's start: uᵗ, vᵗ (3n each), t
    const Eigen::VectorXd& lag;    ///< where friction is lagged (3n): uᵗ, or ContactPotential::lag_friction_at's u
    double time_step;              ///< Δt [s]
    double stiffness;              ///< κ [N/m] of the step
};

/// The extension point of the contact potential: a term P_c(u) that ContactPotential adds to its sum
/// over obstacles, with the step's κ, d̂ and friction smoothing ε = ε_v Δt, and that takes part in the
/// line search's collision check and in out_of_contact. Each function has a default that adds nothing
/// (0, no entries, +∞ for distances and times of impact, always out of contact), so a term overrides
/// what it has. Vectors are 3n (n: the body's vertices); time is where the obstacles stand [s].
/// Chapter 15 makes three: the obstacles' edges and corners against the body's edges, the body's
/// surface against itself with friction between bodies, and the intersection referee.
/// docs/14_contact.md#the-contact-potential
class ContactTerm {
public:
    virtual ~ContactTerm() = default;

    /// The step begins: the term may lag its friction (ContactStepStart) and get ready.
    virtual void begin_step(const ContactStepStart& /*start*/) {}
    /// Called first at every configuration the potential's energy is asked of: a debug check that
    /// throws fem::Error at a configuration it refuses.
    virtual void check(const Eigen::VectorXd& /*u*/, double /*time*/) const {}
    /// Its barrier energy with stiffness κ [J] (+∞ where it touches: d = 0).
    virtual double barrier_energy(const Eigen::VectorXd& /*u*/, double /*time*/, double /*stiffness*/) const
    {
        return 0.0;
    }
    /// Adds the barrier energy's gradient (3n) to gradient.
    virtual void add_barrier_gradient(const Eigen::VectorXd& /*u*/, double /*time*/, double /*stiffness*/,
                                      Eigen::VectorXd& /*gradient*/) const {}
    /// Appends the barrier energy's Hessian entries to triplets, each block projected to PSD with
    /// projection (chapter 12's project_to_psd; none: as they are).
    virtual void add_barrier_hessian(const Eigen::VectorXd& /*u*/, double /*time*/, double /*stiffness*/,
                                     std::vector<Eigen::Triplet<double>>& /*triplets*/,
                                     std::optional<hyper::Projection> /*projection*/) const {}
    /// Its lagged friction energy with smoothing ε = ε_v Δt [m] [J].
    virtual double friction_energy(const Eigen::VectorXd& /*u*/, double /*epsilon*/) const { return 0.0; }
    /// Adds the friction energy's gradient (3n) to gradient.
    virtual void add_friction_gradient(const Eigen::VectorXd& /*u*/, double /*epsilon*/,
                                       Eigen::VectorXd& /*gradient*/) const {}
    /// Appends the friction energy's Hessian entries (PSD as they are) to triplets.
    virtual void add_friction_hessian(const Eigen::VectorXd& /*u*/, double /*epsilon*/,
                                      std::vector<Eigen::Triplet<double>>& /*triplets*/) const {}
    /// The step's Hessian pattern beyond the entries above (explicit zeros, 3n×3n; empty: none).
    virtual const dynamics::SparseMatrix* pattern() const { return nullptr; }
    /// Σ_o w_o · (the force of obstacle o through this term on the body) at u [N·m/s].
    virtual double obstacle_power(const Eigen::VectorXd& /*u*/, double /*time*/, double /*stiffness*/) const
    {
        return 0.0;
    }
    /// The smallest distance of any of its pairs within reach at u [m] (+∞ when none is).
    virtual double smallest_distance(const Eigen::VectorXd& /*u*/, double /*time*/, double /*reach*/) const;
    /// The earliest time of impact s ∈ [0, 1] of its pairs while the body moves from u to u + du and
    /// the obstacles from time to end_time (end_time == time: the obstacles held there), +∞ for none.
    virtual double time_of_impact(const Eigen::VectorXd& /*u*/, const Eigen::VectorXd& /*du*/, double /*time*/,
                                  double /*end_time*/) const;
    /// The earliest time of impact s ∈ [0, 1] of its pairs while the obstacles move from time to
    /// end_time and the body stays at u, +∞ for none (ContactPotential::obstacle_advance).
    virtual double obstacle_time_of_impact(const Eigen::VectorXd& /*u*/, double /*time*/, double /*end_time*/) const;
    /// What it is when one of its pairs meets, for messages (e.g. "the body's surface meets itself").
    virtual std::string meeting() const { return "a pair of a contact term meets"; }
    /// Whether the step from u at time to u_end at end_time keeps its pairs at least reach apart at
    /// both ends and meeting nowhere on the way (ContactPotential::out_of_contact).
    virtual bool out_of_contact(const Eigen::VectorXd& /*u*/, double /*time*/, const Eigen::VectorXd& /*u_end*/,
                                double /*end_time*/, double /*reach*/) const
    {
        return true;
    }
    /// The broad phases it has run since it was made (ContactClocks::broad_phases).
    virtual long long broad_phases() const { return 0; }
};

/// Where a ContactPotential's time goes, for the tables of what contact costs (ch15_body_contact's
/// cost study, the scenes runner's contact_steps.csv): wall time summed over whole calls (one
/// steady_clock read at each call's start and end, common/timer.hpp; no clock per pair, so they cost
/// nothing to keep), since the potential's construction or its last reset_clocks. The calls
/// contact_step makes of the potential itself (has_free_start, its stages' obstacle_advance, the
/// barrier energies it books as work) and out_of_contact, smallest_distance are in neither clock.
/// docs/15_body_contact.md#the-cost-of-contact
struct ContactClocks {
    /// begin_step (κ, the lagged friction pairs, the terms' begin_step) and every energy, gradient
    /// and Hessian: the barriers with their broad phases and the friction terms [s].
    double barrier_seconds = 0.0;
    /// largest_safe_step (the line search's continuous collision check, with the terms' broad phases
    /// over the swept boxes) and start_velocity (the start's check against the obstacles) [s].
    double collision_seconds = 0.0;
    /// The broad phases the contact terms ran, whichever call asked (ContactTerm::broad_phases).
    long long broad_phases = 0;
};

/// The contact potential of a body against obstacles (a chapter 12 StepPotential: hand it to
/// NewtonBackwardEuler::set_potential), plus its contact terms. docs/14_contact.md#the-contact-potential
class ContactPotential final : public hyper::StepPotential {
public:
    /// The surface vertices of body's mesh (chapter 13's boundary faces) against every obstacle, plus
    /// the terms (summed in their order). fem::Error for no obstacle and no term, a null one, d̂ ≤ 0,
    /// κ < 0, a safety outside (0, 1), ε_v ≤ 0 or ε_d < 0.
    ContactPotential(const dynamics::Body& body, std::vector<std::shared_ptr<const Obstacle>> obstacles,
                     ContactOptions options = {}, std::vector<std::unique_ptr<ContactTerm>> terms = {});

    /// Fixes the step: the obstacles at t + Δt; κ (fixed, or AdaptiveStiffness::next with the
    /// smallest distance at uᵗ and, until balanced, the load −f − f_ext against the unit-κ barrier's
    /// gradient, over free dofs); the friction pairs from x_vᵗ (obstacle_friction_pairs); then each
    /// term's begin_step.
    void begin_step(dynamics::Body& body, const dynamics::State& state, double time_step) override;

    /// P(u) of the header [J] (+∞ when some surface vertex has d ≤ 0 or a term is +∞).
    double energy(const Eigen::VectorXd& u) const override;
    /// ∇P (3n): κ b'(d) ∇d per active pair and piece, plus μλ f₁(y) T ŷ per friction pair (ŷ = Tᵀ(x − start)/y),
    /// plus the terms'.
    Eigen::VectorXd gradient(const Eigen::VectorXd& u) const override;
    /// ∇²P made PSD (3n×3n): each vertex's block is the sum of κ (b'' ∇d ∇dᵀ + b' ∇²d) over its
    /// active pairs and, per friction pair with s = Tᵀ(x − start), y = ‖s‖,
    /// μλ T [ (f₁'(y) y − f₁(y))/y³ · s sᵀ + f₁(y)/y · I₂ ] Tᵀ; the sum is projected once
    /// (chapter 12's project_to_psd, ContactOptions::barrier_projection): b' ∇²d of a sphere is
    /// negative semi-definite; plus the terms' barrier blocks (projected) and friction blocks, in the
    /// terms' patterns (explicit zeros: no value changes).
    dynamics::SparseMatrix hessian(const Eigen::VectorXd& u) const override;
    /// ∇²P itself when ContactOptions::exact_barrier_hessian (hessian's blocks unprojected), else
    /// hessian(u): what Newton tries first (chapter 12's HessianChoice::exact_then_definite).
    /// docs/15_body_contact.md#the-cost-of-contact
    dynamics::SparseMatrix exact_hessian(const Eigen::VectorXd& u) const override;
    /// min(1, safety × the earliest time of impact of any surface vertex's path x_v + s·Δx_v and of
    /// the terms' pairs, the obstacles held at the step's end).
    double largest_safe_step(const Eigen::VectorXd& u, const Eigen::VectorXd& du) const override;
    /// The step's start velocity (3n) for Newton: a stage's start (stage_next_step), else the first of v = 0 (the body stays put) and
    /// v = w_o (the body carried along with moving obstacle o, in the obstacles' order; the pins
    /// keep their own velocity) whose motion reaches no obstacle: every surface vertex's path
    /// relative to every obstacle o', from x_v at t to x_v + Δt v_v at t + Δt, stays outside o'
    /// (time_of_impact(x_v, Δt (v_v − w_o'), t) > 1), and no term's pair meets. So an obstacle may
    /// move any distance in a step. fem::Error "the obstacles leave the body no room", naming for
    /// each candidate a vertex and the obstacle that reaches it, when none does (a body squeezed
    /// between obstacles). docs/14_contact.md#moving-obstacles
    Eigen::VectorXd start_velocity(const dynamics::Body& body, const dynamics::State& state,
                                   double time_step) const override;

    /// The barrier's part of P: Σ_v Σ_o Σ_p κ b(d_{o,p}(x_v, time)) with the current step's κ [J] (+∞ when
    /// some surface vertex has d ≤ 0), plus the terms' barrier energies. Its change over a step, with
    /// the obstacles at the step's start and end times, is the work the obstacles did on the body (the
    /// scenes runner books it) and the energy the terms' barriers stored or gave back.
    double barrier_energy(const Eigen::VectorXd& u, double time) const;
    /// The barrier's force on every vertex, −κ b'(d) ∇d summed over obstacles, minus the terms'
    /// barrier gradients (3n) [N].
    Eigen::VectorXd barrier_forces(const Eigen::VectorXd& u) const;
    /// The work the moving obstacles do on the body over the step by carrying their forces along:
    /// Δt (Σ_o w_o · F_o(u) + the terms' obstacle_power) [J], F_o the force of obstacle o's barrier and
    /// friction pairs on the body at u (3n; the step's end: backward Euler's quadrature). With the
    /// change of the barrier's energy, −(B(u⁺, t + Δt) − B(uᵗ, t)), it is the work of the barrier's
    /// forces on the body (∂B/∂t = −∇B·w); 0 when no obstacle moves. docs/14_contact.md#moving-obstacles
    double obstacle_work(const Eigen::VectorXd& u, double time_step) const;
    /// The smallest d_o(x_v) over surface vertices and obstacles at the step's end time [m], and over
    /// the terms' pairs within d̂.
    double smallest_distance(const Eigen::VectorXd& u) const;

    /// Whether the step from u at time t to u_end at t_end (3n each) is out of contact: every surface
    /// vertex is at d ≥ d̂ from every obstacle at its start (the obstacle at t and at t_end) and at its
    /// end (at t_end), no straight path meets an obstacle: x_v + s (x_v⁺ − x_v − (t_end − t) w_o),
    /// s ∈ [0, 1], the vertex's path relative to the obstacle, against the obstacle held at t; and
    /// every term says so (ContactTerm::out_of_contact with reach d̂).
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
    /// obstacle o held at time + from·Δt, and of the terms' pairs; 1 when none reaches (time: the
    /// step's start t).
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
    /// The current step's lagged friction pairs against the obstacles (set by begin_step).
    const std::vector<FrictionPair>& friction_pairs() const { return pairs_; }
    /// The first of its contact terms that is a Term, else null (e.g. chapter 15's
    /// contact.term<BodyContactTerm>(), the barrier between bodies).
    template <class Term>
    const Term* term() const
    {
        for (const auto& term : terms_)
            if (const auto* found = dynamic_cast<const Term*>(term.get()))
                return found;
        return nullptr;
    }

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
    /// The broad phases of every term.
    long long broad_phases() const;

    std::vector<std::shared_ptr<const Obstacle>> obstacles_;
    ContactOptions options_;
    std::vector<std::unique_ptr<ContactTerm>> terms_;
    Eigen::MatrixX3d rest_;            // X (#V × 3)
    std::vector<int> surface_;
    std::optional<AdaptiveStiffness> adaptive_;  // with ContactOptions::stiffness = 0
    double time_ = 0.0, stiffness_ = 0.0, friction_step_ = 0.0;  // friction_step_: ε = ε_v Δt
    std::vector<FrictionPair> pairs_;
    Eigen::VectorXd lag_u_;  // empty: lag at the step's start
    double next_fraction_ = 1.0, fraction_ = 1.0;  // of the step's obstacle motion: the next step's, this one's
    Eigen::VectorXd next_start_, start_;           // the start velocity set for the next step, this one's (empty: none)
    mutable double barrier_seconds_ = 0.0, collision_seconds_ = 0.0;  // ContactClocks' sums
    long long broad_phases_before_ = 0;  // the terms' broad phases at the last reset_clocks
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
