#pragma once
// What a scene's contact steps cost: per contact step the split of its time (the barrier with its
// broad phase, the collision check, the linear solves, the rest) with its Newton iterations, new
// matrix patterns and the contact pairs at its end (contact_steps.csv), and per group of bodies
// with contact the summary (contact_cost.csv, printed at the end of a run).
// docs/scenes.md#what-a-contact-step-costs

#include "common/table.hpp"

#include <string>
#include <vector>

namespace fem::scenes {

/// The time one contact step spent in each part (chapter 14's ContactClocks of the contact potential,
/// 14_contact/contact.hpp, and TimedSolver, 14_contact/timed_solver.hpp): all zero for a step taken
/// out of contact.
struct ContactStepCost {
    double barrier_seconds = 0.0;    ///< the barrier's energy, gradient and Hessian with their broad phase, begin_step [s]
    double collision_seconds = 0.0;  ///< the continuous collision check of the line search, the start's check [s]
    double solve_seconds = 0.0;      ///< the linear solves' prepares (factorisations) and solves [s]
    int new_patterns = 0;            ///< prepares with a new sparsity pattern (a new ordering)
};

/// The contact pairs of a state: the self-contact barrier's pairs within d̂ (point–triangle and
/// edge–edge; 0 without self-contact) and the (surface vertex, obstacle) pairs closer than d̂.
struct ContactPairs {
    int point_triangle = 0, edge_edge = 0, vertex_obstacle = 0;
    int total() const { return point_triangle + edge_edge + vertex_obstacle; }
};

/// One step of a group of bodies with contact (obstacles, other bodies or itself to meet).
struct ContactStepRecord {
    int step = 0;
    double time = 0.0;            ///< at the step's end [s]
    std::string bodies;           ///< the group's body names, "a" or "a+b"
    int surface_primitives = 0;   ///< the group's surface vertices + edges + triangles
    bool contact = false;         ///< the step needed contact (ContactIntegrator::last_contact)
    double seconds = 0.0;         ///< the step's wall time (chapter 10's StepRecord::seconds) [s]
    int newton_iterations = 0;
    ContactStepCost cost;
    ContactPairs pairs;  ///< at the step's end
    /// seconds minus the three timed parts: the own integrator's trial step, the elasticity's
    /// energy, gradient and Hessian, Newton's bookkeeping, the step hook [s].
    double rest_seconds() const
    {
        return seconds - cost.barrier_seconds - cost.collision_seconds - cost.solve_seconds;
    }
};

/// contact_steps.csv: one row per contact step (records with contact) — step, time, bodies, Newton
/// iterations, new matrix patterns, the pairs by kind, the step's time and its split [s].
Table contact_steps_table(const std::vector<ContactStepRecord>& records);

/// contact_cost.csv: one row per group of bodies with contact, in the order of its first record:
/// surface primitives, steps and contact steps, the mean and largest pairs at a contact step's end,
/// the mean Newton iterations and the new matrix patterns per contact step, the mean time per
/// contact step and its split [ms] and the split's shares of the step [measured].
Table contact_cost_table(const std::vector<ContactStepRecord>& records);

}  // namespace fem::scenes
