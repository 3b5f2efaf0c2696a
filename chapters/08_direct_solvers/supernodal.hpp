#pragma once
// Chapter 08: the supernodal (multifrontal) Cholesky factorization, SparseCholesky's fast path.
// docs/08_direct_solvers.md#supernodes-dense-blocks
//
// Neighbouring columns of L with the same pattern below the diagonal form a supernode: together
// they are one dense m×ns block (ns columns, m rows: the columns themselves and the rows below).
// Dense blocks let the factorization run as a few large matrix operations (a blocked dense
// Cholesky, triangular solves through Eigen, and the products C −= A Bᵀ that do almost all the
// flops, with a hand-written AVX2/FMA kernel where the processor has one and Eigen's product
// otherwise) instead of one scalar at a time. Each supernode s
// is factored from its frontal matrix
//     F_s = [ A_s's columns ] + Σ_{children c} extend-add(U_c),
// a partial Cholesky of F_s gives s's columns of L and the update matrix U_s = F_22 − L_21 L_21ᵀ,
// which is added ("extend-add": scattered by row index) into the parent's front. Children finish
// before their parent, so the pending update matrices live on a stack.
//
// The columns must be numbered in a postorder of the elimination tree (SparseCholesky does this),
// so that every supernode is a contiguous range of columns.
//
// Threads (fem::thread_count()): the analysis splits the supernodal tree into independent subtrees
// (each a contiguous range of supernodes, in postorder) and the "top" supernodes above them, by
// estimated flops and never by the number of threads. The subtrees are factored and substituted
// in parallel, the top supernodes one after another with their large products split by column
// panels among the threads. Every front adds its children's updates in the same order on any
// number of threads, so the factor and the solutions are identical to the last bit on 1 thread
// or many. docs/08_direct_solvers.md#threads

#include "08_direct_solvers/sparse_cholesky.hpp"

#include <Eigen/Core>

#include <vector>

namespace fem::direct {

/// When a child supernode is merged into its parent although their patterns differ
/// ("relaxed" supernodes): the merged block may then store explicit zeros. A merge of total width
/// ns with a fraction z of zeros is accepted if ns ≤ 4, or ns ≤ 16 and z < 0.8, or ns ≤ 48 and
/// z < 0.1, or z < 0.05 (CHOLMOD's defaults).
struct SupernodeRelaxation {
    int small = 4, medium = 16, large = 48;
    double medium_zeros = 0.8, large_zeros = 0.1, any_zeros = 0.05;
};

/// The symbolic structure of the supernodes of L and, after factorize(), their dense blocks.
class SupernodalCholesky {
public:
    /// Finds the supernodes of the factor of C: fundamental ones (column j+1 continues j's
    /// supernode when parent[j] = j+1, j is its only child, and counts[j] = counts[j+1] + 1), merged
    /// further by `relaxation`, and the sorted row list of each. `symbolic` must describe C (its
    /// tree in postorder: parent[j] > j). O(nnz(C) + Σ m_s log m_s). fem::Error if the sizes
    /// differ or the tree is not postordered.
    SupernodalCholesky(const SymbolicCholesky& symbolic, const sparse::CscMatrix& C_upper,
                       const SupernodeRelaxation& relaxation = {});

    /// The numeric factorization of C from its LOWER triangle in CSC (the transpose of
    /// symmetric_permutation's result): multifrontal over the supernodes, the subtrees on
    /// thread_count() threads, then the top in order. fem::Error when C is not positive definite,
    /// naming the failed column in the original numbering (symbolic.perm) and its pivot: the first
    /// failing column in the serial order, on any number of threads.
    void factorize(const sparse::CscMatrix& C_lower);

    /// X ← L⁻ᵀ L⁻¹ X in the permuted numbering (each column of X one right-hand side): forward
    /// substitution supernode by supernode (a dense triangular solve and a matrix product per
    /// supernode), then back substitution in reverse order; one column over the subtrees in
    /// parallel, several in blocks of 16 columns on the threads. fem::Error before factorize() or
    /// if X has not n rows.
    void solve_in_place(Eigen::Ref<Eigen::MatrixXd> X) const;

    /// Keeps a copy of the blocks rounded to single precision (made now, dropped by the next
    /// factorize()), for solve_in_place_single. fem::Error before factorize().
    void round_to_single();
    /// x ← L⁻ᵀ L⁻¹ x with the single-precision blocks (one right-hand side, permuted numbering):
    /// the same substitutions as solve_in_place reading half the bytes, with errors of order
    /// 1e-7 κ(L) — what a preconditioner can afford. fem::Error without round_to_single() since
    /// the last factorize(), or if x has not n entries.
    void solve_in_place_single(Eigen::Ref<Eigen::VectorXf> x) const;

