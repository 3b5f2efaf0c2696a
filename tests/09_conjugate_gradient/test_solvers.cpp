// Chapter 09: the solver interface. Every solver by name against a dense solve, the default, the
// errors (unknown name, bad matrices, indefinite A, a missed tolerance), warm starts and
// refactorisation with the same pattern. docs/09_conjugate_gradient.md#one-interface-for-every-solver
#include "09_conjugate_gradient/linear_solver.hpp"
#include "09_conjugate_gradient/model_problems.hpp"

#include "cg_test_support.hpp"

#include "07_sparse_storage/sparse_formats.hpp"
#include "08_direct_solvers/model_problems.hpp"
#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

using namespace fem::cg;
using fem::random_vector;
using fem::cg::test::spd_with_spectrum;
using fem::cg::test::relative_error;
using Catch::Matchers::Contains;

namespace {

bool listed(const std::string& name)
{
    const std::vector<std::string> names = solver_names();
    return std::find(names.begin(), names.end(), name) != names.end();
}

}  // namespace

TEST_CASE("every solver of the interface solves the elastic box and a Laplacian", "[ex09.5]")
{
    const ElasticBox box = clamped_box(4, fem::elastic::lame_parameters(1e5, 0.45), 1000.0);
    const Eigen::SparseMatrix<double> laplacian = fem::sparse::to_eigen(fem::direct::laplacian_3d(7));
    SolverOptions options;
    options.relative_tolerance = 1e-10;
    for (const auto& [A, b] : {std::pair{box.K, box.f}, std::pair{laplacian, random_vector(laplacian.rows(), 2u)}}) {
        const Eigen::VectorXd reference = Eigen::MatrixXd(A).llt().solve(b);
        for (const std::string& name : solver_names()) {
            CAPTURE(name);
            const std::unique_ptr<LinearSolver> solver = make_solver(name, options);
            CHECK(solver->name() == name);
            solver->prepare(A);
            CHECK(solver->size() == A.rows());
            const Eigen::VectorXd x = solver->solve(b);
            CHECK(relative_error(x, reference) <= 1e-6);  // κ ≈ 10⁴ times τ
            const SolveStats& stats = solver->stats();
            if (solver->is_direct()) {
                CHECK(stats.iterations == 0);
                CHECK(solver->relative_residual() <= 1e-12);
            } else {
                CHECK(stats.iterations > 0);
                CHECK(solver->relative_residual() <= 2e-10);
            }
            CHECK(stats.prepare_seconds >= 0.0);
            CHECK(stats.solve_seconds >= 0.0);
        }
    }
}

TEST_CASE("a right-hand side near underflow or overflow: every solver returns the scaled solution", "[ex09.5]")
{
    // A motion decaying to rest drives b towards 1e-300; CG's inner products (squares of 1e-160)
    // would underflow to 0 and fail. Scaling by powers of two is exact, so the answer is the
    // normal-sized one scaled back.
    const Eigen::SparseMatrix<double> A = fem::sparse::to_eigen(fem::direct::laplacian_3d(6));
    Eigen::VectorXd b = random_vector(A.rows(), 3u);
    b /= 2.0 * b.cwiseAbs().maxCoeff();  // largest entry ½: solved as it is
    for (const std::string& name : solver_names()) {
        CAPTURE(name);
        const std::unique_ptr<LinearSolver> solver = make_solver(name);
        solver->prepare(A);
        const auto times_power_of_two = [](const Eigen::VectorXd& v, int power) {
            return Eigen::VectorXd(v.unaryExpr([power](double entry) { return std::ldexp(entry, power); }));
        };
        for (const int power : {-700, -1000, -1060, 700}) {  // 2⁻¹⁰⁶⁰ b: subnormal, fewer bits kept
            CAPTURE(power);
            const Eigen::VectorXd tiny = times_power_of_two(b, power);
            // The answer for the b it holds, taken to that size too (where it may round as well).
            const Eigen::VectorXd x = times_power_of_two(solver->solve(times_power_of_two(tiny, -power)), power);
            Eigen::VectorXd scaled;
            REQUIRE_NOTHROW(scaled = solver->solve(tiny));
            CHECK((times_power_of_two(scaled - x, -power)).norm() <= 1e-12 * times_power_of_two(x, -power).norm());
        }
    }
}

