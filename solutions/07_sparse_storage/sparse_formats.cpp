// Chapter 07: COO, CSR and CSC, their checks and the conversions between them.
// docs/07_sparse_storage.md
#include "07_sparse_storage/sparse_formats.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

namespace fem::sparse {
namespace {

constexpr std::size_t max_index = static_cast<std::size_t>(std::numeric_limits<int>::max());

/// How a compressed format names its two directions in messages.
struct Roles {
    const char* format;  // "CSR"
    const char* outer;   // "row"
    const char* inner;   // "column"
};
constexpr Roles csr_roles{"CSR", "row", "column"};
constexpr Roles csc_roles{"CSC", "column", "row"};

void check_dimensions(const char* format, int rows, int cols)
{
    if (rows < 0 || cols < 0)
        throw Error(str(format, " matrix: ", rows, "×", cols, " has a negative size; rows and cols must be ≥ 0"));
}

/// The O(1) checks of view(): the three arrays have the sizes IA promises.
CompressedView checked_view(const Roles& roles, int rows, int cols, int outer, int inner,
                            const std::vector<double>& A, const std::vector<int>& IA,
                            const std::vector<int>& JA)
{
    check_dimensions(roles.format, rows, cols);
    if (IA.size() != static_cast<std::size_t>(outer) + 1)
        throw Error(str(roles.format, " matrix ", rows, "×", cols, ": IA has ", IA.size(),
                        " entries, needs ", roles.outer, "s + 1 = ", outer + 1));
    if (IA.front() != 0)
        throw Error(str(roles.format, " matrix: IA[0] = ", IA.front(), ", must be 0"));
    const int nnz = IA.back();
    if (nnz < 0 || A.size() != static_cast<std::size_t>(nnz) || JA.size() != static_cast<std::size_t>(nnz))
        throw Error(str(roles.format, " matrix: IA[", outer, "] = ", nnz, " entries, but A has ", A.size(),
                        " values and JA ", JA.size(), " indices; all three must be equal"));
    return CompressedView{outer, inner, A, IA, JA};
}

/// Whether the arrays break a rule of check_structure, as one branch-free sweep that the compiler
/// can vectorise (a valid matrix, the common case, then costs a fraction of a copy).
bool breaks_structure(const CompressedView& M, bool sorted, bool finite)
{
    const int* const IA = M.IA.data();
    const int* const JA = M.JA.data();
    const double* const A = M.A.data();
    const int nnz = IA[M.outer];
    int bad = 0;
    for (int o = 0; o < M.outer; ++o)
        bad |= static_cast<int>(IA[o + 1] < IA[o]) | static_cast<int>(IA[o + 1] > nnz);
    if (bad)
        return true;
    unsigned largest = 0;  // a negative index becomes a huge unsigned one
    for (int k = 0; k < nnz; ++k)
        largest = std::max(largest, static_cast<unsigned>(JA[k]));
    if (nnz > 0 && largest >= static_cast<unsigned>(M.inner))
        return true;
    if (sorted)
        for (int o = 0; o < M.outer; ++o)
            for (int k = IA[o] + 1; k < IA[o + 1]; ++k)
                bad |= static_cast<int>(JA[k - 1] >= JA[k]);
    if (finite)
        for (int k = 0; k < nnz; ++k)
            bad |= static_cast<int>(!(std::abs(A[k]) <= std::numeric_limits<double>::max()));
    return bad != 0;
}

/// The O(outer + nnz) checks every function that indexes with IA and JA needs: IA non-decreasing
/// and every JA in [0, inner). `sorted` adds the canonical-form rule (strictly increasing JA within
/// a slice), `finite` the finiteness of the values. The message names the first offending entry.
void check_structure(const Roles& roles, const CompressedView& M, bool sorted, bool finite)
{
    if (!breaks_structure(M, sorted, finite))
        return;
    const int nnz = M.IA[M.outer];
    for (int o = 0; o < M.outer; ++o) {
        if (M.IA[o + 1] < M.IA[o])
            throw Error(str(roles.format, " matrix: IA[", o + 1, "] = ", M.IA[o + 1], " < IA[", o, "] = ",
                            M.IA[o], "; the ", roles.outer, " pointer must not decrease"));
        if (M.IA[o + 1] > nnz)
            throw Error(str(roles.format, " matrix: IA[", o + 1, "] = ", M.IA[o + 1], " points past the ", nnz,
                            " stored entries"));
    }
    for (int o = 0; o < M.outer; ++o)
        for (int k = M.IA[o]; k < M.IA[o + 1]; ++k) {
            const int j = M.JA[k];
            if (j < 0 || j >= M.inner)
                throw Error(str(roles.format, " matrix: entry k = ", k, " (", roles.outer, " ", o, ") has ",
                                roles.inner, " JA[", k, "] = ", j, ", outside [0, ", M.inner, ")"));
            if (sorted && k > M.IA[o] && M.JA[k - 1] >= j)
                throw Error(str(roles.format, " matrix: ", roles.outer, " ", o, " has ", roles.inner, "s JA[",
                                k - 1, "] = ", M.JA[k - 1], " then JA[", k, "] = ", j, "; they must increase "
                                "strictly within a ", roles.outer, " (sorted, no duplicates: coo_to_csr sums them)"));
            if (finite && !std::isfinite(M.A[k]))
                throw Error(str(roles.format, " matrix: A[", k, "] = ", M.A[k], " (", roles.outer, " ", o, ", ",
                                roles.inner, " ", j, ") is not finite"));
        }
    throw Error(str(roles.format, " matrix: inconsistent arrays"));  // not reached: a rule above broke
}

}  // namespace

CompressedView view(const CsrMatrix& M)
{
    return checked_view(csr_roles, M.rows, M.cols, M.rows, M.cols, M.A, M.IA, M.JA);
}

CompressedView view(const CscMatrix& M)
{
    return checked_view(csc_roles, M.rows, M.cols, M.cols, M.rows, M.A, M.IA, M.JA);
}

void validate(const CooMatrix& M)
{
    check_dimensions("COO", M.rows, M.cols);
    const std::size_t n = M.value.size();
    if (M.row.size() != n || M.col.size() != n)
        throw Error(str("COO matrix: ", M.row.size(), " row indices, ", M.col.size(), " column indices and ", n,
                        " values; give one of each per entry"));
    if (n > max_index)
        throw Error(str("COO matrix: ", n, " entries; int indices allow at most ", max_index));
    // One branch-free sweep first (vectorisable); only a matrix that breaks a rule is searched
    // again for the first offending entry.
    unsigned largest_row = 0, largest_col = 0;  // a negative index becomes a huge unsigned one
    int infinite = 0;
    for (std::size_t k = 0; k < n; ++k) {
        largest_row = std::max(largest_row, static_cast<unsigned>(M.row[k]));
        largest_col = std::max(largest_col, static_cast<unsigned>(M.col[k]));
        infinite |= static_cast<int>(!(std::abs(M.value[k]) <= std::numeric_limits<double>::max()));
    }
    if (n == 0 || (largest_row < static_cast<unsigned>(M.rows) && largest_col < static_cast<unsigned>(M.cols) &&
                   !infinite))
        return;
    for (std::size_t k = 0; k < n; ++k) {
        const int i = M.row[k], j = M.col[k];
        if (i < 0 || i >= M.rows || j < 0 || j >= M.cols)
            throw Error(str("COO matrix ", M.rows, "×", M.cols, ": entry k = ", k, " at (row ", i, ", column ", j,
                            ") is out of range; allowed 0 ≤ row < ", M.rows, ", 0 ≤ column < ", M.cols));
        if (!std::isfinite(M.value[k]))
            throw Error(str("COO matrix: entry k = ", k, " at (row ", i, ", column ", j, ") has the value ",
                            M.value[k], ", which is not finite"));
    }
}

void validate(const CsrMatrix& M)
{
    check_structure(csr_roles, view(M), true, true);
}

void validate(const CscMatrix& M)
{
    check_structure(csc_roles, view(M), true, true);
}

void transpose_compressed(const CompressedView& M, std::vector<double>& A_t, std::vector<int>& IA_t,
                          std::vector<int>& JA_t)
{
    if (M.outer < 0 || M.inner < 0 || M.IA.size() != static_cast<std::size_t>(M.outer) + 1 || M.IA[0] != 0 ||
        M.A.size() != static_cast<std::size_t>(M.IA[M.outer]) || M.JA.size() != M.A.size())
        throw Error(str("transpose_compressed: inconsistent arrays: outer = ", M.outer, ", inner = ", M.inner,
                        ", IA has ", M.IA.size(), " entries, A ", M.A.size(), ", JA ", M.JA.size()));
    check_structure(Roles{"compressed", "outer slice", "inner index"}, M, false, false);
    const double* const A = M.A.data();
    const int* const IA = M.IA.data();
    const int* const JA = M.JA.data();
    // BEGIN EXERCISE 07.4 transpose_compressed #transpose
    // HINT: pass 1: IA_t[j + 1] counts the entries with inner index j; prefix sums turn counts into
    // HINT: pointers. Pass 2: walk the slices o in order and put each entry at next[JA[k]]++,
    // HINT: recording o as its new inner index (so they come out sorted).
    const int nnz = IA[M.outer];
    IA_t.assign(static_cast<std::size_t>(M.inner) + 1, 0);
    int* const count = IA_t.data();
    for (int k = 0; k < nnz; ++k)
        ++count[JA[k] + 1];
    for (int j = 0; j < M.inner; ++j)
        count[j + 1] += count[j];
    std::vector<int> next(IA_t.begin(), IA_t.end() - 1);
    A_t.resize(nnz);
    JA_t.resize(nnz);
    int* const place = next.data();
    int* const index_t = JA_t.data();
    double* const value_t = A_t.data();
    for (int o = 0; o < M.outer; ++o) {
        const int end = IA[o + 1];
        for (int k = IA[o]; k < end; ++k) {
            const int p = place[JA[k]]++;
            index_t[p] = o;
            value_t[p] = A[k];
        }
    }
    // END EXERCISE
}

CsrMatrix coo_to_csr(const CooMatrix& M)
{
    validate(M);
    CsrMatrix R;
    R.rows = M.rows;
    R.cols = M.cols;
    const int* const row = M.row.data();
    const int* const col = M.col.data();
    const double* const value = M.value.data();
    // BEGIN EXERCISE 07.5 coo_to_csr #from-triplets-to-csr
    // HINT: 1. counting sort by column: count, prefix sums, place (rows unsorted, with duplicates);
    // HINT: 2. in each column, add each repeated row into its first copy (remember where[i]);
    // HINT: 3. transpose_compressed of these column slices gives the rows, columns sorted.
    const int n = static_cast<int>(M.entries());
    std::vector<int> IA_c(static_cast<std::size_t>(M.cols) + 1, 0);
    for (int k = 0; k < n; ++k)
        ++IA_c[col[k] + 1];
    for (int j = 0; j < M.cols; ++j)
        IA_c[j + 1] += IA_c[j];
    std::vector<int> next(IA_c.begin(), IA_c.end() - 1);
    // "for overwrite": no zero-fill, every entry is written before it is read.
    const auto JA_c = std::make_unique_for_overwrite<int[]>(n);
    const auto A_c = std::make_unique_for_overwrite<double[]>(n);
    int* const place = next.data();
    int* const rows_c = JA_c.get();
    double* const values_c = A_c.get();
    for (int k = 0; k < n; ++k) {
        const int p = place[col[k]]++;
        rows_c[p] = row[k];
        values_c[p] = value[k];
    }
    // Sum duplicates, compacting in place: where[i] is the position of row i in the column being
    // compacted, or lies before the column's start (then row i has not appeared in it yet).
    std::vector<int> where(M.rows, -1);
    int* const seen = where.data();
    int write = 0;
    for (int j = 0; j < M.cols; ++j) {
        const int begin = IA_c[j], end = IA_c[j + 1], start = write;
        IA_c[j] = start;
        for (int p = begin; p < end; ++p) {
            const int i = rows_c[p];
            if (seen[i] >= start) {
                values_c[seen[i]] += values_c[p];
            } else {
                seen[i] = write;
                rows_c[write] = i;
                values_c[write] = values_c[p];
                ++write;
            }
        }
    }
    IA_c[M.cols] = write;
    transpose_compressed(CompressedView{M.cols, M.rows, {values_c, std::size_t(write)}, IA_c,
                                        {rows_c, std::size_t(write)}},
                         R.A, R.IA, R.JA);
    // END EXERCISE
    return R;
}

CscMatrix csr_to_csc(const CsrMatrix& M)
{
    CscMatrix C;
    C.rows = M.rows;
    C.cols = M.cols;
    transpose_compressed(view(M), C.A, C.IA, C.JA);
    return C;
}

CsrMatrix csc_to_csr(const CscMatrix& M)
{
    CsrMatrix R;
    R.rows = M.rows;
    R.cols = M.cols;
    transpose_compressed(view(M), R.A, R.IA, R.JA);
    return R;
}

CsrMatrix transpose(const CsrMatrix& M)
{
    CsrMatrix T;
    T.rows = M.cols;
    T.cols = M.rows;
    transpose_compressed(view(M), T.A, T.IA, T.JA);
    return T;
}

CooMatrix csr_to_coo(const CsrMatrix& M)
{
    const CompressedView v = view(M);
    CooMatrix C;
    C.rows = M.rows;
    C.cols = M.cols;
    C.row.reserve(v.A.size());
    C.col.assign(v.JA.begin(), v.JA.end());
    C.value.assign(v.A.begin(), v.A.end());
    for (int i = 0; i < M.rows; ++i)
        C.row.insert(C.row.end(), static_cast<std::size_t>(v.IA[i + 1] - v.IA[i]), i);
    return C;
}

CsrMatrix lower_triangle(const CsrMatrix& M)
{
    const CompressedView v = view(M);
    if (M.rows != M.cols)
        throw Error(str("lower_triangle: the matrix is ", M.rows, "×", M.cols, "; a symmetric matrix is square"));
    CsrMatrix L;
    L.rows = L.cols = M.rows;
    L.IA.assign(static_cast<std::size_t>(M.rows) + 1, 0);
    for (int i = 0; i < M.rows; ++i) {
        for (int k = v.IA[i]; k < v.IA[i + 1]; ++k)
            if (v.JA[k] <= i) {
                L.JA.push_back(v.JA[k]);
                L.A.push_back(v.A[k]);
            }
        L.IA[i + 1] = static_cast<int>(L.A.size());
    }
    return L;
}

namespace {

/// Copies the compressed arrays of an Eigen matrix (compressed mode) into A, IA, JA.
template <typename EigenMatrix>
void copy_arrays(const EigenMatrix& E, std::vector<double>& A, std::vector<int>& IA, std::vector<int>& JA)
{
    const Eigen::Index nnz = E.nonZeros();
    A.assign(E.valuePtr(), E.valuePtr() + nnz);
    IA.assign(E.outerIndexPtr(), E.outerIndexPtr() + E.outerSize() + 1);
    JA.assign(E.innerIndexPtr(), E.innerIndexPtr() + nnz);
}

}  // namespace

CsrMatrix csr_from_eigen(const Eigen::SparseMatrix<double>& M)
{
    Eigen::SparseMatrix<double, Eigen::RowMajor, int> R = M;  // Eigen's own transposing copy
    R.makeCompressed();
    CsrMatrix C;
    C.rows = static_cast<int>(R.rows());
    C.cols = static_cast<int>(R.cols());
    copy_arrays(R, C.A, C.IA, C.JA);
    validate(C);
    return C;
}

CscMatrix csc_from_eigen(const Eigen::SparseMatrix<double>& M)
{
    Eigen::SparseMatrix<double> E = M;
    E.makeCompressed();
    CscMatrix C;
    C.rows = static_cast<int>(E.rows());
    C.cols = static_cast<int>(E.cols());
    copy_arrays(E, C.A, C.IA, C.JA);
    validate(C);
    return C;
}

Eigen::SparseMatrix<double> to_eigen(const CsrMatrix& M)
{
    validate(M);
    const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor, int>> map(
        M.rows, M.cols, M.nonzeros(), M.IA.data(), M.JA.data(), M.A.data());
    return Eigen::SparseMatrix<double>(map);
}

Eigen::SparseMatrix<double> to_eigen(const CscMatrix& M)
{
    validate(M);
    const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::ColMajor, int>> map(
        M.rows, M.cols, M.nonzeros(), M.IA.data(), M.JA.data(), M.A.data());
    return Eigen::SparseMatrix<double>(map);
}

}  // namespace fem::sparse
