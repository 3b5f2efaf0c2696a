#pragma once
// A scene's frames: when the runner takes them, and how they look. The PNG frames, the live view's
// window and the web page all draw a frame as this file says (camera, colour field, caption,
// obstacles), so the three show the same picture. docs/scenes.md#outputs

#include "scenes/scene_file.hpp"

#include "common/figures.hpp"
#include "common/vtk_io.hpp"

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace fem::scenes {

/// Called with every frame a run takes (the merged mesh of every body), its step and time, and the
/// models the bodies use at that frame (as frame_caption writes them), e.g. the live view's.
using FrameObserver =
    std::function<void(const io::MeshData& frame, int step, double time, const std::string& models)>;

/// The steps between two frames: 1/(frame_rate Δt) rounded, at least 1 (a frame at every multiple
/// of it, and at the last step).
int steps_per_frame(const SceneSpec& scene);

/// The frames a whole run takes: one at step 0, at every steps_per_frame-th step and at the last.
int frame_count(const SceneSpec& scene);

/// How many times slower than real time the run's frames play: the video's (make_video) frames per
/// second are fewer than output.frame_rate when the run's frames (frame_count) would last less than
/// min_video_seconds; 1 when they last long enough. The live view and the web page play at the same pace.
double slow_motion(const SceneSpec& scene);

/// How a scene's frames are drawn: title, colour field (colour_by output.colour), camera, size, and
/// the frame box and colour range when the scene fixes them. The PNG frames, the live view and the
/// web page use it alike.
fig::RenderOptions frame_view(const SceneSpec& scene);

/// Colours view by the frame field `field` (scene_file.hpp's OutputSpec::fields): its unit on the
/// colour bar ("m", "m/s", "Pa") and the percentile its range is clipped at (the stress at 99, as it
/// concentrates in the few tets at a pin or a contact; the others at 100, not clipped).
void colour_by(fig::RenderOptions& view, const std::string& field);

/// How a model is named on a frame: a material's label (chapter 12's material_descriptions(), e.g.
/// "StVK", "stable neo-Hookean"); any other name ("linear", "corotational") as it is.
std::string model_label(const std::string& model);

/// The caption of the frame at time t: "<scene file's stem> · <models> · t = 0.5 s" and, when the
/// frames play slower than real time (slow_motion), " · slow motion ×5" (rounded to 0.1). models:
/// what each body uses at that frame, e.g. "stable neo-Hookean" (frame_models in runner.cpp).
std::string frame_caption(const SceneSpec& scene, const std::string& models, double time);

/// The title of the frame at time t, as the PNG frames, the live view and the web page write it: the
/// scene's title, frame_caption under it, and when the displacement is drawn exaggerated a line saying so.
std::string frame_title(const SceneSpec& scene, const std::string& models, double time);

/// The shapes the scene's obstacles are drawn as at time t (fig::Prop, grey): each one's own
/// triangles (chapter 14's Obstacle::surface_at), moved by t·w; a solid whole, a mesh as its
/// triangles, a half-space as the square of its plane under body_box (the floor or slope where the
/// body moves). body_box: (xmin, xmax, ymin, ymax, zmin, zmax) of the body's motion [m].
/// docs/scenes.md#outputs
std::vector<fig::Prop> obstacle_props(const SceneSpec& scene, const std::array<double, 6>& body_box, double time);

}  // namespace fem::scenes
