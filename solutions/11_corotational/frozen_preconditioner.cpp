#include "11_corotational/frozen_preconditioner.hpp"

#include "09_conjugate_gradient/conjugate_gradient.hpp"
#include "09_conjugate_gradient/linear_operator.hpp"

#include "common/error.hpp"

namespace fem::corot {

FrozenFactorPcg::FrozenFactorPcg(const cg::SolverOptions& options, int refresh_iterations)
    : cg::LinearSolver("frozen-cholesky-pcg"), options_(options), refresh_iterations_(refresh_iterations)
{
    if (!(options.relative_tolerance > 0.0 && options.relative_tolerance < 1.0))
        throw Error(str("frozen-cholesky-pcg: the tolerance must lie in (0, 1), got ", options.relative_tolerance));
    if (options.max_iterations < 0 || refresh_iterations < 0)
        throw Error("frozen-cholesky-pcg: the iteration cap and the refresh count must be >= 0");
}

void FrozenFactorPcg::do_prepare(const Eigen::SparseMatrix<double>& A, bool same_pattern)
{
    A_ = A;
    if (refresh_ || !same_pattern || factor_ == nullptr) {
        factor_ = cg::make_solver("default");
        factor_->prepare(A);
        ++factorizations_;
        refresh_ = false;
    }
}

int FrozenFactorPcg::do_solve(const Eigen::VectorXd& b, Eigen::VectorXd& x)
{
    cg::CgSettings settings;
    settings.relative_tolerance = options_.relative_tolerance;
    settings.max_iterations = options_.max_iterations;
    cg::CgResult result;
    // BEGIN EXERCISE 11.7 frozen_factor_pcg #solving-a-changing-matrix
    // HINT: chapter 09's preconditioned_conjugate_gradient on the current matrix (cg::EigenOperator of
    // HINT: A_) from x, with a cg::FunctionOperator preconditioner that applies the frozen factor:
    // HINT: z = factor_->solve(r).
    const cg::EigenOperator A(A_);
    const cg::FunctionOperator preconditioner(A_.rows(), [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
        z = factor_->solve(r);
    });
    result = cg::preconditioned_conjugate_gradient(A, preconditioner, b, x, settings);
    // END EXERCISE
    if (!result.converged)
        throw Error(str(name(), ": CG missed its tolerance ", options_.relative_tolerance, " within ",
                        result.iterations, " iterations"));
    if (refresh_iterations_ > 0 && result.iterations > refresh_iterations_)
        refresh_ = true;  // the next prepare() factors the current matrix
    return result.iterations;
}

}  // namespace fem::corot
