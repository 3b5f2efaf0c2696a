// Chapter 15: the squared distances between a point and a triangle and between two edges, and the
// edge–edge mollifier — d² against an independent constrained least-squares answer (every face of
// the parameter domain solved by Eigen, the feasible best kept) and a dense sampling of the domain,
// gradients and Hessians against central differences in every region, d² and ∇d² continuous where
// the types meet (found by bisection along random lines), symmetry under relabelling, the
// mollifier's C¹ join, and bad, degenerate and nearly parallel input.
// docs/15_body_contact.md#distances-between-primitives
#include "15_body_contact/distances.hpp"

#include "common/error.hpp"
#include "common/random.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

using namespace fem;
using namespace fem::contact;
using fem::test::EntriesNear;
using fem::test::entries_of;

namespace {

using Points = std::array<Eigen::Vector3d, 4>;

const std::array<const char*, 7> triangle_type_names{"corner_a", "corner_b", "corner_c", "edge_ab",
                                                     "edge_bc",  "edge_ca",  "face"};
const std::array<const char*, 9> edge_type_names{"a0_b0",     "a0_b1",     "a1_b0",     "a1_b1",    "a0_edge_b",
                                                 "a1_edge_b", "b0_edge_a", "b1_edge_a", "edge_edge"};

/// The two kinds of primitive pair, behind one interface for the generic checks: the stacked points'
/// names, the classification and the typed d².
struct Pair {
    bool triangle;  // point–triangle (p, a, b, c), else edge–edge (ea0, ea1, eb0, eb1)

