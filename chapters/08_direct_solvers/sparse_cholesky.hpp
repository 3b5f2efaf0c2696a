#pragma once
// Chapter 08: sparse Cholesky factorization A = Pᵀ L Lᵀ P on the CSC matrices of chapter 07.
// docs/08_direct_solvers.md#sparse-cholesky
//
// Four steps, each a function below:
//   1. ordering       P from orderings.hpp, and C = P A Pᵀ (symmetric_permutation);
//   2. symbolic       the elimination tree of C and the number of nonzeros of every column of L
//                     (elimination_tree, column_counts, symbolic_cholesky): the exact memory of L
//                     before a single flop;
//   3. numeric        L from C: up-looking, one row of L at a time by a sparse triangular solve
//                     (up_looking_cholesky, the exercise route), or supernodal/multifrontal with
//                     dense blocks (SparseCholesky's fast path);
//   4. solve          L y = P b, Lᵀ z = y, x = Pᵀ z: twice nnz(L) multiply-adds per right-hand side.
// Steps 1–3 run once; step 4 as often as b changes (the lecture's "A does not change!").
//
// Symmetric matrices are given by their lower triangle: every function reads the entries A_ij with
// i ≥ j and ignores those above the diagonal, so a matrix stored with both triangles (as chapter
// 06 assembles K) and one stored as its lower triangle give the same factor.

#include "08_direct_solvers/orderings.hpp"

#include "07_sparse_storage/sparse_formats.hpp"

#include "common/error.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <string>
#include <vector>

namespace fem::direct {

/// The upper triangle (i ≤ j) of C = P A Pᵀ in CSC, rows sorted in each column, built from the
/// lower triangle of A: C(k, l) = A(perm[k], perm[l]). Column k of this matrix holds row k of C's
/// lower triangle, which is what the up-looking factorization and the elimination tree read.
/// fem::Error for a non-square or invalid A or a bad permutation.
/// docs/08_direct_solvers.md#permuting-a-symmetric-matrix
sparse::CscMatrix symmetric_permutation(const sparse::CscMatrix& A, const Permutation& perm);

/// The elimination tree of a symmetric matrix C given by its upper triangle (CSC): parent[j] is the
/// row index of the first off-diagonal nonzero of column j of L (the smallest i > j with L_ij ≠ 0),
/// −1 for a root. Liu's algorithm: for each column k and each C_ik ≠ 0, i < k, climb from i
/// towards the root (with path compression through `ancestor`) and hang the top under k.
/// O(nnz(C) log n). fem::Error for a non-square C. docs/08_direct_solvers.md#the-elimination-tree
std::vector<int> elimination_tree(const sparse::CscMatrix& C_upper);

/// A postorder of a forest: post[k] is the k-th vertex visited by a depth-first search that
/// numbers every child before its parent (children in increasing order). Renumbering the unknowns
/// by it keeps the fill and makes every subtree a contiguous range. fem::Error for a parent index
/// outside [−1, n) or a cycle. docs/08_direct_solvers.md#the-elimination-tree
std::vector<int> tree_postorder(const std::vector<int>& parent);

/// The number of nonzeros in each column j of L, diagonal included, for C given by its upper
/// triangle and its elimination tree: row k of L has nonzeros at the vertices of the "row
/// subtree" — the paths from each i with C_ik ≠ 0, i < k, up the tree until k (or a vertex
/// already marked for row k). Counting them column by column costs O(nnz(L)).
/// fem::Error if parent has the wrong size. docs/08_direct_solvers.md#symbolic-factorization
std::vector<int> column_counts(const sparse::CscMatrix& C_upper, const std::vector<int>& parent);

/// What the symbolic factorization of C = P A Pᵀ knows before any numeric work.
struct SymbolicCholesky {
    int n = 0;
    Permutation perm;                 ///< the ordering used, perm[new] = old
    std::vector<int> parent;          ///< elimination tree of C
    std::vector<int> counts;          ///< nonzeros of each column of L (diagonal included)
    std::vector<long long> pointers;  ///< column pointers of L: pointers[j+1] − pointers[j] = counts[j]
    long long nonzeros = 0;           ///< nnz(L) = Σ counts
    double flops = 0.0;               ///< Σ_j counts[j]²: the flops of the numeric factorization (±n)
};

/// Permutes A, then computes the elimination tree, column counts, column pointers, nnz(L) and the
/// flop count. fem::Error for a non-square or invalid A, a bad permutation, or nnz(L) ≥ 2³¹.
/// docs/08_direct_solvers.md#symbolic-factorization
SymbolicCholesky symbolic_cholesky(const sparse::CscMatrix& A, const Permutation& perm);

/// The Cholesky factor L of C = P A Pᵀ (C given by its upper triangle, as symmetric_permutation
/// returns it), up-looking: for k = 0 … n−1, row k of L solves the sparse triangular system
/// L(0:k, 0:k) l_kᵀ = C(0:k, k), whose nonzero pattern is the row subtree of k (found by walking
/// the elimination tree from each C_ik ≠ 0); then l_kk = √(c_kk − l_k·l_k). L is returned in CSC
/// with rows sorted in each column (the diagonal first), nnz(L) = symbolic.nonzeros.
/// fem::Error for sizes that do not match the symbolic factorization, and when C is not positive
/// definite (pivot_thresholds): the message names the column — in A's original numbering, perm[k] —
/// whose pivot c_kk − l_k·l_k failed, and its value. docs/08_direct_solvers.md#up-looking-cholesky
sparse::CscMatrix up_looking_cholesky(const sparse::CscMatrix& C_upper, const SymbolicCholesky& symbolic);

/// The pivot rule of the numeric factorizations: column j of C fails when its pivot
/// d_j = c_jj − Σ_k l_jk² is not above n ε |c_jj| — negative (C is indefinite) or round-off of
/// c_jj (C is singular to working precision, e.g. a stiffness matrix with rigid modes). Returns the
/// n thresholds n ε |c_jj| from C's diagonal (C given by either triangle or both).
/// docs/08_direct_solvers.md#when-cholesky-fails
std::vector<double> pivot_thresholds(const sparse::CscMatrix& C);

/// The fem::Error of a failed pivot: names the column in the matrix's own (original) numbering,
/// the pivot and the threshold, and says that the matrix is not symmetric positive definite.
Error not_positive_definite(int original_column, double pivot, double threshold);

/// Which numeric factorization SparseCholesky runs.
enum class Factorization {
    up_looking,   ///< up_looking_cholesky: simple, one scalar at a time
    supernodal,   ///< multifrontal over relaxed supernodes with dense blocks (supernodal.hpp)
};

/// "up-looking" or "supernodal".
std::string factorization_name(Factorization factorization);

struct CholeskyOptions {
    Ordering ordering = Ordering::nested_dissection;
    Factorization factorization = Factorization::supernodal;
    /// Also keep L rounded to single precision after every factorization, for
    /// solve_single_precision (supernodal only): a preconditioner's cheaper solve.
    bool single_precision_copy = false;
};

/// Times of the phases of the last analysis and factorization (wall clock, seconds).
struct CholeskyTimes {
    double ordering = 0.0;   ///< the fill-reducing ordering
    double symbolic = 0.0;   ///< permutation, elimination tree, counts, supernodes
    double numeric = 0.0;    ///< the numeric factorization
    /// Supernodal: the numeric factorization's independent subtrees and its top supernodes
    /// (docs/08_direct_solvers.md#threads); 0 for up-looking.
    double numeric_subtrees = 0.0, numeric_top = 0.0;
};

/// Factor once, solve many: the sparse Cholesky factorization P A Pᵀ = L Lᵀ of a symmetric
/// positive definite A (its lower triangle is read), kept for any number of right-hand sides.
///
///     fem::direct::SparseCholesky chol(A);              // order, analyse, factor (expensive)
///     Eigen::VectorXd x = chol.solve(b);                // two triangular solves (cheap)
///     chol.factorize(A2);                               // new values, same pattern: numeric only
///
/// Construction orders, analyses and factors; fem::Error for a non-square, empty or invalid A and
/// when A is not positive definite to working precision (pivot_thresholds; the message names the
/// column, in A's numbering, whose pivot failed).
/// docs/08_direct_solvers.md#factor-once-solve-many
class SparseCholesky {
public:
    explicit SparseCholesky(const sparse::CscMatrix& A, CholeskyOptions options = {});
    /// A symmetric matrix in CSR: its arrays are the CSC arrays of Aᵀ = A (no copy of the values
    /// beyond the one conversion). Reads the entries with column ≤ row, like the CSC constructor.
    explicit SparseCholesky(const sparse::CsrMatrix& A, CholeskyOptions options = {});
    /// An Eigen sparse matrix (column-major), as chapter 06 assembles K.
    explicit SparseCholesky(const Eigen::SparseMatrix<double>& A, CholeskyOptions options = {});
    ~SparseCholesky();
    SparseCholesky(SparseCholesky&&) noexcept;
    SparseCholesky& operator=(SparseCholesky&&) noexcept;

