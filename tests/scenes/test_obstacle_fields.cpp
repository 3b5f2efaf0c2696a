// The obstacle red team's fields (issue 48, items 6b, 6e, 6f): an obstacle that starts through or
// inside a body, a gap or a size a double cannot resolve, an obstacle that reaches or travels too far,
// and chapter 14's own refusals are each refused by the reader at the scene's line and column,
// naming the field, the body and its primitives and what is allowed; directions and angles of any
// magnitude are read as the directions they are. docs/scenes.md#obstacles
#include "scenes/runner.hpp"
#include "scenes/scene_text.hpp"

#include "14_contact/surface.hpp"

#include "common/error.hpp"

#include <Eigen/Core>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace fem;
using namespace fem::scenes;
using testing::output;
using testing::scene_from;

namespace {

/// A 10 cm one-cell block, its lowest face at z = `height` (lines 1–7), then the obstacle's lines
/// from line 8 ([[obstacle]] on line 8, its first field on line 9). model is the body's.
std::string block_and(const std::string& obstacle, const std::string& height = "0.01",
                      const std::string& model = "auto")
{
    return "[[body]]\n"
           "name = \"block\"\n"
           "mesh = { generator = \"box\", size = [0.1, 0.1, 0.1], cells = [1, 1, 1], translate = [0.0, 0.0, " +
           height + "] }\n"
           "material = { model = \"" + model + "\", youngs_modulus = 1e5, poisson_ratio = 0.4, density = 1000.0 }\n"
           "[time]\nstep = 0.01\nduration = 0.1\n"
           "[[obstacle]]\n" + obstacle;
}

/// A triangle surface in the tests' output folder, beside the scenes scene_from writes.
void write_surface(const std::string& name, const std::string& text)
{
    std::filesystem::create_directories(output);
    std::ofstream(output / name) << text;
}

struct Refusal {
    std::string name, text;
    std::vector<std::string> contains;  // besides "<name>.toml:"
};

}  // namespace

