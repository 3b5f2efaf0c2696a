#pragma once
// The scenes capstone: bodies that meet each other (chapter 14's self-contact across bodies).
// docs/scenes.md#bodies-against-bodies
//
// With [contact] bodies = true, the bodies that can touch are stepped as one incremental potential:
// one chapter 10 Body over the joined mesh (their vertices one after another), whose elasticity is
// block diagonal — JointForces composes each body's own force model over its slice of the unknowns —
// whose mass matrix is built from each body's own density (dynamics::Scene::densities), whose pins
// are each body's, and whose contact couples them through chapter 14's self-contact barrier of the
// joined mesh (SelfContactBarrier: every surface point–triangle and edge–edge pair sharing no
// vertex). Bodies that cannot reach each other stay separate solves (contact_groups decides, once,
// before the first step; the runner checks after every step that it held). BodyGroups is what the
// runner builds, once: the start check, the groups, and the chapter 10 Scene of each body and group.

#include "scenes/scene_file.hpp"

#include "15_body_contact/broad_phase.hpp"

#include "10_linear_dynamics/body.hpp"

#include "common/mesh.hpp"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace fem::scenes {

/// How far a body's vertices can travel in the run, at most as far as its motion is driven [m]:
/// ‖v₀‖ T + ½ (‖g‖ + ‖Σ loads‖/m) T² + the largest prescribed displacement of its pins (a rotation's
/// chord bounded by twice the pinned vertex's distance from the axis, plus the axis's displacement), T the duration and m the
/// body's mass. Elastic deformation driven by pins can move a free vertex further: the runner's check
/// after every step (separate_bodies_apart) catches that.
double travel_bound(const SceneSpec& scene, const BodySpec& body);

/// The groups of bodies stepped as one solve (indices into scene.bodies, each increasing, the groups
/// in the order of their first body). Without [contact] bodies every body is a group of its own;
/// with it, bodies i and j share a group when their rest bounding boxes, each grown by d̂ and its
/// travel_bound, meet (and, transitively, the bodies either meets). fem::Error when a group's bodies
/// differ in damping or mass model (one solve has one of each), naming both bodies.
/// docs/scenes.md#bodies-against-bodies
std::vector<std::vector<int>> contact_groups(const SceneSpec& scene);

/// Refuses, before the first step, bodies that start intersecting or closer than d̂ (with [contact]
/// bodies): fem::Error naming both bodies and the primitives, e.g. "body 'a' vertex 12 is 2e-4 m from
/// body 'b' triangle (3, 7, 9), closer than d̂ = 1e-3 m", for every surface point–triangle and
/// edge–edge pair of two bodies within d̂, every surface edge of one that crosses a surface triangle of
/// the other (chapter 14's first_edge_through_triangle), and a body whose first surface vertex lies
/// inside another's surface (winding number > ½, chapter 13). Nothing without [contact] bodies.
void check_start_gaps(const SceneSpec& scene);

/// After a step: fem::Error when two bodies of different groups (stepped as separate solves) have
/// come within d̂ of each other's bounding boxes at positions x (per body, #V×3), naming both: the
/// grouping's travel bound did not hold (a pin drove one further), and their contact would be missed.
void check_groups_apart(const SceneSpec& scene, const std::vector<std::vector<int>>& groups,
                        const std::vector<MatrixX3d>& positions);

/// The joined mesh of the bodies members (their vertices one after another, tets renumbered).
TetMesh joined_mesh(const SceneSpec& scene, const std::vector<int>& members);

/// Chapter 10's Scene of a group: the joined mesh, each tet's density from its body
/// (Scene::densities), every body's pins (shifted), the scene's gravity, Δt and duration, the bodies'
/// damping and mass model (contact_groups checked that they agree), and as material the
/// volume-weighted mean Young's modulus and the mean density (what chapter 10's divergence check
/// reads: Y V is the sum of the bodies' Y_i V_i).
dynamics::Scene joined_scene(const SceneSpec& scene, const std::vector<int>& members);

/// The bodies of a scene as the solves that step them, built once before the first step: the start
/// check (check_start_gaps), the groups (contact_groups), chapter 10's Scene of every body
/// (dynamics_scene) and of every group of several (joined_scene); after every step, check_apart.
/// The scene must outlive it. docs/scenes.md#bodies-against-bodies
class BodyGroups {
public:
    /// fem::Error as check_start_gaps and contact_groups.
    explicit BodyGroups(const SceneSpec& scene);

    /// The groups: each one's bodies (indices into scene.bodies, increasing), as contact_groups.
    const std::vector<std::vector<int>>& members() const { return members_; }
    /// Chapter 10's Scene of body i alone (its mesh, pins, material, the scene's gravity and Δt).
    const dynamics::Scene& body_scene(std::size_t i) const { return body_scenes_[i]; }
    /// Chapter 10's Scene of group g's joined mesh (joined_scene); null for a group of one body.
    const dynamics::Scene* joint_scene(std::size_t g) const { return joint_scenes_[g] ? &*joint_scenes_[g] : nullptr; }
    /// Whether bodies of separate solves could meet, so that check_apart has work after each step
    /// ([contact] bodies with more than one group).
    bool checks_apart() const { return scene_.contact.bodies && members_.size() > 1; }
    /// check_groups_apart at positions x (per body, #V×3) after a step.
    void check_apart(const std::vector<MatrixX3d>& positions) const;

private:
    const SceneSpec& scene_;
    std::vector<std::vector<int>> members_;
    std::vector<dynamics::Scene> body_scenes_;
    std::vector<std::optional<dynamics::Scene>> joint_scenes_;
};

/// A force model over the joined unknowns of several bodies: body i's model on its slice u_i of u
/// (3n_i entries from 3 offset_i): U(u) = Σ U_i(u_i), f = (f_1, f_2, …), K = blockdiag(K_i).
class JointForces final : public dynamics::ForceModel {
public:
    /// parts: each body's force model (not owned, they must outlive this) and its vertex count.
    JointForces(std::vector<dynamics::ForceModel*> parts, std::vector<Eigen::Index> vertex_counts);

    /// The parts' names joined by "+" ("stvk+corotational"), or the one name they share.
    std::string name() const override;
    double evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& forces) override;
    double energy(const Eigen::VectorXd& u) override;
    const dynamics::SparseMatrix& stiffness(const Eigen::VectorXd& u) override;
    const dynamics::SparseMatrix& definite_stiffness(const Eigen::VectorXd& u) override;
    /// True when every part's is.
    bool constant_stiffness() const override;
    Eigen::VectorXd von_mises_stress(const Eigen::VectorXd& u) const override;

    /// The first vertex of part i in the joined numbering.
    Eigen::Index offset(std::size_t i) const { return offsets_[i]; }

private:
    /// blockdiag of each part's matrix (matrix(part, u_i)) into K_.
    template <class Matrix>
    const dynamics::SparseMatrix& block_diagonal(const Eigen::VectorXd& u, Matrix matrix);
    Eigen::VectorXd slice(const Eigen::VectorXd& u, std::size_t i) const;

    std::vector<dynamics::ForceModel*> parts_;
    std::vector<Eigen::Index> counts_, offsets_;
    dynamics::SparseMatrix K_;
};

}  // namespace fem::scenes