    int type(const Points& x) const
    {
        return triangle ? static_cast<int>(point_triangle_type(x[0], x[1], x[2], x[3]))
                        : static_cast<int>(edge_edge_type(x[0], x[1], x[2], x[3]));
    }
    PrimitiveFunction of_type(const Points& x, int type) const
    {
        return triangle ? point_triangle_squared_distance(x[0], x[1], x[2], x[3], static_cast<PointTriangleType>(type))
                        : edge_edge_squared_distance(x[0], x[1], x[2], x[3], static_cast<EdgeEdgeType>(type));
    }
    /// d² of the type the classification gives.
    PrimitiveFunction classified(const Points& x) const { return of_type(x, type(x)); }
    const char* type_name(int type) const { return triangle ? triangle_type_names[type] : edge_type_names[type]; }
    int types() const { return triangle ? 7 : 9; }
    /// The points as a string, every digit: what a failure prints.
    std::string describe(const Points& x) const
    {
        static const std::array<const char*, 4> triangle_names{"p", "a", "b", "c"}, edge_names{"ea0", "ea1", "eb0", "eb1"};
        std::ostringstream out;
        out.precision(17);
        for (int i = 0; i < 4; ++i)
            out << (triangle ? triangle_names : edge_names)[i] << " = (" << x[i].transpose() << ") ";
        return out.str();
    }
};

const Pair point_triangle{true}, edge_edge{false};

Eigen::Matrix<double, 12, 1> stack(const Points& x)
{
    Eigen::Matrix<double, 12, 1> X;
    X << x[0], x[1], x[2], x[3];
    return X;
}

Points unstack(const Eigen::Matrix<double, 12, 1>& X)
{
    return {X.segment<3>(0), X.segment<3>(3), X.segment<3>(6), X.segment<3>(9)};
}

/// Random points in [−1, 1]³ (the first one, the point of a point–triangle pair, in [−1.5, 1.5]³, so
/// that it lands in every region), skipping triangles thinner than sin ≈ 0.05.
Points random_points(const Pair& pair, unsigned seed)
{
    for (;; seed += 7919) {
        const Eigen::VectorXd r = random_vector(12, seed);
        Points x = unstack(r);
        if (!pair.triangle)
            return x;
        x[0] *= 1.5;
        const double twice_area = (x[2] - x[1]).cross(x[3] - x[1]).norm();
        const double longest = std::max({(x[2] - x[1]).norm(), (x[3] - x[2]).norm(), (x[1] - x[3]).norm()});
        if (twice_area > 0.05 * longest * longest)
            return x;
    }
}

/// The independent answer: min over (u, v) in the pair's parameter domain of |w₀ + u v₁ + v v₂|², by
/// solving the least-squares problem on every face of the domain (its inside with Eigen's QR, each
/// side in closed form, each corner) and keeping the best feasible one. The domain is the triangle
/// u, v ≥ 0, u + v ≤ 1 (a point q = a + u (b − a) + v (c − a) of the triangle) or the square [0, 1]²
/// (ea0 + u e_a and eb0 + v e_b). Returns d² and the type its face means, and the runner-up's d²
/// among the other faces (how clear the type is).
struct Minimum {
    double value = std::numeric_limits<double>::infinity(), runner_up = std::numeric_limits<double>::infinity();
    int type = -1;
};

Minimum constrained_minimum(const Pair& pair, const Points& x)
{
    Eigen::Vector3d w0;
    Eigen::Matrix<double, 3, 2> M;
    std::vector<Eigen::Vector2d> corners;
    std::vector<int> corner_types, side_types;  // side i runs from corner i to corner i + 1
    int inside_type;
    if (pair.triangle) {
        w0 = x[0] - x[1];
        M << x[1] - x[2], x[1] - x[3];
        corners = {{0, 0}, {1, 0}, {0, 1}};
        corner_types = {0, 1, 2};
        side_types = {3, 4, 5};
        inside_type = 6;
    } else {
        w0 = x[0] - x[2];
        M << x[1] - x[0], x[2] - x[3];
        corners = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        corner_types = {0, 2, 3, 1};
        side_types = {6, 5, 7, 4};
        inside_type = 8;
    }
    Minimum best;
    const auto offer = [&](const Eigen::Vector2d& uv, int type) {
        const double value = (w0 + M * uv).squaredNorm();
        if (value < best.value) {
            if (type != best.type)
                best.runner_up = best.value;
            best.value = value;
            best.type = type;
        } else if (type != best.type) {
            best.runner_up = std::min(best.runner_up, value);
        }
    };
    const Eigen::Vector2d inside = M.colPivHouseholderQr().solve(-w0);
    const bool feasible = pair.triangle ? inside.minCoeff() >= 0.0 && inside.sum() <= 1.0
                                        : inside.minCoeff() >= 0.0 && inside.maxCoeff() <= 1.0;
    if (feasible)
        offer(inside, inside_type);
    const int n = static_cast<int>(corners.size());
    for (int i = 0; i < n; ++i) {
        const Eigen::Vector2d from = corners[i], along = corners[(i + 1) % n] - from;
        const Eigen::Vector3d d = M * along;
        const double tau = -(w0 + M * from).dot(d) / d.squaredNorm();
        if (tau >= 0.0 && tau <= 1.0)
            offer(from + tau * along, side_types[i]);
        offer(from, corner_types[i]);
    }
    return best;
}

/// The smallest |w₀ + u v₁ + v v₂|² over a 40 × 40 grid of the domain (a dense sampling: an upper
/// bound of the minimum).
double sampled_minimum(const Pair& pair, const Points& x)
{
    double smallest = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= 40; ++i)
        for (int j = 0; j <= 40; ++j) {
            const double u = i / 40.0, v = j / 40.0;
            if (pair.triangle && u + v > 1.0)
                continue;
            const Eigen::Vector3d w = pair.triangle ? Eigen::Vector3d(x[0] - x[1] - u * (x[2] - x[1]) - v * (x[3] - x[1]))
                                                    : Eigen::Vector3d(x[0] + u * (x[1] - x[0]) - x[2] - v * (x[3] - x[2]));
            smallest = std::min(smallest, w.squaredNorm());
        }
    return smallest;
}

/// ∇ by central differences of the value and ∇² by central differences of the gradient, step h
/// along each of the 12 coordinates, of the classified d².
std::pair<Vector12d, Matrix12d> central_differences(const Pair& pair, const Points& x, double h)
{
    Vector12d gradient;
    Matrix12d hessian;
    const Vector12d X = stack(x);
    for (int i = 0; i < 12; ++i) {
        const Vector12d step = h * Vector12d::Unit(i);
        const PrimitiveFunction plus = pair.classified(unstack(X + step)), minus = pair.classified(unstack(X - step));
        gradient[i] = (plus.value - minus.value) / (2.0 * h);
        hessian.col(i) = (plus.gradient - minus.gradient) / (2.0 * h);
    }
    return {gradient, hessian};
}

