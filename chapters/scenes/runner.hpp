#pragma once
// The scenes capstone: one runner over chapters 10–14. docs/scenes.md#the-runner
//
// For each body of a scene the runner builds chapter 10's Scene, Body and Simulation — one loop,
// chapter 10's — with
//   - a force model that may change between steps (SceneForces: the model the body needs, each
//     built by chapter 12's factory on first use; model_auto.hpp),
//   - an integrator that follows it (chapter 10's θ-step for linear and corotational, chapter 12's
//     Newton backward Euler for the hyperelastic models; each made by chapter 12's factory),
//   - with obstacles, contact in the steps that need it (ContactIntegrator: scene_contact.hpp),
//   - the scene's step hook (SceneConditions: loads, moving pins, auto's level; scene_conditions.hpp),
// and steps the bodies together, one step each in turn. Chapter 10's loop books the energy the
// hook and the moving pins put in, the damping and the integrator's own dissipation, and fails on
// divergence; the runner adds the body's name to its message. Frames (every 1/frame_rate s) merge
// every body into one mesh; a skin (chapter 13) is one more observer of its body's frames.

#include "scenes/contact_cost.hpp"
#include "scenes/frame_look.hpp"
#include "scenes/model_auto.hpp"
#include "scenes/scene_conditions.hpp"
#include "scenes/scene_file.hpp"
#include "scenes/skin_observer.hpp"

#include "10_linear_dynamics/time_integration.hpp"

#include "common/cli.hpp"
#include "common/vtk_io.hpp"

#include <Eigen/Core>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace fem::scenes {

/// A stretch of steps one body ran with one model.
struct Segment {
    int first_step = 0, last_step = 0;
    Level level = Level::linear;
    std::string model;  ///< the model's name ("linear", "corotational", "stvk", …)
};

/// "linear 0-3, stable-neo-hookean 4-120": each segment's model and steps.
std::string describe_segments(const std::vector<Segment>& segments);

/// What a run did, per body and in total.
struct RunResult {
    int steps = 0;                     ///< steps taken
    bool interrupted = false;          ///< stopped by a stop signal (the files so far are valid)
    double seconds = 0.0;              ///< wall time of the steps (outputs excluded)
    int newton_iterations = 0;         ///< summed over steps and bodies
    std::vector<std::vector<Segment>> segments;  ///< per body
    /// per body: the steps that needed contact (scene_contact.hpp; 0 without obstacles)
    std::vector<int> contact_steps;
    /// per body: positions x (#V×3) at each frame (only when RunOptions::keep_positions)
    std::vector<std::vector<MatrixX3d>> frames;
    /// per body: chapter 10's record of every step (step 0 first): energies, work in, dissipation
    std::vector<std::vector<dynamics::StepRecord>> records;
    /// every step (from step 1) of every group of bodies with contact, in the order taken: its
    /// time split and pairs (contact_cost.hpp; contact_steps.csv and contact_cost.csv)
    std::vector<ContactStepRecord> contact_records;
    int frame_count = 0;
    /// With [contact] check_path: the path segments proven free of crossings (every contact step's
    /// Newton path, every chord of a step without contact) and the primitive pairs the CCDs tested.
    long long path_segments = 0, path_pair_tests = 0;
};

/// How to run a scene.
struct RunOptions {
    FrameObserver on_frame;            ///< e.g. the live view; may throw to abandon the run
    const RunContext* run = nullptr;   ///< where files go; nullptr: write nothing
    std::string model;                 ///< when set, every body uses this model instead of its own
    bool keep_positions = false;       ///< keep every frame's positions (for the model comparison)
    bool progress = false;             ///< a progress bar on stderr (when it is a terminal)
    bool print_models = true;          ///< print which model each part of the run used
    /// The scene's skin, bound already (fem_scene binds it before it makes the output folder, so a
    /// bad skin is refused first). Null: run_scene binds the scene's skin itself when it writes
    /// frames (a run that writes nothing has no use for it).
    std::shared_ptr<const SkinObserver> skin;
    /// Asked before every step what pulls the bodies (e.g. LiveView::pull); unset: nothing does. A
    /// pull that starts or ends prints one line ("pulling …", "released …").
    std::function<PullRequest()> pull;
    /// The pull's spring stiffness k [N/m]; 0: default_pull_stiffness of the pulled body.
    double pull_stiffness = 0.0;
    /// Run until stopped (a stop signal or the live view's q) instead of for the scene's duration.
    bool forever = false;
};

/// Runs a scene (header comment), writing (when options.run is set) the outputs the scene asks for:
/// <name>.pvd with its .vtu frames, PNG frames <name>_NNNN.png, a video <name>.mp4/.gif (ffmpeg; a
/// one-line notice without it), steps.csv and the charts energies, step_time and newton_iterations,
/// and with output.html the web page <name>.html (web_page.hpp); with contact, contact_steps.csv and
/// contact_cost.csv (contact_cost.hpp; the latter printed too).
/// A stop signal (fem::stop_requested, common/interrupt.hpp) stops after the current step with every
/// file so far valid. fem::Error when a step fails or the run diverges (naming body, step, time and
/// model). docs/scenes.md#the-runner
RunResult run_scene(const SceneSpec& scene, const RunOptions& options);

/// run_scene writing nothing and printing nothing, keeping every frame's positions (and every step's
/// record): the run a comparison or a test looks at. model (when set) replaces every body's model.
RunResult run_positions(const SceneSpec& scene, const std::string& model = "");

}  // namespace fem::scenes
