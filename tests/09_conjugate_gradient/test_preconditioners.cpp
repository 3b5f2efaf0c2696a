// Chapter 09: Jacobi and IC(0) against their definitions and dense references, the breakdown of
// IC(0) on Kershaw's matrix and the diagonal shift, PCG against CG and Eigen's ConjugateGradient,
// and the Lanczos estimate of the spectrum. docs/09_conjugate_gradient.md#preconditioning
#include "09_conjugate_gradient/conjugate_gradient.hpp"
#include "09_conjugate_gradient/linear_operator.hpp"
#include "09_conjugate_gradient/model_problems.hpp"
#include "09_conjugate_gradient/preconditioners.hpp"

#include "cg_test_support.hpp"

#include "07_sparse_storage/sparse_formats.hpp"
#include "08_direct_solvers/model_problems.hpp"
#include "common/error.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>

#include <cmath>
#include <random>

using namespace fem::cg;
using fem::cg::test::dense_solve;
using fem::cg::test::kershaw_matrix;
using fem::cg::test::relative_error;
using fem::random_vector;
using fem::cg::test::spd_with_spectrum;
using fem::cg::test::tridiagonal_laplacian;
using fem::sparse::CsrMatrix;
using Catch::Matchers::Contains;
using fem::test::EntriesNear;
using fem::test::entries_of;

namespace {

CsrMatrix csr_of(const Eigen::MatrixXd& A)
{
    return fem::sparse::csr_from_eigen(Eigen::SparseMatrix<double>(A.sparseView()));
}

Eigen::MatrixXd dense_of(const CsrMatrix& A)
{
    return Eigen::MatrixXd(fem::sparse::to_eigen(A));
}

/// A random lower triangular n×n matrix with a nonzero diagonal in [1, 2] and off-diagonal entries
/// of density 0.3 in [−1, 1], dense (built without the chapter's code).
Eigen::MatrixXd random_lower(int n, unsigned seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    Eigen::MatrixXd L = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < n; ++i) {
        L(i, i) = 1.0 + uniform(rng);
        for (int j = 0; j < i; ++j)
            if (uniform(rng) < 0.3)
                L(i, j) = 2.0 * uniform(rng) - 1.0;
    }
    return L;
}

}  // namespace

// --- Jacobi ------------------------------------------------------------------------------------

TEST_CASE("Jacobi divides each residual entry by the diagonal", "[ex09.2]")
{
    const Eigen::VectorXd d = (Eigen::VectorXd(4) << 2.0, 0.5, 10.0, 4.0).finished();
    const JacobiPreconditioner M(d);
    const Eigen::VectorXd r = (Eigen::VectorXd(4) << 1.0, -1.0, 5.0, 2.0).finished();
    Eigen::VectorXd z;
    M.apply(r, z);
    CHECK(z.isApprox((Eigen::VectorXd(4) << 0.5, -2.0, 0.5, 0.5).finished(), 1e-15));
}

TEST_CASE("Jacobi undoes a bad scaling of the rows and columns", "[ex09.2]")
{
    // S A S with S = diag(10^s), s in [−2, 2]: κ explodes, the diagonal preconditioner removes most of it.
    const Eigen::MatrixXd A = tridiagonal_laplacian(60);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> exponent(-2.0, 2.0);
    Eigen::VectorXd s(60);
    for (int i = 0; i < 60; ++i)
        s[i] = std::pow(10.0, exponent(rng));
    const Eigen::MatrixXd scaled = s.asDiagonal() * A * s.asDiagonal();
    const CsrMatrix csr = csr_of(scaled);
    const CsrOperator op(csr);
    const Eigen::VectorXd b = random_vector(60, 4u);
    CgSettings settings;
    settings.relative_tolerance = 1e-10;
    settings.max_iterations = 5000;
    Eigen::VectorXd x_cg, x_pcg;
    const CgResult cg = conjugate_gradient(op, b, x_cg, settings);
    const CgResult pcg = preconditioned_conjugate_gradient(op, JacobiPreconditioner(diagonal(csr)), b, x_pcg, settings);
    CHECK(pcg.converged);
    CHECK(3 * pcg.iterations < cg.iterations);
    CHECK(relative_error(x_pcg, dense_solve(scaled, b)) <= 1e-6);
}