TEST_CASE("the solver names, the default and CHOLMOD", "[solvers]")
{
    for (const char* name : {"ours-cholesky", "ours-cg", "ours-pcg-jacobi", "ours-pcg-ic0", "eigen-llt", "eigen-cg"})
        CHECK(listed(name));
    CHECK(listed("cholmod") == cholmod_available());
    CHECK(listed(default_solver_name()));
    CHECK(make_solver()->name() == default_solver_name());
    CHECK(make_solver("default")->name() == default_solver_name());
    CHECK_THROWS_WITH(make_solver("superlu"), Contains("unknown solver 'superlu'") && Contains("ours-pcg-ic0"));
    if (!cholmod_available())
        CHECK_THROWS_WITH(make_solver("cholmod"), Contains("no CHOLMOD"));
    SolverOptions bad;
    bad.relative_tolerance = 2.0;
    CHECK_THROWS_AS(make_solver("ours-cg", bad), fem::Error);
}

TEST_CASE("every solver refuses an indefinite matrix with fem::Error", "[ex09.5]")
{
    const Eigen::MatrixXd dense = spd_with_spectrum((Eigen::VectorXd(6) << -1, 1, 2, 3, 4, 5).finished(), 3u);
    const Eigen::SparseMatrix<double> A = dense.sparseView();
    const Eigen::VectorXd b = random_vector(6, 4u);
    for (const std::string& name : solver_names()) {
        CAPTURE(name);
        if (name == "eigen-cg")
            continue;  // Eigen's CG does not check pᵀAp (CG may still succeed on an indefinite A)
        const std::unique_ptr<LinearSolver> solver = make_solver(name);
        // A direct solver finds out when it factors, an iterative one when it iterates.
        CHECK_THROWS_AS(
            [&] {
                solver->prepare(A);
                solver->solve(b);
            }(),
            fem::Error);
    }
}

TEST_CASE("prepare checks the matrix, solve checks b", "[solvers]")
{
    const std::unique_ptr<LinearSolver> solver = make_solver("ours-cg");
    CHECK_THROWS_WITH(solver->solve(Eigen::VectorXd::Ones(3)), Contains("before prepare"));
    CHECK_THROWS_WITH(solver->prepare(Eigen::SparseMatrix<double>(3, 4)), Contains("square"));
    Eigen::MatrixXd unsymmetric = Eigen::MatrixXd::Identity(3, 3);
    unsymmetric(0, 2) = 0.5;
    CHECK_THROWS_WITH(solver->prepare(unsymmetric.sparseView()), Contains("not symmetric"));
    unsymmetric(2, 0) = 0.25;  // both entries stored, and different: the message names the pair
    CHECK_THROWS_WITH(solver->prepare(unsymmetric.sparseView()), Contains("A(2, 0) − A(0, 2) = -0.25"));
    unsymmetric(2, 0) = 0.5;
    CHECK_NOTHROW(solver->prepare(unsymmetric.sparseView()));
    Eigen::MatrixXd not_finite = Eigen::MatrixXd::Identity(3, 3);
    not_finite(1, 1) = std::nan("");
    CHECK_THROWS_WITH(solver->prepare(not_finite.sparseView()), Contains("not finite"));
    solver->prepare(Eigen::MatrixXd::Identity(3, 3).sparseView());
    CHECK_THROWS_WITH(solver->solve(Eigen::VectorXd::Ones(4)), Contains("b has 4 entries"));
}

