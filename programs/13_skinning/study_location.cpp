// Study 1 of ch13_skinning: point location by brute force, a uniform grid and an AABB tree, on the
// bunny and an upsampled bunny, in TetGen's tets of the bunny and in a coarse lattice around it:
// build time, points per second, and whether the three agree. docs/13_skinning.md#point-location-in-practice
#include "studies.hpp"

#include "04_tet_jacobians/tet_jacobians.hpp"

#include "common/table.hpp"
#include "common/timer.hpp"

#include <algorithm>
#include <iostream>

namespace fem::skin::study {

void location_study(const RunContext& run, const Settings& settings)
{
    std::cout << "\n== 1. Point location: the tet of every surface vertex, three ways\n\n";
    const TriMesh bunny = bunny_surface();
    const TriMesh fine = midpoint_subdivision(bunny, settings.levels);
    const std::vector<std::pair<std::string, TetMesh>> coarse{
        {"TetGen bunny", bunny_tets()}, {"lattice 8", enclosing_lattice(bunny, 8)}};
    const double tolerance = SkinOptions{}.tolerance;
    // Why: brute force costs #T a point; on 10⁵ points it would take minutes, so it is timed on the
    // first points only and every method is checked against it there.
    const Eigen::Index sample = run.quick ? 300 : 2000;
    Table table("Point location: set-up and points per second (brute force timed on the first points; all agree with it there)",
                {{"coarse mesh", Format::text}, {"tets", Format::integer}, {"surface vertices", Format::integer},
                 {"method", Format::text}, {"build [s]", Format::scientific, 2}, {"points per second [1/s]", Format::scientific, 2},
                 {"points timed", Format::integer}, {"found inside", Format::integer}, {"differ from brute force", Format::integer}});
    for (const auto& [coarse_name, mesh] : coarse) {
        const BarycentricFrames frames(mesh);
        for (const TriMesh* surface : {&bunny, &fine}) {
            const Eigen::Index n = surface->V.rows(), checked = std::min(n, sample);
            std::vector<int> reference(checked);
            for (Eigen::Index s = 0; s < checked; ++s)
                reference[s] = locate_brute_force(frames, surface->V.row(s).transpose(), tolerance).tet;
            for (LocateMethod method : {LocateMethod::brute_force, LocateMethod::grid, LocateMethod::tree}) {
                std::unique_ptr<PointLocator> locator;
                const double build = best_time([&] { locator = make_locator(method, frames, tolerance); }, settings.seconds, 5);
                const Eigen::Index timed = method == LocateMethod::brute_force ? checked : n;
                int inside = 0, differ = 0;
                Timer clock;
                for (Eigen::Index s = 0; s < timed; ++s) {
                    const int t = locator->locate(surface->V.row(s).transpose()).tet;
                    inside += t >= 0;
                    differ += s < checked && t != reference[s];
                }
                const double rate = double(timed) / clock.seconds();
                table.add_row({coarse_name, double(mesh.T.rows()), double(n), method_name(method), build, rate,
                               double(timed), double(inside), double(differ)});
            }
        }
    }
    // Why: chapter 04's locate_point is the same brute force with a validation and an LU solve per
    // tet; a few points show what preparing T⁻¹ once saves.
    const TetMesh& tetgen = coarse.front().second;
    const int few = run.quick ? 3 : 20;
    int inside = 0;
    Timer clock;
    for (int s = 0; s < few; ++s)
        inside += tet::locate_point(tetgen, bunny.V.row(s).transpose(), tolerance).inside;
    table.add_row({"TetGen bunny", double(tetgen.T.rows()), double(bunny.V.rows()), "chapter 04 locate_point", 0.0,
                   double(few) / clock.seconds(), double(few), double(inside), 0.0});
    table.print(std::cout);
    table.write_csv(run.file("location_table.csv"));
}

}  // namespace fem::skin::study
