// Study 1 of ch15_body_contact: the distance to a triangle mesh obstacle, three ways — every triangle
// (the reference), chapter 13's AABB tree (exact, fewer triangles tested), and a sampled grid
// (one cell a query, but only approximate) — timed per query and measured against the reference on
// the same random points, over the whole box and near the surface, where the barrier looks; then the
// mesh obstacle in use, a block dropped into the bowl (study_bowl.cpp).
// docs/15_body_contact.md#tree-or-grid
#include "15_body_contact/mesh_obstacle.hpp"
#include "studies.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh_io.hpp"
#include "common/random.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <algorithm>
#include <iostream>
#include <vector>

namespace fem::contact::study {
namespace {

/// The largest and mean |d − d_reference| over points, and the largest over those with d_reference < near.
struct Errors {
    double largest = 0.0, mean = 0.0, largest_near = 0.0;
};

template <class Distance>
Errors errors(const Distance& distance, const std::vector<Eigen::Vector3d>& points, const std::vector<double>& reference,
              double near)
{
    Errors e;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const double error = std::abs(distance(points[i]) - reference[i]);
        e.largest = std::max(e.largest, error);
        e.mean += error / double(points.size());
        if (reference[i] < near)
            e.largest_near = std::max(e.largest_near, error);
    }
    return e;
}

/// Seconds per query of distance over the points (the best of a few passes).
template <class Distance>
double seconds_per_query(const Distance& distance, const std::vector<Eigen::Vector3d>& points)
{
    double sink = 0.0;
    const double seconds = best_time([&] {
        for (const Eigen::Vector3d& p : points)
            sink += distance(p);
    }, 0.05, 5);
    if (!(sink >= 0.0))  // keeps the loop from being optimised away (a distance is never negative)
        std::cout << "unexpected: a negative distance\n";
    return seconds / double(points.size());
}

}  // namespace

void mesh_study(const RunContext& run, const Settings& settings)
{
    std::cout << "\n== 1. Mesh obstacles: the distance to the nearest triangle by every triangle, by chapter 13's AABB tree\n"
                 "   and by a sampled grid (trilinear), on the same random points of the mesh's box grown by 2 cm\n\n";
    struct Surface {
        const char* name;
        const char* file;
        double scale;
    };
    std::vector<Surface> surfaces{{"bowl", "bowl.obj", 1.0}};
    if (!run.quick)
        surfaces.push_back({"bunny", "bunny.obj", 0.02});  // 3,674 triangles, about 19 cm tall
    const double near = 5e-3, margin = 0.02;
    Table table("Distance to a mesh: time per query and error against testing every triangle",
                {{"mesh", Format::text}, {"triangles", Format::integer}, {"method", Format::text},
                 {"grid spacing [m]", Format::text}, {"set-up [ms]", Format::fixed, 2},
                 {"time per query [us]", Format::fixed, 3},
                 {"largest error [m]", Format::scientific, 2}, {"mean error [m]", Format::scientific, 2},
                 {"largest error, d < 5 mm [m]", Format::scientific, 2}});
    for (const Surface& surface : surfaces) {
        TriMesh triangles = io::read_tri_mesh(data_path(surface.file));
        triangles.V *= surface.scale;
        Timer setup;
        const MeshObstacle mesh(triangles);
        const double tree_setup = setup.seconds();
        const Eigen::Vector3d low = mesh.surface().V.colwise().minCoeff().transpose().array() - margin;
        const Eigen::Vector3d high = mesh.surface().V.colwise().maxCoeff().transpose().array() + margin;
        // Half the points anywhere in the box, half within 5 mm of a vertex (the barrier's range).
        std::vector<Eigen::Vector3d> points(static_cast<std::size_t>(settings.mesh_queries));
        for (std::size_t i = 0; i < points.size(); ++i) {
            const Eigen::Vector3d r = random_vector(3, 17 + static_cast<unsigned>(i));
            if (i % 2 == 0)
                points[i] = 0.5 * (low + high) + 0.5 * (high - low).cwiseProduct(r);
            else
                points[i] = mesh.surface().V.row(static_cast<Eigen::Index>(i % mesh.surface().V.rows())).transpose() + near * r;
        }
        std::vector<double> reference(points.size());
        for (std::size_t i = 0; i < points.size(); ++i)
            reference[i] = mesh.nearest_brute_force(points[i]).distance;
        const auto add = [&](const std::string& method, const std::string& spacing, double setup_seconds,
                             const auto& distance) {
            const Errors e = errors(distance, points, reference, near);
            table.add_row({std::string(surface.name), double(mesh.surface().F.rows()), method, spacing,
                           1e3 * setup_seconds, 1e6 * seconds_per_query(distance, points), e.largest, e.mean,
                           e.largest_near});
        };
        add("every triangle", "-", 0.0, [&](const Eigen::Vector3d& p) { return mesh.nearest_brute_force(p).distance; });
        add("AABB tree", "-", tree_setup, [&](const Eigen::Vector3d& p) { return mesh.local_distance(p); });
        for (double spacing : settings.grid_spacings) {
            Timer grid_setup;
            const DistanceGrid grid(mesh, spacing, margin);
            const double seconds = grid_setup.seconds();
            add("grid", str(spacing), seconds, [&](const Eigen::Vector3d& p) { return grid.distance(p); });
        }
    }
    table.print(std::cout);
    table.write_csv(run.file("mesh_table.csv"));
    bowl_study(run);
}

}  // namespace fem::contact::study
