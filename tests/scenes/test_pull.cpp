// The live view's pull (scene_conditions.hpp's Pull), through the runner's RunOptions::pull as the
// live view's mouse drives it: the pulled vertex follows the pointer, the spring's work is booked as
// work put in, and the body settles again once it is released.
#include "scenes/runner.hpp"
#include "scenes/scene_text.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace fem;
using namespace fem::scenes;

namespace {

/// A damped cantilever with no gravity, at rest: any motion is the pull's.
SceneSpec resting_beam(const std::string& model)
{
    return testing::scene_from("pulled_beam_" + model,
                               "gravity = [0.0, 0.0, 0.0]\n[[body]]\nname = \"beam\"\n"
                               "mesh = { generator = \"box\", size = [0.2, 0.02, 0.02], cells = [8, 1, 1] }\n"
                               "material = { model = \"" + model + "\", youngs_modulus = 1e5, poisson_ratio = 0.3, "
                               "density = 1000.0 }\ndamping = { alpha = 0.02, beta = 0.02 }\n"
                               "[[body.pin]]\nplane = { point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }\n"
                               "[time]\nstep = \"1/60\"\nduration = 3.0\n");
}

}  // namespace

TEST_CASE("the mouse's pull: the vertex follows the pointer, its work is booked, and the body settles once released",
          "[scenes]")
{
    for (const std::string model : {"corotational", "stable-neo-hookean"}) {
        CAPTURE(model);
        const SceneSpec scene = resting_beam(model);
        const MatrixX3d& rest = scene.bodies[0].mesh.V;
        Eigen::Index tip = 0;  // the vertex farthest from the pinned end
        rest.col(0).maxCoeff(&tip);
        const Eigen::Vector3d target = rest.row(tip).transpose() + Eigen::Vector3d(0.0, 0.0, 0.04);
        const int held = 60;  // the pointer holds the vertex 4 cm above its rest place for 1 s, then lets go
        int steps_asked = 0;
        RunOptions options;
        options.keep_positions = true;
        options.print_models = false;
        options.pull = [&] {
            PullRequest pull;
            if (++steps_asked <= held)
                pull = {0, static_cast<int>(tip), target};
            return pull;
        };
        const RunResult result = run_scene(scene, options);
        REQUIRE(result.steps == 180);
        const int every = steps_per_frame(scene);
        const auto tip_at = [&](int step) {
            return Eigen::Vector3d(result.frames[0].at(static_cast<std::size_t>(step / every)).row(tip).transpose());
        };
        const auto& records = result.records[0];
        // Held: the tip has gone a good part of the way to the pointer (the beam's stiffness holds it
        // back: its spring, 3EI/L³ = 0.5 N/m, against the pull's k = M (2π · 1 Hz)² = 3.2 N/m).
        const double rise = tip_at(held).z() - rest(tip, 2);
        CHECK((tip_at(held) - target).norm() < 0.6 * 0.04);
        // The spring's work is the only energy put in, and it is put in while the pointer holds.
        CHECK(records.at(held).work_in > 0.0);
        CHECK(records.back().work_in == Approx(records.at(held + 1).work_in).epsilon(1e-12));
        // The books balance: what the integrator removed is a share of what was put in, never negative
        // beyond round-off (chapter 10's loop would have failed the run on a rise).
        CHECK(records.back().integrator_dissipated > -1e-9 * records.back().work_in);
        // Released: damped, the beam falls back to rest.
        CHECK(std::abs(tip_at(180).z() - rest(tip, 2)) < 0.1 * rise);
        CHECK(records.back().energies.kinetic < 1e-3 * records.at(held).work_in);
    }
}

TEST_CASE("a pull is refused on a vertex the body does not have, or with a stiffness that is not > 0", "[scenes]")
{
    const SceneSpec scene = resting_beam("corotational");
    RunOptions options;
    options.print_models = false;
    options.pull = [] { return PullRequest{0, 100000, Eigen::Vector3d::Zero()}; };
    CHECK_THROWS_WITH(run_scene(scene, options), Catch::Contains("pull: vertex 100000 is not a vertex of the body"));
    options.pull = [] { return PullRequest{0, 0, Eigen::Vector3d::Zero()}; };
    options.pull_stiffness = -1.0;
    CHECK_THROWS_WITH(run_scene(scene, options), Catch::Contains("pull: the stiffness must be a number > 0 N/m"));
}
