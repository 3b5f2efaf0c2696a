// Chapter 09: conjugate gradients against dense solves, its n-step property, its √κ growth on
// Laplacians, warm starts, the iteration cap, indefinite matrices, the operator adapters and
// agreement with Eigen's ConjugateGradient. docs/09_conjugate_gradient.md#the-conjugate-gradient-method
#include "09_conjugate_gradient/conjugate_gradient.hpp"
#include "09_conjugate_gradient/linear_operator.hpp"
#include "09_conjugate_gradient/model_problems.hpp"

#include "cg_test_support.hpp"

#include "01_finite_differences/finite_differences.hpp"
#include "02_heat_equation/heat_grid.hpp"
#include "06_assembly/assembly.hpp"
#include "07_sparse_storage/sparse_formats.hpp"
#include "08_direct_solvers/model_problems.hpp"
#include "common/error.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>

#include <cmath>
#include <limits>
#include <vector>

using namespace fem::cg;
using fem::test::EntriesNear;
using fem::test::entries_of;
using fem::cg::test::dense_solve;
using fem::cg::test::relative_error;
using fem::random_vector;
using fem::cg::test::spd_with_spectrum;
using Catch::Matchers::Contains;

namespace {

EigenOperator sparse_operator(const Eigen::MatrixXd& A)
{
    return EigenOperator(Eigen::SparseMatrix<double>(A.sparseView()));
}

Eigen::SparseMatrix<double> laplacian_2d(int n)
{
    return fem::sparse::to_eigen(fem::direct::laplacian_2d(n));
}

}  // namespace

TEST_CASE("CG solves small SPD systems in at most n iterations to 1e-10", "[ex09.1]")
{
    for (int n : {5, 12, 30}) {
        CAPTURE(n);
        // κ = 10: every eigenvalue in [1, 10].
        const Eigen::MatrixXd A = spd_with_spectrum(Eigen::VectorXd::LinSpaced(n, 1.0, 10.0), 7u + n);
        const Eigen::VectorXd b = random_vector(n, 3u + n);
        const Eigen::VectorXd reference = dense_solve(A, b);
        CgSettings settings;
        settings.relative_tolerance = 1e-10;
        Eigen::VectorXd x;
        const CgResult result = conjugate_gradient(sparse_operator(A), b, x, settings);
        CHECK(result.converged);
        CHECK(result.iterations <= n);
        REQUIRE(result.residual_history.size() == static_cast<std::size_t>(result.iterations) + 1);
        CHECK(result.residual_history.front() == Approx(1.0));  // x₀ = 0: r₀ = b
        CHECK(result.residual_history.back() <= 1e-10);
        CHECK(result.relative_residual <= 2e-10);  // the true residual of the returned x
        // ‖x − x*‖ / ‖x*‖ ≤ κ ‖r‖ / ‖b‖ = 10 · 1e-10.
        CHECK(relative_error(x, reference) <= 1e-9);
        CHECK(result.alpha.size() == static_cast<std::size_t>(result.iterations));
    }
}

TEST_CASE("CG finishes in as many iterations as A has distinct eigenvalues", "[ex09.1]")
{
    // Three distinct eigenvalues: the Krylov space of dimension 3 holds the solution
    // (a polynomial of degree 3 with roots 1, 4 and 9 annihilates A).
    Eigen::VectorXd lambda(40);
    for (int i = 0; i < 40; ++i)
        lambda[i] = i < 13 ? 1.0 : (i < 26 ? 4.0 : 9.0);
    const Eigen::MatrixXd A = spd_with_spectrum(lambda, 11u);
    const Eigen::VectorXd b = random_vector(40, 12u);
    CgSettings settings;
    settings.relative_tolerance = 1e-10;
    Eigen::VectorXd x;
    const CgResult result = conjugate_gradient(sparse_operator(A), b, x, settings);
    CHECK(result.converged);
    CHECK(result.iterations <= 3);
    CHECK(relative_error(x, dense_solve(A, b)) <= 1e-9);
}