/// Whether the type stays the same at every point x ± h e_i (the central differences see one formula).
bool same_type_around(const Pair& pair, const Points& x, double h)
{
    const int type = pair.type(x);
    const Vector12d X = stack(x);
    for (int i = 0; i < 12; ++i)
        for (double sign : {-1.0, 1.0})
            if (pair.type(unstack(X + sign * h * Vector12d::Unit(i))) != type)
                return false;
    return true;
}

}  // namespace

namespace {

/// d² of random pairs of one kind against the constrained least-squares minimum and a sampled one,
/// and the type against the minimum's, every type met. A wrong branch fails thousands of samples:
/// the first few mismatches are printed with their points (every digit), then their count.
void check_least_squares_minimum(const Pair& pair)
{
    constexpr int printed = 5;
    std::map<int, int> seen;
    int types_compared = 0, mismatches = 0;
    for (unsigned seed = 1; seed <= 3000; ++seed) {
        const Points x = random_points(pair, seed);
        const int type = pair.type(x);
        const Minimum minimum = constrained_minimum(pair, x);
        const double d2 = pair.classified(x).value, sampled = sampled_minimum(pair, x);
        const bool clear = minimum.runner_up - minimum.value > 1e-9;  // clear of the border between two types
        const bool value_right = std::abs(d2 - minimum.value) <= 1e-13 && d2 <= sampled + 1e-13;
        const bool type_right = !clear || type == minimum.type;
        types_compared += clear ? 1 : 0;
        ++seen[type];
        if (value_right && type_right)
            continue;
        if (++mismatches <= printed) {
            std::ostringstream out;
            out.precision(17);
            out << "seed " << seed << ": " << pair.describe(x) << "\n  type " << pair.type_name(type)
                << ", the least squares' " << pair.type_name(minimum.type) << "; d^2 = " << d2 << ", the least squares' "
                << minimum.value << ", the sampled minimum " << sampled;
            UNSCOPED_INFO(out.str());
        }
    }
    INFO((pair.triangle ? "point–triangle" : "edge–edge") << ": " << mismatches << " of 3000 samples wrong (the first "
                                                            << printed << " above)");
    CHECK(mismatches == 0);
    CHECK(types_compared > 2900);
    for (int type = 0; type < pair.types(); ++type) {
        INFO("type " << pair.type_name(type));
        CHECK(seen[type] >= 20);
    }
}

}  // namespace

TEST_CASE("point-triangle distance: d^2 equals the constrained least-squares minimum and no sample of the "
          "triangle is nearer, its type that of the minimum, in every region", "[ex15.1]")
{
    check_least_squares_minimum(point_triangle);
}