TEST_CASE("PCG with Jacobi agrees with Eigen's ConjugateGradient and its diagonal preconditioner", "[ex09.2]")
{
    const ElasticBox box = clamped_box(5, fem::elastic::lame_parameters(1e5, 0.45), 1000.0);
    const double tau = 1e-10;
    Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> eigen_cg(box.K);
    eigen_cg.setTolerance(tau);
    const Eigen::VectorXd x_eigen = eigen_cg.solve(box.f);
    REQUIRE(eigen_cg.info() == Eigen::Success);

    const CsrMatrix csr = fem::sparse::csr_from_eigen(box.K);
    CgSettings settings;
    settings.relative_tolerance = tau;
    Eigen::VectorXd x;
    const CgResult result =
        preconditioned_conjugate_gradient(SymmetricCsrOperator(csr), JacobiPreconditioner(diagonal(csr)), box.f, x,
                                          settings);
    CHECK(result.converged);
    CHECK(std::abs(result.iterations - static_cast<int>(eigen_cg.iterations())) <= 2);
    CHECK(relative_error(x, x_eigen) <= 1e-6);
}

TEST_CASE("Jacobi rejects a diagonal that is not positive", "[cg]")
{
    CHECK_THROWS_WITH(JacobiPreconditioner((Eigen::VectorXd(3) << 1.0, 0.0, 2.0).finished()),
                      Contains("diagonal entry 1"));
    CHECK_THROWS_AS(JacobiPreconditioner((Eigen::VectorXd(2) << 1.0, std::nan("")).finished()), fem::Error);
    const JacobiPreconditioner M(Eigen::VectorXd::Ones(3));
    Eigen::VectorXd z;
    CHECK_THROWS_AS(M.apply(Eigen::VectorXd::Ones(4), z), fem::Error);
}

// --- IC(0) -------------------------------------------------------------------------------------

TEST_CASE("IC(0) of a tridiagonal matrix is its exact Cholesky factor (no fill to drop)", "[ex09.3]")
{
    const Eigen::MatrixXd A = tridiagonal_laplacian(12);
    const IcAttempt ic = incomplete_cholesky_factor(fem::sparse::lower_triangle(csr_of(A)), 0.0);
    REQUIRE(ic.breakdown_row == -1);
    const Eigen::MatrixXd L = Eigen::LLT<Eigen::MatrixXd>(A).matrixL();
    CHECK_THAT(entries_of(dense_of(ic.L)), EntriesNear(L, 1e-13 * L.norm()));
}

TEST_CASE("IC(0) reproduces A on its pattern and drops the fill elsewhere", "[ex09.3]")
{
    const CsrMatrix A = fem::sparse::csr_from_eigen(fem::sparse::to_eigen(fem::direct::laplacian_2d(6)));
    const IcAttempt ic = incomplete_cholesky_factor(fem::sparse::lower_triangle(A), 0.0);
    REQUIRE(ic.breakdown_row == -1);
    const Eigen::MatrixXd L = dense_of(ic.L);
    const Eigen::MatrixXd M = L * L.transpose();
    const Eigen::MatrixXd dense = dense_of(A);
    const auto on_pattern = (dense.array() != 0.0);
    CHECK_THAT(entries_of(on_pattern.select(M, 0.0)), EntriesNear(dense, 0.0, 1e-12));
    const double off_pattern = on_pattern.select(0.0, M).cwiseAbs().maxCoeff();
    CHECK(off_pattern > 1.0);  // the dropped fill: L Lᵀ ≠ A off the pattern
    // The same pattern as A's lower triangle.
    const CsrMatrix lower = fem::sparse::lower_triangle(A);
    CHECK(ic.L.IA == lower.IA);
    CHECK(ic.L.JA == lower.JA);
}

