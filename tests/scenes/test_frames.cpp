// How a scene's frames are drawn: obstacles in the picture where they are, the caption of every frame
// (scene, model, time, slow motion), and the colour range MotionRecorder gives a clipped field.
// docs/scenes.md#outputs
#include "scenes/frame_look.hpp"
#include "scenes/runner.hpp"
#include "scenes/scene_text.hpp"

#include "15_body_contact/mesh_obstacle.hpp"

#include "common/figures.hpp"
#include "common/motion.hpp"

#include <catch2/catch.hpp>

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

using namespace fem;
using namespace fem::scenes;
using testing::output;

namespace {


/// A 0.1 m cube 5 cm above the floor z = 0 (or with no obstacle, or above a ball), for `duration`
/// seconds at Δt = 0.01 s.
std::string cube_over(const std::string& obstacle, const std::string& duration = "0.5")
{
    return "title = \"cube\"\n[[body]]\n"
           "mesh = { generator = \"box\", size = [0.1, 0.1, 0.1], cells = [2, 2, 2], translate = [-0.05, -0.05, 0.05] }\n"
           "material = { model = \"stable-neo-hookean\", youngs_modulus = 1e5, poisson_ratio = 0.3, density = 500.0 }\n" +
           obstacle + "[time]\nstep = 0.01\nduration = " + duration + "\n[output]\nframe_rate = 50\ncolour = \"displacement\"\n";
}

const std::string floor_obstacle = "[[obstacle]]\ntype = \"half-space\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n";
const std::string ball_obstacle =
    "[[obstacle]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, -0.1]\nradius = 0.08\nvelocity = [0.05, 0.0, 0.0]\n";

/// Where the pixels of the obstacles' grey and of the body lie in a rendered frame: their counts and
/// mean rows (0 at the top) in the data's part of the picture (left of the colour bar, under the title).
struct FramePixels {
    long grey = 0, body = 0;
    double grey_row = 0.0, body_row = 0.0;
};

FramePixels frame_pixels(const std::filesystem::path& png)
{
    vtkNew<vtkPNGReader> reader;
    reader->SetFileName(png.c_str());
    reader->Update();
    int dims[3];
    reader->GetOutput()->GetDimensions(dims);
    vtkDataArray* pixels = reader->GetOutput()->GetPointData()->GetScalars();
    FramePixels found;
    for (vtkIdType i = 0; i < pixels->GetNumberOfTuples(); ++i) {
        const int x = int(i % dims[0]), row = dims[1] - 1 - int(i / dims[0]);
        if (x > 0.8 * dims[0] || row < 0.2 * dims[1])
            continue;
        const double r = pixels->GetComponent(i, 0), g = pixels->GetComponent(i, 1), b = pixels->GetComponent(i, 2);
        const double high = std::max({r, g, b}), low = std::min({r, g, b});
        if (high - low < 8.0 && high > 80.0 && high < 215.0) {  // the obstacles' grey, lit (not white, not black)
            ++found.grey;
            found.grey_row += row;
        } else if (high - low > 40.0) {  // the body: viridis, never grey
            ++found.body;
            found.body_row += row;
        }
    }
    found.grey_row /= std::max(found.grey, 1L);
    found.body_row /= std::max(found.body, 1L);
    return found;
}

/// The scene's body at rest as a frame (displacement zero), drawn as the runner draws frame 0 of
/// the scene (frame_view, its obstacles under the body's box) into png.
void draw_rest_frame(const SceneSpec& scene, const std::filesystem::path& png)
{
    const BodySpec& body = scene.bodies.front();
    const io::MeshData frame = io::displaced_mesh(body.mesh.V, body.mesh.T, MatrixX3d::Zero(body.mesh.V.rows(), 3));
    fig::RenderOptions view = frame_view(scene);
    view.show_edges = false;
    view.range = std::pair{0.0, 1.0};
    std::array<double, 6> box = fig::empty_bounds();
    fig::grow_bounds(box, frame.points);
    view.props = obstacle_props(scene, box, 0.0);
    for (const fig::Prop& prop : view.props)
        fig::grow_bounds(box, prop.shape.points);
    view.frame_bounds = box;
    view.title = frame_title(scene, "stable neo-Hookean", 0.0);
    REQUIRE(fig::render_mesh_png(png, frame, view));
}

}  // namespace

