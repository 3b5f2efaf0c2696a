// ch11_corotational (work in progress)
#include "11_corotational/studies.hpp"

#include "09_conjugate_gradient/linear_solver.hpp"

#include "common/cli.hpp"
#include "common/error.hpp"

#include <iostream>

using namespace fem;
using namespace fem::corot;

int main(int argc, char** argv)
{
    ChapterCli cli("ch11_corotational", "11_corotational",
                   "Chapter 11: corotational elements — best-fit rotations, warped stiffness, a changing step matrix");
    study::Settings settings;
    cli.app.add_option("--cost-cells", settings.cost_cells, "Cells along the beams of the cost study (10 to 200)")
        ->capture_default_str();
    cli.app.add_option("--seconds", settings.seconds, "Measuring time per timed kernel [s] (> 0)")->capture_default_str();
    return cli.run(argc, argv, [&](const RunContext& run) {
        cg::set_blas_threads(1);
        study::swing_study(run, settings);
        study::cost_study(run, settings);
    });
}
