#pragma once
// Analytic deformations x = φ(X) with their exact gradients F(X) = ∂φ/∂X: the known answers that the
// per-tet F of chapter 04 (and the strains of chapter 05) are compared with.
// docs/04_tet_jacobians.md#results

#include "common/types.hpp"

#include <Eigen/Core>

#include <functional>
#include <string>

namespace fem::tet {

/// A deformation x = map(X) with its analytic gradient F(X) = ∂map/∂X.
struct DeformationField {
    std::string name;         ///< short, usable in a file name: "twist"
    std::string description;  ///< for tables: "90 degrees about the axis"
    std::function<Eigen::Vector3d(const Eigen::Vector3d&)> map;
    std::function<Eigen::Matrix3d(const Eigen::Vector3d&)> gradient;
};

/// x = A X + b: F = A everywhere. fem::Error for non-finite entries.
DeformationField affine_field(const std::string& name, const std::string& description,
                              const Eigen::Matrix3d& A, const Eigen::Vector3d& b = Eigen::Vector3d::Zero());

/// A twist about the line parallel to x through (y, z) = (y_axis, z_axis): the cross-section at X
/// turns by θ(X) = rate · X (radians): x = X, (y, z) → axis + R(θ) ((Y, Z) − axis).
/// det F = 1 everywhere. fem::Error for non-finite arguments.
DeformationField twist_field(double rate, double y_axis, double z_axis);

/// A pinch of the height about z = z_axis: z − z_axis is scaled by σ(X) = 1 − depth·exp(−((X − x_centre)/width)²).
/// det F = σ, negative (inverted) where depth·exp(…) > 1. fem::Error unless width > 0 and all finite.
DeformationField pinch_field(double depth, double width, double x_centre, double z_axis);

/// The deformed positions x_v = field.map(V_v), one row per vertex.
MatrixX3d deform(const MatrixX3d& V, const DeformationField& field);

}  // namespace fem::tet
