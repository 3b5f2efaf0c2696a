#pragma once
// Chapter 07: sparse storage by hand. docs/07_sparse_storage.md
//
// Three ways to store a sparse rows×cols matrix, with the lecture's names for the arrays:
//   COO  (coordinate, "triplets"): row[k], col[k], value[k] for every stored entry k, in any order,
//        duplicates allowed (they add up). The way to *build* a matrix.
//   CSR  (compressed sparse row): the values row by row in A, their column indices in JA, and the
//        row pointer IA with IA[0] = 0, IA[i+1] = IA[i] + (entries of row i); row i is
//        A[IA[i] … IA[i+1]−1]. The way to *multiply* A x.
//   CSC  (compressed sparse column): the same with the roles of rows and columns exchanged:
//        A column by column, JA the row indices, IA the column pointer (cols+1 entries).
// The CSC arrays of A are the CSR arrays of Aᵀ: one data structure, read along rows or columns.
// Eigen calls the two roles "outer" (the compressed direction) and "inner".
//
// Indices are int (4 bytes), as in Eigen's default SparseMatrix: an index moves half the bytes of
// a 64-bit one, which matters because SpMV is limited by memory traffic. The price is a limit of
// 2³¹ − 1 ≈ 2.1·10⁹ stored entries (and rows, columns); the conversions check it.
// docs/07_sparse_storage.md#the-index-type

#include <Eigen/SparseCore>

#include <span>
#include <vector>

namespace fem::sparse {

/// A matrix as a list of triplets (row[k], col[k], value[k]), k = 0 … entries()−1, 0-based, in any
/// order; entries with the same (row, col) add up. docs/07_sparse_storage.md#coo-triplets
struct CooMatrix {
    int rows = 0;
    int cols = 0;
    std::vector<int> row;       ///< row index of entry k
    std::vector<int> col;       ///< column index of entry k
    std::vector<double> value;  ///< value of entry k

    /// Appends the triplet (i, j, v) (checked later, by validate or a conversion).
    void add(int i, int j, double v)
    {
        row.push_back(i);
        col.push_back(j);
        value.push_back(v);
    }
    /// The number of stored triplets (duplicates counted).
    std::size_t entries() const { return value.size(); }
};

/// Compressed sparse row, the lecture's A, IA, JA. Row i holds the entries k = IA[i] … IA[i+1]−1,
/// at columns JA[k] with values A[k]. Canonical form (what validate checks and every function of
/// this chapter returns): columns strictly increasing within each row (sorted, no duplicates).
/// A default-constructed CsrMatrix is the valid 0×0 matrix. docs/07_sparse_storage.md#csr
struct CsrMatrix {
    int rows = 0;
    int cols = 0;
    std::vector<double> A;     ///< values, row by row (nnz)
    std::vector<int> IA{0};    ///< row pointer (rows + 1): IA[0] = 0, IA[rows] = nnz
    std::vector<int> JA;       ///< column index of each value (nnz)

    /// The number of stored entries, nnz = IA[rows].
    int nonzeros() const { return static_cast<int>(A.size()); }
};

/// Compressed sparse column: CSR with rows and columns exchanged. Column j holds the entries
/// k = IA[j] … IA[j+1]−1, at rows JA[k] with values A[k]; rows strictly increasing within a
/// column. These are exactly the CSR arrays of Aᵀ. docs/07_sparse_storage.md#csc
struct CscMatrix {
    int rows = 0;
    int cols = 0;
    std::vector<double> A;     ///< values, column by column (nnz)
    std::vector<int> IA{0};    ///< column pointer (cols + 1): IA[0] = 0, IA[cols] = nnz
    std::vector<int> JA;       ///< row index of each value (nnz)

