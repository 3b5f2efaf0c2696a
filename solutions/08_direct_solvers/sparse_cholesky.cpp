// Chapter 08: sparse Cholesky: symmetric permutation, elimination tree, postorder, column counts,
// the up-looking factorization, and the factor-once/solve-many object.
// docs/08_direct_solvers.md#sparse-cholesky
#include "08_direct_solvers/sparse_cholesky.hpp"

#include "08_direct_solvers/supernodal.hpp"

#include "common/error.hpp"
#include "common/timer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>

namespace fem::direct {
namespace {

void require_square(const sparse::CscMatrix& A, const char* what)
{
    if (A.rows != A.cols)
        throw Error(str(what, ": the matrix is ", A.rows, "×", A.cols, "; it must be square"));
}


}  // namespace

std::vector<double> pivot_thresholds(const sparse::CscMatrix& C)
{
    require_square(C, "pivot thresholds");
    const double scale = static_cast<double>(C.cols) * std::numeric_limits<double>::epsilon();
    std::vector<double> tiny(C.cols, 0.0);
    for (int j = 0; j < C.cols; ++j)
        for (int k = C.IA[j]; k < C.IA[j + 1]; ++k)
            if (C.JA[k] == j)
                tiny[j] = scale * std::abs(C.A[k]);
    return tiny;
}

Error not_positive_definite(int original_column, double pivot, double threshold)
{
    return Error(str("sparse Cholesky: the matrix is not symmetric positive definite: the pivot of column ",
                     original_column, " (in the matrix's own numbering) is ", pivot, ", not above n ε |a_jj| = ",
                     threshold));
}

sparse::CscMatrix symmetric_permutation(const sparse::CscMatrix& A, const Permutation& perm)
{
    sparse::validate(A);
    require_square(A, "symmetric permutation");
    const int n = A.cols;
    const Permutation position = inverse_permutation(perm);  // validates perm
    if (static_cast<int>(perm.size()) != n)
        throw Error(str("symmetric permutation: the permutation has ", perm.size(), " entries, the matrix ", n,
                        " columns"));
    // A_ij with i ≥ j goes to C(a, b), a = position[i], b = position[j]: stored in column max(a, b).
    sparse::CscMatrix C;
    C.rows = C.cols = n;
    C.IA.assign(n + 1, 0);
    for (int j = 0; j < n; ++j)
        for (int k = A.IA[j]; k < A.IA[j + 1]; ++k)
            if (A.JA[k] >= j)
                ++C.IA[std::max(position[A.JA[k]], position[j]) + 1];
    std::partial_sum(C.IA.begin(), C.IA.end(), C.IA.begin());
    C.JA.resize(C.IA[n]);
    C.A.resize(C.IA[n]);
    std::vector<int> next(C.IA.begin(), C.IA.end() - 1);
    for (int j = 0; j < n; ++j)
        for (int k = A.IA[j]; k < A.IA[j + 1]; ++k) {
            const int i = A.JA[k];
            if (i < j)
                continue;
            const int a = position[i], b = position[j];
            const int p = next[std::max(a, b)]++;
            C.JA[p] = std::min(a, b);
            C.A[p] = A.A[k];
        }
    // Sort the rows of each column (a column is short: insertion sort of index/value pairs).
    for (int j = 0; j < n; ++j)
        for (int p = C.IA[j] + 1; p < C.IA[j + 1]; ++p) {
            const int row = C.JA[p];
            const double value = C.A[p];
            int q = p;
            for (; q > C.IA[j] && C.JA[q - 1] > row; --q) {
                C.JA[q] = C.JA[q - 1];
                C.A[q] = C.A[q - 1];
            }
            C.JA[q] = row;
            C.A[q] = value;
        }
    return C;
}

std::vector<int> elimination_tree(const sparse::CscMatrix& C_upper)
{
    require_square(C_upper, "elimination tree");
    const int n = C_upper.cols;
    std::vector<int> parent(n, -1);
    std::vector<int> ancestor(n, -1);  // a shortcut towards the root of i's current subtree
    // BEGIN EXERCISE 08.5 elimination_tree #the-elimination-tree
    // HINT: for each column k, for each row i < k of column k: climb from i along `ancestor`
    // HINT: until reaching k or a vertex r with no ancestor yet; on the way point every visited
    // HINT: vertex's ancestor at k (path compression); if the climb ended at such an r, then
    // HINT: parent[r] = k (and ancestor[r] = k).
    for (int k = 0; k < n; ++k)
        for (int p = C_upper.IA[k]; p < C_upper.IA[k + 1]; ++p) {
            int i = C_upper.JA[p];
            while (i != -1 && i < k) {
                const int next = ancestor[i];
                ancestor[i] = k;
                if (next == -1)
                    parent[i] = k;
                i = next;
            }
        }
    // END EXERCISE
    return parent;
}

std::vector<int> tree_postorder(const std::vector<int>& parent)
{
    const int n = static_cast<int>(parent.size());
    // Children lists with the lowest-numbered child first: push in decreasing order.
    std::vector<int> head(n, -1), next(n, -1);
    for (int j = n - 1; j >= 0; --j) {
        const int p = parent[j];
        if (p < -1 || p >= n || p == j)
            throw Error(str("postorder: parent[", j, "] = ", p, "; allowed −1 (a root) or another vertex in [0, ",
                            n, ")"));
        if (p >= 0) {
            next[j] = head[p];
            head[p] = j;
        }
    }
    std::vector<int> post;
    post.reserve(n);
    std::vector<int> stack;
    for (int root = 0; root < n; ++root) {
        if (parent[root] != -1)
            continue;
        stack.push_back(root);
        while (!stack.empty()) {
            const int v = stack.back();
            const int child = head[v];
            if (child == -1) {
                stack.pop_back();
                post.push_back(v);
            } else {
                head[v] = next[child];  // the next child, next time v is on top
                stack.push_back(child);
            }
        }
    }
    if (static_cast<int>(post.size()) != n)
        throw Error(str("postorder: only ", post.size(), " of ", n, " vertices hang below a root: parent has a cycle"));
    return post;
}

std::vector<int> column_counts(const sparse::CscMatrix& C_upper, const std::vector<int>& parent)
{
    require_square(C_upper, "column counts");
    const int n = C_upper.cols;
    if (static_cast<int>(parent.size()) != n)
        throw Error(str("column counts: the tree has ", parent.size(), " vertices, the matrix ", n, " columns"));
    std::vector<int> counts(n, 1);    // the diagonal
    std::vector<int> mark(n, -1);     // mark[j] = k: j already counted for row k
    // BEGIN EXERCISE 08.6 column_counts #symbolic-factorization
    // HINT: row k of L: for each i < k in column k of C_upper, climb i, parent[i], … while the
    // HINT: vertex is not marked for row k (and is < k); each vertex j climbed has L_kj ≠ 0:
    // HINT: counts[j] += 1 and mark it. Mark k itself first so that no climb passes it.
    for (int k = 0; k < n; ++k) {
        mark[k] = k;
        for (int p = C_upper.IA[k]; p < C_upper.IA[k + 1]; ++p)
            for (int j = C_upper.JA[p]; j != -1 && j < k && mark[j] != k; j = parent[j]) {
                ++counts[j];
                mark[j] = k;
            }
    }
    // END EXERCISE
    return counts;
}

SymbolicCholesky symbolic_cholesky(const sparse::CscMatrix& A, const Permutation& perm)
{
    const sparse::CscMatrix C = symmetric_permutation(A, perm);
    SymbolicCholesky S;
    S.n = C.cols;
    S.perm = perm;
    S.parent = elimination_tree(C);
    S.counts = column_counts(C, S.parent);
    S.pointers.assign(S.n + 1, 0);
    for (int j = 0; j < S.n; ++j) {
        S.pointers[j + 1] = S.pointers[j] + S.counts[j];
        S.flops += static_cast<double>(S.counts[j]) * S.counts[j];
    }
    S.nonzeros = S.pointers[S.n];
    return S;
}

namespace {

/// Row k of the up-looking factorization: solves L(0:k, 0:k) x = C(0:k, k) in the pattern of row
/// k of L (the row subtree), appends x_j = L_kj to column j of L, and returns the pivot
/// d = c_kk − Σ_j L_kj². `x` (n entries, zero on entry and on exit), `mark` and `pattern` are
/// work arrays; next[j] is the next free slot of column j of L.
double up_looking_row(const sparse::CscMatrix& C, const std::vector<int>& parent, int k, sparse::CscMatrix& L,
                      std::vector<int>& next, std::vector<double>& x, std::vector<int>& mark, std::vector<int>& pattern)
{
    double d = 0.0;
    // BEGIN EXERCISE 08.7 up_looking_cholesky #up-looking-cholesky
    // HINT: 1. scatter column k of C into x (the diagonal c_kk into d) and collect the pattern:
    // HINT:    from each row i < k climb the tree until k or a vertex marked for k; the vertices of
    // HINT:    each climb, in reverse, go in front of what was collected so far (a topological order).
    // HINT: 2. for each j of the pattern in that order: L_kj = x_j / L_jj (L_jj is the first entry of
    // HINT:    column j); x_i −= L_ij L_kj for the other entries i of column j written so far; d −= L_kj²;
    // HINT:    append (row k, L_kj) to column j at next[j]; reset x_j = 0.
    const int n = C.cols;
    mark[k] = k;
    int top = n;  // the pattern occupies pattern[top … n−1], in topological order
    for (int p = C.IA[k]; p < C.IA[k + 1]; ++p) {
        const int i = C.JA[p];
        if (i == k) {
            d = C.A[p];
            continue;
        }
        x[i] = C.A[p];
        int length = 0;  // the climb from i, collected at the start of pattern, then moved to the top
        for (int j = i; mark[j] != k; j = parent[j]) {
            pattern[length++] = j;
            mark[j] = k;
        }
        while (length > 0)
            pattern[--top] = pattern[--length];
    }
    for (int t = top; t < n; ++t) {
        const int j = pattern[t];
        const int first = L.IA[j];
        const double l_kj = x[j] / L.A[first];
        x[j] = 0.0;
        for (int q = first + 1; q < next[j]; ++q)
            x[L.JA[q]] -= L.A[q] * l_kj;
        d -= l_kj * l_kj;
        L.JA[next[j]] = k;
        L.A[next[j]++] = l_kj;
    }
    // END EXERCISE
    return d;
}

}  // namespace

sparse::CscMatrix up_looking_cholesky(const sparse::CscMatrix& C_upper, const SymbolicCholesky& symbolic)
{
    require_square(C_upper, "up-looking Cholesky");
    const int n = C_upper.cols;
    if (symbolic.n != n || static_cast<int>(symbolic.parent.size()) != n ||
        static_cast<int>(symbolic.pointers.size()) != n + 1 || static_cast<int>(symbolic.perm.size()) != n)
        throw Error(str("up-looking Cholesky: the symbolic factorization is for ", symbolic.n,
                        " unknowns, the matrix has ", n));
    if (symbolic.nonzeros > std::numeric_limits<int>::max())
        throw Error(str("up-looking Cholesky: nnz(L) = ", symbolic.nonzeros, " does not fit the int indices of CSC"));
    sparse::CscMatrix L;
    L.rows = L.cols = n;
    L.IA.resize(n + 1);
    for (int j = 0; j <= n; ++j)
        L.IA[j] = static_cast<int>(symbolic.pointers[j]);
    L.JA.resize(symbolic.nonzeros);
    L.A.resize(symbolic.nonzeros);
    std::vector<int> next(n);
    std::vector<double> x(n, 0.0);
    std::vector<int> mark(n, -1), pattern(n);
    const std::vector<double> tiny = pivot_thresholds(C_upper);
    for (int k = 0; k < n; ++k) {
        const double d = up_looking_row(C_upper, symbolic.parent, k, L, next, x, mark, pattern);
        if (!(d > tiny[k]))
            throw not_positive_definite(symbolic.perm[k], d, tiny[k]);
        // the diagonal is the first entry of column k (rows arrive in increasing order)
        L.JA[L.IA[k]] = k;
        L.A[L.IA[k]] = std::sqrt(d);
        next[k] = L.IA[k] + 1;
    }
    return L;
}

std::string factorization_name(Factorization factorization)
{
    return factorization == Factorization::up_looking ? "up-looking" : "supernodal";
}

// --- SparseCholesky --------------------------------------------------------------------------

struct SparseCholesky::Impl {
    CholeskyOptions options;
    SymbolicCholesky symbolic;
    std::vector<int> pattern_IA, pattern_JA;  // C's upper triangle: the pattern factorize() expects
    CholeskyTimes times;
    std::optional<sparse::CscMatrix> L;                  // up-looking
    std::optional<SupernodalCholesky> supernodal;        // supernodal

