// Study 3 of ch15_body_contact: the broad phase of self-contact — which pairs of surface primitives (a
// vertex and a triangle, two edges) two blocks thrown at each other can bring within d̂ over one
// step's motion — found three ways with one answer: every pair, chapter 13's AABB tree over the
// swept boxes, and a spatial hash; the time of each against the number of surface primitives.
// docs/15_body_contact.md#bodies-against-bodies-and-self-contact
#include "15_body_contact/broad_phase.hpp"
#include "studies.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh.hpp"
#include "common/random.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <iostream>

namespace fem::contact::study {

void self_contact_study(const RunContext& run)
{
    std::cout << "\n== 3. Bodies against bodies: the broad phase of self-contact — the surface pairs two blocks can\n"
                 "   bring within d-hat = 1 mm over one step, by every pair, by chapter 13's AABB tree and by a\n"
                 "   spatial hash (the same pairs each time), timed against the number of surface primitives\n\n";
    const double activation_distance = 1e-3, edge = 0.1;
    Table table("Self-contact broad phase: candidate pairs and time per search, two blocks 2 mm apart closing at 2 m/s "
                "for a step of 1/200 s",
                {{"cells per edge", Format::integer}, {"surface primitives", Format::integer},
                 {"method", Format::text}, {"point-triangle pairs", Format::integer},
                 {"edge-edge pairs", Format::integer}, {"same as every pair", Format::text},
                 {"time per search [ms]", Format::fixed, 3}});
    const std::vector<int> cells = run.quick ? std::vector<int>{2, 4, 8} : std::vector<int>{2, 4, 8, 12, 16};
    for (int k : cells) {
        // Two k×k×k blocks 2 mm apart along x, the second shifted 3 cm in y and 2 cm in z; at the
        // step's end each has moved 5 mm towards the other (they would overlap by 8 mm), every vertex
        // also jittered by up to 0.1 mm at both ends (a body deforms).
        const TetMesh block = box_mesh(k, k, k, Eigen::Vector3d::Constant(edge));
        TetMesh both;
        const Eigen::Index n = block.V.rows();
        both.V.resize(2 * n, 3);
        both.V << block.V, block.V.rowwise() + Eigen::RowVector3d(edge + 2e-3, 0.03, 0.02);
        both.T.resize(2 * block.T.rows(), 4);
        both.T << block.T, (block.T.array() + static_cast<int>(n)).matrix();
        const SurfacePrimitives surface = surface_primitives(both);
        const MatrixX3d start = both.V + 1e-4 * random_matrix(2 * n, 3, 5);
        MatrixX3d end = both.V + 1e-4 * random_matrix(2 * n, 3, 6);
        end.topRows(n).col(0).array() += 5e-3;
        end.bottomRows(n).col(0).array() -= 5e-3;
        const double primitives = double(surface.vertices.size() + surface.edges.rows() + surface.triangles.rows());
        struct Method {
            const char* name;
            CandidatePairs (*search)(const SurfacePrimitives&, const MatrixX3d&, const MatrixX3d&, double);
        };
        const Method methods[] = {{"every pair", brute_force_candidates},
                                  {"AABB tree", tree_candidates},
                                  {"spatial hash", hash_candidates}};
        const CandidatePairs reference = brute_force_candidates(surface, start, end, activation_distance);
        for (const Method& method : methods) {
            CandidatePairs pairs;
            const double seconds = best_time([&] { pairs = method.search(surface, start, end, activation_distance); },
                                             run.quick ? 0.02 : 0.2, run.quick ? 3 : 20);
            table.add_row({double(k), primitives, std::string(method.name), double(pairs.point_triangle.size()),
                           double(pairs.edge_edge.size()), std::string(pairs == reference ? "yes" : "NO"),
                           1e3 * seconds});
        }
    }
    table.print(std::cout);
    table.write_csv(run.file("self_broad_phase_table.csv"));
}

}  // namespace fem::contact::study
