#include "11_corotational/frozen_preconditioner.hpp"

#include "09_conjugate_gradient/conjugate_gradient.hpp"
#include "09_conjugate_gradient/linear_operator.hpp"

#include "common/error.hpp"

namespace fem::corot {

FrozenFactorPcg::FrozenFactorPcg(const cg::SolverOptions& options, int refresh_iterations, BlockRotations rotations)
    : cg::LinearSolver(rotations ? "rotated-frozen-cholesky-pcg" : "frozen-cholesky-pcg"), options_(options),
      refresh_iterations_(refresh_iterations), rotations_(std::move(rotations))
{
    if (!(options.relative_tolerance > 0.0 && options.relative_tolerance < 1.0))
        throw Error(str(name(), ": the tolerance must lie in (0, 1), got ", options.relative_tolerance));
    if (options.max_iterations < 0 || refresh_iterations < 0)
        throw Error(str(name(), ": the iteration cap and the refresh count must be >= 0"));
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
        factor_.emplace(A);
        ++factorizations_;
        refresh_ = false;
        frozen_rotations_ = current;
    }
    turn_.resize(current.size());
    for (std::size_t i = 0; i < current.size(); ++i)
        turn_[i] = current[i] * frozen_rotations_[i].transpose();
}

int FrozenFactorPcg::do_solve(const Eigen::VectorXd& b, Eigen::VectorXd& x)
{
    cg::CgSettings settings;
    settings.relative_tolerance = options_.relative_tolerance;
    settings.max_iterations = options_.max_iterations;
    cg::CgResult result;
    // BEGIN EXERCISE 11.7 frozen_factor_pcg #solving-a-changing-matrix
    // HINT: chapter 09's preconditioned_conjugate_gradient on the current matrix (cg::EigenOperator of
    // HINT: *A_) from x, with a cg::FunctionOperator preconditioner that applies the frozen factor,
    // HINT: turned by the blocks' rotations when there are any: z = Q A₀⁻¹ Qᵀ r (turn_[i] = Qᵢ),
    // HINT: else z = factor_->solve(r).
    const cg::EigenOperator A(*A_);
    const cg::FunctionOperator preconditioner(A_->rows(), [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
        if (turn_.empty()) {
            z = factor_->solve(r);
            return;
        }
        Eigen::VectorXd turned_back(r.size());  // Qᵀ r, block by block
        for (std::size_t i = 0; i < turn_.size(); ++i)
            turned_back.segment<3>(3 * i) = turn_[i].transpose() * r.segment<3>(3 * i);
        z = factor_->solve(turned_back);
        for (std::size_t i = 0; i < turn_.size(); ++i)
            z.segment<3>(3 * i) = (turn_[i] * z.segment<3>(3 * i)).eval();
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