TEST_CASE("the relative residual of the last solve, computed when asked", "[solvers]")
{
    // Eigen's CG does not report its residual, so relative_residual() multiplies by A itself; a loose
    // tolerance leaves residuals far from round-off, different for each right-hand side.
    const Eigen::MatrixXd A = spd_with_spectrum(Eigen::VectorXd::LinSpaced(60, 1.0, 1e3), 3u);
    SolverOptions loose;
    loose.relative_tolerance = 0.05;
    const std::unique_ptr<LinearSolver> solver = make_solver("eigen-cg", loose);
    solver->prepare(A.sparseView());
    CHECK_THROWS_WITH(solver->relative_residual(), Contains("before a solve"));
    const auto residual = [&](const Eigen::VectorXd& b, const Eigen::VectorXd& x) {
        return (b - A * x).norm() / b.norm();
    };
    const Eigen::VectorXd b1 = random_vector(60, 4u), b2 = random_vector(60, 5u);
    const Eigen::VectorXd x1 = solver->solve(b1);
    const Eigen::VectorXd x2 = solver->solve(b2);
    CHECK(residual(b2, x2) > 1e-4);
    CHECK(residual(b1, x1) != residual(b2, x2));
    CHECK(solver->relative_residual() == Approx(residual(b2, x2)).epsilon(1e-12));  // the last solve's
    CHECK(solver->relative_residual() == Approx(residual(b2, x2)).epsilon(1e-12));  // asked again
    CHECK(solver->solve(Eigen::VectorXd::Zero(60)).norm() == 0.0);
    CHECK(solver->relative_residual() == 0.0);  // b = 0: ‖x‖
    solver->prepare(A.sparseView());  // prepared again: no residual until the next solve
    CHECK_THROWS_WITH(solver->relative_residual(), Contains("before a solve"));
}

TEST_CASE("an iterative solver that misses its tolerance says so", "[ex09.5]")
{
    SolverOptions options;
    options.max_iterations = 3;
    const Eigen::SparseMatrix<double> A = fem::sparse::to_eigen(fem::direct::laplacian_2d(20));
    for (const char* name : {"ours-cg", "ours-pcg-jacobi", "ours-pcg-ic0", "eigen-cg"}) {
        CAPTURE(name);
        const std::unique_ptr<LinearSolver> solver = make_solver(name, options);
        solver->prepare(A);
        CHECK_THROWS_WITH(solver->solve(Eigen::VectorXd::Ones(A.rows())), Contains("did not reach"));
    }
}

TEST_CASE("a warm start from the last solution costs an iterative solver nothing", "[ex09.5]")
{
    const Eigen::SparseMatrix<double> A = fem::sparse::to_eigen(fem::direct::laplacian_2d(30));
    const Eigen::VectorXd b = random_vector(A.rows(), 6u);
    for (const char* name : {"ours-cg", "ours-pcg-jacobi", "ours-pcg-ic0", "eigen-cg"}) {
        CAPTURE(name);
        const std::unique_ptr<LinearSolver> solver = make_solver(name);
        solver->prepare(A);
        Eigen::VectorXd x;
        solver->solve(b, x);
        const int cold = solver->stats().iterations;
        solver->solve(b, x);
        CHECK(solver->stats().iterations <= 1);  // the true residual may sit a hair above τ
        // A slightly different right-hand side (the next time step): fewer iterations than cold.
        solver->solve(b + 1e-3 * random_vector(A.rows(), 7u), x);
        CHECK(solver->stats().iterations < cold);
    }
}

TEST_CASE("prepare again with new values on the same pattern", "[ex09.5]")
{
    const ElasticBox box = clamped_box(3, fem::elastic::lame_parameters(1e5, 0.3), 1000.0);
    const Eigen::SparseMatrix<double> stiffer = 2.0 * box.K;
    SolverOptions options;
    options.relative_tolerance = 1e-12;
    for (const std::string& name : solver_names()) {
        CAPTURE(name);
        const std::unique_ptr<LinearSolver> solver = make_solver(name, options);
        solver->prepare(box.K);
        const Eigen::VectorXd x = solver->solve(box.f);
        solver->prepare(stiffer);  // same pattern: a direct solver reuses its analysis
        const Eigen::VectorXd half = solver->solve(box.f);
        CHECK(relative_error(half, 0.5 * x) <= 1e-8);
        solver->prepare(fem::sparse::to_eigen(fem::direct::laplacian_2d(6)));  // a new pattern and size
        CHECK(solver->size() == 36);
        CHECK(solver->solve(Eigen::VectorXd::Ones(36)).allFinite());
    }
}

