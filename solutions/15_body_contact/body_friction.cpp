// Chapter 15: lagged friction between two surface primitives of the bodies — their closest points'
// weights, tangent bases and one pair's energy, gradient and Hessian, and their sum over the pairs.
// docs/15_body_contact.md#friction-between-bodies
#include "15_body_contact/body_friction.hpp"

#include "15_body_contact/pair_barrier.hpp"

#include "14_contact/barrier.hpp"

#include "common/error.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace fem::contact {

namespace {

/// The parameter of y's closest point on the line x₀ + t (x₁ − x₀).
double line_parameter(const Eigen::Vector3d& y, const Eigen::Vector3d& x0, const Eigen::Vector3d& x1)
{
    const Eigen::Vector3d e = x1 - x0;
    return (y - x0).dot(e) / e.squaredNorm();
}

}  // namespace

Eigen::Vector4d closest_point_weights(PrimitivePair kind, const Eigen::Matrix<double, 3, 4>& x)
{
    const Eigen::Vector3d x0 = x.col(0), x1 = x.col(1), x2 = x.col(2), x3 = x.col(3);
    if (kind == PrimitivePair::point_triangle) {
        // β over the triangle's corners (x1, x2, x3) of the point closest to p = x0.
        Eigen::Vector3d beta = Eigen::Vector3d::Zero();
        const auto on_edge = [&](int i, int j) {
            const double t = line_parameter(x0, x.col(i + 1), x.col(j + 1));
            beta(i) = 1.0 - t;
            beta(j) = t;
        };
        switch (point_triangle_type(x0, x1, x2, x3)) {
        case PointTriangleType::corner_a: beta(0) = 1.0; break;
        case PointTriangleType::corner_b: beta(1) = 1.0; break;
        case PointTriangleType::corner_c: beta(2) = 1.0; break;
        case PointTriangleType::edge_ab: on_edge(0, 1); break;
        case PointTriangleType::edge_bc: on_edge(1, 2); break;
        case PointTriangleType::edge_ca: on_edge(2, 0); break;
        case PointTriangleType::face: {
            // The normal equations of min |p − a − β_b (b − a) − β_c (c − a)|².
            const Eigen::Vector3d e1 = x2 - x1, e2 = x3 - x1, w = x0 - x1;
            Eigen::Matrix2d A;
            A << e1.dot(e1), e1.dot(e2), e1.dot(e2), e2.dot(e2);
            const Eigen::Vector2d bc = A.inverse() * Eigen::Vector2d(w.dot(e1), w.dot(e2));
            beta << 1.0 - bc(0) - bc(1), bc(0), bc(1);
            break;
        }
        }
        return {1.0, -beta(0), -beta(1), -beta(2)};
    }
    double alpha = 0.0, gamma = 0.0;  // the parameters along edge a = (x0, x1) and edge b = (x2, x3)
    switch (edge_edge_type(x0, x1, x2, x3)) {
    case EdgeEdgeType::a0_b0: break;
    case EdgeEdgeType::a0_b1: gamma = 1.0; break;
    case EdgeEdgeType::a1_b0: alpha = 1.0; break;
    case EdgeEdgeType::a1_b1: alpha = gamma = 1.0; break;
    case EdgeEdgeType::a0_edge_b: gamma = line_parameter(x0, x2, x3); break;
    case EdgeEdgeType::a1_edge_b: alpha = 1.0, gamma = line_parameter(x1, x2, x3); break;
    case EdgeEdgeType::b0_edge_a: alpha = line_parameter(x2, x0, x1); break;
    case EdgeEdgeType::b1_edge_a: gamma = 1.0, alpha = line_parameter(x3, x0, x1); break;
    case EdgeEdgeType::edge_edge: {
        // The normal equations of min |w + α e_a − γ e_b|², w = a₀ − b₀.
        const Eigen::Vector3d ea = x1 - x0, eb = x3 - x2, w = x0 - x2;
        Eigen::Matrix2d A;
        A << ea.dot(ea), -ea.dot(eb), -ea.dot(eb), eb.dot(eb);
        const Eigen::Vector2d ag = A.inverse() * Eigen::Vector2d(-ea.dot(w), eb.dot(w));
        alpha = ag(0);
        gamma = ag(1);
        break;
    }
    }
    return {1.0 - alpha, alpha, -(1.0 - gamma), -gamma};
}

Eigen::Matrix<double, 3, 2> pair_tangent_basis(PrimitivePair kind, const Eigen::Matrix<double, 3, 4>& x,
                                               const Eigen::Vector4d& weights)
{
    Eigen::Vector3d normal = x * weights;  // Γ x: the closest points' difference
    if (kind == PrimitivePair::point_triangle &&
        point_triangle_type(x.col(0), x.col(1), x.col(2), x.col(3)) == PointTriangleType::face)
        normal = (x.col(2) - x.col(1)).cross(x.col(3) - x.col(1));
    else if (kind == PrimitivePair::edge_edge &&
             edge_edge_type(x.col(0), x.col(1), x.col(2), x.col(3)) == EdgeEdgeType::edge_edge)
        normal = (x.col(1) - x.col(0)).cross(x.col(3) - x.col(2));
    if (!(normal.norm() > 0.0))
        throw Error("friction: the tangent basis of a pair was asked where its primitives touch (d = 0)");
    return tangent_basis(normal);
}

