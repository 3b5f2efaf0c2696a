#pragma once
// Chapter 10: time integrators and the time loop. docs/10_linear_dynamics.md
//
// The lecture's "best practice" step is backward Euler on the first-order system (u, v):
//     [M + Δt D + Δt² K] v⁺ = M v − Δt [K u − f_ext],      u⁺ = u + Δt v⁺.
// It is the θ = 1 member of the θ-method (chapter 02 used the same family for heat):
//     u⁺ = u + Δt v_θ,   M (v⁺ − v) = Δt [f(u_θ) + f_ext − D v_θ],   w_θ = θ w⁺ + (1 − θ) w,
// which for the linear forces f(u) = −K u is one linear system for v⁺:
//     A v⁺ = b,   A = M + θΔt D + θ²Δt² K,
//                 b = M v + Δt (f(u) + f_ext) − (1 − θ) Δt (D v + θ Δt K v).
// θ = 1 is backward Euler (first order, damps every mode), θ = ½ the implicit midpoint rule (= the
// trapezoidal rule = Newmark's average acceleration for a linear body: second order, and it keeps
// the energy of an undamped body exactly). A is constant for a linear body: ThetaMethod factors it
// once (chapter 09's make_solver, default solver) and each step is one product and one solve.
//
// The same system written for the change of velocity Δv = v⁺ − v,
//     A Δv = Δt [f(u) + f_ext − D v − θΔt K v],
// has the same solution in exact arithmetic but no M v on the right: in floating point the lecture's
// b carries M v, which the solve must cancel again, and the round-off of that cancellation reaches
// v⁺ amplified by κ(A). ThetaMethod solves for Δv by default and offers the lecture's form to
// compare (docs/10_linear_dynamics.md#two-forms-of-one-step).
// For a force model whose K changes (chapter 11) the same step is the linearly implicit (one Newton
// iteration) step, and A is refactored every step on the same pattern.
//
// Beside them, the explicit (symplectic) Euler step v⁺ = v + Δt M⁻¹ [f(u) + f_ext − D v],
// u⁺ = u + Δt v⁺, stable only for Δt < 2/ω_max (modes.hpp).
//
// Pinned vertices that move (docs/10_linear_dynamics.md#moving-pins): the body's pin velocity ṽ_p
// (Body::set_pin_velocity) fixes v_θ = ṽ_p on the pinned dofs, so u_p⁺ = u_p + Δt ṽ_p, and the
// free dofs feel it through the coupling A_fp of the step matrix: A_ff x_f = b_f − A_fp x_p.
// The reactions r_p that move the pins do the work Δt ṽ_pᵀ r_p on the body (StepInfo::boundary_work).
//
// Simulation owns the loop: time, energies, what damping and the integrator dissipate, the energy
// the scene puts in (a hook before each step may move the pins, change the loads and switch the
// force model, and the loop books what that does), divergence detection (an fem::Error naming the
// step and the growth of H − W_in, never a NaN frame) and the observers that write frames.

#include "10_linear_dynamics/body.hpp"

#include "common/error.hpp"
#include "common/threads_study.hpp"
#include "common/vtk_io.hpp"

#include "09_conjugate_gradient/linear_solver.hpp"

#include <Eigen/Core>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace fem::dynamics {

/// Where the body is: time, step, displacement u and velocity v (3n each; zero on pinned dofs),
/// and the force model's answer at u (kept so that each step evaluates the model once).
struct State {
    double time = 0.0;
    int step = 0;
    Eigen::VectorXd u;              ///< displacement x − x₀ (3n)
    Eigen::VectorXd v;              ///< velocity (3n)
    Eigen::VectorXd forces;         ///< internal forces f(u) = −∂U/∂u (3n)
    double elastic_energy = 0.0;    ///< U(u)
};

/// The state (u0, v0) at time 0 (empty vectors: zero), with the force model evaluated at u0.
/// fem::Error unless u0 and v0 have 3n finite entries. A pinned vertex may start displaced or moving
/// (a prescribed motion's state at time 0); it then moves only as the body's pin velocity says.
State initial_state(Body& body, const Eigen::VectorXd& u0 = {}, const Eigen::VectorXd& v0 = {});

