// Chapter 08: dense LU with partial pivoting, triangular substitution, dense Cholesky, against
// Eigen's PartialPivLU and LLT, and the Hilbert matrices. docs/08_direct_solvers.md
#include "08_direct_solvers/dense_solvers.hpp"

#include "direct_test_support.hpp"

#include "common/error.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Dense>

#include <cmath>
#include <limits>

using namespace fem::direct;
using fem::random_matrix;
using fem::direct::test::random_spd;
using fem::random_vector;
using Catch::Matchers::Contains;
using fem::direct::test::fem_error_message;
using fem::test::EntriesNear;
using fem::test::entries_of;

namespace {

const double eps = std::numeric_limits<double>::epsilon();

/// ‖b − A x‖₂ / ‖b‖₂
double relative_residual(const Eigen::MatrixXd& A, const Eigen::VectorXd& x, const Eigen::VectorXd& b)
{
    return (A * x - b).norm() / b.norm();
}

/// x with P A = L U and A x = b, by Eigen's triangular solves with the factors of F: a check of
/// lu_factor (exercise 08.1) that does not need the chapter's substitutions (08.2, 08.3).
Eigen::VectorXd solve_with_factors(const LuFactorization& F, const Eigen::VectorXd& b)
{
    const Eigen::MatrixXd L = F.L(), U = F.U();
    return U.triangularView<Eigen::Upper>().solve(L.triangularView<Eigen::UnitLower>().solve(F.P() * b));
}

}  // namespace

TEST_CASE("LU: P A = L U reconstructs A, with unit lower L, |multipliers| ≤ 1 and upper U", "[ex08.1]")
{
    for (int n : {1, 2, 5, 30, 100}) {
        const Eigen::MatrixXd A = random_matrix(n, n, 10 + n);
        const LuFactorization F = lu_factor(A);
        REQUIRE(F.size() == n);
        const Eigen::MatrixXd L = F.L(), U = F.U(), P = F.P();
        // backward error of Gaussian elimination with partial pivoting: O(n ε ‖A‖) for a modest growth
        CHECK_THAT(entries_of(L * U), EntriesNear(P * A, 10.0 * n * eps * A.cwiseAbs().maxCoeff()));
        CHECK(L.cwiseAbs().maxCoeff() <= 1.0);  // partial pivoting: every multiplier |l_ij| ≤ 1
        CHECK(Eigen::MatrixXd(U.triangularView<Eigen::StrictlyLower>()).isZero(0.0));
        // P is a permutation: every index once
        std::vector<int> sorted = F.row_of;
        std::sort(sorted.begin(), sorted.end());
        for (int k = 0; k < n; ++k)
            CHECK(sorted[k] == k);
    }
}

TEST_CASE("LU: the pivot is the largest entry of the column (a 2×2 by hand)", "[ex08.1]")
{
    Eigen::MatrixXd A(2, 2);
    A << 1.0, 2.0,
         4.0, 3.0;
    const LuFactorization F = lu_factor(A);
    CHECK(F.row_of == std::vector<int>{1, 0});
    // P A = [4 3; 1 2] = [1 0; 1/4 1] [4 3; 0 2 − 3/4]
    CHECK(F.LU(0, 0) == 4.0);
    CHECK(F.LU(0, 1) == 3.0);
    CHECK(F.LU(1, 0) == 0.25);
    CHECK(F.LU(1, 1) == 1.25);
}

TEST_CASE("LU: a tiny leading entry needs pivoting", "[ex08.1]")
{
    // Without pivoting, l_21 = 1e20 and u_22 = 1 − 1e20 wipe out the 1: x_1 comes out 0.
    Eigen::MatrixXd A(2, 2);
    A << 1e-20, 1.0,
         1.0, 1.0;
    const Eigen::Vector2d x_exact(1.0 / (1.0 - 1e-20), (1.0 - 2e-20) / (1.0 - 1e-20));
    const Eigen::VectorXd b = Eigen::Vector2d(1.0, 2.0);
    const LuFactorization F = lu_factor(A);
    CHECK(F.row_of == std::vector<int>{1, 0});
    const Eigen::VectorXd x = solve_with_factors(F, b);
    CHECK(x[0] == Approx(x_exact[0]).epsilon(1e-15));
    CHECK(x[1] == Approx(x_exact[1]).epsilon(1e-15));
}