TEST_CASE("CG iterations grow like the square root of the condition number on Laplacians", "[ex09.1]")
{
    const double tau = 1e-8;
    CgSettings settings;
    settings.relative_tolerance = tau;
    for (int dimension : {2, 3}) {
        CAPTURE(dimension);
        const std::vector<int> sizes = dimension == 2 ? std::vector<int>{16, 32, 64, 128}
                                                      : std::vector<int>{8, 16, 32};
        std::vector<double> kappa, iterations;
        for (int n : sizes) {
            const EigenOperator A(fem::sparse::to_eigen(dimension == 2 ? fem::direct::laplacian_2d(n)
                                                                       : fem::direct::laplacian_3d(n)));
            const Eigen::VectorXd b = random_vector(A.size(), 5u);
            Eigen::VectorXd x;
            const CgResult result = conjugate_gradient(A, b, x, settings);
            REQUIRE(result.converged);
            const double k = laplacian_condition_number(n);
            // The residual bound ‖r_k‖/‖r₀‖ ≤ 2√κ ((√κ−1)/(√κ+1))^k (x₀ = 0).
            CHECK(result.iterations <= iteration_bound(k, tau / std::sqrt(k)));
            kappa.push_back(k);
            iterations.push_back(result.iterations);
        }
        // The slope of log(iterations) against log(κ): ½ for CG.
        const double exponent = fem::fd::fitted_order(kappa, iterations);
        CAPTURE(iterations);
        CHECK(exponent == Approx(0.5).margin(0.08));
    }
}

TEST_CASE("laplacian_condition_number is λ_max/λ_min of the Laplacian (dense eigenvalues)", "[cg]")
{
    for (int n : {3, 8}) {
        const Eigen::MatrixXd A = Eigen::MatrixXd(laplacian_2d(n));
        const Eigen::VectorXd lambda = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A).eigenvalues();
        CHECK(laplacian_condition_number(n) == Approx(lambda.maxCoeff() / lambda.minCoeff()).epsilon(1e-10));
    }
    CHECK_THROWS_AS(laplacian_condition_number(0), fem::Error);
}

TEST_CASE("CG with the matrix-free stencil follows CG with the assembled Laplacian", "[ex09.1]")
{
    fem::heat::Grid grid;
    grid.n = 40;
    const FunctionOperator stencil = stencil_operator(grid);
    const CsrOperator assembled(fem::sparse::csr_from_eigen(laplacian_2d(grid.n)));
    const Eigen::VectorXd b = random_vector(stencil.size(), 21u);
    Eigen::VectorXd x_stencil, x_assembled;
    const CgResult a = conjugate_gradient(stencil, b, x_stencil);
    const CgResult c = conjugate_gradient(assembled, b, x_assembled);
    CHECK(a.converged);
    CHECK(std::abs(a.iterations - c.iterations) <= 1);
    CHECK(relative_error(x_stencil, x_assembled) <= 1e-7);
}

TEST_CASE("a warm start near the solution needs fewer iterations, the solution itself none", "[ex09.1]")
{
    const EigenOperator A(laplacian_2d(30));
    const Eigen::VectorXd b = random_vector(A.size(), 8u);
    CgSettings settings;
    settings.relative_tolerance = 1e-10;
    Eigen::VectorXd x;
    const CgResult cold = conjugate_gradient(A, b, x, settings);
    REQUIRE(cold.converged);

    Eigen::VectorXd near = x + 1e-4 * x.norm() / std::sqrt(double(x.size())) * random_vector(x.size(), 9u);
    const CgResult warm = conjugate_gradient(A, b, near, settings);
    CHECK(warm.converged);
    CHECK(warm.iterations < cold.iterations);
    CHECK(warm.residual_history.front() < 1e-3);  // relative to ‖b‖: the start is already close

    Eigen::VectorXd exact = x;
    const CgResult none = conjugate_gradient(A, b, exact, settings);
    CHECK(none.converged);
    CHECK(none.iterations == 0);
    CHECK(none.residual_history.size() == 1);
    CHECK(exact == x);
}

