#pragma once
// Chapter 10: vibration modes, the scalar oscillator every mode obeys, and the answers they give.
// docs/10_linear_dynamics.md#modes
//
// On the free dofs the undamped body M ü + K u = 0 has the modes K φ = ω² M φ (the generalized
// symmetric eigenproblem), φᵢᵀ M φⱼ = δᵢⱼ. Rayleigh damping D = α M + β K is diagonal in the same
// basis, so each modal coordinate q = φᵀ M u obeys the scalar damped oscillator
//     q̈ + 2 ξ ω q̇ + ω² q = 0,        ξ = α/(2ω) + β ω/2,
// and every θ-step (time_integration.hpp) acts on (q, p = q̇) as one 2×2 matrix G(ω, ξ, Δt, θ). This
// makes the modes the chapter's exact references: the simulated tip of a body started in mode φ₁
// must follow Gⁿ to round-off; backward Euler's amplitude factor per step is 1/√(1 + ω²Δt²); the
// exact semi-discrete motion is the sum of exact damped oscillators; explicit Euler is stable
// only for Δt < 2/ω_max.

#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace fem::dynamics {

/// Modes of (K, M): omega ascending (rad/s), shapes one column per mode, M-orthonormal.
struct Modes {
    Eigen::VectorXd omega;
    Eigen::MatrixXd shapes;
};

/// The `count` lowest modes by a dense generalized eigensolver (Eigen's
/// GeneralizedSelfAdjointEigenSolver on the full matrices): the reference, for n up to a few
/// thousand. fem::Error unless K and M are square of one size n ≥ count ≥ 1, M is positive
/// definite and K positive semi-definite. docs/10_linear_dynamics.md#modes
Modes lowest_modes_dense(const SparseMatrix& K, const SparseMatrix& M, int count);

/// The `count` lowest modes of large sparse (K, M) by shift-invert Lanczos (Spectra's
/// SymGEigsShiftSolver, σ = 0: the Lanczos vectors are made with K⁻¹ M, one sparse Cholesky of K),
/// converged to 1e-10 relative. fem::Error as lowest_modes_dense, or if Lanczos does not converge.
/// K must be positive definite (pin something). docs/10_linear_dynamics.md#modes
Modes lowest_modes(const SparseMatrix& K, const SparseMatrix& M, int count);

/// ω_max, the largest ω of K φ = ω² M φ, by Lanczos (Spectra's SymGEigsSolver on (K, M) with M
/// Cholesky-factored), to 1e-10 relative. fem::Error as lowest_modes_dense.
/// docs/10_linear_dynamics.md#the-explicit-stability-limit
double highest_frequency(const SparseMatrix& K, const SparseMatrix& M);

/// What power_iteration found.
struct PowerIteration {
    double omega = 0.0;   ///< √ of the last Rayleigh quotient (a lower bound on ω_max)
    int iterations = 0;
    bool converged = false;  ///< the quotient changed by less than the tolerance (relative)
};

/// ω_max by power iteration on M⁻¹K with a lumped (diagonal) M given as its diagonal `masses`:
/// y = M⁻¹ K x, x = y / ‖y‖, ω² ≈ xᵀ K x / xᵀ M x, from a fixed start vector (all ones plus an
/// alternating sign, so that the high modes are present). With λ = ω², λ_max the largest and λ′ the
/// second largest, the iterate x converges like (λ′/λ_max)^k and the Rayleigh quotient twice as fast,
/// like (λ′/λ_max)^(2k) = (ω′/ω_max)^(4k): slowly on fine meshes all the same, where λ′/λ_max → 1,
/// which is why highest_frequency uses Lanczos.
/// fem::Error unless sizes match, masses > 0, tolerance in (0, 1), max_iterations ≥ 1.
/// docs/10_linear_dynamics.md#the-explicit-stability-limit
PowerIteration power_iteration(const SparseMatrix& K, const Eigen::VectorXd& masses, double tolerance = 1e-8,
                               int max_iterations = 10000);

/// The modal damping ratio ξ = α/(2ω) + β ω/2 of Rayleigh damping at ω > 0.
double damping_ratio(const Damping& damping, double omega);

/// The largest Δt at which symplectic Euler is stable for a mode (ω, ξ):
///   Δt_max = (2/ω) (√(1 + ξ²) − ξ),
/// 2/ω undamped; damping lowers it (the explicit damping force overshoots too). Applied at ω_max
/// with ξ = damping_ratio(damping, ω_max). fem::Error unless ω > 0 and ξ ≥ 0, finite.
/// docs/10_linear_dynamics.md#the-explicit-stability-limit
double explicit_stability_limit(double omega, double xi = 0.0);

