// Chapter 15: exact ties on flat mesh obstacles — a point standing exactly over (or a round-off
// beside) the shared edge of two coplanar triangles or a vertex of a flat fan feels the plane's one
// barrier, whatever the winding, the diagonal or the file the floor came from; and a block dropped
// with its corners on a plate's diagonal or on a grid floor's lines and vertices lands and rests
// as on the half-space (issue 48, item 6a). docs/15_body_contact.md#mesh-obstacles
#include "15_body_contact/body_contact.hpp"
#include "14_contact/barrier.hpp"
#include "14_contact/contact_scenes.hpp"
#include "15_body_contact/mesh_obstacle.hpp"
#include "14_contact/obstacles.hpp"
#include "../14_contact/one_thread.hpp"

#include "common/mesh.hpp"
#include "common/mesh_io.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

using namespace fem;
using namespace fem::contact;

namespace flat_ties {

constexpr double tie_dhat = 1e-3, tie_kappa = 1e4;

/// square_mesh(cells) scaled to [−1, 1]² (z = 0): the 2 m plate of two triangles (faces 0 1 2 and
/// 0 2 3, its diagonal from (−1, −1) to (1, 1)) for one cell, a grid of spacing 2/cells else.
TriMesh grid_floor(int cells)
{
    TriMesh floor = square_mesh(cells);
    floor.V.leftCols<2>() = (2.0 * floor.V.leftCols<2>()).array() - 1.0;
    return floor;
}

/// The same triangles run the other way round (their normals −z).
TriMesh inverted(TriMesh mesh)
{
    mesh.F.col(1).swap(mesh.F.col(2));
    return mesh;
}

/// κ Σ b(dᵢ) over the pieces p feels within d̂, and how many there are.
std::pair<double, int> tie_barrier(const Obstacle& obstacle, const Eigen::Vector3d& p)
{
    std::vector<DistancePiece> pieces;
    obstacle.local_pieces(p, tie_dhat, pieces);
    double energy = 0.0;
    for (const DistancePiece& piece : pieces)
        energy += tie_kappa * barrier(piece.distance, tie_dhat).value;
    return {energy, static_cast<int>(pieces.size())};
}

/// The floors every tie is tried on: the plate and the grid, each as made, inverted, and written
/// to and read back from an .obj and an .stl (STL's corners merged again by the reader); the plate
/// as one quad of an .obj.
std::vector<std::pair<std::string, TriMesh>> floors()
{
    std::vector<std::pair<std::string, TriMesh>> all;
    const std::filesystem::path folder = std::filesystem::path(FEM_TEST_OUTPUT_DIR) / "flat_ties";
    std::filesystem::create_directories(folder);
    for (const int cells : {1, 10}) {
        const std::string name = cells == 1 ? "plate" : "grid";
        all.emplace_back(name, grid_floor(cells));
        all.emplace_back(name + " inverted", inverted(grid_floor(cells)));
        for (const char* extension : {".obj", ".stl"}) {
            const std::filesystem::path file = folder / (name + extension);
            io::write_tri_mesh(file, grid_floor(cells));
            all.emplace_back(name + extension, io::read_tri_mesh(file));
        }
    }
    // The plate as one quad, which the reader splits into two triangles.
    std::ofstream(folder / "plate_quad.obj") << "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n";
    all.emplace_back("plate as a quad", io::read_tri_mesh(folder / "plate_quad.obj"));
    return all;
}

}  // namespace flat_ties

using namespace flat_ties;

