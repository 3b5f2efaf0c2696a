// ch12_hyperelastic_newton: hyperelastic energy densities ψ(F) — St. Venant–Kirchhoff, neo-Hookean,
// stable neo-Hookean — with their stresses P = ∂ψ/∂F and derivatives ∂P/∂F, and backward Euler
// written as a minimisation, E(v) = ½(v − q̇ᵗ)ᵀM(v − q̇ᵗ) + U(qᵗ + Δt v) − Δt vᵀ f_ext, solved by
// Newton's method with a line search. Read chapters 04 (F, B), 06 (the pattern), 09 (make_solver),
// 10 (the scene and the loop) and 11 (the corotational model it is compared with) first. Studies:
//   1. materials: derivatives by finite differences; the uniaxial stress–stretch curves;
//   2. Newton: quadratic convergence, the Hessian choice, the line search, the tolerance;
//   3. the swing: every model on chapter 11's soft cantilever against a fine reference;
//   4. cost: a Newton iteration's parts up to 36k dofs; a 10 000-vertex step against Vega.
//
// Sample runs:
//   ch12_hyperelastic_newton                 full run
//   ch12_hyperelastic_newton --quick         the small run ctest checks
//
// Writes (under out/12_hyperelastic_newton): the tables *_table.csv; the charts (PNG + CSV)
// uniaxial, newton_history, swing_pareto; swing.pvd with PNG frames swing_NNNN.png.
// docs/12_hyperelastic_newton.md

#include "studies.hpp"

#include "09_conjugate_gradient/linear_solver.hpp"

#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/parallel.hpp"

#include <algorithm>

using namespace fem;
using namespace fem::hyper;

int main(int argc, char** argv)
{
    ChapterCli cli("ch12_hyperelastic_newton", "12_hyperelastic_newton",
                   "Chapter 12: hyperelastic materials and backward Euler by Newton's method with a line search");
    study::Settings settings;
    cli.app.add_option("--cost-cells", settings.cost_cells, "Cells along the beams of the cost study")
        ->check(check::integer(10, 200))->capture_default_str();
    cli.app.add_option("--seconds", settings.seconds, "Measuring time per timed kernel [s]")
        ->check(check::real(0.0, 60.0, check::Ends::open_closed))->capture_default_str();
    return cli.run(argc, argv, [&](const RunContext& run) {
        if (run.quick) {
            settings.cost_cells = {10, 20};
            settings.seconds = std::min(settings.seconds, 0.02);
        }
        set_blas_threads(1);
        study::materials_study(run, settings);
        study::newton_study(run, settings);
        study::swing_study(run, settings);
        study::cost_study(run, settings);
    });
}
