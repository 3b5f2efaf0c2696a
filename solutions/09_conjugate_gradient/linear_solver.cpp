// Chapter 09: the solvers of the course behind one interface.
// docs/09_conjugate_gradient.md#one-interface-for-every-solver
#include "09_conjugate_gradient/linear_solver.hpp"

#include "09_conjugate_gradient/linear_operator.hpp"
#include "09_conjugate_gradient/preconditioners.hpp"

#include "07_sparse_storage/sparse_formats.hpp"
#include "08_direct_solvers/sparse_cholesky.hpp"
#include "common/error.hpp"
#include "common/timer.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#ifdef FEM_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

#include <algorithm>
#include <cmath>
#include <optional>
#include <type_traits>

namespace fem::cg {
namespace {

/// fem::Error naming `who` unless τ lies in (0, 1) and the cap is ≥ 0.
void require_valid(const SolverOptions& options, const std::string& who)
{
    if (!(options.relative_tolerance > 0.0 && options.relative_tolerance < 1.0))
        throw Error(str(who, ": the relative tolerance must lie in (0, 1), got ", options.relative_tolerance));
    if (options.max_iterations < 0)
        throw Error(str(who, ": the iteration cap must be ≥ 0 (0: the default), got ", options.max_iterations));
}

using SparseMatrix = Eigen::SparseMatrix<double>;

/// fem::Error unless A is square, not empty and finite; returns max |A_ij|. One pass over the
/// values; only a matrix that fails is searched for the entry to name.
double check_square_and_finite(const SparseMatrix& A)
{
    if (A.rows() == 0 || A.rows() != A.cols())
        throw Error(str("LinearSolver::prepare: the matrix is ", A.rows(), "×", A.cols(),
                        "; it must be square and not empty"));
    SparseMatrix compressed;
    if (!A.isCompressed()) {
        compressed = A;
        compressed.makeCompressed();
    }
    const auto values = (A.isCompressed() ? A : compressed).coeffs();  // the stored values, in order
    // (x · 0) is 0 for every finite x and NaN for ±∞ or NaN, so the sum is 0 exactly when all are finite.
    if ((values * 0.0).sum() == 0.0)
        return values.cwiseAbs().maxCoeff();
    for (Eigen::Index j = 0; j < A.outerSize(); ++j)
        for (SparseMatrix::InnerIterator it(A, j); it; ++it)
            if (!std::isfinite(it.value()))
                throw Error(str("LinearSolver::prepare: A(", it.row(), ", ", it.col(), ") = ", it.value(),
                                " is not finite"));
    return 0.0;  // not reached: some value is not finite
}

/// The pairs of stored entries a symmetry check compares, for a compressed A: each (k, m) with k
/// the position of (i, j) and m that of its mirror (j, i), once per pair (k < m); an entry whose
/// mirror is not stored is paired with −1 (it must be 0). Built once per pattern, so that a matrix
/// that changes every step (chapters 11–12) is checked in one pass over the pairs, without Aᵀ − A.
std::vector<std::pair<int, int>> mirror_pairs(const SparseMatrix& A)
{
    std::vector<std::pair<int, int>> pairs;
    const auto* outer = A.outerIndexPtr();
    const auto* inner = A.innerIndexPtr();
    for (Eigen::Index j = 0; j < A.outerSize(); ++j)
        for (auto k = outer[j]; k < outer[j + 1]; ++k) {
            const auto i = inner[k];
            const auto* first = inner + outer[i];
            const auto* last = inner + outer[i + 1];
            const auto* found = std::lower_bound(first, last, static_cast<int>(j));
            const int m = found != last && *found == j ? static_cast<int>(found - inner) : -1;
            if (m < 0 || k < m)
                pairs.emplace_back(k, m);
        }
    return pairs;
}

/// fem::Error unless max |A_ij − A_ji| ≤ symmetry_tolerance · largest (an entry without a mirror
/// counts as its own difference), over the pairs of mirror_pairs(A).
void check_symmetric(const SparseMatrix& A, const std::vector<std::pair<int, int>>& pairs, double largest)
{
    const double* value = A.valuePtr();
    const double allowed = symmetry_tolerance * largest;
    for (const auto& [k, m] : pairs) {
        const double difference = m >= 0 ? value[m] - value[k] : -value[k];
        if (!(std::abs(difference) <= allowed)) {
            // Where entry k sits, for the message: its column j (A is compressed, column-major).
            const auto* outer = A.outerIndexPtr();
            const Eigen::Index j = std::upper_bound(outer, outer + A.outerSize() + 1, k) - outer - 1;
            const Eigen::Index i = A.innerIndexPtr()[k];
            throw Error(str("LinearSolver::prepare: A is not symmetric: A(", i, ", ", j, ") − A(", j, ", ", i,
                            ") = ", -difference, " (allowed: ", symmetry_tolerance, " × max |A_ij| = ", allowed,
                            "); the solvers of this interface need a symmetric positive definite A"));
        }
    }
}

bool same_pattern(const SparseMatrix& a, const SparseMatrix& b)
{
    if (a.rows() != b.rows() || a.cols() != b.cols() || a.nonZeros() != b.nonZeros())
        return false;
    const auto outer = a.outerSize() + 1;
    return std::equal(a.outerIndexPtr(), a.outerIndexPtr() + outer, b.outerIndexPtr()) &&
           std::equal(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros(), b.innerIndexPtr());
}

/// CG iterations that missed the tolerance are an error here: the interface promises a solution.
void require_converged(const std::string& name, int iterations, double reached, double tolerance, bool converged)
{
    if (!converged)
        throw Error(str(name, ": did not reach the relative residual ", tolerance, " within ", iterations,
                        " iterations (reached ", reached, "); raise the iteration cap, loosen the tolerance, or "
                        "use a better preconditioner or a direct solver"));
}

// --- our solvers -------------------------------------------------------------------------------

class OursCholesky final : public LinearSolver {
public:
    OursCholesky() : LinearSolver("ours-cholesky") {}
    bool is_direct() const override { return true; }

private:
    void do_prepare(const SparseMatrix& A, bool same) override
    {
        if (same && factor_) {
            factor_->factorize(sparse::csc_from_eigen(A));
            return;
        }
        try {
            factor_.emplace(A);
        } catch (const Error&) {
            // A new pattern whose values are not positive definite: keep its ordering and analysis
            // for the next matrix of the pattern (Newton's definite Hessian after a failed exact one)
            // by analysing a positive definite stand-in of the same pattern, then fail on A's values
            // as before.
            factor_.emplace(diagonally_dominant(A));
            factor_->factorize(sparse::csc_from_eigen(A));
        }
    }
    /// A's pattern with |a_ij| off the diagonal and 1 + Σ_j |a_ij| on it: positive definite.
    static SparseMatrix diagonally_dominant(const SparseMatrix& A)
    {
        SparseMatrix D = A;
        const Eigen::VectorXd row_sums = Eigen::VectorXd(A.cwiseAbs() * Eigen::VectorXd::Ones(A.cols()));
        for (int j = 0; j < D.outerSize(); ++j)
            for (SparseMatrix::InnerIterator it(D, j); it; ++it)
                it.valueRef() = it.row() == it.col() ? 1.0 + row_sums[j] : std::abs(it.value());
        return D;
    }
    int do_solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override
    {
        x = factor_->solve(b);
        return 0;
    }
    std::optional<direct::SparseCholesky> factor_;
};

/// ours-cg, ours-pcg-jacobi and ours-pcg-ic0: the operator is A's lower triangle.
class OursCg final : public LinearSolver {
public:
    enum class Kind { plain, jacobi, ic0 };
    OursCg(std::string name, Kind kind, const SolverOptions& options) : LinearSolver(std::move(name), options), kind_(kind) {}
    bool is_direct() const override { return false; }

private:
    void do_prepare(const SparseMatrix& A, bool) override
    {
        preconditioner_.reset();
        const sparse::CsrMatrix csr = sparse::csr_from_eigen(A);
        operator_.emplace(csr);
        if (kind_ == Kind::jacobi)
            preconditioner_ = std::make_unique<JacobiPreconditioner>(diagonal(csr));
        else if (kind_ == Kind::ic0)
            preconditioner_ = std::make_unique<IncompleteCholesky>(csr);
    }
    int do_solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override
    {
        CgSettings settings;
        settings.relative_tolerance = options().relative_tolerance;
        settings.max_iterations = options().max_iterations;
        const CgResult result = preconditioner_
                                    ? preconditioned_conjugate_gradient(*operator_, *preconditioner_, b, x, settings)
                                    : conjugate_gradient(*operator_, b, x, settings);
        require_converged(name(), result.iterations, result.residual_history.back(), settings.relative_tolerance,
                          result.converged);
        report_true_residual(result.relative_residual);  // CG's last product with A (the same one)
        return result.iterations;
    }
    Kind kind_;
    std::optional<SymmetricCsrOperator> operator_;
    std::unique_ptr<LinearOperator> preconditioner_;
};

// --- references --------------------------------------------------------------------------------

/// Eigen::SimplicialLLT, and CHOLMOD's supernodal LLT through Eigen: the same calls.
template <typename Factorization>
class EigenDirect final : public LinearSolver {
public:
    explicit EigenDirect(std::string name) : LinearSolver(std::move(name))
    {
#ifdef FEM_HAVE_CHOLMOD
        if constexpr (std::is_same_v<Factorization, Eigen::CholmodSupernodalLLT<SparseMatrix>>)
            factor_.cholmod().print = 0;  // failures become fem::Error, not CHOLMOD's own messages
#endif
    }
    bool is_direct() const override { return true; }

private:
    void do_prepare(const SparseMatrix& A, bool same) override
    {
        if (!same || !analysed_) {
            factor_.analyzePattern(A);
            analysed_ = true;
        }
        factor_.factorize(A);
        if (factor_.info() != Eigen::Success)
            throw Error(str(name(), ": the Cholesky factorization failed: the matrix is not positive definite"));
    }
    int do_solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override
    {
        x = factor_.solve(b);
        if (factor_.info() != Eigen::Success)
            throw Error(str(name(), ": the triangular solves failed"));
        return 0;
    }
    Factorization factor_;
    bool analysed_ = false;
};

class EigenCg final : public LinearSolver {
public:
    explicit EigenCg(const SolverOptions& options) : LinearSolver("eigen-cg", options) {}
    bool is_direct() const override { return false; }

private:
    void do_prepare(const SparseMatrix& A, bool) override
    {
        if (options().max_iterations > 0)
            cg_.setMaxIterations(options().max_iterations);
        else
            cg_.setMaxIterations(iteration_cap_per_unknown * A.rows());
        cg_.compute(A);
    }
    int do_solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override
    {
        cg_.setTolerance(options().relative_tolerance);
        x = cg_.solveWithGuess(b, x);
        require_converged(name(), static_cast<int>(cg_.iterations()), cg_.error(), options().relative_tolerance,
                          cg_.info() == Eigen::Success);
        return static_cast<int>(cg_.iterations());
    }
    Eigen::ConjugateGradient<SparseMatrix> cg_;
};

const std::vector<std::string>& all_names()
{
    static const std::vector<std::string> names{"ours-cholesky", "ours-cg",   "ours-pcg-jacobi", "ours-pcg-ic0",
                                                "eigen-llt",     "eigen-cg",  "cholmod"};
    return names;
}

}  // namespace

LinearSolver::LinearSolver(std::string name, const SolverOptions& options) : name_(std::move(name)), options_(options)
{
    require_valid(options, name_);
}

void LinearSolver::set_relative_tolerance(double tolerance)
{
    SolverOptions changed = options_;
    changed.relative_tolerance = tolerance;
    require_valid(changed, name_);
    options_ = changed;
}

void LinearSolver::prepare(const Eigen::SparseMatrix<double>& A)
{
    prepared_ = false;
    const double largest = check_square_and_finite(A);
    const bool same = A_.rows() > 0 && A.isCompressed() && same_pattern(A, A_);
    // The solver keeps its own copy: Eigen's iterative solvers hold a reference to their matrix,
    // and the residual check needs it too. After a failed prepare the solver is unprepared, but
    // keeps the pattern (and a direct solver its analysis) when A itself was valid.
    if (same) {
        std::copy(A.valuePtr(), A.valuePtr() + A.nonZeros(), A_.valuePtr());  // the pattern is A_'s already
    } else {
        A_ = A;
        A_.makeCompressed();
    }
    stats_ = SolveStats{};
    relative_residual_ = -1.0;
    residual_pending_ = false;
    Timer timer;
    try {
        if (!same)
            mirror_ = mirror_pairs(A_);
        check_symmetric(A_, mirror_, largest);
    } catch (...) {
        A_ = Eigen::SparseMatrix<double>();
        mirror_.clear();
        throw;
    }
    do_prepare(A_, same);  // a failure (not positive definite) leaves it unprepared, the pattern kept
    prepared_ = true;
    stats_.prepare_seconds = timer.seconds();
}

Eigen::VectorXd LinearSolver::solve(const Eigen::VectorXd& b)
{
    Eigen::VectorXd x;
    solve(b, x);
    return x;
}

void LinearSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x)
{
    if (!prepared_)
        throw Error(str(name_, ": solve() before prepare() (or after a prepare() that failed); give the solver ",
                        "its matrix first"));
    if (b.size() != A_.rows())
        throw Error(str(name_, ": b has ", b.size(), " entries, the matrix is ", A_.rows(), "×", A_.cols()));
    if (!b.allFinite())
        throw Error(str(name_, ": b has a non-finite entry"));
    if (x.size() != A_.rows() || !x.allFinite())
        x = Eigen::VectorXd::Zero(A_.rows());
    // Solving A (2⁻ᵏx) = 2⁻ᵏb does the same operations on numbers scaled by 2⁻ᵏ, exactly; far from
    // 1 (below 2⁻³⁰⁰ ≈ 5e-91) the squares in CG's inner products would underflow, so such a b is
    // brought near 1 first.
    const double largest = b.cwiseAbs().maxCoeff();
    int exponent = 0;
    if (largest > 0.0 && (largest < 0x1p-300 || largest > 0x1p300))
        std::frexp(largest, &exponent);
    Timer timer;
    reported_residual_ = -1.0;
    relative_residual_ = -1.0;
    residual_pending_ = false;
    if (exponent == 0) {
        stats_.iterations = do_solve(b, x);
    } else {
        // Entry by entry: 2ᵏ itself overflows for a subnormal b (k > 1023).
        const auto scale = [](const Eigen::VectorXd& v, int power) {
            return Eigen::VectorXd(v.unaryExpr([power](double entry) { return std::ldexp(entry, power); }));
        };
        x = scale(x, -exponent);
        stats_.iterations = do_solve(scale(b, -exponent), x);
        x = scale(x, exponent);
    }
    stats_.solve_seconds = timer.seconds();
    // (The relative residual of a solve scaled by 2ᵏ is the unscaled one: the scaling is exact.)
    const double b_norm = b.norm();
    if (b_norm == 0.0 || reported_residual_ >= 0.0) {
        relative_residual_ = b_norm == 0.0 ? x.norm() : reported_residual_;
    } else {
        residual_b_ = b;  // relative_residual() computes ‖b − A x‖ / ‖b‖ when asked
        residual_x_ = x;
        residual_pending_ = true;
    }
}