TEST_CASE("flat ties: a point exactly over a shared edge or vertex of a flat floor, or beside it by any small offset, "
          "feels the plane's one barrier", "[obstacles][ex15.1]")
{
    const HalfSpace plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
    const double height = 4e-4;
    // Over the plate's diagonal (its middle and a point 2 cm along it), over the grid's diagonals,
    // its lines and its vertices (every kind of tie); then moved by δ across or along, each way.
    const std::vector<Eigen::Vector2d> ties{{0.0, 0.0}, {-0.02, -0.02}, {0.02, 0.02}, {0.2, 0.2},  {0.1, 0.0},
                                            {0.0, 0.1}, {0.2, 0.0},    {-0.4, 0.6},  {0.35, 0.35}};
    const std::vector<double> offsets{0.0, 1e-15, 1e-12, 1e-10, 1e-8, 1e-7, 2e-7, 2.8e-7, 3e-7, 1e-6, 1e-5};
    const std::vector<Eigen::Vector2d> directions{{1.0, -1.0}, {-1.0, 1.0}, {1.0, 0.0}, {0.0, -1.0}, {1.0, 1.0}};
    for (const auto& [name, surface] : floors()) {
        const MeshObstacle floor(surface);
        double worst = 0.0;
        int pieces_other_than_one = 0;
        for (const Eigen::Vector2d& tie : ties)
            for (const double offset : offsets)
                for (const Eigen::Vector2d& direction : directions) {
                    const Eigen::Vector2d at = tie + offset * direction.normalized();
                    const Eigen::Vector3d p(at.x(), at.y(), height);
                    const auto [energy, pieces] = tie_barrier(floor, p);
                    const double expected = tie_barrier(plane, p).first;
                    worst = std::max(worst, std::abs(energy - expected) / expected);
                    pieces_other_than_one += pieces != 1;
                }
        INFO(name << ": the barrier's largest relative difference from the plane's " << worst);
        CHECK(pieces_other_than_one == 0);
        CHECK(worst <= 1e-12);
    }
}

TEST_CASE("flat ties: a block dropped with its corners on a plate's diagonal, or on a grid floor's lines and vertices, "
          "lands and rests as on the half-space", "[obstacles][ex15.4]")
{
    BlockSettings settings;
    settings.terms = body_contact_term_maker();  // the obstacles' edges and corners too
    settings.model = "neo-hookean";
    settings.material = dynamics::Material{1e5, 0.4, 1000.0};
    settings.height = 0.01;
    const int steps = 30;  // falls 1 cm, lands at step 5, rests
    const auto run = [&](BlockSettings these) {
        BlockScene block = block_scene(these);
        std::vector<Eigen::VectorXd> states;
        for (int step = 0; step < steps; ++step) {
            block.step();
            states.push_back(block.state.u);
        }
        return states;
    };
    struct Drop {
        std::string what;
        double edge;
        Eigen::Vector2d corner;
        int cells;  // of the floor: 1, the plate
    };
    // The 4 cm block at (−0.02, −0.02) (two corners on the plate's diagonal); a 20 cm one on
    // the grid's vertices; one on its lines (x mid-cell).
    const std::vector<Drop> drops{{"4 cm block, corners on the plate's diagonal", 0.04, {-0.02, -0.02}, 1},
                                  {"4 cm block, corners on the grid's diagonals", 0.04, {-0.02, -0.02}, 10},
                                  {"20 cm block, every corner on a grid vertex", 0.2, {0.0, 0.0}, 10},
                                  {"20 cm block, every corner on a grid line", 0.2, {0.1, 0.0}, 10}};
    for (const Drop& drop : drops) {
        BlockSettings these = settings;
        these.edge = drop.edge;
        these.corner = drop.corner;
        const std::vector<Eigen::VectorXd> half = run(these);
        for (const bool flip : {false, true}) {
            these.obstacles = {std::make_shared<MeshObstacle>(flip ? inverted(grid_floor(drop.cells)) : grid_floor(drop.cells))};
            INFO(drop.what << (flip ? ", the floor's winding inverted" : ""));
            std::vector<Eigen::VectorXd> states;
            REQUIRE_NOTHROW(states = run(these));
            double apart = 0.0;
            for (int step = 0; step < steps; ++step)
                apart = std::max(apart, (states[step] - half[step]).lpNorm<Eigen::Infinity>());
            INFO("the largest difference from the half-space's run " << apart << " m");
            CHECK(apart <= 1e-9);
        }
    }
}
