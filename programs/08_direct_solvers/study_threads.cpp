// ch08_direct_solvers: 5b. the supernodal factorization and solve on 1 and 2 threads.
// docs/08_direct_solvers.md
#include "studies.hpp"

#include "common/parallel.hpp"
#include "common/random.hpp"
#include "common/table.hpp"
#include "common/threads_study.hpp"
#include "common/timer.hpp"

#include <iostream>

namespace fem::direct::study {

/// The supernodal factorization and a solve on 1 and 2 threads (threads_table: quiet and beside a
/// busy core, the bits compared), on the stiffness matrix of a box of 25³ cubes (50,700 unknowns;
/// quick: 5³). docs/08_direct_solvers.md#threads
void threads_study(const RunContext& run)
{
    const int cells = run.quick ? 5 : 25;
    const double seconds = run.quick ? 0.2 : 3.0;
    const sparse::CscMatrix K = box_stiffness(cells, rubber);
    const Eigen::VectorXd b = random_vector(K.rows, 12);
    SparseCholesky chol(K);
    const Table factor = threads_table(
        str("Supernodal numeric factorization (+ one solve, whose x is compared) on 1 and 2 threads, 3D elasticity, ",
            cells, "^3 cubes, ", K.rows, " unknowns"),
        [&] {
            chol.factorize(K);
            return chol.solve(b);
        },
        seconds);
    factor.print(std::cout);
    factor.write_csv(run.file("threads_factor_table.csv"));

    // Where the two threads gain: the factorization's phases (CholeskyTimes), medians of the calls
    // made in `seconds` on each count.
    Table phases(str("The factorization's two phases on 1 and 2 threads (medians), same matrix: the subtrees side by "
                     "side, then the top supernodes one after another"),
                 {{"threads", Format::integer},
                  {"factorization [s]", Format::scientific, 3},
                  {"subtrees [s]", Format::scientific, 3},
                  {"top supernodes [s]", Format::scientific, 3},
                  {"subtrees: speed-up [measured]", Format::fixed, 2},
                  {"top: speed-up [measured]", Format::fixed, 2},
                  {"top: share of the time [measured]", Format::fixed, 2}});
    double one_thread_subtrees = 0.0, one_thread_top = 0.0;
    for (const int threads : {1, 2}) {
        const ScopedThreadCount scope(threads);
        std::vector<double> numeric, subtrees, top;
        const Timer measuring;
        while (numeric.size() < 3 || measuring.seconds() < seconds) {
            chol.factorize(K);
            numeric.push_back(chol.times().numeric);
            subtrees.push_back(chol.times().numeric_subtrees);
            top.push_back(chol.times().numeric_top);
        }
        const double subtree_time = median(subtrees), top_time = median(top), numeric_time = median(numeric);
        if (threads == 1) {
            one_thread_subtrees = subtree_time;
            one_thread_top = top_time;
        }
        phases.add_row({double(threads), numeric_time, subtree_time, top_time, one_thread_subtrees / subtree_time,
                        one_thread_top / top_time, top_time / numeric_time});
    }
    phases.print(std::cout);
    phases.write_csv(run.file("threads_phases_table.csv"));
    const Table solve = threads_table(
        str("Supernodal solve (forward and back substitution, one right-hand side) on 1 and 2 threads, same matrix"),
        [&] { return chol.solve(b); }, seconds);
    solve.print(std::cout);
    solve.write_csv(run.file("threads_solve_table.csv"));
}

}  // namespace fem::direct::study