TEST_CASE("IC(0) with a shift factors A + α diag(A)", "[ex09.3]")
{
    const Eigen::MatrixXd A = tridiagonal_laplacian(8);
    const double alpha = 0.5;
    const IcAttempt ic = incomplete_cholesky_factor(fem::sparse::lower_triangle(csr_of(A)), alpha);
    REQUIRE(ic.breakdown_row == -1);
    const Eigen::MatrixXd shifted = A + alpha * Eigen::MatrixXd(A.diagonal().asDiagonal());
    const Eigen::MatrixXd L = Eigen::LLT<Eigen::MatrixXd>(shifted).matrixL();
    CHECK_THAT(entries_of(dense_of(ic.L)), EntriesNear(L, 1e-13 * L.norm()));
}

TEST_CASE("IC(0) breaks down on Kershaw's matrix, and the diagonal shift repairs it", "[ex09.3]")
{
    const Eigen::MatrixXd A = kershaw_matrix();
    REQUIRE(Eigen::LLT<Eigen::MatrixXd>(A).info() == Eigen::Success);  // SPD all the same
    // By hand: L00 = √3, L10 = −2/√3, L11 = √(5/3), L21 = −2/√(5/3), L22 = √(3/5), L30 = 2/√3,
    // L32 = −2/√(3/5) (rows 2 and 3 share no earlier column), pivot 3 − 4/3 − 20/3 = −5.
    const IcAttempt ic = incomplete_cholesky_factor(fem::sparse::lower_triangle(csr_of(A)), 0.0);
    CHECK(ic.breakdown_row == 3);
    CHECK(ic.pivot == Approx(-5.0).epsilon(1e-12));

    IcSettings strict;
    strict.allow_shift = false;
    CHECK_THROWS_WITH(IncompleteCholesky(csr_of(A), strict), Contains("broke down in row 3"));

    const IncompleteCholesky shifted(csr_of(A));
    CHECK(shifted.shift() > 0.0);
    CHECK(shifted.attempts() >= 2);
    // The shift that worked is the first of 0, α₀, 2α₀, … that does not break down.
    const IcAttempt previous = incomplete_cholesky_factor(fem::sparse::lower_triangle(csr_of(A)),
                                                          shifted.attempts() == 2 ? 0.0 : shifted.shift() / 2.0);
    CHECK(previous.breakdown_row >= 0);
}

TEST_CASE("PCG with the shifted IC(0) solves Kershaw's system", "[ex09.5]")
{
    const Eigen::MatrixXd A = kershaw_matrix();
    const IncompleteCholesky shifted(csr_of(A));
    REQUIRE(shifted.shift() > 0.0);
    const Eigen::VectorXd b = random_vector(4, 2u);
    Eigen::VectorXd x;
    CgSettings settings;
    settings.relative_tolerance = 1e-12;
    const CgResult result = preconditioned_conjugate_gradient(CsrOperator(csr_of(A)), shifted, b, x, settings);
    CHECK(result.converged);
    CHECK(relative_error(x, dense_solve(A, b)) <= 1e-9);
}

TEST_CASE("IC(0) rejects what it cannot factor", "[ex09.3]")
{
    Eigen::MatrixXd A = tridiagonal_laplacian(4);
    A(2, 2) = -1.0;
    CHECK_THROWS_WITH(incomplete_cholesky_factor(fem::sparse::lower_triangle(csr_of(A)), 0.0),
                      Contains("row 2 has no positive diagonal"));
    CHECK_THROWS_WITH(incomplete_cholesky_factor(csr_of(tridiagonal_laplacian(4)), 0.0), Contains("above the diagonal"));
    CHECK_THROWS_AS(incomplete_cholesky_factor(fem::sparse::lower_triangle(csr_of(tridiagonal_laplacian(4))), -1.0),
                    fem::Error);
    // Symmetric, indefinite, with a diagonal so small that even A + 1049 diag(A) stays indefinite:
    // every shift breaks down.
    Eigen::MatrixXd indefinite(2, 2);
    indefinite << 1e-6, 1.0, 1.0, 1e-6;
    CHECK_THROWS_WITH(IncompleteCholesky(csr_of(indefinite)), Contains("still broke down"));
}