/// Commits a step an integrator has computed: the force model evaluated once at u⁺ (forces and
/// energy kept in the state for the next step and the energies), then u, v, time and step. Nothing
/// of state changes if the model throws. For integrators of later chapters (chapter 12's Newton).
void commit_step(ForceModel& model, double time_step, Eigen::VectorXd u_next, Eigen::VectorXd v_next, State& state);

/// One frame of a body for a .pvd time series: rest positions with the point fields "displacement"
/// and "velocity" and the cell field "von Mises stress" (from the force model).
io::MeshData body_frame(const Body& body, const State& state);

/// T, U and W of a state (see Energies). docs/10_linear_dynamics.md#energy
Energies energies(const Body& body, const State& state);

/// The energy one θ-step of an undamped linear body takes out of H = T + U + W by itself (the
/// integrator's dissipation, a derivation exercise):
///     H − H⁺ = (θ − ½) [(v⁺ − v)ᵀ M (v⁺ − v) + (u⁺ − u)ᵀ K (u⁺ − u)]  [J],
/// ≥ 0 for θ ≥ ½ and M, K positive semi-definite, zero for the midpoint rule; a constant load does
/// not change it. M, K: n×n; u, u_next, v, v_next: n each (the state before and after the step).
/// fem::Error for θ outside [½, 1] or mismatched sizes. docs/10_linear_dynamics.md#energy
double theta_step_dissipation(const SparseMatrix& M, const SparseMatrix& K, const Eigen::VectorXd& u,
                              const Eigen::VectorXd& u_next, const Eigen::VectorXd& v, const Eigen::VectorXd& v_next,
                              double theta);

// --- The teaching pieces of the implicit step (exercises) -------------------------------------

/// The matrix of the θ-step, A = M + θΔt D + θ²Δt² K with D = α M + β K, i.e.
///   A = (1 + θΔt α) M + (θΔt β + θ²Δt²) K
/// (M, K: n×n of one shape; the result has K's pattern when M's lies inside it). θ = 1 gives the
/// lecture's M + Δt D + Δt² K. fem::Error for Δt ≤ 0, θ outside [½, 1] or mismatched sizes.
/// docs/10_linear_dynamics.md#the-implicit-step
SparseMatrix step_matrix(const SparseMatrix& M, const SparseMatrix& K, const Damping& damping, double time_step,
                         double theta = 1.0);

/// The step matrix of a body whose stiffness changes every step (chapters 11 and 12), assembled on
/// the free dofs in one fixed pattern: A_ff = Pᵀ (a M + k K) P, with a = 1 + θΔt α and
/// k = θΔt β + θ²Δt² as in step_matrix. The pattern of A_ff and the slot of every entry of M and K
/// in it (or none, for a pinned row or column) are found once; each assemble() is then one pass
/// over M's and K's values, where reduce(step_matrix(M, K)) would build two new matrices.
/// docs/10_linear_dynamics.md#the-implicit-step
class ReducedStepMatrix {
public:
    /// The pattern of Pᵀ (M + K) P (both n×n, n = dofs.full_size()). fem::Error on sizes.
    ReducedStepMatrix(const SparseMatrix& M, const SparseMatrix& K, const FreeDofs& dofs);

    /// True when M and K have the patterns this was built for (one pass over their indices).
    bool fits(const SparseMatrix& M, const SparseMatrix& K) const;

    /// A_ff = Pᵀ (a M + k K) P in the fixed pattern (size dofs.size(), CSC, both triangles).
    /// fem::Error unless fits(M, K).
    const SparseMatrix& assemble(const SparseMatrix& M, const SparseMatrix& K, double a, double k);

    /// assemble with a and k of the θ-step: step_matrix's weights for damping, Δt and θ.
    const SparseMatrix& assemble(const SparseMatrix& M, const SparseMatrix& K, const Damping& damping,
                                 double time_step, double theta = 1.0);

private:
    /// The pattern of one n×n input, kept to check that a later M or K still has it.
    struct Pattern {
        std::vector<int> outer, inner;
        explicit Pattern(const SparseMatrix& A);
        bool matches(const SparseMatrix& A) const;
    };
    SparseMatrix A_;                            // A_ff, its pattern fixed
    Pattern M_pattern_, K_pattern_;
    std::vector<int> M_slot_, K_slot_;          // entry k of M or K (compressed order) → entry of A_ff, or −1
};