TEST_CASE("LU: residual below 1e-12 on well-conditioned non-symmetric systems, as Eigen's PartialPivLU",
          "[ex08.3]")
{
    for (int n : {3, 20, 80, 200}) {
        const Eigen::MatrixXd A = random_matrix(n, n, 100 + n) + 2.0 * std::sqrt(n) * Eigen::MatrixXd::Identity(n, n);
        const Eigen::VectorXd x_exact = random_vector(n, 200 + n);
        const Eigen::VectorXd b = A * x_exact;
        const Eigen::VectorXd x = lu_solve(lu_factor(A), b);
        CHECK(relative_residual(A, x, b) < 1e-12);
        const Eigen::VectorXd x_eigen = A.partialPivLu().solve(b);
        CHECK((x - x_eigen).norm() <= 1e-12 * x_eigen.norm());
        CHECK((x - x_exact).norm() <= 1e-12 * x_exact.norm());
    }
}

TEST_CASE("LU: a singular matrix is an fem::Error naming the column of the failed pivot", "[ex08.1]")
{
    Eigen::MatrixXd rank_one(2, 2);
    rank_one << 1.0, 2.0,
                2.0, 4.0;
    CHECK_THAT(fem_error_message([&] { (void)lu_factor(rank_one); }),
               Contains("column 1") && Contains("singular"));

    Eigen::MatrixXd rank_two(3, 3);  // row 3 = 2 row 2 − row 1: the pivot of column 2 is round-off
    rank_two << 1.0, 2.0, 3.0,
                4.0, 5.0, 6.0,
                7.0, 8.0, 9.0;
    CHECK_THAT(fem_error_message([&] { (void)lu_factor(rank_two); }),
               Contains("column 2") && Contains("singular"));

    Eigen::MatrixXd zero_column = random_matrix(5, 5, 7);
    zero_column.col(3).setZero();
    CHECK_THAT(fem_error_message([&] { (void)lu_factor(zero_column); }),
               Contains("column 3"));
}

TEST_CASE("LU: bad input is an fem::Error", "[ex08.1]")
{
    CHECK_THROWS_AS(lu_factor(Eigen::MatrixXd(2, 3)), fem::Error);
    CHECK_THROWS_AS(lu_factor(Eigen::MatrixXd(0, 0)), fem::Error);
    Eigen::MatrixXd A = Eigen::MatrixXd::Identity(3, 3);
    A(1, 2) = std::nan("");
    CHECK_THAT(fem_error_message([&] { (void)lu_factor(A); }),
               Contains("(1, 2)"));
    CHECK_THROWS_AS(lu_solve(lu_factor(Eigen::MatrixXd::Identity(3, 3)), Eigen::VectorXd::Ones(4)), fem::Error);
}

TEST_CASE("forward substitution: exact by hand, and as Eigen's triangular solve", "[ex08.2]")
{
    Eigen::MatrixXd L(2, 2);
    L << 2.0, 0.0,
         1.0, 4.0;
    const Eigen::VectorXd y = forward_substitution(L, Eigen::Vector2d(2.0, 9.0));
    CHECK(y[0] == 1.0);
    CHECK(y[1] == 2.0);

    const int n = 60;
    Eigen::MatrixXd M = random_matrix(n, n, 3);
    M.diagonal().array() += 3.0;
    const Eigen::VectorXd b = random_vector(n, 4);
    const Eigen::VectorXd reference = M.triangularView<Eigen::Lower>().solve(b);
    CHECK((forward_substitution(M, b) - reference).norm() <= 1e-13 * reference.norm());  // reads the lower triangle only
    // Diagonal::unit: the stored diagonal is ignored and taken as ones (small multipliers keep the
    // unit triangular matrix well conditioned)
    Eigen::MatrixXd U = random_matrix(n, n, 7) / n;
    U.diagonal().setConstant(7.0);
    const Eigen::VectorXd unit_reference = U.triangularView<Eigen::UnitLower>().solve(b);
    CHECK((forward_substitution(U, b, Diagonal::unit) - unit_reference).norm() <= 1e-13 * unit_reference.norm());
}

