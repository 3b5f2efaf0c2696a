#pragma once
// Chapter 12: backward Euler as a minimisation, solved by Newton's method with a backtracking line
// search (notes 001, "Backward Euler as optimisation" to "Line Search"), as a chapter 10 integrator.
// docs/12_hyperelastic_newton.md#backward-euler-as-minimisation
//
// The step from (qᵗ, q̇ᵗ) finds the velocity v that minimises
//     E(v) = ½ (v − q̇ᵗ)ᵀ M (v − q̇ᵗ) + U(qᵗ + Δt v) − Δt vᵀ f_ext + (Δt/2) vᵀ D v,
// and sets q⁺ = qᵗ + Δt v, q̇⁺ = v. Its gradient ∇E = M (v − q̇ᵗ) − Δt (f(qᵗ + Δt v) + f_ext − D v) is
// zero exactly at the backward Euler step; its Hessian is M + Δt D + Δt² K(qᵗ + Δt v). D = α M + β K_t
// is Rayleigh damping with K_t the (positive semi-definite) tangent at the step's start, fixed over
// the step (StepDamping). Pinned dofs move with the body's pin velocity ṽ_p (v_p = ṽ_p, not unknowns).
// The notes write the
// kinetic term with qᵗ instead of q̇ᵗ, drop the Δt in the update, and loop while ‖∇E‖ is *below*
// the tolerance; all three are corrected here (docs: where the notes slip).

#include "12_hyperelastic_newton/hyperelastic.hpp"

#include "10_linear_dynamics/time_integration.hpp"

#include "09_conjugate_gradient/linear_solver.hpp"

