// Study 2 of ch13_skinning: surface vertices outside the coarse mesh — the rule (nearest tet,
// extrapolated weights), how many, how far, that affine motions are still carried exactly, and the
// limit beyond which a vertex is refused. docs/13_skinning.md#points-outside-in-practice
#include "studies.hpp"

#include "common/error.hpp"
#include "common/table.hpp"

#include <iostream>

namespace fem::skin::study {
namespace {

/// The surface scaled by factor about its centroid.
TriMesh scaled(const TriMesh& surface, double factor)
{
    TriMesh grown = surface;
    const Eigen::RowVector3d centre = surface.V.colwise().mean();
    grown.V = ((surface.V.rowwise() - centre) * factor).rowwise() + centre;
    return grown;
}

}  // namespace

void outside_study(const RunContext& run, const Settings& settings)
{
    std::cout << "\n== 2. Points outside the coarse mesh: nearest tet, extrapolated weights\n\n";
    const TriMesh bunny = bunny_surface();
    const TetMesh tetgen = bunny_tets();
    SkinOptions options;
    options.max_outside_distance = settings.max_outside;
    // Why: an affine motion x ↦ A x + b of the coarse mesh must move every skinned vertex by the same
    // map, the outside ones included: their weights still sum to 1 and reproduce X.
    Eigen::Matrix3d A;
    A << 1.1, 0.2, -0.1, 0.05, 0.9, 0.3, -0.2, 0.1, 1.2;
    const Eigen::RowVector3d b(0.3, -0.7, 1.1);
    const MatrixX3d moved = (tetgen.V * A.transpose()).rowwise() + b;
    Table table(str("Surfaces skinned to TetGen's bunny (", tetgen.T.rows(), " tets), outside rule up to ",
                    settings.max_outside, " longest edges"),
                {{"surface", Format::text}, {"vertices", Format::integer}, {"outside", Format::integer},
                 {"largest distance (bunny units)", Format::scientific, 3}, {"largest distance / longest edge", Format::scientific, 3},
                 {"smallest weight", Format::scientific, 3}, {"affine motion error [round-off]", Format::scientific, 2}});
    const std::vector<std::pair<std::string, TriMesh>> surfaces{
        {"bunny", bunny}, {"bunny subdivided once", midpoint_subdivision(bunny, 1)},
        {"bunny x 1.01", scaled(bunny, 1.01)}, {"bunny x 1.02", scaled(bunny, 1.02)}};
    for (const auto& [name, surface] : surfaces) {
        const Skin skin = build_skin(tetgen, surface, options);
        double largest_relative = 0.0;
        for (const OutsidePoint& o : skin.outside)
            largest_relative = std::max(largest_relative, o.relative_distance);
        const double smallest = *std::min_element(skin.W.A.begin(), skin.W.A.end());
        const MatrixX3d expected = (surface.V * A.transpose()).rowwise() + b;
        const double error = (skinned_positions(skin.W, moved) - expected).cwiseAbs().maxCoeff() / expected.cwiseAbs().maxCoeff();
        table.add_row({name, double(surface.V.rows()), double(skin.outside.size()), skin.largest_outside_distance(),
                       largest_relative, smallest, error});
    }
    table.print(std::cout);
    table.write_csv(run.file("outside_table.csv"));

    // Why: far outside, extrapolated weights are no longer a skin but a guess: refused, by name.
    std::cout << "\nThe bunny grown by 30 % around the same tets:\n";
    try {
        build_skin(tetgen, scaled(bunny, 1.3), options);
        std::cout << "  accepted (the limit is above every distance)\n";
    } catch (const Error& e) {
        std::cout << "  refused: " << e.what() << "\n";
    }
}

}  // namespace fem::skin::study
