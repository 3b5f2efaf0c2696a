#include "15_body_contact/distances.hpp"

#include "common/error.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace fem::contact {

namespace {

using Points = std::array<Eigen::Vector3d, 4>;

/// "(x, y, z)" with 17 significant digits: a message names the exact input.
std::string coordinates(const Eigen::Vector3d& x)
{
    std::ostringstream out;
    out.precision(17);
    out << "(" << x.x() << ", " << x.y() << ", " << x.z() << ")";
    return out.str();
}

/// fem::Error unless every coordinate of the named points is finite. what: the function's name.
void require_finite_points(const Points& x, const std::array<const char*, 4>& names, const char* what)
{
    for (int i = 0; i < 4; ++i)
        if (!x[i].allFinite())
            throw Error(str(what, ": ", names[i], " = ", coordinates(x[i]),
                            " is not finite; coordinates must be finite numbers"));
}

/// fem::Error for an edge from x0 to x1 (named `name`, its ends end0 and end1) whose length is at most
/// 10⁻¹⁴ of its endpoints' largest coordinate: its direction would be round-off.
void require_edge(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const char* name, const char* end0,
                  const char* end1, const char* what)
{
    const double length = (x1 - x0).norm(), size = std::max(x0.cwiseAbs().maxCoeff(), x1.cwiseAbs().maxCoeff());
    if (!(length > 1e-14 * size))
        throw Error(str(what, ": edge ", name, " (", end0, " = ", coordinates(x0), ", ", end1, " = ", coordinates(x1),
                        ") has zero length: |", end1, " − ", end0, "| = ", length,
                        " is at most 1e-14 times its largest coordinate; edges must not be degenerate"));
}

/// fem::Error for a triangle whose twice area |(b − a) × (c − a)| is at most 2·10⁻¹⁴ × its longest
/// edge² (fem::validate's rule).
void require_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, const char* what)
{
    const double twice_area = (b - a).cross(c - a).norm();
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    if (!(twice_area > 2e-14 * longest * longest))
        throw Error(str(what, ": the triangle a = ", coordinates(a), ", b = ", coordinates(b), ", c = ", coordinates(c),
                        " has zero area: |(b − a) × (c − a)| = ", twice_area,
                        " is at most 2e-14 times its longest edge squared; triangles must not be degenerate"));
}

/// The checks of a point–triangle pair (p, a, b, c): finite, a triangle of non-zero area.
void check_point_triangle(const Points& x, const char* what)
{
    require_finite_points(x, {"p", "a", "b", "c"}, what);
    require_triangle(x[1], x[2], x[3], what);
}

/// The checks of an edge pair (ea0, ea1, eb0, eb1): finite, edges of non-zero length.
void check_edges(const Points& x, const char* what)
{
    require_finite_points(x, {"ea0", "ea1", "eb0", "eb1"}, what);
    require_edge(x[0], x[1], "a", "ea0", "ea1", what);
    require_edge(x[2], x[3], "b", "eb0", "eb1", what);
}

/// A type's form: the point w₀ = x_i − x_j and the directions x_l − x_m (0, 1 or 2), as the
/// stacked points' indices {i, j}, {l, m}.
struct SpanForm {
    std::array<int, 2> point;
    std::vector<std::array<int, 2>> directions;
};

/// x_i − x_j as coefficients of the stacked points.
Eigen::Vector4d difference(const std::array<int, 2>& ij)
{
    return Eigen::Vector4d::Unit(ij[0]) - Eigen::Vector4d::Unit(ij[1]);
}

