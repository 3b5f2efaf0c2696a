#pragma once
// What a scene changes between steps: its loads, its moving pins and, for model "auto", the force
// model — chapter 10's step hook, built for one body of a scene. docs/scenes.md#the-runner
//
// Before the step from t to t + Δt the hook
//   1. sets the applied loads to their value at t + Δt (Body::set_applied_loads), when they change
//      in time (a ramp, a release);
//   2. sets the pins' velocity over the step, ṽ_p = (g(t + Δt) − u_p(t))/Δt, from each pin's
//      prescribed motion g (Body::set_pin_velocity); chapter 10's step then moves the pins there
//      and books the work their reactions do;
//   3. for "auto", measures the deformation at t and switches the body's model to the level it
//      needs (model_auto.hpp); after a step that needed contact (scene_contact.hpp), at least
//      corotational: a body resting on an obstacle has a large rigid displacement u, where the linear
//      energy ½uᵀKu of a translation is zero only up to a round-off ε‖K‖‖u‖² that hides Newton's last
//      decreases from its line search (docs/scenes.md#obstacles).
//   4. with the live view's mouse pulling the body (Pull), adds the pull's force to the loads.
// It reports a change of the loads or the model, so that chapter 10's loop books the jump of H as
// work put in. A body whose pins are fixed and whose loads are constant pays for none of this.

#include "scenes/model_auto.hpp"
#include "scenes/scene_file.hpp"

#include "10_linear_dynamics/time_integration.hpp"

#include "common/mesh.hpp"

#include <Eigen/Core>

#include <memory>
#include <vector>

namespace fem::scenes {

class ContactIntegrator;

/// The applied loads of a body at time t (3n): point loads spread over their vertices, surface
/// tractions lumped a third of each boundary triangle's force (area × traction) to its corners.
/// boundary: the body's boundary triangles (boundary_faces).
Eigen::VectorXd applied_loads(const BodySpec& body, const MatrixX3i& boundary, double t);

/// A pull on a body by a spring of stiffness k [N/m] from a target point: the live view's mouse
/// dragging the body (docs/scenes.md#pulling-the-body). The spring pulls the mass-weighted centre
/// c = Σ mᵢ xᵢ / Σ mᵢ of the vertices within pull_radius of the picked one (a patch, not one vertex,
/// which a hard pull would draw out into a spike), with the force F = k (target − c) at the step's
/// start, shared by mass (fᵢ = mᵢ/Σ m · F): one more applied load, lagged a step, whose work
/// chapter 10's loop books like any load's. Lagged, it is stable while k Δt² < 4 Σ mᵢ (a mass on an
/// explicit spring); default_pull_stiffness keeps far below that.
struct Pull {
    int vertex = -1;             ///< the picked vertex; −1: no pull
    std::vector<int> vertices;   ///< the patch that carries the pull (the picked vertex among them)
    Eigen::VectorXd shares;      ///< mᵢ / Σ m per patch vertex
    Eigen::Vector3d target = Eigen::Vector3d::Zero();  ///< [m]
    double stiffness = 0.0;      ///< k [N/m]
};

/// What pulls a scene's bodies at the moment (the live view's mouse): body (its index in the scene)
/// and vertex, and the target [m] a spring pulls them toward; body −1: nothing pulls.
struct PullRequest {
    int body = -1, vertex = -1;
    Eigen::Vector3d target = Eigen::Vector3d::Zero();
};

/// The patch of a pull: the vertices within this fraction of the body's rest bounding-box diagonal
/// of the picked one.
inline constexpr double pull_radius = 0.1;

/// k = M (2π · 1 Hz)², M the body's mass: the spring alone would swing the whole body at 1 Hz; a
/// lecture's pull that moves the body without tearing at it.
double default_pull_stiffness(const dynamics::Body& body);

/// The pull of body's vertex toward target with stiffness k > 0 (the patch and shares of Pull).
/// fem::Error for a vertex out of range or k ≤ 0.
Pull make_pull(const dynamics::Body& body, int vertex, const Eigen::Vector3d& target, double stiffness);

/// The pull's load (3n): fᵢ = sharesᵢ k (target − c) on the patch, c the patch's centre at u (3n).
Eigen::VectorXd pull_load(const Pull& pull, const dynamics::Body& body, const Eigen::VectorXd& u);

/// The step hook of one body of a scene (a chapter 10 Simulation::BeforeStep).
class SceneConditions {
public:
    /// forces: the body's switching force model, or nullptr when its model is fixed (then auto is off);
    /// contact: the body's contact steps (scene_contact.hpp), or nullptr in a scene without obstacles.
    /// fem::Error naming the load (its selector's place in the scene file) for a surface load whose
    /// selected vertices span no boundary triangle: it would apply nothing.
    /// pull: the body's pull of the moment, which the runner changes between steps (null: never pulled).
    SceneConditions(const BodySpec& body, const SceneSpec& scene, SceneForces* forces, bool automatic,
                    const ContactIntegrator* contact = nullptr, std::shared_ptr<const Pull> pull = nullptr);

    /// The hook: loads at step_end (with the pull's), the pins' velocity over the step, auto's level
    /// (see the header comment). True when the loads or the model changed.
    bool operator()(dynamics::Body& body, const dynamics::State& state, double step_end);

    /// The loads at t = 0 (3n), for the body before its first step.
    const Eigen::VectorXd& initial_loads() const { return initial_loads_; }

private:
    const BodySpec* body_;
    const SceneSpec* scene_;
    SceneForces* forces_;
    bool automatic_;
    const ContactIntegrator* contact_;
    std::shared_ptr<const Pull> pull_;
    bool loads_change_ = false, pins_move_ = false, pulled_ = false;  // pulled_: at the last step
    MatrixX3i boundary_;
    Eigen::VectorXd initial_loads_;
};

}  // namespace fem::scenes
