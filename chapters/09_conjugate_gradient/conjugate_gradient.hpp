#pragma once
// Chapter 09: the conjugate gradient method and its preconditioned form.
// docs/09_conjugate_gradient.md
//
// For a symmetric positive definite A, solving A x = b is minimising the energy
// φ(x) = ½ xᵀA x − bᵀx, whose gradient is −r = A x − b. CG walks along search directions p_k
// that are A-conjugate (p_iᵀ A p_k = 0 for i ≠ k), minimising φ exactly along each; in exact
// arithmetic it reaches x after at most n steps, and after k steps its error is the best one in
// the Krylov space span{r₀, A r₀, …, A^{k−1} r₀}. In floating point it is an iterative method:
//     ‖x − x_k‖_A ≤ 2 ((√κ − 1)/(√κ + 1))^k ‖x − x₀‖_A,   κ = λ_max / λ_min,
// so about ½ √κ ln(2/τ) iterations reduce the error by τ. docs/09_conjugate_gradient.md#convergence
//
// One iteration: one product A p, two dot products, three vector updates (plus one application
// of M⁻¹ and one more dot product with a preconditioner). Memory: five vectors.

#include "09_conjugate_gradient/linear_operator.hpp"

#include <Eigen/Core>

#include <functional>
#include <vector>

