#pragma once
// How a scene's frames are drawn, and the live view of --view that plays a run as it computes.
// docs/scenes.md#the-live-view

#include "scenes/scene_file.hpp"

#include "common/figures.hpp"
#include "common/timer.hpp"
#include "common/vtk_io.hpp"

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace fem::scenes {

/// How a scene's frames are drawn: title, colour field, camera, size, and the frame box and colour
/// range when the scene fixes them. The PNG frames and the live view use it alike.
fig::RenderOptions frame_view(const SceneSpec& scene);

/// The title of the frame at time t, as the PNG frames write it.
std::string frame_title(const SceneSpec& scene, double time);

/// The live view of --view: a window that plays the run's frames as they come, one frame interval
/// (1/frame_rate) apart at least, drawn as the PNG frames are. Keys: space pauses and resumes, the
/// right arrow steps one frame while paused, r restarts the run (throws Restart), c switches the
/// colour field, q stops the run (fem::request_stop). docs/scenes.md#the-live-view
class LiveView {
public:
    /// Thrown by frame() when r is pressed: the caller runs the scene again.
    struct Restart {};
    /// Opens the window (fem::Error without a display). screenshot_step ≥ 0: save the window at that
    /// step to screenshot (for the test against the PNG frame of the same step).
    LiveView(const SceneSpec& scene, std::filesystem::path screenshot = {}, int screenshot_step = -1);
    /// Shows one frame and handles the keys pressed since the last one.
    void frame(const io::MeshData& frame, int step, double time);

private:
    const SceneSpec& scene_;
    fig::MeshWindow window_;
    std::vector<std::string> fields_;
    std::size_t field_ = 0;
    bool paused_ = false;
    std::filesystem::path screenshot_;
    int screenshot_step_;
    Timer clock_;  // since the last frame shown
};

}  // namespace fem::scenes
