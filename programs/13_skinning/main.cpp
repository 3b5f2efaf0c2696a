// ch13_skinning: a fine render surface carried by a coarse tet mesh. Each surface vertex is located
// in a coarse tet once, at rest; its barycentric weights φ = T⁻¹(X − X₀) (notes 001) fill one row of
// the sparse W (#V_skin × #V_sim, four weights a row), and every frame the skin is one sparse
// product, x_surface = W Q, with its normals recomputed. Read chapters 04 (shape functions,
// locate_point), 07 (COO → CSR), 10 (the scene and the time loop) and 11–12 (the force models)
// first. The studies, in order:
//   1. point location: brute force, a uniform grid and an AABB tree on the bunny and on an
//      upsampled bunny of 10⁵ vertices — build time and points per second;
//   2. points outside: surfaces larger than the tet mesh, the rule, the count and the distances,
//      and the limit beyond which a vertex is refused;
//   3. skinning against simulation: the pushed rubber bunny simulated on coarse lattices and on
//      TetGen's fine mesh; the skinned surface's error against the fine simulation, the cost of a
//      step and of a skin; a .pvd of the skin (.vtp) beside the coarse tets (.vtu), PNG frames.
//
// Sample runs:
//   ch13_skinning                            full run
//   ch13_skinning --quick                    the small run ctest checks
//   ch13_skinning --cells 4 8 16 --model stable-neo-hookean
//
// Writes (under out/13_skinning): the tables *_table.csv; the chart skinning_pareto (PNG + CSV);
// skin.pvd (frames skin/skin_NNNN.vtp: displacement, normal) and coarse.pvd (frames
// coarse/coarse_NNNN.vtu) with PNG frames skin_NNNN.png and coarse_NNNN.png. docs/13_skinning.md

#include "studies.hpp"

#include "09_conjugate_gradient/linear_solver.hpp"

#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/parallel.hpp"

#include <algorithm>

using namespace fem;
using namespace fem::skin;

int main(int argc, char** argv)
{
    ChapterCli cli("ch13_skinning", "13_skinning",
                   "Chapter 13: skinning: point location, barycentric weights, x_surface = W q, points outside");
    study::Settings settings;
    cli.app.add_option("--cells", settings.cells, "Cubes along the bunny's longest side of the coarse lattices swept")
        ->check(check::integer(2, 40))->capture_default_str();
    cli.app.add_option("--shown-cells", settings.shown_cells, "Cubes along the longest side of the lattice shown in the time series")
        ->check(check::integer(2, 40))->capture_default_str();
    cli.app.add_option("--levels", settings.levels, "Midpoint subdivisions of the upsampled bunny (3: 117,602 vertices)")
        ->check(check::integer(1, 4))->capture_default_str();
    cli.app.add_option("--model", settings.model, "Force model of the simulations: corotational or stable-neo-hookean")
        ->check(check::accepted_by([](const std::string& name) {
            const auto& names = study::model_names();
            if (std::find(names.begin(), names.end(), name) == names.end())
                throw Error(str("must be corotational or stable-neo-hookean, got '", name, "'"));
        }))
        ->capture_default_str();
    cli.app.add_option("--duration", settings.duration, "Length of the push [s] (a multiple of 1/60)")
        ->check(check::real(0.0, 10.0, check::Ends::open_closed))->capture_default_str();
    cli.app.add_option("--max-outside", settings.max_outside,
                       "Largest distance of a point outside the coarse mesh, in longest edges of its nearest tet")
        ->check(check::real(0.0, 10.0, check::Ends::closed))->capture_default_str();
    cli.app.add_option("--seconds", settings.seconds, "Measuring time per timed kernel [s]")
        ->check(check::real(0.0, 60.0, check::Ends::open_closed))->capture_default_str();
    cli.check_options([&] {
        try {
            dynamics::step_count(settings.duration, 1.0 / 60.0);
        } catch (const Error& e) {
            throw Error(str("--duration must be a multiple of 1/60 s, the simulation's step: ", e.what()));
        }
    });
    return cli.run(argc, argv, [&](const RunContext& run) {
        if (run.quick) {
            settings.cells = {4, 6};
            settings.shown_cells = 6;
            settings.levels = 1;
            settings.duration = std::min(settings.duration, 0.25);
            settings.seconds = std::min(settings.seconds, 0.02);
        }
        set_blas_threads(1);
        study::location_study(run, settings);
        study::outside_study(run, settings);
        study::simulation_study(run, settings);
    });
}