/// G, the 2×2 matrix of one θ-step on the modal oscillator q̈ + 2ξω q̇ + ω² q = 0:
/// (q⁺, p⁺) = G (q, p) with q⁺ = q + Δt (θ p⁺ + (1−θ) p) and
/// p⁺ = p − Δt [ω² (θ q⁺ + (1−θ) q) + 2ξω (θ p⁺ + (1−θ) p)]. Backward Euler (θ = 1, ξ = 0) has the
/// eigenvalues 1/(1 ∓ iωΔt): modulus 1/√(1 + ω²Δt²), angle atan(ωΔt) per step.
/// fem::Error unless ω ≥ 0, ξ ≥ 0, Δt > 0, θ ∈ [½, 1]. docs/10_linear_dynamics.md#one-mode-one-oscillator
Eigen::Matrix2d oscillator_step_matrix(double omega, double xi, double time_step, double theta = 1.0);

/// The 2×2 matrix of one symplectic Euler step on the same oscillator: p⁺ = p − Δt (ω² q + 2ξω p),
/// q⁺ = q + Δt p⁺. Same checks as oscillator_step_matrix.
Eigen::Matrix2d symplectic_oscillator_step_matrix(double omega, double xi, double time_step);

/// How closely a body follows one mode's recurrence: starting at rest in `start` (3n, a mode shape
/// φ times an amplitude), runs `steps` steps of integrator (Δt: the body's) and returns
///   max_n |u_dof(n) − (Gⁿ (1, 0)ᵀ)₀ · start_dof| / max_n |u_dof(n)|,
/// G the integrator's 2×2 step matrix on that mode (oscillator_step_matrix and its kin). Round-off
/// for an exact G. fem::Error for a dof outside [0, 3n), steps < 1, or what the run raises.
/// docs/10_linear_dynamics.md#one-mode-one-oscillator
double modal_recurrence_deviation(Body& body, Integrator& integrator, const Eigen::VectorXd& start, Eigen::Index dof,
                                  const Eigen::Matrix2d& G, int steps);

/// The exact (q(t), q̇(t)) of the damped oscillator from (q₀, p₀) at t = 0, for every ξ ≥ 0
/// (under-, critically and over-damped). fem::Error unless ω > 0, ξ ≥ 0, t finite.
Eigen::Vector2d exact_oscillator(double omega, double xi, double q0, double p0, double t);

/// The exact motion of a linear body under a constant load, by superposition of all its modes
/// (dense, for small meshes): with the static solution u_s = K⁻¹ f,
///     u(t) = u_s + Σ_k φ_k q_k(t),   q_k(0) = φ_kᵀ M (u₀ − u_s),   q̇_k(0) = φ_kᵀ M v₀,
/// each q_k the exact damped oscillator (ω_k, ξ_k). Exact in time for the semi-discrete equations,
/// it is the reference that measures an integrator's time error alone.
/// docs/10_linear_dynamics.md#speed-against-error
class ModalSolution {
public:
    /// K, M (n×n, the free dofs), f, u0, v0 (n). fem::Error as lowest_modes_dense (with count = n),
    /// for mismatched sizes or a damping outside the lecture's range.
    ModalSolution(const SparseMatrix& K, const SparseMatrix& M, const Eigen::VectorXd& f, const Damping& damping,
                  const Eigen::VectorXd& u0, const Eigen::VectorXd& v0);

    Eigen::VectorXd displacement(double t) const;  ///< u(t) (n)
    /// One entry u_dof(t), in O(n) instead of O(n²). fem::Error for a dof outside [0, n).
    double displacement(double t, Eigen::Index dof) const;
    const Modes& modes() const { return modes_; }
    const Eigen::VectorXd& static_solution() const { return static_; }

private:
    Modes modes_;
    Eigen::VectorXd xi_, q0_, p0_, static_;
    Eigen::Vector2d coordinate(Eigen::Index k, double t) const;
};

/// The Euler–Bernoulli first bending frequency of a cantilever [Hz]:
///   f₁ = (β₁² / 2π) √(E I / (ρ A L⁴)),  β₁ = 1.8751 (the first root of cos β cosh β = −1),
/// I the second moment of the cross-section about the bending axis, A its area.
/// fem::Error unless every argument is finite and > 0. docs/10_linear_dynamics.md#frequency-against-beam-theory
double euler_bernoulli_first_frequency(double youngs_modulus, double density, double length, double area,
                                       double second_moment);

}  // namespace fem::dynamics
