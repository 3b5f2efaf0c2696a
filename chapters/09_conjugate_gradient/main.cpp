// ch09_conjugate_gradient: conjugate gradients and preconditioning, side by side with direct
// solvers on the same matrices.
//   1. convergence against conditioning: CG iterations on 2D and 3D Laplacians of growing size,
//      against κ = cot²(πh/2), the bound ½√κ ln(2√κ/τ) and the Lanczos estimate of κ;
//   2. the operator: one product y = A x through Eigen, CSR, the stored lower triangle, and the
//      matrix-free 5-point stencil;
//   3. preconditioners on the elastic box and a Laplacian: iterations, κ(M⁻¹A), setup and solve
//      times, residual histories; IC(0) breakdown and the diagonal shift;
//   4. speed against error: every iterative solver against the tolerance, and every direct one,
//      on 2D/3D Laplacians and the elastic box from ~1k to ≥150k unknowns; the crossover where
//      iterative beats direct; our PCG against Eigen's ConjugateGradient, Jacobi against its
//      diagonal preconditioner and IC(0) against its IncompleteCholesky, timed in alternation;
//   5. hard cases: indefinite and singular matrices through every solver;
//   6. pictures: the CG error on a grid after k iterations, the sagging box (VTK + PNG).
//
// Sample runs:
//   ch09_conjugate_gradient                   full run (about two minutes on two cores)
//   ch09_conjugate_gradient --quick           the small run ctest checks
//   ch09_conjugate_gradient --cells 4 8 14 --lap2 32 100 --lap3 10 22 --tolerances 1e-4 1e-8
//   ch09_conjugate_gradient --poisson 0.499 --cells 4 8 14       nearly incompressible: IC(0) breaks down
//
// Writes: tables conditioning_table.csv, exponent_table.csv, operator_table.csv,
// preconditioner_table.csv, ic0_shift_table.csv, tolerance_table.csv, crossover_table.csv,
// crossover_summary_table.csv, pcg_vs_eigen_table.csv, hard_cases_table.csv; charts (PNG + CSV)
// iterations_vs_kappa, residual_histories, work_precision_{lap2,lap3,box}, crossover_{lap2,lap3,box};
// error_snapshot_table.csv and tolerance_box_table.csv; cg_error_snapshots.vti with cg_error_{0,5,30}.png;
// box_displacement.vtu/.png.
// docs/09_conjugate_gradient.md

#include "09_conjugate_gradient/conjugate_gradient.hpp"
#include "09_conjugate_gradient/linear_operator.hpp"
#include "09_conjugate_gradient/linear_solver.hpp"
#include "09_conjugate_gradient/model_problems.hpp"
#include "09_conjugate_gradient/preconditioners.hpp"

#include "01_finite_differences/finite_differences.hpp"
#include "02_heat_equation/heat_grid.hpp"
#include "05_strain_stress/strain_stress.hpp"
#include "06_assembly/assembly.hpp"
#include "07_sparse_storage/sparse_formats.hpp"
#include "08_direct_solvers/model_problems.hpp"

#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"
#include "common/vtk_io.hpp"
#include "common/random.hpp"

#include <Eigen/IterativeLinearSolvers>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <tuple>

using namespace fem;
using namespace fem::cg;

