#pragma once
// The live view of --view: a window that plays a run as it computes, its frames drawn as the PNG
// frames are (frame_look.hpp).
// docs/scenes.md#the-live-view

#include "scenes/frame_look.hpp"
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
    std::array<double, 6> seen_ = fig::empty_bounds();  // the bodies' bounds as drawn, every frame shown so far
};

}  // namespace fem::scenes
