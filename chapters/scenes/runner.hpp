#pragma once
// The scenes capstone: one runner over chapters 10–13 (13: the skin, see SkinObserver).
// docs/scenes.md#the-runner
//
// For each body of a scene the runner builds chapter 10's Scene and Body, whose force model is a
// SceneForces: the model the body needs (chapter 10's linear, chapter 11's corotational, chapter
// 12's hyperelastic ones; each built only when first used) plus the scene's applied loads. Each step:
//   1. time-dependent boundary conditions: the pinned vertices are put where their motion says at
//      t + Δt (u_p = g(t + Δt), v_p = 0) and the loads are scaled to t + Δt; the free dofs then take
//      one backward Euler step with the pins already there (exact for Newton, the linearised step
//      for chapter 10's θ-step). Skipped — no extra force evaluation — when nothing moves;
//   2. model "auto": the deformation of every tet at t (deformation_measures) decides the cheapest
//      model that is accurate enough (choose_level); a change re-evaluates the forces once;
//   3. the step, by chapter 10's ThetaMethod (linear, corotational: factored once for the linear
//      model, whose K is constant) or chapter 12's NewtonBackwardEuler (hyperelastic);
//   4. the energy balance: H = T + U + W (chapter 10's energies, U including the loads' potential)
//      less the work the moving pins, changing loads and model switches put in; a rise above
//      chapter 10's divergence_energy_fraction of the energies in play is divergence.
// Chapter 10's Simulation cannot be used as it is: its loop has no place to move pinned vertices
// or switch a force model between steps, and its divergence rule has no energy source term
// (docs/scenes.md#what-chapter-10-would-need).

#include "scenes/scene_file.hpp"

#include "10_linear_dynamics/time_integration.hpp"

#include "common/cli.hpp"
#include "common/figures.hpp"
#include "common/timer.hpp"

#include <Eigen/Core>

#include <array>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace fem::scenes {

/// The models of "auto", cheapest first.
enum class Level { linear = 0, corotational = 1, hyperelastic = 2 };

/// The level a fixed model name runs at ("linear", "corotational", a hyperelastic material).
Level level_of(const std::string& model);

/// The deformation of a body, from every tet's deformation gradient F (chapter 04), at positions x.
/// docs/scenes.md#model-auto
struct DeformationMeasures {
    double rotation = 0.0;      ///< largest element rotation [rad]: asin ‖axial((F − Fᵀ)/2)‖ (exact for F = R)
    double strain = 0.0;        ///< largest |principal value| of the Green strain ½(FᵀF − I) (chapter 05)
    double volume_ratio = 1.0;  ///< smallest det F (below 0: a tet is inverted)
};

/// The measures of mesh at deformed positions x (#V×3). No SVD: a few products per tet.
DeformationMeasures deformation_measures(const TetMesh& mesh, const MatrixX3d& x);

/// The cheapest level the measures allow: hyperelastic when strain > thresholds.strain or
/// volume_ratio < thresholds.volume_ratio, else corotational when rotation > thresholds.rotation,
/// else linear. From level current, a move up is immediate; a move down needs the measures inside
/// the thresholds scaled by thresholds.hysteresis (volume ratio: 1 − h(1 − threshold)), so that a
/// body near a threshold does not switch every step.
Level choose_level(const DeformationMeasures& measures, Level current, const AutoThresholds& thresholds);

/// A body's force model in a scene: the model of its current level (built on first use) plus the
/// applied loads f_a (point and surface loads, scaled to the current time): U(u) − f_aᵀ u, f(u) + f_a.
class SceneForces final : public dynamics::ForceModel {
public:
    /// hyperelastic: the material name used at Level::hyperelastic.
    SceneForces(const TetMesh& mesh, const dynamics::Material& material, std::string hyperelastic, Level level);

    std::string name() const override { return active().name(); }
    double evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& forces) override;
    double energy(const Eigen::VectorXd& u) override;
    const dynamics::SparseMatrix& stiffness(const Eigen::VectorXd& u) override { return active().stiffness(u); }
    const dynamics::SparseMatrix& definite_stiffness(const Eigen::VectorXd& u) override
    {
        return active().definite_stiffness(u);
    }
    bool constant_stiffness() const override { return active().constant_stiffness(); }
    Eigen::VectorXd von_mises_stress(const Eigen::VectorXd& u) const override { return active().von_mises_stress(u); }

    Level level() const { return level_; }
    void set_level(Level level);
    /// The applied loads f_a (3n), replaced.
    void set_loads(Eigen::VectorXd loads) { loads_ = std::move(loads); }
    const Eigen::VectorXd& loads() const { return loads_; }

