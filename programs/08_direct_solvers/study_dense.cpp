// ch08_direct_solvers: 1. dense LU and Cholesky against Eigen on random matrices.
// docs/08_direct_solvers.md
#include "studies.hpp"

#include "08_direct_solvers/dense_solvers.hpp"

#include "common/figures.hpp"
#include "common/random.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <Eigen/Dense>

#include <cmath>
#include <iostream>
#include <map>

namespace fem::direct::study {

void dense_study(const RunContext& run)
{
    const std::vector<int> sizes = run.quick ? std::vector<int>{50, 100} : std::vector<int>{100, 200, 400, 800};
    Table table("Dense direct solvers on random well-conditioned matrices (LU: non-symmetric, Cholesky: SPD)",
                {{"solver", Format::text}, {"n", Format::integer}, {"flops", Format::scientific, 2},
                 {"factor time [s]", Format::scientific, 2}, {"solve time [s]", Format::scientific, 2},
                 {"rate [GFLOP/s]", Format::fixed, 2}, {"residual", Format::scientific, 2}});
    std::map<std::string, std::vector<double>> times;
    std::vector<double> ns;
    for (int n : sizes) {
        ns.push_back(n);
        const Eigen::MatrixXd A = random_matrix(n, n, 1 + n) + 2.0 * std::sqrt(double(n)) * Eigen::MatrixXd::Identity(n, n);
        const Eigen::MatrixXd B = random_matrix(n, n, 2 + n);
        const Eigen::MatrixXd S = B * B.transpose() / n + Eigen::MatrixXd::Identity(n, n);
        const Eigen::VectorXd b = random_vector(n, 3 + n);
        const double lu_flops = 2.0 / 3.0 * n * double(n) * n, llt_flops = lu_flops / 2.0;
        const auto add = [&](const std::string& name, double flops, double factor, double solve,
                             const Eigen::MatrixXd& M, const Eigen::VectorXd& x) {
            table.add_row({name, double(n), flops, factor, solve, flops / factor * 1e-9, (M * x - b).norm() / b.norm()});
            times[name].push_back(factor);
        };
        {
            LuFactorization F;
            Eigen::VectorXd x;
            const double factor = timed([&] { F = lu_factor(A); });
            const double solve = timed([&] { x = lu_solve(F, b); });
            add("ours: LU", lu_flops, factor, solve, A, x);
        }
        {
            Eigen::PartialPivLU<Eigen::MatrixXd> F;
            Eigen::VectorXd x;
            const double factor = timed([&] { F.compute(A); });
            const double solve = timed([&] { x = F.solve(b); });
            add("Eigen PartialPivLU", lu_flops, factor, solve, A, x);
        }
        {
            Eigen::MatrixXd L;
            Eigen::VectorXd x;
            const double factor = timed([&] { L = cholesky_factor(S); });
            const double solve = timed([&] { x = cholesky_solve(L, b); });
            add("ours: Cholesky", llt_flops, factor, solve, S, x);
        }
        {
            Eigen::LLT<Eigen::MatrixXd> F;
            Eigen::VectorXd x;
            const double factor = timed([&] { F.compute(S); });
            const double solve = timed([&] { x = F.solve(b); });
            add("Eigen LLT", llt_flops, factor, solve, S, x);
        }
    }
    table.print(std::cout);
    table.write_csv(run.file("dense_table.csv"));
    fig::LineChart chart{"Dense factorizations: time against n (O(n^3))", "n", "factor time [s]", true, true, {}};
    for (const auto& [name, t] : times)
        chart.series.push_back({name, ns, t});
    chart.legend = fig::Corner::top_left;
    fig::save_chart(chart, run.out_dir / "dense_times", run.figures);
}

}  // namespace fem::direct::study
