// Chapter 07: sparse matrix × vector products. docs/07_sparse_storage.md#sparse-matrix-times-vector
#include "07_sparse_storage/sparse_products.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <functional>

namespace fem::sparse {
namespace {

/// fem::Error when the two ranges share memory: y = A x must not overwrite x while reading it.
void check_no_overlap(std::span<const double> x, std::span<double> y, const char* where)
{
    if (x.empty() || y.empty())
        return;
    const std::less<const double*> before;
    if (before(x.data(), y.data() + y.size()) && before(y.data(), x.data() + x.size()))
        throw Error(str(where, ": x and y share memory; the product needs a separate output vector"));
}

void check_sizes(const char* where, std::size_t x_size, std::size_t x_needed, std::size_t y_size,
                 std::size_t y_needed)
{
    if (x_size != x_needed)
        throw Error(str(where, ": x has ", x_size, " entries, the matrix needs ", x_needed));
    if (y_size != y_needed)
        throw Error(str(where, ": y has ", y_size, " entries, the matrix gives ", y_needed));
}

std::span<const double> as_span(const Eigen::VectorXd& v) { return {v.data(), static_cast<std::size_t>(v.size())}; }
std::span<double> as_span(Eigen::VectorXd& v) { return {v.data(), static_cast<std::size_t>(v.size())}; }

/// Sizes y for a product with x, after refusing y = x (resizing y would invalidate x).
void prepare_output(const char* where, const Eigen::VectorXd& x, Eigen::VectorXd& y, int y_size)
{
    if (&x == &y)
        throw Error(str(where, ": x and y are the same vector; the product needs a separate output vector"));
    y.resize(y_size);
}

}  // namespace

void gather_product(const CompressedView& M, std::span<const double> x, std::span<double> y)
{
    check_sizes("gather_product", x.size(), static_cast<std::size_t>(M.inner), y.size(),
                static_cast<std::size_t>(M.outer));
    check_no_overlap(x, y, "gather_product");
    const double* const A = M.A.data();
    const int* const IA = M.IA.data();
    const int* const JA = M.JA.data();
    const double* const xp = x.data();
    double* const yp = y.data();
    // BEGIN EXERCISE 07.2 gather_product #gather-and-scatter
    // HINT: for each slice o: sum A[k] * x[JA[k]] over k = IA[o] … IA[o+1] − 1, then y[o] = sum.
    for (int o = 0; o < M.outer; ++o) {
        // Four partial sums: the additions into one sum wait for each other (a few cycles
        // each); four independent chains keep the adder busy while the memory streams in.
        double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
        int k = IA[o];
        const int end = IA[o + 1];
        for (; k + 4 <= end; k += 4) {
            s0 += A[k] * xp[JA[k]];
            s1 += A[k + 1] * xp[JA[k + 1]];
            s2 += A[k + 2] * xp[JA[k + 2]];
            s3 += A[k + 3] * xp[JA[k + 3]];
        }
        for (; k < end; ++k)
            s0 += A[k] * xp[JA[k]];
        yp[o] = (s0 + s1) + (s2 + s3);
    }
    // END EXERCISE
}

void scatter_product(const CompressedView& M, std::span<const double> x, std::span<double> y)
{
    check_sizes("scatter_product", x.size(), static_cast<std::size_t>(M.outer), y.size(),
                static_cast<std::size_t>(M.inner));
    check_no_overlap(x, y, "scatter_product");
    const double* const A = M.A.data();
    const int* const IA = M.IA.data();
    const int* const JA = M.JA.data();
    const double* const xp = x.data();
    double* const yp = y.data();
    // BEGIN EXERCISE 07.3 scatter_product #gather-and-scatter
    // HINT: start from y = 0; slice o adds x[o] times its entries into y: y[JA[k]] += A[k] * x[o].
    std::fill(yp, yp + M.inner, 0.0);
    for (int o = 0; o < M.outer; ++o) {
        const double xo = xp[o];
        for (int k = IA[o]; k < IA[o + 1]; ++k)
            yp[JA[k]] += A[k] * xo;
    }
    // END EXERCISE
}

void csr_times_vector(const CsrMatrix& M, const Eigen::VectorXd& x, Eigen::VectorXd& y)
{
    const CompressedView v = view(M);
    prepare_output("csr_times_vector", x, y, M.rows);
    gather_product(v, as_span(x), as_span(y));
}

void csc_times_vector(const CscMatrix& M, const Eigen::VectorXd& x, Eigen::VectorXd& y)
{
    const CompressedView v = view(M);
    prepare_output("csc_times_vector", x, y, M.rows);
    scatter_product(v, as_span(x), as_span(y));
}

void vector_times_csc(const Eigen::VectorXd& x, const CscMatrix& M, Eigen::VectorXd& y)
{
    const CompressedView v = view(M);
    prepare_output("vector_times_csc", x, y, M.cols);
    gather_product(v, as_span(x), as_span(y));
}

void vector_times_csr(const Eigen::VectorXd& x, const CsrMatrix& M, Eigen::VectorXd& y)
{
    const CompressedView v = view(M);
    prepare_output("vector_times_csr", x, y, M.cols);
    scatter_product(v, as_span(x), as_span(y));
}

void coo_times_vector(const CooMatrix& M, const Eigen::VectorXd& x, Eigen::VectorXd& y)
{
    const std::size_t n = M.value.size();
    if (M.rows < 0 || M.cols < 0 || M.row.size() != n || M.col.size() != n)
        throw Error(str("coo_times_vector: inconsistent COO matrix ", M.rows, "×", M.cols, " with ", M.row.size(),
                        " rows, ", M.col.size(), " columns and ", n, " values; see validate"));
    prepare_output("coo_times_vector", x, y, M.rows);
    check_sizes("coo_times_vector", static_cast<std::size_t>(x.size()), static_cast<std::size_t>(M.cols),
                static_cast<std::size_t>(y.size()), static_cast<std::size_t>(M.rows));
    const int* const row = M.row.data();
    const int* const col = M.col.data();
    const double* const value = M.value.data();
    const double* const xp = x.data();
    double* const yp = y.data();
    // BEGIN EXERCISE 07.1 coo_times_vector #coo-triplets
    // HINT: start from y = 0; every triplet (i, j, v) adds v * x[j] to y[i].
    std::fill(yp, yp + M.rows, 0.0);
    for (std::size_t k = 0; k < n; ++k)
        yp[row[k]] += value[k] * xp[col[k]];
    // END EXERCISE
}

void symmetric_times_vector(const CsrMatrix& M, const Eigen::VectorXd& x, Eigen::VectorXd& y)
{
    const CompressedView v = view(M);
    if (M.rows != M.cols)
        throw Error(str("symmetric_times_vector: the matrix is ", M.rows, "×", M.cols,
                        "; a symmetric matrix is square"));
    prepare_output("symmetric_times_vector", x, y, M.rows);
    check_sizes("symmetric_times_vector", static_cast<std::size_t>(x.size()), static_cast<std::size_t>(M.cols),
                static_cast<std::size_t>(y.size()), static_cast<std::size_t>(M.rows));
    const double* const A = v.A.data();
    const int* const IA = v.IA.data();
    const int* const JA = v.JA.data();
    const double* const xp = x.data();
    double* const yp = y.data();
    // BEGIN EXERCISE 07.6 symmetric_times_vector #symmetric-storage
    // HINT: start from y = 0. In row i, an entry a at column j < i stands for A_ij and A_ji:
    // HINT: y[i] += a * x[j] and y[j] += a * x[i]. The diagonal (j == i) counts once. Columns are
    // HINT: sorted, so stop the row at the first j ≥ i: entries above the diagonal are not read.
    std::fill(yp, yp + M.rows, 0.0);
    for (int i = 0; i < M.rows; ++i) {
        const double xi = xp[i];
        const int end = IA[i + 1];
        double sum = 0.0;
        int k = IA[i];
        for (; k < end && JA[k] < i; ++k) {
            const int j = JA[k];
            sum += A[k] * xp[j];  // A_ij x_j
            yp[j] += A[k] * xi;   // A_ji x_i, the mirrored entry
        }
        if (k < end && JA[k] == i)
            sum += A[k] * xi;     // the diagonal, once
        yp[i] += sum;
    }
    // END EXERCISE
}

double spmv_bytes(double stored_entries, int index_bytes, double pointer_entries, double x_size, double y_size)
{
    return stored_entries * (8.0 + index_bytes) + 4.0 * pointer_entries + 8.0 * (x_size + y_size);
}

}  // namespace fem::sparse