/// One type's squared distance d², from the point w₀ = Σ_i base_i x_i to the span of the directions
/// v_k = Σ_i directions_k,i x_i (0, 1 or 2 of them; base and directions as the form's differences): min over y of F = |w(y)|², w(y) = Σ_i c_i(y) x_i,
/// c(y) = base + Σ_k y_k directions_k. Its value by the closed form of the header (|w₀|²,
/// |w₀ × v₁|²/|v₁|², (w₀·(v₁ × v₂))²/|v₁ × v₂|²); its derivatives by the implicit function theorem
/// at the minimiser y (G y = −Vᵀw₀, G = VᵀV), where w = w(y) ⟂ every v_k:
///   ∇d² = F_x, block i = 2 c_i w;
///   ∇²d² = F_xx − F_xy F_yy⁻¹ F_yx = 2 (c cᵀ) ⊗ I − 2 B G⁻¹ Bᵀ,  B_k's block i = c_i v_k + directions_k,i w.
PrimitiveFunction distance_to_span(const Points& x, const SpanForm& form)
{
    const Eigen::Vector4d base = difference(form.point);
    Eigen::Matrix<double, 2, 4> coefficients = Eigen::Matrix<double, 2, 4>::Zero();
    const int k = static_cast<int>(form.directions.size());
    for (int m = 0; m < k; ++m)
        coefficients.row(m) = difference(form.directions[m]).transpose();
    Eigen::Vector3d w0 = Eigen::Vector3d::Zero();
    Eigen::Matrix<double, 3, 2> v = Eigen::Matrix<double, 3, 2>::Zero();
    for (int i = 0; i < 4; ++i) {
        w0 += base[i] * x[i];
        v += x[i] * coefficients.col(i).transpose();
    }
    PrimitiveFunction d;
    Eigen::Vector4d c = base;
    Eigen::Matrix2d inverse_gram = Eigen::Matrix2d::Zero();
    if (k == 0) {
        d.value = w0.squaredNorm();
    } else if (k == 1) {
        d.value = w0.cross(v.col(0)).squaredNorm() / v.col(0).squaredNorm();
        inverse_gram(0, 0) = 1.0 / v.col(0).squaredNorm();
    } else {
        const Eigen::Vector3d n = v.col(0).cross(v.col(1));
        d.value = std::pow(w0.dot(n), 2) / n.squaredNorm();
        inverse_gram = (v.transpose() * v).inverse();
    }
    const Eigen::Vector2d y = -inverse_gram * (v.transpose() * w0);
    c += coefficients.transpose() * y;
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    for (int i = 0; i < 4; ++i)
        w += c[i] * x[i];
    Eigen::Matrix<double, 12, 2> B = Eigen::Matrix<double, 12, 2>::Zero();
    for (int i = 0; i < 4; ++i) {
        d.gradient.segment<3>(3 * i) = 2.0 * c[i] * w;
        for (int j = 0; j < 4; ++j)
            d.hessian.block<3, 3>(3 * i, 3 * j) = 2.0 * c[i] * c[j] * Eigen::Matrix3d::Identity();
        for (int m = 0; m < k; ++m)
            B.block<3, 1>(3 * i, m) = c[i] * v.col(m) + coefficients(m, i) * w;
    }
    d.hessian.noalias() -= (2.0 * B * inverse_gram).lazyProduct(B.transpose());  // (lazy: no GEMM for 12×2×12)
    return d;
}

/// An endpoint's closest point on a segment from x0 to x1, and its feature there (0: x0, 1: x1, 2:
/// the inside, by the clamped parameter t = (p − x0)·e/|e|²).
struct SegmentPoint {
    int feature = 0;
    Eigen::Vector3d point;
};

SegmentPoint closest_on_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& x0, const Eigen::Vector3d& x1)
{
    const Eigen::Vector3d e = x1 - x0;
    const double t = (p - x0).dot(e) / e.squaredNorm();
    if (t <= 0.0)
        return {0, x0};
    if (t >= 1.0)
        return {1, x1};
    return {2, x0 + t * e};
}

}  // namespace

// --- Point and triangle ---------------------------------------------------------------------------