TEST_CASE("forward substitution: a zero diagonal entry or a size mismatch is an fem::Error", "[substitution]")
{
    Eigen::MatrixXd L = Eigen::MatrixXd::Identity(3, 3);
    L(1, 1) = 0.0;
    CHECK_THAT(fem_error_message([&] { (void)forward_substitution(L, Eigen::Vector3d::Ones()); }),
               Contains("diagonal entry 1"));
    CHECK_THROWS_AS(forward_substitution(Eigen::MatrixXd::Identity(3, 3), Eigen::VectorXd::Ones(2)), fem::Error);
    CHECK_THROWS_AS(back_substitution(L, Eigen::Vector3d::Ones()), fem::Error);
}

TEST_CASE("back substitution: exact by hand, and as Eigen's triangular solve", "[ex08.3]")
{
    Eigen::MatrixXd U(2, 2);
    U << 2.0, 1.0,
         0.0, 4.0;
    const Eigen::VectorXd x = back_substitution(U, Eigen::Vector2d(4.0, 8.0));
    CHECK(x[1] == 2.0);
    CHECK(x[0] == 1.0);

    const int n = 60;
    Eigen::MatrixXd M = random_matrix(n, n, 5);
    M.diagonal().array() += 3.0;
    const Eigen::VectorXd y = random_vector(n, 6);
    const Eigen::VectorXd reference = M.triangularView<Eigen::Upper>().solve(y);
    CHECK((back_substitution(M, y) - reference).norm() <= 1e-13 * reference.norm());  // reads the upper triangle only
}

TEST_CASE("Cholesky: L Lᵀ reconstructs A, L is Eigen's LLT factor, residual below 1e-12", "[ex08.4]")
{
    for (int n : {1, 4, 50, 150}) {
        const Eigen::MatrixXd A = random_spd(n, 30 + n);
        const Eigen::MatrixXd L = cholesky_factor(A);
        CHECK(Eigen::MatrixXd(L.triangularView<Eigen::StrictlyUpper>()).isZero(0.0));
        CHECK((L.diagonal().array() > 0.0).all());
        CHECK_THAT(entries_of(L * L.transpose()), EntriesNear(A, 10.0 * n * eps * A.cwiseAbs().maxCoeff()));
        const Eigen::MatrixXd L_eigen = A.llt().matrixL();
        CHECK_THAT(entries_of(L), EntriesNear(L_eigen, 1e-13 * L_eigen.cwiseAbs().maxCoeff()));
        const Eigen::VectorXd b = random_vector(n, 40 + n);
        const Eigen::VectorXd x = cholesky_solve(L, b);
        CHECK(relative_residual(A, x, b) < 1e-12);
        CHECK((x - A.llt().solve(b)).norm() <= 1e-12 * x.norm());
    }
}

TEST_CASE("Cholesky: reads only the lower triangle", "[ex08.4]")
{
    Eigen::MatrixXd A = random_spd(12, 8);
    const Eigen::MatrixXd L = cholesky_factor(A);
    A.triangularView<Eigen::StrictlyUpper>().setConstant(1e6);  // garbage above the diagonal
    CHECK_THAT(entries_of(cholesky_factor(A)), EntriesNear(L, 0.0));
}

TEST_CASE("Cholesky: a matrix that is not SPD is an fem::Error naming the column, the pivot and 'not SPD'",
          "[ex08.4]")
{
    // a negative diagonal entry: the pivot of column 2 is −1
    const Eigen::MatrixXd D = Eigen::Vector4d(1.0, 2.0, -1.0, 3.0).asDiagonal();
    CHECK_THAT(fem_error_message([&] { (void)cholesky_factor(D); }),
               Contains("not symmetric positive definite") && Contains("column 2") && Contains("-1"));
    // indefinite with a positive diagonal: [1 2; 2 1] has eigenvalues 3 and −1; pivot 1 − 4 = −3
    Eigen::MatrixXd indefinite(2, 2);
    indefinite << 1.0, 2.0,
                  2.0, 1.0;
    CHECK_THAT(fem_error_message([&] { (void)cholesky_factor(indefinite); }),
               Contains("column 1") && Contains("-3"));
    // singular (positive semi-definite): [1 1; 1 1] has the pivot 0 in column 1
    CHECK_THAT(fem_error_message([&] { (void)cholesky_factor(Eigen::MatrixXd::Ones(2, 2)); }),
               Contains("column 1") && Contains("not symmetric positive definite"));
    // a non-symmetric "SPD-looking" upper triangle does not matter: the lower one decides
    Eigen::MatrixXd A = random_spd(6, 9);
    A(5, 5) = -0.5;
    CHECK_THAT(fem_error_message([&] { (void)cholesky_factor(A); }),
               Contains("column 5"));
}

