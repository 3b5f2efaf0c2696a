// How a scene's frames are drawn, and the live view. docs/scenes.md#the-live-view
#include "scenes/live_view.hpp"

#include "scenes/run_outputs.hpp"
#include "scenes/runner.hpp"

#include "common/error.hpp"
#include "common/interrupt.hpp"
#include "common/motion.hpp"

#include <Eigen/Geometry>

#include <array>
#include <chrono>
#include <cmath>
#include <limits>
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
    return model == "stvk" ? "StVK" : model == "neo-hookean" ? "neo-Hookean" : model == "stable-neo-hookean" ? "stable neo-Hookean" : model;
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

namespace {

/// Two unit vectors spanning the plane of unit normal n.
std::pair<Eigen::Vector3d, Eigen::Vector3d> plane_axes(const Eigen::Vector3d& n)
{
    const Eigen::Vector3d other = std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    const Eigen::Vector3d u = n.cross(other).normalized();
    return {u, n.cross(u)};
}

/// The square of the plane through p with unit normal n under box: its corners projected, grown by
/// a fifth of its diagonal each way (two triangles).
io::MeshData plane_patch(const Eigen::Vector3d& p, const Eigen::Vector3d& n, const std::array<double, 6>& box)
{
    const auto [u, v] = plane_axes(n);
    double lo_u = std::numeric_limits<double>::infinity(), hi_u = -lo_u, lo_v = lo_u, hi_v = -lo_u;
    for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d c(box[(corner & 1) ? 1 : 0], box[(corner & 2) ? 3 : 2], box[(corner & 4) ? 5 : 4]);
        lo_u = std::min(lo_u, u.dot(c - p));
        hi_u = std::max(hi_u, u.dot(c - p));
        lo_v = std::min(lo_v, v.dot(c - p));
        hi_v = std::max(hi_v, v.dot(c - p));
    }
    const double margin = 0.2 * Eigen::Vector3d(box[1] - box[0], box[3] - box[2], box[5] - box[4]).norm();
    io::MeshData patch;
    patch.points.resize(4, 3);
    int row = 0;
    for (double a : {lo_u - margin, hi_u + margin})
        for (double b : {lo_v - margin, hi_v + margin})
            patch.points.row(row++) = (p + a * u + b * v).transpose();
    patch.cells.resize(2, 3);
    patch.cells << 0, 1, 3, 0, 3, 2;
    return patch;
}

/// A ball of centre c and radius r: 24 rings of 48 triangles' quads.
io::MeshData ball(const Eigen::Vector3d& c, double r)
{
    const int rings = 24, segments = 48;
    io::MeshData sphere;
    sphere.points.resize((rings + 1) * segments, 3);
    for (int i = 0; i <= rings; ++i)
        for (int j = 0; j < segments; ++j) {
            const double polar = M_PI * i / rings, around = 2.0 * M_PI * j / segments;
            sphere.points.row(i * segments + j) =
                (c + r * Eigen::Vector3d(std::sin(polar) * std::cos(around), std::sin(polar) * std::sin(around),
                                         std::cos(polar))).transpose();
        }
    sphere.cells.resize(2 * rings * segments, 3);
    int row = 0;
    for (int i = 0; i < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            const int a = i * segments + j, b = i * segments + (j + 1) % segments;
            sphere.cells.row(row++) << a, a + segments, b + segments;
            sphere.cells.row(row++) << a, b + segments, b;
        }
    return sphere;
}

/// A box: centre c, edge lengths size along the columns of R (12 triangles).
io::MeshData box_surface(const Eigen::Vector3d& c, const Eigen::Vector3d& size, const Eigen::Matrix3d& R)
{
    io::MeshData box;
    box.points.resize(8, 3);
    for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d sign((corner & 1) ? 0.5 : -0.5, (corner & 2) ? 0.5 : -0.5, (corner & 4) ? 0.5 : -0.5);
        box.points.row(corner) = (c + R * sign.cwiseProduct(size)).transpose();
    }
    box.cells.resize(12, 3);
    box.cells << 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5;
    return box;
}

}  // namespace

std::vector<fig::Prop> obstacle_props(const SceneSpec& scene, const std::array<double, 6>& body_box, double time)
{
    std::vector<fig::Prop> props;
    for (const ObstacleSpec& obstacle : scene.obstacles) {
        const Eigen::Vector3d shift = time * obstacle.velocity;
        fig::Prop prop;
        switch (obstacle.kind) {  // one case per kind of obstacle
        case ObstacleSpec::Kind::half_space:
            prop.shape = plane_patch(obstacle.point + shift, obstacle.normal.normalized(), body_box);
            break;
        case ObstacleSpec::Kind::sphere:
            prop.shape = ball(obstacle.center + shift, obstacle.radius);
            break;
        case ObstacleSpec::Kind::box:
            prop.shape = box_surface(obstacle.center + shift, obstacle.size,
                                     Eigen::AngleAxisd(obstacle.angle, obstacle.axis.normalized()).toRotationMatrix());
            break;
        case ObstacleSpec::Kind::mesh:  // its triangles, placed already
            prop.shape.points = obstacle.surface.V.rowwise() + shift.transpose();
            prop.shape.cells = obstacle.surface.F;
            break;
        }
        props.push_back(std::move(prop));
    }
    return props;
}

// --- LiveView -------------------------------------------------------------------------------------

LiveView::LiveView(const SceneSpec& scene, std::filesystem::path screenshot, int screenshot_step)
    : scene_(scene), window_(frame_view(scene), str("fem_scene: ", scene.title)), screenshot_(std::move(screenshot)),
      screenshot_step_(screenshot_step), name_(str("fem_scene: ", scene.title))
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
        if (pull_.body >= 0) {  // the spring: a line from the pulled vertex to the pointer's point
            int first = 0;
            for (int b = 0; b < pull_.body; ++b)
                first += static_cast<int>(scene_.bodies[static_cast<std::size_t>(b)].mesh.V.rows());
            const Eigen::Vector3d rest = frame.points.row(first + pull_.vertex).transpose();
            fig::Prop spring;  // one line cell
            spring.colour = {0.8, 0.1, 0.1};
            spring.shape.points.resize(2, 3);
            spring.shape.points.row(0) = shown.points.row(first + pull_.vertex);
            spring.shape.points.row(1) = (rest + scene_.output.warp * (pull_.target - rest)).transpose();
            spring.shape.cells.resize(1, 2);
            spring.shape.cells << 0, 1;
            view.props.push_back(std::move(spring));
        }
        if (!view.frame_bounds) {
            for (const fig::Prop& prop : view.props)
                fig::grow_bounds(box, prop.shape.points);
            view.frame_bounds = box;
        }
        window_.show(shown, view);
    };
    draw();
    if (step == screenshot_step_)
        window_.save_png(screenshot_);
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