/// The lecture's right-hand side b = M v + Δt (f + f_ext), i.e. M v − Δt [K u − f_ext] with the
/// internal forces f = −K u (all vectors of M's size). The θ < 1 correction is added by ThetaMethod.
/// fem::Error for Δt ≤ 0 or mismatched sizes. docs/10_linear_dynamics.md#the-implicit-step
Eigen::VectorXd step_right_hand_side(const SparseMatrix& M, const Eigen::VectorXd& v, const Eigen::VectorXd& forces,
                                     const Eigen::VectorXd& external_forces, double time_step);

/// The right-hand side of the velocity-change form, r = Δt [f + f_ext − D v − θΔt K v] with
/// D v = α M v + β K v (all vectors of M's size, Kv = K v included: where β = 0 and θ = 1 its terms
/// vanish, but its size is checked all the same — pass K v or zeros). A Δv = r gives v⁺ = v + Δv, the same v⁺ as A v⁺ = b with b from step_right_hand_side
/// and its θ < 1 correction. fem::Error for Δt ≤ 0, θ outside [½, 1] or mismatched sizes.
/// docs/10_linear_dynamics.md#two-forms-of-one-step
Eigen::VectorXd velocity_change_right_hand_side(const SparseMatrix& M, const Eigen::VectorXd& v,
                                                const Eigen::VectorXd& Kv, const Eigen::VectorXd& forces,
                                                const Eigen::VectorXd& external_forces, const Damping& damping,
                                                double time_step, double theta = 1.0);

// --- Integrators -------------------------------------------------------------------------------

/// How the pinned dofs are kept out of the implicit solve. docs/10_linear_dynamics.md#pinned-vertices
enum class PinnedRoute {
    eliminate,  ///< solve A_ff v_f = b_f on the free dofs only (size 3n − 3·#pinned; the default)
    keep,       ///< solve P̂ A P̂ + (I − P̂) on all 3n dofs with b zeroed on the pinned ones
};

/// Which unknown the implicit step solves for (docs/10_linear_dynamics.md#two-forms-of-one-step).
enum class StepForm {
    velocity_change,  ///< A Δv = Δt [f + f_ext − D v − θΔt K v] (the default: less cancellation)
    velocity,         ///< the lecture's A v⁺ = M v + Δt (f + f_ext) − (1 − θ)Δt (D v + θΔt K v)
};

/// The choices of an implicit step, compared side by side in the chapter's executable.
struct ImplicitOptions {
    std::string solver = "default";     ///< a chapter 09 solver name (cg::make_solver)
    cg::SolverOptions solver_options;   ///< tolerance and cap of an iterative solver
    bool refactor_every_step = false;   ///< prepare A every step even when it is constant (to
                                        ///< measure what factoring once saves)
    bool warm_start = true;             ///< an iterative solver starts from its last answer (the
                                        ///< last Δv, or v⁺ = v in the lecture's form); false: from
                                        ///< zero (which in the Δv form is v⁺ = v as well)
    PinnedRoute pinned = PinnedRoute::eliminate;
    StepForm form = StepForm::velocity_change;
    /// When set, the solver is made by this instead of cg::make_solver(solver, solver_options): the
    /// hook through which a later chapter plugs in its own (chapter 11's frozen-factorization PCG).
    std::function<std::unique_ptr<cg::LinearSolver>()> make_solver;
};

/// What one step did, for the loop's bookkeeping.
struct StepInfo {
    double damping_work = 0.0;   ///< energy removed by D in this step: Δt v_θᵀ D v_θ ≥ 0 [J]
    /// The work the pinned vertices' reactions did on the body in this step [J]: Δt ṽ_pᵀ r_p, with
    /// r = M (v⁺ − v)/Δt − f_θ − f_ext + D v_θ the residual of the step's momentum equation, zero on
    /// the free dofs (0 when the pins rest). docs/10_linear_dynamics.md#moving-pins
    double boundary_work = 0.0;
    int solver_iterations = 0;   ///< iterations of an iterative solver (0 for a direct one)
    int newton_iterations = 0;   ///< Newton iterations of a nonlinear step (chapter 12; 0 here)
    bool prepared = false;       ///< the step (re)factored its matrix
};

