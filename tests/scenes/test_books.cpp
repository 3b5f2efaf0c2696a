// The runner's books: one chapter 10 loop per body keeps them, and they must balance — work put in
// by loads and moving pins, divergence named, the comparison's reference converged, and the small
// defects found in review. docs/scenes.md#the-runner
#include "scenes/compare.hpp"
#include "scenes/runner.hpp"
#include "scenes/scene_text.hpp"

#include "12_hyperelastic_newton/materials.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

using namespace fem;
using namespace fem::scenes;
using Catch::Matchers::Contains;
using testing::scene_from;
using testing::gallery;

namespace {

/// A 0.2 m bar of 8 × 2 × 2 cubes along x, clamped at x = 0, with the extra TOML text given.
std::string bar(const std::string& model, const std::string& extra)
{
    return "[[body]]\nname = \"bar\"\n"
           "mesh = { generator = \"box\", size = [0.2, 0.04, 0.04], cells = [8, 2, 2] }\n"
           "material = { model = \"" + model + "\", youngs_modulus = 1e5, poisson_ratio = 0.3, density = 1000.0 }\n"
           "[[body.pin]]\nplane = { point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }\n" + extra;
}

}  // namespace

TEST_CASE("a scene that diverges on purpose is stopped at a named step of a named body", "[scenes]")
{
    // Symplectic Euler at dt = 10 ms on a bar whose explicit limit is well under 1 ms.
    const SceneSpec scene = scene_from("diverging", bar("linear", "[time]\nstep = 0.01\nduration = 1.0\n"
                                                                  "integrator = \"symplectic-euler\"\n"));
    CHECK_THROWS_WITH(run_positions(scene), Contains("body 'bar'") && Contains("diverged at step") &&
                                            Contains("symplectic Euler") && Contains("stability limit"));
}

TEST_CASE("a constant point load's work over a run is f . du, and it puts nothing in", "[scenes]")
{
    // The load's potential is chapter 10's W = -f_ext u: the work the load did is exactly f . du of
    // its vertices, and a load that never changes is no energy source (work in stays 0).
    const SceneSpec scene = scene_from("constant_load", "gravity = [0.0, 0.0, 0.0]\n" +
        bar("corotational", "[[body.load]]\ntype = \"point\"\nforce = [0.0, 0.5, -2.0]\n"
                            "plane = { point = [0.2, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }\n"
                            "[time]\nstep = 0.01\nduration = 0.3\n[output]\nframe_rate = 100\n"));
    const RunResult result = run_positions(scene);
    const std::vector<int>& loaded = scene.bodies[0].loads[0].select.vertices;
    const Eigen::Vector3d share = scene.bodies[0].loads[0].value / double(loaded.size());
    const MatrixX3d u = result.frames[0].back() - scene.bodies[0].mesh.V;
    double work = 0.0;
    for (int v : loaded)
        work += share.dot(u.row(v).transpose());
    const dynamics::StepRecord& last = result.records[0].back();
    CAPTURE(work, last.energies.gravitational, last.work_in);
    REQUIRE(work > 1e-4);
    CHECK(std::abs(-last.energies.gravitational - work) <= 1e-12 * work);
    CHECK(last.work_in == 0.0);
}

TEST_CASE("with the midpoint rule a scene's books balance to round-off: ramped loads, a turning clamp, damping", "[scenes]")
{
    // The midpoint rule on a linear body dissipates nothing itself: H(t) = H(0) + W_in - damping to
    // round-off, so a mis-booked load change or pin work shows as integrator dissipation.
    const std::string extra = "[[body.pin]]\nplane = { point = [0.2, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }\n"
                              "motion = \"rotate\"\naxis = [1.0, 0.0, 0.0]\ncenter = [0.2, 0.02, 0.02]\nangle = 20.0\n"
                              "start = 0.0\nend = 0.3\n"
                              "[[body.load]]\ntype = \"surface\"\ntraction = [0.0, 0.0, -200.0]\n"
                              "plane = { point = [0.0, 0.0, 0.04], normal = [0.0, 0.0, 1.0] }\nramp = 0.2\nuntil = 0.35\n"
                              "[time]\nstep = 0.005\nduration = 0.5\nintegrator = \"implicit-midpoint\"\n";
    for (const std::string damping : {"", "damping = { alpha = 0.0, beta = 0.002 }\n"}) {
        std::string text = bar("linear", extra);
        text.insert(text.find("[[body.pin]]"), damping);
        const SceneSpec scene = scene_from("midpoint_books", text);
        const RunResult result = run_positions(scene);
        double worst = 0.0, largest = 0.0;
        for (const dynamics::StepRecord& r : result.records[0]) {
            worst = std::max(worst, std::abs(r.integrator_dissipated));
            largest = std::max(largest, r.energies.magnitude());
        }
        const dynamics::StepRecord& last = result.records[0].back();
        CAPTURE(damping, worst, largest, last.work_in, last.damping_dissipated);
        REQUIRE(std::abs(last.work_in) > 1e-3 * largest);  // the clamp and the load did real work
        CHECK(worst <= 1e-9 * largest);
    }
}