TEST_CASE("obstacle fields: what starts through or inside a body, a gap or a size below a double's resolution, and "
          "an obstacle reaching or travelling too far are refused at the field's line", "[scenes][contact]")
{
    // A thin spike whose tip pokes 5 mm into the block's bottom face between its vertices (no tet
    // edge crosses it), and a small plate inside the block.
    write_surface("red_spike.obj", "v 0.02 0.06 -0.05\nv 0.04 0.06 -0.05\nv 0.03 0.08 -0.05\nv 0.03 0.07 0.015\n"
                                   "f 1 2 4\nf 2 3 4\nf 3 1 4\n");
    write_surface("red_plate.obj", "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n");
    const std::vector<Refusal> refusals{
        // 6b: through or inside the body.
        {"red_slab", "type = \"box\"\ncenter = [0.05, 0.05, 0.06]\nsize = [1.0, 1.0, 0.02]\n",
         {":8:1: obstacle[0]: body 'block' starts with its surface edge from vertex", "through it (both ends outside)"}},
        {"red_rod", "type = \"capsule\"\nstart = [-1.0, 0.05, 0.06]\nend = [1.0, 0.05, 0.06]\nradius = 0.01\n",
         {":8:1: obstacle[0]: body 'block' starts with its surface edge"}},
        {"red_ball_inside", "type = \"sphere\"\ncenter = [0.05, 0.05, 0.06]\nradius = 0.01\n",
         {":8:1: obstacle[0]: starts inside body 'block'", "in tet"}},
        {"red_spike", "type = \"mesh\"\nfile = \"red_spike.obj\"\n",
         {":8:1: obstacle[0]: body 'block' starts through it (edge (", "meets body triangle ("}},
        {"red_plate_inside", "type = \"mesh\"\nfile = \"red_plate.obj\"\nscale = 0.01\ntranslate = [0.05, 0.05, 0.06]\n",
         {":8:1: obstacle[0]: body 'block' starts through it"}},
        // 6e: gaps and reaches a double cannot resolve.
        {"red_gap_1e-300", "type = \"half-space\"\n",
         {":8:1: obstacle[0]: body 'block' starts 1e-300 m from it (vertex 0), closer than 1e-08 d̂ = 1e-11 m"}},
        {"red_gap_denormal", "type = \"half-space\"\n", {"starts 3.99996e-320 m from it (vertex 0)"}},
        {"red_far_sphere", "type = \"sphere\"\ncenter = [0.05, 0.05, -1e9]\nradius = 1e9\n",
         {":10:10: obstacle[0].center: places the sphere 2e+09 m from the origin, more than 1e+08 d̂ = 100000 m"}},
        {"red_far_plane", "type = \"half-space\"\npoint = [0.0, 0.0, -1e300]\nnormal = [0.0, 1.0, 1.0]\n",
         {":10:9: obstacle[0].point: places the half-space 7.07107e+299 m from the origin"}},
        {"red_fast", "type = \"half-space\"\nvelocity = [1e12, 0.0, 0.0]\n",
         {":10:12: obstacle[0].velocity: moves it 1e+11 m in the run", "slow it to at most 1e+06 m/s"}},
        {"red_fastest", "type = \"half-space\"\nvelocity = [1e308, 0.0, 0.0]\n", {":10:12: obstacle[0].velocity: moves it"}},
        // 6f: chapter 14's and the mesh's refusals, at the scene's line.
        {"red_tiny_box", "type = \"box\"\ncenter = [0.05, 0.05, -0.001]\nsize = [1e-200, 1e-200, 1e-200]\n",
         {":11:8: obstacle[0].size: must be at least 1e-09 times the box's reach"}},
        {"red_short_capsule", "type = \"capsule\"\nstart = [1.0, 1.0, -1.0]\nend = [1.0, 1.0, -0.9999999999999999]\nradius = 0.5\n",
         {":11:7: obstacle[0].end: must differ from start: a capsule's segment has a length > 0 (m), by more than 1e-09 times"}},
        {"red_mesh_scale", "type = \"mesh\"\nfile = \"red_plate.obj\"\nscale = 1e-300\ntranslate = [0.0, 0.0, -0.1]\n",
         {":11:9: obstacle[0].scale: places the mesh", "red_plate.obj: triangle 0 (vertices 0, 1, 2) has zero area"}},
        {"red_mesh_translate", "type = \"mesh\"\nfile = \"red_plate.obj\"\ntranslate = [1e17, 0.0, -0.1]\n",
         {":11:13: obstacle[0].translate: places the mesh"}},
    };
    for (const Refusal& refusal : refusals) {
        INFO(refusal.name);
        const std::string height = refusal.name == "red_gap_1e-300" ? "1e-300" : refusal.name == "red_gap_denormal" ? "4e-320" : "0.01";
        std::string message;
        try {
            scene_from(refusal.name, block_and(refusal.text, height));
        } catch (const Error& e) {
            message = e.what();
        }
        CHECK_THAT(message, Catch::Contains(refusal.name + ".toml:"));
        for (const std::string& part : refusal.contains)
            CHECK_THAT(message, Catch::Contains(part));
    }
    // A model linear body, at its model field (line 4, column 22).
    CHECK_THROWS_WITH(scene_from("red_linear", block_and("type = \"half-space\"\n", "0.01", "linear")),
                      Catch::Contains("red_linear.toml:4:22: body[0].material.model: model linear cannot meet obstacles"));
}

TEST_CASE("obstacle fields: the gaps, reaches and sizes just inside the limits are read", "[scenes][contact]")
{
    // 10⁻¹⁰ m above the floor (10⁻⁷ d̂), a sphere reaching 5·10⁴ m, an obstacle moving 10⁵ m in the run.
    CHECK_NOTHROW(scene_from("red_gap_ok", block_and("type = \"half-space\"\n", "1e-10")));
    CHECK_NOTHROW(scene_from("red_sphere_ok", block_and("type = \"sphere\"\ncenter = [0.05, 0.05, -2.5e4]\nradius = 24999.99\n")));
    CHECK_NOTHROW(scene_from("red_speed_ok", block_and("type = \"half-space\"\nvelocity = [1e6, 0.0, 0.0]\n")));
    CHECK_NOTHROW(scene_from("red_box_ok", block_and("type = \"box\"\ncenter = [0.05, 0.05, -0.001]\nsize = [1e-9, 1e-9, 1e-9]\n")));
}

