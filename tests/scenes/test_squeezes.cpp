// Squeezes (issue 48, item 6d): a pinned body and prescribed obstacle motions, or two floors
// closing, that leave it no room are refused before stepping, naming the obstacle, the body, the
// pinned vertex, the time and the field's place; the same squeezes ended before that time are not refused, and run with every tet
// upright (chapter 12's volume filter). docs/scenes.md#obstacles
#include "scene_text.hpp"

#include "scenes/runner.hpp"

#include "common/error.hpp"
#include "common/parallel.hpp"

#include <catch2/catch.hpp>

#include <string>

using namespace fem;
using namespace fem::scenes;

namespace {

/// A 10 cm neo-Hookean block pinned at pin (a [[body.pin]] table's body), and obstacle, for duration.
std::string pinned_block(const std::string& pin, const std::string& obstacle, double duration)
{
    return str("[[body]]\n"
               "mesh = { generator = \"box\", size = [0.1, 0.1, 0.1], cells = [1, 1, 1] }\n"
               "material = { model = \"neo-hookean\", youngs_modulus = 1e5, poisson_ratio = 0.3, density = 1000.0 }\n"
               "[[body.pin]]\n", pin, "\n",
               "[[obstacle]]\n", obstacle, "\n",
               "[time]\nstep = 0.01\nduration = ", duration, "\n");
}

const std::string base_pin = "plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }";
const std::string top_pin = "plane = { point = [0.0, 0.0, 0.1], normal = [0.0, 0.0, 1.0] }";
const std::string falling_box = "type = \"box\"\ncenter = [0.05, 0.05, 0.2]\nsize = [0.3, 0.3, 0.1]\nvelocity = [0.0, 0.0, -1.0]";
const std::string rising_floor = "type = \"half-space\"\npoint = [0.0, 0.0, -0.05]\nnormal = [0.0, 0.0, 1.0]\nvelocity = [0.0, 0.0, 1.0]";
const std::string still_floor = "type = \"half-space\"\npoint = [0.0, 0.0, -0.05]\nnormal = [0.0, 0.0, 1.0]";
const std::string driven_down =
    "plane = { point = [0.0, 0.0, 0.1], normal = [0.0, 0.0, 1.0] }\nmotion = \"translate\"\ndisplacement = [0.0, 0.0, -0.3]\nstart = 0.0\nend = 0.2";

}  // namespace

TEST_CASE("squeezes the prescribed motions make impossible are refused before stepping, at the field, naming the "
          "obstacle, the body, the pinned vertex and the time", "[scenes]")
{
    // The box comes down on the top face at t = 0.05 s and reaches the pinned base at 0.15 s; the
    // floor rises to the free base at 0.05 s and to the pinned top at 0.15 s.
    CHECK_THROWS_WITH(testing::scene_from("squeeze_box", pinned_block(base_pin, falling_box, 0.2)),
                      Catch::Contains(":10:12: obstacle[0].velocity: moves the box onto pinned vertex") &&
                          Catch::Contains("of body 'body0' (body[0].pin[0]) at t = 0.15 s"));
    CHECK_THROWS_WITH(testing::scene_from("squeeze_floor", pinned_block(top_pin, rising_floor, 0.2)),
                      Catch::Contains("obstacle[0].velocity: moves the half-space onto pinned vertex") &&
                          Catch::Contains("at t = 0.15 s"));
    // The top face driven down 30 cm in 0.2 s (a ramp) into a still floor 5 cm under the base.
    CHECK_THROWS_WITH(testing::scene_from("squeeze_pin_into_floor", pinned_block(driven_down, still_floor, 0.2)),
                      Catch::Contains(": obstacle[0]: is reached by pinned vertex") &&
                          Catch::Contains("(body[0].pin[0], its prescribed motion) at t = "));
    // … and through a plate 2 mm thick (a thin box) 5 cm under the base: the pinned top reaches it at 0.1 s.
    const std::string plate = "type = \"box\"\ncenter = [0.05, 0.05, -0.051]\nsize = [2.0, 2.0, 0.002]";
    CHECK_THROWS_WITH(testing::scene_from("squeeze_pin_through_plate", pinned_block(driven_down, plate, 0.2)),
                      Catch::Contains(": obstacle[0]: is reached by pinned vertex") && Catch::Contains("at t = 0.1"));
}

