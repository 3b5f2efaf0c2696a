// ch10_linear_dynamics: a pinned elastic body in motion, M ü + D u̇ + K u = f_ext, stepped by
// backward Euler (the lecture's "best practice"), the implicit midpoint rule and symplectic Euler,
// each checked against the body's own modes. Read chapters 06 (M, D, f, P) and 09 (make_solver)
// first. The studies, in order (one file each, study_*.cpp):
//   1. modes: the lowest modes of the cantilever by a dense eigensolver and by shift-invert Lanczos,
//      the first bending frequency against Euler–Bernoulli under refinement (linear tets lock),
//      ω_max by Lanczos and by power iteration, and the explicit stability limit;
//   2. one mode, one oscillator: the body started in mode 1 follows the 2×2 modal recurrence of
//      each integrator; backward Euler's amplitude factor and phase per step, measured;
//   3. speed against error: every integrator at many Δt against the exact modal solution (tip
//      error at t = 1 s, energy drift, wall time), the tip trajectories and the energies;
//   4. statics: a damped beam settles to K⁻¹ f; how many steps at which Δt;
//   5. hard cases: explicit Euler just above and below its limit, backward Euler far above it, a
//      very stiff body at Δt = 1/30 s, free fall, the two forms of the step;
//   6. cost: time per simulated second on beams up to 36k dofs: factor once, refactor every step,
//      warm-started PCG, explicit at its limit; the prefactored step against its floor; SOFA's beam;
//   7. scenes: the beam swinging and the coarse TetGen bunny pushed sideways, as .pvd time series
//      and PNG frames.
//
// Sample runs:
//   ch10_linear_dynamics                       full run (about a minute on two cores)
//   ch10_linear_dynamics --quick               the small run ctest checks
//   ch10_linear_dynamics --youngs 1e5 --duration 2 --cost-cells 20 40
//
// Writes (under out/10_linear_dynamics): the tables *_table.csv; the charts (PNG + CSV)
// tip_trajectories, energies, pareto, beam_frequency; beam.pvd and bunny.pvd (frames with
// displacement, velocity, von Mises stress) with PNG frames beam_NNNN.png, bunny_NNNN.png.
// docs/10_linear_dynamics.md

#include "studies.hpp"

#include "09_conjugate_gradient/linear_solver.hpp"

#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/parallel.hpp"

#include <iostream>

using namespace fem;
using namespace fem::dynamics;

int main(int argc, char** argv)
{
    ChapterCli cli("ch10_linear_dynamics", "10_linear_dynamics",
                   "Chapter 10: implicit time stepping of a pinned elastic body, checked against its modes");
    study::Settings settings;
    cli.app.add_option("--youngs", settings.beam.youngs_modulus, "Young's modulus Y of the beam [Pa]")
        ->check(check::real(lowest_youngs_modulus, highest_youngs_modulus, check::Ends::closed))->capture_default_str();
    cli.app.add_option("--poisson", settings.beam.poisson_ratio, "Poisson's ratio of the beam, at most 0.499999995 "
                       "(lambda/mu <= 1e8: nearer 0.5 the stiffness leaves a double no digits; towards it, and for a "
                       "large --youngs or a small --density, the accuracy study's symplectic Euler needs ever more "
                       "steps: at most 2000000 are run)")
        ->check(check::real(-1.0, highest_poisson_ratio, check::Ends::open_closed))->capture_default_str();
    cli.app.add_option("--density", settings.beam.density, "Density of the beam [kg/m^3]")
        ->check(check::real(lowest_density, highest_density, check::Ends::closed))->capture_default_str();
    cli.app.add_option("--duration", settings.duration, "Accuracy horizon and demo length [s]")
        ->check(check::real(0.0, 10.0, check::Ends::open_closed))->capture_default_str();
    cli.app.add_option("--accuracy-cells", settings.accuracy_cells,
                       "Cells along the beam of the accuracy study (the reference is dense)")
        ->check(check::integer(2, 40))->capture_default_str();
    cli.app.add_option("--cost-cells", settings.cost_cells, "Cells along the beams of the cost study")
        ->check(check::integer(10, 200))->capture_default_str();
    cli.app.add_option("--seconds", settings.seconds, "Measuring time per timed kernel [s]")
        ->check(check::real(0.0, 60.0, check::Ends::open_closed))->capture_default_str();
    // The beam's scene as a whole (its mass, its stiffness, its time step) is checked once more, and
    // the steps its explicit limit asks of symplectic Euler are counted (they explode as ν → 0.5).
    cli.check_options([&] {
        validate(cantilever_scene(settings.beam, 2));
        study::explicit_steps(settings);
    });
    return cli.run(argc, argv, [&](const RunContext& run) {
        if (run.quick) {
            settings.accuracy_cells = std::min(settings.accuracy_cells, 10);
            settings.cost_cells = {10, 20};
            settings.seconds = std::min(settings.seconds, 0.02);
        }
        set_blas_threads(1);
        std::cout << "Solver of the implicit steps: " << cg::default_solver_name() << "\n\n";
        study::modes_study(run, settings);
        study::recurrence_study(run, settings);
        study::accuracy_study(run, settings);
        study::statics_study(run, settings);
        study::hard_cases_study(run, settings);
        study::cost_study(run, settings);
        study::demo_scenes(run, settings);
    });
}
