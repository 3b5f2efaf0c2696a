// ch08_direct_solvers: 5. factor once, solve many.
// docs/08_direct_solvers.md
#include "studies.hpp"

#include "common/random.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <algorithm>
#include <iomanip>
#include <iostream>

namespace fem::direct::study {

void solve_many_study(const RunContext& run)
{
    const int cells = run.quick ? 5 : 20;
    const int steps = 100, block = 20;
    const sparse::CscMatrix K = box_stiffness(cells, rubber);
    const Eigen::MatrixXd B = random_matrix(K.rows, steps, 11);
    Timer timer;
    SparseCholesky chol(K);
    const double construct = timer.seconds();
    const double analyse = chol.times().ordering + chol.times().symbolic, numeric = chol.times().numeric;
    Eigen::MatrixXd X(K.rows, steps);
    const double one_at_a_time = timed([&] {
        for (int c = 0; c < steps; ++c)
            X.col(c) = chol.solve(Eigen::VectorXd(B.col(c)));
    });
    Eigen::MatrixXd Y(K.rows, steps);
    const double blocked = timed([&] {
        for (int c = 0; c < steps; c += block)
            Y.middleCols(c, block) = chol.solve_many(B.middleCols(c, block));
    });
    double worst = 0.0;
    for (int c = 0; c < steps; ++c)
        worst = std::max(worst, symmetric_residual(K, Y.col(c), B.col(c)));
    Table table(str("Factor once, solve many: ", steps, " right-hand sides, 3D elasticity, ", cells, "^3 cubes, ",
                    K.rows, " unknowns (largest residual ", std::scientific, std::setprecision(2), worst, ")"),
                {{"work", Format::text}, {"right-hand sides", Format::integer}, {"time [s]", Format::scientific, 3},
                 {"per right-hand side [s]", Format::scientific, 3}});
    const Cell none = std::string("-");
    table.add_row({std::string("analyse: ordering + symbolic (once)"), none, analyse, none});
    table.add_row({std::string("numeric factorization (once)"), none, numeric, none});
    table.add_row({std::string("solve, one right-hand side at a time"), double(steps), one_at_a_time, one_at_a_time / steps});
    table.add_row({str("solve_many, ", block, " right-hand sides at a time"), double(steps), blocked, blocked / steps});
    table.add_row({std::string("factor once + solve each"), double(steps), construct + one_at_a_time,
                   (construct + one_at_a_time) / steps});
    table.add_row({std::string("factor every step (from one factorization's time)"), double(steps),
                   steps * (construct + one_at_a_time / steps), construct + one_at_a_time / steps});
    table.print(std::cout);
    table.write_csv(run.file("solve_many_table.csv"));
}

}  // namespace fem::direct::study