namespace fem::cg {

/// The default stopping rule: ‖b − A x_k‖₂ ≤ default_relative_tolerance · ‖b‖₂.
inline constexpr double default_relative_tolerance = 1e-8;
/// The default iteration cap is iteration_cap_per_unknown · n (n = A.size()): exact arithmetic
/// needs at most n, round-off can delay convergence beyond that, and 2n is Eigen's choice too.
inline constexpr int iteration_cap_per_unknown = 2;

/// How PCG turns the new preconditioned residual z_{k+1} = M⁻¹ r_{k+1} into the next direction
/// p_{k+1} = z_{k+1} + β_k p_k. docs/09_conjugate_gradient.md#flexible-pcg
enum class CgBeta {
    /// β_k = r_{k+1}ᵀz_{k+1} / r_kᵀz_k (Fletcher–Reeves): the classical CG and PCG, right when M⁻¹
    /// is one fixed symmetric positive definite matrix (the identity, Jacobi, IC(0) in double).
    fletcher_reeves,
    /// β_k = z_{k+1}ᵀ(r_{k+1} − r_k) / r_kᵀz_k (Polak–Ribière): flexible PCG (Golub and Ye 1999,
    /// Notay 2000), for an M⁻¹ that is not exactly linear or symmetric or that changes from one
    /// application to the next (a factor applied in single precision, an inner iteration). For a
    /// fixed SPD M⁻¹, z_{k+1}ᵀr_k = 0 and the two β agree; Polak–Ribière costs one more stored
    /// vector (r_k) and one more dot product per iteration.
    polak_ribiere,
};

/// When CG stops, and who watches it.
struct CgSettings {
    /// Stop at the first k with ‖r_k‖₂ ≤ relative_tolerance · ‖b‖₂ (r_k the updated residual).
    /// Relative to ‖b‖, not to ‖r₀‖: a good warm start then needs fewer iterations, not more.
    double relative_tolerance = default_relative_tolerance;
    /// The iteration cap; 0 means iteration_cap_per_unknown · n.
    int max_iterations = 0;
    /// Called with (k, x_k, ‖r_k‖/‖b‖) for k = 0 (the start) and after every iteration, if set:
    /// e.g. to record the error against a known solution. It must not change CG's vectors.
    std::function<void(int iteration, const Eigen::VectorXd& x, double relative_residual)> observer;
    /// The formula of β (PCG; for plain CG, z = r, the two differ only by round-off).
    CgBeta beta = CgBeta::fletcher_reeves;
};

/// What a CG run did.
struct CgResult {
    bool converged = false;      ///< the stopping rule was met within the cap
    int iterations = 0;          ///< iterations done (products A p; 0 if x₀ already satisfied the rule)
    /// The true relative residual ‖b − A x‖₂ / ‖b‖₂ of the returned x, recomputed at the end (the
    /// updated residual of the history can drift below it by round-off).
    /// docs/09_conjugate_gradient.md#round-off
    double relative_residual = 0.0;
    /// ‖r_k‖₂ / ‖b‖₂ of the updated residual for k = 0 … iterations (iterations + 1 entries).
    std::vector<double> residual_history;
    /// The step lengths α_k = r_kᵀz_k / p_kᵀA p_k (one per iteration) and the ratios β_k of
    /// CgSettings::beta (one per new search direction): the Lanczos coefficients that
    /// lanczos_extreme_eigenvalues turns into eigenvalue estimates (for a fixed SPD M⁻¹).
    std::vector<double> alpha;
    std::vector<double> beta;
};

/// Conjugate gradients for A x = b, A symmetric positive definite. x holds the starting guess on
/// entry (a warm start; an empty x means x₀ = 0) and the solution on exit. With r₀ = b − A x₀,
/// p₀ = r₀, for k = 0, 1, …:
///     α_k = r_kᵀr_k / p_kᵀA p_k,  x_{k+1} = x_k + α_k p_k,  r_{k+1} = r_k − α_k A p_k,
///     β_k = r_{k+1}ᵀr_{k+1} / r_kᵀr_k,  p_{k+1} = r_{k+1} + β_k p_k,
/// until ‖r_k‖ ≤ relative_tolerance · ‖b‖ or the cap (then converged = false; no exception).
/// b = 0 returns x = 0 at once. fem::Error if sizes disagree, b or x₀ is not finite, the
/// tolerance is not in (0, 1) or the cap is negative, and when p_kᵀA p_k ≤ 0 (or not finite):
/// A is then not positive definite, and the message names the iteration k and the value.
/// docs/09_conjugate_gradient.md#the-conjugate-gradient-method
CgResult conjugate_gradient(const LinearOperator& A, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                            const CgSettings& settings = {});

/// Preconditioned CG with M⁻¹ given as an operator (e.g. JacobiPreconditioner,
/// IncompleteCholesky): the same loop with z_k = M⁻¹ r_k taking r_k's place in α, β and p:
///     α_k = r_kᵀz_k / p_kᵀA p_k,  β_k = r_{k+1}ᵀz_{k+1} / r_kᵀz_k,  p_{k+1} = z_{k+1} + β_k p_k,
/// or, with settings.beta = CgBeta::polak_ribiere (flexible PCG, for an M⁻¹ that is not exactly a
/// fixed SPD matrix), β_k = z_{k+1}ᵀ(r_{k+1} − r_k) / r_kᵀz_k.
/// The stopping rule still measures ‖r_k‖₂, so runs with different M compare directly. Errors as
/// conjugate_gradient, plus a size mismatch of M and r_kᵀz_k ≤ 0 (M⁻¹ not positive definite).
/// docs/09_conjugate_gradient.md#preconditioning
CgResult preconditioned_conjugate_gradient(const LinearOperator& A, const LinearOperator& M_inverse,
                                           const Eigen::VectorXd& b, Eigen::VectorXd& x,
                                           const CgSettings& settings = {});

/// The smallest and largest Ritz value of a CG run, estimates of λ_min and λ_max of M⁻¹A.
struct SpectrumEstimate {
    double lambda_min = 0.0;
    double lambda_max = 0.0;
    double condition() const { return lambda_max / lambda_min; }  ///< κ estimate
};

/// CG's coefficients are the Lanczos process in disguise: the k×k tridiagonal matrix T with
///     T_jj = 1/α_j + β_{j−1}/α_{j−1}  (β_{−1}/α_{−1} := 0),   T_{j,j+1} = T_{j+1,j} = √β_j / α_j
/// has eigenvalues (Ritz values) inside [λ_min, λ_max] of M⁻¹A, whose extreme ones converge to
/// λ_min and λ_max within a few dozen iterations. So every CG run estimates κ for free.
/// fem::Error if the run did no iteration, if beta has fewer than alpha.size() − 1 entries, or a
/// coefficient is not finite and positive. docs/09_conjugate_gradient.md#condition-number-from-cg
SpectrumEstimate lanczos_extreme_eigenvalues(const CgResult& run);

/// The bound on the iterations CG needs to reduce the A-norm error by τ: the smallest k with
/// 2 ((√κ − 1)/(√κ + 1))^k ≤ τ, about ½ √κ ln(2/τ). fem::Error unless κ ≥ 1 and 0 < τ < 1.
/// docs/09_conjugate_gradient.md#convergence
int iteration_bound(double condition_number, double tau);

}  // namespace fem::cg
