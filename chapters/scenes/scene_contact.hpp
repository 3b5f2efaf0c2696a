#pragma once
// The scenes capstone: a body of a scene with obstacles (chapter 14). docs/scenes.md#obstacles
//
// Contact is one more thing a scene may need, and like every other it is paid for only in the steps
// that need it: each step is first taken by the body's own integrator (its model's, as without
// obstacles) and kept when it is out of contact (ContactPotential::out_of_contact: every surface
// vertex at least d̂ from every obstacle at the step's start and end, no path crossing one), where
// the barrier and friction are zero and the step is the contact step's answer. Otherwise the step is
// taken again from its start by chapter 12's Newton backward Euler with chapter 14's contact
// potential (barrier, lagged friction, the line search cut by the continuous collision check), on
// the force model of the body's current level, raised to corotational first if it is linear: the
// linear energy ½ uᵀK u of a body that has moved far from where it started is round-off (its terms
// cancel), so the line search could not tell a decrease from noise (the rule that refuses model
// linear with obstacles, applied to auto's choice of the moment). With [contact] solver =
// "augmented_lagrangian" the contact step is chapter 16's augmented_lagrangian_step instead (the
// multipliers on d ≥ d̂, the same collision check cutting every line search, no barrier).

#include "scenes/contact_cost.hpp"
#include "scenes/model_auto.hpp"
#include "scenes/scene_file.hpp"

#include "14_contact/contact.hpp"
#include "14_contact/surface.hpp"
#include "15_body_contact/timed_solver.hpp"
#include "16_contact_solvers/augmented_lagrangian.hpp"

#include "12_hyperelastic_newton/newton.hpp"

#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include <memory>
#include <string>
#include <vector>

namespace fem::scenes {

/// Newton iterations a contact step may take (chapter 12's default is 50). The contact Hessian is
/// projected to PSD per vertex and per pair, so where the barrier's exact curvature is negative (a
/// vertex near a mesh's edge or corner, an edge pair) the model is stiffer than the energy and Newton
/// converges linearly: measured on bowl_drop's --compare reference (Δt = 1/1600 s), 0.94 per
/// iteration at the slowest step; a 20 cm block fired at 6 m/s at a 5 cm sphere (its faces held by
/// chapter 15's rounded-core barrier, every iterate cut to a tenth of its gap) took 1,214 at its
/// impact, where 200 stopped the run. docs/scenes.md#obstacles
inline constexpr int contact_newton_iterations = 2000;

/// Chapter 14's obstacles of a scene (each spec's obstacle).
std::vector<std::shared_ptr<const contact::Obstacle>> scene_obstacles(const SceneSpec& scene);

/// A body's integrator in a scene with obstacles (header comment): its own integrator while out of
/// contact, Newton backward Euler with the contact potential in the steps that need it.
class ContactIntegrator final : public dynamics::Integrator {
public:
    /// own: the body's integrator without contact (backward Euler; not owned, it must outlive this);
    /// levels: the force model of each body in it (not owned; one, or each body of a group stepped as
    /// one solve, scene_group.hpp), each raised to Level::corotational for a contact step taken at
    /// Level::linear (header comment). The contact potential is built for body against obstacles
    /// with the scene's d̂ and ε_v (κ adaptive), with self_contact its surface against itself too (the
    /// bodies of a group against each other, and each member whose self_contacts entry is true — one
    /// a member, in order — against itself; vertex_body: the member of each vertex), with the scene's
    /// friction between bodies, Newton with the scene's solver and tolerance; body_names: each
    /// member's name (the path check's messages, [contact] check_path). With the scene's solver
    /// "augmented_lagrangian", chapter 16's AugmentedLagrangianContact with δ = d̂ and the same ε_v,
    /// bodies and self-contact. fem::Error as ContactPotential (or AugmentedLagrangianContact).
    ContactIntegrator(dynamics::Integrator& own, std::vector<SceneForces*> levels, const dynamics::Body& body,
                      std::vector<std::shared_ptr<const contact::Obstacle>> obstacles, const SceneSpec& scene,
                      bool self_contact = false, std::vector<int> vertex_body = {}, std::vector<bool> self_contacts = {},
                      std::vector<std::string> body_names = {});

    std::string name() const override { return last_contact_ ? newton_.name() + " with contact" : own_.name(); }
    int order() const override { return 1; }
    bool is_explicit() const override { return !last_contact_ && own_.is_explicit(); }
    /// One step from state (time t) to t + Δt (header comment). A contact step is chapter 14's
    /// contact::contact_step (or, with the augmented Lagrangian, chapter 16's
    /// augmented_lagrangian_step: no barrier stores energy, and its obstacles do not move), which books the obstacles' work on the body in StepInfo::boundary_work
    /// (the barrier's store and the moving obstacles' push: chapter 10's loop counts it as work put
    /// in, so it is not mistaken for dissipation or divergence); a level raised for the step adds the
    /// jump of H it makes at the step's start (dynamics::apply_step_hook's booking).
    /// fem::Error when a step fails.
    dynamics::StepInfo step(dynamics::Body& body, double time_step, dynamics::State& state) override;

    /// The steps so far that needed contact.
    int contact_steps() const { return contact_steps_; }
    /// Whether the last step needed contact.
    bool last_contact() const { return last_contact_; }
    /// IPC's contact potential, or the augmented Lagrangian's collision check (a chapter 15 potential
    /// whose barrier is never evaluated): what decides out_of_contact and counts the pairs.
    const contact::ContactPotential& potential() const { return *checks_; }
    /// The last step's time in the barrier, the collision check and the linear solves, and its new
    /// matrix patterns (contact_cost.hpp; chapter 14's ContactClocks of the contact step's potential
    /// and TimedSolver around its solver): zeros when it was out of contact. With the augmented
    /// Lagrangian, its terms' time is in none of the three (the barrier's is its collision check's
    /// begin_step).
    const ContactStepCost& last_cost() const { return last_cost_; }
    /// The contact pairs at u (3n) at time t (contact_cost.hpp): the self-contact barrier's pairs
    /// within d̂ by kind, and the surface vertices closer than d̂ to each obstacle (one pair per
    /// vertex and obstacle). fem::Error on u's size.
    ContactPairs pairs(const Eigen::VectorXd& u, double time) const;
    /// The surface primitives of the body's mesh: its surface vertices, edges and triangles.
    int surface_primitives() const;

private:
    dynamics::Integrator& own_;
    std::vector<SceneForces*> levels_;
    std::vector<std::shared_ptr<const contact::Obstacle>> obstacles_;
    std::unique_ptr<contact::ContactPotential> barrier_;                  // IPC's (null with the augmented Lagrangian)
    std::unique_ptr<contact::AugmentedLagrangianContact> multipliers_;  // chapter 16's (null with IPC)
    const contact::ContactPotential* checks_ = nullptr;                 // barrier_, or multipliers_'s collision check
    contact::TimedSolver* solver_ = nullptr;  // Newton's solver, timed (owned by newton_)
    hyper::NewtonBackwardEuler newton_;
    contact::SurfacePrimitives surface_;
    MatrixX3d rest_;  // the body's rest positions (#V×3)
    ContactStepCost last_cost_;
    int contact_steps_ = 0;
    bool last_contact_ = false;
};

}  // namespace fem::scenes