TEST_CASE("Cholesky: bad input is an fem::Error", "[cholesky]")
{
    CHECK_THROWS_AS(cholesky_factor(Eigen::MatrixXd(3, 2)), fem::Error);
    Eigen::MatrixXd A = Eigen::MatrixXd::Identity(2, 2);
    A(1, 0) = INFINITY;
    CHECK_THROWS_AS(cholesky_factor(A), fem::Error);
}

TEST_CASE("Hilbert matrices: the exact condition number, against known values and Eigen's estimate", "[hilbert]")
{
    CHECK(hilbert_condition_number(1) == 1.0);
    CHECK(hilbert_condition_number(2) == Approx(27.0).epsilon(1e-14));    // ‖H₂‖₁ = 3/2, ‖H₂⁻¹‖₁ = 18
    CHECK(hilbert_condition_number(3) == Approx(748.0).epsilon(1e-14));   // 11/6 · 408
    CHECK(hilbert_condition_number(4) == Approx(28375.0).epsilon(1e-14)); // 25/12 · 13620
    // Eigen's estimate of κ₁ (Hager–Higham, from its LU) estimates ‖H⁻¹‖₁ from below: it is at most
    // the exact value (up to round-off) and, here, within a factor 3 of it while κ ε < 1
    for (int n = 2; n <= 12; ++n) {
        const Eigen::PartialPivLU<Eigen::MatrixXd> lu(hilbert_matrix(n));
        const double estimate = 1.0 / lu.rcond(), exact = hilbert_condition_number(n);
        INFO("n = " << n << ": estimate " << estimate << ", exact " << exact);
        CHECK(estimate <= exact * (1.0 + 1e-3));
        CHECK(estimate >= exact / 3.0);
    }
    CHECK_THROWS_AS(hilbert_matrix(0), fem::Error);
    CHECK_THROWS_AS(hilbert_condition_number(21), fem::Error);
}

TEST_CASE("Hilbert matrices n = 4 … 14: the LU error grows with κ and stays below n κ ε", "[ex08.3][hilbert]")
{
    // x = (1, …, 1) and b = H x summed in long double, so that b carries no more than its own
    // rounding: the computed x then has a forward error of about κ times the backward error
    // (≈ n ε for partial pivoting without growth), i.e. error ≤ C κ ε with C = n.
    double error_4 = 0.0, error_12 = 0.0;
    for (int n = 4; n <= 14; ++n) {
        const Eigen::MatrixXd H = hilbert_matrix(n);
        const Eigen::VectorXd b = hilbert_row_sums(n);
        const double kappa = hilbert_condition_number(n);
        INFO("n = " << n << ", kappa = " << kappa);
        if (n == 14) {
            // κ ε ≈ 10⁴: H₁₄ is singular to working precision, and LU says so (the last pivot is
            // below n ε times its column)
            CHECK_THAT(fem_error_message([&] { (void)lu_factor(H); }),
               Contains("column 13") && Contains("singular"));
            continue;
        }
        const Eigen::VectorXd x = lu_solve(lu_factor(H), b);
        const double error = (x.array() - 1.0).abs().maxCoeff();  // ‖x − 1‖∞ / ‖1‖∞
        CHECK(error <= n * kappa * eps);
        if (n == 4)
            error_4 = error;
        if (n == 12)
            error_12 = error;
    }
    CHECK(error_4 < 1e-12);
    CHECK(error_12 > 1e6 * error_4);  // κ grew by 10¹²: the error grows with it
}