TEST_CASE("b = 0 gives x = 0 whatever the start", "[cg]")
{
    const EigenOperator A(laplacian_2d(5));
    Eigen::VectorXd x = Eigen::VectorXd::Ones(A.size());
    const CgResult result = conjugate_gradient(A, Eigen::VectorXd::Zero(A.size()), x);
    CHECK(result.converged);
    CHECK(result.iterations == 0);
    CHECK(x.isZero(0.0));
}

TEST_CASE("the iteration cap stops CG, reports it, and keeps the history", "[ex09.1]")
{
    const EigenOperator A(laplacian_2d(32));
    const Eigen::VectorXd b = Eigen::VectorXd::Ones(A.size());
    CgSettings settings;
    settings.max_iterations = 5;
    Eigen::VectorXd x;
    const CgResult result = conjugate_gradient(A, b, x, settings);
    CHECK_FALSE(result.converged);
    CHECK(result.iterations == 5);
    REQUIRE(result.residual_history.size() == 6);
    CHECK(result.residual_history.back() > settings.relative_tolerance);
    // The residual of CG is not monotone, but the A-norm error is: the energy went down.
    const Eigen::VectorXd Ax = A.matrix() * x;
    CHECK(0.5 * x.dot(Ax) - b.dot(x) < 0.0);
}

TEST_CASE("an indefinite matrix is detected: pᵀAp ≤ 0 names the iteration and the value", "[ex09.1]")
{
    SECTION("negative curvature at the first step")
    {
        Eigen::MatrixXd A(2, 2);
        A << 1, 0, 0, -1;
        Eigen::VectorXd b(2);
        b << 1, 2;  // p₀ = b: pᵀAp = 1 − 4 = −3
        Eigen::VectorXd x;
        CHECK_THROWS_WITH(conjugate_gradient(sparse_operator(A), b, x),
                          Contains("pᵀAp = -3") && Contains("iteration 0") && Contains("not positive definite"));
    }
    SECTION("negative curvature found later")
    {
        const Eigen::MatrixXd A = spd_with_spectrum((Eigen::VectorXd(6) << -0.5, 1, 2, 3, 4, 5).finished(), 4u);
        const Eigen::VectorXd b = random_vector(6, 5u);
        Eigen::VectorXd x;
        CHECK_THROWS_AS(conjugate_gradient(sparse_operator(A), b, x), fem::Error);
        CHECK_THROWS_WITH(conjugate_gradient(sparse_operator(A), b, x), Contains("pᵀAp"));
    }
}

TEST_CASE("CG agrees with Eigen's ConjugateGradient", "[ex09.1]")
{
    const ElasticBox box = clamped_box(4, fem::elastic::lame_parameters(1e5, 0.45), 1000.0);
    for (const Eigen::SparseMatrix<double>& K : {box.K, laplacian_2d(24)}) {
        const Eigen::VectorXd b = random_vector(K.rows(), 31u);
        const double tau = 1e-10;
        Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                                 Eigen::IdentityPreconditioner>
            eigen_cg(K);
        eigen_cg.setTolerance(tau);
        const Eigen::VectorXd x_eigen = eigen_cg.solve(b);
        REQUIRE(eigen_cg.info() == Eigen::Success);

        CgSettings settings;
        settings.relative_tolerance = tau;
        Eigen::VectorXd x;
        const CgResult result = conjugate_gradient(EigenOperator(K), b, x, settings);
        CHECK(result.converged);
        CHECK(std::abs(result.iterations - static_cast<int>(eigen_cg.iterations())) <= 2);
        const Eigen::VectorXd reference = Eigen::SimplicialLLT<Eigen::SparseMatrix<double>>(K).solve(b);
        CHECK(relative_error(x, x_eigen) <= 1e-6);
        CHECK(relative_error(x, reference) <= 1e-6);
    }
}

