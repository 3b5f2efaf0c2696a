#pragma once
// The output sink of a scene run: the runner's loop (runner.cpp) hands it every step's records and
// every frame, and calls finish once after the last step; it writes what the scene asks for. Internal
// to the runner. docs/scenes.md#outputs

#include "scenes/contact_cost.hpp"
#include "scenes/frame_look.hpp"
#include "scenes/run_outputs.hpp"
#include "scenes/scene_file.hpp"
#include "scenes/skin_observer.hpp"
#include "scenes/web_page.hpp"

#include "10_linear_dynamics/time_integration.hpp"

#include "common/cli.hpp"
#include "common/motion.hpp"
#include "common/vtk_io.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace fem::scenes {

/// One frame of a running scene, as the loop hands it to the sink.
struct SceneFrame {
    int step = 0;
    double time = 0.0;
    std::string models;  ///< what each body uses now (frame_models in runner.cpp), for the caption
    io::MeshData mesh;   ///< every body merged (merged_frame); empty when the sink takes none (takes_mesh)
    std::vector<Eigen::VectorXd> displacements;  ///< each body's u (3n_i), in the scene's order
};

/// Where a run's steps and frames go, as the scene's [output] asks: during the run the .pvd series
/// with its .vtu frames (and the skin's .vtp beside them), the web page's frames and the frame
/// observer (the live view); after it (finish) steps.csv and the charts, the contact tables, the web
/// page, the PNG frames and the video. With run null it writes nothing and only calls the observer.
class SceneOutput {
public:
    /// Binds the scene's skin first (skin_body; make_skin_observer when skin is null and the run
    /// writes frames), so that a bad skin is refused before anything runs or is written.
    SceneOutput(const SceneSpec& scene, const RunContext* run, std::shared_ptr<const SkinObserver> skin,
                FrameObserver on_frame);

    /// Whether add_frame needs the frame's merged mesh (a series, a web page or an observer takes it).
    bool takes_mesh() const { return recorder_ || page_ || on_frame_; }
    /// One row of steps.csv: a body's record after a step (or at step 0), with its model's name.
    void add_step(const std::string& body, const std::string& model, const dynamics::StepRecord& record);
    /// One frame: to the series, the web page, the skin's series, then the observer (which may throw
    /// to abandon the run, after the frame's files are written).
    void add_frame(const SceneFrame& frame);
    /// After the last step (or a stop after step `steps`): the files made of the whole run. records:
    /// per body, every step's (the web page's bound); contact_records: every step of every group with
    /// contact. An interrupted run writes no PNGs or video.
    void finish(const std::vector<std::vector<dynamics::StepRecord>>& records,
                const std::vector<ContactStepRecord>& contact_records, int steps, bool interrupted);

private:
    /// The PNG frames <stem>_NNNN.png (and a skin's <stem>_skin_NNNN.png), then the video of them.
    void render_frames() const;

    const SceneSpec& scene_;
    const RunContext* run_;
    FrameObserver on_frame_;
    std::string stem_;      // the scene file's stem: the name of every file
    bool png_ = false;      // PNG frames (a run with figures, output.png)
    std::size_t skinned_ = 0;
    std::shared_ptr<const SkinObserver> skin_;
    std::optional<io::MotionRecorder> recorder_;       // <stem>.pvd
    std::optional<io::MotionRecorder> skin_recorder_;  // <stem>_skin.pvd, the skin's .vtp frames
    std::optional<WebPage> page_;                      // <stem>.html
    StepHistory history_;
    std::vector<std::string> models_;  // per frame, for its caption
};

}  // namespace fem::scenes
