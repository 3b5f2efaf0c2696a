// Chapter 08: the dense solves refuse a non-finite right-hand side instead of returning NaN (issue 10).
#include "08_direct_solvers/dense_solvers.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace fem::direct;
using Catch::Matchers::Contains;

TEST_CASE("substitutions and solves: a NaN or inf right-hand side is an fem::Error naming the entry", "[substitution]")
{
    Eigen::MatrixXd L(2, 2);
    L << 2, 0, 1, 3;
    const Eigen::Vector2d bad(1.0, std::nan(""));
    CHECK_THROWS_WITH(forward_substitution(L, bad), Contains("entry 1") && Contains("finite"));
    CHECK_THROWS_WITH(back_substitution(Eigen::MatrixXd(L.transpose()), Eigen::Vector2d(INFINITY, 0.0)),
                      Contains("entry 0"));
    CHECK_THROWS_AS(cholesky_solve(L, bad), fem::Error);
}
