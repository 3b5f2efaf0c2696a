// ch08_direct_solvers: 2. the Hilbert matrices: error against condition number.
// docs/08_direct_solvers.md
#include "studies.hpp"

#include "08_direct_solvers/dense_solvers.hpp"

#include "common/figures.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <Eigen/Dense>

#include <iomanip>
#include <iostream>

namespace fem::direct::study {

void hilbert_study(const RunContext& run)
{
    Table table("Hilbert matrices: x = (1, ..., 1), b = H x summed in long double; max-norm error of x",
                {{"n", Format::integer}, {"kappa_1 (exact)", Format::scientific, 2},
                 {"kappa_1 (Eigen estimate)", Format::scientific, 2}, {"kappa eps", Format::scientific, 2},
                 {"LU error", Format::text}, {"LU error / (kappa eps)", Format::text},
                 {"Cholesky error", Format::text}, {"Eigen PartialPivLU error", Format::scientific, 2}});
    std::vector<double> kappas, lu_errors, llt_errors, eigen_errors, bound;
    const auto cell = [](double value) { return str(std::scientific, std::setprecision(3), value); };
    for (int n = 2; n <= 14; ++n) {
        const Eigen::MatrixXd H = hilbert_matrix(n);
        const Eigen::VectorXd b = hilbert_row_sums(n);
        const double kappa = hilbert_condition_number(n);
        const Eigen::PartialPivLU<Eigen::MatrixXd> eigen_lu(H);
        const double eigen_error = (eigen_lu.solve(b).array() - 1.0).abs().maxCoeff();
        std::string lu_text, ratio_text, llt_text;
        try {
            const double error = (lu_solve(lu_factor(H), b).array() - 1.0).abs().maxCoeff();
            lu_text = cell(error);
            ratio_text = cell(error / (kappa * eps));
            kappas.push_back(kappa);
            lu_errors.push_back(error);
            eigen_errors.push_back(eigen_error);
            bound.push_back(n * kappa * eps);
        } catch (const Error& e) {
            lu_text = "singular (LU refuses)";
            ratio_text = "-";
        }
        try {
            const double error = (cholesky_solve(cholesky_factor(H), b).array() - 1.0).abs().maxCoeff();
            llt_text = cell(error);
            if (static_cast<int>(llt_errors.size()) < static_cast<int>(kappas.size()))
                llt_errors.push_back(error);
        } catch (const Error& e) {
            llt_text = "not SPD in double";
        }
        table.add_row({double(n), kappa, 1.0 / eigen_lu.rcond(), kappa * eps, lu_text, ratio_text, llt_text, eigen_error});
    }
    table.print(std::cout);
    table.write_csv(run.file("hilbert_table.csv"));
    std::vector<double> llt_kappas(kappas.begin(), kappas.begin() + static_cast<std::ptrdiff_t>(llt_errors.size()));
    fig::LineChart chart{"Hilbert matrices n = 2..13: error of x against the condition number", "kappa_1(H_n)",
                         "max-norm error of x", true, true,
                         {{"ours: LU", kappas, lu_errors},
                          {"ours: Cholesky", llt_kappas, llt_errors},
                          {"Eigen PartialPivLU", kappas, eigen_errors},
                          {"bound n kappa eps", kappas, bound}}};
    chart.legend = fig::Corner::top_left;
    fig::save_chart(chart, run.out_dir / "hilbert_errors", run.figures);
}

}  // namespace fem::direct::study
