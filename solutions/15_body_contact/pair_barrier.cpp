// Chapter 15: one primitive pair's barrier and the time of impact that cuts a step for it.
// docs/15_body_contact.md#edges-and-corners-of-obstacles
#include "15_body_contact/pair_barrier.hpp"

#include "14_contact/barrier.hpp"

#include "common/types.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <utility>
#include <vector>

namespace fem::contact {
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

double additive_time_of_impact(PrimitivePair kind, const PrimitiveMotion& motion, double radius)
{
    const double start = std::sqrt(squared_distance_at(kind, motion, 0.0)) - radius;
    if (!(start > 0.0))
        return 0.0;  // a rounded pair already touching (radius 0: d(0) > 0 is the caller's)
    return additive_time_to_gap(kind, motion, 0.1 * start, radius);
}

double additive_time_to_gap(PrimitivePair kind, const PrimitiveMotion& motion, double gap, double radius)
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
    if (bound == 0.0)
        return infinity;
    double s = 0.0;
    for (int advance = 0; advance < 100; ++advance) {
        const double step = (std::sqrt(squared_distance_at(kind, motion, s)) - radius - gap) / bound;
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

double coplanar_free_time(PrimitivePair kind, const PrimitiveMotion& motion)
{
    // f(t) = det[A, B, C](t): point–triangle A = b − a, B = c − a, C = p − a; edge–edge A = a₁ − a₀,
    // B = b₀ − a₀, C = b₁ − a₀. On [t₀, t₁] each column is linear, so f is a cubic whose Bernstein
    // coefficients are the sums of the dets with k columns taken at t₁ and 3 − k at t₀ (k = 0…3, up
    // to the positive factors 1, 1/3, 1/3, 1); they bound f there: all of one sign, f has no root.
    const bool point = kind == PrimitivePair::point_triangle;
    const int origin = point ? 1 : 0;
    const int columns[3] = {point ? 2 : 1, point ? 3 : 2, point ? 0 : 3};
    double size = 0.0;  // the largest |x| of the motion's vertices, for the dets' round-off
    for (int i = 0; i < 4; ++i)
        size = std::max({size, motion.start.col(i).norm(), motion.end.col(i).norm()});
    const double round_off = 1e-12 * size * size * size;
    const auto columns_at = [&](double t) {
        const Eigen::Matrix<double, 3, 4> x = (1.0 - t) * motion.start + t * motion.end;
        Eigen::Matrix3d m;
        for (int k = 0; k < 3; ++k)
            m.col(k) = x.col(columns[k]) - x.col(origin);
        return m;
    };
    // Depth first from t = 0: the first interval of width 2⁻¹² whose coefficients do not exclude a
    // root ends the search, at most coplanar_filter_intervals intervals looked at.
    std::vector<std::pair<double, double>> stack = {{0.0, 1.0}};
    for (int looked = 0; !stack.empty(); ++looked) {
        const auto [t0, t1] = stack.back();
        stack.pop_back();
        if (looked == coplanar_filter_intervals)
            return t0;
        const Eigen::Matrix3d m0 = columns_at(t0), m1 = columns_at(t1);
        double coefficients[4] = {0.0, 0.0, 0.0, 0.0};
        for (int pattern = 0; pattern < 8; ++pattern) {  // bit k set: column k at t₁
            Eigen::Matrix3d m;
            int ones = 0;
            for (int k = 0; k < 3; ++k) {
                const bool late = (pattern >> k) & 1;
                m.col(k) = late ? m1.col(k) : m0.col(k);
                ones += late;
            }
            coefficients[ones] += m.col(0).cross(m.col(1)).dot(m.col(2));
        }
        const bool positive = std::all_of(std::begin(coefficients), std::end(coefficients),
                                          [&](double c) { return c > 3.0 * round_off; });
        const bool negative = std::all_of(std::begin(coefficients), std::end(coefficients),
                                          [&](double c) { return c < -3.0 * round_off; });
        if (positive || negative)
            continue;
        if (t1 - t0 <= 0x1p-12)
            return t0;
        const double middle = 0.5 * (t0 + t1);
        stack.emplace_back(middle, t1);
        stack.emplace_back(t0, middle);
    }
    return infinity;
}

double line_search_time_of_impact(PrimitivePair kind, const PrimitiveMotion& motion, double separation)
{
    // No contact before the primitives first turn coplanar: the CCD below looks at the rest only.
    const double free = coplanar_free_time(kind, motion);
    if (free < 1.0) {
        PrimitiveMotion rest = motion;
        rest.start = (1.0 - free) * motion.start + free * motion.end;
        const double inclusion =
            inclusion_ccd(kind, rest, {.tolerance = 1e-6, .max_boxes = line_search_ccd_boxes}).time_of_impact;
        if (std::isfinite(inclusion))
            return free + (1.0 - free) * std::max(inclusion, additive_time_of_impact(kind, rest));
    }
    // They never touch on [0, 1], but may end a hair apart (a free flight that lands exactly on a
    // face: 1.7e-18 m), where the barrier's curvature κ b''(d) ~ κ d̂²/d² swamps every mass in a double.
    // Where the end is nearer than the gap, the step is cut where the distance may first reach it.
    const double gap = 0.1 * std::min(std::sqrt(squared_distance_at(kind, motion, 0.0)), separation);
    if (gap > 0.0 && std::sqrt(squared_distance_at(kind, motion, 1.0)) < gap)
        return additive_time_to_gap(kind, motion, gap);
    return infinity;
}

}  // namespace fem::contact
