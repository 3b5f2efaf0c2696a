// Chapter 09: Jacobi and incomplete Cholesky IC(0). docs/09_conjugate_gradient.md#preconditioning
#include "09_conjugate_gradient/preconditioners.hpp"

#include "common/error.hpp"

#include <cmath>
#include <vector>

namespace fem::cg {
namespace {

void check_apply(const char* where, Eigen::Index n, const Eigen::VectorXd& r, const Eigen::VectorXd& z)
{
    if (r.size() != n)
        throw Error(str(where, ": r has ", r.size(), " entries, the preconditioner is ", n, "×", n));
    if (&r == &z)
        throw Error(str(where, ": r and z are the same vector; apply(r, z) needs a separate output"));
}

/// fem::Error unless L is square, lower triangular CSR whose rows each end with a non-zero diagonal.
void check_triangular_factor(const sparse::CsrMatrix& L, const Eigen::VectorXd& x, const char* where)
{
    if (L.rows != L.cols || static_cast<int>(L.IA.size()) != L.rows + 1)
        throw Error(str(where, ": L is ", L.rows, "×", L.cols, " with ", L.IA.size(),
                        " row pointers; it must be square CSR"));
    if (x.size() != L.rows)
        throw Error(str(where, ": the vector has ", x.size(), " entries, L is ", L.rows, "×", L.cols));
    for (int i = 0; i < L.rows; ++i) {
        const int last = L.IA[i + 1] - 1;
        if (last < L.IA[i] || L.JA[last] != i || L.A[last] == 0.0)
            throw Error(str(where, ": row ", i, " of L does not end with a non-zero diagonal entry; L must be "
                            "lower triangular with its diagonal last in each row (as IC(0) makes it)"));
    }
}

}  // namespace

// --- Jacobi ------------------------------------------------------------------------------------

JacobiPreconditioner::JacobiPreconditioner(const Eigen::VectorXd& diagonal)
{
    for (Eigen::Index i = 0; i < diagonal.size(); ++i)
        if (!std::isfinite(diagonal[i]) || diagonal[i] <= 0.0)
            throw Error(str("JacobiPreconditioner: diagonal entry ", i, " is ", diagonal[i],
                            "; the diagonal of an SPD matrix is finite and > 0"));
    inverse_diagonal_ = diagonal.cwiseInverse();
}

void JacobiPreconditioner::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const
{
    check_apply("JacobiPreconditioner::apply", size(), r, z);
    z.resize(r.size());
    // BEGIN EXERCISE 09.2 JacobiPreconditioner #jacobi
    // HINT: M = diag(A), so M⁻¹ r divides each r_i by d_i: z_i = r_i · (1/d_i), stored in inverse_diagonal_.
    z = r.cwiseProduct(inverse_diagonal_);
    // END EXERCISE
}

// --- IC(0) -------------------------------------------------------------------------------------

IcAttempt incomplete_cholesky_factor(const sparse::CsrMatrix& lower, double shift)
{
    sparse::validate(lower);
    if (lower.rows != lower.cols)
        throw Error(str("incomplete_cholesky_factor: the matrix is ", lower.rows, "×", lower.cols,
                        "; it must be square"));
    if (!std::isfinite(shift) || shift < 0.0)
        throw Error(str("incomplete_cholesky_factor: the shift must be finite and ≥ 0, got ", shift));
    const int n = lower.rows;
    for (int i = 0; i < n; ++i) {
        const int last = lower.IA[i + 1] - 1;
        if (last >= lower.IA[i] && lower.JA[last] > i)
            throw Error(str("incomplete_cholesky_factor: row ", i, " stores column ", lower.JA[last],
                            " above the diagonal; pass the lower triangle (sparse::lower_triangle)"));
        if (last < lower.IA[i] || lower.JA[last] != i || !(lower.A[last] > 0.0))
            throw Error(str("incomplete_cholesky_factor: row ", i, " has no positive diagonal entry",
                            last >= lower.IA[i] && lower.JA[last] == i ? str(" (A_ii = ", lower.A[last], ")") : "",
                            "; an SPD matrix has A_ii > 0"));
    }

    IcAttempt attempt;
    attempt.L = lower;  // the same pattern; the values are overwritten row by row
    const std::vector<int>& IA = attempt.L.IA;
    const std::vector<int>& JA = attempt.L.JA;
    std::vector<double>& L = attempt.L.A;
    const std::vector<double>& A = lower.A;
    // BEGIN EXERCISE 09.3 incomplete_cholesky_factor #incomplete-cholesky-ic0
    // HINT: keep row i of L computed so far in a dense work vector w (w[k] = L_ik, zero elsewhere).
    // HINT: for each stored j < i, in increasing order: L_ij = (A_ij − Σ_k L_jk w[k]) / L_jj, the sum
    // HINT: over the stored k < j of row j (already finished); set w[j] = L_ij. Then the pivot
    // HINT: d = (1 + shift) A_ii − Σ_j L_ij²: if d ≤ ic0_pivot_floor · (1 + shift) A_ii, report row i
    // HINT: and d in the IcAttempt and return; else L_ii = √d. Clear w at row i's columns after the row.
    std::vector<double> w(static_cast<std::size_t>(n), 0.0);
    for (int i = 0; i < n; ++i) {
        const int diagonal = IA[i + 1] - 1;
        double sum_of_squares = 0.0;
        for (int k = IA[i]; k < diagonal; ++k) {
            const int j = JA[k];
            const int j_diagonal = IA[j + 1] - 1;
            double s = A[k];
            for (int q = IA[j]; q < j_diagonal; ++q)
                s -= L[q] * w[JA[q]];
            const double l_ij = s / L[j_diagonal];
            L[k] = l_ij;
            w[j] = l_ij;
            sum_of_squares += l_ij * l_ij;
        }
        const double shifted = (1.0 + shift) * A[diagonal];
        const double pivot = shifted - sum_of_squares;
        for (int k = IA[i]; k < diagonal; ++k)
            w[JA[k]] = 0.0;
        if (!(pivot > ic0_pivot_floor * shifted)) {
            attempt.breakdown_row = i;
            attempt.pivot = pivot;
            return attempt;
        }
        L[diagonal] = std::sqrt(pivot);
    }
    // END EXERCISE
    return attempt;
}

namespace {

// The two substitutions without the checks: IncompleteCholesky checked its factor once when it made
// it, and applies it in every iteration. solve_lower and solve_lower_transposed check, then call these.

void forward_substitution(const sparse::CsrMatrix& L, Eigen::VectorXd& x)
{
    const int* const IA = L.IA.data();
    const int* const JA = L.JA.data();
    const double* const values = L.A.data();
    double* const y = x.data();
    // BEGIN EXERCISE 09.4 solve_lower #triangular-solves
    // HINT: rows in increasing order; row i's entries before its diagonal (the last entry) multiply
    // HINT: the y_j already computed: y_i = (x_i − Σ_{j<i} L_ij y_j) / L_ii, written over x_i.
    for (int i = 0; i < L.rows; ++i) {
        const int diagonal = IA[i + 1] - 1;
        double s = y[i];
        for (int k = IA[i]; k < diagonal; ++k)
            s -= values[k] * y[JA[k]];
        // s · (1/L_ii) rather than s / L_ii: the division does not wait for s, so it leaves the
        // chain of dependent operations that limits this loop.
        y[i] = s * (1.0 / values[diagonal]);
    }
    // END EXERCISE
}

void backward_substitution(const sparse::CsrMatrix& L, Eigen::VectorXd& x)
{
    const int* const IA = L.IA.data();
    const int* const JA = L.JA.data();
    const double* const values = L.A.data();
    double* const z = x.data();
    // BEGIN EXERCISE 09.5 solve_lower_transposed #triangular-solves
    // HINT: Lᵀ is upper triangular and row i of L is its column i. Go i = n−1 … 0: when you reach i,
    // HINT: every z_j with j > i has already been subtracted, so z_i = x_i / L_ii; then scatter
    // HINT: x_j −= L_ij z_i for the stored j < i of row i.
    for (int i = L.rows - 1; i >= 0; --i) {
        const int diagonal = IA[i + 1] - 1;
        const double zi = z[i] * (1.0 / values[diagonal]);
        z[i] = zi;
        for (int k = IA[i]; k < diagonal; ++k)
            z[JA[k]] -= values[k] * zi;
    }
    // END EXERCISE
}

}  // namespace

void solve_lower(const sparse::CsrMatrix& L, Eigen::VectorXd& x)
{
    check_triangular_factor(L, x, "solve_lower");
    forward_substitution(L, x);
}

void solve_lower_transposed(const sparse::CsrMatrix& L, Eigen::VectorXd& x)
{
    check_triangular_factor(L, x, "solve_lower_transposed");
    backward_substitution(L, x);
}

IncompleteCholesky::IncompleteCholesky(const sparse::CsrMatrix& A, const IcSettings& settings)
{
    sparse::validate(A);
    if (A.rows != A.cols)
        throw Error(str("IncompleteCholesky: the matrix is ", A.rows, "×", A.cols, "; it must be square"));
    if (!std::isfinite(settings.initial_shift) || settings.initial_shift <= 0.0 || settings.max_doublings < 0)
        throw Error(str("IncompleteCholesky: the initial shift must be finite and > 0 and the number of "
                        "doublings ≥ 0, got ", settings.initial_shift, " and ", settings.max_doublings));
    const sparse::CsrMatrix lower = sparse::lower_triangle(A);
    double shift = 0.0;
    const int max_attempts = settings.allow_shift ? settings.max_doublings + 2 : 1;
    for (int attempt = 1; attempt <= max_attempts; ++attempt) {
        IcAttempt result = incomplete_cholesky_factor(lower, shift);
        attempts_ = attempt;
        if (result.breakdown_row < 0) {
            L_ = std::move(result.L);
            shift_ = shift;
            return;
        }
        if (!settings.allow_shift)
            throw Error(str("IncompleteCholesky: IC(0) broke down in row ", result.breakdown_row, ": pivot ",
                            result.pivot, " ≤ ", ic0_pivot_floor, " × A_ii. The matrix is SPD only if IC(0) "
                            "of it is not guaranteed (it is for M-matrices); allow the diagonal shift "
                            "(IcSettings::allow_shift) to factor A + α diag(A) instead"));
        if (attempt == max_attempts)
            throw Error(str("IncompleteCholesky: IC(0) of A + α diag(A) still broke down at α = ", shift,
                            " (row ", result.breakdown_row, ", pivot ", result.pivot, ") after ", attempt,
                            " attempts; is A symmetric positive definite?"));
        shift = attempt == 1 ? settings.initial_shift : 2.0 * shift;
    }
}

void IncompleteCholesky::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const
{
    check_apply("IncompleteCholesky::apply", size(), r, z);
    z = r;
    forward_substitution(L_, z);   // L was checked when it was made
    backward_substitution(L_, z);
}

}  // namespace fem::cg
