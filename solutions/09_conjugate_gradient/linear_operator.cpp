// Chapter 09: the operator adapters. docs/09_conjugate_gradient.md#the-operator-interface
#include "09_conjugate_gradient/linear_operator.hpp"

#include "07_sparse_storage/sparse_products.hpp"
#include "common/error.hpp"

#include <utility>

namespace fem::cg {
namespace {

void check_product(const char* where, Eigen::Index n, const Eigen::VectorXd& x, const Eigen::VectorXd& y)
{
    if (x.size() != n)
        throw Error(str(where, ": x has ", x.size(), " entries, the operator is ", n, "×", n));
    if (&x == &y)
        throw Error(str(where, ": x and y are the same vector; apply(x, y) needs a separate output"));
}

void check_square_csr(const sparse::CsrMatrix& A, const char* where)
{
    sparse::validate(A);
    if (A.rows != A.cols)
        throw Error(str(where, ": the matrix is ", A.rows, "×", A.cols, "; an operator for CG is square"));
}

}  // namespace

EigenOperator::EigenOperator(Eigen::SparseMatrix<double> A) : A_(std::move(A))
{
    if (A_.rows() != A_.cols())
        throw Error(str("EigenOperator: the matrix is ", A_.rows(), "×", A_.cols(),
                        "; an operator for CG is square"));
    A_.makeCompressed();
}

void EigenOperator::apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const
{
    check_product("EigenOperator::apply", size(), x, y);
    y.noalias() = A_ * x;
}

CsrOperator::CsrOperator(sparse::CsrMatrix A) : A_(std::move(A))
{
    check_square_csr(A_, "CsrOperator");
}

void CsrOperator::apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const
{
    sparse::csr_times_vector(A_, x, y);
}

SymmetricCsrOperator::SymmetricCsrOperator(const sparse::CsrMatrix& A)
{
    check_square_csr(A, "SymmetricCsrOperator");
    lower_ = sparse::lower_triangle(A);
}

void SymmetricCsrOperator::apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const
{
    sparse::symmetric_times_vector(lower_, x, y);
}

FunctionOperator::FunctionOperator(Eigen::Index n, Product product) : n_(n), product_(std::move(product))
{
    if (n < 0)
        throw Error(str("FunctionOperator: the size must be ≥ 0, got ", n));
    if (!product_)
        throw Error("FunctionOperator: no product function given");
}

void FunctionOperator::apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const
{
    check_product("FunctionOperator::apply", n_, x, y);
    y.resize(n_);
    product_(x, y);
}

FunctionOperator stencil_operator(const heat::Grid& grid)
{
    heat::validate(grid);
    const double h = grid.h();
    const heat::BoundaryValues zero = heat::constant_boundary(grid, 0.0);
    return FunctionOperator(grid.unknowns(), [grid, zero, h](const Eigen::VectorXd& x, Eigen::VectorXd& y) {
        heat::stencil_sweep(grid, zero, x, 0.0, -1.0 / (h * h), y);
    });
}

Eigen::VectorXd diagonal(const sparse::CsrMatrix& A)
{
    if (A.rows != A.cols)
        throw Error(str("diagonal: the matrix is ", A.rows, "×", A.cols, "; it must be square"));
    Eigen::VectorXd d = Eigen::VectorXd::Zero(A.rows);
    for (int i = 0; i < A.rows; ++i)
        for (int k = A.IA[i]; k < A.IA[i + 1]; ++k)
            if (A.JA[k] == i)
                d[i] = A.A[k];
    return d;
}

}  // namespace fem::cg