double LinearSolver::relative_residual() const
{
    if (residual_pending_) {
        relative_residual_ = (residual_b_ - A_ * residual_x_).norm() / residual_b_.norm();
        residual_pending_ = false;
    }
    if (relative_residual_ < 0.0)
        throw Error(str(name_, ": relative_residual() before a solve"));
    return relative_residual_;
}

std::unique_ptr<LinearSolver> make_solver(std::string_view name, const SolverOptions& options)
{
    require_valid(options, "make_solver");
    const std::string resolved = name == "default" ? default_solver_name() : std::string(name);
    if (resolved == "ours-cholesky")
        return std::make_unique<OursCholesky>();
    if (resolved == "ours-cg")
        return std::make_unique<OursCg>(resolved, OursCg::Kind::plain, options);
    if (resolved == "ours-pcg-jacobi")
        return std::make_unique<OursCg>(resolved, OursCg::Kind::jacobi, options);
    if (resolved == "ours-pcg-ic0")
        return std::make_unique<OursCg>(resolved, OursCg::Kind::ic0, options);
    if (resolved == "eigen-llt")
        return std::make_unique<EigenDirect<Eigen::SimplicialLLT<SparseMatrix>>>(resolved);
    if (resolved == "eigen-cg")
        return std::make_unique<EigenCg>(options);
    if (resolved == "cholmod") {
#ifdef FEM_HAVE_CHOLMOD
        return std::make_unique<EigenDirect<Eigen::CholmodSupernodalLLT<SparseMatrix>>>(resolved);
#else
        throw Error("make_solver: this build has no CHOLMOD (install SuiteSparse, Debian: libsuitesparse-dev, "
                    "and configure again)");
#endif
    }
    std::string valid = "default";
    for (const std::string& known : solver_names())
        valid += ", " + known;
    throw Error(str("make_solver: unknown solver '", name, "'; this build has: ", valid));
}

std::vector<std::string> solver_names()
{
    std::vector<std::string> names;
    for (const std::string& name : all_names())
        if (name != "cholmod" || cholmod_available())
            names.push_back(name);
    return names;
}

std::string default_solver_name()
{
    // Measured in ch09_conjugate_gradient (docs/09_conjugate_gradient.md#which-solver-by-default):
    // the fastest direct solver on one core up to ~10⁴ unknowns, in every build.
    return "ours-cholesky";
}

bool cholmod_available()
{
#ifdef FEM_HAVE_CHOLMOD
    return true;
#else
    return false;
#endif
}

}  // namespace fem::cg
