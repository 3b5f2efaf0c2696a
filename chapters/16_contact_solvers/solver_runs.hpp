#pragma once
// Chapter 16: IPC's contact step (chapters 14/15) and the augmented Lagrangian step (this chapter)
// run on the same scene, with what each costs and keeps: Newton iterations per step and over the
// steps in contact, linear solves (factorizations), time per step, the smallest distance, the largest
// violation of d ≥ δ, momentum. What the study of ch16_contact_solvers and the tests share.
// docs/16_contact_solvers.md#side-by-side

#include "16_contact_solvers/augmented_lagrangian.hpp"

#include "15_body_contact/body_scenes.hpp"

#include "14_contact/obstacles.hpp"

#include "12_hyperelastic_newton/newton.hpp"

#include "10_linear_dynamics/time_integration.hpp"

#include "common/mesh.hpp"

#include <Eigen/Core>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace fem::contact {

/// Which contact solver a run uses.
enum class ContactSolver {
    ipc,                   ///< chapter 14's contact_step on chapter 15's potential (barrier, CCD line search)
    augmented_lagrangian,  ///< augmented_lagrangian_step (this chapter)
    none,                  ///< no contact at all: the free step the others are measured against
};

/// "IPC", "augmented Lagrangian" or "free".
std::string solver_name(ContactSolver solver);

/// A scene both solvers run: a body (one mesh, possibly several bodies: vertex_body), its
/// obstacles, its start, the steps.
struct SolverScene {
    std::string name;
    dynamics::Scene scene;  ///< mesh, material, gravity, Δt (stable neo-Hookean)
    std::vector<std::shared_ptr<const Obstacle>> obstacles;
    Eigen::VectorXd u0, v0;          ///< the start (3n each; empty: zero)
    bool self_contact = false;       ///< the body's surface pairs too (bodies against bodies)
    std::vector<int> vertex_body;    ///< the body of each vertex (empty: one body)
    int steps = 10;
    double newton_tolerance = 1e-6;  ///< chapter 12's relative tolerance (both solvers)
};

/// One step of a run.
struct SolverStep {
    int newton_iterations = 0;  ///< summed over the step's solves
    int outer_iterations = 1;   ///< the augmented Lagrangian's solves (1 for IPC)
    int factorizations = 0;     ///< the linear solver's prepares (failed ones included)
    double seconds = 0.0;
    double smallest_distance = 0.0;  ///< at the step's end over the pairs within d̂ (+∞: none) [m]
    /// The step was not out of contact (ContactPotential::out_of_contact with d̂ = δ: some pair
    /// within δ at its start or end, or some straight vertex path from start to end meeting an obstacle).
    bool in_contact = false;
};

/// What a run measured.
struct SolverRun {
    std::vector<SolverStep> steps;
    int newton_iterations = 0, factorizations = 0, contact_steps = 0, contact_iterations = 0;
    /// The factorizations with a new sparsity pattern (a new fill-reducing ordering and symbolic
    /// analysis, chapter 15's TimedSolver::new_patterns).
    int new_patterns = 0;
    double seconds = 0.0;
    /// The continuous collision check's share of it: ContactClocks::collision_seconds of the run's
    /// chapter 15 potential (IPC's own; the augmented Lagrangian's collision_check) [s]. The
    /// augmented Lagrangian's own search for the pairs that join is not in it.
    double collision_seconds = 0.0;
    double smallest_distance = 0.0;  ///< over every step's end [m] (+∞: never within d̂)
    /// max over the steps' ends of max(0, δ − d) over the pairs within δ [m]: how far inside δ
    /// (the augmented Lagrangian's constraint; IPC's barrier keeps d < d̂ = δ by design).
    double largest_violation = 0.0;
    double momentum_drift = 0.0;     ///< max over steps |Σ m v − Σ m v₀| / Σ m |v₀| (0 for v₀ = 0)
    std::string error;               ///< the step that failed and why (empty: every step ran)
    dynamics::State end;             ///< the state after the last step run
};

