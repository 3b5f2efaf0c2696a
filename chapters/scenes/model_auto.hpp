#pragma once
// Model "auto": the cheapest force model that is accurate enough, chosen per body before every step
// from the deformation of its tets. docs/scenes.md#model-auto
//
// What each cheaper model gets wrong, measured on every tet's deformation gradient F (H = F − I):
//   linear        its strain sym(H) misses the Green strain E = sym(H) + ½ HᵀH by the ghost strain
//                 G = ½ HᵀH. A rotation by θ has G with eigenvalues 0, 1 − cos θ, 1 − cos θ: zero
//                 only at θ = 0 and growing all the way to θ = 180°, so no angle fools it. Linear
//                 is kept while G is small against the tet's real strain |E| (ghost_ratio) or below
//                 the ghost strain of a small rigid rotation (rotation);
//   corotational  linear in the rotated frame: its stress departs from a hyperelastic material's by
//                 a relative O(|E|), and its volume response is linear: kept while |E| ≤ strain and
//                 |det F − 1| ≤ 1 − volume_ratio (an inverted tet, det F ≤ 0, always fails this).

#include "scenes/scene_file.hpp"

#include "10_linear_dynamics/body.hpp"

#include "common/mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <memory>
#include <string>

namespace fem::scenes {

/// The models of "auto", cheapest first.
enum class Level { linear = 0, corotational = 1, hyperelastic = 2 };

/// The level a fixed model name runs at ("linear", "corotational", a hyperelastic material).
Level level_of(const std::string& model);

/// The model name of a level; hyperelastic: the name of the hyperelastic material in use.
std::string level_name(Level level, const std::string& hyperelastic);

/// The deformation of a body, from every tet's deformation gradient F (chapter 04) at positions x,
/// measured against the thresholds of auto. docs/scenes.md#model-auto
struct DeformationMeasures {
    double ghost = 0.0;          ///< largest ghost strain ½ λ_max(HᵀH), H = F − I (1 − cos θ for a rotation by θ)
    double strain = 0.0;         ///< largest |principal value| of the Green strain E = ½(FᵀF − I)
    double volume_change = 0.0;  ///< largest |det F − 1| (≥ 1: a tet is flat or inverted)
    /// The largest, over tets, of ghost_t / (ghost_ratio · strain_t + 1 − cos(rotation)): the ghost
    /// strain as a fraction of what linear elasticity may miss in that tet. Linear holds while ≤ 1.
    double linear_error = 0.0;
};

/// The measures of mesh at deformed positions x (#V×3) for the thresholds t (ghost_ratio and rotation
/// enter linear_error). Two symmetric 3×3 eigenvalue problems per tet, no SVD.
DeformationMeasures deformation_measures(const TetMesh& mesh, const MatrixX3d& x, const AutoThresholds& t);

/// The cheapest level the measures allow: hyperelastic when strain > t.strain or volume_change >
/// 1 − t.volume_ratio; else corotational when linear_error > 1; else linear. From level current, a
/// move up is immediate; a move down needs the measures inside the thresholds scaled by t.hysteresis
/// (linear_error ≤ h, strain ≤ h · t.strain, volume_change ≤ h (1 − t.volume_ratio)), so that a body
/// near a threshold does not switch every step.
Level choose_level(const DeformationMeasures& measures, Level current, const AutoThresholds& t);

/// A body's force model in a scene whose model may change between steps: the model of its current
/// level (each built on first use by chapter 12's factory, so a linear run never pays for rotations).
class SceneForces final : public dynamics::ForceModel {
public:
    /// hyperelastic: the material name used at Level::hyperelastic.
    SceneForces(const TetMesh& mesh, const dynamics::Material& material, std::string hyperelastic, Level level);

    std::string name() const override { return active().name(); }
    double evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& forces) override { return active().evaluate(u, forces); }
    double energy(const Eigen::VectorXd& u) override { return active().energy(u); }
    const dynamics::SparseMatrix& stiffness(const Eigen::VectorXd& u) override { return active().stiffness(u); }
    const dynamics::SparseMatrix& definite_stiffness(const Eigen::VectorXd& u) override
    {
        return active().definite_stiffness(u);
    }
    bool constant_stiffness() const override { return active().constant_stiffness(); }
    Eigen::VectorXd von_mises_stress(const Eigen::VectorXd& u) const override { return active().von_mises_stress(u); }

    Level level() const { return level_; }
    /// The model name of the current level.
    std::string level_model() const { return level_name(level_, hyperelastic_); }
    void set_level(Level level);

private:
    dynamics::ForceModel& active() const { return *models_[static_cast<int>(level_)]; }
    TetMesh mesh_;
    dynamics::Material material_;
    std::string hyperelastic_;
    Level level_;
    std::array<std::unique_ptr<dynamics::ForceModel>, 3> models_;
};

}  // namespace fem::scenes