PointTriangleType point_triangle_type(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                      const Eigen::Vector3d& c)
{
    check_point_triangle({p, a, b, c}, "point_triangle_type");
    // BEGIN EXERCISE 15.1 point_triangle_type #distances-between-primitives
    // HINT: Which features of triangle abc hold the point nearest to p (docs/15_body_contact.md#distances-between-primitives):
    // HINT: with t_i = (p − x_i)·(x_{i+1} − x_i)/|x_{i+1} − x_i|², p's parameter along edge i (from corner i to
    // HINT: corner i + 1; corners a, b, c are 0, 1, 2), corner i when t_i ≤ 0 and t_{i−1} ≥ 1 (before edge i's
    // HINT: start and past edge i − 1's end); else edge i (edge_ab, edge_bc, edge_ca) when p lies across the
    // HINT: edge's line from the opposite corner, ((x_{i+1} − x_i) × (p − x_i))·n < 0 with n = (b − a) × (c − a),
    // HINT: and 0 < t_i < 1; else the face. Only signs are tested: no square root, no division but the t_i.
    const std::array<Eigen::Vector3d, 3> x{a, b, c};
    const Eigen::Vector3d n = (b - a).cross(c - a);
    std::array<double, 3> t;  // p's parameter along edge i, from corner i to corner i + 1
    for (int i = 0; i < 3; ++i) {
        const Eigen::Vector3d e = x[(i + 1) % 3] - x[i];
        t[i] = (p - x[i]).dot(e) / e.squaredNorm();
    }
    static constexpr std::array<PointTriangleType, 3> corners{PointTriangleType::corner_a, PointTriangleType::corner_b,
                                                              PointTriangleType::corner_c};
    static constexpr std::array<PointTriangleType, 3> edges{PointTriangleType::edge_ab, PointTriangleType::edge_bc,
                                                            PointTriangleType::edge_ca};
    for (int i = 0; i < 3; ++i)  // corner i: before edge i's start and past the end of edge i − 1
        if (t[i] <= 0.0 && t[(i + 2) % 3] >= 1.0)
            return corners[i];
    for (int i = 0; i < 3; ++i)  // edge i: across its line from the opposite corner (λ < 0), within it
        if ((x[(i + 1) % 3] - x[i]).cross(p - x[i]).dot(n) < 0.0 && t[i] > 0.0 && t[i] < 1.0)
            return edges[i];
    return PointTriangleType::face;
    // END EXERCISE
}

PrimitiveFunction point_triangle_squared_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                                  const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                                  PointTriangleType type)
{
    const Points x{p, a, b, c};
    check_point_triangle(x, "point_triangle_squared_distance");
    // By the order of PointTriangleType; the stacked points: 0 p, 1 a, 2 b, 3 c.
    static const std::array<SpanForm, 7> forms{{{{0, 1}, {}},
                                                {{0, 2}, {}},
                                                {{0, 3}, {}},
                                                {{0, 1}, {{2, 1}}},
                                                {{0, 2}, {{3, 2}}},
                                                {{0, 3}, {{1, 3}}},
                                                {{0, 1}, {{2, 1}, {3, 1}}}}};
    return distance_to_span(x, forms[static_cast<int>(type)]);
}

// --- Two edges ------------------------------------------------------------------------------------

