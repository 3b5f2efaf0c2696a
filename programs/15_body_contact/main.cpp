// ch15_body_contact: bodies against bodies — chapter 14's contact potential with the terms of this
// chapter: triangle meshes as obstacles, the distances between surface primitives and their
// continuous collision detection, the broad phase that finds the pairs, self-contact, several bodies
// in one solve, friction between them, and what it all costs. Read chapter 14 (the barrier, the
// contact potential, friction) first.
// The studies, in order:
//   1. mesh obstacles: the distance to a triangle mesh (the bowl, the bunny) by every triangle, by
//      chapter 13's AABB tree and by sampled grids — time per query and error against the first;
//      a block dropped into the bowl, its frames;
//   2. primitive CCD: point–triangle and edge–edge continuous collision detection, the naive
//      coplanarity cubic against the conservative inclusion method, on the CCD benchmark's queries
//      (data/ccd-unit-tests; --ccd-queries FILE... runs only this study, on those files);
//   3. bodies against bodies: the broad phase of self-contact (which surface pairs two blocks can
//      bring within d̂ over a step) by every pair, chapter 13's AABB tree and a spatial hash, timed
//      against the number of surface primitives;
//   4. bodies against bodies, the cost: two coarse bunnies thrown at each other with self-contact,
//      beside the same two without contact — per step the linear solves, the barrier with its broad
//      phase and the collision check, momentum and the intersection check; Newton's tolerance
//      loosened to 10⁻³, its iterations against the end state's offset;
//   5. a stack at rest (three blocks, self-contact) against its closed form — the force between
//      blocks against the weight above, the gaps against d̂ — swept over d̂ and Newton's tolerance.
//
// Sample runs:
//   ch15_body_contact                       full run
//   ch15_body_contact --quick               the small run ctest checks
//   ch15_body_contact --ccd-queries data/ccd-unit-tests/edge-edge/data_0_0.csv   CCD on one query file
//
// Writes (under out/15_body_contact): mesh_table.csv, bowl_table.csv, ccd_queries_table.csv,
// self_broad_phase_table.csv, two_bunnies_table.csv, two_bunnies_tolerance_table.csv,
// stack_tolerance_table.csv, bowl.pvd (frames bowl/bowl_NNNN.vtu) and the bowl's frames bowl_NNNN.png.
// docs/15_body_contact.md

#include "studies.hpp"
#include "study_ccd.hpp"

#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/parallel.hpp"

using namespace fem;
using namespace fem::contact;

int main(int argc, char** argv)
{
    ChapterCli cli("ch15_body_contact", "15_body_contact",
                   "Chapter 15: bodies against bodies: mesh obstacles, primitive CCD, broad phases, self-contact, friction between bodies");
    study::Settings settings;
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
            if (cli.app.count("--hessian-variants") > 0)
                throw Error("--hessian-variants: --ccd-queries runs only the CCD study and would ignore it");
            cli.protect_inputs({ccd_files.begin(), ccd_files.end()});
        }
    });
    return cli.run(argc, argv, [&](const RunContext& run) {
        if (!ccd_files.empty()) {
            study::ccd_study(run, ccd_files);
            return;
        }
        if (run.quick) {
            settings.mesh_queries = 2000;
            settings.grid_spacings = {0.01};
        }
        set_blas_threads(1);
        study::mesh_study(run, settings);
        study::ccd_study(run, study::ccd_benchmark_files());
        study::self_contact_study(run);
        study::bodies_study(run, hessian_variants);
        study::stack_study(run);
    });
}