// --- triangular solves -------------------------------------------------------------------------

TEST_CASE("solve_lower is forward substitution", "[ex09.4]")
{
    const Eigen::MatrixXd L = random_lower(25, 5u);
    const Eigen::VectorXd r = random_vector(25, 6u);
    Eigen::VectorXd x = r;
    solve_lower(csr_of(L), x);
    const Eigen::VectorXd expected = L.triangularView<Eigen::Lower>().solve(r);
    CHECK_THAT(entries_of(x), EntriesNear(expected, 1e-12 * expected.norm()));
}

TEST_CASE("solve_lower_transposed is backward substitution with Lᵀ", "[ex09.5]")
{
    const Eigen::MatrixXd L = random_lower(25, 7u);
    const Eigen::VectorXd y = random_vector(25, 8u);
    Eigen::VectorXd x = y;
    solve_lower_transposed(csr_of(L), x);
    const Eigen::VectorXd expected = L.transpose().triangularView<Eigen::Upper>().solve(y);
    CHECK_THAT(entries_of(x), EntriesNear(expected, 1e-12 * expected.norm()));
}

TEST_CASE("the IC(0) preconditioner solves L Lᵀ z = r", "[ex09.5]")
{
    const CsrMatrix A = fem::sparse::csr_from_eigen(fem::sparse::to_eigen(fem::direct::laplacian_2d(5)));
    const IncompleteCholesky ic(A);
    CHECK(ic.shift() == 0.0);  // a Laplacian is an M-matrix: IC(0) never breaks down
    CHECK(ic.attempts() == 1);
    const Eigen::MatrixXd L = dense_of(ic.factor());
    const Eigen::VectorXd r = random_vector(25, 3u);
    Eigen::VectorXd z;
    ic.apply(r, z);
    CHECK_THAT(entries_of(L * (L.transpose() * z)), EntriesNear(r, 1e-12 * r.norm()));
}

TEST_CASE("the triangular solves reject a factor without its diagonal", "[cg]")
{
    Eigen::MatrixXd L = random_lower(5, 1u);
    L(3, 3) = 0.0;
    Eigen::VectorXd x = Eigen::VectorXd::Ones(5);
    CHECK_THROWS_WITH(solve_lower(csr_of(L), x), Contains("row 3"));
    CHECK_THROWS_WITH(solve_lower_transposed(csr_of(L), x), Contains("row 3"));
    Eigen::VectorXd short_x = Eigen::VectorXd::Ones(4);
    CHECK_THROWS_AS(solve_lower(csr_of(random_lower(5, 1u)), short_x), fem::Error);
}

// --- PCG against CG ----------------------------------------------------------------------------

TEST_CASE("PCG needs fewer iterations than CG on the elasticity K", "[ex09.5]")
{
    const ElasticBox box = clamped_box(6, fem::elastic::lame_parameters(1e5, 0.45), 1000.0);
    const CsrMatrix K = fem::sparse::csr_from_eigen(box.K);
    const SymmetricCsrOperator A(K);
    const Eigen::VectorXd reference = Eigen::SimplicialLLT<Eigen::SparseMatrix<double>>(box.K).solve(box.f);
    CgSettings settings;
    settings.relative_tolerance = 1e-10;
    Eigen::VectorXd x_cg, x_jacobi, x_ic;
    const CgResult cg = conjugate_gradient(A, box.f, x_cg, settings);
    const CgResult jacobi = preconditioned_conjugate_gradient(A, JacobiPreconditioner(diagonal(K)), box.f, x_jacobi,
                                                              settings);
    const IncompleteCholesky ic0(K);
    const CgResult ic = preconditioned_conjugate_gradient(A, ic0, box.f, x_ic, settings);
    REQUIRE(cg.converged);
    REQUIRE(jacobi.converged);
    REQUIRE(ic.converged);
    CHECK(jacobi.iterations < cg.iterations);
    CHECK(3 * ic.iterations < cg.iterations);
    for (const Eigen::VectorXd* x : {&x_cg, &x_jacobi, &x_ic})
        CHECK(relative_error(*x, reference) <= 1e-5);  // κ(K) ≈ 10⁴ times τ = 1e-10
}

