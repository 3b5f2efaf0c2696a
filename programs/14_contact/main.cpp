// ch14_contact: a block meets the floor — incremental potential contact (Li et al. 2020) on chapter
// 12's Newton backward Euler: the log barrier of every surface vertex against every obstacle, the
// continuous collision check that cuts each Newton step, lagged smoothed Coulomb friction. Read
// chapters 10 (the time loop) and 12 (backward Euler as minimisation, the line search) first.
// The studies, in order:
//   1. the drop: a cube falls h onto the floor; its speed at contact against √(2gh), how high it
//      rebounds, the smallest distance ever seen, Newton iterations and time per step, swept over
//      d̂, κ, Δt and the Newton tolerance; a .pvd of the drop, its height and force against time;
//   2. the slope: a cube on a slope that slides (tan θ > μ) against a = g (sin θ − μ cos θ), and one
//      that sticks (tan θ < μ), its creep per step against ε_v Δt, over the same sweep and with the
//      friction lagged once a step or updated within it; the paths and the cost against the creep's error.
// Chapter 15 (ch15_body_contact) goes on with meshes as obstacles and bodies against bodies.
//
// Sample runs:
//   ch14_contact                                   full run
//   ch14_contact --quick                           the small run ctest checks
//   ch14_contact --dhat 1e-3 --kappa 0 --dt 0.01   one configuration
//
// Writes (under out/14_contact): drop_table.csv, slope_table.csv, drop.pvd (frames drop/drop_NNNN.vtu),
// charts drop_height, drop_force, slope_slide, slope_stick, slope_cost (.csv, .png, .svg).
// docs/14_contact.md

#include "studies.hpp"

#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/parallel.hpp"

#include <algorithm>

using namespace fem;
using namespace fem::contact;

/// A fixed κ must be at least this many W/d̂ (W: the block's weight).
constexpr double smallest_barrier_hold = 1e-4;

int main(int argc, char** argv)
{
    ChapterCli cli("ch14_contact", "14_contact",
                   "Chapter 14: contact with obstacles: the IPC barrier, the collision-free line search, friction");
    study::Settings settings;
    cli.app.add_option("--dhat", settings.activation_distances,
                       "Activation distances d̂ [m] swept (from 1e-5: below, Newton stalls at the drop's 1e-7 tolerance)")
        ->check(check::real(1e-5, 0.1, check::Ends::closed))->capture_default_str();
    cli.app.add_option("--kappa", settings.stiffnesses,
                       "Barrier stiffnesses kappa [N/m] swept (0: adaptive; else at least 1e-4 W / d̂, W = the block's weight)")
        ->check(check::real(0.0, 1e9, check::Ends::closed))->capture_default_str();
    cli.app.add_option("--dt", settings.time_steps, "Time steps [s] swept")
        ->check(check::real(0.0, 0.05, check::Ends::open_closed))->capture_default_str();
    cli.app.add_option("--tolerance", settings.tolerances,
                       "Newton's relative tolerances swept (from 1e-7: below, round-off of the barrier's gradient)")
        ->check(check::real(1e-7, 0.1, check::Ends::closed))->capture_default_str();
    cli.app.add_option("--friction-updates", settings.friction_updates,
                       "Lagged friction updates per step swept on the slope (1: IPC's one lag; 0: until converged)")
        ->check(check::integer(0, 20))->capture_default_str();
    cli.app.add_option("--height", settings.drop_height, "Drop height h [m]")
        ->check(check::real(0.0, 1.0, check::Ends::open_closed))->capture_default_str();
    cli.app.add_option("--duration", settings.duration, "Length of each run [s]")
        ->check(check::real(0.0, 5.0, check::Ends::open_closed))->capture_default_str();
    cli.check_options([&] {
        // --quick runs one fixed configuration: a swept option beside it would be silently ignored.
        if (cli.app.count("--quick") > 0)
            for (const char* swept : {"--dhat", "--kappa", "--dt", "--tolerance"})
                if (cli.app.count(swept) > 0)
                    throw Error(str(swept, ": --quick runs its one fixed configuration and would ignore it; ",
                                    "leave out --quick or ", swept));
        // A fixed κ must hold the block up at a resolvable distance: a vertex carrying its share of
        // the weight W sinks to about κ d̂² / W, and where κ d̂ < 1e-4 W (κ = 1e-3 N/m at d̂ = 1e-3 m,
        // 20 N/m at 1e-5 m) Newton stalled in the sweep of --dt.
        const double weight = study::block_weight();
        const double smallest_dhat = *std::min_element(settings.activation_distances.begin(), settings.activation_distances.end());
        for (double kappa : settings.stiffnesses)
            if (kappa > 0.0 && kappa * smallest_dhat < smallest_barrier_hold * weight)
                throw Error(str("--kappa: ", kappa, " N/m with --dhat ", smallest_dhat, " m holds the block's weight W = ",
                                weight, " N too weakly: a fixed kappa must be 0 (adaptive) or at least ",
                                smallest_barrier_hold, " W / d̂ = ", smallest_barrier_hold * weight / smallest_dhat, " N/m"));
        // The sweep's work, before any of it is done: a tiny --dt would otherwise run for days.
        if (cli.app.count("--quick") == 0 && study::swept_steps(settings) > study::most_swept_steps)
            throw Error(str("--dt: the drop and slope studies would take ", study::swept_steps(settings),
                            " steps over the sweep of --dhat, --kappa, --dt, --tolerance and --friction-updates; at "
                            "most ", study::most_swept_steps, ": raise the smallest --dt, shorten --duration or "
                            "sweep fewer values"));
        for (double dt : settings.time_steps)
            try {
                dynamics::step_count(settings.duration, dt);
            } catch (const Error& e) {
                throw Error(str("--duration must be a whole number of every --dt: ", e.what()));
            }
    });
    return cli.run(argc, argv, [&](const RunContext& run) {
        if (run.quick) {
            settings.activation_distances = {1e-3};
            settings.stiffnesses = {0.0};
            settings.time_steps = {1.0 / 100.0};
            settings.tolerances = {1e-6};
            settings.duration = std::min(settings.duration, 0.3);
        }
        set_blas_threads(1);
        study::drop_study(run, settings);
        study::slope_study(run, settings);
    });
}
