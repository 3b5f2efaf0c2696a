// Chapter 10: the eigensolvers that find the modes of (K, M): Eigen's dense generalized solver (the
// reference), Spectra's shift-invert Lanczos for the lowest modes of a large mesh, and Lanczos for
// the highest frequency. Only chapter 10 calls them (fem_add_chapter's OWN). docs/10_linear_dynamics.md#modes
#include "10_linear_dynamics/modes.hpp"

#include "09_conjugate_gradient/linear_solver.hpp"

#include "common/error.hpp"

#include <Eigen/Eigenvalues>
#include <Spectra/MatOp/SparseCholesky.h>
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>
#include <Spectra/SymGEigsSolver.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <utility>
#include <vector>

namespace fem::dynamics {
namespace {

constexpr double lanczos_tolerance = 1e-10;

void require_pair(const SparseMatrix& K, const SparseMatrix& M, int count)
{
    if (K.rows() != K.cols() || M.rows() != M.cols() || K.rows() != M.rows())
        throw Error(str("modes: K (", K.rows(), "x", K.cols(), ") and M (", M.rows(), "x", M.cols(),
                        ") must be square and of one size"));
    if (count < 1 || count > K.rows())
        throw Error(str("modes: the number of modes must lie in [1, n = ", K.rows(), "], got ", count));
    // Entry by entry over the stored ones, O(nnz): a dense copy of K would take 8 n² bytes (10 GB
    // at the cost study's 36k dofs).
    for (const auto& [matrix, name] : {std::pair{&K, "K"}, std::pair{&M, "M"}})
        for (Eigen::Index column = 0; column < matrix->outerSize(); ++column)
            for (SparseMatrix::InnerIterator entry(*matrix, column); entry; ++entry)
                if (!std::isfinite(entry.value()))
                    throw Error(str("modes: ", name, " has a non-finite entry"));
}

/// Scales every column to φᵀ M φ = 1 and sorts by ω ascending.
Modes normalized_modes(const Eigen::VectorXd& eigenvalues, const Eigen::MatrixXd& vectors, const SparseMatrix& M)
{
    std::vector<Eigen::Index> order(static_cast<std::size_t>(eigenvalues.size()));
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) { return eigenvalues[a] < eigenvalues[b]; });
    Modes modes;
    modes.omega.resize(eigenvalues.size());
    modes.shapes.resize(vectors.rows(), eigenvalues.size());
    for (Eigen::Index k = 0; k < eigenvalues.size(); ++k) {
        const Eigen::Index j = order[static_cast<std::size_t>(k)];
        modes.omega[k] = std::sqrt(std::max(eigenvalues[j], 0.0));
        const Eigen::VectorXd phi = vectors.col(j);
        modes.shapes.col(k) = phi / std::sqrt(phi.dot(M * phi));
    }
    return modes;
}

/// y = (K − σ M)⁻¹ x with chapter 09's default sparse Cholesky: Spectra's shift-invert operation.
class ShiftInvertOperator {
public:
    using Scalar = double;

    ShiftInvertOperator(const SparseMatrix& K, const SparseMatrix& M)
        : K_(K), M_(M), solver_(cg::make_solver("default"))
    {
    }
    Eigen::Index rows() const { return K_.rows(); }
    Eigen::Index cols() const { return K_.cols(); }
    void set_shift(double sigma) { solver_->prepare(K_ - sigma * M_); }
    void perform_op(const double* x, double* y) const
    {
        Eigen::Map<Eigen::VectorXd>(y, rows()) = solver_->solve(Eigen::Map<const Eigen::VectorXd>(x, rows()));
    }

private:
    const SparseMatrix& K_;
    const SparseMatrix& M_;
    std::unique_ptr<cg::LinearSolver> solver_;
};

}  // namespace

Modes lowest_modes_dense(const SparseMatrix& K, const SparseMatrix& M, int count)
{
    require_pair(K, M, count);
    const Eigen::MatrixXd Kd(K), Md(M);
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(Kd, Md, Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
    if (solver.info() != Eigen::Success)
        throw Error("modes: the dense generalized eigensolver failed: M must be symmetric positive definite");
    const Eigen::VectorXd lambda = solver.eigenvalues();
    if (lambda[0] < -1e-9 * std::abs(lambda[lambda.size() - 1]))
        throw Error(str("modes: K has the negative eigenvalue ", lambda[0], "; a stiffness must be positive semi-definite"));
    return normalized_modes(lambda.head(count), solver.eigenvectors().leftCols(count), M);
}

Modes lowest_modes(const SparseMatrix& K, const SparseMatrix& M, int count)
{
    require_pair(K, M, count);
    const Eigen::Index n = K.rows();
    if (n <= 3 * count + 20)  // too small for Lanczos to have room: the dense solver is exact
        return lowest_modes_dense(K, M, count);
    ShiftInvertOperator op(K, M);
    Spectra::SparseSymMatProd<double> mass(M);
    const Eigen::Index ncv = std::min<Eigen::Index>(n, std::max(2 * count + 1, 24));
    Spectra::SymGEigsShiftSolver<ShiftInvertOperator, Spectra::SparseSymMatProd<double>, Spectra::GEigsMode::ShiftInvert>
        eigs(op, mass, count, ncv, 0.0);
    eigs.init();
    eigs.compute(Spectra::SortRule::LargestMagn, 1000, lanczos_tolerance);
    if (eigs.info() != Spectra::CompInfo::Successful)
        throw Error(str("modes: shift-invert Lanczos did not converge to ", lanczos_tolerance, " for ", count, " modes"));
    return normalized_modes(eigs.eigenvalues(), eigs.eigenvectors(), M);
}

double highest_frequency(const SparseMatrix& K, const SparseMatrix& M)
{
    require_pair(K, M, 1);
    const Eigen::Index n = K.rows();
    if (n <= 24) {
        const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(Eigen::MatrixXd(K), Eigen::MatrixXd(M),
                                                                               Eigen::EigenvaluesOnly | Eigen::Ax_lBx);
        if (solver.info() != Eigen::Success)
            throw Error("highest frequency: M must be symmetric positive definite");
        return std::sqrt(std::max(solver.eigenvalues().maxCoeff(), 0.0));
    }
    Spectra::SparseSymMatProd<double> stiffness(K);
    Spectra::SparseCholesky<double> mass(M);
    if (mass.info() != Spectra::CompInfo::Successful)
        throw Error("highest frequency: M must be symmetric positive definite");
    Spectra::SymGEigsSolver<Spectra::SparseSymMatProd<double>, Spectra::SparseCholesky<double>, Spectra::GEigsMode::Cholesky>
        eigs(stiffness, mass, 1, std::min<Eigen::Index>(n, 24));
    eigs.init();
    eigs.compute(Spectra::SortRule::LargestAlge, 5000, lanczos_tolerance);
    if (eigs.info() != Spectra::CompInfo::Successful)
        throw Error(str("highest frequency: Lanczos did not converge to ", lanczos_tolerance));
    return std::sqrt(std::max(eigs.eigenvalues()[0], 0.0));
}

}  // namespace fem::dynamics