namespace {

struct Settings {
    std::vector<int> lap2{32, 100, 224, 388};   // 2D Laplacians: n² unknowns (1k … 150k)
    std::vector<int> lap3{10, 22, 37, 54};      // 3D Laplacians: n³ unknowns (1k … 157k)
    std::vector<int> cells{4, 8, 14, 25, 37};   // elastic boxes: 3 c (c+1)² unknowns (300 … 160k)
    std::vector<double> tolerances{1e-2, 1e-4, 1e-6, 1e-8, 1e-10};
    int llt_max_3d = 12000;   // Eigen's SimplicialLLT on 3D problems up to this many unknowns
    int ours_max_3d = 60000;  // our sparse Cholesky on 3D problems up to this many (with CHOLMOD there)
    int eigen_sweep_max = 100000;  // Eigen's CG at every tolerance up to this many unknowns
    double youngs = 1e5;      // Y [Pa] of the box (rubber)
    double poisson = 0.45;    // ν of the box
    double density = 1000.0;  // ρ [kg/m³]
    double seconds = 0.3;     // measuring time per timed run (the best run counts)
};

/// The tolerance of the crossover and of the PCG-against-Eigen comparison: the interface's default.
constexpr double comparison_tolerance = default_relative_tolerance;

/// What each study solves: A x = b with A symmetric positive definite.
struct Problem {
    std::string key;    // lap2, lap3, box
    std::string label;  // for tables
    bool three_d = false;
    Eigen::SparseMatrix<double> A;
    Eigen::VectorXd b;
};

Problem make_problem(const std::string& key, int size, const Settings& settings)
{
    Problem p;
    p.key = key;
    if (key == "lap2") {
        p.label = "2D Laplacian";
        p.A = sparse::to_eigen(direct::laplacian_2d(size));
        p.b = Eigen::VectorXd::Ones(p.A.rows());  // a uniform source
    } else if (key == "lap3") {
        p.label = "3D Laplacian";
        p.three_d = true;
        p.A = sparse::to_eigen(direct::laplacian_3d(size));
        p.b = Eigen::VectorXd::Ones(p.A.rows());
    } else {
        p.label = "elastic box";
        p.three_d = true;
        const ElasticBox box = clamped_box(size, elastic::lame_parameters(settings.youngs, settings.poisson),
                                           settings.density);
        p.A = box.K;
        p.b = box.f;  // its weight
    }
    p.A.makeCompressed();
    return p;
}

std::string scientific(double value)
{
    std::ostringstream out;
    out.precision(0);
    out << std::scientific << value;
    return out.str();
}

double relative_error(const Eigen::VectorXd& x, const Eigen::VectorXd& reference)
{
    return (x - reference).norm() / reference.norm();
}

// --- our iterative methods, one place that builds them --------------------------------------------

/// Our CG variants on the stored lower triangle (the fastest product, section 2).
struct OurMethod {
    std::string name;  // CG, PCG-Jacobi, PCG-IC0
    std::unique_ptr<LinearOperator> preconditioner;
    double setup_seconds = 0.0;
};

const std::vector<std::string> our_methods{"CG", "PCG-Jacobi", "PCG-IC0"};

/// What a figure calls a solver: the tables name the direct ones by make_solver's keys
/// ("eigen-llt"), which a legend beside "ours CG" and "Eigen CG (diagonal)" should not.
std::string figure_label(const std::string& solver)
{
    static const std::map<std::string, std::string> direct{{"ours-cholesky", "ours Cholesky (direct)"},
                                                           {"eigen-llt", "Eigen LLT (direct)"},
                                                           {"cholmod", "CHOLMOD (direct)"}};
    const auto found = direct.find(solver);
    return found == direct.end() ? solver : found->second;
}

OurMethod make_method(const std::string& name, const sparse::CsrMatrix& csr)
{
    OurMethod method;
    method.name = name;
    Timer timer;
    if (name == "PCG-Jacobi")
        method.preconditioner = std::make_unique<JacobiPreconditioner>(diagonal(csr));
    else if (name == "PCG-IC0")
        method.preconditioner = std::make_unique<IncompleteCholesky>(csr);
    method.setup_seconds = timer.seconds();
    return method;
}

CgResult run_method(const LinearOperator& A, const OurMethod& method, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                    const CgSettings& settings)
{
    return method.preconditioner ? preconditioned_conjugate_gradient(A, *method.preconditioner, b, x, settings)
                                 : conjugate_gradient(A, b, x, settings);
}

// --- 1. convergence against conditioning ---------------------------------------------------------

void conditioning_study(const RunContext& run)
{
    const double tau = comparison_tolerance;
    const std::map<int, std::vector<int>> sizes =
        run.quick ? std::map<int, std::vector<int>>{{2, {16, 32, 64, 128}}, {3, {8, 16, 24}}}
                  : std::map<int, std::vector<int>>{{2, {16, 32, 64, 128, 256}}, {3, {8, 16, 32, 48}}};
    Table table(str("CG on the Laplacians, b random, tolerance ", tau,
                    ": iterations against kappa = cot^2(pi h/2) and the bound"),
                {{"dimension", Format::integer}, {"n", Format::integer}, {"unknowns", Format::integer},
                 {"kappa", Format::scientific, 3}, {"kappa (Lanczos)", Format::scientific, 3},
                 {"iterations", Format::integer}, {"bound", Format::integer},
                 {"iterations / sqrt(kappa)", Format::fixed, 3}});
    Table exponents("Fitted exponent p of iterations ~ kappa^p (theory: 1/2)",
                    {{"dimension", Format::integer}, {"fitted exponent", Format::fixed, 3}});
    fig::LineChart chart{str("CG iterations to ", tau, " against the condition number"), "kappa",
                         "iterations", true, true, {}};
    chart.legend = fig::Corner::top_left;
    for (const auto& [dimension, ns] : sizes) {
        std::vector<double> kappa, iterations, bound;
        for (int n : ns) {
            const EigenOperator A(sparse::to_eigen(dimension == 2 ? direct::laplacian_2d(n) : direct::laplacian_3d(n)));
            // A random right-hand side has every eigenvector in it (b = 1 would miss the modes that
            // are odd about the centre, and run into CG's finite termination on small grids).
            const Eigen::VectorXd b = random_vector(A.size(), 5);
            CgSettings settings;
            settings.relative_tolerance = tau;
            Eigen::VectorXd x;
            const CgResult result = conjugate_gradient(A, b, x, settings);
            const double k = laplacian_condition_number(n);
            const int limit = iteration_bound(k, tau / std::sqrt(k));
            kappa.push_back(k);
            iterations.push_back(result.iterations);
            bound.push_back(limit);
            table.add_row({double(dimension), double(n), double(A.size()), k,
                           lanczos_extreme_eigenvalues(result).condition(), double(result.iterations),
                           double(limit), result.iterations / std::sqrt(k)});
        }
        exponents.add_row({double(dimension), fd::fitted_order(kappa, iterations)});
        chart.series.push_back({str(dimension, "D Laplacian, CG"), kappa, iterations});
        if (dimension == 2)
            chart.series.push_back({"bound 1/2 sqrt(kappa) ln(2 sqrt(kappa)/tau)", kappa, bound});
    }
    table.print(std::cout);
    table.write_csv(run.file("conditioning_table.csv"));
    exponents.print(std::cout);
    exponents.write_csv(run.file("exponent_table.csv"));
    fig::save_chart(chart, run.out_dir / "iterations_vs_kappa", run.figures);
}

// --- 2. the operator -----------------------------------------------------------------------------

void operator_study(const RunContext& run, const Settings& settings)
{
    Table table("One product y = A x through each operator (the best of repeated calls)",
                {{"problem", Format::text}, {"unknowns", Format::integer}, {"operator", Format::text},
                 {"stored entries", Format::integer}, {"time per product [s]", Format::scientific, 3},
                 {"max difference to Eigen", Format::scientific, 1}});
    const int n2 = run.quick ? 64 : 224;    // 50 176 unknowns
    const int cells = run.quick ? 6 : 25;   // 50 700 unknowns
    for (const Problem& p : {make_problem("lap2", n2, settings), make_problem("box", cells, settings)}) {
        const sparse::CsrMatrix csr = sparse::csr_from_eigen(p.A);
        std::vector<std::pair<std::string, std::unique_ptr<LinearOperator>>> operators;
        operators.emplace_back("Eigen SparseMatrix", std::make_unique<EigenOperator>(p.A));
        operators.emplace_back("CSR, both triangles (ch07 gather)", std::make_unique<CsrOperator>(csr));
        operators.emplace_back("CSR, lower triangle (ch07 symmetric)", std::make_unique<SymmetricCsrOperator>(csr));
        if (p.key == "lap2") {
            heat::Grid grid;
            grid.n = n2;
            operators.emplace_back("matrix-free 5-point stencil (ch02)",
                                   std::make_unique<FunctionOperator>(stencil_operator(grid)));
        }
        const Eigen::VectorXd x = random_vector(p.A.rows(), 1);
        Eigen::VectorXd reference;
        operators.front().second->apply(x, reference);
        for (const auto& [name, op] : operators) {
            Eigen::VectorXd y;
            const double seconds = best_time([&] { op->apply(x, y); }, settings.seconds);
            const double entries = name.find("lower") != std::string::npos
                                       ? double(sparse::lower_triangle(csr).nonzeros())
                                       : (name.find("matrix-free") != std::string::npos ? 0.0 : double(csr.nonzeros()));
            table.add_row({p.label, double(p.A.rows()), name, entries, seconds,
                           (y - reference).cwiseAbs().maxCoeff() / reference.cwiseAbs().maxCoeff()});
        }
    }
    table.print(std::cout);
    table.write_csv(run.file("operator_table.csv"));
}

// --- 3. preconditioners ------------------------------------------------------------------------------

void preconditioner_study(const RunContext& run, const Settings& settings)
{
    const double tau = comparison_tolerance;
    const int cells = run.quick ? 6 : 14;
    const int n2 = run.quick ? 32 : 100;
    Table table(str("CG and PCG to ", tau, ": iterations, kappa(M^-1 A) from the Lanczos coefficients, times"),
                {{"problem", Format::text}, {"unknowns", Format::integer}, {"method", Format::text},
                 {"iterations", Format::integer}, {"kappa (Lanczos)", Format::scientific, 3},
                 {"IC(0) shift", Format::text}, {"setup time [s]", Format::scientific, 2},
                 {"solve time [s]", Format::scientific, 2}});
    fig::LineChart histories{str("Residual histories on the elastic box (", cells, " cells a side)"), "iteration",
                             "relative residual |r_k| / |b|", false, true, {}};
    histories.legend = fig::Corner::top_right;
    for (const Problem& p : {make_problem("box", cells, settings), make_problem("lap2", n2, settings)}) {
        const sparse::CsrMatrix csr = sparse::csr_from_eigen(p.A);
        const SymmetricCsrOperator A(csr);
        for (const std::string& name : our_methods) {
            const OurMethod method = make_method(name, csr);
            CgSettings cg_settings;
            cg_settings.relative_tolerance = tau;
            Eigen::VectorXd x;
            CgResult result;
            const double seconds = best_time(
                [&] {
                    x.resize(0);
                    result = run_method(A, method, p.b, x, cg_settings);
                },
                settings.seconds, 20);
            const auto* ic = dynamic_cast<const IncompleteCholesky*>(method.preconditioner.get());
            table.add_row({p.label, double(p.A.rows()), name, double(result.iterations),
                           lanczos_extreme_eigenvalues(result).condition(),
                           ic ? (ic->shift() > 0.0 ? str(ic->shift()) : std::string("none needed")) : std::string("-"),
                           method.setup_seconds, seconds});
            if (p.key == "box") {
                std::vector<double> k(result.residual_history.size());
                for (std::size_t i = 0; i < k.size(); ++i)
                    k[i] = double(i);
                histories.series.push_back({name, k, result.residual_history});
            }
        }
        Eigen::ConjugateGradient<Eigen::SparseMatrix<double>> eigen_cg;
        eigen_cg.setTolerance(tau);
        Eigen::VectorXd x;
        const double seconds = best_time(
            [&] {
                eigen_cg.compute(p.A);
                x = eigen_cg.solve(p.b);
            },
            settings.seconds, 20);
        table.add_row({p.label, double(p.A.rows()), std::string("Eigen CG (diagonal)"),
                       double(eigen_cg.iterations()), std::string("-"), std::string("-"), 0.0, seconds});
    }
    table.print(std::cout);
    table.write_csv(run.file("preconditioner_table.csv"));
    fig::save_chart(histories, run.out_dir / "residual_histories", run.figures);
}

/// Kershaw's matrix and boxes of rising Poisson ratio: when IC(0) breaks down, and the shift.
void ic0_shift_study(const RunContext& run, const Settings& settings)
{
    Table table("IC(0): breakdown without a shift, and the shift alpha in A + alpha diag(A) that works",
                {{"matrix", Format::text}, {"unknowns", Format::integer}, {"breakdown without shift", Format::text},
                 {"shift used", Format::text}, {"factorizations", Format::integer},
                 {"PCG iterations", Format::integer}});
    std::vector<std::pair<std::string, Eigen::SparseMatrix<double>>> matrices;
    Eigen::MatrixXd kershaw(4, 4);
    kershaw << 3, -2, 0, 2, -2, 3, -2, 0, 0, -2, 3, -2, 2, 0, -2, 3;
    matrices.emplace_back("Kershaw's 4x4 matrix", kershaw.sparseView());
    const int cells = run.quick ? 4 : 10;
    for (double nu : {0.3, 0.45, 0.49, 0.499})
        matrices.emplace_back(str("elastic box, ", cells, " cells, nu = ", nu),
                              clamped_box(cells, elastic::lame_parameters(settings.youngs, nu), settings.density).K);
    matrices.emplace_back("2D Laplacian (an M-matrix)", sparse::to_eigen(direct::laplacian_2d(run.quick ? 16 : 64)));
    for (const auto& [name, K] : matrices) {
        const sparse::CsrMatrix csr = sparse::csr_from_eigen(K);
        const IcAttempt plain = incomplete_cholesky_factor(sparse::lower_triangle(csr), 0.0);
        const IncompleteCholesky ic(csr);
        Eigen::VectorXd x;
        const Eigen::VectorXd b = Eigen::VectorXd::Ones(K.rows());
        const CgResult result = preconditioned_conjugate_gradient(SymmetricCsrOperator(csr), ic, b, x);
        table.add_row({name, double(K.rows()),
                       plain.breakdown_row < 0 ? std::string("no")
                                               : str("row ", plain.breakdown_row, ", pivot ", plain.pivot),
                       ic.shift() > 0.0 ? str(ic.shift()) : std::string("0"), double(ic.attempts()),
                       double(result.iterations)});
    }
    table.print(std::cout);
    table.write_csv(run.file("ic0_shift_table.csv"));
}

// --- 4. speed against error ------------------------------------------------------------------------

struct Measurement {
    std::string problem;  // label
    int unknowns = 0;
    std::string solver;
    bool direct = false;
    double tolerance = 0.0;  // 0 for a direct solver
    int iterations = 0;
    double residual = 0.0;   // true relative residual
    double error = 0.0;      // against the reference solution
    double setup = 0.0;      // seconds: factorization or preconditioner
    double seconds = 0.0;    // seconds to the answer, setup included
    bool reached = true;     // false: the iteration cap came first (the row holds the last iterate)
};

std::string reached_text(const Measurement& row)
{
    return row.reached ? "yes" : "no: the cap";
}

/// Our method on p, watched at every tolerance: the first iterate whose updated residual meets τ gives
/// the row for τ (iterations, time since the start plus the setup, error, true residual). The
/// observer's own work (an error and a residual at each crossing) is timed and taken out. The best
/// of repeated runs counts. A tolerance not reached within the cap (2n) gives a row with the last
/// iterate and reached = false.
std::vector<Measurement> sweep_ours(const Problem& p, const sparse::CsrMatrix& csr, const std::string& name,
                                    const Eigen::VectorXd& reference, std::vector<double> tolerances,
                                    const Settings& settings)
{
    std::sort(tolerances.begin(), tolerances.end(), std::greater<>());
    const SymmetricCsrOperator A(csr);
    std::vector<Measurement> rows(tolerances.size());
    double best_setup = 1e300;
    Timer budget;
    for (int repeat = 0; repeat < 20; ++repeat) {
        const OurMethod method = make_method(name, csr);
        best_setup = std::min(best_setup, method.setup_seconds);
        std::size_t next = 0;
        double observer_seconds = 0.0;
        Timer timer;
        CgSettings cg_settings;
        cg_settings.relative_tolerance = tolerances.back();
        cg_settings.observer = [&](int k, const Eigen::VectorXd& x, double relative_residual) {
            if (next >= tolerances.size() || relative_residual > tolerances[next])
                return;
            const double elapsed = timer.seconds() - observer_seconds;
            Timer own;
            Eigen::VectorXd Ax;
            A.apply(x, Ax);
            const double residual = (p.b - Ax).norm() / p.b.norm();
            const double error = relative_error(x, reference);
            for (; next < tolerances.size() && relative_residual <= tolerances[next]; ++next) {
                Measurement& row = rows[next];
                const double seconds = elapsed + method.setup_seconds;
                if (repeat == 0 || seconds < row.seconds)
                    row.seconds = seconds;
                row.tolerance = tolerances[next];
                row.iterations = k;
                row.residual = residual;
                row.error = error;
            }
            observer_seconds += own.seconds();
        };
        Eigen::VectorXd x;
        const CgResult result = run_method(A, method, p.b, x, cg_settings);
        const double total = timer.seconds() - observer_seconds + method.setup_seconds;
        for (std::size_t missed = next; missed < tolerances.size(); ++missed) {
            Measurement& row = rows[missed];
            row.tolerance = tolerances[missed];
            row.iterations = result.iterations;
            row.residual = result.relative_residual;
            row.error = relative_error(x, reference);
            if (repeat == 0 || total < row.seconds)
                row.seconds = total;
            row.reached = false;
        }
        if (!result.converged)
            break;  // the cap: no need to repeat a run that long
        if (budget.seconds() >= settings.seconds)
            break;
    }
    for (Measurement& row : rows) {
        row.problem = p.label;
        row.unknowns = static_cast<int>(p.A.rows());
        row.solver = "ours " + name;
        row.setup = best_setup;
    }
    return rows;
}

/// The peer of each of our preconditioners in Eigen: its ConjugateGradient with the diagonal
/// preconditioner (reading the lower triangle, its default), or with its IncompleteCholesky
/// (reading both triangles: Lower|Upper, the fast product).
enum class EigenPreconditioner { diagonal, incomplete_cholesky };

/// Eigen's ConjugateGradient with `preconditioner` (its defaults otherwise) to the tolerance tau,
/// once: the time of compute() and solve(), and what it reached.
Measurement run_eigen_cg(const Problem& p, const Eigen::VectorXd& reference, double tau,
                         EigenPreconditioner preconditioner = EigenPreconditioner::diagonal)
{
    Measurement row;
    Eigen::VectorXd x;
    const auto solve = [&](auto& cg) {
        cg.setTolerance(tau);
        Timer timer;
        cg.compute(p.A);
        row.setup = timer.seconds();
        x = cg.solve(p.b);
        row.seconds = timer.seconds();
        row.reached = cg.info() == Eigen::Success;
        row.iterations = static_cast<int>(cg.iterations());
    };
    if (preconditioner == EigenPreconditioner::diagonal) {
        Eigen::ConjugateGradient<Eigen::SparseMatrix<double>> cg;
        solve(cg);
        row.solver = "Eigen CG (diagonal)";
    } else {
        Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                                 Eigen::IncompleteCholesky<double>>
            cg;
        solve(cg);
        row.solver = "Eigen CG (IncompleteCholesky)";
    }
    row.problem = p.label;
    row.unknowns = static_cast<int>(p.A.rows());
    row.tolerance = tau;
    row.residual = (p.b - p.A * x).norm() / p.b.norm();
    row.error = relative_error(x, reference);
    return row;
}

/// Eigen's CG once per tolerance, each the best of repeated runs.
std::vector<Measurement> sweep_eigen(const Problem& p, const Eigen::VectorXd& reference,
                                     const std::vector<double>& tolerances, const Settings& settings)
{
    std::vector<Measurement> rows;
    for (double tau : tolerances) {
        Measurement best;
        Timer budget;
        for (int repeat = 0; repeat < 20; ++repeat) {
            const Measurement row = run_eigen_cg(p, reference, tau);
            if (repeat == 0 || row.seconds < best.seconds)
                best = row;
            if (budget.seconds() >= settings.seconds)
                break;
        }
        rows.push_back(best);
    }
    return rows;
}

/// The performance goal, measured fairly on a shared machine: our PCG with `ours` ("PCG-Jacobi" or
/// "PCG-IC0", on the stored lower triangle, the preconditioner built inside the timing) and Eigen's
/// CG with its peer preconditioner at the comparison tolerance, run in alternation so that both
/// meet the same load, each the best of its runs.
std::pair<Measurement, Measurement> race_against_eigen(const Problem& p, const sparse::CsrMatrix& csr,
                                                       const Eigen::VectorXd& reference, const Settings& settings,
                                                       const std::string& ours_name, EigenPreconditioner peer)
{
    const SymmetricCsrOperator A(csr);
    Measurement ours, eigen;
    Timer budget;
    for (int repeat = 0; repeat < 20; ++repeat) {
        Timer timer;
        const OurMethod method = make_method(ours_name, csr);
        CgSettings cg_settings;
        cg_settings.relative_tolerance = comparison_tolerance;
        Eigen::VectorXd x;
        const CgResult result = run_method(A, method, p.b, x, cg_settings);
        const double seconds = timer.seconds();
        if (repeat == 0 || seconds < ours.seconds) {
            ours.seconds = seconds;
            ours.setup = method.setup_seconds;
            ours.iterations = result.iterations;
            ours.reached = result.converged;
        }
        const Measurement row = run_eigen_cg(p, reference, comparison_tolerance, peer);
        if (repeat == 0 || row.seconds < eigen.seconds)
            eigen = row;
        if (budget.seconds() >= settings.seconds)
            break;
    }
    return {ours, eigen};
}

/// A direct solver of the interface: prepare and solve, best of repeated runs.
Measurement measure_direct(const Problem& p, const std::string& name, const Eigen::VectorXd* reference,
                           Eigen::VectorXd& x, const Settings& settings)
{
    const std::unique_ptr<LinearSolver> solver = make_solver(name);
    Measurement row;
    row.problem = p.label;
    row.unknowns = static_cast<int>(p.A.rows());
    row.solver = name;
    row.direct = true;
    double best_setup = 1e300, best_solve = 1e300;
    Timer budget;
    for (int repeat = 0; repeat < 10; ++repeat) {
        solver->prepare(p.A);
        x = solver->solve(p.b);
        best_setup = std::min(best_setup, solver->stats().prepare_seconds);
        best_solve = std::min(best_solve, solver->stats().solve_seconds);
        if (budget.seconds() >= settings.seconds)
            break;
    }
    row.setup = best_setup;
    row.seconds = best_setup + best_solve;
    row.residual = solver->relative_residual();
    row.error = reference ? relative_error(x, *reference) : 0.0;
    return row;
}

void speed_against_error_study(const RunContext& run, const Settings& settings)
{
    std::vector<double> tolerances = settings.tolerances;
    if (std::find(tolerances.begin(), tolerances.end(), comparison_tolerance) == tolerances.end())
        tolerances.push_back(comparison_tolerance);
    std::sort(tolerances.begin(), tolerances.end(), std::greater<>());

    const std::vector<std::pair<std::string, std::vector<int>>> problems =
        run.quick ? std::vector<std::pair<std::string, std::vector<int>>>{{"lap2", {16, 32}}, {"lap3", {6, 10}},
                                                                         {"box", {3, 5}}}
                  : std::vector<std::pair<std::string, std::vector<int>>>{
                        {"lap2", settings.lap2}, {"lap3", settings.lap3}, {"box", settings.cells}};
    std::vector<std::string> direct_solvers{"ours-cholesky", "eigen-llt"};
    if (cholmod_available())
        direct_solvers.push_back("cholmod");

    Table tolerance_table("Iterative solvers against the tolerance: iterations, residual, error against the "
                          "direct solution, time (setup included)",
                          {{"problem", Format::text}, {"unknowns", Format::integer}, {"solver", Format::text},
                           {"tolerance", Format::scientific, 0}, {"iterations", Format::integer},
                           {"relative residual", Format::scientific, 2}, {"relative error", Format::scientific, 2},
                           {"time [s]", Format::scientific, 2}, {"reached", Format::text}});
    // The same rows for the elastic box of about 50 000 unknowns alone (the one the docs quote).
    Table box_tolerance_table = tolerance_table;
    Table crossover(str("Direct against iterative (tolerance ", comparison_tolerance,
                        "): the time of one solve from scratch"),
                    {{"problem", Format::text}, {"unknowns", Format::integer}, {"solver", Format::text},
                     {"iterations", Format::integer}, {"relative residual", Format::scientific, 2},
                     {"relative error", Format::scientific, 2}, {"setup time [s]", Format::scientific, 2},
                     {"total time [s]", Format::scientific, 2}, {"reached", Format::text}});
    Table summary("The crossover: the fastest direct and iterative solve, and how many right-hand sides pay for a "
                  "factorization",
                  {{"problem", Format::text}, {"unknowns", Format::integer},
                   {"fastest direct [measured]", Format::text}, {"direct time [s]", Format::scientific, 2},
                   {"fastest iterative [measured]", Format::text}, {"iterative time [s]", Format::scientific, 2},
                   {"iterative / direct [measured]", Format::fixed, 2},
                   {"solves to amortise [measured]", Format::fixed, 1}});
    Table versus(str("Our PCG against Eigen's ConjugateGradient with the peer preconditioner, tolerance ",
                     comparison_tolerance, ", timed in alternation (preconditioner setup included)"),
                 {{"problem", Format::text}, {"unknowns", Format::integer},
                  {"preconditioner (ours / Eigen)", Format::text}, {"ours iterations", Format::integer},
                  {"Eigen iterations", Format::integer}, {"ours setup [s]", Format::scientific, 2},
                  {"Eigen setup [s]", Format::scientific, 2}, {"ours time [s]", Format::scientific, 2},
                  {"Eigen time [s]", Format::scientific, 2}, {"ours / Eigen [measured]", Format::fixed, 2}});

    for (const auto& [key, sizes] : problems) {
        fig::LineChart work{"", "time to the answer [s]", "relative error against the direct solution", true, true, {}};
        work.legend = fig::Corner::top_right;
        fig::LineChart times{"", "unknowns", str("one solve, iterative ones to ", comparison_tolerance, ": time [s]"),
                             true, true, {}};
        times.legend = fig::Corner::top_left;
        std::map<std::string, fig::Series> crossover_series;
        for (int size : sizes) {
            const Problem p = make_problem(key, size, settings);
            std::cout << "\n" << p.label << " with " << p.A.rows() << " unknowns, " << p.A.nonZeros()
                      << " stored entries" << std::endl;
            times.title = str("Direct against iterative: ", p.label);

            // The reference: our sparse Cholesky (deterministic, single-threaded); on 3D problems
            // beyond ours_max_3d CHOLMOD's, when this build has it (4 to 10 times faster there).
            const bool ours_direct = !(p.three_d && p.A.rows() > settings.ours_max_3d && cholmod_available());
            Eigen::VectorXd reference;
            std::vector<Measurement> direct_rows;
            direct_rows.push_back(
                measure_direct(p, ours_direct ? "ours-cholesky" : "cholmod", nullptr, reference, settings));
            const std::string reference_solver = direct_rows.back().solver;
            for (const std::string& name : direct_solvers) {
                if (name == reference_solver || (name == "ours-cholesky" && !ours_direct) ||
                    (name == "eigen-llt" && p.three_d && p.A.rows() > settings.llt_max_3d))
                    continue;
                Eigen::VectorXd x;
                direct_rows.push_back(measure_direct(p, name, &reference, x, settings));
            }

            std::vector<Measurement> iterative_rows;
            const sparse::CsrMatrix csr = sparse::csr_from_eigen(p.A);
            for (const std::string& name : our_methods) {
                const std::vector<Measurement> rows = sweep_ours(p, csr, name, reference, tolerances, settings);
                iterative_rows.insert(iterative_rows.end(), rows.begin(), rows.end());
            }
            // Eigen's CG: at the comparison tolerance in the race with our PCG (Jacobi); at the other
            // tolerances on problems up to eigen_sweep_max unknowns.
            const auto [ours_race, eigen_race] = race_against_eigen(p, csr, reference, settings, "PCG-Jacobi",
                                                                    EigenPreconditioner::diagonal);
            const auto [ours_ic, eigen_ic] = race_against_eigen(p, csr, reference, settings, "PCG-IC0",
                                                                EigenPreconditioner::incomplete_cholesky);
            const bool eigen_sweep = p.A.rows() <= settings.eigen_sweep_max;
            std::vector<double> other_tolerances;
            if (eigen_sweep)
                for (double tau : tolerances)
                    if (tau != comparison_tolerance)
                        other_tolerances.push_back(tau);
            std::vector<Measurement> eigen_rows = sweep_eigen(p, reference, other_tolerances, settings);
            eigen_rows.push_back(eigen_race);
            std::sort(eigen_rows.begin(), eigen_rows.end(),
                      [](const Measurement& a, const Measurement& b) { return a.tolerance > b.tolerance; });
            iterative_rows.insert(iterative_rows.end(), eigen_rows.begin(), eigen_rows.end());

            for (const Measurement& row : iterative_rows) {
                const std::vector<Cell> cells{row.problem,  double(row.unknowns), row.solver,
                                              row.tolerance, double(row.iterations), row.residual,
                                              row.error,    row.seconds,          reached_text(row)};
                tolerance_table.add_row(cells);
                if (key == "box" && size == (run.quick ? sizes.back() : 25))
                    box_tolerance_table.add_row(cells);
            }

            // Crossover rows: every direct solver, every iterative one at the comparison tolerance.
            const Measurement* best_direct = nullptr;
            const Measurement* best_iterative = nullptr;
            std::vector<const Measurement*> at_tolerance;
            for (const Measurement& row : direct_rows) {
                at_tolerance.push_back(&row);
                if (!best_direct || row.seconds < best_direct->seconds)
                    best_direct = &row;
            }
            for (const Measurement& row : iterative_rows) {
                if (row.tolerance != comparison_tolerance)
                    continue;
                at_tolerance.push_back(&row);
                if (row.reached && (!best_iterative || row.seconds < best_iterative->seconds))
                    best_iterative = &row;
            }
            for (const Measurement* row : at_tolerance) {
                crossover.add_row({row->problem, double(row->unknowns), row->solver, double(row->iterations),
                                   row->residual, row->solver == reference_solver ? Cell(std::string("reference"))
                                                                                 : Cell(row->error),
                                   row->setup, row->seconds, reached_text(*row)});
                fig::Series& series = crossover_series[row->solver];
                series.name = figure_label(row->solver);
                series.x.push_back(row->unknowns);
                series.y.push_back(row->seconds);
            }
            if (best_iterative) {
                const double direct_solve = best_direct->seconds - best_direct->setup;
                const double gain = best_iterative->seconds - direct_solve;
                summary.add_row({p.label, double(p.A.rows()), best_direct->solver, best_direct->seconds,
                                 best_iterative->solver, best_iterative->seconds,
                                 best_iterative->seconds / best_direct->seconds,
                                 gain > 0.0 ? best_direct->setup / gain : 0.0});
            } else {
                summary.add_row({p.label, double(p.A.rows()), best_direct->solver, best_direct->seconds,
                                 std::string("none reached the tolerance"), 0.0, 0.0, 0.0});
            }
            const auto add_race = [&](const std::string& pair, const Measurement& ours, const Measurement& eigen) {
                versus.add_row({p.label, double(p.A.rows()), pair, double(ours.iterations), double(eigen.iterations),
                                ours.setup, eigen.setup, ours.seconds, eigen.seconds,
                                ours.reached && eigen.reached ? Cell(ours.seconds / eigen.seconds)
                                                              : Cell(std::string("cap hit"))});
            };
            add_race("Jacobi / diagonal", ours_race, eigen_race);
            add_race("IC(0) / IncompleteCholesky", ours_ic, eigen_ic);

            // The work-precision chart: the largest size with Eigen's whole sweep.
            if (eigen_sweep) {
                work.title = str("Speed against error: ", p.label, ", ", p.A.rows(), " unknowns");
                work.series.clear();
                std::map<std::string, fig::Series> curves;
                for (const Measurement& row : iterative_rows) {
                    fig::Series& series = curves[row.solver];
                    series.name = row.solver;
                    series.x.push_back(row.seconds);
                    series.y.push_back(std::max(row.error, 1e-17));
                }
                for (const Measurement& row : direct_rows)
                    if (row.solver != reference_solver)  // the reference itself has no error to show
                        curves[row.solver] = {figure_label(row.solver), {row.seconds}, {std::max(row.error, 1e-17)},
                                              true};
                for (auto& [name, series] : curves)
                    work.series.push_back(series);
            }
        }
        for (auto& [name, series] : crossover_series)
            times.series.push_back(series);
        fig::save_chart(work, run.out_dir / ("work_precision_" + key), run.figures);
        fig::save_chart(times, run.out_dir / ("crossover_" + key), run.figures);
    }
    tolerance_table.print(std::cout);
    tolerance_table.write_csv(run.file("tolerance_table.csv"));
    box_tolerance_table.write_csv(run.file("tolerance_box_table.csv"));
    crossover.print(std::cout);
    crossover.write_csv(run.file("crossover_table.csv"));
    summary.print(std::cout);
    summary.write_csv(run.file("crossover_summary_table.csv"));
    versus.print(std::cout);
    versus.write_csv(run.file("pcg_vs_eigen_table.csv"));
}

// --- 5. hard cases -----------------------------------------------------------------------------------

/// The message of an fem::Error up to its second ": " or first "; " (what failed and where, without
/// the advice that follows).
std::string short_message(const std::string& message)
{
    const auto first = message.find(": ");
    const auto second = first == std::string::npos ? first : message.find(": ", first + 2);
    return message.substr(0, std::min(second, message.find("; ")));
}

void hard_cases_study(const RunContext& run, const Settings& settings)
{
    const int cells = 3;
    const elastic::Lame material = elastic::lame_parameters(settings.youngs, settings.poisson);
    const ElasticBox box = clamped_box(cells, material, settings.density);
    // Indefinite: K − σ I with σ = 10 λ_min, between the smallest eigenvalues (estimated by CG).
    Eigen::VectorXd probe;
    const CgResult estimate = conjugate_gradient(EigenOperator(box.K), box.f, probe);
    const double sigma = 10.0 * lanczos_extreme_eigenvalues(estimate).lambda_min;
    Eigen::SparseMatrix<double> identity(box.K.rows(), box.K.rows());
    identity.setIdentity();
    const Eigen::SparseMatrix<double> shifted = box.K - sigma * identity;
    // Singular: K of the free box (nothing pinned): six rigid motions, and a load with a net force.
    const Eigen::SparseMatrix<double> free_K = assembly::stiffness_matrix(box.mesh, material);
    const Eigen::VectorXd free_f = assembly::gravity_load(box.mesh, settings.density);

    Table table("Hard cases: what every solver says about a matrix that is not positive definite",
                {{"matrix", Format::text}, {"solver", Format::text}, {"outcome", Format::text}});
    const std::vector<std::tuple<std::string, const Eigen::SparseMatrix<double>*, const Eigen::VectorXd*>> cases{
        {str("K - sigma I, indefinite (", cells, " cells)"), &shifted, &box.f},
        {str("K without pinned vertices, singular (", cells, " cells)"), &free_K, &free_f}};
    for (const auto& [name, A, b] : cases) {
        for (const std::string& solver_name : solver_names()) {
            const std::unique_ptr<LinearSolver> solver = make_solver(solver_name);
            std::string outcome;
            try {
                solver->prepare(*A);
                const Eigen::VectorXd x = solver->solve(*b);
                outcome = str("no error: relative residual ", scientific(solver->relative_residual()),
                              ", |x| = ", scientific(x.norm()));
            } catch (const Error& e) {
                std::cout << solver_name << " on " << name << ": " << e.what() << '\n';
                outcome = "fem::Error: " + short_message(e.what());
            }
            table.add_row({name, solver_name, outcome});
        }
    }
    table.print(std::cout);
    table.write_csv(run.file("hard_cases_table.csv"));
}

// --- 6. pictures -------------------------------------------------------------------------------------

/// CG smooths the error: start from the solution plus noise, and look at the error after k steps.
void error_snapshots(const RunContext& run)
{
    heat::Grid grid;
    grid.n = run.quick ? 31 : 63;
    const int n = grid.n;
    const EigenOperator A(sparse::to_eigen(direct::laplacian_2d(n)));
    const Eigen::VectorXd solution = heat::sample(grid, [](double x, double y) { return x * (1 - x) * y * y * (1 - y); });
    Eigen::VectorXd b;
    A.apply(solution, b);
    Eigen::VectorXd start = solution + 0.02 * random_vector(solution.size(), 2);  // CG overwrites it
    const std::vector<int> snapshots{0, 5, 30};
    std::vector<Eigen::VectorXd> errors;
    CgSettings settings;
    settings.max_iterations = snapshots.back();
    settings.observer = [&](int k, const Eigen::VectorXd& x, double) {
        if (std::find(snapshots.begin(), snapshots.end(), k) != snapshots.end())
            errors.push_back(x - solution);
    };
    conjugate_gradient(A, b, start, settings);

    // One grid with a field per snapshot (the interior unknowns; ParaView shows them side by side),
    // and a picture of each, scaled to its largest error.
    io::ImageGrid image;
    image.dims = {n, n, 1};
    image.spacing = {grid.h(), grid.h(), 1.0};
    image.origin = {grid.h(), grid.h(), 0.0};
    Table table("CG error e_k = x_k - x* on the 2D grid: it is smoothed long before it is small",
                {{"iteration k", Format::integer}, {"max |e_k|", Format::scientific, 3},
                 {"max |e_k| / max |e_0|", Format::scientific, 3}});
    for (std::size_t s = 0; s < errors.size(); ++s) {
        const double largest = errors[s].cwiseAbs().maxCoeff();
        table.add_row({double(snapshots[s]), largest, largest / errors[0].cwiseAbs().maxCoeff()});
        image.point_data.push_back({str("error after ", snapshots[s], " iterations"), errors[s]});
    }
    io::write_vti(run.file("cg_error_snapshots.vti"), image);
    table.print(std::cout);
    table.write_csv(run.file("error_snapshot_table.csv"));
    for (std::size_t s = 0; s < errors.size(); ++s) {
        io::ImageGrid scaled = image;
        scaled.point_data = {{"scaled error", errors[s] / errors[s].cwiseAbs().maxCoeff()}};
        fig::RenderOptions options;
        options.title = str("CG error after ", snapshots[s], " iterations, e_k / max |e_k|");
        options.field = "scaled error";
        options.range = std::pair{-1.0, 1.0};
        options.width = 620;
        options.height = 520;
        fig::render_grid_png(run.file(str("cg_error_", snapshots[s], ".png")), scaled, options);
    }
}

/// The box sagging under its weight, solved by the default solver.
void box_picture(const RunContext& run, const Settings& settings)
{
    const int cells = run.quick ? 6 : 14;
    const ElasticBox box = clamped_box(cells, elastic::lame_parameters(settings.youngs, settings.poisson),
                                       settings.density);
    const std::unique_ptr<LinearSolver> solver = make_solver("default");
    solver->prepare(box.K);
    const Eigen::VectorXd u = assembly::expand(box.P, solver->solve(box.f));
    const MatrixX3d displacement = io::vertex_rows(u);
    const io::MeshData data = io::displaced_mesh(box.mesh.V, box.mesh.T, displacement);
    io::write_vtu(run.file("box_displacement.vtu"), data);
    fig::RenderOptions options;
    options.title =
        str("clamped box sagging under its weight (true scale, ", figure_label(solver->name()), "): |u| [m]");
    options.field = "displacement";
    options.unit = "m";
    options.view_direction = {0.5, 1.0, -0.6};
    options.view_up = {0.0, 0.0, 1.0};
    options.height = 560;
    fig::render_mesh_png(run.file("box_displacement.png"), io::warped(data), options);
    std::cout << "\nbox_displacement.vtu: " << box.mesh.T.rows() << " tets, " << box.K.rows()
              << " unknowns solved by " << solver->name() << " in " << solver->stats().prepare_seconds +
                                                                       solver->stats().solve_seconds
              << " s; largest |u| = " << displacement.rowwise().norm().maxCoeff() << " m\n";
}

}  // namespace

