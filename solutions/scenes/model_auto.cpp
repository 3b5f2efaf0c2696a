// Model "auto": what each cheaper model gets wrong, measured per tet; the level it allows; the force
// model that switches between levels. docs/scenes.md#model-auto
#include "scenes/model_auto.hpp"

#include "12_hyperelastic_newton/force_models.hpp"

#include "04_tet_jacobians/tet_jacobians.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace fem::scenes {

Level level_of(const std::string& model)
{
    if (model == hyper::linear_model)
        return Level::linear;
    if (model == hyper::corotational_model)
        return Level::corotational;
    return Level::hyperelastic;
}

std::string level_name(Level level, const std::string& hyperelastic)
{
    switch (level) {
    case Level::linear: return std::string(hyper::linear_model);
    case Level::corotational: return std::string(hyper::corotational_model);
    case Level::hyperelastic: return hyperelastic;
    }
    return "?";
}

DeformationMeasures deformation_measures(const TetMesh& mesh, const MatrixX3d& x, const AutoThresholds& t)
{
    DeformationMeasures m;
    const double rotation_ghost = 1.0 - std::cos(t.rotation);  // the ghost strain of an unstrained rotation
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
    for (const Eigen::Matrix3d& F : tet::deformation_gradients(mesh, x)) {
        const Eigen::Matrix3d H = F - Eigen::Matrix3d::Identity();
        const Eigen::Matrix3d ghost_tensor = 0.5 * H.transpose() * H;  // what sym(H) misses of E
        const Eigen::Matrix3d green = H.transpose() + H;                // 2 sym(H), then E = sym(H) + ½ HᵀH
        const double ghost = eigen.compute(ghost_tensor, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
        const double strain =
            eigen.compute(0.5 * green + ghost_tensor, Eigen::EigenvaluesOnly).eigenvalues().cwiseAbs().maxCoeff();
        m.ghost = std::max(m.ghost, ghost);
        m.strain = std::max(m.strain, strain);
        m.volume_change = std::max(m.volume_change, std::abs(F.determinant() - 1.0));
        m.linear_error = std::max(m.linear_error, ghost / (t.ghost_ratio * strain + rotation_ghost));
    }
    return m;
}

Level choose_level(const DeformationMeasures& m, Level current, const AutoThresholds& t)
{
    const auto needed = [&](double scale) {
        if (m.strain > scale * t.strain || m.volume_change > scale * (1.0 - t.volume_ratio))
            return Level::hyperelastic;
        if (m.linear_error > scale)
            return Level::corotational;
        return Level::linear;
    };
    // Up at once; down only as far as the stricter (hysteresis-scaled) thresholds allow.
    return std::max(needed(1.0), std::min(current, needed(t.hysteresis)));
}

SceneForces::SceneForces(const TetMesh& mesh, const dynamics::Material& material, std::string hyperelastic, Level level)
    : mesh_(mesh), material_(material), hyperelastic_(std::move(hyperelastic)), level_(Level::linear)
{
    set_level(level);
}

void SceneForces::set_level(Level level)
{
    std::unique_ptr<dynamics::ForceModel>& model = models_[static_cast<int>(level)];
    if (model == nullptr)  // built on first use: a linear run never pays for rotations
        model = hyper::make_force_model(level_name(level, hyperelastic_), mesh_, material_);
    level_ = level;
}

}  // namespace fem::scenes