EdgeEdgeType edge_edge_type(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1, const Eigen::Vector3d& eb0,
                            const Eigen::Vector3d& eb1)
{
    check_edges({ea0, ea1, eb0, eb1}, "edge_edge_type");
    // BEGIN EXERCISE 15.2 edge_edge_type #distances-between-primitives
    // HINT: Which features of edges a = (ea0, ea1) and b = (eb0, eb1) hold their closest points
    // HINT: (docs/15_body_contact.md#distances-between-primitives). Not parallel (|e_a × e_b|² above
    // HINT: parallel_edges_sin2 |e_a|²|e_b|²): solve the 2×2 normal equations of |r + s e_a − t e_b|²
    // HINT: (r = ea0 − eb0) for the lines' closest points; both 0 < s, t < 1 gives edge_edge (compare the
    // HINT: numerators with the determinant |e_a × e_b|² instead of dividing). Otherwise the minimum is on the
    // HINT: border of the square: for each endpoint y (ea0, ea1, eb0, eb1) its closest point q on the other
    // HINT: edge (closest_on_segment: a clamped projection, and which feature of the edge q is) — the first
    // HINT: where (y − q)·(y' − y) ≥ 0 (y' the other end of y's edge) names the type; if round-off leaves
    // HINT: none, the nearest. Parallel edges always end on the border.
    const Eigen::Vector3d ea = ea1 - ea0, eb = eb1 - eb0, r = ea0 - eb0;
    const double cross2 = ea.cross(eb).squaredNorm();
    if (cross2 > parallel_edges_sin2 * ea.squaredNorm() * eb.squaredNorm()) {
        // The lines' closest points minimise |r + s e_a − t e_b|²: A s − B t = −D, −B s + C t = E, of
        // determinant A C − B² = |e_a × e_b|²; s, t = the numerators over it.
        const double A = ea.squaredNorm(), B = ea.dot(eb), C = eb.squaredNorm(), D = ea.dot(r), E = eb.dot(r);
        const double s_times_cross2 = B * E - C * D, t_times_cross2 = A * E - B * D;
        if (s_times_cross2 > 0.0 && s_times_cross2 < cross2 && t_times_cross2 > 0.0 && t_times_cross2 < cross2)
            return EdgeEdgeType::edge_edge;
    }
    // On the border of the parameter square: at one of the four endpoints' closest points q on the
    // other edge, the one where moving the endpoint into its own edge does not bring it nearer to q,
    // (y − q)·(y' − y) ≥ 0 (y' its edge's other end). With q's own parameter clamped, that is the
    // minimum's optimality condition (KKT) on the square, enough for the convex |r + s e_a − t e_b|²:
    // a test of signs, so the type is right up to round-off of the border's position.
    using T = EdgeEdgeType;
    struct Candidate {
        const Eigen::Vector3d &end, &other_end;  // y and y'
        SegmentPoint closest;
        std::array<EdgeEdgeType, 3> types;  // by q's feature: the other edge's first end, its second, its inside
    };
    const std::array<Candidate, 4> candidates{
        Candidate{ea0, ea1, closest_on_segment(ea0, eb0, eb1), {T::a0_b0, T::a0_b1, T::a0_edge_b}},
        Candidate{ea1, ea0, closest_on_segment(ea1, eb0, eb1), {T::a1_b0, T::a1_b1, T::a1_edge_b}},
        Candidate{eb0, eb1, closest_on_segment(eb0, ea0, ea1), {T::a0_b0, T::a1_b0, T::b0_edge_a}},
        Candidate{eb1, eb0, closest_on_segment(eb1, ea0, ea1), {T::a0_b1, T::a1_b1, T::b1_edge_a}}};
    for (const Candidate& candidate : candidates)
        if ((candidate.end - candidate.closest.point).dot(candidate.other_end - candidate.end) >= 0.0)
            return candidate.types[candidate.closest.feature];
    // None by round-off (at the border of the inside): the nearest.
    const Candidate& nearest =
        *std::min_element(candidates.begin(), candidates.end(), [](const Candidate& l, const Candidate& r) {
            return (l.end - l.closest.point).squaredNorm() < (r.end - r.closest.point).squaredNorm();
        });
    return nearest.types[nearest.closest.feature];
    // END EXERCISE
}

