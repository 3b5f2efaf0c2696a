// Model "auto": the deformation measures, the level they choose, and where a run switches.
// docs/scenes.md#model-auto
#include "scenes/runner.hpp"
#include "scenes/scene_text.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <filesystem>
#include <fstream>

using namespace fem;
using namespace fem::scenes;
using testing::gallery;

namespace {

/// The cantilever of the gallery, small and short, one frame per step.
SceneSpec small_cantilever(std::vector<std::string> overrides)
{
    overrides.insert(overrides.end(), {"body.mesh.cells=[10, 1, 1]", "time.duration=0.5", "output.frame_rate=60"});
    return read_scene(gallery / "cantilever.toml", overrides);
}

}  // namespace

TEST_CASE("deformation measures of a rigid rotation at every angle: ghost strain 1 - cos(angle), no strain", "[scenes]")
{
    // The skew-part measure asin |axial(skew F)| reads pi - angle past 90 degrees and 0 at 180: a
    // half-turned tet looked unrotated. The ghost strain grows all the way.
    const TetMesh mesh = box_mesh(2, 1, 1, Eigen::Vector3d(0.2, 0.1, 0.1));
    const AutoThresholds t;
    for (double degrees : {1.0, 10.0, 45.0, 80.0, 91.0, 135.0, 170.0, 180.0}) {
        const double angle = degrees * std::acos(-1.0) / 180.0;
        const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
        const MatrixX3d x = mesh.V * R.transpose();
        const DeformationMeasures m = deformation_measures(mesh, x, t);
        CAPTURE(degrees, m.ghost, m.strain, m.volume_change, m.linear_error);
        CHECK(std::abs(m.ghost - (1.0 - std::cos(angle))) <= 1e-14);
        CHECK(m.strain < 1e-14);
        CHECK(m.volume_change < 1e-14);
        // No strain, so only the rotation's ghost counts: linear up to auto.rotation (5 degrees), never beyond.
        const Level level = choose_level(m, Level::linear, t);
        CHECK(level == (degrees < 5.0 ? Level::linear : Level::corotational));
        CHECK(choose_level(m, Level::corotational, t) == (degrees < 2.5 ? Level::linear : Level::corotational));
    }
}

TEST_CASE("deformation measures of a stretch: Green strain e + e^2/2, ghost strain H^T H / 2, det F", "[scenes]")
{
    const TetMesh mesh = box_mesh(1, 1, 1, Eigen::Vector3d::Ones());
    MatrixX3d x = mesh.V;
    x.col(0) *= 1.1;   // stretch x by 10 %
    x.col(2) *= 0.5;   // squash z to half
    const AutoThresholds t;
    const DeformationMeasures m = deformation_measures(mesh, x, t);
    CHECK(m.strain == Approx(0.375).epsilon(1e-14));  // E = ½(F² − I) = diag(0.105, 0, −0.375)
    CHECK(m.ghost == Approx(0.125).epsilon(1e-14));   // ½ HᵀH = diag(0.005, 0, 0.125)
    CHECK(m.volume_change == Approx(0.45));           // det F = 0.55
    CHECK(m.linear_error == Approx(0.125 / (t.ghost_ratio * 0.375 + 1.0 - std::cos(t.rotation))).epsilon(1e-13));
    CHECK(choose_level(m, Level::linear, t) == Level::hyperelastic);
}

