#pragma once
// Chapter 09: one interface for every linear solver of the course, chosen by name.
// docs/09_conjugate_gradient.md#one-interface-for-every-solver
//
// The chapters after this one solve symmetric positive definite systems A x = b (the implicit
// step of chapter 10, the warped stiffness of chapter 11, Newton's systems of chapter 12). They
// pick a solver by name and use it through LinearSolver:
//
//     auto solver = fem::cg::make_solver("default");    // or "ours-pcg-ic0", "cholmod", ...
//     solver->prepare(A);                               // factor, or build the preconditioner
//     Eigen::VectorXd x = solver->solve(b);             // as often as b changes
//     solver->solve(b, x);                              // iterative: x is also the warm start
//     solver->prepare(A2);                              // A changed: a direct solver reuses its
//                                                       // analysis when the pattern is the same
//
// Names (solver_names() lists those this build has):
//   ours-cholesky     chapter 08's supernodal sparse Cholesky, nested-dissection ordering
//   ours-cg           conjugate_gradient on A's lower triangle (symmetric SpMV of chapter 07)
//   ours-pcg-jacobi   preconditioned_conjugate_gradient with JacobiPreconditioner
//   ours-pcg-ic0      preconditioned_conjugate_gradient with IncompleteCholesky (shifted if needed)
//   eigen-llt         Eigen::SimplicialLLT (AMD ordering)
//   eigen-cg          Eigen::ConjugateGradient with its defaults (lower triangle, diagonal
//                     preconditioner)
//   cholmod           CHOLMOD's supernodal Cholesky through Eigen::CholmodSupernodalLLT, only in
//                     a build that found SuiteSparse (cholmod_available())
//   default           default_solver_name() = "ours-cholesky": the fastest correct one on this
//                     chapter's measurements (docs/09_conjugate_gradient.md#which-solver-by-default)
//
// Every solver reports SolveStats; an iterative solver that does not reach its tolerance within
// its cap, and a direct solver that meets a matrix that is not positive definite, throw fem::Error.

#include "09_conjugate_gradient/conjugate_gradient.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace fem::cg {

/// prepare() rejects A unless max |A_ij − A_ji| ≤ symmetry_tolerance · max |A_ij|: assembled
/// matrices are symmetric up to the round-off of summing element entries in different orders.
inline constexpr double symmetry_tolerance = 1e-12;

/// How make_solver sets up a solver. Iterative solvers only: direct ones ignore both.
struct SolverOptions {
    double relative_tolerance = default_relative_tolerance;  ///< ‖b − A x‖ ≤ τ ‖b‖
    int max_iterations = 0;  ///< 0: iteration_cap_per_unknown · n
};

/// What the last prepare() and solve() did.
struct SolveStats {
    int iterations = 0;              ///< CG iterations of the last solve (0 for a direct solver)
    double prepare_seconds = 0.0;    ///< wall time of the last prepare()
    double solve_seconds = 0.0;      ///< wall time of the last solve (without the residual check)
};

/// A solver of A x = b for a sparse symmetric positive definite A (both triangles stored).
/// docs/09_conjugate_gradient.md#one-interface-for-every-solver
class LinearSolver {
public:
    virtual ~LinearSolver() = default;
    LinearSolver(const LinearSolver&) = delete;
    LinearSolver& operator=(const LinearSolver&) = delete;

    /// The name it was made with ("default" resolved), e.g. "ours-pcg-ic0".
    const std::string& name() const { return name_; }
    /// True for a factorization (prepare is expensive, solve cheap), false for an iterative one.
    virtual bool is_direct() const = 0;

    /// Factor A (direct) or build the preconditioner (iterative); call it again whenever A changes.
    /// The solver keeps a copy of A (for the residual check). fem::Error if A is empty, not square,
    /// not finite or not symmetric (symmetry_tolerance), and for a direct solver if A is not
    /// positive definite; after an error the solver is unprepared (solve refuses), but after a
    /// factorization that failed on A's values it keeps A's pattern and its analysis: the next
    /// matrix of that pattern (Newton's definite Hessian after an exact one that failed) is only
    /// factored, not ordered and analysed anew.
    void prepare(const Eigen::SparseMatrix<double>& A);

