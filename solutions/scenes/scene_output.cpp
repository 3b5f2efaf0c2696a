// The output sink of a scene run: frames to the series, the web page and the observer as they come;
// the history, contact tables, web page, PNG frames and video at the end. docs/scenes.md#outputs
#include "scene_output.hpp"

#include "common/error.hpp"

#include <array>
#include <cmath>
#include <filesystem>
#include <iostream>

namespace fem::scenes {

namespace {

/// The lattice of a skinned body drawn around its skin: the body's frame k (warped as the skin is),
/// its surface's edges coloured by the skin's field on the skin's colour scale.
fig::Prop lattice_prop(const io::MotionRecorder& bodies, std::size_t k, double warp)
{
    fig::Prop lattice;
    lattice.shape = io::warped(bodies.kept_frame(k), warp);
    lattice.by_field = true;
    lattice.wireframe = true;
    return lattice;
}

}  // namespace

SceneOutput::SceneOutput(const SceneSpec& scene, const RunContext* run, std::shared_ptr<const SkinObserver> skin,
                         FrameObserver on_frame)
    : scene_(scene), run_(run), on_frame_(std::move(on_frame)), stem_(scene.file.stem().string()),
      png_(run != nullptr && run->figures && scene.output.png), skin_(std::move(skin))
{
    if (scene.skin) {
        skinned_ = skin_body(scene);
        if (!skin_ && run != nullptr && scene.output.pvd)
            skin_ = make_skin_observer(*scene.skin, scene.bodies[skinned_]);
    }
    if (run == nullptr)
        return;
    if (scene.output.pvd) {
        recorder_.emplace(run->file(stem_ + ".pvd"), png_ ? 1 : 0);
        if (skin_)
            skin_recorder_.emplace(run->file(stem_ + "_skin.pvd"), png_ ? 1 : 0, io::FrameFile::surface);
    }
    if (scene.output.html)
        page_.emplace(scene);
}

void SceneOutput::add_step(const std::string& body, const std::string& model, const dynamics::StepRecord& record)
{
    history_.add(body, model, record);
}

void SceneOutput::add_frame(const SceneFrame& frame)
{
    models_.push_back(frame.models);
    if (!takes_mesh())
        return;
    if (recorder_)
        recorder_->add(frame.time, frame.mesh);
    if (page_)
        page_->add_frame(frame.mesh, frame.time, frame.models);
    if (skin_recorder_)
        skin_recorder_->add(frame.time, skin_->frame(frame.displacements.at(skinned_)));
    if (on_frame_)
        on_frame_(frame.mesh, frame.step, frame.time, frame.models);
}

void SceneOutput::finish(const std::vector<std::vector<dynamics::StepRecord>>& records,
                         const std::vector<ContactStepRecord>& contact_records, int steps, bool interrupted)
{
    if (run_ == nullptr)
        return;
    const RunContext& run = *run_;
    if (interrupted)
        std::cout << "interrupted after step " << steps << ": " << models_.size()
                  << " frames written, the .pvd lists them; no PNGs or video\n";
    if (scene_.output.csv)
        history_.write_csv(run.file("steps.csv"));
    if (scene_.output.charts)
        history_.save_charts(scene_, scene_.bodies.size(), run);
    if (!contact_records.empty()) {
        const Table cost = contact_cost_table(contact_records);
        std::cout << "\n";
        cost.print(std::cout);
        if (scene_.output.csv) {
            contact_steps_table(contact_records).write_csv(run.file("contact_steps.csv"));
            cost.write_csv(run.file("contact_cost.csv"));
        }
    }
    if (page_) {
        const std::filesystem::path file = run.file(stem_ + ".html");
        const Eigen::Vector3d bound = page_->write(file, records);
        std::cout << "web page: " << file.filename().string() << " (" << models_.size() << " frames, "
                  << std::lround(std::filesystem::file_size(file) / 1e4) / 100.0 << " MB; positions to within "
                  << bound.maxCoeff() << " m)\n";
    }
    if (recorder_ && png_ && !interrupted)
        render_frames();
}

void SceneOutput::render_frames() const
{
    // Every frame captioned with the models of its moment; the obstacles drawn at its time under
    // the box the camera frames (the scene's, as the live view takes it, or the motion's).
    const double warp = scene_.output.warp;
    const std::array<double, 6> box = scene_.output.frame_box.value_or(recorder_->motion_bounds(warp));
    io::FrameExtras extras;
    extras.title = [&](std::size_t k, double time) { return frame_title(scene_, models_.at(k), time); };
    extras.props = [&](std::size_t, double time) { return obstacle_props(scene_, box, time); };
    const int written = recorder_->render_png_frames(run_->file(stem_), frame_view(scene_), warp, extras);
    // A skinned scene's picture is its skin (the bunny), coloured by its displacement, the one
    // field a skin frame has besides its normals, with the lattice that carries it drawn around it
    // as edges on the same colour scale; the video shows it.
    int skin_written = 0;
    if (skin_recorder_) {
        fig::RenderOptions view = frame_view(scene_);
        colour_by(view, io::displacement_field);  // in m, not clipped
        view.range.reset();
        view.smooth = true;  // a render surface: shaded smooth by its normals, no facets or edges
        view.show_edges = false;
        io::FrameExtras skin_extras = extras;
        skin_extras.props = [&](std::size_t k, double time) {
            std::vector<fig::Prop> props = obstacle_props(scene_, box, time);
            props.push_back(lattice_prop(*recorder_, k, warp));
            return props;
        };
        skin_written = skin_recorder_->render_png_frames(run_->file(stem_ + "_skin"), view, warp, skin_extras);
    }
    if (written > 0 && scene_.output.video != "none")
        make_video(*run_, skin_written > 0 ? stem_ + "_skin" : stem_, scene_.output);
}

}  // namespace fem::scenes
