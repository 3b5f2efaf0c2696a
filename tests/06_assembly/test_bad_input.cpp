// Chapter 06: solve_spd refuses what its factorization would answer wrongly (issue 10).
#include "06_assembly/assembly.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using fem::assembly::solve_spd;
using Catch::Matchers::Contains;

TEST_CASE("solve_spd refuses a non-symmetric matrix and non-finite entries", "[ch06]")
{
    Eigen::MatrixXd A(3, 3);
    A << 4, 1, 0, 1, 3, 1, 0, 1, 2;
    const Eigen::VectorXd b = Eigen::Vector3d(1, 2, 3);
    CHECK((A * solve_spd(A.sparseView(), b) - b).norm() <= 1e-14 * b.norm());
    Eigen::MatrixXd skew = A;
    skew(0, 2) = 5.0;  // the factorization reads one triangle: this used to give a residual of 19
    CHECK_THROWS_WITH(solve_spd(skew.sparseView(), b), Contains("not symmetric"));
    Eigen::MatrixXd nan = A;
    nan(1, 1) = std::nan("");
    CHECK_THROWS_WITH(solve_spd(nan.sparseView(), b), Contains("A(1, 1)") && Contains("finite"));
    CHECK_THROWS_WITH(solve_spd(A.sparseView(), Eigen::Vector3d(1, INFINITY, 0)), Contains("b(1)"));
}