TEST_CASE("the ghost strain is held relative to the real strain: a strained rotation stays linear longer", "[scenes]")
{
    // A stretch of 4 % along x and then a rotation by 9 degrees: an unstrained 9 degrees is past the
    // 5 degrees auto.rotation allows, but against a 4 % strain the ghost is a small part.
    const TetMesh mesh = box_mesh(1, 1, 1, Eigen::Vector3d::Ones());
    const AutoThresholds t;
    const Eigen::Matrix3d R = Eigen::AngleAxisd(9.0 * std::acos(-1.0) / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const MatrixX3d rotated = mesh.V * R.transpose();
    MatrixX3d stretched = mesh.V;
    stretched.col(0) *= 1.04;
    const DeformationMeasures alone = deformation_measures(mesh, rotated, t);
    const DeformationMeasures both = deformation_measures(mesh, stretched * R.transpose(), t);
    CAPTURE(alone.linear_error, both.linear_error, both.strain);
    CHECK(choose_level(alone, Level::linear, t) == Level::corotational);
    CHECK(both.strain < t.strain);
    CHECK(both.linear_error < alone.linear_error);
}

TEST_CASE("choose_level: up at once, down only inside the hysteresis band", "[scenes]")
{
    AutoThresholds t;
    t.strain = 0.1;
    t.volume_ratio = 0.5;
    t.hysteresis = 0.5;
    DeformationMeasures m;
    CHECK(choose_level(m, Level::linear, t) == Level::linear);
    m.linear_error = 1.05;
    CHECK(choose_level(m, Level::linear, t) == Level::corotational);
    m.linear_error = 0.75;  // below the threshold, above half of it: stays corotational
    CHECK(choose_level(m, Level::corotational, t) == Level::corotational);
    CHECK(choose_level(m, Level::linear, t) == Level::linear);
    m.linear_error = 0.45;  // below half: back to linear
    CHECK(choose_level(m, Level::corotational, t) == Level::linear);
    m.strain = 0.11;
    CHECK(choose_level(m, Level::linear, t) == Level::hyperelastic);
    m.strain = 0.07;
    CHECK(choose_level(m, Level::hyperelastic, t) == Level::hyperelastic);
    m.strain = 0.04;
    CHECK(choose_level(m, Level::hyperelastic, t) == Level::linear);
    m.strain = 0.0;
    m.volume_change = 0.55;  // near inversion: beyond 1 − 0.5
    CHECK(choose_level(m, Level::linear, t) == Level::hyperelastic);
    m.volume_change = 0.3;  // above 0.5 (1 − 0.5) = 0.25: stays
    CHECK(choose_level(m, Level::hyperelastic, t) == Level::hyperelastic);
    m.volume_change = 0.2;
    CHECK(choose_level(m, Level::hyperelastic, t) == Level::linear);
}

TEST_CASE("the volume rule fires before the strain rule under an even squeeze", "[scenes]")
{
    // An even squeeze to 96.5 % along each axis: Green strain 0.034 (below 5 %), volume 0.899 (more
    // than the 10 % change corotational allows). The old det F < 0.5 rule could never fire first.
    const TetMesh mesh = box_mesh(1, 1, 1, Eigen::Vector3d::Ones());
    const AutoThresholds t;
    const DeformationMeasures m = deformation_measures(mesh, 0.965 * mesh.V, t);
    CAPTURE(m.strain, m.volume_change);
    CHECK(m.strain < t.strain);
    CHECK(choose_level(m, Level::linear, t) == Level::hyperelastic);
}

TEST_CASE("auto gives the linear result exactly on a small-load scene", "[scenes]")
{
    const SceneSpec scene = small_cantilever({"gravity=[0.0, 0.0, -0.01]"});
    const RunResult linear = run_positions(scene, "linear"), automatic = run_positions(scene, "auto");
    REQUIRE(automatic.segments.size() == 1);
    REQUIRE(automatic.segments[0].size() == 1);
    CHECK(automatic.segments[0][0].level == Level::linear);
    CHECK(automatic.segments[0][0].last_step == 30);
    REQUIRE(linear.frames[0].size() == 31);
    REQUIRE(automatic.frames[0].size() == 31);
    for (std::size_t f = 0; f < linear.frames[0].size(); ++f)
        CHECK((linear.frames[0][f].array() == automatic.frames[0][f].array()).all());  // to the last bit
    CHECK(linear.frames[0].back().col(2).minCoeff() < -1e-7);  // it did sag
}

TEST_CASE("auto switches at the first step whose linear state crosses a threshold", "[scenes]")
{
    // The switch points, found independently: the measures of the fixed linear run, step by step.
    struct Case {
        std::vector<std::string> overrides;
        Level expected;
    };
    const std::vector<Case> cases{
        {{}, Level::corotational},                   // a bending beam: its rotation's ghost strain crosses first
        {{"auto.rotation=89"}, Level::hyperelastic},  // a ghost floor of 1 - cos 89 degrees: the strain crosses first
    };
    for (const Case& c : cases) {
        const SceneSpec scene = small_cantilever(c.overrides);
        const RunResult linear = run_positions(scene, "linear");
        int crossing = -1;
        Level crossed = Level::linear;
        for (std::size_t k = 0; k < linear.frames[0].size() && crossing < 0; ++k) {
            crossed = choose_level(deformation_measures(scene.bodies[0].mesh, linear.frames[0][k], scene.thresholds),
                                   Level::linear, scene.thresholds);
            if (crossed != Level::linear)
                crossing = static_cast<int>(k);
        }
        REQUIRE(crossing > 0);
        CHECK(crossed == c.expected);
        const RunResult automatic = run_positions(scene, "auto");
        const std::vector<Segment>& segments = automatic.segments[0];
        REQUIRE(segments.size() >= 2);
        CHECK(segments[0].level == Level::linear);
        CHECK(segments[0].last_step == crossing);  // the state of step k decides step k + 1
        CHECK(segments[1].first_step == crossing + 1);
        CHECK(segments[1].level == c.expected);
        for (int k = 0; k <= crossing; ++k)
            CHECK((linear.frames[0][static_cast<std::size_t>(k)].array() ==
                   automatic.frames[0][static_cast<std::size_t>(k)].array()).all());
        CHECK((linear.frames[0][static_cast<std::size_t>(crossing + 1)].array() !=
               automatic.frames[0][static_cast<std::size_t>(crossing + 1)].array()).any());
    }
}

TEST_CASE("a cube turned by half a turn stays free of ghost forces under auto", "[scenes]")
{
    // The cube's bottom face turns by 180 degrees about the vertical axis through its centre over
    // 1 s and holds: the cube turns along. Linear elasticity sees ghost strains up to 1 - cos 180 = 2
    // and tears it apart; auto must see them too at every angle (the old skew measure read 0 at 180
    // degrees and dropped back to linear) and end where the corotational run ends.
    const std::filesystem::path file = std::filesystem::path(FEM_TEST_OUTPUT_DIR) / "half_turn.toml";
    std::filesystem::create_directories(file.parent_path());
    std::ofstream(file) << "gravity = [0.0, 0.0, 0.0]\n[[body]]\n"
                           "mesh = { generator = \"box\", size = [0.1, 0.1, 0.1], cells = [2, 2, 2] }\n"
                           "material = { model = \"auto\", youngs_modulus = 1e5, poisson_ratio = 0.3, density = 1000.0 }\n"
                           "[[body.pin]]\nplane = { point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }\n"
                           "motion = \"rotate\"\naxis = [0.0, 0.0, 1.0]\ncenter = [0.05, 0.05, 0.0]\nangle = 180.0\n"
                           "start = 0.0\nend = 1.0\n"
                           "[time]\nstep = 0.02\nduration = 1.5\n";
    const SceneSpec scene = read_scene(file);
    const MatrixX3d& X = scene.bodies[0].mesh.V;
    MatrixX3d turned = X;  // the rest shape turned by 180 degrees about the axis
    turned.col(0) = 0.1 - X.col(0).array();
    turned.col(1) = 0.1 - X.col(1).array();
    const auto error = [&](const RunResult& r) { return (r.frames[0].back() - turned).rowwise().norm().maxCoeff(); };
    const RunResult automatic = run_positions(scene, "auto"), corotational = run_positions(scene, "corotational"),
                    linear = run_positions(scene, "linear");
    CAPTURE(describe_segments(automatic.segments[0]), error(automatic), error(corotational), error(linear));
    CHECK(error(linear) > 0.02);         // the ghost forces: centimetres on a 10 cm cube
    CHECK(error(corotational) < 2e-3);   // the turn itself, and a little swing left
    CHECK(error(automatic) < 2e-3);
    for (const Segment& segment : automatic.segments[0])  // never linear once the turn is under way
        CHECK((segment.level != Level::linear || segment.last_step < 10));
}

TEST_CASE("every gallery scene's first switch is where its linear run first crosses a threshold", "[scenes][slow]")
{
    // The switch points reproduced independently for every body that runs auto in the gallery's
    // quick runs: the measures of the fixed linear run, step by step, say where auto must leave linear.
    for (const std::string name : {"cantilever", "twisted_bar", "bunny", "stiff_soft_pair"}) {
        const SceneSpec scene = read_scene(gallery / (name + ".toml"), {"output.frame_rate=60"}, true);
        REQUIRE(steps_per_frame(scene) == 1);
        const RunResult linear = run_positions(scene, "linear"), automatic = run_positions(scene);
        for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
            if (scene.bodies[b].model != "auto")
                continue;
            int crossing = -1;
            for (std::size_t k = 0; k < linear.frames[b].size() && crossing < 0; ++k)
                if (choose_level(deformation_measures(scene.bodies[b].mesh, linear.frames[b][k], scene.thresholds),
                                 Level::linear, scene.thresholds) != Level::linear)
                    crossing = static_cast<int>(k);
            const std::vector<Segment>& segments = automatic.segments[b];
            CAPTURE(name, scene.bodies[b].name, crossing, describe_segments(segments));
            REQUIRE(segments.front().level == Level::linear);
            if (crossing < 0) {  // never crosses within the quick run: auto stays linear throughout
                CHECK(segments.size() == 1);
                continue;
            }
            CHECK(segments.front().last_step == crossing);  // the state of step k decides step k + 1
            REQUIRE(segments.size() >= 2);
            CHECK(segments[1].first_step == crossing + 1);
        }
    }
}
