#pragma once
// Chapter 15: continuous collision detection (CCD) of two moving primitives — a point against a
// triangle, an edge against an edge — the test IPC needs for body-against-body contact, where the
// obstacles' closed forms (a plane, a sphere) no longer apply. docs/15_body_contact.md#primitive-ccd
//
// The four vertices move linearly over t ∈ [0, 1]: x(t) = (1 − t) x₀ + t x₁. The primitives touch at
// time t when
//     point–triangle:  p(t) = (1 − u − v) a(t) + u b(t) + v c(t)    for some u, v ≥ 0, u + v ≤ 1,
//     edge–edge:       (1 − u) a₀(t) + u a₁(t) = (1 − v) b₀(t) + v b₁(t)   for some u, v ∈ [0, 1].
// Two methods answer "do they touch for some t ∈ [0, 1], and when first?":
//   cubic_ccd      the classic test: the four points are coplanar at the roots of a cubic in t,
//                  det[x₁ − x₀, x₂ − x₀, x₃ − x₀](t) = 0; at each root in [0, 1] test whether the
//                  point lies in the triangle / the edges cross. Fast, and wrong in floating point
//                  exactly where contact happens: a double root (a graze) has no sign change, a
//                  motion that stays coplanar makes the cubic vanish, and a crossing at an edge or
//                  corner is decided by round-off — it has false negatives.
//   inclusion_ccd  a conservative test in the manner of Tight Inclusion (Wang et al. 2021): bisect
//                  the box (t, u, v) ∈ [0, 1]³ of F(t, u, v) = (the two sides' difference above),
//                  each coordinate of which is multilinear, so its range over a box is spanned by its
//                  8 corner values; a box is discarded only when a coordinate is > ε (or < −ε) at all
//                  8 corners, ε bounding the round-off of evaluating F. No root is ever discarded:
//                  no false negatives, and the time it reports is never later than the true one.
// And a reader of the public CCD benchmark's query files (Wang, Ferguson, Schneider, Jiang, Attene,
// Panozzo 2021; data/ccd-unit-tests/).

#include <Eigen/Core>

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