TEST_CASE("flexible PCG: plain PCG's iterates for a fixed preconditioner, fewer iterations for a changing one",
          "[ex09.1]")
{
    // A 1D Laplacian with a varying diagonal (SPD, n = 300).
    const int n = 300;
    std::vector<Eigen::Triplet<double>> entries;
    for (int i = 0; i < n; ++i) {
        entries.emplace_back(i, i, 2.0 + 0.5 * std::sin(0.1 * i) + 1.0 + i % 7);
        if (i + 1 < n) {
            entries.emplace_back(i, i + 1, -1.0);
            entries.emplace_back(i + 1, i, -1.0);
        }
    }
    Eigen::SparseMatrix<double> A(n, n);
    A.setFromTriplets(entries.begin(), entries.end());
    const Eigen::VectorXd b = random_vector(n, 95u), jacobi = A.diagonal().cwiseInverse();
    const EigenOperator product(A);
    CgSettings plain_settings, flexible_settings;
    plain_settings.relative_tolerance = flexible_settings.relative_tolerance = 1e-10;
    flexible_settings.beta = CgBeta::polak_ribiere;
    // A fixed SPD preconditioner (Jacobi, written out): z_{k+1}ᵀr_k = 0, both β agree, the same iterates.
    const FunctionOperator fixed(n, [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) { z = jacobi.cwiseProduct(r); });
    Eigen::VectorXd x_plain, x_flexible;
    const CgResult plain = preconditioned_conjugate_gradient(product, fixed, b, x_plain, plain_settings);
    const CgResult flexible = preconditioned_conjugate_gradient(product, fixed, b, x_flexible, flexible_settings);
    CAPTURE(plain.iterations, flexible.iterations);
    CHECK(std::abs(plain.iterations - flexible.iterations) <= 1);
    CHECK(relative_error(x_flexible, x_plain) <= 1e-8);
    // A preconditioner that changes at every application (D⁻¹ and 4 D⁻², in turn; D = diag A):
    // plain PCG's β assumes a fixed M⁻¹ and loses the conjugacy of consecutive directions; the
    // Polak–Ribière β keeps it and needs fewer iterations.
    int applications = 0;
    const FunctionOperator changing(n, [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
        z = (applications++ % 2 == 0) ? Eigen::VectorXd(jacobi.cwiseProduct(r))
                                      : Eigen::VectorXd(jacobi.cwiseProduct(jacobi).cwiseProduct(r) * 4.0);
    });
    plain_settings.max_iterations = flexible_settings.max_iterations = 2000;
    Eigen::VectorXd y_plain, y_flexible;
    applications = 0;
    const CgResult plain_changing = preconditioned_conjugate_gradient(product, changing, b, y_plain, plain_settings);
    applications = 0;
    const CgResult flexible_changing =
        preconditioned_conjugate_gradient(product, changing, b, y_flexible, flexible_settings);
    // The first β by hand, from x₀ = 0: r₀ = b, z₀ = D⁻¹ r₀, p₀ = z₀, r₁ = r₀ − α₀ A p₀, z₁ = 4 D⁻² r₁.
    const Eigen::VectorXd z0 = jacobi.cwiseProduct(b), Ap0 = A * z0;
    const double rz0 = b.dot(z0), alpha0 = rz0 / z0.dot(Ap0);
    const Eigen::VectorXd r1 = b - alpha0 * Ap0, z1 = 4.0 * jacobi.cwiseProduct(jacobi).cwiseProduct(r1);
    const double fletcher_reeves = z1.dot(r1) / rz0, polak_ribiere = z1.dot(r1 - b) / rz0;
    REQUIRE(std::abs(fletcher_reeves - polak_ribiere) > 1e-3 * std::abs(fletcher_reeves));  // they differ here
    REQUIRE(!plain_changing.beta.empty());
    REQUIRE(!flexible_changing.beta.empty());
    INFO("beta_0: plain PCG " << plain_changing.beta[0] << ", flexible " << flexible_changing.beta[0]
                              << "; by hand r_1^T z_1 / r_0^T z_0 = " << fletcher_reeves
                              << " (Fletcher-Reeves) and z_1^T (r_1 - r_0) / r_0^T z_0 = " << polak_ribiere
                              << " (Polak-Ribiere, CgBeta::polak_ribiere)");
    CHECK(plain_changing.beta[0] == Approx(fletcher_reeves).epsilon(1e-12));
    CHECK(flexible_changing.beta[0] == Approx(polak_ribiere).epsilon(1e-12));
    CAPTURE(plain_changing.iterations, flexible_changing.iterations, plain.iterations);
    CHECK(flexible_changing.converged);
    CHECK(flexible_changing.relative_residual <= 1e-10);
    CHECK(flexible_changing.iterations < plain_changing.iterations);
}

