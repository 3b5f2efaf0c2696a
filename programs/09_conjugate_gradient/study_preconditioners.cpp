// ch09_conjugate_gradient: 3. preconditioners on the elastic box and a Laplacian: iterations, κ(M⁻¹A),
// setup and solve times, residual histories; IC(0) breakdown and the diagonal shift.
// docs/09_conjugate_gradient.md
#include "studies.hpp"

#include "08_direct_solvers/model_problems.hpp"

#include "common/figures.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <Eigen/IterativeLinearSolvers>

#include <iostream>

namespace fem::cg::study {

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

}  // namespace fem::cg::study