TEST_CASE("point_triangle_type at the region borders: a tie goes to the corner, an edge's line to the face",
          "[ex15.1]")
{
    // The unit triangle a = (0, 0, 0), b = (1, 0, 0), c = (0, 1, 0): every t_i and every sign below is
    // computed exactly. Corner i when t_i <= 0 and t_{i-1} >= 1 (ties included: ≤ and ≥, not < and >);
    // edge i only when p lies strictly across its line (λ < 0), so a point right above an edge's
    // line, inside its span, is the face's.
    const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
    struct Tie {
        Eigen::Vector3d p;
        PointTriangleType expected;
        const char* why;
    };
    const std::vector<Tie> ties{
        {{0, -1, 1}, PointTriangleType::corner_a, "t_ab = 0, t_ca = 2"},
        {{-1, 0, 1}, PointTriangleType::corner_a, "t_ab = -1, t_ca = 1"},
        {{0, 0, 1}, PointTriangleType::corner_a, "t_ab = 0, t_ca = 1: above the corner"},
        {{1, -1, 1}, PointTriangleType::corner_b, "t_bc = -1/2, t_ab = 1"},
        {{2, 1, 1}, PointTriangleType::corner_b, "t_bc = 0, t_ab = 2"},
        {{1, 2, 1}, PointTriangleType::corner_c, "t_ca = -1, t_bc = 1"},
        {{-1, 1, 1}, PointTriangleType::corner_c, "t_ca = 0, t_bc = 3/2"},
        {{0.5, 0, 1}, PointTriangleType::face, "above edge ab's line (λ_c = 0), t_ab = 1/2"},
        {{0, 0.5, -1}, PointTriangleType::face, "below edge ca's line (λ_b = 0), t_ca = 1/2"},
        {{0.5, 0.5, 1}, PointTriangleType::face, "above edge bc's line (λ_a = 0), t_bc = 1/2"},
        {{0.5, -0.5, 1}, PointTriangleType::edge_ab, "across ab, t_ab = 1/2"},
    };
    const auto name = [](PointTriangleType type) { return point_triangle.type_name(static_cast<int>(type)); };
    for (const Tie& tie : ties) {
        std::ostringstream where;
        where.precision(17);
        where << "point_triangle_type(p = (" << tie.p.transpose() << "), the unit triangle): " << tie.why;
        INFO(where.str() << "; got " << name(point_triangle_type(tie.p, a, b, c)) << ", expected " << name(tie.expected));
        CHECK(point_triangle_type(tie.p, a, b, c) == tie.expected);
    }
}

TEST_CASE("edge-edge distance: d^2 equals the constrained least-squares minimum and no sample of the "
          "square is nearer, its type that of the minimum, in every region", "[ex15.2]")
{
    check_least_squares_minimum(edge_edge);
}

TEST_CASE("primitive distances: gradient and Hessian of d^2 against central differences in every region", "[ex15.2]")
{
    for (const Pair& pair : {point_triangle, edge_edge}) {
        std::map<int, int> checked;
        for (unsigned seed = 1; seed <= 3000; ++seed) {
            const Points x = random_points(pair, seed);
            const int type = pair.type(x);
            const double h = 1e-6;
            if (checked[type] >= 5 || !same_type_around(pair, x, 10.0 * h))
                continue;
            ++checked[type];
            const PrimitiveFunction d = pair.classified(x);
            const auto [gradient, hessian] = central_differences(pair, x, h);
            INFO(pair.describe(x) << "\ntype " << pair.type_name(type));
            const double scale = 1.0 + hessian.norm();  // the differences' error grows with it
            CHECK_THAT(entries_of(d.gradient), EntriesNear(gradient, 1e-8 * scale));
            CHECK_THAT(entries_of(d.hessian), EntriesNear(hessian, 1e-7 * scale));
            CHECK_THAT(entries_of(d.hessian), EntriesNear(d.hessian.transpose(), 1e-12));
        }
        for (int type = 0; type < pair.types(); ++type) {
            INFO("type " << pair.type_name(type));
            CHECK(checked[type] == 5);
        }
    }
}

