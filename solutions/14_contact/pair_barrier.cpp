// Chapter 14: one primitive pair's barrier and the time of impact that cuts a step for it.
// docs/14_contact.md#edges-and-corners-of-obstacles
#include "14_contact/pair_barrier.hpp"

#include "14_contact/barrier.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fem::contact {
namespace {

constexpr double infinity = std::numeric_limits<double>::infinity();

/// The squared distance of the primitives of motion at s ∈ [0, 1].
double squared_distance_at(PrimitivePair kind, const PrimitiveMotion& motion, double s)
{
    const Eigen::Matrix<double, 3, 4> x = (1.0 - s) * motion.start + s * motion.end;
    if (kind == PrimitivePair::point_triangle)
        return point_triangle_squared_distance(x.col(0), x.col(1), x.col(2), x.col(3),
                                               point_triangle_type(x.col(0), x.col(1), x.col(2), x.col(3)))
            .value;
    return edge_edge_squared_distance(x.col(0), x.col(1), x.col(2), x.col(3),
                                      edge_edge_type(x.col(0), x.col(1), x.col(2), x.col(3)))
        .value;
}

}  // namespace

PrimitiveFunction mollified_barrier(const PrimitiveFunction& squared_distance, const PrimitiveFunction& mollifier,
                                    double activation_distance, bool with_derivatives)
{
    const double d = std::sqrt(squared_distance.value);
    const BarrierValue b = barrier(d, activation_distance);
    PrimitiveFunction result;
    result.value = mollifier.value * b.value;
    if (!with_derivatives)
        return result;
    const Vector12d distance_gradient = squared_distance.gradient / (2.0 * d);
    const Matrix12d distance_hessian = squared_distance.hessian / (2.0 * d) -
                                       squared_distance.gradient * squared_distance.gradient.transpose() /
                                           (4.0 * d * d * d);
    const Vector12d barrier_gradient = b.first * distance_gradient;
    const Matrix12d barrier_hessian =
        b.second * distance_gradient * distance_gradient.transpose() + b.first * distance_hessian;
    result.gradient = mollifier.value * barrier_gradient + b.value * mollifier.gradient;
    result.hessian = mollifier.value * barrier_hessian + barrier_gradient * mollifier.gradient.transpose() +
                     mollifier.gradient * barrier_gradient.transpose() + b.value * mollifier.hessian;
    return result;
}

void add_pair_block(const int (&vertices)[4], const Matrix12d& block, std::vector<Eigen::Triplet<double>>& triplets)
{
    for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b)
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    triplets.emplace_back(3 * vertices[a] + i, 3 * vertices[b] + j, block(3 * a + i, 3 * b + j));
}

PrimitiveFunction unit_mollifier()
{
    PrimitiveFunction one;
    one.value = 1.0;
    return one;
}

double additive_time_of_impact(PrimitivePair kind, const PrimitiveMotion& motion)
{
    Eigen::Matrix<double, 3, 4> change = motion.end - motion.start;
    change.colwise() -= change.rowwise().mean();
    const int first = kind == PrimitivePair::point_triangle ? 1 : 2;  // vertices of the first primitive
    double first_move = 0.0, second_move = 0.0;
    for (int i = 0; i < 4; ++i) {
        double& move = i < first ? first_move : second_move;
        move = std::max(move, change.col(i).norm());
    }
    const double bound = first_move + second_move;
    const double gap = 0.1 * std::sqrt(squared_distance_at(kind, motion, 0.0));
    if (bound == 0.0)
        return infinity;
    double s = 0.0;
    for (int advance = 0; advance < 100; ++advance) {
        const double step = (std::sqrt(squared_distance_at(kind, motion, s)) - gap) / bound;
        if (step <= 0.0)
            return s;
        s += step;
        if (s > 1.0)
            return infinity;
        if (step < 1e-3 * s)
            break;
    }
    return s;
}

double line_search_time_of_impact(PrimitivePair kind, const PrimitiveMotion& motion)
{
    const double inclusion =
        inclusion_ccd(kind, motion, {.tolerance = 1e-6, .max_boxes = line_search_ccd_boxes}).time_of_impact;
    if (!std::isfinite(inclusion))
        return inclusion;
    return std::max(inclusion, additive_time_of_impact(kind, motion));
}

}  // namespace fem::contact