#include <Eigen/Core>

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace fem::hyper {

/// Which Hessian a Newton iteration solves with (docs/12_hyperelastic_newton.md#definiteness).
enum class HessianChoice {
    exact_then_definite,  ///< M + Δt² K; if that is not positive definite (the factorization fails or
                          ///< d is no descent direction), M + Δt² K_PSD (the default: quadratic
                          ///< convergence wherever the exact Hessian allows it)
    definite,             ///< always M + Δt² K_PSD (ForceModel::definite_stiffness): safe, linear
                          ///< convergence where the projection changed K
    exact,                ///< always M + Δt² K: fails with fem::Error where K is too indefinite
};

/// Every constant of the Newton step, named once (docs/12_hyperelastic_newton.md#newton-with-line-search).
struct NewtonOptions {
    double relative_tolerance = 1e-6;  ///< stop when ‖∇E‖ ≤ this × the step's momentum scale
    int max_iterations = 50;           ///< Newton iterations per step before fem::Error
    double armijo = 1e-4;              ///< c: accept α when E(v + αd) ≤ E(v) + c α ∇Eᵀd
    double shrink = 0.5;               ///< α ← shrink · α after a rejected trial
    double smallest_step = 1e-10;      ///< a line search that needs α below this fails (fem::Error)
    /// Also converged when the Newton direction d is this small: ‖d‖∞ ≤ step_tolerance (x's units;
    /// for a step, a velocity: a fraction of d̂ / Δt bounds every vertex's last move), after taking
    /// its step, beside the gradient's test (IPC's test on the step's length). 0: the gradient's
    /// test alone (the default). docs/15_body_contact.md#the-cost-of-contact
    double step_tolerance = 0.0;
    bool line_search = true;           ///< false: plain Newton, α = 1 always (to show what it risks)
    /// The volume filter of NewtonBackwardEuler's line search: its trials start at α ≤ the largest
    /// step that keeps every tet's volume ≥ this fraction of its volume at the iterate
    /// (largest_volume_keeping_step), so no accepted iterate turns a tet inside out, whatever the
    /// material. In [0, 1); 0: off (and off without the line search). docs/12_hyperelastic_newton.md#the-volume-filter
    double kept_volume = 0.1;
    HessianChoice hessian = HessianChoice::exact_then_definite;
    /// Inexact Newton: an iterative solver solves H d = −∇E only to the relative residual
    /// max(its own tolerance, min(forcing, ‖∇E‖/scale)) — loose far from the answer, tight near it,
    /// where η = O(‖∇E‖) keeps the convergence quadratic (Eisenstat and Walker 1996). 0: always to
    /// its own tolerance. A direct solver solves exactly either way. In [0, 1).
    double forcing = 0.01;
    std::string solver = "default";    ///< chapter 09's solver of H d = −∇E
    /// When set, the solver is made by this instead of cg::make_solver(solver): e.g. chapter 11's
    /// frozen-factor PCG, which keeps one factorization across Newton iterations and steps.
    std::function<std::unique_ptr<cg::LinearSolver>()> make_solver;
};

/// The relative round-off of the objective: the line search accepts a trial whose E misses the
/// Armijo line by less than this times the size of E's terms (|kinetic| + |U| + |work|), where a
/// difference of E says nothing. Near convergence that is what keeps a step from failing.
inline constexpr double objective_round_off = 1e-13;

/// How far below the size of E's terms a change of E can be lost in E's round-off: the terms of a
/// body's elastic energy cancel to first order in the strain (the neo-Hookean μ tr H against −μ ln J),
/// so U's round-off can be far above objective_round_off × |U| (seen: 20× in a contact step of the
/// bunny, ~70× in a resting block at small Δt). Where both E's change and the decrease Armijo asks
/// for are below this × its terms, E's test passes or fails by its round-off, so the line search
/// decides with slopes instead: E(x + αd) − E(x) ≈ α (∇E(x)ᵀd + ∇E(x + αd)ᵀd)/2, the trapezoid
/// rule, exact for a quadratic E, from gradients, which hold no cancelling constant (Hager and
/// Zhang's approximate Wolfe condition, 2005). docs/12_hyperelastic_newton.md#newton-with-line-search
inline constexpr double objective_resolution = 1e-10;

/// The smallest gradient norm newton_minimize can measure: √(smallest normal double) ≈ 1.5·10⁻¹⁵⁴.
/// Below it the squares in a norm underflow, and products such as ∇Eᵀd vanish, so the relative
/// test says nothing: a motion that has decayed this far (a vibration damped out without gravity,
/// after a few hundred steps) is at rest in any units, and the iteration has converged.
inline const double smallest_measurable_norm = std::sqrt(std::numeric_limits<double>::min());

/// Rayleigh damping over one backward Euler step: D = α M + β K_t (3n×3n), with α, β the scene's and
/// K_t = ForceModel::definite_stiffness(qᵗ) the positive semi-definite tangent at the step's start,
/// fixed over the step. D is symmetric positive semi-definite, so E's term (Δt/2) vᵀ D v is convex
/// and the energy it removes, Δt vᵀ D v, is never negative: damping cannot add energy, which the
/// exact K(qᵗ) of an indefinite material could. For a linear body K_t = K, chapter 10's D.
/// docs/12_hyperelastic_newton.md#rayleigh-damping
class StepDamping {
public:
    /// No damping: D = 0 (for an undamped body).
    StepDamping() = default;
    /// D of body.scene().damping at the start displacement u_start (3n): keeps a copy of
    /// definite_stiffness(u_start) when β ≠ 0 (one assembly per step), nothing more when β = 0.
    StepDamping(dynamics::Body& body, const Eigen::VectorXd& u_start);

    const dynamics::Damping& coefficients() const { return coefficients_; }
    /// D v = α M v + β K_t v (3n). fem::Error unless v has M's size.
    Eigen::VectorXd times(const Eigen::VectorXd& v) const;
    /// K_t (3n×3n; empty when β = 0).
    const dynamics::SparseMatrix& start_stiffness() const { return K_start_; }

private:
    dynamics::Damping coefficients_;
    const dynamics::SparseMatrix* M_ = nullptr;
    dynamics::SparseMatrix K_start_;
};

/// An energy P(u) the incremental potential gains beyond the elastic U and the loads: a term of E
/// that a later chapter adds without changing this one (chapter 14's contact barrier and friction).
/// Like U it is a function of the displacement u = q (3n) at the step's end, so E(v) gains
/// P(qᵗ + Δt v), ∇E gains Δt ∇P and the Hessian Δt² ∇²P. It may be +∞ (infeasible: a vertex
/// inside an obstacle); then it says, for a Newton direction, how far the line search may go
/// before P becomes infinite (largest_safe_step), and the line search starts there instead of at 1.
/// docs/12_hyperelastic_newton.md#an-extra-potential
class StepPotential {
public:
    virtual ~StepPotential() = default;
    /// Called once before each step's Newton iterations with the state at t and Δt: what the
    /// potential lags or adapts over a step is fixed here (default: nothing).
    virtual void begin_step(dynamics::Body& body, const dynamics::State& state, double time_step)
    {
        (void)body, (void)state, (void)time_step;
    }
    /// P(u) [J] (u: 3n); +∞ where the potential is undefined.
    virtual double energy(const Eigen::VectorXd& u) const = 0;
    /// ∇P(u) (3n) [N].
    virtual Eigen::VectorXd gradient(const Eigen::VectorXd& u) const = 0;
    /// A positive semi-definite ∇²P(u) (3n×3n) [N/m] whose entries lie in the 3×3 blocks of vertices
    /// that share a tet (the pattern of every stiffness matrix of the course holds them).
    virtual dynamics::SparseMatrix hessian(const Eigen::VectorXd& u) const = 0;
    /// ∇²P(u) as it is, possibly indefinite (3n×3n, the same blocks as hessian): what Newton adds to
    /// the exact K when it tries the exact Hessian first (HessianChoice::exact_then_definite, exact);
    /// the definite Hessian takes hessian(u). Default: hessian(u) (a potential with no other).
    virtual dynamics::SparseMatrix exact_hessian(const Eigen::VectorXd& u) const { return hessian(u); }
    /// The largest α in (0, 1] with P finite on the whole segment u + s·du, s ∈ [0, α], shrunk by
    /// a safety factor (default: 1, a potential that is finite everywhere).
    virtual double largest_safe_step(const Eigen::VectorXd& u, const Eigen::VectorXd& du) const
    {
        (void)u, (void)du;
        return 1.0;
    }
    /// The velocity v (3n) the step's search starts from before it tries the last velocity: the
    /// step's motion from qᵗ to qᵗ + Δt v must be one the potential allows (P finite at the end,
    /// nothing it guards crossed on the way; its pinned entries are replaced by the pins' own).
    /// Called after begin_step. Default: v = 0, the positions of the step's start.
    virtual Eigen::VectorXd start_velocity(const dynamics::Body& body, const dynamics::State& state,
                                           double time_step) const
    {
        (void)body, (void)time_step;
        return Eigen::VectorXd::Zero(state.v.size());
    }
};

/// E(v) of the header comment for the full velocity v (3n), with model's energy at qᵗ + Δt v
/// (+∞ where the model is undefined) and damping's D; magnitude (if given) receives
/// |½ΔvᵀMΔv| + |U| + |Δt vᵀf_ext| + (Δt/2) vᵀDv, the scale of E's round-off. fem::Error on sizes,
/// Δt ≤ 0, or a damping whose α, β are not the body's (a damped body needs StepDamping(body, qᵗ)).
double backward_euler_objective(dynamics::Body& body, const dynamics::State& state, double time_step,
                                const Eigen::VectorXd& v, double* magnitude = nullptr,
                                const StepDamping& damping = {});

/// ∇E(v) = M (v − q̇ᵗ) − Δt (f(qᵗ + Δt v) + f_ext − D v) (3n; pinned entries included: there it is
/// Δt times the reaction the pins exert). fem::Error on sizes, Δt ≤ 0, a damping whose α, β are not
/// the body's, or where the model is undefined.
Eigen::VectorXd backward_euler_gradient(dynamics::Body& body, const dynamics::State& state, double time_step,
                                        const Eigen::VectorXd& v, const StepDamping& damping = {});

/// The scale the gradient is measured against: ‖M q̇ᵗ‖ + Δt ‖f_ext‖ + Δt ‖f(qᵗ)‖ over the free dofs
/// (momentum: the inertia and the loads of the step), plus ‖M ṽ_p‖ + Δt ‖f(qᵗ + Δt ṽ_p)‖ over the
/// free dofs when the pins move (what their step pushes into the body; one model evaluation). A
/// step that starts at rest under no load with the pins at rest has scale 0 and a zero gradient: it
/// is converged at once.
double momentum_scale(dynamics::Body& body, const dynamics::State& state, double time_step);

/// A minimisation problem for newton_minimize, on the free unknowns x (free dofs of a body).
struct NewtonProblem {
    std::function<double(const Eigen::VectorXd& x, double* magnitude)> objective;  ///< +∞ outside the
                                                      ///< domain; magnitude: the size of its terms
    std::function<Eigen::VectorXd(const Eigen::VectorXd& x)> gradient;
    /// The Hessian at x, exact or made positive semi-definite (definite = true): a reference to a
    /// matrix the problem keeps (refilled in its fixed pattern), valid until the next call.
    std::function<const dynamics::SparseMatrix&(const Eigen::VectorXd& x, bool definite)> hessian;
    /// Optional: the largest step length α ≤ 1 along d from x that keeps the objective finite (a
    /// StepPotential's continuous collision check); the line search starts there instead of at 1.
    std::function<double(const Eigen::VectorXd& x, const Eigen::VectorXd& d)> largest_step;
    double scale = 0.0;   ///< converged when ‖gradient‖ ≤ relative_tolerance × scale
    std::string what;     ///< names the problem in error messages, e.g. "step 12 (t = 0.2 s)"
};

/// What newton_minimize did.
struct NewtonResult {
    Eigen::VectorXd x;
    int iterations = 0, solver_iterations = 0, definite_fallbacks = 0;
    std::vector<double> gradient_history;  ///< ‖gradient‖ / scale at each iterate (the first: at x₀;
                                           ///< none at the last one when step_tolerance stopped it)
    std::vector<double> step_lengths;      ///< the α the line search accepted
};

/// Newton's method with a backtracking (Armijo) line search from x₀ (where the objective must be
/// finite): solve H d = −∇ with `solver`, the Hessian chosen as options.hessian says, take the
/// largest α = shrinkᵏ with objective(x + αd) ≤ objective(x) + c α ∇ᵀd (+ its round-off; where the
/// change is below objective_resolution × E's terms, the same test by the trapezoid rule on
/// slopes), until
/// ‖∇‖ ≤ tolerance × scale (or ≤ smallest_measurable_norm), or, with options.step_tolerance > 0,
/// until the step of a direction with ‖d‖∞ ≤ step_tolerance is taken. fem::Error naming problem.what when
/// the cap is reached, the line search fails, or no Hessian gives a descent direction. When the
/// problem has a largest_step, the trials start at α = largest_step(x, d) instead of 1.
/// docs/12_hyperelastic_newton.md#newton-with-line-search
NewtonResult newton_minimize(const NewtonProblem& problem, Eigen::VectorXd x0, const NewtonOptions& options,
                             cg::LinearSolver& solver);

/// The static equilibrium of a body under its loads: the minimiser of U(u) − f_extᵀu over the free
/// dofs by newton_minimize from u = 0, the gradient measured against ‖f_ext‖. Returns u (3n).
/// docs/12_hyperelastic_newton.md#statics
Eigen::VectorXd solve_static(dynamics::Body& body, const NewtonOptions& options = {});

/// Backward Euler by Newton's method with a backtracking (Armijo) line search, for any force model
/// (chapter 10's linear one converges in one iteration), with the scene's Rayleigh damping
/// (StepDamping) and the body's moving pins. docs/12_hyperelastic_newton.md#newton-with-line-search
class NewtonBackwardEuler final : public dynamics::Integrator {
public:
    /// fem::Error for a tolerance outside (0, 1), a cap < 1, c outside (0, ½), shrink outside (0, 1),
    /// a smallest step outside (0, 1), a step tolerance < 0 or not finite, a kept volume outside
    /// [0, 1), or an unknown solver.
    explicit NewtonBackwardEuler(NewtonOptions options = {});

    std::string name() const override { return "Newton backward Euler"; }
    int order() const override { return 1; }
    /// One step: Newton iterations from v = q̇ᵗ (or v = 0 when E(q̇ᵗ) = +∞) on the free dofs until
    /// ‖∇E‖ ≤ tol · momentum_scale, the pinned dofs held at v = ṽ_p (Body::pin_velocity), so
    /// q⁺_p = qᵗ_p + Δt ṽ_p. With a potential: from the potential's start_velocity v₀, moved toward
    /// q̇ᵗ as far as its largest_safe_step allows, and the scale raised by Δt ‖∇P‖ at that start.
    /// With options.kept_volume > 0 the start (moved from v = 0 or v₀ toward q̇ᵗ) and every line
    /// search are also cut by the volume filter (largest_volume_keeping_step): a tet of positive
    /// volume at qᵗ keeps a positive volume at every iterate, and a step the filter cuts at a tet
    /// squeezed below collapsed_volume_ratio of its rest volume is refused (fem::Error naming the tet
    /// and the material: one whose energy stays finite at det F = 0 cannot stop that impact).
    /// StepInfo::damping_work = Δt v⁺ᵀ D v⁺ (≥ 0) [J]; when the pins move,
    /// StepInfo::boundary_work = Δt ṽ_pᵀ r_p = ṽ_pᵀ ∇E(v⁺) (the reactions r_p = ∇E_p(v⁺)/Δt) [J]. fem::Error (state
    /// unchanged) when the cap is reached, the line search fails, or d is no descent direction (an
    /// indefinite Hessian: use a projection).
    dynamics::StepInfo step(dynamics::Body& body, double time_step, dynamics::State& state) override;

    /// What the last step's Newton iterations did (gradient norms relative to the momentum scale,
    /// step lengths, fallbacks to the definite Hessian).
    const NewtonResult& last() const { return last_; }
    /// The solver of Newton's systems (made from the options).
    const cg::LinearSolver& solver() const { return *solver_; }
    /// Adds potential's P(q⁺) to every later step's E (nullptr: none, the default). Not owned: it
    /// must outlive the steps. Each step calls its begin_step first, starts Newton from the part of
    /// v = q̇ᵗ that largest_safe_step allows from v = 0, and cuts every line search by it.
    void set_potential(StepPotential* potential) { potential_ = potential; }

private:
    NewtonOptions options_;
    std::unique_ptr<cg::LinearSolver> solver_;
    std::optional<dynamics::ReducedStepMatrix> reduced_;  // M + Δt² K on the free dofs, pattern fixed
    const dynamics::Body* reduced_body_ = nullptr;
    NewtonResult last_;
    StepPotential* potential_ = nullptr;
};

}  // namespace fem::hyper
