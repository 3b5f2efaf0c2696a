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
//      friction lagged once a step or updated within it; the paths and the cost against the creep's error;
//   3. mesh obstacles: the distance to a triangle mesh (the bowl, the bunny) by every triangle, by
//      chapter 13's AABB tree and by sampled grids — time per query and error against the first;
//      a block dropped into the bowl, its frames;
//   4. primitive CCD: point–triangle and edge–edge continuous collision detection, the naive
//      coplanarity cubic against the conservative inclusion method, on the CCD benchmark's queries
//      (data/ccd-unit-tests; --ccd-queries FILE... runs only this study, on those files);
//   5. bodies against bodies: the broad phase of self-contact (which surface pairs two blocks can
//      bring within d̂ over a step) by every pair, chapter 13's AABB tree and a spatial hash, timed
//      against the number of surface primitives;
//   6. bodies against bodies, the cost: two coarse bunnies thrown at each other with self-contact,
//      beside the same two without contact — per step the linear solves, the barrier with its broad
//      phase and the collision check, momentum and the intersection check; Newton's tolerance
//      loosened to 10⁻³, its iterations against the end state's offset;
//   7. a stack at rest (three blocks, self-contact) against its closed form — the force between
//      blocks against the weight above, the gaps against d̂ — swept over d̂ and Newton's tolerance.
//
// Sample runs:
//   ch14_contact                                   full run
//   ch14_contact --quick                           the small run ctest checks
//   ch14_contact --dhat 1e-3 --kappa 0 --dt 0.01   one configuration
//   ch14_contact --ccd-queries data/ccd-unit-tests/edge-edge/data_0_0.csv   CCD on one query file
//
// Writes (under out/14_contact): drop_table.csv, slope_table.csv, mesh_table.csv, bowl_table.csv,
// ccd_queries_table.csv, self_broad_phase_table.csv, two_bunnies_table.csv,
// two_bunnies_tolerance_table.csv, stack_tolerance_table.csv, drop.pvd and bowl.pvd (frames drop/drop_NNNN.vtu, …), charts drop_height,
// drop_force, slope_slide, slope_stick, slope_cost (.csv, .png, .svg) and the bowl's frames bowl_NNNN.png.
// docs/14_contact.md

#include "studies.hpp"
#include "study_ccd.hpp"

#include "09_conjugate_gradient/linear_solver.hpp"

#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/parallel.hpp"

#include <algorithm>

using namespace fem;
using namespace fem::contact;

int main(int argc, char** argv)
{
    ChapterCli cli("ch14_contact", "14_contact",
                   "Chapter 14: contact with obstacles: the IPC barrier, the collision-free line search, friction");
    study::Settings settings;
    cli.app.add_option("--dhat", settings.activation_distances, "Activation distances d̂ [m] swept")
        ->check(check::real(0.0, 0.1, check::Ends::open_closed))->capture_default_str();
    cli.app.add_option("--kappa", settings.stiffnesses, "Barrier stiffnesses kappa [N/m] swept (0: adaptive)")
        ->check(check::real(0.0, 1e9, check::Ends::closed))->capture_default_str();
    cli.app.add_option("--dt", settings.time_steps, "Time steps [s] swept")
        ->check(check::real(0.0, 0.05, check::Ends::open_closed))->capture_default_str();
    cli.app.add_option("--tolerance", settings.tolerances, "Newton's relative tolerances swept")
        ->check(check::real(0.0, 0.1, check::Ends::open_closed))->capture_default_str();
    cli.app.add_option("--friction-updates", settings.friction_updates,
                       "Lagged friction updates per step swept on the slope (1: IPC's one lag; 0: until converged)")
        ->check(check::integer(0, 20))->capture_default_str();
    cli.app.add_option("--height", settings.drop_height, "Drop height h [m]")
        ->check(check::real(0.0, 1.0, check::Ends::open_closed))->capture_default_str();
    cli.app.add_option("--duration", settings.duration, "Length of each run [s]")
        ->check(check::real(0.0, 5.0, check::Ends::open_closed))->capture_default_str();
    bool hessian_variants = false;
    cli.app.add_flag("--hessian-variants", hessian_variants,
                     "Also run the two bunnies with the barrier's Hessian, kappa and Newton's stopping test changed (eight more runs, minutes): "
                     "two_bunnies_hessian_table.csv");
    std::vector<std::string> ccd_files;
    cli.app.add_option("--ccd-queries", ccd_files,
                       "CCD benchmark query files, each in a folder vertex-face or edge-edge: run only the CCD study")
        ->check(check::accepted_by(study::check_ccd_query_file));
    cli.check_options([&] {
        if (!ccd_files.empty()) {  // runs the CCD study alone: another study's option would be ignored
            for (const char* other : {"--dhat", "--kappa", "--dt", "--tolerance", "--friction-updates", "--height",
                                      "--duration", "--hessian-variants"})
                if (cli.app.count(other) > 0)
                    throw Error(str(other, ": --ccd-queries runs only the CCD study and would ignore it"));
            cli.protect_inputs({ccd_files.begin(), ccd_files.end()});
        }
        // --quick runs one fixed configuration: a swept option beside it would be silently ignored.
        if (cli.app.count("--quick") > 0)
            for (const char* swept : {"--dhat", "--kappa", "--dt", "--tolerance"})
                if (cli.app.count(swept) > 0)
                    throw Error(str(swept, ": --quick runs its one fixed configuration and would ignore it; ",
                                    "leave out --quick or ", swept));
        // The sweep's work, before any of it is done: a tiny --dt would otherwise run for days.
        if (ccd_files.empty() && cli.app.count("--quick") == 0 && study::swept_steps(settings) > study::most_swept_steps)
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
        if (!ccd_files.empty()) {
            study::ccd_study(run, ccd_files);
            return;
        }
        if (run.quick) {
            settings.activation_distances = {1e-3};
            settings.stiffnesses = {0.0};
            settings.time_steps = {1.0 / 100.0};
            settings.tolerances = {1e-6};
            settings.duration = std::min(settings.duration, 0.3);
            settings.mesh_queries = 2000;
            settings.grid_spacings = {0.01};
        }
        set_blas_threads(1);
        study::drop_study(run, settings);
        study::slope_study(run, settings);
        study::mesh_study(run, settings);
        study::ccd_study(run, study::ccd_benchmark_files());
        study::self_contact_study(run);
        study::bodies_study(run, hessian_variants);
        study::stack_study(run);
    });
}