PrimitiveFunction edge_edge_squared_distance(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                                             const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1, EdgeEdgeType type)
{
    const Points x{ea0, ea1, eb0, eb1};
    check_edges(x, "edge_edge_squared_distance");
    const Eigen::Vector3d ea = ea1 - ea0, eb = eb1 - eb0;
    const double cross2 = ea.cross(eb).squaredNorm();
    if (type == EdgeEdgeType::edge_edge && !(cross2 > parallel_edges_sin2 * ea.squaredNorm() * eb.squaredNorm()))
        throw Error(str("edge_edge_squared_distance: the edge_edge type of parallel edges (|e_a × e_b|² = ", cross2,
                        ", sin² of their angle at most ", parallel_edges_sin2,
                        "); parallel edges take an endpoint type (edge_edge_type)"));
    // By the order of EdgeEdgeType; the stacked points: 0 ea0, 1 ea1, 2 eb0, 3 eb1. The last (edge_edge):
    // ea0 against the plane through eb0 spanned by e_a and e_b, ((ea0 − eb0)·(e_a × e_b))²/|e_a × e_b|².
    static const std::array<SpanForm, 9> forms{{{{0, 2}, {}},
                                                {{0, 3}, {}},
                                                {{1, 2}, {}},
                                                {{1, 3}, {}},
                                                {{0, 2}, {{3, 2}}},
                                                {{1, 2}, {{3, 2}}},
                                                {{2, 0}, {{1, 0}}},
                                                {{3, 0}, {{1, 0}}},
                                                {{0, 2}, {{1, 0}, {3, 2}}}}};
    return distance_to_span(x, forms[static_cast<int>(type)]);
}

// --- The mollifier --------------------------------------------------------------------------------

double edge_edge_mollifier_threshold(const Eigen::Vector3d& ea0_rest, const Eigen::Vector3d& ea1_rest,
                                     const Eigen::Vector3d& eb0_rest, const Eigen::Vector3d& eb1_rest)
{
    check_edges({ea0_rest, ea1_rest, eb0_rest, eb1_rest}, "edge_edge_mollifier_threshold");
    return 1e-3 * (ea1_rest - ea0_rest).squaredNorm() * (eb1_rest - eb0_rest).squaredNorm();
}

PrimitiveFunction edge_edge_mollifier(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                                      const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1, double threshold)
{
    require_finite_points({ea0, ea1, eb0, eb1}, {"ea0", "ea1", "eb0", "eb1"}, "edge_edge_mollifier");
    require_positive(threshold, "edge_edge_mollifier: the threshold ε_x [m⁴]");
    PrimitiveFunction m;
    const Eigen::Vector3d ea = ea1 - ea0, eb = eb1 - eb0;
    const double c = ea.cross(eb).squaredNorm();
    m.value = 1.0;
    if (c >= threshold)
        return m;
    const double ratio = c / threshold;
    m.value = ratio * (2.0 - ratio);
    const double first = 2.0 / threshold * (1.0 - ratio), second = -2.0 / (threshold * threshold);
    // c = |e_a|²|e_b|² − (e_a·e_b)² (Lagrange) as a function of e = (e_a, e_b), then e_a = ea1 − ea0 and
    // e_b = eb1 − eb0: point i's block of ∇c is sign_i ∇_e c of its edge, block (i, j) of ∇²c is
    // sign_i sign_j ∇²_e c of their edges, sign = −1 at a first end, +1 at a second.
    const double A = ea.squaredNorm(), B = ea.dot(eb), C = eb.squaredNorm();
    const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
    const std::array<Eigen::Vector3d, 2> grad_e{2.0 * C * ea - 2.0 * B * eb, 2.0 * A * eb - 2.0 * B * ea};
    const Eigen::Matrix3d across = 4.0 * ea * eb.transpose() - 2.0 * eb * ea.transpose() - 2.0 * B * I;
    const std::array<std::array<Eigen::Matrix3d, 2>, 2> hess_e{
        {{2.0 * C * I - 2.0 * eb * eb.transpose(), across}, {across.transpose(), 2.0 * A * I - 2.0 * ea * ea.transpose()}}};
    const std::array<double, 4> sign{-1.0, 1.0, -1.0, 1.0};
    Vector12d grad_c;
    for (int i = 0; i < 4; ++i) {
        grad_c.segment<3>(3 * i) = sign[i] * grad_e[i / 2];
        for (int j = 0; j < 4; ++j)
            m.hessian.block<3, 3>(3 * i, 3 * j) = first * sign[i] * sign[j] * hess_e[i / 2][j / 2];
    }
    m.gradient = first * grad_c;
    m.hessian.noalias() += second * grad_c * grad_c.transpose();
    return m;
}

}  // namespace fem::contact
