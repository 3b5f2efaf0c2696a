// ch11_corotational: linear elasticity grows a body that merely rotates; the corotational element
// takes each tet's rotation out first, applies the linear element in the rotated frame and rotates
// the forces back:  f_e = −R_e K_e (R_eᵀ x_e − X_e),  K_R = Σ_e R̂_e K_e R̂_eᵀ (warped stiffness).
// Chapter 10's scene, integrators and time loop do the rest. Read chapters 04 (F), 06 (K_e, the
// pattern), 09 (make_solver) and 10 (ThetaMethod, Simulation) first. The studies, in order:
//   1. rotations: the slide's U Vᵀ against R = V Uᵀ; the lecture's edge fit, the centroid fit and
//      the polar decomposition of F on single tets and on every tet of the TetGen bunny;
//   2. a large swing: a soft cantilever released from the horizontal, linear against corotational
//      (volume, tip against a Δt/16 reference, time per step), the θ-step with the warped stiffness
//      (the midpoint rule diverges), .pvd time series and PNG frames of both models side by side;
//   3. cost: the parts of a step on beams up to 36k dofs, four solvers of the changing step matrix,
//      SOFA's corotational beam.
//
// Sample runs:
//   ch11_corotational                       full run (about a minute on two cores)
//   ch11_corotational --quick               the small run ctest checks
//   ch11_corotational --youngs 1e5 --duration 2 --cost-cells 20 40
//
// Writes (under out/11_corotational): the tables *_table.csv; the charts (PNG + CSV) swing_pareto
// and swing_tips; swing.pvd (frames with displacement, velocity, von Mises stress and the model of
// each half) with PNG frames swing_NNNN.png. docs/11_corotational.md

#include "studies.hpp"

#include "09_conjugate_gradient/linear_solver.hpp"

#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/parallel.hpp"

#include <algorithm>

using namespace fem;
using namespace fem::corot;

int main(int argc, char** argv)
{
    ChapterCli cli("ch11_corotational", "11_corotational",
                   "Chapter 11: corotational elements: best-fit rotations, warped stiffness, a step matrix that changes");
    study::Settings settings;
    cli.app.add_option("--youngs", settings.soft.youngs_modulus, "Young's modulus Y of the swinging beam [Pa]")
        ->check(check::real(dynamics::lowest_youngs_modulus, dynamics::highest_youngs_modulus, check::Ends::closed))
        ->capture_default_str();
    cli.app.add_option("--duration", settings.duration, "Length of the swing [s] (a multiple of 1/30)")
        ->check(check::real(0.0, 10.0, check::Ends::open_closed))->capture_default_str();
    cli.app.add_option("--swing-cells", settings.swing_cells, "Cells along the swinging beam")
        ->check(check::integer(2, 60))->capture_default_str();
    cli.app.add_option("--cost-cells", settings.cost_cells, "Cells along the beams of the cost study")
        ->check(check::integer(10, 200))->capture_default_str();
    cli.app.add_option("--seconds", settings.seconds, "Measuring time per timed kernel [s]")
        ->check(check::real(0.0, 60.0, check::Ends::open_closed))->capture_default_str();
    // The swing runs at steps of 1/30 s and finer: its length must be a whole number of them.
    cli.check_options([&] {
        try {
            dynamics::step_count(settings.duration, 1.0 / 30.0);
        } catch (const Error& e) {
            throw Error(str("--duration must be a multiple of 1/30 s, the swing's largest step: ", e.what()));
        }
    });
    return cli.run(argc, argv, [&](const RunContext& run) {
        if (run.quick) {
            settings.cost_cells = {10, 20};
            settings.seconds = std::min(settings.seconds, 0.02);
        }
        set_blas_threads(1);
        study::rotation_study(run, settings);
        study::swing_study(run, settings);
        study::cost_study(run, settings);
    });
}
