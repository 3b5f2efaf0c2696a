// ch09_conjugate_gradient: 2. the operator: one product y = A x through Eigen, CSR, the stored lower
// triangle and the matrix-free 5-point stencil.
// docs/09_conjugate_gradient.md
#include "studies.hpp"

#include "02_heat_equation/heat_grid.hpp"

#include "common/random.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <iostream>
#include <memory>
#include <utility>

namespace fem::cg::study {

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
            const double seconds = best_time([&, &op = op] { op->apply(x, y); }, settings.seconds);
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

}  // namespace fem::cg::study
