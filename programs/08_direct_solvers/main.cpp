// ch08_direct_solvers: dense LU and Cholesky against Eigen; the Hilbert matrices (error against
// condition number); fill-reducing orderings (natural, RCM, minimum degree, nested dissection,
// Eigen's AMD, CHOLMOD's choice) on 2D/3D Laplacians and the stiffness matrix of a box; our sparse
// Cholesky (up-looking and supernodal) against Eigen's SimplicialLLT and CHOLMOD's supernodal
// factorization on the same matrices: analysis, factor and solve times, nnz(L), residual and error;
// the kernels against the hardware: the factorization's rate against the BLAS's dgemm on the
// shapes of its supernodes, our solve against CHOLMOD's, each pair timed in alternation;
// factor once / solve many; the cases where a direct solver must refuse.
//
// Sample runs:
//   ch08_direct_solvers                        full run: about 10k, 50k and 160k unknowns per family
//   ch08_direct_solvers --quick                the small run ctest checks
//   ch08_direct_solvers --max-unknowns 60000   skip the largest matrices
//
// Writes: tables dense_table.csv, hilbert_table.csv, ordering_table.csv, speed_table.csv,
// goals_table.csv, supernodes_table.csv, kernels_table.csv, solve_many_table.csv, failures_table.csv,
// threads_factor_table.csv, threads_phases_table.csv, threads_solve_table.csv;
// charts (PNG + CSV) dense_times, hilbert_errors, fill_growth, factor_times, solve_times;
// the patterns of L for four orderings (factor_patterns.vti/.png) and the box under gravity solved
// with our Cholesky (box_displacement.vtu/.png). docs/08_direct_solvers.md

#include "studies.hpp"

#include "common/cli.hpp"
#include "common/parallel.hpp"

using namespace fem;
using namespace fem::direct;

int main(int argc, char** argv)
{
    ChapterCli cli("ch08_direct_solvers", "08_direct_solvers",
                   "Chapter 08: dense LU and Cholesky, orderings, sparse Cholesky against Eigen and CHOLMOD");
    study::Settings settings;
    cli.app.add_option("--max-unknowns", settings.max_unknowns, "Skip sparse matrices with more unknowns")
        ->check(check::integer(1, 100000000))->capture_default_str();
    cli.app.add_option("--simplicial-flops", settings.simplicial_flops,
                       "Run the scalar factorizations (ours up-looking, Eigen SimplicialLLT) only below this many flops")
        ->check(check::non_negative())->capture_default_str();
    int blas_threads = 1;
    cli.app.add_option("--blas-threads", blas_threads,
                       "Threads of CHOLMOD's BLAS (1: one core against our one core)")
        ->check(check::integer(1, 256))->capture_default_str();
    return cli.run(argc, argv, [&](const RunContext& run) {
        set_blas_threads(blas_threads);
        study::dense_study(run);
        study::hilbert_study(run);
        study::ordering_study(run, settings);
        study::pattern_figure(run);
        {
            const ScopedThreadCount one_core(1);  // the speed tables compare one core with one core
            study::goals_table(run, study::speed_study(run, settings));
            study::solve_many_study(run);
        }
        study::threads_study(run);
        study::failures_study(run);
        study::box_under_gravity(run);
    });
}
