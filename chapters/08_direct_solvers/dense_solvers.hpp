#pragma once
// Chapter 08: dense direct solvers. docs/08_direct_solvers.md
//
// The lecture's recipe for A x = b with a constant A: decompose A once (expensive, O(n³)), then
// solve for each new b with one forward and one back substitution (cheap, O(n²)).
//   LU with partial pivoting   P A = L U   for any non-singular square A;
//   Cholesky                   A = L Lᵀ    for a symmetric positive definite A (half the work,
//                                          no pivoting, and it fails exactly when A is not SPD).
// Matrices are Eigen's column-major MatrixXd; the loops run down columns (contiguous memory).

#include <Eigen/Core>

#include <vector>

namespace fem::direct {

/// The factors of P A = L U in one matrix, as LAPACK stores them: U on and above the diagonal,
/// the multipliers of L strictly below it (L's unit diagonal is not stored), and the row
/// permutation P as a list: row k of P A is row row_of[k] of A.
/// docs/08_direct_solvers.md#lu-with-partial-pivoting
struct LuFactorization {
    Eigen::MatrixXd LU;
    std::vector<int> row_of;

    int size() const { return static_cast<int>(LU.rows()); }
    /// L (n×n, unit lower triangular), copied out of LU.
    Eigen::MatrixXd L() const;
    /// U (n×n, upper triangular), copied out of LU.
    Eigen::MatrixXd U() const;
    /// P (n×n permutation matrix) with P(k, row_of[k]) = 1, so that P A = L U.
    Eigen::MatrixXd P() const;
};

/// P A = L U by Gaussian elimination with partial pivoting: at step k the row with the largest
/// |entry| in column k (rows k … n−1) is swapped into row k, the multipliers l_ik = a_ik / a_kk
/// are stored below the diagonal and the trailing block is updated, a_ij −= l_ik a_kj. Every
/// multiplier has |l_ik| ≤ 1. (2/3) n³ flops.
/// fem::Error for an empty or non-square A, a non-finite entry, or a matrix that is singular to
/// working precision: the pivot of column k (the largest candidate) has |u_kk| ≤ n ε max_i |a_ik|,
/// i.e. it is round-off relative to the original column k; the message names column k and the
/// pivot. docs/08_direct_solvers.md#lu-with-partial-pivoting
LuFactorization lu_factor(const Eigen::MatrixXd& A);

/// Whether a triangular matrix's diagonal is stored or is implicitly all ones (L of an LU).
enum class Diagonal { stored, unit };

/// Solves L y = b for a lower triangular L (n×n) by forward substitution,
/// y_i = (b_i − Σ_{j<i} l_ij y_j) / l_ii, reading only the entries on and below the diagonal
/// (strictly below with Diagonal::unit, where l_ii = 1). n² flops. fem::Error for a non-square L,
/// a size mismatch, or a zero diagonal entry (naming the row).
/// docs/08_direct_solvers.md#forward-and-back-substitution
Eigen::VectorXd forward_substitution(const Eigen::MatrixXd& L, const Eigen::VectorXd& b,
                                     Diagonal diagonal = Diagonal::stored);

/// Solves U x = y for an upper triangular U (n×n) by back substitution,
/// x_i = (y_i − Σ_{j>i} u_ij x_j) / u_ii for i = n−1 … 0, reading only the entries on and above
/// the diagonal. n² flops. fem::Error for a non-square U, a size mismatch or a zero diagonal entry.
/// docs/08_direct_solvers.md#forward-and-back-substitution
Eigen::VectorXd back_substitution(const Eigen::MatrixXd& U, const Eigen::VectorXd& y);

/// x with A x = b from P A = L U: L y = P b (forward), U x = y (back). fem::Error if b has not n
/// entries. docs/08_direct_solvers.md#forward-and-back-substitution
Eigen::VectorXd lu_solve(const LuFactorization& F, const Eigen::VectorXd& b);

/// The Cholesky factor L (lower triangular, positive diagonal) of a symmetric positive definite A,
/// A = L Lᵀ, column by column: l_jj = √(a_jj − Σ_{k<j} l_jk²), l_ij = (a_ij − Σ_{k<j} l_ik l_jk) / l_jj
/// for i > j. Reads only the lower triangle of A (as LAPACK's dpotrf). n³/3 flops, no pivoting.
/// fem::Error for an empty, non-square or non-finite A, and when A is not SPD to working
/// precision: the pivot a_jj − Σ l_jk² of column j is ≤ n ε |a_jj| (negative: indefinite; round-off
/// of a_jj: singular); the message names the column and the pivot. docs/08_direct_solvers.md#dense-cholesky
Eigen::MatrixXd cholesky_factor(const Eigen::MatrixXd& A);

/// x with A x = b from A = L Lᵀ: L y = b (forward), Lᵀ x = y (back). fem::Error for a size mismatch.
/// docs/08_direct_solvers.md#dense-cholesky
Eigen::VectorXd cholesky_solve(const Eigen::MatrixXd& L, const Eigen::VectorXd& b);

/// The n×n Hilbert matrix H_ij = 1 / (i + j + 1) (0-based), symmetric positive definite and
/// notoriously ill-conditioned (κ grows like e^{3.5 n}). fem::Error unless 1 ≤ n ≤ 1000.
/// docs/08_direct_solvers.md#ill-conditioning-the-hilbert-matrix
Eigen::MatrixXd hilbert_matrix(int n);

/// b = H (1, …, 1)ᵀ for the n×n Hilbert matrix, b_i = Σ_j 1 / (i + j + 1), summed in long double
/// and rounded once: a right-hand side whose exact solution is x = (1, …, 1) up to b's own
/// rounding, so the error of a computed x measures the solver alone. fem::Error unless
/// 1 ≤ n ≤ 1000. docs/08_direct_solvers.md#ill-conditioning-the-hilbert-matrix
Eigen::VectorXd hilbert_row_sums(int n);

/// The exact 1-norm condition number κ₁(H) = ‖H‖₁ ‖H⁻¹‖₁ of the n×n Hilbert matrix, from the
/// closed form of its inverse, (H⁻¹)_ij = (−1)^{i+j} (i+j+1) C(n+i, n−j−1) C(n+j, n−i−1) C(i+j, i)²
/// (0-based), evaluated in long double. fem::Error unless 1 ≤ n ≤ 20.
/// docs/08_direct_solvers.md#ill-conditioning-the-hilbert-matrix
double hilbert_condition_number(int n);

}  // namespace fem::direct