TEST_CASE("the observer sees every iterate", "[ex09.1]")
{
    const Eigen::MatrixXd A = spd_with_spectrum(Eigen::VectorXd::LinSpaced(10, 1.0, 3.0), 2u);
    const Eigen::VectorXd b = random_vector(10, 3u);
    const Eigen::VectorXd reference = dense_solve(A, b);
    std::vector<double> errors, residuals;
    CgSettings settings;
    settings.relative_tolerance = 1e-12;
    settings.observer = [&](int k, const Eigen::VectorXd& x, double relative_residual) {
        CHECK(k == static_cast<int>(errors.size()));
        errors.push_back(std::sqrt((x - reference).dot(A * (x - reference))));  // the A-norm error
        residuals.push_back(relative_residual);
    };
    Eigen::VectorXd x;
    const CgResult result = conjugate_gradient(sparse_operator(A), b, x, settings);
    REQUIRE(errors.size() == static_cast<std::size_t>(result.iterations) + 1);
    CHECK(residuals == result.residual_history);
    for (std::size_t k = 1; k < errors.size(); ++k)
        CHECK(errors[k] <= errors[k - 1] * (1.0 + 1e-12));  // CG minimises the A-norm error
}

TEST_CASE("CG rejects bad input with fem::Error", "[cg]")
{
    const EigenOperator A(laplacian_2d(4));
    const Eigen::VectorXd b = Eigen::VectorXd::Ones(16);
    Eigen::VectorXd x;
    CHECK_THROWS_WITH(conjugate_gradient(A, Eigen::VectorXd::Ones(15), x), Contains("b has 15 entries"));
    Eigen::VectorXd wrong_start = Eigen::VectorXd::Zero(3);
    CHECK_THROWS_WITH(conjugate_gradient(A, b, wrong_start), Contains("starting guess"));
    Eigen::VectorXd nan_b = b;
    nan_b[5] = std::numeric_limits<double>::quiet_NaN();
    CHECK_THROWS_WITH(conjugate_gradient(A, nan_b, x), Contains("b[5]"));
    CgSettings bad;
    bad.relative_tolerance = 0.0;
    CHECK_THROWS_WITH(conjugate_gradient(A, b, x, bad), Contains("relative tolerance"));
    bad.relative_tolerance = 1e-8;
    bad.max_iterations = -1;
    CHECK_THROWS_WITH(conjugate_gradient(A, b, x, bad), Contains("iteration cap"));
    const EigenOperator small(laplacian_2d(2));
    CHECK_THROWS_AS(preconditioned_conjugate_gradient(A, small, b, x), fem::Error);
}

TEST_CASE("iteration_bound is the smallest k with 2((√κ−1)/(√κ+1))^k ≤ τ", "[cg]")
{
    CHECK(iteration_bound(1.0, 1e-8) == 1);
    for (double kappa : {4.0, 100.0, 1e4}) {
        for (double tau : {1e-2, 1e-8}) {
            const int k = iteration_bound(kappa, tau);
            const double rate = (std::sqrt(kappa) - 1.0) / (std::sqrt(kappa) + 1.0);
            CHECK(2.0 * std::pow(rate, k) <= tau);
            CHECK(2.0 * std::pow(rate, k - 1) > tau);
        }
    }
    CHECK_THROWS_AS(iteration_bound(0.5, 1e-8), fem::Error);
    CHECK_THROWS_AS(iteration_bound(10.0, 1.0), fem::Error);
}

