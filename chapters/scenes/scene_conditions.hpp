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
// It reports a change of the loads or the model, so that chapter 10's loop books the jump of H as
// work put in. A body whose pins are fixed and whose loads are constant pays for none of this.

#include "scenes/model_auto.hpp"
#include "scenes/scene_file.hpp"

#include "10_linear_dynamics/time_integration.hpp"

#include "common/mesh.hpp"

#include <Eigen/Core>

namespace fem::scenes {

class ContactIntegrator;

/// The applied loads of a body at time t (3n): point loads spread over their vertices, surface
/// tractions lumped a third of each boundary triangle's force (area × traction) to its corners.
/// boundary: the body's boundary triangles (boundary_faces).
Eigen::VectorXd applied_loads(const BodySpec& body, const MatrixX3i& boundary, double t);

/// The step hook of one body of a scene (a chapter 10 Simulation::BeforeStep).
class SceneConditions {
public:
    /// forces: the body's switching force model, or nullptr when its model is fixed (then auto is off);
    /// contact: the body's contact steps (scene_contact.hpp), or nullptr in a scene without obstacles.
    /// fem::Error naming the load (its selector's place in the scene file) for a surface load whose
    /// selected vertices span no boundary triangle: it would apply nothing.
    SceneConditions(const BodySpec& body, const SceneSpec& scene, SceneForces* forces, bool automatic,
                    const ContactIntegrator* contact = nullptr);

    /// The hook: loads at step_end, the pins' velocity over the step, auto's level (see the header
    /// comment). True when the loads or the model changed.
    bool operator()(dynamics::Body& body, const dynamics::State& state, double step_end);

    /// The loads at t = 0 (3n), for the body before its first step.
    const Eigen::VectorXd& initial_loads() const { return initial_loads_; }

private:
    const BodySpec* body_;
    const SceneSpec* scene_;
    SceneForces* forces_;
    bool automatic_;
    const ContactIntegrator* contact_;
    bool loads_change_ = false, pins_move_ = false;
    MatrixX3i boundary_;
    Eigen::VectorXd initial_loads_;
};

}  // namespace fem::scenes
