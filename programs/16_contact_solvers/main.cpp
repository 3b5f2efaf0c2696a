// ch16_contact_solvers: IPC's Newton beside a barrier-free augmented Lagrangian (after Zheng, Luo and
// Li 2026) — the same scenes with both contact solvers, in one run. Read chapter 14 (the barrier,
// the CCD-bounded line search) and 15 (distances, CCD, bodies against bodies) first.
// One study, side by side, one run of each solver per scene: the problem it solves (the Newton
// iterations of every step in contact counted by kind: cut by the time of impact, moving the
// surface, Newton's tail), IPC's beside the augmented Lagrangian's inner iterations; Newton
// iterations per step in contact and per run, linear solves, time per step against the free step,
// smallest distance, largest violation of d ≥ δ, momentum; the block at rest and the stack against
// their weights; the augmented Lagrangian's open choices against their alternatives.
//
// Sample runs:
//   ch16_contact_solvers            full run (the stack over 100 steps; about a minute)
//   ch16_contact_solvers --quick    the small run ctest checks
//   ch16_contact_solvers --bunnies  also the two coarse bunnies of chapter 15 (minutes)
//
// Writes (under out/16_contact_solvers): trace_table.csv, side_by_side_table.csv,
// closed_forms_table.csv, choices_table.csv, newton_per_step_*.csv and their PNGs.
// docs/16_contact_solvers.md

#include "studies.hpp"

#include "common/cli.hpp"
#include "common/parallel.hpp"

using namespace fem;
using namespace fem::contact;

int main(int argc, char** argv)
{
    ChapterCli cli("ch16_contact_solvers", "16_contact_solvers",
                   "Chapter 16: contact solvers: IPC's Newton beside a barrier-free augmented Lagrangian, on the same scenes");
    bool bunnies = false;
    cli.app.add_flag("--bunnies", bunnies, "Also run the two coarse bunnies of chapter 15 with both solvers (minutes)");
    return cli.run(argc, argv, [&](const RunContext& run) {
        // One thread: the meshes are small (tens to thousands of tets), where OpenMP's threads cost
        // more than they save, and the times compared must not depend on another process's load.
        set_thread_count(1);
        set_blas_threads(1);
        study::side_by_side_study(run, study::comparison_scenes(run, bunnies));
    });
}
