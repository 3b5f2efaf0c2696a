// The live view: the run's frames in a window as they come, its keys and mouse. docs/scenes.md#the-live-view
#include "scenes/live_view.hpp"

#include "common/error.hpp"
#include "common/interrupt.hpp"
#include "common/motion.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <iostream>
#include <thread>

namespace fem::scenes {

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
        colour_by(view, fields_[field_]);
        if (field_ != 0)
            view.range.reset();  // the fixed range belongs to the scene's colour field
        view.title = frame_title(scene_, models, time);
        if (scene_.output.warp != 1.0)
            view.outline = frame;  // the rest shape, as the PNG frames draw it (its points are at rest)
        // The body's box: the scene's fixed one, as the PNG frames take it (runner.cpp), else the
        // bodies as drawn in every frame shown so far, grown by a tenth of their size each way: the
        // body fills the window at the start, and the camera backs off only when the body leaves
        // what it framed. The camera frames the obstacles under it too.
        std::array<double, 6> box = fig::empty_bounds();
        if (scene_.output.frame_box) {
            box = *scene_.output.frame_box;
        } else {
            fig::grow_bounds(seen_, shown.points);
            if (scene_.output.warp != 1.0)
                fig::grow_bounds(seen_, frame.points);  // the rest shape drawn behind it
            box = seen_;
            const double margin = 0.1 * std::hypot(box[1] - box[0], box[3] - box[2], box[5] - box[4]);
            for (int axis = 0; axis < 3; ++axis) {
                box[2 * axis] -= margin;
                box[2 * axis + 1] += margin;
            }
        }
        view.props = obstacle_props(scene_, box, time);
        if (!view.frame_bounds) {  // the body's box and the obstacles, not the pull's spring (which the camera
            std::array<double, 6> framed = box;  // chasing would move the pointer's point under the hand)
            for (const fig::Prop& prop : view.props)
                fig::grow_bounds(framed, prop.shape.points);
            view.frame_bounds = framed;
        }
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
            // a script driving the window waits for the line (tests/scenes/test_live_view.cpp).
            std::cout << "paused at step " << step << " (t = " << time << " s)" << std::endl;
            announced = true;
        }
        if (paused_ && !advance)
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        pull_ = pull_of(window_.pointer_drag(), frame);
    } while (paused_ && !advance && !stop_requested());
}

}  // namespace fem::scenes