namespace {

/// A direct solver wrapped to record, per prepare, whether the interface saw the pattern of the
/// last prepare (the flag it hands to do_prepare).
class PatternRecorder final : public LinearSolver {
public:
    explicit PatternRecorder(std::unique_ptr<LinearSolver> inner) : LinearSolver(inner->name()), inner_(std::move(inner)) {}
    bool is_direct() const override { return inner_->is_direct(); }
    std::vector<bool> same_patterns;

private:
    void do_prepare(const Eigen::SparseMatrix<double>& A, bool same_pattern) override
    {
        same_patterns.push_back(same_pattern);
        inner_->prepare(A);
    }
    int do_solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override
    {
        inner_->solve(b, x);
        return 0;
    }
    std::unique_ptr<LinearSolver> inner_;
};

}  // namespace

TEST_CASE("a factorization that fails keeps the pattern: the next matrix of it solves correctly", "[solvers]")
{
    // Newton's exact Hessian that is not positive definite, then its definite one with the same
    // pattern: the second prepare is a same-pattern one, and the solve after it is right.
    const Eigen::SparseMatrix<double> A = fem::sparse::to_eigen(fem::direct::laplacian_3d(4));
    Eigen::SparseMatrix<double> identity(A.rows(), A.cols());
    identity.setIdentity();
    // A diagonal entry below 0: not positive definite (the pattern stays A's: the diagonal is stored).
    const Eigen::SparseMatrix<double> indefinite = A - 1.5 * A.diagonal().maxCoeff() * identity;
    const Eigen::VectorXd b = random_vector(A.rows(), 7u);
    const Eigen::VectorXd expected = Eigen::MatrixXd(A).llt().solve(b);
    for (const std::string& name : solver_names()) {
        if (!make_solver(name)->is_direct())
            continue;
        CAPTURE(name);
        PatternRecorder solver(make_solver(name));
        CHECK_THROWS_WITH(solver.prepare(indefinite), Contains("positive definite"));
        CHECK(solver.size() == 0);
        CHECK_THROWS_WITH(solver.solve(b), Contains("before prepare"));
        solver.prepare(A);
        CHECK(relative_error(solver.solve(b), expected) <= 1e-10);
        CHECK_THROWS_AS(solver.prepare(indefinite), fem::Error);  // once more, after a success
        solver.prepare(2.0 * A);
        CHECK(relative_error(solver.solve(b), 0.5 * expected) <= 1e-10);
        CHECK(solver.same_patterns == std::vector<bool>{false, true, true, true});
    }
}

TEST_CASE("the tolerance of an iterative solver can change between solves (inexact Newton's need)", "[ex09.5]")
{
    const Eigen::SparseMatrix<double> A = fem::sparse::to_eigen(fem::direct::laplacian_2d(30));
    const Eigen::VectorXd b = random_vector(A.rows(), 8u);
    for (const char* name : {"ours-cg", "ours-pcg-jacobi", "ours-pcg-ic0", "eigen-cg"}) {
        CAPTURE(name);
        const std::unique_ptr<LinearSolver> solver = make_solver(name);
        solver->prepare(A);
        std::vector<int> iterations;
        for (const double tolerance : {1e-2, 1e-5, 1e-10}) {
            solver->set_relative_tolerance(tolerance);
            CHECK(solver->options().relative_tolerance == tolerance);
            (void)solver->solve(b);
            CHECK(solver->relative_residual() <= 1.01 * tolerance);
            iterations.push_back(solver->stats().iterations);
        }
        CHECK(iterations[0] < iterations[1]);
        CHECK(iterations[1] < iterations[2]);
        CHECK_THROWS_WITH(solver->set_relative_tolerance(1.0), Contains("(0, 1)"));
        CHECK_THROWS_AS(solver->set_relative_tolerance(std::nan("")), fem::Error);
        CHECK(solver->options().relative_tolerance == 1e-10);  // a refused value changes nothing
    }
    const std::unique_ptr<LinearSolver> direct = make_solver("ours-cholesky");
    direct->prepare(A);
    direct->set_relative_tolerance(1e-2);  // ignored: a factorization solves exactly
    CHECK(relative_error(A * direct->solve(b), b) <= 1e-12);
}