    /// Numeric factorization of a matrix with the same pattern as the one given at construction
    /// (e.g. K after a change of material): the ordering and symbolic analysis are reused.
    /// fem::Error if the size or pattern differs, or A is not positive definite.
    void factorize(const sparse::CscMatrix& A);

    /// x with A x = b. fem::Error if b has not rows() entries or is not finite.
    Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
    /// X with A X = B, one column per right-hand side (blocked: L is read once for all columns).
    /// fem::Error if B has not rows() rows or is not finite.
    Eigen::MatrixXd solve_many(const Eigen::MatrixXd& B) const;
    /// x ≈ A⁻¹ b with the single-precision copy of L (options.single_precision_copy): b is rounded
    /// to float, both substitutions run in float (half the bytes of solve's), x is returned in
    /// double. Its relative error is of order 1e-7 κ(A): for a preconditioner, not for an answer.
    /// fem::Error without the copy, or if b has not rows() entries or is not finite.
    /// docs/08_direct_solvers.md#single-precision-solves
    Eigen::VectorXd solve_single_precision(const Eigen::VectorXd& b) const;

    int rows() const;
    const CholeskyOptions& options() const;
    /// The ordering P (perm[new] = old) actually used, including the postorder of the tree.
    const Permutation& permutation() const;
    /// nnz(L) of the exact factor (what column_counts gives), whichever factorization runs.
    long long factor_nonzeros() const;
    /// Entries the factor occupies in memory: nnz(L) for up-looking; for supernodal also the
    /// explicit zeros of the dense blocks (upper triangles of diagonal blocks, relaxed merges).
    long long stored_entries() const;
    /// Σ counts² of the symbolic factorization (the flops of the factorization, ± n).
    double flops() const;
    /// The number of supernodes (n for the up-looking factorization).
    int supernodes() const;
    const CholeskyTimes& times() const;

    /// L of C = P A Pᵀ as a CSC matrix (rows sorted), for tests and figures: the up-looking factor
    /// itself, or the supernodal blocks without their explicit zeros.
    sparse::CscMatrix factor() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// The relative residual ‖A x − b‖₂ / ‖b‖₂ for a symmetric A given by its lower triangle (or
/// both): the product uses each stored A_ij, i > j, twice. fem::Error for mismatched sizes.
double symmetric_residual(const sparse::CscMatrix& A, const Eigen::VectorXd& x, const Eigen::VectorXd& b);

}  // namespace fem::direct