int main(int argc, char** argv)
{
    ChapterCli cli("ch09_conjugate_gradient", "09_conjugate_gradient",
                   "Chapter 09: conjugate gradients, preconditioning, and iterative against direct solvers");
    Settings settings;
    cli.app.add_option("--lap2", settings.lap2, "2D Laplacian sizes n (n^2 unknowns) of the speed study")
        ->check(check::integer(2, 2000))->capture_default_str();
    cli.app.add_option("--lap3", settings.lap3, "3D Laplacian sizes n (n^3 unknowns) of the speed study")
        ->check(check::integer(2, 120))->capture_default_str();
    cli.app.add_option("--cells", settings.cells, "Elastic boxes: cubes a side (3 c (c+1)^2 unknowns)")
        ->check(check::integer(1, 60))->capture_default_str();
    cli.app.add_option("--tolerances", settings.tolerances, "Relative residual tolerances of the speed study")
        ->check(check::real(0.0, 1.0, check::Ends::open))->capture_default_str();
    cli.app.add_option("--llt-max-3d", settings.llt_max_3d,
                       "Largest 3D problem (unknowns) given to Eigen's SimplicialLLT (0: none)")
        ->check(check::at_least(0))->capture_default_str();
    cli.app.add_option("--ours-max-3d", settings.ours_max_3d,
                       "Largest 3D problem (unknowns) given to our sparse Cholesky when CHOLMOD is there (0: none)")
        ->check(check::at_least(0))->capture_default_str();
    cli.app.add_option("--eigen-sweep-max", settings.eigen_sweep_max,
                       "Largest problem (unknowns) on which Eigen's CG runs every tolerance (0: none)")
        ->check(check::at_least(0))->capture_default_str();
    cli.app.add_option("--youngs", settings.youngs, "Young's modulus of the box [Pa]")->check(check::positive())
        ->capture_default_str();
    cli.app.add_option("--poisson", settings.poisson, "Poisson's ratio of the box")
        ->check(check::real(-1.0, 0.5, check::Ends::open))->capture_default_str();
    cli.app.add_option("--seconds", settings.seconds, "Measuring time per timed run [s]")
        ->check(check::real(0.0, 60.0, check::Ends::open_closed))->capture_default_str();
    int blas_threads = 1;
    cli.app.add_option("--blas-threads", blas_threads,
                       "Threads of CHOLMOD's BLAS (1: one core against our one core)")
        ->check(check::integer(1, 256))->capture_default_str();
    return cli.run(argc, argv, [&](const RunContext& run) {
        // One core against one core by default: CHOLMOD's BLAS would otherwise use every core.
        const bool limited = set_blas_threads(blas_threads);
        std::cout << "CHOLMOD: " << (cholmod_available() ? "available" : "not in this build")
                  << (!limited ? std::string()
                      : blas_threads == 1 ? std::string(", its BLAS on one thread")
                                          : str(", its BLAS on ", blas_threads, " threads"))
                  << "; default solver: " << default_solver_name()
                  << "\n\n";
        conditioning_study(run);
        operator_study(run, settings);
        preconditioner_study(run, settings);
        ic0_shift_study(run, settings);
        speed_against_error_study(run, settings);
        hard_cases_study(run, settings);
        error_snapshots(run);
        box_picture(run, settings);
    });
}
