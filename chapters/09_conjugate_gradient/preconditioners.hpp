#pragma once
// Chapter 09: preconditioners for CG, each a LinearOperator that applies M⁻¹.
// docs/09_conjugate_gradient.md#preconditioning
//
// PCG solves A x = b with the help of an SPD M ≈ A that is cheap to invert: the iteration count
// then grows like √κ(M⁻¹A) instead of √κ(A). Two classics:
//   Jacobi   M = diag(A): z_i = r_i / A_ii. Free to build and apply; fixes bad row scaling.
//   IC(0)    M = L Lᵀ, the Cholesky factor computed only on the pattern of A's lower triangle
//            (no fill-in): "incomplete" Cholesky with zero extra entries. Two triangular solves
//            per application; far fewer iterations on Laplacians and stiffness matrices.
//
// IC(0) exists for every M-matrix (e.g. the Laplacians) but can break down on other SPD matrices
// (a pivot A_ii − Σ L_ik² ≤ 0), e.g. a stiffness matrix K. The strategy here (Manteuffel's shift):
// if a pivot falls to ic0_pivot_floor × its diagonal or below, factor A + α diag(A) instead, with
// α = 0 first, then ic0_initial_shift, doubling up to ic0_max_shift_doublings times. A large
// enough α makes A + α diag(A) diagonally dominant, for which IC(0) cannot break down.
// docs/09_conjugate_gradient.md#incomplete-cholesky-ic0

#include "09_conjugate_gradient/linear_operator.hpp"

#include "07_sparse_storage/sparse_formats.hpp"

#include <Eigen/Core>

namespace fem::cg {

/// IC(0) breaks down in row i when its pivot d_i = (1 + α) A_ii − Σ_{k<i} L_ik² is at most this
/// fraction of (1 + α) A_ii: below it, d_i is within a few orders of magnitude of the round-off
/// of the cancellation that produced it, and 1/L_ii would blow up that row of M⁻¹.
inline constexpr double ic0_pivot_floor = 1e-8;
/// The first diagonal shift α tried after IC(0) of A itself broke down.
inline constexpr double ic0_initial_shift = 1e-3;
/// How often α is doubled before giving up: the last α tried is 10⁻³ · 2²⁰ ≈ 1049.
inline constexpr int ic0_max_shift_doublings = 20;

/// Jacobi: M = diag(A), applied as z_i = r_i / d_i. fem::Error (naming the index) unless every
/// d_i is finite and > 0, which holds for the diagonal of any SPD matrix.
/// docs/09_conjugate_gradient.md#jacobi
class JacobiPreconditioner final : public LinearOperator {
public:
    explicit JacobiPreconditioner(const Eigen::VectorXd& diagonal);
    Eigen::Index size() const override { return inverse_diagonal_.size(); }
    /// z = D⁻¹ r. fem::Error for a wrong size of r or z the same vector as r.
    void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const override;

private:
    Eigen::VectorXd inverse_diagonal_;  // 1 / d_i
};

/// One attempt at IC(0): the factor on the lower pattern, or where it broke down.
struct IcAttempt {
    sparse::CsrMatrix L;     ///< lower triangular, the pattern of A's lower triangle, diagonal last
    int breakdown_row = -1;  ///< −1: success; else the row whose pivot fell to the floor
    double pivot = 0.0;      ///< that pivot d_i (≤ ic0_pivot_floor · (1 + α) A_ii)
};

/// IC(0) of A + shift · diag(A): L has exactly the pattern of `lower` (A's lower triangle with the
/// diagonal, canonical CSR, diagonal the last entry of each row), and L Lᵀ equals A + shift·diag(A)
/// on that pattern. Row by row, for each stored j < i:
///     L_ij = (A_ij − Σ_{k<j} L_ik L_jk) / L_jj,   then   L_ii = √((1 + shift) A_ii − Σ_{k<i} L_ik²),
/// the sums running only over the stored entries. Stops at the first row i whose pivot is
/// ≤ ic0_pivot_floor · (1 + shift) A_ii and reports it in breakdown_row (no exception).
/// fem::Error if lower is not square, not valid CSR, not lower triangular, lacks a positive diagonal
/// entry in some row (named), or if shift is negative or not finite.
/// docs/09_conjugate_gradient.md#incomplete-cholesky-ic0
IcAttempt incomplete_cholesky_factor(const sparse::CsrMatrix& lower, double shift);

/// Forward substitution L y = r in place (x holds r on entry, y on exit) for L lower triangular
/// in CSR with the diagonal last in each row: y_i = (r_i − Σ_{j<i} L_ij y_j) / L_ii, a gather
/// along row i. fem::Error for a size mismatch or a row whose last entry is not a non-zero diagonal.
/// docs/09_conjugate_gradient.md#triangular-solves
void solve_lower(const sparse::CsrMatrix& L, Eigen::VectorXd& x);

/// Backward substitution Lᵀ z = y in place (x holds y on entry, z on exit) with the same CSR L:
/// row i of L is column i of Lᵀ, so the solve runs i = n−1 … 0, sets z_i = y_i / L_ii and then
/// scatters y_j −= L_ij z_i for the stored j < i. Errors as solve_lower.
/// docs/09_conjugate_gradient.md#triangular-solves
void solve_lower_transposed(const sparse::CsrMatrix& L, Eigen::VectorXd& x);

/// How IncompleteCholesky handles a breakdown.
struct IcSettings {
    bool allow_shift = true;                       ///< false: a breakdown is an fem::Error
    double initial_shift = ic0_initial_shift;      ///< first α after α = 0 failed
    int max_doublings = ic0_max_shift_doublings;   ///< α doubles at most this often
};

/// IC(0) as a preconditioner: M = L Lᵀ with L = incomplete_cholesky_factor(lower(A), α), α the
/// first of 0, initial_shift, 2·initial_shift, … that does not break down; apply() solves
/// L Lᵀ z = r by solve_lower and solve_lower_transposed. A may store both triangles (only the lower
/// one is read). fem::Error for a non-square or invalid A, a missing or non-positive diagonal
/// entry, a breakdown with allow_shift = false (naming the row and pivot), or if every shift
/// broke down. docs/09_conjugate_gradient.md#incomplete-cholesky-ic0
class IncompleteCholesky final : public LinearOperator {
public:
    explicit IncompleteCholesky(const sparse::CsrMatrix& A, const IcSettings& settings = {});
    Eigen::Index size() const override { return L_.rows; }
    /// z = (L Lᵀ)⁻¹ r. fem::Error for a wrong size of r or z the same vector as r.
    void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const override;

    const sparse::CsrMatrix& factor() const { return L_; }  ///< L
    double shift() const { return shift_; }                  ///< the α that worked (0: none needed)
    int attempts() const { return attempts_; }               ///< factorisations tried (1: no breakdown)

private:
    sparse::CsrMatrix L_;
    double shift_ = 0.0;
    int attempts_ = 0;
};

}  // namespace fem::cg