BodyFrictionPair body_friction_pair(PrimitivePair kind, const int (&vertices)[4], const Eigen::Matrix<double, 3, 4>& x_lag,
                                    const Eigen::Matrix<double, 3, 4>& x_start, double normal_force,
                                    double coefficient)
{
    if (!(normal_force >= 0.0 && coefficient >= 0.0))
        throw Error(str("friction: a pair's normal force and coefficient must be >= 0, got ", normal_force, " and ",
                        coefficient));
    BodyFrictionPair pair;
    std::copy(vertices, vertices + 4, pair.vertices);
    pair.normal_force = normal_force;
    pair.coefficient = coefficient;
    pair.weights = closest_point_weights(kind, x_lag);
    pair.tangent = pair_tangent_basis(kind, x_lag, pair.weights);
    pair.start = Eigen::Map<const Vector12d>(x_start.data());
    return pair;
}

PrimitiveFunction body_friction(const BodyFrictionPair& pair, const Vector12d& x, double epsilon)
{
    Eigen::Vector3d relative = Eigen::Vector3d::Zero();
    for (int i = 0; i < 4; ++i)
        relative += pair.weights(i) * (x.segment<3>(3 * i) - pair.start.segment<3>(3 * i));
    const LaggedFriction f = lagged_friction(pair.tangent, relative, pair.coefficient * pair.normal_force, epsilon);
    PrimitiveFunction result;
    result.value = f.value;
    for (int i = 0; i < 4; ++i) {
        result.gradient.segment<3>(3 * i) = pair.weights(i) * f.gradient;
        for (int j = 0; j < 4; ++j)
            result.hessian.block<3, 3>(3 * i, 3 * j) = pair.weights(i) * pair.weights(j) * f.hessian;
    }
    return result;
}

namespace {

/// The 4 vertices of a pair at u (3×4): X_v + u_v.
Eigen::Matrix<double, 3, 4> corners(const MatrixX3d& rest, const Eigen::VectorXd& u, const int (&vertices)[4])
{
    Eigen::Matrix<double, 3, 4> x;
    for (int k = 0; k < 4; ++k)
        x.col(k) = rest.row(vertices[k]).transpose() + u.segment<3>(3 * vertices[k]);
    return x;
}

}  // namespace

void BodyFriction::lag(const std::vector<SurfacePair>& pairs, const Eigen::VectorXd& u_lag,
                       const Eigen::VectorXd& u_start, double stiffness, double coefficient,
                       double activation_distance)
{
    if (u_lag.size() != 3 * rest_.rows() || u_start.size() != u_lag.size())
        throw Error(str("friction: the lag needs u_lag and u_start with 3n = ", 3 * rest_.rows(), " entries, got ",
                        u_lag.size(), " and ", u_start.size()));
    pairs_.clear();
    if (coefficient == 0.0)
        return;
    for (const SurfacePair& pair : pairs) {
        const double force = stiffness * pair.mollifier * std::abs(barrier(pair.distance, activation_distance).first);
        pairs_.push_back(body_friction_pair(pair.kind, pair.vertices, corners(rest_, u_lag, pair.vertices),
                                            corners(rest_, u_start, pair.vertices), force, coefficient));
    }
}

Vector12d BodyFriction::stacked(const BodyFrictionPair& pair, const Eigen::VectorXd& u) const
{
    const Eigen::Matrix<double, 3, 4> x = corners(rest_, u, pair.vertices);
    return Eigen::Map<const Vector12d>(x.data());
}

double BodyFriction::energy(const Eigen::VectorXd& u, double epsilon) const
{
    double total = 0.0;
    for (const BodyFrictionPair& pair : pairs_)
        total += body_friction(pair, stacked(pair, u), epsilon).value;
    return total;
}

void BodyFriction::add_gradient(const Eigen::VectorXd& u, double epsilon, Eigen::VectorXd& gradient) const
{
    if (gradient.size() != u.size())
        throw Error(str("friction: the gradient needs ", u.size(), " entries, got ", gradient.size()));
    for (const BodyFrictionPair& pair : pairs_) {
        const PrimitiveFunction f = body_friction(pair, stacked(pair, u), epsilon);
        for (int k = 0; k < 4; ++k)
            gradient.segment<3>(3 * pair.vertices[k]) += f.gradient.segment<3>(3 * k);
    }
}

void BodyFriction::add_hessian(const Eigen::VectorXd& u, double epsilon,
                               std::vector<Eigen::Triplet<double>>& triplets) const
{
    for (const BodyFrictionPair& pair : pairs_)
        add_pair_block(pair.vertices, body_friction(pair, stacked(pair, u), epsilon).hessian, triplets);
}

}  // namespace fem::contact
