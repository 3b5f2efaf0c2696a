// Chapter 08: supernodes (fundamental and relaxed), their row structures, and the multifrontal
// numeric factorization and triangular solves with dense blocks (their products in
// supernodal_kernels.cpp). docs/08_direct_solvers.md#supernodes-dense-blocks
#include "08_direct_solvers/supernodal.hpp"

#include "08_direct_solvers/supernodal_kernels.hpp"

#include "common/error.hpp"
#include "common/parallel.hpp"
#include "common/simd.hpp"
#include "common/timer.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <numeric>
#include <vector>

namespace fem::direct {
namespace {

using Block = Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>>;
using ConstBlock = Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>;

/// Columns per step of the blocked dense factorization of a front.
constexpr int panel_width = 64;

/// Factors with fewer stored entries are factored and substituted on one thread (the same
/// operations either way): below this, starting the threads costs more than they save.
constexpr long long parallel_entries = 100000;

/// On top fronts of at least this many m² entries the loops over columns (assembly, extend-add,
/// copies) run on all threads.
constexpr long long split_front_entries = 65536;

/// body(c) for c in [0, count): on all threads (chunks of 32 columns to whichever thread is free)
/// when `on_threads`, else a plain loop, which costs nothing per call where a parallel region
/// with a false `if` still costs a microsecond (thousands of small fronts).
template <class Body>
void for_each_column(int count, bool on_threads, Body&& body)
{
    if (!on_threads) {
        for (int c = 0; c < count; ++c)
            body(c);
        return;
    }
#pragma omp parallel for schedule(dynamic, 32)
    for (int c = 0; c < count; ++c)
        body(c);
}

/// Products with fewer multiply-adds (m n k) run on one thread: a parallel region costs microseconds.
constexpr double split_multiply_adds = 2e6;

/// subtract_product with C's columns split among the threads when `split` and the product is
/// large: pieces of 48 columns (whole 8×6 register blocks; the last piece takes the rest), each
/// on the AVX2 kernel's path as the whole product would be, so every entry of C sees the same
/// operations in the same order on any number of threads. Without the kernel, on one thread.
void subtract_product_split(int m, int n, int k, const double* A, int lda, const double* B, int ldb, double* C,
                            int ldc, bool split)
{
#ifdef FEM_AVX2_KERNEL
    constexpr int piece_columns = 8 * kernel_cols;
    const int pieces = n / piece_columns;
    if (split && pieces >= 2 && avx2_enabled() && m >= kernel_rows &&
        static_cast<double>(m) * n * k >= split_multiply_adds) {
#pragma omp parallel for schedule(dynamic, 1)
        for (int p = 0; p < pieces; ++p) {
            const int j0 = p * piece_columns, width = p + 1 < pieces ? piece_columns : n - j0;
            subtract_product(m, width, k, A, lda, B + j0, ldb, C + static_cast<long long>(j0) * ldc, ldc);
        }
        return;
    }
#endif
    subtract_product(m, n, k, A, lda, B, ldb, C, ldc);
}

/// C −= A Aᵀ on the lower triangle of the square C (q×q, leading dimension ldc), A q×k (lda), by
/// column panels: each panel also computes the upper half of its small diagonal block (wasted,
/// but a plain product runs faster than a triangular one). The panels are independent products:
/// with `split` (and enough work) they run on all threads, each panel the same as on one.
void lower_rank_update(int q, int k, const double* A, int lda, double* C, int ldc, bool split)
{
    constexpr int width = 120;
    const int panels = (q + width - 1) / width;
    [[maybe_unused]] const bool parallel = split && panels >= 2 && 0.5 * q * static_cast<double>(q) * k >= split_multiply_adds;
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
    for (int p = 0; p < panels; ++p) {
        const int c0 = p * width, cb = std::min(width, q - c0);
        subtract_product(q - c0, cb, k, A + c0, lda, A + c0, lda, C + c0 + static_cast<long long>(c0) * ldc, ldc);
    }
}

/// Dense Cholesky of the kb×kb lower triangle at D (leading dimension ld), right-looking, one
/// column at a time; the pivot of column j must exceed tiny[j] (pivot_thresholds). Returns the
/// local index of a failed pivot (and its value), or −1.
int unblocked_cholesky(double* D, int kb, int ld, const double* tiny, double& failed_pivot)
{
    for (int j = 0; j < kb; ++j) {
        double* const column = D + static_cast<long long>(j) * ld;
        const double d = column[j];
        if (!(d > tiny[j])) {
            failed_pivot = d;
            return j;
        }
        const double l_jj = std::sqrt(d);
        column[j] = l_jj;
        for (int i = j + 1; i < kb; ++i)
            column[i] /= l_jj;
        for (int c = j + 1; c < kb; ++c) {
            double* const target = D + static_cast<long long>(c) * ld;
            const double l_cj = column[c];
            for (int i = c; i < kb; ++i)
                target[i] -= column[i] * l_cj;
        }
    }
    return -1;
}

/// The partial Cholesky of a front: the m×ns block F (leading dimension m) holds the supernode's
/// columns of the frontal matrix; on return its top ns×ns lower triangle is L_11 and the rows
/// below are L_21 = F_21 L_11⁻ᵀ. Blocked, right-looking: per panel of columns an unblocked
/// Cholesky of the diagonal block, a triangular solve for the rows below, and a rank-kb update
/// of the remaining columns. tiny: the pivot thresholds of the ns columns. `split`: the updates run
/// on all threads (subtract_product_split). Returns the local failed column (pivot in
/// failed_pivot), or −1.
int partial_cholesky(double* F, int m, int ns, const double* tiny, bool split, double& failed_pivot)
{
    Block front(F, m, ns, Eigen::OuterStride<>(m));
    for (int k0 = 0; k0 < ns; k0 += panel_width) {
        const int kb = std::min(panel_width, ns - k0);
        const int failed = unblocked_cholesky(F + static_cast<long long>(k0) * m + k0, kb, m, tiny + k0, failed_pivot);
        if (failed >= 0)
            return k0 + failed;
        const int below = m - k0 - kb;
        if (below == 0)
            break;
        const auto D = front.block(k0, k0, kb, kb);
        auto P = front.block(k0 + kb, k0, below, kb);
        D.triangularView<Eigen::Lower>().transpose().solveInPlace<Eigen::OnTheRight>(P);
        const int q = ns - k0 - kb;  // columns of the supernode still to factor
        if (q > 0) {
            const double* const panel = F + (k0 + kb) + static_cast<long long>(k0) * m;  // P, leading dimension m
            double* const trailing = F + (k0 + kb) + static_cast<long long>(k0 + kb) * m;
            lower_rank_update(q, kb, panel, m, trailing, m, split);
            subtract_product_split(m - ns, q, kb, panel + q, m, panel, m, trailing + q, m, split);
        }
    }
    return -1;
}

/// The sizes of the multifrontal loop's work areas over a sequence of supernodes: the peak of the
/// update stack (Σ r² of the pending update matrices) and the largest update matrix r².
struct StackSize {
    long long peak = 0, largest = 0;
};
template <class Sequence>
StackSize update_stack_size(const Sequence& supernodes, const std::vector<int>& parent,
                            const SupernodalCholesky& chol)
{
    const auto update_rows = [&](int s) { return static_cast<long long>(chol.rows(s) - (chol.first(s + 1) - chol.first(s))); };
    StackSize size;
    long long stack = 0;
    std::vector<int> pending;
    for (const int s : supernodes) {
        while (!pending.empty() && parent[pending.back()] == s) {
            stack -= update_rows(pending.back()) * update_rows(pending.back());
            pending.pop_back();
        }
        const long long r = update_rows(s);
        size.largest = std::max(size.largest, r * r);
        if (r > 0) {
            stack += r * r;
            size.peak = std::max(size.peak, stack);
            pending.push_back(s);
        }
    }
    return size;
}

/// The split of the supernodal tree (postordered; `subtree_flops[s]`: the estimated flops of s and
/// its descendants) into independent subtrees and the top supernodes above them. Starting from
/// the roots, the heaviest subtree is replaced by its children (its root moves to the top) until
/// the subtrees, dealt largest first to the less loaded of two threads, load neither more than
/// 5 % above half their sum; or the heaviest is one supernode, or 2000 steps passed. Depends on
/// the tree alone, never on the number of threads. Returns the roots of the subtrees; `top`
/// receives the others, increasing.
std::vector<int> split_into_subtrees(const std::vector<int>& parent, const std::vector<double>& subtree_flops,
                                     const std::vector<int>& children_start, const std::vector<int>& children,
                                     std::vector<int>& top)
{
    std::vector<int> roots;
    for (int s = 0; s < static_cast<int>(parent.size()); ++s)
        if (parent[s] < 0)
            roots.push_back(s);
    const auto heavier = [&](int a, int b) {
        return subtree_flops[a] > subtree_flops[b] || (subtree_flops[a] == subtree_flops[b] && a < b);
    };
    top.clear();
    for (int step = 0; step < 2000 && !roots.empty(); ++step) {
        std::sort(roots.begin(), roots.end(), heavier);
        double load[2] = {0.0, 0.0};
        for (const int r : roots)
            load[load[1] < load[0] ? 1 : 0] += subtree_flops[r];
        const int heaviest = roots.front();
        if (std::max(load[0], load[1]) <= 0.525 * (load[0] + load[1]) ||
            children_start[heaviest] == children_start[heaviest + 1])
            break;
        roots.erase(roots.begin());
        top.push_back(heaviest);
        roots.insert(roots.end(), children.begin() + children_start[heaviest],
                     children.begin() + children_start[heaviest + 1]);
    }
    std::sort(top.begin(), top.end());
    return roots;
}

}  // namespace

SupernodalCholesky::SupernodalCholesky(const SymbolicCholesky& symbolic, const sparse::CscMatrix& C_upper,
                                       const SupernodeRelaxation& relaxation)
    : n_(symbolic.n), perm_(symbolic.perm)
{
    const int n = n_;
    if (C_upper.cols != n || C_upper.rows != n || static_cast<int>(symbolic.parent.size()) != n ||
        static_cast<int>(symbolic.counts.size()) != n || static_cast<int>(perm_.size()) != n)
        throw Error(str("supernodes: the symbolic factorization is for ", symbolic.n, " unknowns, the matrix is ",
                        C_upper.rows, "×", C_upper.cols));
    const std::vector<int>& parent = symbolic.parent;
    const std::vector<int>& counts = symbolic.counts;
    std::vector<int> children(n, 0);
    for (int j = 0; j < n; ++j) {
        if (parent[j] != -1 && (parent[j] <= j || parent[j] >= n))
            throw Error(str("supernodes: parent[", j, "] = ", parent[j], "; the tree must be postordered (parent > child)"));
        if (parent[j] >= 0)
            ++children[parent[j]];
    }

    // 1. Fundamental supernodes: chains j → j+1 with one child and counts dropping by one.
    std::vector<int> start;  // first column of each fundamental supernode
    for (int j = 0; j < n; ++j)
        if (j == 0 || !(parent[j - 1] == j && children[j] == 1 && counts[j - 1] == counts[j] + 1))
            start.push_back(j);
    const int fundamental = static_cast<int>(start.size());
    std::vector<int> end(fundamental), owner(n);
    for (int s = 0; s < fundamental; ++s) {
        end[s] = s + 1 < fundamental ? start[s + 1] : n;
        for (int j = start[s]; j < end[s]; ++j)
            owner[j] = s;
    }

    // 2. Relaxed merges: a supernode absorbs the child that ends right where it starts, while the
    //    merged block stays dense enough. merged_into is a union-find towards the surviving parent.
    std::vector<int> super_parent(fundamental), merged_into(fundamental);
    std::vector<long long> rows_of(fundamental), exact(fundamental);
    std::iota(merged_into.begin(), merged_into.end(), 0);
    for (int s = 0; s < fundamental; ++s) {
        const int last = end[s] - 1;
        super_parent[s] = parent[last] < 0 ? -1 : owner[parent[last]];
        rows_of[s] = counts[start[s]];
        exact[s] = 0;
        for (int j = start[s]; j < end[s]; ++j)
            exact[s] += counts[j];
    }
    const auto find = [&](int s) {
        while (merged_into[s] != s)
            s = merged_into[s] = merged_into[merged_into[s]];
        return s;
    };
    std::vector<int> last_owner(n, -1);  // the live supernode whose last column is j
    for (int s = 0; s < fundamental; ++s) {
        for (;;) {
            if (start[s] == 0)
                break;
            const int c = last_owner[start[s] - 1];
            if (c < 0 || find(c) != c || super_parent[c] < 0 || find(super_parent[c]) != s)
                break;
            const long long ns = (end[s] - start[s]) + (end[c] - start[c]);
            const long long m = (end[c] - start[c]) + rows_of[s];
            const long long stored = ns * m - ns * (ns - 1) / 2;
            const double zeros = static_cast<double>(stored - exact[s] - exact[c]) / static_cast<double>(stored);
            const bool accept = ns <= relaxation.small || (ns <= relaxation.medium && zeros < relaxation.medium_zeros) ||
                                (ns <= relaxation.large && zeros < relaxation.large_zeros) || zeros < relaxation.any_zeros;
            if (!accept)
                break;
            merged_into[c] = s;
            start[s] = start[c];
            rows_of[s] = m;
            exact[s] += exact[c];
        }
        last_owner[end[s] - 1] = s;
    }

    // 3. The surviving supernodes, in column order, and their tree.
    first_.clear();
    std::vector<int> final_end;
    for (int s = 0; s < fundamental; ++s)
        if (find(s) == s) {
            first_.push_back(start[s]);
            final_end.push_back(end[s]);
        }
    const int S = static_cast<int>(first_.size());
    first_.push_back(n);
    column_to_supernode_.assign(n, 0);
    for (int s = 0; s < S; ++s)
        for (int j = first_[s]; j < first_[s + 1]; ++j)
            column_to_supernode_[j] = s;
    parent_.assign(S, -1);
    for (int s = 0; s < S; ++s) {
        const int p = parent[first_[s + 1] - 1];
        parent_[s] = p < 0 ? -1 : column_to_supernode_[p];
    }

    // 4. Row structures: rows(s) = s's columns ∪ (rows below s of C's columns in s) ∪ (rows below s
    //    of each child's structure). C's lower triangle column j is row j of C_upper: transpose
    //    the pattern once.
    std::vector<int> lower_start(n + 1, 0), lower_rows(C_upper.IA[n]);
    for (int k = 0; k < C_upper.IA[n]; ++k)
        ++lower_start[C_upper.JA[k] + 1];
    std::partial_sum(lower_start.begin(), lower_start.end(), lower_start.begin());
    {
        std::vector<int> next(lower_start.begin(), lower_start.end() - 1);
        for (int i = 0; i < n; ++i)
            for (int k = C_upper.IA[i]; k < C_upper.IA[i + 1]; ++k)
                lower_rows[next[C_upper.JA[k]]++] = i;
    }
    std::vector<int> child_head(S, -1), child_next(S, -1);
    for (int s = S - 1; s >= 0; --s)
        if (parent_[s] >= 0) {
            child_next[s] = child_head[parent_[s]];
            child_head[parent_[s]] = s;
        }
    row_start_.assign(S + 1, 0);
    rows_.clear();
    std::vector<int> mark(n, -1), below;
    for (int s = 0; s < S; ++s) {
        const int f = first_[s], e = first_[s + 1];
        below.clear();
        for (int j = f; j < e; ++j)
            for (int k = lower_start[j]; k < lower_start[j + 1]; ++k) {
                const int i = lower_rows[k];
                if (i >= e && mark[i] != s) {
                    mark[i] = s;
                    below.push_back(i);
                }
            }
        for (int c = child_head[s]; c >= 0; c = child_next[c]) {
            const int nc = first_[c + 1] - first_[c];
            for (long long t = row_start_[c] + nc; t < row_start_[c + 1]; ++t) {
                const int i = rows_[t];
                if (i >= e && mark[i] != s) {
                    mark[i] = s;
                    below.push_back(i);
                }
            }
        }
        std::sort(below.begin(), below.end());
        for (int j = f; j < e; ++j)
            rows_.push_back(j);
        rows_.insert(rows_.end(), below.begin(), below.end());
        row_start_[s + 1] = static_cast<long long>(rows_.size());
    }
    value_start_.assign(S + 1, 0);
    for (int s = 0; s < S; ++s)
        value_start_[s + 1] = value_start_[s] + static_cast<long long>(rows(s)) * (first_[s + 1] - first_[s]);

    // 5. The parallel schedule: the children of each supernode (decreasing, the order the serial
    //    stack pops them), independent subtrees by estimated flops (ns m² per supernode), the top.
    children_start_.assign(S + 1, 0);
    for (int s = 0; s < S; ++s)
        if (parent_[s] >= 0)
            ++children_start_[parent_[s] + 1];
    std::partial_sum(children_start_.begin(), children_start_.end(), children_start_.begin());
    children_.assign(children_start_[S], 0);
    {
        std::vector<int> next(children_start_.begin(), children_start_.end() - 1);
        for (int s = S - 1; s >= 0; --s)
            if (parent_[s] >= 0)
                children_[next[parent_[s]]++] = s;
    }
    std::vector<double> subtree_flops(S, 0.0);
    std::vector<int> first_descendant(S);
    std::iota(first_descendant.begin(), first_descendant.end(), 0);
    for (int s = 0; s < S; ++s) {
        subtree_flops[s] += static_cast<double>(first_[s + 1] - first_[s]) * rows(s) * rows(s);
        if (parent_[s] >= 0) {
            subtree_flops[parent_[s]] += subtree_flops[s];
            first_descendant[parent_[s]] = std::min(first_descendant[parent_[s]], first_descendant[s]);
        }
    }
    subtree_root_ = split_into_subtrees(parent_, subtree_flops, children_start_, children_, top_);
    subtree_schedule_.resize(subtree_root_.size());
    std::iota(subtree_schedule_.begin(), subtree_schedule_.end(), 0);
    std::sort(subtree_root_.begin(), subtree_root_.end());
    subtree_begin_.clear();
    for (const int root : subtree_root_)
        subtree_begin_.push_back(first_descendant[root]);
    std::stable_sort(subtree_schedule_.begin(), subtree_schedule_.end(),
                     [&](int a, int b) { return subtree_flops[subtree_root_[a]] > subtree_flops[subtree_root_[b]]; });
}

int SupernodalCholesky::factor_front(int s, const sparse::CscMatrix& C_lower, const double* tiny,
                                     const double* const* updates, double* W, double* update,
                                     std::vector<int>& position, std::vector<int>& relative, bool split,
                                     double& pivot)
{
    const int f = first_[s];
    const int ns = first_[s + 1] - f;
    const int m = rows(s);
    const int r = m - ns;
    const int* const row = rows_.data() + row_start_[s];
    double* const L = values_.data() + value_start_[s];
    for (int t = 0; t < m; ++t)
        position[row[t]] = t;

    // The loops over columns below write each column from one thread, in the serial order within it:
    // on a large top front (split) they run on all threads with the same bits.
    const bool columns_on_threads = split && static_cast<long long>(m) * m >= split_front_entries;

    // The front: A's columns of s into the zeroed L (m×ns), zero update area W (r×r, lower triangle).
    for_each_column(ns, columns_on_threads, [&](int c) {
        double* const column = L + static_cast<long long>(c) * m;
        std::fill(column, column + m, 0.0);
        for (int k = C_lower.IA[f + c]; k < C_lower.IA[f + c + 1]; ++k)
            column[position[C_lower.JA[k]]] += C_lower.A[k];
    });
    for_each_column(r, columns_on_threads, [&](int c) {
        std::fill(W + static_cast<long long>(c) * r + c, W + static_cast<long long>(c + 1) * r, 0.0);
    });

    // Extend-add the update matrices of the children, the last one first.
    for (int k = children_start_[s]; k < children_start_[s + 1]; ++k) {
        const int c = children_[k];
        const int nc = first_[c + 1] - first_[c];
        const int rc = rows(c) - nc;
        const double* const U = updates[k - children_start_[s]];
        const int* const child_rows = rows_.data() + row_start_[c] + nc;
        relative.resize(rc);
        for (int t = 0; t < rc; ++t)
            relative[t] = position[child_rows[t]];
        for_each_column(rc, columns_on_threads, [&](int jj) {
            const int pj = relative[jj];
            const double* const source = U + static_cast<long long>(jj) * rc;
            if (pj < ns) {
                double* const target = L + static_cast<long long>(pj) * m;
                for (int ii = jj; ii < rc; ++ii)
                    target[relative[ii]] += source[ii];
            } else {
                double* const target = W + static_cast<long long>(pj - ns) * r - ns;
                for (int ii = jj; ii < rc; ++ii)
                    target[relative[ii]] += source[ii];
            }
        });
    }

    const int failed = partial_cholesky(L, m, ns, tiny + f, split, pivot);
    if (failed >= 0)
        return failed;
    if (r > 0) {
        lower_rank_update(r, ns, L + ns, m, W, r, split);  // W −= L21 L21ᵀ
        for_each_column(r, columns_on_threads, [&](int c) {
            std::memcpy(update + static_cast<long long>(c) * r + c, W + static_cast<long long>(c) * r + c,
                        sizeof(double) * (r - c));
        });
    }
    return -1;
}

std::vector<double> SupernodalCholesky::factor_supernodes(const std::vector<int>& sequence, int stop,
                                                          const sparse::CscMatrix& C_lower, const double* tiny,
                                                          std::vector<std::vector<double>>& root_updates,
                                                          const std::vector<int>& subtree_with_root, bool split,
                                                          Failure& failure)
{
    const StackSize size = update_stack_size(sequence, parent_, *this);
    std::vector<double> stack_values(static_cast<std::size_t>(size.peak));
    std::vector<double> work(static_cast<std::size_t>(size.largest));
    struct Pending {
        int supernode;
        long long offset;
    };
    std::vector<Pending> stack;
    long long stack_top = 0;
    thread_local std::vector<int> position, relative;  // one per thread: position is n long
    position.resize(std::max<std::size_t>(position.size(), static_cast<std::size_t>(n_)));
    std::vector<const double*> updates;
    for (const int s : sequence) {
        if (s > stop)
            break;
        updates.clear();
        for (int k = children_start_[s]; k < children_start_[s + 1]; ++k) {
            const int c = children_[k], t = subtree_with_root[c];
            if (t >= 0) {
                updates.push_back(root_updates[t].data());
            } else {  // on top of the stack: the children are popped in decreasing order
                updates.push_back(stack_values.data() + stack.back().offset);
                stack_top = stack.back().offset;
                stack.pop_back();
            }
        }
        const int r = rows(s) - (first_[s + 1] - first_[s]);
        double pivot = 0.0;
        const int failed = factor_front(s, C_lower, tiny, updates.data(), work.data(), stack_values.data() + stack_top,
                                        position, relative, split, pivot);
        if (failed >= 0) {
            failure = {s, first_[s] + failed, pivot};
            return {};
        }
        for (int k = children_start_[s]; k < children_start_[s + 1]; ++k)
            if (subtree_with_root[children_[k]] >= 0)
                std::vector<double>().swap(root_updates[subtree_with_root[children_[k]]]);
        if (r > 0) {
            stack.push_back({s, stack_top});
            stack_top += static_cast<long long>(r) * r;
        }
    }
    stack_values.resize(static_cast<std::size_t>(stack_top));  // the last root's update, at offset 0
    stack_values.shrink_to_fit();
    return stack_values;
}

void SupernodalCholesky::factorize(const sparse::CscMatrix& C_lower)
{
    const int n = n_;
    if (C_lower.rows != n || C_lower.cols != n)
        throw Error(str("supernodal factorization: the matrix is ", C_lower.rows, "×", C_lower.cols,
                        ", the analysis was for ", n, "×", n));
    factored_ = false;
    single_values_.clear();
    const int S = supernodes();
    const std::vector<double> tiny = pivot_thresholds(C_lower);
    values_.resize(static_cast<std::size_t>(stored_entries()));  // each front zeroes its own block

    // 1. The subtrees, in parallel: the heaviest first, each taken by the next free thread. Each
    //    keeps its root's update matrix for the top.
    Timer phase;
    const int T = subtrees();
    std::vector<int> subtree_with_root(S, -1);
    for (int t = 0; t < T; ++t)
        subtree_with_root[subtree_root_[t]] = t;
    std::vector<std::vector<double>> root_updates(T);
    std::vector<Failure> failures(T);
    std::vector<std::exception_ptr> errors(T);
#pragma omp parallel for schedule(dynamic, 1) if (stored_entries() >= parallel_entries)
    for (int k = 0; k < T; ++k) {
        const int t = subtree_schedule_[k];
        try {
            std::vector<int> sequence(subtree_root_[t] - subtree_begin_[t] + 1);
            std::iota(sequence.begin(), sequence.end(), subtree_begin_[t]);
            root_updates[t] = factor_supernodes(sequence, S, C_lower, tiny.data(), root_updates, subtree_with_root,
                                                false, failures[t]);
        } catch (...) {
            errors[t] = std::current_exception();
        }
    }
    for (const std::exception_ptr& error : errors)
        if (error)
            std::rethrow_exception(error);
    // The serial order fails at the smallest failed supernode: a failure in a subtree stops the
    // top before the supernodes after it (a top supernode before it may fail first).
    Failure first;
    for (const Failure& failure : failures)
        if (failure.supernode >= 0 && (first.supernode < 0 || failure.supernode < first.supernode))
            first = failure;
    const int stop = first.supernode < 0 ? S : first.supernode;

    subtree_seconds_ = phase.seconds();

    // 2. The top supernodes, in order, each on all threads.
    phase.restart();
    Failure top_failure;
    factor_supernodes(top_, stop, C_lower, tiny.data(), root_updates, subtree_with_root,
                      stored_entries() >= parallel_entries, top_failure);
    top_seconds_ = phase.seconds();
    if (top_failure.supernode >= 0)
        first = top_failure;
    if (first.supernode >= 0)
        throw not_positive_definite(perm_[first.column], first.pivot, tiny[first.column]);
    factored_ = true;
}

template <class Scalar>
void SupernodalCholesky::solve_vector(const Scalar* values, Scalar* x) const
{
    // One right-hand side. Supernode s owns the unknowns f … f+ns−1 and a column-major m×ns panel
    // of L: its diagonal block on top, the r = m − ns rows below it (the unknowns `below`). The
    // panel's unknowns are gathered into w (m), and the substitution runs over the panel four
    // columns at a time: a 4×4 triangle by scalars, then one pass of the columns' entries below it
    // (diagonal block and rows below together: each stored entry of L is read once per solve).
    //
    // Threads: forward, the subtrees run in parallel; what a subtree adds to unknowns outside it
    // (its root's rows below, all in the top) goes into a buffer of its own, and the buffers are
    // added to x in subtree order, on any number of threads; then the top in order. Backward, the
    // top in reverse order, then the subtrees in parallel (reading the top's unknowns).
    constexpr int step = 4;
    const int S = supernodes(), T = subtrees();
    int largest = 0;
    for (int s = 0; s < S; ++s)
        largest = std::max(largest, rows(s));
    const auto below_rows = [&](int s) { return rows_.data() + row_start_[s] + (first_[s + 1] - first_[s]); };

    // L y = b at supernode s; rows ≥ limit are outside the subtree: added to outside[k] where
    // outside_rows[k] is that row (both sorted).
    const auto forward = [&](int s, Scalar* w, int limit, const int* outside_rows, Scalar* outside) {
        const int f = first_[s], ns = first_[s + 1] - f, m = rows(s);
        const Scalar* const P = values + value_start_[s];
        const int* const below = below_rows(s);
        std::copy(x + f, x + f + ns, w);
        std::fill(w + ns, w + m, Scalar(0));
        for (int j0 = 0; j0 < ns; j0 += step) {
            const int jb = std::min(step, ns - j0);
            for (int j = j0; j < j0 + jb; ++j) {
                w[j] /= P[j + static_cast<long long>(j) * m];
                for (int i = j + 1; i < j0 + jb; ++i)
                    w[i] -= P[i + static_cast<long long>(j) * m] * w[j];
            }
            subtract_panel_product<false>(m - j0 - jb, jb, P + j0 + jb + static_cast<long long>(j0) * m, m, w + j0,
                                          w + j0 + jb);
        }
        std::copy(w, w + ns, x + f);
        int i = 0, k = 0;
        for (; i < m - ns && below[i] < limit; ++i)
            x[below[i]] += w[ns + i];
        for (; i < m - ns; ++i) {
            while (outside_rows[k] < below[i])
                ++k;
            outside[k] += w[ns + i];
        }
    };
    // Lᵀ x = y at supernode s.
    const auto backward = [&](int s, Scalar* w) {
        const int f = first_[s], ns = first_[s + 1] - f, m = rows(s);
        const Scalar* const P = values + value_start_[s];
        const int* const below = below_rows(s);
        std::copy(x + f, x + f + ns, w);
        for (int i = 0; i < m - ns; ++i)
            w[ns + i] = x[below[i]];
        for (int j0 = (ns - 1) / step * step; j0 >= 0; j0 -= step) {
            const int jb = std::min(step, ns - j0);
            subtract_panel_product<true>(m - j0 - jb, jb, P + j0 + jb + static_cast<long long>(j0) * m, m, w + j0 + jb,
                                         w + j0);
            for (int j = j0 + jb - 1; j >= j0; --j) {
                for (int i = j + 1; i < j0 + jb; ++i)
                    w[j] -= P[i + static_cast<long long>(j) * m] * w[i];
                w[j] /= P[j + static_cast<long long>(j) * m];
            }
        }
        std::copy(w, w + ns, x + f);
    };

    std::vector<std::vector<Scalar>> outside(T);
#pragma omp parallel if (stored_entries() >= parallel_entries)
    {
        std::vector<Scalar> work(static_cast<std::size_t>(largest));
#pragma omp for schedule(dynamic, 1)
        for (int k = 0; k < T; ++k) {
            const int t = subtree_schedule_[k], root = subtree_root_[t];
            outside[t].assign(static_cast<std::size_t>(rows(root) - (first_[root + 1] - first_[root])), Scalar(0));
            for (int s = subtree_begin_[t]; s <= root; ++s)
                forward(s, work.data(), first_[root + 1], below_rows(root), outside[t].data());
        }
    }
    for (int t = 0; t < T; ++t) {
        const int* const rows_outside = below_rows(subtree_root_[t]);
        for (std::size_t i = 0; i < outside[t].size(); ++i)
            x[rows_outside[i]] += outside[t][i];
    }
    std::vector<Scalar> work(static_cast<std::size_t>(largest));
    for (const int s : top_)
        forward(s, work.data(), n_, nullptr, nullptr);
    for (auto s = top_.rbegin(); s != top_.rend(); ++s)
        backward(*s, work.data());
#pragma omp parallel if (stored_entries() >= parallel_entries)
    {
        std::vector<Scalar> thread_work(static_cast<std::size_t>(largest));
#pragma omp for schedule(dynamic, 1)
        for (int k = 0; k < T; ++k) {
            const int t = subtree_schedule_[k];
            for (int s = subtree_root_[t]; s >= subtree_begin_[t]; --s)
                backward(s, thread_work.data());
        }
    }
}

void SupernodalCholesky::round_to_single()
{
    if (!factored_)
        throw Error("supernodal factorization: round_to_single() before factorize()");
    single_values_.assign(values_.begin(), values_.end());
}

void SupernodalCholesky::solve_in_place_single(Eigen::Ref<Eigen::VectorXf> x) const
{
    if (!factored_ || single_values_.size() != values_.size())
        throw Error("supernodal solve: no single-precision factor (call round_to_single() after factorize())");
    if (x.size() != n_)
        throw Error(str("supernodal solve: the right-hand side has ", x.size(), " rows, the matrix ", n_));
    solve_vector(single_values_.data(), x.data());
}

void SupernodalCholesky::solve_in_place(Eigen::Ref<Eigen::MatrixXd> X) const
{
    if (!factored_)
        throw Error("supernodal solve: the matrix has not been factored (or its factorization failed)");
    if (X.rows() != n_)
        throw Error(str("supernodal solve: the right-hand side has ", X.rows(), " rows, the matrix ", n_));
    if (X.cols() == 1) {
        solve_vector(values_.data(), X.data());
        return;
    }
    // Several right-hand sides: blocks of 16 columns on the threads, each block by blocked
    // substitutions (a triangular solve and a product per supernode). Inside a parallel loop
    // Eigen's products run on one thread, so each column's bits do not depend on the threads.
    constexpr Eigen::Index block_columns = 16;
    const int S = supernodes();
    int largest = 0;
    for (int s = 0; s < S; ++s)
        largest = std::max(largest, rows(s) - (first_[s + 1] - first_[s]));
    const Eigen::Index blocks = (X.cols() + block_columns - 1) / block_columns;
    parallel_for(blocks, [&](Eigen::Index b) {
        auto Xb = X.middleCols(b * block_columns, std::min(block_columns, X.cols() - b * block_columns));
        Eigen::MatrixXd work(largest, Xb.cols());
        for (int s = 0; s < S; ++s) {  // forward: L Y = B
            const int f = first_[s], ns = first_[s + 1] - f, m = rows(s), r = m - ns;
            const ConstBlock L(values_.data() + value_start_[s], m, ns, Eigen::OuterStride<>(m));
            auto Xs = Xb.middleRows(f, ns);
            L.topRows(ns).triangularView<Eigen::Lower>().solveInPlace(Xs);
            if (r > 0) {
                auto T = work.topRows(r);
                T.noalias() = L.bottomRows(r) * Xs;
                const int* const below = rows_.data() + row_start_[s] + ns;
                for (int t = 0; t < r; ++t)
                    Xb.row(below[t]) -= T.row(t);
            }
        }
        for (int s = S - 1; s >= 0; --s) {  // backward: Lᵀ X = Y
            const int f = first_[s], ns = first_[s + 1] - f, m = rows(s), r = m - ns;
            const ConstBlock L(values_.data() + value_start_[s], m, ns, Eigen::OuterStride<>(m));
            auto Xs = Xb.middleRows(f, ns);
            if (r > 0) {
                auto T = work.topRows(r);
                const int* const below = rows_.data() + row_start_[s] + ns;
                for (int t = 0; t < r; ++t)
                    T.row(t) = Xb.row(below[t]);
                Xs.noalias() -= L.bottomRows(r).transpose() * T;
            }
            L.topRows(ns).triangularView<Eigen::Lower>().transpose().solveInPlace(Xs);
        }
    });
}

sparse::CscMatrix SupernodalCholesky::factor() const
{
    if (!factored_)
        throw Error("supernodal factor: the matrix has not been factored");
    sparse::CscMatrix L;
    L.rows = L.cols = n_;
    L.IA.assign(n_ + 1, 0);
    for (int s = 0; s < supernodes(); ++s) {
        const int f = first_[s], ns = first_[s + 1] - f, m = rows(s);
        const double* const block = values_.data() + value_start_[s];
        const int* const row = rows_.data() + row_start_[s];
        for (int c = 0; c < ns; ++c) {
            for (int t = c; t < m; ++t) {
                const double value = block[static_cast<long long>(c) * m + t];
                if (value != 0.0) {
                    L.JA.push_back(row[t]);
                    L.A.push_back(value);
                }
            }
            L.IA[f + c + 1] = static_cast<int>(L.A.size());
        }
    }
    return L;
}

}  // namespace fem::direct
