// Analytic deformation fields with exact gradients. docs/04_tet_jacobians.md#results
#include "04_tet_jacobians/deformation_fields.hpp"

#include "common/error.hpp"

#include <cmath>
#include <numbers>

namespace fem::tet {

DeformationField affine_field(const std::string& name, const std::string& description, const Eigen::Matrix3d& A,
                              const Eigen::Vector3d& b)
{
    if (!A.allFinite() || !b.allFinite())
        throw Error(str("affine_field '", name, "': A and b must be finite"));
    return {name, description, [A, b](const Eigen::Vector3d& X) -> Eigen::Vector3d { return A * X + b; },
            [A](const Eigen::Vector3d&) -> Eigen::Matrix3d { return A; }};
}

DeformationField twist_field(double rate, double y_axis, double z_axis)
{
    require_finite(rate, "twist_field: the twist rate");
    require_finite(y_axis, "twist_field: the axis position y");
    require_finite(z_axis, "twist_field: the axis position z");
    DeformationField field;
    field.name = "twist";
    field.description = str(rate * 180.0 / std::numbers::pi, " degrees per unit length about the axis");
    field.map = [=](const Eigen::Vector3d& X) -> Eigen::Vector3d {
        const double c = std::cos(rate * X.x()), s = std::sin(rate * X.x());
        const double y = X.y() - y_axis, z = X.z() - z_axis;
        return {X.x(), y_axis + c * y - s * z, z_axis + s * y + c * z};
    };
    field.gradient = [=](const Eigen::Vector3d& X) -> Eigen::Matrix3d {
        const double c = std::cos(rate * X.x()), s = std::sin(rate * X.x());
        const double y = X.y() - y_axis, z = X.z() - z_axis;
        Eigen::Matrix3d F;
        F << 1.0, 0.0, 0.0,
             rate * (-s * y - c * z), c, -s,
             rate * (c * y - s * z), s, c;
        return F;
    };
    return field;
}

DeformationField pinch_field(double depth, double width, double x_centre, double z_axis)
{
    require_finite(depth, "pinch_field: the depth");
    require_positive(width, "pinch_field: the width");
    require_finite(x_centre, "pinch_field: the centre x");
    require_finite(z_axis, "pinch_field: the axis position z");
    const auto bump = [=](double x) { return std::exp(-std::pow((x - x_centre) / width, 2)); };
    DeformationField field;
    field.name = "pinch";
    field.description = str("z scaled by 1 - ", depth, " exp(-((x - ", x_centre, ")/", width, ")^2)");
    field.map = [=](const Eigen::Vector3d& X) -> Eigen::Vector3d {
        return {X.x(), X.y(), z_axis + (X.z() - z_axis) * (1.0 - depth * bump(X.x()))};
    };
    field.gradient = [=](const Eigen::Vector3d& X) -> Eigen::Matrix3d {
        Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
        F(2, 0) = (X.z() - z_axis) * depth * 2.0 * (X.x() - x_centre) / (width * width) * bump(X.x());
        F(2, 2) = 1.0 - depth * bump(X.x());
        return F;
    };
    return field;
}

MatrixX3d deform(const MatrixX3d& V, const DeformationField& field)
{
    MatrixX3d x(V.rows(), 3);
    for (Eigen::Index v = 0; v < V.rows(); ++v)
        x.row(v) = field.map(V.row(v).transpose()).transpose();
    if (!x.allFinite())
        throw Error(str("deform: the field '", field.name, "' produced a non-finite position"));
    return x;
}

}  // namespace fem::tet