    void numeric(const sparse::CscMatrix& C_upper)
    {
        Timer timer;
        if (options.factorization == Factorization::up_looking) {
            L = up_looking_cholesky(C_upper, symbolic);
        } else {
            sparse::CscMatrix C_lower;
            C_lower.rows = C_lower.cols = C_upper.cols;
            sparse::transpose_compressed(sparse::view(C_upper), C_lower.A, C_lower.IA, C_lower.JA);
            supernodal->factorize(C_lower);
            times.numeric_subtrees = supernodal->subtree_seconds();
            times.numeric_top = supernodal->top_seconds();
            if (options.single_precision_copy)
                supernodal->round_to_single();
        }
        times.numeric = timer.seconds();
    }
};

SparseCholesky::SparseCholesky(const sparse::CscMatrix& A, CholeskyOptions options) : impl_(std::make_unique<Impl>())
{
    sparse::validate(A);
    require_square(A, "sparse Cholesky");
    if (A.rows == 0)
        throw Error("sparse Cholesky: the matrix is empty (0×0)");
    Impl& m = *impl_;
    m.options = options;
    Timer timer;
    const Permutation fill = fill_reducing_ordering(A, options.ordering);
    m.times.ordering = timer.seconds();
    timer.restart();
    // Postorder the elimination tree (same fill, contiguous subtrees): perm = fill ∘ post.
    const SymbolicCholesky first = symbolic_cholesky(A, fill);
    const std::vector<int> post = tree_postorder(first.parent);
    const int n = A.cols;
    std::vector<int> new_of_old_label(n);
    for (int k = 0; k < n; ++k)
        new_of_old_label[post[k]] = k;
    SymbolicCholesky& S = m.symbolic;
    S.n = n;
    S.perm.resize(n);
    S.parent.resize(n);
    S.counts.resize(n);
    for (int k = 0; k < n; ++k) {
        S.perm[k] = fill[post[k]];
        const int p = first.parent[post[k]];
        S.parent[k] = p < 0 ? -1 : new_of_old_label[p];
        S.counts[k] = first.counts[post[k]];
    }
    S.pointers.assign(n + 1, 0);
    for (int j = 0; j < n; ++j) {
        S.pointers[j + 1] = S.pointers[j] + S.counts[j];
        S.flops += static_cast<double>(S.counts[j]) * S.counts[j];
    }
    S.nonzeros = S.pointers[n];
    sparse::CscMatrix C = symmetric_permutation(A, S.perm);
    m.pattern_IA = C.IA;
    m.pattern_JA = C.JA;
    if (options.factorization == Factorization::supernodal)
        m.supernodal.emplace(S, C);
    m.times.symbolic = timer.seconds();
    m.numeric(C);
}

SparseCholesky::SparseCholesky(const sparse::CsrMatrix& A, CholeskyOptions options)
    : SparseCholesky(sparse::CscMatrix{A.cols, A.rows, A.A, A.IA, A.JA}, options)
{
    // The CSR arrays of A are the CSC arrays of Aᵀ; for a symmetric A that is A itself.
}

SparseCholesky::SparseCholesky(const Eigen::SparseMatrix<double>& A, CholeskyOptions options)
    : SparseCholesky(sparse::csc_from_eigen(A), options)
{
}

SparseCholesky::~SparseCholesky() = default;
SparseCholesky::SparseCholesky(SparseCholesky&&) noexcept = default;
SparseCholesky& SparseCholesky::operator=(SparseCholesky&&) noexcept = default;

void SparseCholesky::factorize(const sparse::CscMatrix& A)
{
    Impl& m = *impl_;
    if (A.rows != m.symbolic.n || A.cols != m.symbolic.n)
        throw Error(str("sparse Cholesky: factorize got a ", A.rows, "×", A.cols, " matrix; the analysis was for ",
                        m.symbolic.n, "×", m.symbolic.n));
    const sparse::CscMatrix C = symmetric_permutation(A, m.symbolic.perm);
    if (C.IA != m.pattern_IA || C.JA != m.pattern_JA)
        throw Error("sparse Cholesky: factorize got a matrix with a different sparsity pattern (lower triangle) "
                    "than the one analysed; construct a new SparseCholesky for it");
    m.numeric(C);
}

Eigen::MatrixXd SparseCholesky::solve_many(const Eigen::MatrixXd& B) const
{
    const Impl& m = *impl_;
    const int n = m.symbolic.n;
    if (B.rows() != n)
        throw Error(str("sparse Cholesky: the right-hand side has ", B.rows(), " rows, the matrix ", n));
    if (!B.allFinite())
        throw Error("sparse Cholesky: the right-hand side has a non-finite entry");
    const Permutation& perm = m.symbolic.perm;
    Eigen::MatrixXd X(n, B.cols());
    for (int k = 0; k < n; ++k)
        X.row(k) = B.row(perm[k]);  // P b
    if (m.L) {
        // L y = P b, then Lᵀ z = y, column by column of L (the diagonal is each column's first entry)
        const sparse::CscMatrix& L = *m.L;
        for (Eigen::Index c = 0; c < X.cols(); ++c) {
            double* x = X.col(c).data();
            for (int j = 0; j < n; ++j) {
                x[j] /= L.A[L.IA[j]];
                for (int q = L.IA[j] + 1; q < L.IA[j + 1]; ++q)
                    x[L.JA[q]] -= L.A[q] * x[j];
            }
            for (int j = n - 1; j >= 0; --j) {
                double s = x[j];
                for (int q = L.IA[j] + 1; q < L.IA[j + 1]; ++q)
                    s -= L.A[q] * x[L.JA[q]];
                x[j] = s / L.A[L.IA[j]];
            }
        }
    } else {
        m.supernodal->solve_in_place(X);
    }
    Eigen::MatrixXd result(n, B.cols());
    for (int k = 0; k < n; ++k)
        result.row(perm[k]) = X.row(k);  // x = Pᵀ z
    return result;
}

Eigen::VectorXd SparseCholesky::solve_single_precision(const Eigen::VectorXd& b) const
{
    const Impl& m = *impl_;
    const int n = m.symbolic.n;
    if (!m.supernodal || !m.options.single_precision_copy)
        throw Error("sparse Cholesky: single-precision solves need the supernodal factorization with "
                    "single_precision_copy set");
    if (b.size() != n)
        throw Error(str("sparse Cholesky: the right-hand side has ", b.size(), " rows, the matrix ", n));
    if (!b.allFinite())
        throw Error("sparse Cholesky: the right-hand side has a non-finite entry");
    const Permutation& perm = m.symbolic.perm;
    Eigen::VectorXf z(n);
    for (int k = 0; k < n; ++k)
        z[k] = static_cast<float>(b[perm[k]]);  // P b
    m.supernodal->solve_in_place_single(z);
    Eigen::VectorXd x(n);
    for (int k = 0; k < n; ++k)
        x[perm[k]] = z[k];  // x = Pᵀ z
    return x;
}

Eigen::VectorXd SparseCholesky::solve(const Eigen::VectorXd& b) const
{
    const Eigen::MatrixXd B = b;
    return solve_many(B).col(0);
}

int SparseCholesky::rows() const { return impl_->symbolic.n; }
const CholeskyOptions& SparseCholesky::options() const { return impl_->options; }
const Permutation& SparseCholesky::permutation() const { return impl_->symbolic.perm; }
long long SparseCholesky::factor_nonzeros() const { return impl_->symbolic.nonzeros; }
double SparseCholesky::flops() const { return impl_->symbolic.flops; }
const CholeskyTimes& SparseCholesky::times() const { return impl_->times; }

long long SparseCholesky::stored_entries() const
{
    return impl_->supernodal ? impl_->supernodal->stored_entries() : impl_->symbolic.nonzeros;
}

int SparseCholesky::supernodes() const
{
    return impl_->supernodal ? impl_->supernodal->supernodes() : impl_->symbolic.n;
}

sparse::CscMatrix SparseCholesky::factor() const
{
    return impl_->L ? *impl_->L : impl_->supernodal->factor();
}

double symmetric_residual(const sparse::CscMatrix& A, const Eigen::VectorXd& x, const Eigen::VectorXd& b)
{
    if (A.rows != A.cols || x.size() != A.cols || b.size() != A.rows)
        throw Error(str("residual: A is ", A.rows, "×", A.cols, ", x has ", x.size(), " and b ", b.size(),
                        " entries"));
    Eigen::VectorXd Ax = Eigen::VectorXd::Zero(A.rows);
    for (int j = 0; j < A.cols; ++j)
        for (int k = A.IA[j]; k < A.IA[j + 1]; ++k) {
            const int i = A.JA[k];
            if (i < j)
                continue;  // the upper triangle is not read
            Ax[i] += A.A[k] * x[j];
            if (i > j)
                Ax[j] += A.A[k] * x[i];
        }
    const double norm_b = b.norm();
    return (Ax - b).norm() / (norm_b > 0.0 ? norm_b : 1.0);
}

}  // namespace fem::direct