TEST_CASE("obstacles are drawn in the frames: the floor and a ball below the body, nothing without them", "[scenes]")
{
    if (!fig::display_available()) {
        WARN("SKIPPED: no X display: run the tests under xvfb-run -a to check the frames' pictures");
        return;
    }
    struct Case {
        std::string name, obstacle;
    };
    for (const Case& c : {Case{"none", ""}, Case{"floor", floor_obstacle}, Case{"ball", ball_obstacle}}) {
        CAPTURE(c.name);
        const SceneSpec scene = testing::scene_from("frame_" + c.name, cube_over(c.obstacle));
        const std::filesystem::path png = output / ("frame_" + c.name + ".png");
        draw_rest_frame(scene, png);
        const FramePixels pixels = frame_pixels(png);
        CHECK(pixels.body > 1000);
        if (c.obstacle.empty()) {
            CHECK(pixels.grey < 50);  // no grey: only anti-aliased edges could come near it
        } else {
            CHECK(pixels.grey > 5000);
            CHECK(pixels.grey_row > pixels.body_row);  // under the body (the camera's up is +z)
        }
    }
}

TEST_CASE("obstacle_props: a floor patch under the body's box, a ball where it is at the frame's time", "[scenes]")
{
    const SceneSpec scene = testing::scene_from("props", cube_over(floor_obstacle + ball_obstacle));
    const std::array<double, 6> box{-0.05, 0.05, -0.05, 0.05, 0.05, 0.15};
    for (double t : {0.0, 0.5}) {
        const std::vector<fig::Prop> props = obstacle_props(scene, box, t);
        REQUIRE(props.size() == 2);
        const MatrixX3d& patch = props[0].shape.points;
        CHECK(patch.col(2).cwiseAbs().maxCoeff() < 1e-15);  // on the plane z = 0
        // The box's footprint grown by a fifth of its diagonal, sqrt(0.03)/5, each way.
        const double margin = 0.2 * std::sqrt(0.03);
        CHECK(patch.col(0).minCoeff() == Approx(-0.05 - margin));
        CHECK(patch.col(1).maxCoeff() == Approx(0.05 + margin));
        // The ball: every point at its radius from its centre at time t, (0.05 t, 0, −0.1).
        const Eigen::RowVector3d centre(0.05 * t, 0.0, -0.1);
        const MatrixX3d& ball = props[1].shape.points;
        CHECK(((ball.rowwise() - centre).rowwise().norm().array() - 0.08).abs().maxCoeff() < 1e-12);
        CHECK(ball.col(0).mean() == Approx(0.05 * t).margin(1e-12));
    }
}

TEST_CASE("obstacle_props: a mesh obstacle is its own triangles where it stands at the frame's time", "[scenes]")
{
    SceneSpec scene;
    TriMesh triangle;
    triangle.V.resize(3, 3);
    triangle.V << 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0;
    triangle.F.resize(1, 3);
    triangle.F << 0, 1, 2;
    scene.obstacles.push_back(
        {"mesh", std::make_shared<contact::MeshObstacle>(triangle, 0.0, Eigen::Vector3d(0.0, 0.0, -0.5)), {}});
    const std::vector<fig::Prop> props = obstacle_props(scene, {0.0, 1.0, 0.0, 1.0, 0.0, 1.0}, 2.0);
    REQUIRE(props.size() == 1);
    CHECK(props[0].shape.cells == MatrixXiR(triangle.F));
    CHECK(props[0].shape.points.col(2).isConstant(-1.0));  // moved by t w = (0, 0, -1)
    CHECK(props[0].shape.points.leftCols(2) == triangle.V.leftCols(2));
}