namespace fem::contact {

/// Which primitives a motion holds (the order of its four vertices).
enum class PrimitivePair {
    point_triangle,  ///< vertices p, a, b, c: the point p and the triangle (a, b, c)
    edge_edge,       ///< vertices a₀, a₁, b₀, b₁: the edges (a₀, a₁) and (b₀, b₁)
};

/// "point-triangle" or "edge-edge".
std::string pair_name(PrimitivePair pair);

/// Four vertices moving linearly over t ∈ [0, 1]: column i is vertex i at t = 0 (start, 3×4) and at
/// t = 1 (end, 3×4); x_i(t) = (1 − t) start.col(i) + t end.col(i).
struct PrimitiveMotion {
    Eigen::Matrix<double, 3, 4> start = Eigen::Matrix<double, 3, 4>::Zero();
    Eigen::Matrix<double, 3, 4> end = Eigen::Matrix<double, 3, 4>::Zero();
};

/// What a CCD method answers.
struct CcdResult {
    bool collides = false;
    /// The time of impact in [0, 1] when collides (for inclusion_ccd: never later than the first
    /// true contact); +∞ otherwise.
    double time_of_impact = std::numeric_limits<double>::infinity();
    /// inclusion_ccd: the boxes whose corners were evaluated; cubic_ccd: the roots in [0, 1] tested.
    long long work = 0;
    /// inclusion_ccd: stopped at max_boxes with boxes still queued (time_of_impact is then the lowest
    /// t still queued: still conservative, less precise).
    bool stopped_at_limit = false;
};

/// The naive test. The coplanarity cubic f(t) = (x₁ − x₀)(t) · ((x₂ − x₀)(t) × (x₃ − x₀)(t)) =
/// k₀ + k₁ t + k₂ t² + k₃ t³ (each difference linear in t), its real roots in [0, 1] found by
/// bisection on the intervals between f's critical points (the roots of f′, a quadratic) where f
/// changes sign or vanishes at an end, in increasing order; at each root t*, the inside test in
/// the plane at t*, without tolerance: for a point, with e₁ = b − a, e₂ = c − a, w = p − a and
/// n = e₁ × e₂, its barycentric coordinates u = (w × e₂)·n / n·n, v = (e₁ × w)·n / n·n must satisfy
/// u, v ≥ 0, u + v ≤ 1; for two edges, with d_a = a₁ − a₀, d_b = b₁ − b₀, r = b₀ − a₀ and
/// n = d_a × d_b, the lines' crossing parameters u = (r × d_b)·n / n·n, v = (r × d_a)·n / n·n must lie
/// in [0, 1]. Returns the first root that passes. Known false negatives (by design, for
/// the docs): f ≡ 0 (coplanar motion: no root is isolated, none tested), a root of even multiplicity
/// where round-off removes the sign change, parallel edges (n = 0) or a degenerate triangle, and a
/// crossing exactly at an edge or corner decided by round-off. fem::Error for a non-finite coordinate.
CcdResult cubic_ccd(PrimitivePair pair, const PrimitiveMotion& motion);

/// The inclusion method's parameters.
struct InclusionSettings {
    /// δ: a box whose sides in t, u and v are all ≤ δ and that is not discarded ends the search; its
    /// lowest t is the time of impact: never later than the first contact, and a time at which the
    /// primitives are within about δ × (the motion's size and speed) of touching. In [2⁻⁴⁰, 1]
    /// (2⁻⁴⁰ ≈ 9.1·10⁻¹³: every corner and 1 − u − v stay exact binary fractions).
    double tolerance = 1e-6;
    /// The most boxes evaluated before the search stops and answers the lowest t still queued
    /// (conservative). At least 1.
    long long max_boxes = 1'000'000;
};

/// The conservative test. F(t, u, v) = p(t) − ((1 − u − v) a(t) + u b(t) + v c(t)) (point–triangle)
/// or (1 − u) a₀(t) + u a₁(t) − (1 − v) b₀(t) − v b₁(t) (edge–edge), (t, u, v) ∈ [0, 1]³; the
/// primitives touch where F = 0 (point–triangle: also u + v ≤ 1; a box with u_lo + v_lo > 1 is
/// discarded). Each coordinate F_k is multilinear (degree ≤ 1 in each of t, u, v), so over a box its
/// range is [min, max] of its 8 corner values. Boxes are bisected breadth-first, one level at a
/// time, t then u then v, each level in order of increasing t; a box is discarded when for some k
/// all 8 computed corner values are finite and > ε_k, or all < −ε_k, where
///     ε_k = 4 γ₆ M_k + 2⁻¹⁰⁷⁰,   γ₆ = 6 r / (1 − 6 r),  r = 2⁻⁵³,   M_k = max |x_k| over the 8 inputs
/// bounds the round-off of evaluating F_k at a corner (docs/15_body_contact.md#primitive-ccd). The first
/// box of a level with every side ≤ δ that survives gives the time of impact, its lowest t. Never a
/// false negative; the reported time is never later than the first contact.
/// fem::Error for a non-finite coordinate or settings outside their ranges.
CcdResult inclusion_ccd(PrimitivePair pair, const PrimitiveMotion& motion, const InclusionSettings& settings = {});

/// One query of the CCD benchmark: the motion and the ground truth (the primitives touch for some
/// t ∈ [0, 1]), from the lines first_line … first_line + 7 of its file.
struct CcdQuery {
    PrimitiveMotion motion;
    bool collides = false;
    int first_line = 0;
};

/// Reads a query file of the CCD benchmark (Wang et al. 2021): rows of 7 integers separated by
/// commas, x_num, x_den, y_num, y_den, z_num, z_den, truth (a coordinate is num/den; truth 0 or 1);
/// every 8 rows are one query, the four vertices at t = 0 then the four at t = 1 (vertex–face:
/// v, f₀, f₁, f₂; edge–edge: a₀, a₁, b₀, b₁), the same truth on all 8. fem::Error, naming the file and
/// line, for a file that cannot be read or holds no row, a row without exactly 7 integers, an
/// integer beyond a double's range, a zero denominator, a truth other than 0 or 1 or not the same
/// on a query's rows, and a row count that is not a multiple of 8. Each integer is read as the
/// nearest double (exact below 2⁵³ and for any power of two), the coordinate as their quotient.
std::vector<CcdQuery> read_ccd_queries(const std::filesystem::path& path);

/// The pair a benchmark file holds, from the name of its folder: "vertex-face" (point_triangle) or
/// "edge-edge" (edge_edge); fem::Error naming the file for any other.
PrimitivePair ccd_query_pair(const std::filesystem::path& path);

}  // namespace fem::contact
