// Chapter 09: conjugate gradients, preconditioned CG, and the Lanczos estimate of κ.
// docs/09_conjugate_gradient.md
#include "09_conjugate_gradient/conjugate_gradient.hpp"

#include "common/error.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>

namespace fem::cg {
namespace {

void check_inputs(const char* where, const LinearOperator& A, const LinearOperator* M_inverse,
                  const Eigen::VectorXd& b, const Eigen::VectorXd& x, const CgSettings& settings)
{
    const Eigen::Index n = A.size();
    if (b.size() != n)
        throw Error(str(where, ": b has ", b.size(), " entries, A is ", n, "×", n));
    if (x.size() != 0 && x.size() != n)
        throw Error(str(where, ": the starting guess x has ", x.size(), " entries, A is ", n, "×", n,
                        " (pass an empty x to start from 0)"));
    if (M_inverse && M_inverse->size() != n)
        throw Error(str(where, ": the preconditioner is ", M_inverse->size(), "×", M_inverse->size(), ", A is ", n,
                        "×", n));
    for (Eigen::Index i = 0; i < n; ++i) {
        if (!std::isfinite(b[i]))
            throw Error(str(where, ": b[", i, "] = ", b[i], " is not finite"));
        if (x.size() != 0 && !std::isfinite(x[i]))
            throw Error(str(where, ": the starting guess x[", i, "] = ", x[i], " is not finite"));
    }
    if (!(settings.relative_tolerance > 0.0 && settings.relative_tolerance < 1.0))
        throw Error(str(where, ": the relative tolerance must lie in (0, 1), got ", settings.relative_tolerance));
    if (settings.max_iterations < 0)
        throw Error(str(where, ": the iteration cap must be ≥ 0 (0: the default ", iteration_cap_per_unknown,
                        " n), got ", settings.max_iterations));
}

/// CG's safeguard: along a direction p with pᵀAp ≤ 0 the energy ½xᵀAx − bᵀx has no minimum.
void check_curvature(const char* where, int iteration, double pAp)
{
    if (!(pAp > 0.0))
        throw Error(str(where, ": pᵀAp = ", pAp, (std::isfinite(pAp) ? " ≤ 0" : " is not finite"),
                        " at iteration ", iteration,
                        ": the matrix is not positive definite (CG needs a symmetric positive definite A; "
                        "an indefinite A, or a singular one such as a stiffness matrix without pinned "
                        "vertices, has directions of zero or negative energy)"));
}

/// PCG's second safeguard: rᵀM⁻¹r ≤ 0 means the preconditioner is not positive definite.
void check_preconditioner(const char* where, int iteration, double rz)
{
    if (!(rz > 0.0))
        throw Error(str(where, ": rᵀM⁻¹r = ", rz, " at iteration ", iteration,
                        ": the preconditioner is not positive definite (or produced a non-finite value)"));
}

/// The loop shared by CG (M_inverse null: z = r) and PCG.
CgResult cg_loop(const LinearOperator& A, const LinearOperator* M_inverse, const Eigen::VectorXd& b,
                 Eigen::VectorXd& x, const CgSettings& settings)
{
    const char* const where = M_inverse ? "preconditioned_conjugate_gradient" : "conjugate_gradient";
    check_inputs(where, A, M_inverse, b, x, settings);
    const Eigen::Index n = A.size();
    if (x.size() == 0)
        x = Eigen::VectorXd::Zero(n);
    CgResult result;
    const double b_norm = b.norm();
    if (b_norm == 0.0) {  // the solution of A x = 0 is x = 0, whatever the start
        x.setZero();
        result.converged = true;
        result.residual_history = {0.0};
        if (settings.observer)
            settings.observer(0, x, 0.0);
        return result;
    }
    const long long cap = settings.max_iterations > 0 ? settings.max_iterations
                                                       : iteration_cap_per_unknown * static_cast<long long>(n);
    const double threshold = settings.relative_tolerance * b_norm;
    const auto record = [&](int k, double r_norm) {
        result.residual_history.push_back(r_norm / b_norm);
        if (settings.observer)
            settings.observer(k, x, r_norm / b_norm);
    };
    const auto precondition = [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
        if (M_inverse)
            M_inverse->apply(r, z);
        else
            z = r;
    };

    const bool flexible = settings.beta == CgBeta::polak_ribiere;
    Eigen::VectorXd r(n), z(n), p(n), q(n), r_old;  // r_old: r_k, kept for Polak–Ribière's β only
    // BEGIN EXERCISE 09.1 conjugate_gradient #the-conjugate-gradient-method
    // HINT: r = b − A x, z = M⁻¹ r (precondition), p = z, rz = rᵀz; record(0, ‖r‖).
    // HINT: while ‖r‖ > threshold and k < cap: q = A p; check_curvature(where, k, pᵀq); α = rz / pᵀq;
    // HINT: x += α p; r −= α q (if flexible, keep r_old = r first); k += 1; record(k, ‖r‖) and push α
    // HINT: onto result.alpha; stop if converged; z = M⁻¹ r; rz_new = rᵀz (check_preconditioner(where,
    // HINT: k, rz_new)); β = rz_new / rz, or (rz_new − r_oldᵀz) / rz if flexible (Polak–Ribière),
    // HINT: pushed onto result.beta; p = z + β p; rz = rz_new. Set result.iterations and result.converged.
    A.apply(x, q);
    r = b - q;
    double r_norm = r.norm();
    record(0, r_norm);
    precondition(r, z);
    double rz = r.dot(z);
    int k = 0;
    if (r_norm > threshold)
        check_preconditioner(where, 0, rz);
    p = z;
    while (r_norm > threshold && k < cap) {
        A.apply(p, q);
        const double pAp = p.dot(q);
        check_curvature(where, k, pAp);
        const double alpha = rz / pAp;
        x += alpha * p;
        if (flexible)
            r_old = r;
        r -= alpha * q;
        r_norm = r.norm();
        ++k;
        record(k, r_norm);
        result.alpha.push_back(alpha);
        if (r_norm <= threshold)
            break;
        precondition(r, z);
        const double rz_new = r.dot(z);
        check_preconditioner(where, k, rz_new);
        const double beta = (flexible ? rz_new - r_old.dot(z) : rz_new) / rz;
        result.beta.push_back(beta);
        p = z + beta * p;
        rz = rz_new;
    }
    result.iterations = k;
    result.converged = r_norm <= threshold;
    // END EXERCISE

    // The true residual of the returned x (one more product), not the updated one.
    A.apply(x, q);
    result.relative_residual = (b - q).norm() / b_norm;
    // NaN compares false with everything: a NaN in A or in the preconditioner would otherwise end
    // the loop at once and come back as a quiet "not converged".
    if (!std::isfinite(result.relative_residual) || !x.allFinite())
        throw Error(str(where, ": the residual is not finite after ", result.iterations,
                        " iterations: A or the preconditioner holds a NaN or an infinity"));
    return result;
}

}  // namespace

CgResult conjugate_gradient(const LinearOperator& A, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                            const CgSettings& settings)
{
    return cg_loop(A, nullptr, b, x, settings);
}

CgResult preconditioned_conjugate_gradient(const LinearOperator& A, const LinearOperator& M_inverse,
                                           const Eigen::VectorXd& b, Eigen::VectorXd& x,
                                           const CgSettings& settings)
{
    return cg_loop(A, &M_inverse, b, x, settings);
}

SpectrumEstimate lanczos_extreme_eigenvalues(const CgResult& run)
{
    const std::size_t k = run.alpha.size();
    if (k == 0)
        throw Error("lanczos_extreme_eigenvalues: the CG run did no iteration, so it holds no estimate "
                    "(start from x = 0 with b ≠ 0)");
    if (run.beta.size() + 1 < k)
        throw Error(str("lanczos_extreme_eigenvalues: ", k, " step lengths α need at least ", k - 1,
                        " ratios β, got ", run.beta.size()));
    for (std::size_t j = 0; j < k; ++j)
        if (!(std::isfinite(run.alpha[j]) && run.alpha[j] > 0.0) ||
            (j + 1 < k && !(std::isfinite(run.beta[j]) && run.beta[j] > 0.0)))
            throw Error(str("lanczos_extreme_eigenvalues: coefficient ", j, " is not finite and positive (α = ",
                            run.alpha[j], j + 1 < k ? str(", β = ", run.beta[j]) : std::string(), ")"));
    SpectrumEstimate estimate;
    // BEGIN EXERCISE 09.6 lanczos_extreme_eigenvalues #condition-number-from-cg
    // HINT: diagonal d_j = 1/α_j + β_{j−1}/α_{j−1} (no second term for j = 0), off-diagonal
    // HINT: e_j = √β_j / α_j for j = 0 … k−2; Eigen::SelfAdjointEigenSolver::computeFromTridiagonal
    // HINT: returns the eigenvalues in increasing order (scale T to entries of order 1 first: its
    // HINT: convergence test is not scale invariant).
    Eigen::VectorXd d(static_cast<Eigen::Index>(k));
    Eigen::VectorXd e(static_cast<Eigen::Index>(k > 1 ? k - 1 : 0));
    for (std::size_t j = 0; j < k; ++j) {
        d[static_cast<Eigen::Index>(j)] = 1.0 / run.alpha[j] + (j > 0 ? run.beta[j - 1] / run.alpha[j - 1] : 0.0);
        if (j + 1 < k)
            e[static_cast<Eigen::Index>(j)] = std::sqrt(run.beta[j]) / run.alpha[j];
    }
    // Eigen's tridiagonal QR deflates when |e_j| ≤ ε √(|d_j| + |d_j+1|), a test that is not scale
    // invariant: scale T to entries of order 1 first, and the eigenvalues back afterwards.
    const double scale = d.cwiseAbs().maxCoeff();
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver;
    solver.computeFromTridiagonal(d / scale, e / scale, Eigen::EigenvaluesOnly);
    if (solver.info() != Eigen::Success)
        throw Error(str("lanczos_extreme_eigenvalues: the eigenvalues of the ", k, "×", k,
                        " tridiagonal matrix did not converge"));
    estimate.lambda_min = scale * solver.eigenvalues().minCoeff();
    estimate.lambda_max = scale * solver.eigenvalues().maxCoeff();
    // END EXERCISE
    return estimate;
}

int iteration_bound(double condition_number, double tau)
{
    if (!(std::isfinite(condition_number) && condition_number >= 1.0))
        throw Error(str("iteration_bound: the condition number must be finite and ≥ 1, got ", condition_number));
    if (!(tau > 0.0 && tau < 1.0))
        throw Error(str("iteration_bound: the reduction τ must lie in (0, 1), got ", tau));
    const double root = std::sqrt(condition_number);
    const double rate = (root - 1.0) / (root + 1.0);
    if (rate <= 0.0)
        return 1;  // κ = 1: one step is exact
    return static_cast<int>(std::ceil(std::log(tau / 2.0) / std::log(rate)));
}

}  // namespace fem::cg
