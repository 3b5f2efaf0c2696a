#pragma once
// Chapter 07: sparse matrix × vector products (SpMV) for COO, CSR, CSC and a symmetric matrix
// stored as one triangle, and the bytes each must move. docs/07_sparse_storage.md#sparse-matrix-times-vector
//
// Two loops serve both compressed formats (see CompressedView):
//   gather   y_o = Σ_k A[k] x[JA[k]] over the slice o: a dot product per slice, each y written
//            once. On CSR arrays it computes A x; on CSC arrays xᵀA (= Aᵀx).
//   scatter  y[JA[k]] += A[k] x_o: each slice adds a multiple of itself into y. On CSC arrays it
//            computes A x; on CSR arrays xᵀA.
// The lecture's "cheap: sparse × vector for CSR, vector × sparse for CSC" are the two gathers.
//
// The products check sizes (O(1)), not indices: a matrix built by this chapter's conversions is
// valid; a hand-built one must pass validate() once before it is multiplied many times.

#include "07_sparse_storage/sparse_formats.hpp"

#include <Eigen/Core>

#include <span>

namespace fem::sparse {

/// y_o = Σ_{k = IA[o]}^{IA[o+1]−1} A[k] · x[JA[k]] for o = 0 … outer−1. x has M.inner entries,
/// y M.outer (both fixed-size spans; fem::Error if the sizes differ or x and y overlap).
/// docs/07_sparse_storage.md#gather-and-scatter
void gather_product(const CompressedView& M, std::span<const double> x, std::span<double> y);

/// y = 0, then y[JA[k]] += A[k] · x_o for every slice o and entry k of it. x has M.outer entries,
/// y M.inner (fem::Error if the sizes differ or x and y overlap).
/// docs/07_sparse_storage.md#gather-and-scatter
void scatter_product(const CompressedView& M, std::span<const double> x, std::span<double> y);

/// y = A x from CSR (gather: one dot product per row). x has M.cols entries; y is resized to
/// M.rows. fem::Error for a wrong size of x, or when x and y are the same vector.
/// docs/07_sparse_storage.md#gather-and-scatter
void csr_times_vector(const CsrMatrix& M, const Eigen::VectorXd& x, Eigen::VectorXd& y);

/// y = A x from CSC (scatter: y += x_j · column j). x has M.cols entries; y is resized to M.rows.
/// docs/07_sparse_storage.md#gather-and-scatter
void csc_times_vector(const CscMatrix& M, const Eigen::VectorXd& x, Eigen::VectorXd& y);

/// yᵀ = xᵀ A, i.e. y = Aᵀ x, from CSC (gather: y_j = column j · x). x has M.rows entries; y is
/// resized to M.cols. docs/07_sparse_storage.md#gather-and-scatter
void vector_times_csc(const Eigen::VectorXd& x, const CscMatrix& M, Eigen::VectorXd& y);

/// yᵀ = xᵀ A, i.e. y = Aᵀ x, from CSR (scatter: y += x_i · row i). x has M.rows entries; y is
/// resized to M.cols. docs/07_sparse_storage.md#gather-and-scatter
void vector_times_csr(const Eigen::VectorXd& x, const CsrMatrix& M, Eigen::VectorXd& y);

/// y = A x from triplets: y = 0, then y[row[k]] += value[k] · x[col[k]] for every entry k, in
/// any order; duplicates add up, as they should. fem::Error for an index out of range (checked
/// in a pass before the product), a wrong size of x, or x and y the same vector; y is resized to
/// M.rows. docs/07_sparse_storage.md#coo-triplets
void coo_times_vector(const CooMatrix& M, const Eigen::VectorXd& x, Eigen::VectorXd& y);

/// y = (L + D + Lᵀ) x for the symmetric matrix whose lower triangle with the diagonal, L + D, is
/// stored in the canonical CSR matrix M: each entry a = A_ij with j < i is used twice, y_i += a x_j
/// and y_j += a x_i, the diagonal once. Entries above the diagonal are not read (as with Eigen's
/// selfadjointView<Lower>), so M may be the lower triangle alone (lower_triangle: half the bytes)
/// or the whole symmetric matrix. The same arrays are the upper triangle in CSC. x has M.rows
/// entries, y is resized to M.rows. fem::Error if M is not square, for a wrong size of x, or x and
/// y the same vector. docs/07_sparse_storage.md#symmetric-storage
void symmetric_times_vector(const CsrMatrix& M, const Eigen::VectorXd& x, Eigen::VectorXd& y);

/// The bytes an SpMV must move at the least, counted like the triad of common/bandwidth.hpp
/// (every array read or written once, no write-allocate): per stored entry value_bytes (8) +
/// index_bytes (4 for CSR/CSC, 8 for COO's two indices), the outer pointers (4 per entry of IA;
/// 0 for COO), x read once (8 · x_size) and y written once (8 · y_size). Reading x once assumes
/// the entries of x a slice needs are still in cache from nearby slices, which holds for a mesh
/// with a local numbering. docs/07_sparse_storage.md#the-cost-model
double spmv_bytes(double stored_entries, int index_bytes, double pointer_entries, double x_size,
                  double y_size);

}  // namespace fem::sparse