TEST_CASE("the same squeezes ended before the pinned vertices are reached read and run, every tet upright",
          "[scenes]")
{
    const ScopedThreadCount one_thread(1);
    RunOptions options;
    options.print_models = false;
    const RunResult box = run_scene(testing::scene_from("squeeze_box_short", pinned_block(base_pin, falling_box, 0.14)), options);
    CHECK(box.steps == 14);
    const RunResult floor =
        run_scene(testing::scene_from("squeeze_floor_short", pinned_block(top_pin, rising_floor, 0.14)), options);
    CHECK(floor.steps == 14);
}

TEST_CASE("two floors closing on a free block: refused before stepping where their gap reaches 2 d-hat within the "
          "run, at the moving one's velocity field, and run where they stop wider", "[scenes]")
{
    // A 10 cm block resting 2 mm above a floor, a ceiling 20 cm up coming down at 0.5 m/s: the planes
    // are 2 d̂ = 2 mm apart at t = (0.2 − 0.002)/0.5 = 0.396 s.
    const auto two_floors = [](double duration) {
        return str("[[body]]\n"
                   "mesh = { generator = \"box\", size = [0.1, 0.1, 0.1], cells = [2, 2, 2], translate = [0.0, 0.0, 0.002] }\n"
                   "material = { model = \"neo-hookean\", youngs_modulus = 1e5, poisson_ratio = 0.3, density = 1000.0 }\n"
                   "[[obstacle]]\ntype = \"half-space\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n"
                   "[[obstacle]]\ntype = \"half-space\"\npoint = [0.0, 0.0, 0.2]\nnormal = [0.0, 0.0, -1.0]\n"
                   "velocity = [0.0, 0.0, -0.5]\n"
                   "[contact]\nactivation_distance = 1e-3\n"
                   "[time]\nstep = 0.01\nduration = ", duration, "\n");
    };
    CHECK_THROWS_WITH(testing::scene_from("two_floors_closing", two_floors(0.5)),
                      Catch::Contains(":12:12: obstacle[1].velocity: closes the gap between the half-spaces obstacle[0] "
                                      "and obstacle[1]") &&
                          Catch::Contains("at t = 0.396 s"));
    // The same, the floor rising instead: refused at the still ceiling's table, naming the mover.
    std::string rising = two_floors(0.5);
    rising.replace(rising.find("velocity = [0.0, 0.0, -0.5]\n"), 28, "");
    rising.replace(rising.find("normal = [0.0, 0.0, 1.0]\n"), 25, "normal = [0.0, 0.0, 1.0]\nvelocity = [0.0, 0.0, 0.5]\n");
    CHECK_THROWS_WITH(testing::scene_from("two_floors_rising", rising),
                      Catch::Contains(": obstacle[1]: the motion of obstacle[0] closes the gap between the half-spaces") &&
                          Catch::Contains("at t = 0.396 s"));
    // Ended at 0.22 s the ceiling stops 9 cm above the floor: the block is pressed by 1 cm and the
    // run goes on (the check refuses only what no body could survive).
    const ScopedThreadCount one_thread(1);
    RunOptions options;
    options.print_models = false;
    CHECK(run_scene(testing::scene_from("two_floors_pressing", two_floors(0.22)), options).steps == 22);
}

TEST_CASE("a jelly bunny dropped on the floor: at 1 kPa every model runs, at 10 Pa neo-Hookean runs and stable "
          "neo-Hookean is refused with advice that works", "[scenes][slow]")
{
    // The gallery's bunny_drop, quick (a lattice of 5 cubes), for 0.6 s: the fall, the squash and
    // the rest. Stable neo-Hookean's energy stays finite as a tet flattens, so at 10 Pa the impact
    // would flatten tets the volume filter refuses to cross; neo-Hookean's grows without bound.
    const ScopedThreadCount one_thread(1);
    RunOptions options;
    options.print_models = false;
    const auto jelly = [](const std::string& youngs, const std::string& model) {
        return read_scene(testing::gallery / "bunny_drop.toml",
                          {"body.material.youngs_modulus=" + youngs, "body.material.model=\"" + model + "\"",
                           "time.duration=0.6", "output.video=\"none\"", "output.png=false"},
                          true);
    };
    for (const char* model : {"neo-hookean", "stable-neo-hookean"})
        CHECK(run_scene(jelly("1e3", model), options).steps == 60);
    CHECK_THROWS_WITH(run_scene(jelly("10", "stable-neo-hookean"), options),
                      Catch::Contains("toward inside out") && Catch::Contains("use the material neo-hookean"));
    CHECK(run_scene(jelly("10", "neo-hookean"), options).steps == 60);
}