TEST_CASE("the comparison's reference has converged: halving its own dt moves it less than any error it reports", "[scenes]")
{
    const SceneSpec scene = read_scene(gallery / "cantilever.toml", {}, true);
    const ModelComparison comparison = compare_models(scene, nullptr);
    REQUIRE(comparison.rows.size() == 6);
    CHECK(comparison.reference_time_step == Approx(scene.time_step / reference_refinement));
    for (const ModelError& row : comparison.rows) {
        CAPTURE(row.model, row.tet_max, comparison.reference_change);
        REQUIRE_FALSE(row.failed);
        CHECK(comparison.reference_change < row.tet_max);
    }
    // The stable neo-Hookean run at the scene's dt is not the reference: it carries backward
    // Euler's error at dt, which the comparison used to hide by comparing it with itself.
    CHECK(comparison.rows.front().model == "stable-neo-hookean");
    CHECK(comparison.rows.front().tet_max > 0.0);
}

TEST_CASE("a surface load whose vertices span no boundary triangle is refused, naming the load", "[scenes]")
{
    // Two vertices of the end face selected by a box: no boundary triangle has all three corners
    // in it, so the traction would apply nothing (it used to, silently).
    const SceneSpec scene = scene_from("empty_surface_load",
        bar("linear", "[[body.load]]\ntype = \"surface\"\ntraction = [0.0, 0.0, -100.0]\nbox = [[0.19, -0.001, -0.001], [0.21, 0.021, 0.001]]\n"
                      "[time]\nstep = 0.01\nduration = 0.1\n"));
    CHECK_THROWS_WITH(run_positions(scene), Contains("body[0].load[0]") && Contains("span no boundary triangle"));
}

TEST_CASE("the run's summary names the model it ran, for every fixed model", "[scenes]")
{
    for (const std::string model : {"linear", "corotational", "stvk", "neo-hookean", "stable-neo-hookean"}) {
        const SceneSpec scene = scene_from("summary", bar(model, "[time]\nstep = 0.01\nduration = 0.05\n"));
        const RunResult result = run_positions(scene);
        CHECK(describe_segments(result.segments[0]) == model + " 0-5");
    }
}

TEST_CASE("every model runs a damped scene, so --compare never refuses one", "[scenes][slow]")
{
    // Chapter 12's Newton step has Rayleigh damping too (D = alpha M + beta K at the step's start):
    // the comparison used to refuse damped scenes because its reference could not damp.
    std::string text = bar("linear", "[time]\nstep = 0.02\nduration = 0.2\n");
    text.insert(text.find("[[body.pin]]"), "damping = { alpha = 0.02, beta = 0.002 }\n");
    const SceneSpec scene = scene_from("damped_compare", text);
    const ModelComparison comparison = compare_models(scene, nullptr);
    for (const ModelError& row : comparison.rows) {
        CAPTURE(row.model, row.tet_max, comparison.reference_change);
        CHECK_FALSE(row.failed);
    }
    for (const std::string model : {"linear", "stable-neo-hookean"}) {
        const RunResult result = run_positions(scene, model);
        CAPTURE(model);
        CHECK(result.records[0].back().damping_dissipated > 0.0);
    }
}

TEST_CASE("mesh.scale applies to a generated box as to a mesh file", "[scenes]")
{
    // It was read, checked and then ignored for generator = "box".
    const SceneSpec scene = scene_from("scaled_box", "[[body]]\n"
        "mesh = { generator = \"box\", size = [1.0, 2.0, 3.0], cells = [1, 1, 1], scale = 0.1, translate = [1.0, 0.0, 0.0] }\n"
        "material = { model = \"linear\", youngs_modulus = 1e5, poisson_ratio = 0.3, density = 1000.0 }\n"
        "[[body.pin]]\nplane = { point = [1.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }\n");
    const MatrixX3d& V = scene.bodies[0].mesh.V;
    CHECK(V.colwise().minCoeff().isApprox(Eigen::RowVector3d(1.0, 0.0, 0.0)));
    CHECK(V.colwise().maxCoeff().isApprox(Eigen::RowVector3d(1.1, 0.2, 0.3)));
}

TEST_CASE("every hyperelastic material of chapter 12's registry is a model a scene can name", "[scenes]")
{
    for (const std::string& material : hyper::material_names()) {
        CAPTURE(material);
        const SceneSpec scene = scene_from("registered", bar(material, "[time]\nstep = 0.01\nduration = 0.02\n"),
                                           {"auto.hyperelastic=\"" + material + "\""});
        CHECK(describe_segments(run_positions(scene).segments[0]) == material + " 0-2");
    }
}
