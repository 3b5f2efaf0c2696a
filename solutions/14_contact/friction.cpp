// Chapter 14: lagged, smoothed Coulomb friction — the mollifier, the tangent basis, one pair's
// energy, gradient and Hessian, and the pairs of the surface vertices against the obstacles.
// docs/14_contact.md#friction
#include "14_contact/friction.hpp"

#include "14_contact/barrier.hpp"

#include "common/error.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace fem::contact {

MollifierValue friction_mollifier(double y, double epsilon)
{
    require_positive(epsilon, "friction smoothing ε = ε_v Δt [m]");
    if (!(y >= 0.0))
        throw Error(str("friction_mollifier: the tangential displacement y must be >= 0, got ", y));
    MollifierValue f;
    if (y >= epsilon)
        return {y, 1.0, 0.0};
    // BEGIN EXERCISE 14.4 friction_mollifier #friction
    // HINT: below ε: f₁ = 2y/ε − y²/ε², its derivative f₁' = 2/ε − 2y/ε², and its integral with
    // HINT: f₀(ε) = ε (continuous with f₀ = y above ε): f₀ = y²/ε − y³/(3ε²) + ε/3.
    f.f1 = 2.0 * y / epsilon - y * y / (epsilon * epsilon);
    f.f1_derivative = 2.0 / epsilon - 2.0 * y / (epsilon * epsilon);
    f.f0 = y * y / epsilon - y * y * y / (3.0 * epsilon * epsilon) + epsilon / 3.0;
    // END EXERCISE
    return f;
}

Eigen::Matrix<double, 3, 2> tangent_basis(const Eigen::Vector3d& normal)
{
    const Eigen::Vector3d n = normal.normalized();
    // The axis least aligned with n, crossed with it, gives a first tangent of length ≥ √(2/3).
    Eigen::Index axis = 0;
    n.cwiseAbs().minCoeff(&axis);
    const Eigen::Vector3d first = n.cross(Eigen::Vector3d::Unit(axis)).normalized();
    Eigen::Matrix<double, 3, 2> T;
    T.col(0) = first;
    T.col(1) = n.cross(first);
    return T;
}

LaggedFriction lagged_friction(const Eigen::Matrix<double, 3, 2>& tangent, const Eigen::Vector3d& relative,
                               double scale, double epsilon)
{
    const Eigen::Vector2d s = tangent.transpose() * relative;
    const double y = s.norm();
    const MollifierValue f = friction_mollifier(y, epsilon);
    // f₁(y)/y, finite at y = 0 where it tends to 2/ε.
    const double f1_over_y = y > 0.0 ? f.f1 / y : 2.0 / epsilon;
    // (f₁'y − f₁)/y³ s sᵀ: bounded as y → 0 (it is −s sᵀ/(y ε²) below ε), 0 at y = 0.
    const Eigen::Matrix2d radial =
        y > 0.0 ? Eigen::Matrix2d((f.f1_derivative * y - f.f1) / (y * y * y) * s * s.transpose())
                : Eigen::Matrix2d::Zero();
    LaggedFriction result;
    result.value = scale * f.f0;
    result.gradient = scale * f1_over_y * (tangent * s);
    result.hessian = scale * tangent * (radial + f1_over_y * Eigen::Matrix2d::Identity()) * tangent.transpose();
    return result;
}

std::vector<FrictionPair> obstacle_friction_pairs(const std::vector<std::shared_ptr<const Obstacle>>& obstacles,
                                                  const MatrixX3d& rest, const std::vector<int>& surface,
                                                  const Eigen::VectorXd& u_lag, double lag_time,
                                                  const Eigen::VectorXd& u_start, double time_step, double stiffness,
                                                  double activation_distance)
{
    std::vector<FrictionPair> pairs;
    for (int v : surface)
        for (int o = 0; o < static_cast<int>(obstacles.size()); ++o) {
            const Obstacle& obstacle = *obstacles[static_cast<std::size_t>(o)];
            if (obstacle.friction() == 0.0)
                continue;
            const Eigen::Vector3d x = rest.row(v).transpose() + u_lag.segment<3>(3 * v);
            const double d = obstacle.distance(x, lag_time);
            if (!(d > 0.0 && d < activation_distance))
                continue;
            FrictionPair pair;
            pair.vertex = v;
            pair.obstacle = o;
            std::vector<DistancePiece> pieces;
            obstacle.pieces(x, lag_time, activation_distance, pieces);
            for (const DistancePiece& piece : pieces)
                pair.normal_force += stiffness * std::abs(barrier(piece.distance, activation_distance).first);
            pair.coefficient = obstacle.friction();
            pair.tangent = tangent_basis(obstacle.gradient(x, lag_time));
            pair.start = rest.row(v).transpose() + u_start.segment<3>(3 * v) + time_step * obstacle.velocity();
            pairs.push_back(pair);
        }
    return pairs;
}

}  // namespace fem::contact