TEST_CASE("primitive distances: where two types meet, both give the same d^2 and gradient, and central "
          "differences hold just beside the border", "[ex15.2]")
{
    for (const Pair& pair : {point_triangle, edge_edge}) {
        std::set<std::pair<int, int>> borders;
        for (unsigned seed = 1; seed <= 300; ++seed) {
            const Vector12d X = stack(random_points(pair, seed)), D = random_vector(12, 50000 + seed);
            const auto at = [&](double s) { return unstack(X + s * D); };
            for (int step = 0; step < 100; ++step) {
                double lo = -0.5 + step / 100.0, hi = lo + 0.01;
                const int lo_type = pair.type(at(lo));
                if (pair.type(at(hi)) == lo_type)
                    continue;
                for (int halving = 0; halving < 60 && hi - lo > 1e-15; ++halving) {
                    const double mid = 0.5 * (lo + hi);
                    (pair.type(at(mid)) == lo_type ? lo : hi) = mid;
                }
                const int hi_type = pair.type(at(hi));
                const Points border = at(0.5 * (lo + hi));
                const PrimitiveFunction one = pair.of_type(border, lo_type), other = pair.of_type(border, hi_type);
                INFO(pair.describe(border) << "\nbetween " << pair.type_name(lo_type) << " and "
                                           << pair.type_name(hi_type));
                CHECK(std::abs(one.value - other.value) <= 1e-12);
                CHECK_THAT(entries_of(one.gradient), EntriesNear(other.gradient, 1e-9));
                borders.insert(std::minmax(lo_type, hi_type));
                // 10⁻⁴ to either side, where one formula holds for the central differences' steps.
                for (double side : {lo - 1e-4, hi + 1e-4}) {
                    const Points beside = at(side);
                    if (!same_type_around(pair, beside, 1e-6))
                        continue;
                    const auto [gradient, hessian] = central_differences(pair, beside, 1e-6);
                    const PrimitiveFunction d = pair.classified(beside);
                    INFO("beside the border: " << pair.describe(beside));
                    const double scale = 1.0 + hessian.norm();  // the differences' error grows with it
                    CHECK_THAT(entries_of(d.gradient), EntriesNear(gradient, 1e-8 * scale));
                    CHECK_THAT(entries_of(d.hessian), EntriesNear(hessian, 1e-7 * scale));
                }
            }
        }
        // Every border of the regions was crossed: face–edge ×3 and edge–corner ×6 of a triangle;
        // inside–endpoint-edge ×4 and endpoint-edge–endpoints ×8 of two edges.
        const std::vector<std::pair<int, int>> expected =
            pair.triangle ? std::vector<std::pair<int, int>>{{3, 6}, {4, 6}, {5, 6}, {0, 3}, {1, 3}, {1, 4}, {2, 4}, {2, 5},
                                                             {0, 5}}
                          : std::vector<std::pair<int, int>>{{4, 8}, {5, 8}, {6, 8}, {7, 8}, {0, 4}, {1, 4},
                                                             {2, 5}, {3, 5}, {0, 6}, {2, 6}, {1, 7}, {3, 7}};
        for (const auto& [one, other] : expected) {
            INFO("border " << pair.type_name(one) << " | " << pair.type_name(other));
            CHECK(borders.count({one, other}) == 1);
        }
    }
}

TEST_CASE("primitive distances: relabelling the triangle's corners or the edges gives the same d^2 and the "
          "relabelled gradient", "[ex15.2]")
{
    // Each relabelling: where the stacked point i goes.
    const std::vector<std::array<int, 4>> triangle_relabellings{{0, 1, 3, 2}, {0, 2, 1, 3}, {0, 2, 3, 1},
                                                                 {0, 3, 1, 2}, {0, 3, 2, 1}};
    const std::vector<std::array<int, 4>> edge_relabellings{{1, 0, 2, 3}, {0, 1, 3, 2}, {1, 0, 3, 2},
                                                            {2, 3, 0, 1}, {3, 2, 0, 1}, {2, 3, 1, 0}, {3, 2, 1, 0}};
    for (const Pair& pair : {point_triangle, edge_edge})
        for (unsigned seed = 1; seed <= 300; ++seed) {
            const Points x = random_points(pair, seed);
            const PrimitiveFunction d = pair.classified(x);
            for (const std::array<int, 4>& to : pair.triangle ? triangle_relabellings : edge_relabellings) {
                Points y;
                for (int i = 0; i < 4; ++i)
                    y[to[i]] = x[i];
                const PrimitiveFunction e = pair.classified(y);
                Vector12d gradient;
                for (int i = 0; i < 4; ++i)
                    gradient.segment<3>(3 * i) = e.gradient.segment<3>(3 * to[i]);
                INFO(pair.describe(x) << "\nrelabelled as " << pair.describe(y));
                CHECK(std::abs(d.value - e.value) <= 1e-13);
                CHECK_THAT(entries_of(gradient), EntriesNear(d.gradient, 1e-11));
                if (!pair.triangle) {  // c = |e_a × e_b|² is symmetric too
                    const double threshold = 0.5 * std::pow((x[1] - x[0]).cross(x[3] - x[2]).norm(), 2) + 1e-3;
                    CHECK(std::abs(edge_edge_mollifier(x[0], x[1], x[2], x[3], threshold).value -
                                   edge_edge_mollifier(y[0], y[1], y[2], y[3], threshold).value) <= 1e-13);
                }
            }
        }
}

