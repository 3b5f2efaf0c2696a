// Model "auto": the deformation measures, the level they choose, and where a run switches.
// docs/scenes.md#model-auto
#include "scenes/runner.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

using namespace fem;
using namespace fem::scenes;

namespace {

const std::filesystem::path gallery = FEM_SCENES_DIR;

/// Runs a scene without files, keeping the positions of every step.
RunResult positions_of(const SceneSpec& scene, const std::string& model)
{
    RunOptions options;
    options.model = model;
    options.keep_positions = true;
    options.print_models = false;
    return run_scene(scene, options);
}

/// The cantilever of the gallery, small and short, one frame per step.
SceneSpec small_cantilever(std::vector<std::string> overrides)
{
    overrides.insert(overrides.end(), {"body.mesh.cells=[10, 1, 1]", "time.duration=0.5", "output.frame_rate=60"});
    return read_scene(gallery / "cantilever.toml", overrides);
}

}  // namespace

TEST_CASE("deformation measures of a rigid rotation: the angle, no strain, volume kept", "[scenes]")
{
    const TetMesh mesh = box_mesh(2, 1, 1, Eigen::Vector3d(0.2, 0.1, 0.1));
    for (double degrees : {1.0, 10.0, 45.0, 80.0}) {
        const double angle = degrees * std::acos(-1.0) / 180.0;
        const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
        const MatrixX3d x = mesh.V * R.transpose();
        const DeformationMeasures m = deformation_measures(mesh, x);
        CHECK(m.rotation == Approx(angle).epsilon(1e-12));
        CHECK(m.strain < 1e-13);
        CHECK(m.volume_ratio == Approx(1.0).epsilon(1e-13));
    }
}

TEST_CASE("deformation measures of a stretch: Green strain e + e^2/2, det F, no rotation", "[scenes]")
{
    const TetMesh mesh = box_mesh(1, 1, 1, Eigen::Vector3d::Ones());
    MatrixX3d x = mesh.V;
    x.col(0) *= 1.1;   // stretch x by 10 %
    x.col(2) *= 0.5;   // squash z to half
    const DeformationMeasures m = deformation_measures(mesh, x);
    CHECK(m.rotation < 1e-15);
    CHECK(m.strain == Approx(0.375).epsilon(1e-14));  // E = ½(F² − I) = diag(0.105, 0, −0.375)
    CHECK(m.volume_ratio == Approx(0.55));
}

TEST_CASE("choose_level: up at once, down only inside the hysteresis band", "[scenes]")
{
    AutoThresholds t;
    t.rotation = 0.2;
    t.strain = 0.1;
    t.volume_ratio = 0.5;
    t.hysteresis = 0.5;
    DeformationMeasures m;
    CHECK(choose_level(m, Level::linear, t) == Level::linear);
    m.rotation = 0.21;
    CHECK(choose_level(m, Level::linear, t) == Level::corotational);
    m.rotation = 0.15;  // below the threshold, above half of it: stays corotational
    CHECK(choose_level(m, Level::corotational, t) == Level::corotational);
    CHECK(choose_level(m, Level::linear, t) == Level::linear);
    m.rotation = 0.09;  // below half: back to linear
    CHECK(choose_level(m, Level::corotational, t) == Level::linear);
    m.strain = 0.11;
    CHECK(choose_level(m, Level::linear, t) == Level::hyperelastic);
    m.strain = 0.07;
    CHECK(choose_level(m, Level::hyperelastic, t) == Level::hyperelastic);
    m.strain = 0.04;
    CHECK(choose_level(m, Level::hyperelastic, t) == Level::linear);
    m.strain = 0.0;
    m.volume_ratio = 0.45;  // near inversion
    CHECK(choose_level(m, Level::linear, t) == Level::hyperelastic);
    m.volume_ratio = 0.7;  // inside 1 − 0.5 (1 − 0.5) = 0.75: stays
    CHECK(choose_level(m, Level::hyperelastic, t) == Level::hyperelastic);
}

TEST_CASE("auto gives the linear result exactly on a small-load scene", "[scenes]")
{
    const SceneSpec scene = small_cantilever({"gravity=[0.0, 0.0, -0.01]"});
    const RunResult linear = positions_of(scene, "linear"), automatic = positions_of(scene, "auto");
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
        {{}, Level::hyperelastic},                                              // the strain crosses first
        {{"auto.strain=0.9", "auto.volume_ratio=0.01"}, Level::corotational},  // only the rotation counts
    };
    for (const Case& c : cases) {
        const SceneSpec scene = small_cantilever(c.overrides);
        const RunResult linear = positions_of(scene, "linear");
        int crossing = -1;
        Level crossed = Level::linear;
        for (std::size_t k = 0; k < linear.frames[0].size() && crossing < 0; ++k) {
            crossed = choose_level(deformation_measures(scene.bodies[0].mesh, linear.frames[0][k]), Level::linear,
                                   scene.thresholds);
            if (crossed != Level::linear)
                crossing = static_cast<int>(k);
        }
        REQUIRE(crossing > 0);
        CHECK(crossed == c.expected);
        const RunResult automatic = positions_of(scene, "auto");
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