private:
    dynamics::ForceModel& active() const { return *models_[static_cast<int>(level_)]; }
    TetMesh mesh_;
    dynamics::Material material_;
    std::string hyperelastic_;
    Level level_;
    std::array<std::unique_ptr<dynamics::ForceModel>, 3> models_;
    Eigen::VectorXd loads_;
};

/// The applied loads of a body at time t (3n): point loads spread over their vertices, surface
/// tractions lumped a third of each boundary triangle's force (area × traction) to its corners.
Eigen::VectorXd applied_loads(const BodySpec& body, const MatrixX3i& boundary, double t);

/// The chapter 13 hook: an observer of a body's frames that carries a fine surface (its .vtp
/// series is written beside the tets' frames). docs/scenes.md#skin
class SkinObserver {
public:
    virtual ~SkinObserver() = default;
    /// The skin's surface at the body's displacement u (3n), for the frame's .vtp.
    virtual io::MeshData frame(const Eigen::VectorXd& u) const = 0;
};
/// The skin of a scene, bound to the rest tets of its body by chapter 13's build_skin (the one place
/// chapter 13 plugs in); the skin's file is read in its body's mesh coordinates (the body's scale
/// and translate apply). fem::Error naming the skin's file and body for a surface chapter 13
/// refuses (empty, degenerate, or a vertex farther outside the tets than its limit).
std::unique_ptr<SkinObserver> make_skin_observer(const SkinSpec& skin, const BodySpec& body);
/// The index of the body the scene's skin names (the scene must have a skin; read_scene checked
/// the name).
std::size_t skin_body(const SceneSpec& scene);

/// A stretch of steps one body ran at one level.
struct Segment {
    int first_step = 0, last_step = 0;
    Level level = Level::linear;
};

/// What a run did, per body and in total.
struct RunResult {
    int steps = 0;                     ///< steps taken
    bool interrupted = false;          ///< stopped by SIGINT (the files so far are valid)
    double seconds = 0.0;              ///< wall time of the steps (outputs excluded)
    int newton_iterations = 0;         ///< summed over steps and bodies
    std::vector<std::vector<Segment>> segments;  ///< per body
    /// per body: positions x (#V×3) at each frame (only when RunOptions::keep_positions)
    std::vector<std::vector<MatrixX3d>> frames;
    int frame_count = 0;
};

/// Called with every frame written (the merged mesh of every body), its step and time.
using FrameObserver = std::function<void(const io::MeshData& frame, int step, double time)>;

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
};

/// Runs a scene: the steps of the header comment, writing (when options.run is set) the outputs the
/// scene asks for: <name>.pvd with its .vtu frames, PNG frames <name>_NNNN.png, a video
/// <name>.mp4/.gif (ffmpeg; a one-line notice without it), steps.csv and the charts energies and
/// step_cost. SIGINT stops after the current step with every file so far valid. fem::Error when a
/// step fails or the run diverges (naming body, step and time). docs/scenes.md#the-runner
RunResult run_scene(const SceneSpec& scene, const RunOptions& options);

/// Installs the SIGINT handler run_scene watches (a second SIGINT kills as usual).
void catch_interrupt();

/// Asks run_scene to stop after the current step, as SIGINT does (the live view's 'q').
void request_stop();

/// How a scene's frames are drawn: title, colour field, camera, size, and the frame box and colour
/// range when the scene fixes them. The PNG frames and the live view use it alike.
fig::RenderOptions frame_view(const SceneSpec& scene);

/// The title of the frame at time t, as the PNG frames write it.
std::string frame_title(const SceneSpec& scene, double time);

/// The live view of --view: a window that plays the run's frames as they come, one frame interval
/// (1/frame_rate) apart at least,
/// drawn as the PNG frames are. Keys: space pauses and resumes, the right arrow steps one frame
/// while paused, r restarts the run (throws Restart), c switches the colour field, q stops the run.
/// docs/scenes.md#the-live-view
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

/// Each fixed model and auto against the stable-neo-Hookean reference at the same Δt: RMS and max
/// over frames of the position error of the tet vertices and of the boundary (surface) vertices,
/// time per step and total time; printed, and written to <out>/models_<scene>.csv. fem::Error for a scene
/// with damping (the reference steps without it). docs/scenes.md#what-each-model-costs
void compare_models(const SceneSpec& scene, const RunContext& run);

}  // namespace fem::scenes