TEST_CASE("the operator adapters all compute A x", "[cg]")
{
    const ElasticBox box = clamped_box(2, fem::elastic::lame_parameters(1e5, 0.3), 1000.0);
    const Eigen::MatrixXd dense(box.K);
    const Eigen::VectorXd x = random_vector(dense.rows(), 17u);
    const Eigen::VectorXd expected = dense * x;
    const fem::sparse::CsrMatrix csr = fem::sparse::csr_from_eigen(box.K);
    const EigenOperator eigen_operator(box.K);
    const CsrOperator csr_operator(csr);
    const SymmetricCsrOperator symmetric(csr);
    const SymmetricCsrOperator from_lower(fem::sparse::lower_triangle(csr));
    const FunctionOperator function(dense.rows(), [&](const Eigen::VectorXd& u, Eigen::VectorXd& y) { y = dense * u; });
    for (const LinearOperator* A : std::vector<const LinearOperator*>{&eigen_operator, &csr_operator, &symmetric,
                                                                      &from_lower, &function}) {
        Eigen::VectorXd y;
        A->apply(x, y);
        CHECK_THAT(entries_of(y), EntriesNear(expected, 1e-12 * expected.norm()));
        CHECK_THROWS_AS(A->apply(Eigen::VectorXd::Ones(3), y), fem::Error);
        Eigen::VectorXd same = x;
        CHECK_THROWS_AS(A->apply(same, same), fem::Error);
    }
    CHECK(diagonal(csr) == dense.diagonal());
    CHECK_THROWS_AS(EigenOperator(Eigen::SparseMatrix<double>(3, 4)), fem::Error);
    fem::sparse::CsrMatrix rectangular = fem::sparse::csr_from_eigen(Eigen::SparseMatrix<double>(3, 4));
    CHECK_THROWS_AS(CsrOperator(rectangular), fem::Error);
    CHECK_THROWS_AS(FunctionOperator(3, nullptr), fem::Error);
}

TEST_CASE("the stencil operator is the assembled Laplacian", "[cg]")
{
    fem::heat::Grid grid;
    grid.n = 7;
    const FunctionOperator stencil = stencil_operator(grid);
    const Eigen::SparseMatrix<double> A = laplacian_2d(grid.n);
    const Eigen::VectorXd x = random_vector(49, 4u);
    Eigen::VectorXd y;
    stencil.apply(x, y);
    const Eigen::VectorXd expected = A * x;
    CHECK_THAT(entries_of(y), EntriesNear(expected, 1e-12 * expected.norm()));
}

TEST_CASE("the clamped box is chapter 06's reduced system", "[cg]")
{
    const fem::elastic::Lame material = fem::elastic::lame_parameters(2e5, 0.4);
    const ElasticBox box = clamped_box(3, material, 1200.0);
    CHECK(box.K.rows() == 3 * 3 * 4 * 4);
    CHECK(box.pinned.size() == 16);
    // K against Pᵀ K_full P assembled here from chapter 06, f against the weight of the free part.
    const Eigen::SparseMatrix<double> K_full = fem::assembly::stiffness_matrix(box.mesh, material);
    const Eigen::SparseMatrix<double> reduced = box.P.transpose() * K_full * box.P;
    CHECK_THAT(entries_of(Eigen::MatrixXd(box.K)), EntriesNear(Eigen::MatrixXd(reduced), 1e-12 * Eigen::MatrixXd(reduced).norm()));
    double weight = 0.0;
    for (Eigen::Index i = 2; i < box.f.size(); i += 3)
        weight += box.f[i];
    // The free vertices carry all but the pinned face's share: between 3/4 and all of ρ g V.
    CHECK(weight < 0.0);
    CHECK(-weight < 1200.0 * 9.81);
    CHECK(-weight > 0.75 * 1200.0 * 9.81);
    CHECK_THROWS_AS(clamped_box(0, material, 1000.0), fem::Error);
    CHECK_THROWS_AS(clamped_box(2, material, -1.0), fem::Error);
}
