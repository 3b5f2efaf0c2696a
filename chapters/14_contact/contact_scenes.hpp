#pragma once
// Chapter 14: the small scenes its checks and studies run — a block dropped on, resting on or sliding
// along the floor z = 0 (or dropped into other obstacles: the bowl) — and the closed forms they are
// measured against. docs/14_contact.md#checks
//
// A slope of angle θ is the floor with gravity tilted by θ: g = g (sin θ, 0, −cos θ), the same
// physics as a tilted plane with vertical gravity, with the block's faces on the axes.

#include "14_contact/contact.hpp"

#include "12_hyperelastic_newton/newton.hpp"

#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include <Eigen/Core>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace fem::contact {

/// Makes the contact terms (ContactTerm) of a body against its obstacles with the potential's
/// options: what a later chapter adds to a block scene (chapter 15's body_contact_term_maker).
using ContactTermMaker = std::function<std::vector<std::unique_ptr<ContactTerm>>(
    const dynamics::Body&, const std::vector<std::shared_ptr<const Obstacle>>&, const ContactOptions&)>;

/// What a block scene is made of.
struct BlockSettings {
    double edge = 0.1;                  ///< the cube's edge [m]
    int cells = 1;                      ///< cubes along an edge (box_mesh)
    double height = 5e-4;               ///< the gap under its lowest face at t = 0 [m]
    Eigen::Vector2d corner = Eigen::Vector2d::Zero();  ///< x and y of its lowest corner [m]
    double slope = 0.0;                 ///< θ [rad] in [0, π/2): gravity tilted along +x
    double friction = 0.0;              ///< μ of the floor
    double gravity = 9.81;              ///< |g| [m/s²]
    double time_step = 1.0 / 100.0;     ///< Δt [s]
    dynamics::Material material{1e6, 0.3, 1000.0};  ///< a stiff rubber, ρ of water
    /// Chapter 12's force model by name (make_force_model). Hyperelastic: its energy is a function of
    /// F alone, so a block that has fallen far carries no round-off of ½uᵀKu with u large, which
    /// near rest would hide the last Newton decrease from the line search.
    std::string model = "stable-neo-hookean";
    hyper::NewtonOptions newton;        ///< chapter 12's Newton
    ContactOptions contact;             ///< d̂, κ, ε_v, …
    int friction_updates = 1;           ///< lagged friction updates per step, 0: until converged (step_with_friction_updates)
    /// What the block meets; empty: the floor z = 0 (a HalfSpace with μ = friction).
    std::vector<std::shared_ptr<const Obstacle>> obstacles;
    /// The contact potential's terms beyond the obstacles; empty: none.
    ContactTermMaker terms;
};

/// A step with contact as a chapter 10 integrator, so that chapter 10's time loop (dynamics::Simulation:
/// its energy books, its divergence check) runs a contact scene: contact_step of a Newton backward
/// Euler whose potential is contact, `updates` lagged friction updates a step, which books the
/// obstacles' work on the body (the barrier's store and the moving obstacles' push) as
/// StepInfo::boundary_work, so that the energy the barrier stores and gives back is neither
/// dissipation nor divergence in the loop's books.
class ContactStep final : public dynamics::Integrator {
public:
    /// newton (with contact set as its potential) and contact are not owned and must outlive it;
    /// updates as step_with_friction_updates takes them (0: until converged; < 0 fails at the step).
    ContactStep(hyper::NewtonBackwardEuler& newton, ContactPotential& contact, int updates);
    std::string name() const override;
    int order() const override { return 1; }
    /// One step of Δt (header comment); fem::Error as contact_step.
    dynamics::StepInfo step(dynamics::Body& body, double time_step, dynamics::State& state) override;
    /// The solves the last step took (one for IPC's one lag).
    int last_solves() const { return last_solves_; }

private:
    hyper::NewtonBackwardEuler& newton_;
    ContactPotential& contact_;
    int updates_;
    int last_solves_ = 0;
};

/// A block of settings.model on the floor z = 0 (a HalfSpace with μ) or among settings.obstacles, its Newton
/// integrator with the contact potential set, its step as a chapter 10 integrator, and its state at
/// rest. Not copyable (the integrators point at the potential).
struct BlockScene {
    std::unique_ptr<dynamics::Body> body;
    std::unique_ptr<ContactPotential> contact;
    std::unique_ptr<hyper::NewtonBackwardEuler> integrator;
    /// The step with contact (Δt and friction updates of the settings) for chapter 10's time loop:
    /// dynamics::Simulation(*body, *stepper, state).
    std::unique_ptr<ContactStep> stepper;
    dynamics::State state;

    /// One step of stepper from state (Δt of the settings); solves (when set) receives the number
    /// of solves it took.
    dynamics::StepInfo step(int* solves = nullptr);
    double time_step = 0.0;
};

/// The block of settings. fem::Error for an edge ≤ 0, cells < 1, a height < 0, θ outside [0, π/2),
/// and what Scene, ContactPotential and NewtonBackwardEuler refuse (friction updates < 0: at the step).
BlockScene block_scene(const BlockSettings& settings);

/// The mass-weighted mean of the vertex velocities (3) [m/s]: the block's centre-of-mass velocity.
Eigen::Vector3d mean_velocity(const dynamics::Body& body, const Eigen::VectorXd& v);
/// The lowest z of the body's vertices at u [m].
double lowest_height(const dynamics::Body& body, const Eigen::VectorXd& u);

/// Δt as the studies' tables write it: "1/100" for 0.01 s (1/Δt rounded).
std::string time_step_label(double time_step);

/// The slide's closed form: a = g (sin θ − μ cos θ) when tan θ > μ, 0 when it sticks [m/s²].
double slope_acceleration(double gravity, double slope, double friction);
/// The speed of a fall from rest through height h: √(2 g h) [m/s].
double drop_speed(double gravity, double height);
/// The steady creep of a block that sticks (tan θ < μ), per step and as a fraction of ε_v Δt:
/// 1 − √(1 − tan θ/μ). The friction μλ f₁(y) holds the tangential load λ tan θ, so
/// f₁(y) = 2y/ε − y²/ε² = tan θ/μ, whose root below ε = ε_v Δt is y = ε (1 − √(1 − tan θ/μ)).
/// fem::Error when it slides (tan θ ≥ μ).
double sticking_creep(double slope, double friction);

}  // namespace fem::contact