TEST_CASE("the caption: scene, the model in use, the time and the slow motion the video plays at", "[scenes]")
{
    const SceneSpec scene = testing::scene_from("caption", cube_over(""));
    // 50 steps, a frame every 2 (50 frames/s at 0.01 s): 26 frames, played over 5 s at 5.2 frames/s,
    // 50/5.2 = 9.6 times slower than they happened.
    CHECK(frame_count(scene) == 26);
    CHECK(slow_motion(scene) == Approx(50.0 / 5.2));
    CHECK(frame_caption(scene, "stable neo-Hookean", 0.5) ==
          "caption \u00B7 stable neo-Hookean \u00B7 t = 0.5 s \u00B7 slow motion \u00D79.6");
    CHECK(frame_title(scene, "auto: corotational", 1.0 / 3.0) ==
          "cube\ncaption \u00B7 auto: corotational \u00B7 t = 0.33 s \u00B7 slow motion \u00D79.6");
    // Long enough to play at its own rate: no slow motion said.
    const SceneSpec real_time = testing::scene_from("real_time", cube_over("", "6.0"));
    CHECK(frame_caption(real_time, "linear", 2.0) == "real_time \u00B7 linear \u00B7 t = 2 s");
    CHECK(model_label("stable-neo-hookean") == "stable neo-Hookean");
    CHECK(model_label("stvk") == "StVK");
}

TEST_CASE("MotionRecorder's clipped colour range: the pooled percentile on top, the run's largest value on the bar", "[scenes]")
{
    // Three frames of a scalar field; every second one kept for the PNGs (frames 0 and 2). The kept
    // frames hold 1 … 100 (the 90th percentile by nearest rank: 90); the frame in between, not
    // kept, holds the run's spike (5000), which sets the whole run's range but not the clipped top.
    io::MotionRecorder recorder(output / "clipped" / "clipped.pvd", 2);
    const auto frame_with = [](double first, double spike) {
        io::MeshData frame;
        frame.points.resize(50, 3);
        for (int i = 0; i < 50; ++i)
            frame.points.row(i) << i, (i * 7) % 5, (i * 3) % 4;
        frame.cells.resize(1, 4);
        frame.cells << 0, 1, 2, 3;
        frame.point_data.push_back({io::displacement_field, Eigen::MatrixXd::Zero(50, 3)});
        Eigen::MatrixXd values(50, 1);
        for (int i = 0; i < 50; ++i)
            values(i, 0) = first + i;
        values(49, 0) = std::max(values(49, 0), spike);
        frame.point_data.push_back({"stress", values});
        return frame;
    };
    recorder.add(0.0, frame_with(1.0, 0.0));     // 1 … 50
    recorder.add(0.1, frame_with(2.0, 5000.0));  // 2 … 50, 5000
    recorder.add(0.2, frame_with(51.0, 0.0));    // 51 … 100
    REQUIRE(recorder.kept_frames() == 2);
    fig::RenderOptions options;
    options.field = "stress";
    options.unit = "Pa";
    options.clip_percentile = 90.0;
    const auto [range, note] = recorder.colour_range(options);
    CHECK(range.first == 1.0);
    CHECK(range.second == 90.0);
    CHECK(note.find("range of all 3 frames") != std::string::npos);
    CHECK(note.find("clipped at the 90th percentile") != std::string::npos);
    CHECK(note.find("max 5000 Pa") != std::string::npos);
    // Not clipped: the whole run's range, spike included, and no clip note.
    options.clip_percentile = 100.0;
    const auto [whole, plain] = recorder.colour_range(options);
    CHECK(whole == std::pair{1.0, 5000.0});
    CHECK(plain == "range of all 3 frames");
}