    /// x with A x = b, starting an iterative solver from x = 0.
    Eigen::VectorXd solve(const Eigen::VectorXd& b);
    /// The same, with x on entry the starting guess of an iterative solver (a warm start; a
    /// direct solver ignores it) and on exit the solution. An x of the wrong size starts from 0.
    /// fem::Error before prepare(), if b has not size() entries or is not finite, if an
    /// iterative solver misses its tolerance within its cap, or meets pᵀAp ≤ 0. A b whose largest
    /// entry lies outside [2⁻³⁰⁰, 2³⁰⁰] (a motion decaying towards underflow) is solved scaled by
    /// a power of two, which is exact: the same x, bit for bit, as the scaled solve times 2ᵏ,
    /// where unscaled the squares inside CG would underflow to 0.
    void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x);

    const SolveStats& stats() const { return stats_; }
    /// ‖b − A x‖₂ / ‖b‖₂ of the last solve (‖x‖₂ for b = 0): the value the solver reported (CG's
    /// last product with A), or else computed here at the first call after the solve, a product
    /// with A that callers who never ask, like the time steps of chapters 10–12, do not pay for.
    /// fem::Error before the first solve after prepare().
    double relative_residual() const;
    /// n of the prepared matrix (0 before prepare()).
    Eigen::Index size() const { return prepared_ ? A_.rows() : 0; }

    /// The tolerance and cap of an iterative solver (a direct one ignores them).
    const SolverOptions& options() const { return options_; }
    /// The relative tolerance τ of the next solves of an iterative solver (a direct one ignores
    /// it): Newton's method solves loosely far from its answer and tightly near it (inexact
    /// Newton, chapter 12). fem::Error for τ outside (0, 1).
    void set_relative_tolerance(double tolerance);

protected:
    /// fem::Error for options outside their ranges (τ in (0, 1), cap ≥ 0).
    explicit LinearSolver(std::string name, const SolverOptions& options = {});
    /// Factor or set up for A (already checked; the solver's own copy, alive until the next
    /// prepare()). same_pattern: A has the sparsity pattern of the previous prepare(), so a
    /// symbolic analysis may be reused.
    virtual void do_prepare(const Eigen::SparseMatrix<double>& A, bool same_pattern) = 0;
    /// Solve into x (for iterative solvers x holds the start, sized n); returns the iterations.
    virtual int do_solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) = 0;
    /// For do_solve: the true relative residual ‖b − A x‖₂ / ‖b‖₂ of the x it returns, when it
    /// computed it anyway (chapter 09's CG does, with a product by this A), so that solve() does not
    /// multiply by A once more for relative_residual(). Unreported, relative_residual() computes it.
    void report_true_residual(double relative_residual) { reported_residual_ = relative_residual; }

private:
    std::string name_;
    SolverOptions options_;
    Eigen::SparseMatrix<double> A_;  // for the residual check and the pattern comparison
    std::vector<std::pair<int, int>> mirror_;  // the entry pairs (k, m) the symmetry check compares
    bool prepared_ = false;                    // the last prepare() succeeded
    SolveStats stats_;
    // The last solve's residual (< 0: none yet), or its b and x while relative_residual() has not
    // computed it (pending).
    mutable double relative_residual_ = -1.0;
    Eigen::VectorXd residual_b_, residual_x_;
    mutable bool residual_pending_ = false;
    double reported_residual_ = -1.0;  // report_true_residual's value during a solve (< 0: none)
};

/// The solver called `name` (see the list at the top of this header), with options for the
/// iterative ones. fem::Error for an unknown name (the message lists the valid ones), for
/// "cholmod" in a build without CHOLMOD, or for invalid options (τ outside (0, 1), cap < 0).
/// docs/09_conjugate_gradient.md#one-interface-for-every-solver
std::unique_ptr<LinearSolver> make_solver(std::string_view name = "default", const SolverOptions& options = {});

/// The names make_solver accepts in this build, "default" excluded, in the order of the list above.
std::vector<std::string> solver_names();

/// What "default" stands for: "ours-cholesky", chosen from this chapter's measurements (the
/// fastest direct solver on one core at the sizes of chapters 10–13, present in every build, and
/// deterministic). docs/09_conjugate_gradient.md#which-solver-by-default
std::string default_solver_name();

/// Whether this build found SuiteSparse's CHOLMOD (compile definition FEM_HAVE_CHOLMOD).
bool cholmod_available();

}  // namespace fem::cg
