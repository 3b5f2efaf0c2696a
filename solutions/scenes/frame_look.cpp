// A scene's frames: when they are taken, and how the PNGs, the live view and the web page draw them.
// docs/scenes.md#outputs
#include "scenes/frame_look.hpp"

#include "scenes/run_outputs.hpp"

#include "12_hyperelastic_newton/materials.hpp"

#include "10_linear_dynamics/body.hpp"

#include "common/error.hpp"
#include "common/motion.hpp"

#include <algorithm>
#include <cmath>

namespace fem::scenes {

int steps_per_frame(const SceneSpec& scene)
{
    return std::max(1, static_cast<int>(std::lround(1.0 / (scene.output.frame_rate * scene.time_step))));
}

int frame_count(const SceneSpec& scene)
{
    const int steps = dynamics::step_count(scene.duration, scene.time_step), every = steps_per_frame(scene);
    return 1 + steps / every + (steps % every != 0 ? 1 : 0);
}

double slow_motion(const SceneSpec& scene)
{
    return scene.output.frame_rate / video_frame_rate(frame_count(scene), scene.output);
}

fig::RenderOptions frame_view(const SceneSpec& scene)
{
    const OutputSpec& out = scene.output;
    fig::RenderOptions view;
    view.title = scene.title;
    colour_by(view, out.colour);
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

void colour_by(fig::RenderOptions& view, const std::string& field)
{
    view.field = field;
    view.unit = field == "displacement" ? "m" : field == "velocity" ? "m/s" : field == "von Mises stress" ? "Pa" : "";
    // The stress's peak at a pin or a contact would set the scale and leave the rest of the body one
    // colour (the hanging cube's corners: 6.65·10⁴ Pa).
    view.clip_percentile = field == "von Mises stress" ? 99.0 : 100.0;
}

std::string model_label(const std::string& model)
{
    for (const hyper::MaterialNames& material : hyper::material_descriptions())
        if (material.name == model)
            return material.label;
    return model;
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

}  // namespace fem::scenes
