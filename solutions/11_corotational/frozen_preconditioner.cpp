#include "11_corotational/frozen_preconditioner.hpp"

#include "09_conjugate_gradient/conjugate_gradient.hpp"
#include "09_conjugate_gradient/linear_operator.hpp"

#include "07_sparse_storage/sparse_formats.hpp"

#include "common/error.hpp"

#include <algorithm>

namespace fem::corot {

FrozenFactorPcg::FrozenFactorPcg(const cg::SolverOptions& options, RefreshRule refresh, BlockRotations rotations,
                                 FactorPrecision precision)
    : cg::LinearSolver(rotations ? "rotated-frozen-cholesky-pcg" : "frozen-cholesky-pcg", options),
      refresh_rule_(refresh), rotations_(std::move(rotations)), precision_(precision)
{
    if (refresh.iterations_above < 0)
        throw Error(str(name(), ": the refresh iteration count must be >= 0, got ", refresh.iterations_above));
}

void FrozenFactorPcg::do_prepare(const Eigen::SparseMatrix<double>& A, bool same_pattern)
{
    A_ = &A;
    std::vector<Eigen::Matrix3d> current;
    if (rotations_) {
        current = rotations_();
        if (3 * static_cast<Eigen::Index>(current.size()) != A.rows())
            throw Error(str(name(), ": ", current.size(), " block rotations for a ", A.rows(), "x", A.rows(),
                            " matrix; expected one per 3 unknowns"));
    }
    if (refresh_ || !same_pattern || !factor_) {
        if (factor_ && same_pattern) {
            factor_->factorize(sparse::csc_from_eigen(A));  // the ordering and analysis are kept
        } else {
            direct::CholeskyOptions factor_options;
            factor_options.single_precision_copy = precision_ == FactorPrecision::single_precision;
            factor_.emplace(A, factor_options);
        }
        ++factorizations_;
        refresh_ = false;
        factorization_cost_ = factor_->flops();
        iteration_cost_ = 4.0 * static_cast<double>(factor_->stored_entries()) + 2.0 * static_cast<double>(A.nonZeros());
        extra_cost_ = 0.0;
        fresh_iterations_ = -1;
        frozen_rotations_ = current;
    }
    turn_.resize(current.size());
    for (std::size_t i = 0; i < current.size(); ++i)
        turn_[i] = current[i] * frozen_rotations_[i].transpose();
}

Eigen::VectorXd FrozenFactorPcg::apply_factor(const Eigen::VectorXd& r) const
{
    return precision_ == FactorPrecision::single_precision ? factor_->solve_single_precision(r) : factor_->solve(r);
}

int FrozenFactorPcg::do_solve(const Eigen::VectorXd& b, Eigen::VectorXd& x)
{
    cg::CgSettings settings;
    settings.relative_tolerance = options().relative_tolerance;
    settings.max_iterations = options().max_iterations;
    cg::CgResult result;
    // BEGIN EXERCISE 11.7 frozen_factor_pcg #solving-a-changing-matrix
    // HINT: chapter 09's preconditioned_conjugate_gradient on the current matrix from x (a
    // HINT: cg::FunctionOperator that multiplies by *A_ without copying it), with a cg::FunctionOperator
    // HINT: preconditioner that applies the frozen factor, turned by the blocks' rotations when there
    // HINT: are any: z = Q A₀⁻¹ Qᵀ r (turn_[i] = Qᵢ), else z = apply_factor(r) (A₀⁻¹ r in the factor's
    // HINT: precision).
    // A x as Aᵀ x (A is symmetric): Eigen multiplies the transpose of a column-major matrix row by
    // row, a dot product per row, instead of scattering column by column.
    const cg::FunctionOperator A(A_->rows(), [&](const Eigen::VectorXd& v, Eigen::VectorXd& Av) {
        Av.noalias() = A_->transpose() * v;
    });
    const cg::FunctionOperator preconditioner(A_->rows(), [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
        if (turn_.empty()) {
            z = apply_factor(r);
            return;
        }
        Eigen::VectorXd turned_back(r.size());  // Qᵀ r, block by block
        for (std::size_t i = 0; i < turn_.size(); ++i)
            turned_back.segment<3>(3 * i) = turn_[i].transpose() * r.segment<3>(3 * i);
        z = apply_factor(turned_back);
        for (std::size_t i = 0; i < turn_.size(); ++i)
            z.segment<3>(3 * i) = (turn_[i] * z.segment<3>(3 * i)).eval();
    });
    result = cg::preconditioned_conjugate_gradient(A, preconditioner, b, x, settings);
    // END EXERCISE
    if (!result.converged)
        throw Error(str(name(), ": CG missed its tolerance ", options().relative_tolerance, " within ",
                        result.iterations, " iterations"));
    report_true_residual(result.relative_residual);  // CG's product with the same A
    // The next prepare() factors the current matrix when a rule says so.
    if (refresh_rule_.iterations_above > 0 && result.iterations > refresh_rule_.iterations_above)
        refresh_ = true;
    if (fresh_iterations_ < 0)
        fresh_iterations_ = result.iterations;
    else
        extra_cost_ += std::max(0, result.iterations - fresh_iterations_) * iteration_cost_;
    if (refresh_rule_.balance_cost && extra_cost_ >= factorization_cost_)
        refresh_ = true;
    return result.iterations;
}

}  // namespace fem::corot