/// One step from (u, v) to (u⁺, v⁺) for a body. docs/10_linear_dynamics.md#the-pieces-of-a-simulation
class Integrator {
public:
    virtual ~Integrator() = default;
    virtual std::string name() const = 0;
    /// The order of accuracy in Δt (1 or 2).
    virtual int order() const = 0;
    /// True for an explicit step (stable only below a limit on Δt, as symplectic Euler below
    /// 2/ω_max); the time loop's divergence message says what to change by it.
    virtual bool is_explicit() const { return false; }
    /// Advances state by Δt: u, v, forces, elastic_energy, time and step. fem::Error from the solver
    /// (a matrix that is not positive definite, an iterative solver that misses its tolerance) or
    /// for Δt ≤ 0; state is then unchanged.
    virtual StepInfo step(Body& body, double time_step, State& state) = 0;
};

/// The θ-method of the header comment, θ ∈ [½, 1]: θ = 1 backward Euler, θ = ½ implicit midpoint.
/// A = step_matrix(M, K, damping, Δt, θ) is prepared on the first step and again only when Δt or
/// the stiffness changes (or every step with refactor_every_step). An iterative solver starts from
/// its previous answer (warm start: the previous Δv, or the previous v in the lecture's form).
/// docs/10_linear_dynamics.md#the-implicit-step
class ThetaMethod final : public Integrator {
public:
    /// fem::Error for θ outside [½, 1] or an unknown solver name.
    explicit ThetaMethod(double theta, ImplicitOptions options = {});

    std::string name() const override;
    int order() const override { return theta_ == 0.5 ? 2 : 1; }
    StepInfo step(Body& body, double time_step, State& state) override;

    double theta() const { return theta_; }
    const cg::LinearSolver& solver() const { return *solver_; }

private:
    double theta_;
    ImplicitOptions options_;
    std::unique_ptr<cg::LinearSolver> solver_;
    std::optional<ReducedStepMatrix> reduced_;  // the eliminate route's A_ff, its pattern fixed
    double prepared_time_step_ = 0.0;   // Δt of the prepared matrix (0: none yet)
    const Body* prepared_body_ = nullptr;
    Eigen::VectorXd rhs_, solution_;    // work vectors (free or full size, by route); solution_
                                        // keeps the last answer, the next warm start
};

/// Symplectic (semi-implicit) Euler: v⁺ = v + Δt M⁻¹ [f(u) + f_ext − D v], u⁺ = u + Δt v⁺. Explicit:
/// with the lumped mass M⁻¹ is a division per dof, with the consistent mass M_ff is factored once.
/// Stable only for Δt below explicit_stability_limit (modes.hpp). docs/10_linear_dynamics.md#explicit-euler
class SymplecticEuler final : public Integrator {
public:
    std::string name() const override { return "symplectic Euler"; }
    int order() const override { return 1; }
    bool is_explicit() const override { return true; }
    StepInfo step(Body& body, double time_step, State& state) override;

private:
    std::unique_ptr<cg::LinearSolver> mass_solver_;  // consistent mass only
    const Body* prepared_body_ = nullptr;
};

/// The integrator called `name`: "backward-euler", "implicit-midpoint" or "symplectic-euler"
/// (options: the implicit ones only). fem::Error for another name (the message lists these).
std::unique_ptr<Integrator> make_integrator(std::string_view name, const ImplicitOptions& options = {});

/// The names make_integrator accepts.
std::vector<std::string> integrator_names();

// --- The time loop -----------------------------------------------------------------------------

/// One line of a run's history. The books balance: H(t) = H(0) + work_in − damping_dissipated −
/// integrator_dissipated. docs/10_linear_dynamics.md#energy
struct StepRecord {
    int step = 0;
    double time = 0.0;
    Energies energies;
    double work_in = 0.0;                ///< Σ so far of the energy the scene put in [J]: the hook's
                                         ///< changes (loads, force model) and the pins' boundary work
    double damping_dissipated = 0.0;     ///< Σ damping_work so far [J]
    double integrator_dissipated = 0.0;  ///< H(0) + work_in − H(t) − damping_dissipated: what the
                                         ///< integrator itself removed (> 0) or added (< 0) [J]
    int solver_iterations = 0;           ///< of this step
    int newton_iterations = 0;           ///< of this step (a nonlinear integrator's)
    double seconds = 0.0;                ///< wall time of this step's hook and integrator [s]
};

