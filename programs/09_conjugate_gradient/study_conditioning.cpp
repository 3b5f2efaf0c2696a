// ch09_conjugate_gradient: 1. convergence against conditioning: CG iterations on Laplacians of growing
// size against κ, the bound ½√κ ln(2√κ/τ) and the Lanczos estimate of κ.
// docs/09_conjugate_gradient.md
#include "studies.hpp"

#include "01_finite_differences/finite_differences.hpp"
#include "08_direct_solvers/model_problems.hpp"

#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/random.hpp"
#include "common/table.hpp"

#include <cmath>
#include <iostream>
#include <map>

namespace fem::cg::study {

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

}  // namespace fem::cg::study
