// ch09_conjugate_gradient: 4. speed against error: every iterative solver against the tolerance and every
// direct one; the crossover; our PCG against Eigen's CG, timed in alternation.
// docs/09_conjugate_gradient.md
#include "studies.hpp"

#include "common/figures.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <Eigen/IterativeLinearSolvers>

#include <algorithm>
#include <functional>
#include <iostream>
#include <map>

namespace fem::cg::study {
namespace {

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

}  // namespace

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

}  // namespace fem::cg::study