// --- the Lanczos estimate ----------------------------------------------------------------------

TEST_CASE("CG's coefficients give the extreme eigenvalues", "[ex09.6]")
{
    const Eigen::MatrixXd A = spd_with_spectrum(Eigen::VectorXd::LinSpaced(50, 1.0, 100.0), 13u);
    const Eigen::VectorXd b = random_vector(50, 14u);
    CgSettings settings;
    settings.relative_tolerance = 1e-10;
    Eigen::VectorXd x;
    const CgResult run = conjugate_gradient(EigenOperator(Eigen::SparseMatrix<double>(A.sparseView())), b, x, settings);
    const SpectrumEstimate estimate = lanczos_extreme_eigenvalues(run);
    CHECK(estimate.lambda_min == Approx(1.0).epsilon(1e-6));
    CHECK(estimate.lambda_max == Approx(100.0).epsilon(1e-6));
    CHECK(estimate.condition() == Approx(100.0).epsilon(1e-5));
}

TEST_CASE("the Lanczos estimate of κ matches the Laplacian's cot²(πh/2)", "[ex09.6]")
{
    const int n = 40;
    const EigenOperator A(fem::sparse::to_eigen(fem::direct::laplacian_2d(n)));
    CgSettings settings;
    settings.relative_tolerance = 1e-10;
    Eigen::VectorXd x;
    const CgResult run = conjugate_gradient(A, random_vector(A.size(), 1u), x, settings);
    CHECK(lanczos_extreme_eigenvalues(run).condition() == Approx(laplacian_condition_number(n)).epsilon(1e-3));
}

TEST_CASE("the Lanczos estimate of a preconditioned run is the spectrum of M⁻¹A", "[ex09.6]")
{
    // Jacobi on D A D is exactly the spectrum of D⁻¹ᐟ² (D A D) D⁻¹ᐟ², the diagonally scaled matrix.
    const Eigen::MatrixXd A = tridiagonal_laplacian(30);
    const Eigen::VectorXd s = Eigen::VectorXd::LinSpaced(30, 1.0, 5.0);
    const Eigen::MatrixXd scaled = s.asDiagonal() * A * s.asDiagonal();
    const Eigen::VectorXd d = scaled.diagonal();
    const Eigen::MatrixXd normalised = d.cwiseSqrt().cwiseInverse().asDiagonal() * scaled *
                                       d.cwiseSqrt().cwiseInverse().asDiagonal();
    const Eigen::VectorXd lambda = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(normalised).eigenvalues();
    CgSettings settings;
    settings.relative_tolerance = 1e-12;
    Eigen::VectorXd x;
    const CsrMatrix csr = csr_of(scaled);
    const CgResult run = preconditioned_conjugate_gradient(CsrOperator(csr), JacobiPreconditioner(diagonal(csr)),
                                                           random_vector(30, 2u), x, settings);
    const SpectrumEstimate estimate = lanczos_extreme_eigenvalues(run);
    CHECK(estimate.lambda_min == Approx(lambda.minCoeff()).epsilon(1e-6));
    CHECK(estimate.lambda_max == Approx(lambda.maxCoeff()).epsilon(1e-6));
}

TEST_CASE("the Lanczos estimate needs at least one iteration", "[cg]")
{
    CgResult empty;
    CHECK_THROWS_WITH(lanczos_extreme_eigenvalues(empty), Contains("no iteration"));
    CgResult bad;
    bad.alpha = {1.0, -2.0};
    bad.beta = {0.5};
    CHECK_THROWS_AS(lanczos_extreme_eigenvalues(bad), fem::Error);
}