TEST_CASE("edge-edge mollifier: m(c) of c = |e_a x e_b|^2, its gradient and Hessian against central "
          "differences, C1 at c = eps_x, 0 for parallel edges")
{
    const Eigen::Vector3d ea0(0.1, -0.2, 0.05), eb0(0.0, 0.3, -0.1);
    const Eigen::Vector3d ea = Eigen::Vector3d(0.8, 0.3, -0.2), across = ea.cross(Eigen::Vector3d::UnitZ()).normalized();
    const double threshold = edge_edge_mollifier_threshold(ea0, ea0 + ea, eb0, eb0 + 1.2 * ea);
    CHECK(threshold == Approx(1e-3 * ea.squaredNorm() * (1.2 * ea).squaredNorm()).epsilon(1e-15));
    // Edge b turned from a's direction by the angle θ: c = |e_a|²|e_b|² sin²θ (Lagrange's identity,
    // the independent formula), m = 2c/ε_x − c²/ε_x².
    for (double angle : {0.0, 1e-3, 1e-2, 0.02, 0.03, 0.1}) {
        const Eigen::Vector3d eb = 1.2 * (std::cos(angle) * ea + std::sin(angle) * ea.norm() * across);
        const double c = ea.squaredNorm() * eb.squaredNorm() - std::pow(ea.dot(eb), 2), ratio = c / threshold;
        const PrimitiveFunction m = edge_edge_mollifier(ea0, ea0 + ea, eb0, eb0 + eb, threshold);
        INFO("angle " << angle << ", c/eps_x = " << ratio);
        CHECK(m.value == Approx(ratio < 1.0 ? 2.0 * ratio - ratio * ratio : 1.0).margin(1e-12));
        const Points x{ea0, ea0 + ea, eb0, eb0 + eb};
        const Vector12d X = stack(x);
        Vector12d gradient;
        Matrix12d hessian;
        const double h = 1e-7;
        for (int i = 0; i < 12; ++i) {
            const Vector12d step = h * Vector12d::Unit(i);
            const Points plus = unstack(X + step), minus = unstack(X - step);
            const PrimitiveFunction mp = edge_edge_mollifier(plus[0], plus[1], plus[2], plus[3], threshold);
            const PrimitiveFunction mm = edge_edge_mollifier(minus[0], minus[1], minus[2], minus[3], threshold);
            gradient[i] = (mp.value - mm.value) / (2.0 * h);
            hessian.col(i) = (mp.gradient - mm.gradient) / (2.0 * h);
        }
        CHECK_THAT(entries_of(m.gradient), EntriesNear(gradient, 1e-6, 1e-6));
        CHECK_THAT(entries_of(m.hessian), EntriesNear(hessian, 1e-4, 1e-6));
        if (angle == 0.0) {  // parallel (to round-off): m ≈ 0 at c's minimum, where ∇c = 0
            CHECK(m.value <= 1e-12);
            CHECK(m.gradient.norm() <= 1e-3 * gradient.norm() + 1e-9);
        }
        if (ratio >= 1.0) {
            CHECK(m.gradient.isZero(0.0));
            CHECK(m.hessian.isZero(0.0));
        }
    }
    // The join at c = ε_x: from below m = 1 − δ² and |∇m| = 2δ|∇c|/ε_x with c = ε_x (1 − δ), both → the
    // values above (1 and 0) as δ → 0: C¹.
    const Eigen::Vector3d eb = 1.2 * (std::cos(0.1) * ea + std::sin(0.1) * ea.norm() * across);
    const Points x{ea0, ea0 + ea, eb0, eb0 + eb};
    const auto c_of = [](const Points& y) { return (y[1] - y[0]).cross(y[3] - y[2]).squaredNorm(); };
    const double c = c_of(x);
    Vector12d grad_c;  // by central differences
    for (int i = 0; i < 12; ++i) {
        const Vector12d step = 1e-6 * Vector12d::Unit(i);
        grad_c[i] = (c_of(unstack(stack(x) + step)) - c_of(unstack(stack(x) - step))) / 2e-6;
    }
    for (double delta : {1e-2, 1e-4, 1e-6}) {
        // ε_x = c/(1 − δ): m' = 2δ(1 − δ)/c.
        const PrimitiveFunction below = edge_edge_mollifier(x[0], x[1], x[2], x[3], c / (1.0 - delta));
        const PrimitiveFunction above = edge_edge_mollifier(x[0], x[1], x[2], x[3], c / (1.0 + delta));
        INFO("delta " << delta);
        CHECK(below.value == Approx(1.0 - delta * delta).epsilon(1e-12));
        CHECK_THAT(entries_of(below.gradient), EntriesNear(2.0 * delta * (1.0 - delta) / c * grad_c, 1e-8 * delta, 1e-7));
        CHECK(above.value == 1.0);
        CHECK(above.gradient.isZero(0.0));
    }
}

