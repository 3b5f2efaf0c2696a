#pragma once
// Chapter 09: the linear operator CG works on. docs/09_conjugate_gradient.md#the-operator-interface
//
// Conjugate gradients never look inside A: each iteration needs one product y = A x and nothing
// else. So the solver takes a LinearOperator (size() and apply(x, y)), and the chapter adapts
// four things to it:
//   EigenOperator          an Eigen::SparseMatrix (both triangles stored), Eigen's own product;
//   CsrOperator            chapter 07's hand-written CSR, csr_times_vector (one dot per row);
//   SymmetricCsrOperator   chapter 07's lower triangle alone, symmetric_times_vector (half the
//                          bytes: each stored A_ij (j < i) is used for A_ij and A_ji);
//   FunctionOperator       any function y = f(x), e.g. chapter 02's 5-point stencil as a sweep
//                          over the grid that never stores a matrix (stencil_operator).
// Preconditioners (preconditioners.hpp) are LinearOperators too: they apply M⁻¹.
//
// Every adapter owns what it multiplies with (pass an rvalue, std::move, to avoid a copy), so an
// operator never refers to a matrix that has gone away.

#include "02_heat_equation/heat_grid.hpp"
#include "07_sparse_storage/sparse_formats.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <functional>

namespace fem::cg {

/// A square linear map y = A x on vectors of size() entries, known only by its action.
/// docs/09_conjugate_gradient.md#the-operator-interface
class LinearOperator {
public:
    virtual ~LinearOperator() = default;
    /// n, the number of entries of x and y.
    virtual Eigen::Index size() const = 0;
    /// y = A x. x has size() entries; y is resized to size() and must be a different vector
    /// (fem::Error otherwise, and for a wrong size of x).
    virtual void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const = 0;
};

/// An Eigen sparse matrix (both triangles stored) as an operator: y = A x by Eigen's product.
/// fem::Error for a matrix that is not square.
class EigenOperator final : public LinearOperator {
public:
    explicit EigenOperator(Eigen::SparseMatrix<double> A);
    Eigen::Index size() const override { return A_.rows(); }
    void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override;
    const Eigen::SparseMatrix<double>& matrix() const { return A_; }

private:
    Eigen::SparseMatrix<double> A_;
};

/// Chapter 07's CSR matrix as an operator: y = A x by csr_times_vector (gather, a dot product per
/// row). fem::Error for a matrix that is not square or not valid CSR (checked once here, by
/// sparse::validate).
class CsrOperator final : public LinearOperator {
public:
    explicit CsrOperator(sparse::CsrMatrix A);
    Eigen::Index size() const override { return A_.rows; }
    void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override;
    const sparse::CsrMatrix& matrix() const { return A_; }

private:
    sparse::CsrMatrix A_;
};

/// A symmetric matrix given by its lower triangle with the diagonal (CSR), applied by chapter 07's
/// symmetric_times_vector: y = (L + D + Lᵀ) x, each stored off-diagonal entry used twice. Pass
/// either the whole symmetric matrix (its lower triangle is extracted) or the lower triangle.
/// fem::Error for a matrix that is not square or not valid CSR.
class SymmetricCsrOperator final : public LinearOperator {
public:
    explicit SymmetricCsrOperator(const sparse::CsrMatrix& A);
    Eigen::Index size() const override { return lower_.rows; }
    void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override;
    /// The stored lower triangle with the diagonal.
    const sparse::CsrMatrix& lower() const { return lower_; }

private:
    sparse::CsrMatrix lower_;
};

/// A matrix-free operator: apply(x, y) calls product(x, y), which must set y (already sized n) to
/// A x. fem::Error for n < 0 or an empty function.
class FunctionOperator final : public LinearOperator {
public:
    using Product = std::function<void(const Eigen::VectorXd& x, Eigen::VectorXd& y)>;
    FunctionOperator(Eigen::Index n, Product product);
    Eigen::Index size() const override { return n_; }
    void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override;

private:
    Eigen::Index n_;
    Product product_;
};

/// −Δ_h on the n×n unknowns of chapter 02's grid with zero boundary values, matrix-free:
/// y_{i,j} = (4 u_{i,j} − u_{i+1,j} − u_{i−1,j} − u_{i,j+1} − u_{i,j−1}) / h², one
/// heat::stencil_sweep with α = 0, β = −1/h². The same operator as laplacian_2d(n) (symmetric
/// positive definite), without storing it. fem::Error for an invalid grid.
/// docs/09_conjugate_gradient.md#the-operator-interface
FunctionOperator stencil_operator(const heat::Grid& grid);

/// The diagonal (A_00, A_11, …) of a square CSR matrix, 0 where a row stores no diagonal entry.
/// fem::Error for a matrix that is not square.
Eigen::VectorXd diagonal(const sparse::CsrMatrix& A);

}  // namespace fem::cg
