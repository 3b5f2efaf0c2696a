// Chapter 08: dense LU with partial pivoting, triangular substitution, dense Cholesky, and the
// Hilbert matrix. docs/08_direct_solvers.md
#include "08_direct_solvers/dense_solvers.hpp"

#include "common/error.hpp"

#include <cmath>
#include <limits>
#include <utility>

namespace fem::direct {
namespace {

void require_square(const Eigen::MatrixXd& A, const char* what)
{
    if (A.rows() != A.cols() || A.rows() == 0)
        throw Error(str(what, ": the matrix is ", A.rows(), "×", A.cols(), "; it must be square and non-empty"));
}

void require_finite_entries(const Eigen::MatrixXd& A, const char* what)
{
    for (Eigen::Index j = 0; j < A.cols(); ++j)
        for (Eigen::Index i = 0; i < A.rows(); ++i)
            if (!std::isfinite(A(i, j)))
                throw Error(str(what, ": entry (", i, ", ", j, ") is ", A(i, j), "; every entry must be finite"));
}

void require_size(Eigen::Index expected, const Eigen::VectorXd& b, const char* what)
{
    if (b.size() != expected)
        throw Error(str(what, ": the right-hand side has ", b.size(), " entries, the matrix ", expected,
                        " rows"));
    for (Eigen::Index i = 0; i < b.size(); ++i)
        if (!std::isfinite(b[i]))
            throw Error(str(what, ": entry ", i, " of the right-hand side is ", b[i], "; every entry must be finite"));
}

void require_nonzero_diagonal(const Eigen::MatrixXd& T, const char* what)
{
    for (Eigen::Index i = 0; i < T.rows(); ++i)
        if (T(i, i) == 0.0 || !std::isfinite(T(i, i)))
            throw Error(str(what, ": diagonal entry ", i, " is ", T(i, i),
                            "; a triangular solve needs finite, non-zero diagonal entries"));
}

}  // namespace

Eigen::MatrixXd LuFactorization::L() const
{
    Eigen::MatrixXd L = LU.triangularView<Eigen::StrictlyLower>();
    L.diagonal().setOnes();
    return L;
}

Eigen::MatrixXd LuFactorization::U() const
{
    return LU.triangularView<Eigen::Upper>();
}

Eigen::MatrixXd LuFactorization::P() const
{
    Eigen::MatrixXd P = Eigen::MatrixXd::Zero(size(), size());
    for (int k = 0; k < size(); ++k)
        P(k, row_of[k]) = 1.0;
    return P;
}

LuFactorization lu_factor(const Eigen::MatrixXd& A)
{
    require_square(A, "LU");
    require_finite_entries(A, "LU");
    const int n = static_cast<int>(A.rows());
    // The singularity rule: a pivot that is round-off relative to its column of A.
    const double eps = std::numeric_limits<double>::epsilon();
    Eigen::VectorXd tiny(n);
    for (int j = 0; j < n; ++j)
        tiny[j] = n * eps * A.col(j).cwiseAbs().maxCoeff();

    LuFactorization F{A, std::vector<int>(n)};
    Eigen::MatrixXd& LU = F.LU;
    for (int k = 0; k < n; ++k)
        F.row_of[k] = k;
    for (int k = 0; k < n; ++k) {
        // BEGIN EXERCISE 08.1 lu_factor #lu-with-partial-pivoting
        // HINT: find the row p ≥ k with the largest |LU(p, k)|; swap rows k and p of LU (all n
        // HINT: columns: the multipliers already stored move with their row) and of F.row_of.
        // HINT: Then l_ik = LU(i, k) / LU(k, k) for i > k, and LU(i, j) −= l_ik LU(k, j) for j > k.
        int p = k;
        for (int i = k + 1; i < n; ++i)
            if (std::abs(LU(i, k)) > std::abs(LU(p, k)))
                p = i;
        if (p != k) {
            LU.row(k).swap(LU.row(p));
            std::swap(F.row_of[k], F.row_of[p]);
        }
        const double pivot = LU(k, k);
        for (int i = k + 1; i < n; ++i)
            LU(i, k) /= pivot;
        for (int j = k + 1; j < n; ++j) {
            const double u_kj = LU(k, j);
            for (int i = k + 1; i < n; ++i)  // down column j: contiguous in memory
                LU(i, j) -= LU(i, k) * u_kj;
        }
        // END EXERCISE
        if (!(std::abs(LU(k, k)) > tiny[k]))
            throw Error(str("LU: the matrix is singular to working precision: the pivot of column ", k,
                            " is ", LU(k, k), ", not above n ε max_i |a_ik| = ", tiny[k],
                            " (every candidate in that column was eliminated to round-off)"));
    }
    return F;
}

Eigen::VectorXd forward_substitution(const Eigen::MatrixXd& L, const Eigen::VectorXd& b, Diagonal diagonal)
{
    require_square(L, "forward substitution");
    require_size(L.rows(), b, "forward substitution");
    if (diagonal == Diagonal::stored)
        require_nonzero_diagonal(L, "forward substitution");
    const Eigen::Index n = L.rows();
    Eigen::VectorXd y = b;
    // BEGIN EXERCISE 08.2 forward_substitution #forward-and-back-substitution
    // HINT: column-oriented: once y_j is final, subtract y_j times column j below the diagonal
    // HINT: from the rest of y. With Diagonal::unit there is no division.
    for (Eigen::Index j = 0; j < n; ++j) {
        if (diagonal == Diagonal::stored)
            y[j] /= L(j, j);
        const double y_j = y[j];
        for (Eigen::Index i = j + 1; i < n; ++i)
            y[i] -= L(i, j) * y_j;
    }
    // END EXERCISE
    return y;
}

Eigen::VectorXd back_substitution(const Eigen::MatrixXd& U, const Eigen::VectorXd& y)
{
    require_square(U, "back substitution");
    require_size(U.rows(), y, "back substitution");
    require_nonzero_diagonal(U, "back substitution");
    const Eigen::Index n = U.rows();
    Eigen::VectorXd x = y;
    // BEGIN EXERCISE 08.3 back_substitution #forward-and-back-substitution
    // HINT: the same as forward substitution, from the last unknown up: once x_j is final,
    // HINT: subtract x_j times column j above the diagonal.
    for (Eigen::Index j = n - 1; j >= 0; --j) {
        x[j] /= U(j, j);
        const double x_j = x[j];
        for (Eigen::Index i = 0; i < j; ++i)
            x[i] -= U(i, j) * x_j;
    }
    // END EXERCISE
    return x;
}

Eigen::VectorXd lu_solve(const LuFactorization& F, const Eigen::VectorXd& b)
{
    require_size(F.LU.rows(), b, "LU solve");
    Eigen::VectorXd Pb(b.size());
    for (int k = 0; k < F.size(); ++k)
        Pb[k] = b[F.row_of[k]];
    return back_substitution(F.LU, forward_substitution(F.LU, Pb, Diagonal::unit));
}

Eigen::MatrixXd cholesky_factor(const Eigen::MatrixXd& A)
{
    require_square(A, "Cholesky");
    require_finite_entries(A, "Cholesky");
    const Eigen::Index n = A.rows();
    const double eps = std::numeric_limits<double>::epsilon();
    Eigen::MatrixXd L = Eigen::MatrixXd::Zero(n, n);
    for (Eigen::Index j = 0; j < n; ++j) {
        double pivot = 0.0;  // a_jj − Σ_{k<j} l_jk², set by the exercise
        // BEGIN EXERCISE 08.4 cholesky_factor #dense-cholesky
        // HINT: left-looking, column j: c_i = a_ij − Σ_{k<j} l_ik l_jk for i ≥ j (lower triangle of A
        // HINT: only; one matrix-vector product with the columns already done). The pivot is c_j
        // HINT: (store it in `pivot`), l_jj = √c_j, and l_ij = c_i / l_jj below the diagonal.
        const Eigen::Index below = n - j - 1;
        // rows j … n−1 of column j minus the contributions of the columns already done
        const Eigen::VectorXd column =
            A.col(j).tail(below + 1) - L.block(j, 0, below + 1, j) * L.row(j).head(j).transpose();
        pivot = column[0];
        L(j, j) = std::sqrt(std::max(pivot, 0.0));
        L.col(j).tail(below) = column.tail(below) / L(j, j);
        // END EXERCISE
        // A pivot that is round-off relative to a_jj means a singular (or indefinite) matrix.
        const double tiny = static_cast<double>(n) * eps * std::abs(A(j, j));
        if (!(pivot > tiny))
            throw Error(str("Cholesky: the matrix is not symmetric positive definite: the pivot of column ", j,
                            " is a_jj − Σ l_jk² = ", pivot, ", not above n ε |a_jj| = ", tiny));
    }
    return L;
}

Eigen::VectorXd cholesky_solve(const Eigen::MatrixXd& L, const Eigen::VectorXd& b)
{
    require_size(L.rows(), b, "Cholesky solve");
    const Eigen::MatrixXd Lt = L.transpose();
    return back_substitution(Lt, forward_substitution(L, b));
}

Eigen::MatrixXd hilbert_matrix(int n)
{
    if (n < 1 || n > 1000)
        throw Error(str("hilbert_matrix: n = ", n, "; allowed 1 ≤ n ≤ 1000"));
    Eigen::MatrixXd H(n, n);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
            H(i, j) = 1.0 / (i + j + 1);
    return H;
}

Eigen::VectorXd hilbert_row_sums(int n)
{
    if (n < 1 || n > 1000)
        throw Error(str("hilbert_row_sums: n = ", n, "; allowed 1 ≤ n ≤ 1000"));
    Eigen::VectorXd b(n);
    for (int i = 0; i < n; ++i) {
        long double sum = 0.0L;
        for (int j = 0; j < n; ++j)
            sum += 1.0L / (i + j + 1);
        b[i] = static_cast<double>(sum);
    }
    return b;
}

double hilbert_condition_number(int n)
{
    if (n < 1 || n > 20)
        throw Error(str("hilbert_condition_number: n = ", n, "; allowed 1 ≤ n ≤ 20"));
    const auto binomial = [](int a, int b) {
        long double c = 1.0L;
        for (int k = 1; k <= b; ++k)
            c = c * (a - b + k) / k;
        return c;
    };
    long double norm_H = 0.0L, norm_inverse = 0.0L;  // largest absolute column sums
    for (int j = 0; j < n; ++j) {
        long double column = 0.0L, column_inverse = 0.0L;
        for (int i = 0; i < n; ++i) {
            column += 1.0L / (i + j + 1);
            const long double c = binomial(i + j, i);
            column_inverse += (i + j + 1) * binomial(n + i, n - j - 1) * binomial(n + j, n - i - 1) * c * c;
        }
        norm_H = std::max(norm_H, column);
        norm_inverse = std::max(norm_inverse, column_inverse);
    }
    return static_cast<double>(norm_H * norm_inverse);
}

}  // namespace fem::direct
