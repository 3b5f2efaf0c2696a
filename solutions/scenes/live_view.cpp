// How a scene's frames are drawn, and the live view. docs/scenes.md#the-live-view
#include "scenes/live_view.hpp"

#include "scenes/run_outputs.hpp"
#include "scenes/runner.hpp"

#include "12_hyperelastic_newton/materials.hpp"

#include "common/error.hpp"
#include "common/interrupt.hpp"
#include "common/motion.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <iostream>
#include <thread>

namespace fem::scenes {

namespace {

/// The unit of a frame field (scene_file.hpp's OutputSpec::fields), for the colour bar.
std::string unit_of(const std::string& field)
{
    return field == "displacement" ? "m" : field == "velocity" ? "m/s" : field == "von Mises stress" ? "Pa" : "";
}

/// The percentile a frame field's colour range is clipped at (RenderOptions::clip_percentile): the
/// stress at 99, as it concentrates in the few tets at a pin or a contact, whose peak would set the
/// scale and leave the rest of the body one colour (the hanging cube's corners: 6.65·10⁴ Pa); the
/// others at 100 (not clipped).
double clip_percentile_of(const std::string& field)
{
    return field == "von Mises stress" ? 99.0 : 100.0;
}

}  // namespace

fig::RenderOptions frame_view(const SceneSpec& scene)
{
    const OutputSpec& out = scene.output;
    fig::RenderOptions view;
    view.title = scene.title;
    view.field = out.colour;
    view.unit = unit_of(out.colour);
    view.clip_percentile = clip_percentile_of(out.colour);
    view.view_direction = {out.view_direction.x(), out.view_direction.y(), out.view_direction.z()};
    view.view_up = {out.view_up.x(), out.view_up.y(), out.view_up.z()};
    view.width = out.width;
    view.height = out.height;
    view.scale = 1;  // the scene file's pixels: the live window must fit the screen and match the PNGs
    view.frame_bounds = out.frame_box;
    view.range = out.colour_range;
    view.data_under_title = true;  // a title of two or three lines (frame_title) over the body
    return view;
}

std::string model_label(const std::string& model)
{
    for (const hyper::MaterialNames& material : hyper::material_descriptions())
        if (material.name == model)
            return material.label;
    return model;
}

double slow_motion(const SceneSpec& scene)
{
    return scene.output.frame_rate / video_frame_rate(frame_count(scene), scene.output);
}

std::string frame_caption(const SceneSpec& scene, const std::string& models, double time)
{
    std::string caption = str(scene.file.stem().string(), " \u00B7 ", models, " \u00B7 ", io::time_label(time));
    const double slow = std::round(10.0 * slow_motion(scene)) / 10.0;
    if (slow > 1.0)
        caption += str(" \u00B7 slow motion \u00D7", slow);
    return caption;
}

std::string frame_title(const SceneSpec& scene, const std::string& models, double time)
{
    std::string title = str(scene.title, "\n", frame_caption(scene, models, time));
    if (scene.output.warp != 1.0)
        title += "\n" + io::warp_note(scene.output.warp);
    return title;
}

std::vector<fig::Prop> obstacle_props(const SceneSpec& scene, const std::array<double, 6>& body_box, double time)
{
    std::vector<fig::Prop> props;
    for (const ObstacleSpec& spec : scene.obstacles) {
        const TriMesh drawn = spec.obstacle->surface_at(body_box, time);
        fig::Prop prop;
        prop.shape.points = drawn.V;
        prop.shape.cells = drawn.F;
        props.push_back(std::move(prop));
    }
    return props;
}

// --- LiveView -------------------------------------------------------------------------------------

LiveView::LiveView(const SceneSpec& scene, std::map<int, std::filesystem::path> screenshots)
    : scene_(scene), window_(frame_view(scene), str("fem_scene: ", scene.title)), screenshots_(std::move(screenshots)),
      name_(str("fem_scene: ", scene.title))
{
    fields_ = {scene.output.colour};
    for (const std::string& field : scene.output.fields)
        if (field != scene.output.colour)
            fields_.push_back(field);
    if (scene.output.colour != io::displacement_field)
        fields_.push_back(io::displacement_field);
}

PullRequest LiveView::pull_of(const fig::MeshWindow::PointerDrag& drag, const io::MeshData& frame) const
{
    PullRequest pull;
    if (drag.point < 0)
        return pull;
    int first = 0;  // the body's first point in the merged frame (bodies in the scene's order)
    for (std::size_t b = 0; b < scene_.bodies.size(); ++b) {
        const int count = static_cast<int>(scene_.bodies[b].mesh.V.rows());
        if (drag.point < first + count) {
            pull.body = static_cast<int>(b);
            pull.vertex = drag.point - first;
            const Eigen::Vector3d rest = frame.points.row(drag.point).transpose();
            pull.target = rest + (drag.target - rest) / scene_.output.warp;
            return pull;
        }
        first += count;
    }
    return pull;  // a point past the bodies' (none: the frame holds the bodies only)
}

void LiveView::frame(const io::MeshData& frame, int step, double time, const std::string& models)
{
    // The time this frame took to compute (since the last one was shown) against its screen time.
    const double computed = clock_.seconds(), screen = slow_motion(scene_) / scene_.output.frame_rate;
    window_.set_name(str(name_, " · frame ", std::lround(1e3 * computed), " ms of ", std::lround(1e3 * screen),
                         " ms", computed > screen ? " (slower than real time)" : ""));
    const io::MeshData shown = io::warped(frame, scene_.output.warp);
    const auto draw = [&] {
        fig::RenderOptions view = frame_view(scene_);
        view.field = fields_[field_];
        view.unit = unit_of(view.field);
        view.clip_percentile = clip_percentile_of(view.field);
        if (field_ != 0)
            view.range.reset();  // the fixed range belongs to the scene's colour field
        view.title = frame_title(scene_, models, time);
        if (scene_.output.warp != 1.0)
            view.outline = frame;  // the rest shape, as the PNG frames draw it (its points are at rest)
        // The body's box: the scene's fixed one, as the PNG frames take it (runner.cpp), else the
        // rest shape grown by half its size each way; the camera frames the obstacles under it too.
        std::array<double, 6> box = fig::empty_bounds();
        if (scene_.output.frame_box) {
            box = *scene_.output.frame_box;
        } else {
            fig::grow_bounds(box, frame.points);
            const double margin = 0.5 * (frame.points.colwise().maxCoeff() - frame.points.colwise().minCoeff()).norm();
            for (int axis = 0; axis < 3; ++axis) {
                box[2 * axis] -= margin;
                box[2 * axis + 1] += margin;
            }
        }
        view.props = obstacle_props(scene_, box, time);
        if (pull_.body >= 0) {  // the spring: a red rod from the pulled vertex to the pointer's point
            int first = 0;
            for (int b = 0; b < pull_.body; ++b)
                first += static_cast<int>(scene_.bodies[static_cast<std::size_t>(b)].mesh.V.rows());
            const Eigen::Vector3d rest = frame.points.row(first + pull_.vertex).transpose();
            const Eigen::Vector3d vertex = shown.points.row(first + pull_.vertex).transpose();
            const Eigen::Vector3d pointer = rest + scene_.output.warp * (pull_.target - rest);
            // Sized by the box the camera frames (about 3 pixels across for the rod, 18 for the ball
            // at the picked vertex, in a window of 720 rows framing it): seen from the back of a hall.
            const double size = Eigen::Vector3d(box[1] - box[0], box[3] - box[2], box[5] - box[4]).norm();
            for (const auto& [from, radius] : {std::pair{pointer, 0.0025 * size}, std::pair{vertex, 0.015 * size}}) {
                const TriMesh shape = contact::swept_ball_surface(vertex, from, radius);
                fig::Prop spring;
                spring.colour = {0.85, 0.1, 0.1};
                spring.shape.points = shape.V;
                spring.shape.cells = shape.F;
                view.props.push_back(std::move(spring));
            }
        }
        if (!view.frame_bounds) {
            for (const fig::Prop& prop : view.props)
                fig::grow_bounds(box, prop.shape.points);
            view.frame_bounds = box;
        }
        window_.show(shown, view);
    };
    draw();
    if (const auto picture = screenshots_.find(step); picture != screenshots_.end())
        window_.save_png(picture->second);
    // The video's pace: the next frame comes no sooner than one of its frame intervals after this one.
    while (!paused_ && clock_.seconds() < slow_motion(scene_) / scene_.output.frame_rate)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    clock_.restart();
    bool advance = false, announced = false;
    do {
        for (char key : window_.poll_keys()) {
            if (key == ' ') {
                paused_ = !paused_;
                if (!paused_)
                    std::cout << "resumed" << std::endl;
            } else if (key == '>' && paused_)
                advance = true;
            else if (key == 'r')
                throw Restart{};
            else if (key == 'q')
                request_stop();
            else if (key == 'c') {
                field_ = (field_ + 1) % fields_.size();
                draw();
            }
        }
        if (paused_ && !advance && !announced) {
            // Said once per frame it waits on, when this frame's files are written and it is shown:
            // a script driving the window waits for the line (tests/scenes/test_runner.cpp).
            std::cout << "paused at step " << step << " (t = " << time << " s)" << std::endl;
            announced = true;
        }
        if (paused_ && !advance)
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        pull_ = pull_of(window_.pointer_drag(), frame);
    } while (paused_ && !advance && !stop_requested());
}

}  // namespace fem::scenes