    /// Wall times [s] of the last factorize(): its independent subtrees (side by side on the
    /// threads) and its top supernodes (one after another, each front's large products and column
    /// loops on all threads). docs/08_direct_solvers.md#threads
    double subtree_seconds() const { return subtree_seconds_; }
    double top_seconds() const { return top_seconds_; }

    int supernodes() const { return static_cast<int>(first_.size()) - 1; }
    /// The number of independent subtrees the factorization and the substitutions run in parallel.
    int subtrees() const { return static_cast<int>(subtree_begin_.size()); }
    /// Supernodes outside every subtree (the separators near the roots), factored one at a time.
    int top_supernodes() const { return static_cast<int>(top_.size()); }
    /// Columns first(s) … first(s+1)−1 form supernode s.
    int first(int s) const { return first_[s]; }
    /// The number of rows m_s of supernode s (its columns and the rows below).
    int rows(int s) const { return static_cast<int>(row_start_[s + 1] - row_start_[s]); }
    /// Entries of all dense blocks, Σ m_s ns_s (explicit zeros included).
    long long stored_entries() const { return value_start_.back(); }
    /// The factor as CSC: the entries of the dense blocks on and below the diagonal that are not
    /// exactly zero (the explicit zeros of relaxed supernodes are dropped). fem::Error before
    /// factorize().
    sparse::CscMatrix factor() const;

private:
    int n_ = 0;
    Permutation perm_;                    // for error messages: original column names
    std::vector<int> first_;              // supernode s: columns first_[s] … first_[s+1]−1
    std::vector<int> parent_;             // supernodal tree (−1 for a root)
    std::vector<long long> row_start_;    // rows of s: rows_[row_start_[s] … row_start_[s+1]−1]
    std::vector<int> rows_;               // sorted; the first ns_s are s's own columns
    std::vector<long long> value_start_;  // s's m_s×ns_s column-major block at values_[value_start_[s]]
    std::vector<double> values_;
    std::vector<float> single_values_;    // values_ rounded to float (round_to_single), or empty
    std::vector<int> column_to_supernode_;
    bool factored_ = false;
    double subtree_seconds_ = 0.0, top_seconds_ = 0.0;
    // The parallel schedule (docs/08_direct_solvers.md#threads): subtree t is the supernodes
    // subtree_begin_[t] … subtree_root_[t] (its root last); top_ holds the others, increasing.
    std::vector<int> subtree_begin_, subtree_root_;
    std::vector<int> subtree_schedule_;  // the subtrees by decreasing estimated flops
    std::vector<int> top_;
    std::vector<int> children_start_, children_;  // children of s: children_[children_start_[s] …], decreasing

    /// The front of supernode s: A's columns into its block of values_, the children's update
    /// matrices extend-added (updates[i] belongs to children_[children_start_[s] + i], an r_c×r_c
    /// lower triangle), the partial Cholesky, and U_s = F_22 − L_21 L_21ᵀ, formed in W and copied
    /// to `update` (each r×r, lower triangle). `split`: the large products run on all threads.
    /// Returns the local failed column (pivot in `pivot`) or −1.
    int factor_front(int s, const sparse::CscMatrix& C_lower, const double* tiny, const double* const* updates,
                     double* W, double* update, std::vector<int>& position, std::vector<int>& relative, bool split,
                     double& pivot);
    /// A failed pivot: the supernode, the column (permuted numbering) and the pivot.
    struct Failure {
        int supernode = -1, column = -1;
        double pivot = 0.0;
    };
    /// The multifrontal loop over `sequence` (increasing supernodes, stopping before any > stop):
    /// the updates of children in the sequence on its own stack, those of subtree roots taken
    /// from root_updates[subtree_with_root[c]] (and freed). Returns the update matrix still on the
    /// stack at the end (a subtree's root's, r×r), or the first failure through `failure`.
    std::vector<double> factor_supernodes(const std::vector<int>& sequence, int stop, const sparse::CscMatrix& C_lower,
                                          const double* tiny, std::vector<std::vector<double>>& root_updates,
                                          const std::vector<int>& subtree_with_root, bool split, Failure& failure);

    /// The two substitutions with one right-hand side, for the double blocks or their float copy.
    template <class Scalar>
    void solve_vector(const Scalar* values, Scalar* x) const;
};

}  // namespace fem::direct
