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

#include "studies.hpp"

#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/parallel.hpp"

#include <iostream>
#include <string>

using namespace fem;
using namespace fem::cg;

int main(int argc, char** argv)
{
    ChapterCli cli("ch09_conjugate_gradient", "09_conjugate_gradient",
                   "Chapter 09: conjugate gradients, preconditioning, and iterative against direct solvers");
    study::Settings settings;
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
        study::conditioning_study(run);
        study::operator_study(run, settings);
        study::preconditioner_study(run, settings);
        study::ic0_shift_study(run, settings);
        study::speed_against_error_study(run, settings);
        study::hard_cases_study(run, settings);
        study::error_snapshots(run);
        study::box_picture(run, settings);
    });
}
