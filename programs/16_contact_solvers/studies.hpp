#pragma once
// The studies of ch16_contact_solvers, one file each (study_*.cpp), called in order by main.cpp.
// Not part of the chapter's library: only the executable uses them.

#include "16_contact_solvers/solver_runs.hpp"

#include "common/cli.hpp"

#include <vector>

namespace fem::contact::study {

/// The scenes both solvers run, in this order: the block dropped on the floor, fired at the turned
/// box at 10 and 100 m/s, the stack of three, two blocks of 3³ cells (--quick: 2³) thrown at each other, the block
/// in the bowl; without --quick the block fired at chapter 15's mesh triangle at 10 and 100 m/s; with
/// bunnies the two coarse bunnies (a run of minutes).
std::vector<SolverScene> comparison_scenes(const RunContext& run, bool bunnies);

/// A run with its Newton iterations of the steps in contact counted by kind: the first trial cut
/// by the time of impact, not cut but moving a surface vertex by more than 10⁻² δ, or Newton's tail
/// (study_trace.cpp). The free run (ContactSolver::none) counts none.
struct TracedRun {
    SolverRun run;
    int cut = 0, moving = 0, tail = 0;
};
TracedRun traced_run(const SolverScene& scene, ContactSolver solver, const AugmentedLagrangianOptions& options = {});

/// Side by side: IPC and the augmented Lagrangian on every scene, one traced run each — the
/// iterations by kind (the problem it solves), trace_table.csv; Newton iterations, linear solves,
/// time per step against the free step, the smallest distance, the largest violation, momentum —
/// side_by_side_table.csv and the Newton iterations per step as figures; the closed forms (the block
/// at rest and the stack against their weights), closed_forms_table.csv; and the augmented
/// Lagrangian's open choices measured against their alternatives, choices_table.csv
/// (study_side_by_side.cpp).
void side_by_side_study(const RunContext& run, const std::vector<SolverScene>& scenes);

}  // namespace fem::contact::study