/// Observes a run after each step: the body, the state, and the contact forces on the body (3n) [N]
/// (the augmented Lagrangian's Σ λ ∇g; IPC's barrier forces; zero without contact).
using StepObserver = std::function<void(const dynamics::Body&, const dynamics::State& before,
                                        const dynamics::State& after, const Eigen::VectorXd& forces)>;

/// Puts a potential of one's own between Newton and the run's contact potential (e.g. one that
/// records the line search's safe steps and forwards every call): returns what Newton is to use.
using PotentialWrapper = std::function<hyper::StepPotential&(hyper::StepPotential& contact)>;

/// Runs scene.steps steps of scene with solver (δ = d̂ = options.gap; IPC with chapter 15's
/// defaults, κ adaptive), the linear solver timed (chapter 15's TimedSolver), with chapter 15's
/// referee on every configuration when check_intersections. A step that throws ends the run
/// (SolverRun::error). observer (if set) is called after each step; wrap (if set) puts its potential
/// between Newton and the contact potential.
SolverRun run_scene(const SolverScene& scene, ContactSolver solver, AugmentedLagrangianOptions options = {},
                    bool check_intersections = false, const StepObserver& observer = {},
                    const PotentialWrapper& wrap = {});

/// The scenes of the side-by-side study (docs/16_contact_solvers.md#side-by-side), stiff rubber
/// (Y = 10⁶ Pa, ν = 0.3, ρ = 1000 kg/m³) unless said.

/// A 10 cm cube of cells³ cells dropped from rest, its lowest face height above the floor z = 0,
/// g = 9.81 m/s², Δt = 1/100 s.
SolverScene drop_scene(double height = 0.05, int steps = 40, int cells = 1);

/// A 10 cm cube (one cell) resting 0.5 mm above a floor of friction μ = friction, gravity tilted by
/// slope [rad] along +x (g = 9.81 (sin θ, 0, −cos θ) m/s²: a slope of angle θ), Δt = 1/100 s.
SolverScene slope_scene(double slope, double friction, int steps);

/// Chapter 15's block in the bowl (the mesh obstacle of data/bowl.obj, μ = 0.3): a 4 cm cube of cells³
/// cells of soft rubber (Y = 10⁵ Pa, ν = 0.4), its lowest corner at (0.05, −0.02, 0.045) m, dropped
/// onto the bowl's wall, g = 9.81 m/s², Δt = 1/100 s.
SolverScene bowl_scene(int cells, int steps);

/// Chapter 15's box under the fired block (box_under_block) turned by the rotation of 0.6 rad about
/// (1, 2, 3)/√14: its corners and edges meet the cube's lower face between its vertices.
std::shared_ptr<const Obstacle> turned_box();

/// The cube (one cell, lowest face 0.2 m up, no gravity) fired straight down at speed [m/s] at
/// obstacle for 10 steps of 1/100 s (chapter 15's fired block).
SolverScene fired_scene(std::shared_ptr<const Obstacle> obstacle, double speed);

/// Chapter 15's stack of three (block_stack(reach): one mesh of three bodies with self-contact, the
/// body of vertex v stack_block(v)) on the floor, g = 9.81 m/s², Δt = 1/100 s, Newton's tolerance 10⁻⁹.
SolverScene stack_scene(double reach, int steps);

/// Two copies of mesh (scaled so its largest extent is size [m]), the second gap [m] beyond the first
/// along x, closing at 2 × speed [m/s] while each spins at ±spin [rad/s] about its vertical axis:
/// soft rubber (Y = 10⁵ Pa, ν = 0.4), no gravity, Δt = 1/400 s, self-contact (chapter 15's bunnies).
SolverScene two_bodies_scene(TetMesh mesh, double size, double gap, double speed, double spin, int steps);

}  // namespace fem::contact
