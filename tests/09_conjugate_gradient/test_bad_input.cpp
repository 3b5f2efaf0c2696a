// Chapter 09: CG on a matrix with a NaN says so instead of returning "not converged" (issue 10).
#include "09_conjugate_gradient/conjugate_gradient.hpp"
#include "09_conjugate_gradient/linear_operator.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace fem::cg;
using Catch::Matchers::Contains;

TEST_CASE("CG: a NaN in A is an fem::Error, not a quiet 'not converged' after 0 iterations", "[ex09.1]")
{
    Eigen::MatrixXd A(3, 3);
    A << 4, 1, 0, 1, 3, 1, 0, 1, 2;
    A(2, 2) = std::nan("");
    const Eigen::SparseMatrix<double> sparse = A.sparseView();
    const EigenOperator op(sparse);
    Eigen::VectorXd x;
    CHECK_THROWS_WITH(conjugate_gradient(op, Eigen::Vector3d(1, 2, 3), x), Contains("not finite"));
}