    /// The number of stored entries, nnz = IA[cols].
    int nonzeros() const { return static_cast<int>(A.size()); }
};

/// The three arrays of CSR or CSC, seen without copying, in Eigen's terms: `outer` slices (rows
/// of a CSR, columns of a CSC), each of length `inner` (columns of a CSR, rows of a CSC); slice o
/// holds the entries k = IA[o] … IA[o+1]−1 at inner index JA[k] with value A[k]. The kernels and
/// the transpose work on views, so that one loop serves both formats.
/// docs/07_sparse_storage.md#one-structure-two-readings
struct CompressedView {
    int outer = 0;
    int inner = 0;
    std::span<const double> A;
    std::span<const int> IA;  ///< outer + 1 pointers
    std::span<const int> JA;
};

/// The view of a CSR matrix: outer = rows, inner = cols. fem::Error if the array sizes disagree
/// (IA must have rows+1 entries, A and JA IA[rows]); the indices themselves are checked by
/// validate, not here (O(1), so that a product does not pay O(nnz) twice).
CompressedView view(const CsrMatrix& M);
/// The view of a CSC matrix: outer = cols, inner = rows. Same checks as for CSR.
CompressedView view(const CscMatrix& M);

/// fem::Error unless rows, cols ≥ 0, row, col and value have the same length (≤ 2³¹−1), every
/// index is in range and every value is finite. The message names the entry k and its indices.
void validate(const CooMatrix& M);
/// fem::Error unless M is canonical CSR: rows, cols ≥ 0, IA has rows+1 entries with IA[0] = 0,
/// non-decreasing, IA[rows] = A.size() = JA.size(); every JA in [0, cols), strictly increasing
/// within a row; every value finite. The message names the row, the position k and the index.
void validate(const CsrMatrix& M);
/// As for CSR, with columns as the compressed direction and JA holding row indices.
void validate(const CscMatrix& M);

/// The compressed arrays of the transpose of M, by counting sort (the transpose of a CSR is the
/// CSC of the same matrix, and vice versa). Pass 1 counts the entries of each inner index into
/// IA_t (inner+1 pointers); pass 2 walks the outer slices in order and drops each entry into the
/// next free place of its inner slice, so the new inner indices JA_t come out sorted. O(nnz +
/// outer + inner). The input may have unsorted (even repeated) inner indices; fem::Error for a
/// JA outside [0, inner). docs/07_sparse_storage.md#transpose
void transpose_compressed(const CompressedView& M, std::vector<double>& A_t, std::vector<int>& IA_t,
                          std::vector<int>& JA_t);

/// COO → CSR: entries sorted by row, columns sorted within each row, duplicates summed (a sum
/// that cancels to 0 stays stored). O(entries + rows + cols) by counting sorts: bucket the
/// triplets by column, sum the duplicates of each column, then transpose_compressed (which sorts).
/// fem::Error as validate(const CooMatrix&). docs/07_sparse_storage.md#from-triplets-to-csr
CsrMatrix coo_to_csr(const CooMatrix& M);

/// CSR → CSC of the same matrix (the counting-sort transpose of the arrays).
/// docs/07_sparse_storage.md#transpose
CscMatrix csr_to_csc(const CsrMatrix& M);
/// CSC → CSR of the same matrix. docs/07_sparse_storage.md#transpose
CsrMatrix csc_to_csr(const CscMatrix& M);
/// Aᵀ in CSR (the CSC arrays of A, read as CSR). docs/07_sparse_storage.md#transpose
CsrMatrix transpose(const CsrMatrix& M);

/// CSR → COO: one triplet per stored entry, in row order (expands IA into a row per entry).
CooMatrix csr_to_coo(const CsrMatrix& M);

/// The lower triangle with the diagonal, entries (i, j) with j ≤ i, of a square CSR matrix: what
/// symmetric_times_vector reads. fem::Error if M is not square.
/// docs/07_sparse_storage.md#symmetric-storage
CsrMatrix lower_triangle(const CsrMatrix& M);

/// An Eigen matrix (column-major, Eigen's default) as CSR / CSC / Eigen and back. These use
/// Eigen's own conversions (a row-major copy for CSR), so that the tests can compare our
/// conversions against an independent one. Explicitly stored zeros are kept. fem::Error for a
/// non-finite value. docs/07_sparse_storage.md#eigen
CsrMatrix csr_from_eigen(const Eigen::SparseMatrix<double>& M);
CscMatrix csc_from_eigen(const Eigen::SparseMatrix<double>& M);
Eigen::SparseMatrix<double> to_eigen(const CsrMatrix& M);
Eigen::SparseMatrix<double> to_eigen(const CscMatrix& M);

}  // namespace fem::sparse