TEST_CASE("primitive distances: non-finite coordinates, zero-length edges and zero-area triangles are refused", "[ex15.2]")
{
    const Eigen::Vector3d o(0, 0, 0), x(1, 0, 0), y(0, 1, 0), z(0, 0, 1), p(0.2, 0.3, 0.5);
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    using Catch::Contains;
    const std::array<const char*, 4> triangle_names{"p = (", "a = (", "b = (", "c = ("}, edge_names{"ea0 = (", "ea1 = (", "eb0 = (", "eb1 = ("};
    for (int i = 0; i < 4; ++i)
        for (double bad : {nan, inf, -inf}) {
            Points t{p, o, x, y}, e{o, x, y, z};
            t[i].y() = bad;
            e[i].z() = bad;
            INFO("point " << i << " with " << bad);
            CHECK_THROWS_WITH(point_triangle_type(t[0], t[1], t[2], t[3]),
                              Contains("point_triangle_type") && Contains(triangle_names[i]) && Contains("not finite"));
            CHECK_THROWS_WITH(point_triangle_squared_distance(t[0], t[1], t[2], t[3], PointTriangleType::face),
                              Contains(triangle_names[i]) && Contains("not finite"));
            CHECK_THROWS_WITH(edge_edge_type(e[0], e[1], e[2], e[3]),
                              Contains("edge_edge_type") && Contains(edge_names[i]) && Contains("not finite"));
            CHECK_THROWS_WITH(edge_edge_squared_distance(e[0], e[1], e[2], e[3], EdgeEdgeType::a0_b0),
                              Contains(edge_names[i]) && Contains("not finite"));
            CHECK_THROWS_WITH(edge_edge_mollifier_threshold(e[0], e[1], e[2], e[3]), Contains(edge_names[i]));
            CHECK_THROWS_WITH(edge_edge_mollifier(e[0], e[1], e[2], e[3], 1.0), Contains(edge_names[i]));
        }
    // Zero-length edges: equal endpoints, and endpoints 10⁻¹² apart at 10³ m (agreeing to 15 digits).
    const Eigen::Vector3d far(1e3, -2e3, 5e2), near_far = far + Eigen::Vector3d(1e-12, 0, 0);
    CHECK_THROWS_WITH(edge_edge_type(o, o, y, z), Contains("edge a") && Contains("zero length"));
    CHECK_THROWS_WITH(edge_edge_type(o, x, far, near_far), Contains("edge b") && Contains("zero length"));
    CHECK_THROWS_WITH(edge_edge_squared_distance(o, x, z, z, EdgeEdgeType::a0_b0), Contains("edge b"));
    CHECK_THROWS_WITH(edge_edge_mollifier_threshold(far, near_far, o, x), Contains("edge a"));
    CHECK_NOTHROW(edge_edge_type(o, Eigen::Vector3d(1e-20, 0, 0), y, z));  // short, but not round-off
    // Zero-area triangles: a repeated corner, three points on a line.
    for (const Points& t : {Points{p, o, x, x}, Points{p, o, x, Eigen::Vector3d(0.3, 0, 0)},
                            Points{p, far, 2.0 * far, 3.0 * far}}) {
        INFO(point_triangle.describe(t));
        CHECK_THROWS_WITH(point_triangle_type(t[0], t[1], t[2], t[3]), Contains("zero area"));
        CHECK_THROWS_WITH(point_triangle_squared_distance(t[0], t[1], t[2], t[3], PointTriangleType::corner_a),
                          Contains("zero area"));
    }
    // The edge_edge form of parallel edges divides by 0: refused; their type is an endpoint one.
    CHECK_THROWS_WITH(edge_edge_squared_distance(o, x, y, y + x, EdgeEdgeType::edge_edge), Contains("parallel"));
    CHECK(edge_edge_type(o, x, y, y + x) != EdgeEdgeType::edge_edge);
    CHECK_THROWS_WITH(edge_edge_mollifier(o, x, y, z, 0.0), Contains("threshold"));
    CHECK_THROWS_WITH(edge_edge_mollifier(o, x, y, z, nan), Contains("threshold"));
    // A sliver (twice its area 10⁻¹⁰ of its longest edge²) is still a triangle, and its d² is right.
    const Points sliver{p, o, x, Eigen::Vector3d(0.5, 1e-10, 0)};
    CHECK(std::abs(point_triangle.classified(sliver).value - constrained_minimum(point_triangle, sliver).value) <= 1e-13);
}

