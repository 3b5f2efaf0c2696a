// The scenes' path check ([contact] check_path, fem_scene --check-path; issue 48 item 3): every
// segment of every step's path between bodies proven free of crossings on the gallery's bodies
// against bodies made harder — the bar coiled ±720° and the two bunnies thrown at 5 m/s each — and
// the field refused where no bodies meet. docs/scenes.md#bodies-against-bodies
#include "scene_text.hpp"

#include "scenes/runner.hpp"

#include "common/error.hpp"
#include "common/parallel.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <string>
#include <vector>

using namespace fem;
using namespace fem::scenes;

namespace {

/// The gallery scene `name`, --quick, with overrides and the path check on, run writing nothing on
/// one thread (a few hundred tets: threads cost more than they save, docs/engineering.md).
RunResult run_checked(const std::string& name, std::vector<std::string> overrides)
{
    const ScopedThreadCount one_thread(1);
    overrides.push_back("contact.check_path=true");
    const std::filesystem::path file = std::filesystem::path(FEM_SCENES_DIR) / (name + ".toml");
    RunOptions options;
    options.print_models = false;
    return run_scene(read_scene(file, overrides, true), options);
}

}  // namespace

TEST_CASE("the path check proves every segment of the bar coiled +-720 degrees and of two bunnies thrown at "
          "5 m/s each", "[scenes][bodies][slow]")
{
    // The coil: both ends turned twice as far in half the time, until the loop lies on the bar (the
    // closest pairs come within 10 nm of each other soon after).
    const RunResult coil = run_checked("bar_coil", {"body.pin.0.angle=-720", "body.pin.1.angle=720", "body.pin.0.end=0.75",
                                                    "body.pin.1.end=0.75", "time.duration=0.45"});
    CHECK(coil.steps == 90);
    CHECK(coil.path_segments > coil.steps);  // Newton's iterates, not one chord a step
    CHECK(coil.path_pair_tests > 0);
    // The bunnies, 2 cm apart, closing at 10 m/s: they meet in the first step.
    const RunResult bunnies = run_checked(
        "two_bunnies", {"body.0.initial_velocity=[5.0, 0.0, 0.0]", "body.1.initial_velocity=[-5.0, 0.0, 0.0]",
                        "time.duration=0.02"});
    CHECK(bunnies.steps == 4);
    CHECK(bunnies.path_segments > bunnies.steps);
}

TEST_CASE("[contact] check_path: read, and refused where no bodies meet", "[scenes][bodies]")
{
    const std::filesystem::path file = std::filesystem::path(FEM_SCENES_DIR) / "cantilever.toml";
    CHECK_THROWS_WITH(read_scene(file, {"contact.check_path=true"}, true),
                      Catch::Contains("contact.check_path") && Catch::Contains("the path check needs bodies that meet"));
    CHECK_THROWS_WITH(read_scene(file, {"contact.check_path=1"}, true), Catch::Contains("contact.check_path"));
    const std::filesystem::path coil = std::filesystem::path(FEM_SCENES_DIR) / "bar_coil.toml";
    CHECK(read_scene(coil, {"contact.check_path=true"}, true).contact.check_path);
    CHECK_FALSE(read_scene(coil, {}, true).contact.check_path);
}