/// The divergence rule: a run fails when H − W_in (its total energy less what the scene put in) has
/// risen above H(0) by more than this fraction of the largest energy magnitude T + U + |W| seen so
/// far. A stable integrator never raises it by more than a round-off or O(Δt²) share of that; an
/// unstable one multiplies H every step and crosses the line within a few steps of becoming visible.
inline constexpr double divergence_energy_fraction = 0.5;
/// … and above the elastic energy Y V s² of a uniform strain s of this size (Y: Young's modulus, V:
/// the body's volume): a rise below it is the round-off of the positions (a strain of ~10⁴ ε), not
/// growth, e.g. in a body at rest under no load whose energies are 10⁻³⁰ J.
inline constexpr double divergence_roundoff_strain = 1e-12;

/// Moves a body in time with one integrator and watches every step. docs/10_linear_dynamics.md#the-time-loop
class Simulation {
public:
    /// Called at step 0 and after every step with the new state and its record.
    using Observer = std::function<void(const State&, const StepRecord&)>;

    /// The step hook: called before every step with the body, the state at t and the step's end
    /// time t + Δt. It may set the body's pin velocity and applied loads (Body::set_pin_velocity,
    /// set_applied_loads) and change the force model (a model that switches between others, as the
    /// scenes runner's). It returns true when it changed the loads or the model, i.e. H at the same
    /// (u, v): the loop then evaluates the model at u again and books H_after − H_before as work in.
    /// Moving the pins changes nothing at t; their work is booked by the step (StepInfo::boundary_work).
    /// docs/10_linear_dynamics.md#the-step-hook
    using BeforeStep = std::function<bool(Body& body, const State& state, double step_end)>;

    /// Steps of Δt = body.time_step() (the scene's; Body::set_time_step changes it between runs).
    /// fem::Error if the state does not fit the body.
    Simulation(Body& body, Integrator& integrator, State initial);

    /// Sets the step hook (empty: none, the default): the scene's moving pins, loads and model.
    void set_before_step(BeforeStep hook) { before_step_ = std::move(hook); }

    /// Runs `steps` steps (≥ 0), calling observer (if any) at step 0 of the first run and after every
    /// step. fem::Error when a step fails or the run diverges: a non-finite u, v or energy, or the
    /// divergence rule above; the message names the step, the time, the integrator and the energy
    /// growth, and the observer never sees that state (no NaN frame is ever written).
    void run(int steps, const Observer& observer = {});

    const State& state() const { return state_; }
    const StepRecord& last() const { return last_; }
    double time_step() const { return body_.time_step(); }

private:
    Body& body_;
    Integrator& integrator_;
    State state_;
    BeforeStep before_step_;
    double initial_total_ = 0.0;
    double largest_magnitude_ = 0.0;
    double roundoff_energy_ = 0.0;  // Y V s², s = divergence_roundoff_strain
    StepRecord last_;
    bool started_ = false;
};

/// The energy a step hook puts in (the teaching piece of Simulation::run): H = energies(body,
/// state).total() before, then hook(body, state, step_end); when it returns true (it changed the loads
/// or the force model), the model is evaluated at u again (state.forces and state.elastic_energy)
/// and the work in is H_after − H_before; when it returns false, 0. A change of the load by δf at u
/// puts in −δfᵀu (the load potential's jump); a switch of the model, U_new(u) − U_old(u).
/// docs/10_linear_dynamics.md#the-step-hook
double apply_step_hook(const Simulation::BeforeStep& hook, Body& body, State& state, double step_end);

/// The threads table of one time step (common/threads_study.hpp): each call steps a copy of `start`
/// by Δt with `integrator` and returns its displacement (3n), on 1 and 2 threads, quiet and beside a
/// busy core; `what` names the step in the title. The integrator must do the same work at every
/// call (a factor made before the table, or one made afresh each step), so that the times compare
/// and the bits can be compared. docs/10_linear_dynamics.md#threads
inline Table step_threads_table(const std::string& what, Body& body, Integrator& integrator, const State& start,
                                double time_step, double seconds)
{
    return threads_table(str(what, " on 1 and 2 threads, ", body.dofs().size(),
                             " free dofs, one step from the same state per call"),
                         [&] {
                             State state = start;
                             integrator.step(body, time_step, state);
                             return state.u;
                         },
                         seconds);
}

}  // namespace fem::dynamics
