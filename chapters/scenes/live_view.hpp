#pragma once
// How a scene's frames are drawn, and the live view of --view that plays a run as it computes.
// docs/scenes.md#the-live-view

#include "scenes/scene_conditions.hpp"
#include "scenes/scene_file.hpp"

#include "common/figures.hpp"
#include "common/timer.hpp"
#include "common/vtk_io.hpp"

#include <array>
#include <cstddef>
#include <map>
#include <filesystem>
#include <string>
#include <vector>

namespace fem::scenes {

/// How a scene's frames are drawn: title, colour field, camera, size, and the frame box and colour
/// range when the scene fixes them. The PNG frames and the live view use it alike.
fig::RenderOptions frame_view(const SceneSpec& scene);

/// How a model is named on a frame: a material's label (chapter 12's material_descriptions(), e.g.
/// "StVK", "stable neo-Hookean"); any other name ("linear", "corotational") as it is.
std::string model_label(const std::string& model);

/// How many times slower than real time the run's frames play: the video's (make_video) frames per
/// second are fewer than output.frame_rate when the run's frames (frame_count) would last less than
/// min_video_seconds; 1 when they last long enough. The live view plays at the same pace.
double slow_motion(const SceneSpec& scene);

/// The caption of the frame at time t: "<scene file's stem> · <models> · t = 0.5 s" and, when the
/// frames play slower than real time (slow_motion), " · slow motion ×5" (rounded to 0.1). models:
/// what each body uses at that frame, e.g. "stable neo-Hookean" (frame_models in runner.cpp).
std::string frame_caption(const SceneSpec& scene, const std::string& models, double time);

/// The title of the frame at time t, as the PNG frames and the live view both write it: the scene's
/// title, frame_caption under it, and when the displacement is drawn exaggerated a line saying so.
std::string frame_title(const SceneSpec& scene, const std::string& models, double time);

/// The shapes the scene's obstacles are drawn as at time t (fig::Prop, grey): each one's own
/// triangles (chapter 14's Obstacle::surface_at), moved by t·w; a solid whole, a mesh as its
/// triangles, a half-space as the square of its plane under body_box (the floor or slope where the
/// body moves). body_box: (xmin, xmax, ymin, ymax, zmin, zmax) of the body's motion [m].
/// docs/scenes.md#outputs
std::vector<fig::Prop> obstacle_props(const SceneSpec& scene, const std::array<double, 6>& body_box, double time);

/// The live view of --view: a window that plays the run's frames as they come, one frame interval of
/// the video (slow_motion/frame_rate) apart at least, drawn as the PNG frames are. Keys: space pauses and resumes, the
/// right arrow steps one frame while paused, r restarts the run (throws Restart), c switches the
/// colour field, q stops the run (fem::request_stop). The mouse pulls the body: pressing the left
/// button on it picks the vertex under the pointer, which a spring then pulls toward the pointer
/// (pull(); drawn as a red rod, a ball at the vertex) until the button is released. The window's name says how long the
/// last frame took against its screen time, and whether the run keeps up with it.
/// docs/scenes.md#the-live-view
class LiveView {
public:
    /// Thrown by frame() when r is pressed: the caller runs the scene again.
    struct Restart {};
    /// Opens the window (fem::Error without a display). screenshots: step → file, save the window
    /// at that step to that file (for the test against the PNG frame of the same step, and the
    /// picture of a pull in docs/scenes.md).
    explicit LiveView(const SceneSpec& scene, std::map<int, std::filesystem::path> screenshots = {});
    /// Shows one frame (models: what the bodies use now, as frame_caption writes it) and handles the
    /// keys pressed since the last one.
    void frame(const io::MeshData& frame, int step, double time, const std::string& models);

    /// What the mouse pulls as of the last frame (RunOptions::pull): the picked vertex's body and
    /// vertex, the target the pointer's point at the frame's displacement scale undone
    /// (X + (p − X)/warp, X the vertex's rest position); body −1 when no button is held on the body.
    PullRequest pull() const { return pull_; }

private:
    /// The pull for the window's pointer drag on frame (the merged bodies, rest points).
    PullRequest pull_of(const fig::MeshWindow::PointerDrag& drag, const io::MeshData& frame) const;


    const SceneSpec& scene_;
    fig::MeshWindow window_;
    std::vector<std::string> fields_;
    std::size_t field_ = 0;
    bool paused_ = false;
    std::map<int, std::filesystem::path> screenshots_;
    Timer clock_;  // since the last frame shown
    PullRequest pull_;
    std::string name_;  // the window's name, before the timing
};

}  // namespace fem::scenes