TEST_CASE("obstacle fields: a box's angle and axis and a half-space's normal of any finite magnitude are the "
          "directions they name", "[scenes][contact]")
{
    const SceneSpec huge_normal =
        scene_from("red_normal", block_and("type = \"half-space\"\npoint = [-1.0, -1.0, 0.0]\nnormal = [1e308, 1e308, 0.0]\n"));
    const SceneSpec unit_normal =
        scene_from("red_normal_unit", block_and("type = \"half-space\"\npoint = [-1.0, -1.0, 0.0]\nnormal = [1.0, 1.0, 0.0]\n"));
    const Eigen::Vector3d p(0.3, -0.2, 0.1);
    CHECK(huge_normal.obstacles[0].obstacle->distance(p, 0.0) == unit_normal.obstacles[0].obstacle->distance(p, 0.0));
    // 1.7e308° = 1.7e308 mod 360 degrees; an axis of 1e308s is its direction.
    const std::string box = "type = \"box\"\ncenter = [0.05, 0.05, -1.0]\nsize = [1.0, 2.0, 0.5]\n";
    const SceneSpec huge = scene_from("red_box_huge", block_and(box + "axis = [1e308, 1e308, 0.0]\nangle = 1.7e308\n"));
    const SceneSpec plain = scene_from(
        "red_box_plain", block_and(box + "axis = [1.0, 1.0, 0.0]\nangle = " + std::to_string(std::fmod(1.7e308, 360.0)) + "\n"));
    for (const Eigen::Vector3d& q : {Eigen::Vector3d(0.3, -0.2, 0.1), Eigen::Vector3d(-0.7, 0.4, -0.2)})
        CHECK(std::abs(huge.obstacles[0].obstacle->distance(q, 0.0) - plain.obstacles[0].obstacle->distance(q, 0.0)) <= 1e-12);
}

TEST_CASE("obstacle fields: a mesh obstacle whose triangles need more memory than the scene may use is refused at its "
          "file, with the memory it would need", "[scenes][contact]")
{
    // A 20,000-triangle floor (100 × 100 squares) below the block.
    std::string floor;
    for (int j = 0; j <= 100; ++j)
        for (int i = 0; i <= 100; ++i)
            floor += str("v ", -1.0 + 0.02 * i, " ", -1.0 + 0.02 * j, " -0.01\n");
    for (int j = 0; j < 100; ++j)
        for (int i = 0; i < 100; ++i) {
            const int a = j * 101 + i + 1;
            floor += str("f ", a, " ", a + 1, " ", a + 102, "\nf ", a, " ", a + 102, " ", a + 101, "\n");
        }
    write_surface("red_floor.obj", floor);
    const std::string text = block_and("type = \"mesh\"\nfile = \"red_floor.obj\"\n");
    std::filesystem::create_directories(output);
    std::ofstream(output / "red_memory.toml") << text;
    ReadLimits small;
    small.memory = 10'000'000;  // 10 MB: the floor needs 20 at 1,000 bytes a triangle
    CHECK_THROWS_WITH(read_scene(output / "red_memory.toml", {}, false, small),
                      Catch::Contains("red_memory.toml:10:8: obstacle[0].file: this mesh obstacle needs about 20 MB "
                                      "(20000 triangles") &&
                          Catch::Contains("more than the 10 MB available: use a coarser surface"));
    ReadLimits enough;
    enough.memory = 30'000'000;
    CHECK_NOTHROW(read_scene(output / "red_memory.toml", {}, false, enough));
}

TEST_CASE("obstacle fields: a 2 x 2 x 2 block fired at 6 m/s at a 5 cm sphere keeps every point of its surface "
          "outside it, every frame", "[scenes][contact]")
{
    const SceneSpec scene = scene_from(
        "red_sphere_hit",
        "gravity = [0.0, 0.0, 0.0]\n[[body]]\nname = \"block\"\n"
        "mesh = { generator = \"box\", size = [0.2, 0.2, 0.2], cells = [2, 2, 2], translate = [-0.05, -0.05, 0.01] }\n"
        "material = { model = \"auto\", youngs_modulus = 1e5, poisson_ratio = 0.4, density = 1000.0 }\n"
        "initial_velocity = [0.0, 0.0, -6.0]\n"
        "[[obstacle]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, -0.05]\nradius = 0.05\n"
        "[time]\nstep = 0.01\nduration = 0.1\n[output]\nframe_rate = 100\n");
    const RunResult run = run_positions(scene);
    const contact::SurfacePrimitives surface = contact::surface_primitives(scene.bodies[0].mesh);
    const contact::Obstacle& sphere = *scene.obstacles[0].obstacle;
    double smallest = INFINITY;
    for (const MatrixX3d& x : run.frames[0])
        for (Eigen::Index t = 0; t < surface.triangles.rows(); ++t) {
            const Eigen::Vector3d a = x.row(surface.triangles(t, 0)), b = x.row(surface.triangles(t, 1)),
                                  c = x.row(surface.triangles(t, 2));
            for (int i = 0; i <= 20; ++i)
                for (int j = 0; i + j <= 20; ++j)
                    smallest = std::min(smallest, sphere.distance(a + (b - a) * i / 20.0 + (c - a) * j / 20.0, 0.0));
        }
    INFO("the smallest gap of a sampled surface point over " << run.frames[0].size() << " frames: " << smallest << " m");
    CHECK(run.frames[0].size() == 11);
    CHECK(smallest > 0.0);  // by the vertices alone the sphere was 2.4 cm inside the face
}