TEST_CASE("edge-edge distance of parallel and nearly parallel edges: an endpoint type at sin^2 <= 1e-10, "
          "within 3e-10 min(|ea|^2, |eb|^2) of the least-squares minimum", "[ex15.2]")
{
    const Eigen::Vector3d ea0(-0.4, 0.1, 0.2), ea(1.0, 0.2, -0.1);
    const Eigen::Vector3d across = ea.cross(Eigen::Vector3d(0.3, 1.0, 0.2)).normalized(), side = across.cross(ea).normalized();
    int endpoint_types = 0, line_line = 0;
    for (double angle : {0.0, 1e-14, 1e-8, 1e-6, 9e-6, 1.1e-5, 1e-4, 1e-3})
        for (double shift : {-0.5, 0.6, 1.2})       // b (backwards along a) from before a, inside it, past it
            for (double gap : {0.0, 1e-6, 0.05}) {  // b's offset off a's plane: touching, close, apart
                // b turned by the angle in a's plane (across), crossing a's line halfway along b.
                const Eigen::Vector3d eb0 = ea0 + shift * ea + gap * side + 0.35 * std::sin(angle) * ea.norm() * across;
                const Eigen::Vector3d eb = -0.7 * (std::cos(angle) * ea + std::sin(angle) * ea.norm() * across);
                const Points x{ea0, ea0 + ea, eb0, eb0 + eb};
                const EdgeEdgeType type = edge_edge_type(x[0], x[1], x[2], x[3]);
                const PrimitiveFunction d = edge_edge.classified(x);
                const double sin2 = ea.normalized().cross(eb.normalized()).squaredNorm();
                INFO(edge_edge.describe(x) << "\nangle " << angle << ", type "
                                           << edge_edge.type_name(static_cast<int>(type)));
                if (sin2 <= parallel_edges_sin2)
                    CHECK(type != EdgeEdgeType::edge_edge);
                (type == EdgeEdgeType::edge_edge ? line_line : endpoint_types) += 1;
                CHECK(std::abs(d.value - constrained_minimum(edge_edge, x).value) <=
                      3e-10 * std::min(ea.squaredNorm(), eb.squaredNorm()) + 1e-13);
                CHECK(d.gradient.allFinite());
                CHECK(d.hessian.allFinite());
            }
    CHECK(line_line > 5);
    CHECK(endpoint_types > 5);
    // Exactly parallel, overlapping: d² is the squared gap; on one line: 0.
    const Eigen::Vector3d gap = 0.05 * across;
    CHECK(edge_edge.classified({ea0, ea0 + ea, ea0 + 0.3 * ea + gap, ea0 + 0.8 * ea + gap}).value ==
          Approx(gap.squaredNorm()).epsilon(1e-12));
    CHECK(edge_edge.classified({ea0, ea0 + ea, ea0 + 0.3 * ea, ea0 + 0.8 * ea}).value <= 1e-30);
}
