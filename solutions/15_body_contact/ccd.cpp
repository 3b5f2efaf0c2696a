// Chapter 15: continuous collision detection of a point and a triangle, or two edges, moving
// linearly: the naive coplanarity cubic and the conservative inclusion method, and the reader of the
// CCD benchmark's query files. docs/15_body_contact.md#primitive-ccd
#include "15_body_contact/ccd.hpp"

#include "common/error.hpp"
#include "common/types.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <string_view>

namespace fem::contact {
namespace {

/// Vertex i of the motion at time t: (1 − t) x₀ + t x₁.
Eigen::Vector3d position(const PrimitiveMotion& motion, int i, double t)
{
    return (1.0 - t) * motion.start.col(i) + t * motion.end.col(i);
}

void require_finite_motion(const PrimitiveMotion& motion, const char* method)
{
    for (const auto* points : {&motion.start, &motion.end})
        for (int i = 0; i < 4; ++i)
            for (int k = 0; k < 3; ++k)
                if (!std::isfinite((*points)(k, i)))
                    throw Error(str(method, ": vertex ", i, " at t = ", points == &motion.start ? 0 : 1,
                                    " has a non-finite coordinate ", (*points)(k, i),
                                    "; every coordinate must be a finite number"));
}

// ---- the naive method: the coplanarity cubic -------------------------------------------------

/// Coefficients k₀…k₃ of det[x₁ − x₀, x₂ − x₀, x₃ − x₀](t), each difference d(t) = d₀ + t d′.
std::array<double, 4> coplanarity_cubic(const PrimitiveMotion& motion)
{
    std::array<Eigen::Vector3d, 3> d0, d1;
    for (int i = 0; i < 3; ++i) {
        d0[std::size_t(i)] = motion.start.col(i + 1) - motion.start.col(0);
        d1[std::size_t(i)] = (motion.end.col(i + 1) - motion.end.col(0)) - d0[std::size_t(i)];
    }
    const auto triple = [](const Eigen::Vector3d& x, const Eigen::Vector3d& y, const Eigen::Vector3d& z) {
        return x.dot(y.cross(z));
    };
    return {triple(d0[0], d0[1], d0[2]),
            triple(d1[0], d0[1], d0[2]) + triple(d0[0], d1[1], d0[2]) + triple(d0[0], d0[1], d1[2]),
            triple(d0[0], d1[1], d1[2]) + triple(d1[0], d0[1], d1[2]) + triple(d1[0], d1[1], d0[2]),
            triple(d1[0], d1[1], d1[2])};
}

double evaluate_cubic(const std::array<double, 4>& k, double t)
{
    return ((k[3] * t + k[2]) * t + k[1]) * t + k[0];
}

/// The roots of the cubic in [0, 1], increasing: the interval is cut at f′'s roots, and each piece
/// (where f is monotone) holds a root when f vanishes at its start or changes sign on it, found by
/// bisection to the last bit. None when every coefficient is 0.
std::vector<double> cubic_roots_in_unit_interval(const std::array<double, 4>& k)
{
    std::vector<double> cuts{0.0};
    // f′(t) = 3k₃ t² + 2k₂ t + k₁
    const double a = 3.0 * k[3], b = 2.0 * k[2], c = k[1];
    if (a != 0.0) {
        const double discriminant = b * b - 4.0 * a * c;
        if (discriminant >= 0.0) {
            const double q = -0.5 * (b + std::copysign(std::sqrt(discriminant), b));
            for (double r : {q / a, q != 0.0 ? c / q : infinity})
                if (r > 0.0 && r < 1.0)
                    cuts.push_back(r);
        }
    } else if (b != 0.0 && -c / b > 0.0 && -c / b < 1.0) {
        cuts.push_back(-c / b);
    }
    std::sort(cuts.begin() + 1, cuts.end());
    cuts.push_back(1.0);
    std::vector<double> roots;
    if (k[0] == 0.0 && k[1] == 0.0 && k[2] == 0.0 && k[3] == 0.0)
        return roots;
    const auto add = [&roots](double t) {
        if (roots.empty() || roots.back() != t)
            roots.push_back(t);
    };
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
        double lo = cuts[i], hi = cuts[i + 1];
        double f_lo = evaluate_cubic(k, lo);
        const double f_hi = evaluate_cubic(k, hi);
        if (f_lo == 0.0) {
            add(lo);
            continue;
        }
        if ((f_lo < 0.0) == (f_hi < 0.0) && f_hi != 0.0)
            continue;
        while (true) {
            const double mid = 0.5 * (lo + hi);
            if (mid <= lo || mid >= hi)
                break;
            const double f_mid = evaluate_cubic(k, mid);
            if ((f_mid < 0.0) == (f_lo < 0.0) && f_mid != 0.0) {
                lo = mid;
                f_lo = f_mid;
            } else {
                hi = mid;
            }
        }
        add(hi);
    }
    return roots;
}

/// The exact in-plane test at time t (see cubic_ccd): the point inside the triangle, or the two
/// edges' lines crossing within both edges. False for a degenerate triangle or parallel edges.
bool touches_in_plane(PrimitivePair pair, const PrimitiveMotion& motion, double t)
{
    const Eigen::Vector3d x0 = position(motion, 0, t), x1 = position(motion, 1, t), x2 = position(motion, 2, t),
                          x3 = position(motion, 3, t);
    if (pair == PrimitivePair::point_triangle) {
        const Eigen::Vector3d e1 = x2 - x1, e2 = x3 - x1, w = x0 - x1, n = e1.cross(e2);
        const double nn = n.squaredNorm();
        if (nn == 0.0)
            return false;
        const double u = w.cross(e2).dot(n) / nn, v = e1.cross(w).dot(n) / nn;
        return u >= 0.0 && v >= 0.0 && u + v <= 1.0;
    }
    const Eigen::Vector3d da = x1 - x0, db = x3 - x2, r = x2 - x0, n = da.cross(db);
    const double nn = n.squaredNorm();
    if (nn == 0.0)
        return false;
    const double u = r.cross(db).dot(n) / nn, v = r.cross(da).dot(n) / nn;
    return u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0;
}

// ---- the conservative method: inclusion by bisection ------------------------------------------

/// A box of (t, u, v): lo[axis], hi[axis], axes 0 = t, 1 = u, 2 = v.
struct Box {
    std::array<double, 3> lo{0.0, 0.0, 0.0}, hi{1.0, 1.0, 1.0};
};

/// The weights c_i of F = Σ c_i x_i(t) at (u, v): point–triangle (1, −(1 − u − v), −u, −v),
/// edge–edge (1 − u, u, −(1 − v), −v). Exact for the binary fractions of the boxes' corners.
std::array<double, 4> weights(PrimitivePair pair, double u, double v)
{
    if (pair == PrimitivePair::point_triangle)
        return {1.0, -(1.0 - u - v), -u, -v};
    return {1.0 - u, u, -(1.0 - v), -v};
}

/// F's 8 corner values of the box, coordinate by coordinate (values[k][corner]), each summed left
/// to right as the bound ε assumes: ((c₀x₀ + c₁x₁) + c₂x₂) + c₃x₃, x_i = (1 − t) x_i⁰ + t x_i¹.
std::array<std::array<double, 8>, 3> corner_values(PrimitivePair pair, const PrimitiveMotion& motion, const Box& box)
{
    std::array<std::array<double, 8>, 3> values{};
    for (int ti = 0; ti < 2; ++ti) {
        const double t = ti == 0 ? box.lo[0] : box.hi[0];
        std::array<Eigen::Vector3d, 4> x;
        for (int i = 0; i < 4; ++i)
            x[std::size_t(i)] = position(motion, i, t);
        for (int ui = 0; ui < 2; ++ui)
            for (int vi = 0; vi < 2; ++vi) {
                const std::array<double, 4> c =
                    weights(pair, ui == 0 ? box.lo[1] : box.hi[1], vi == 0 ? box.lo[2] : box.hi[2]);
                const std::size_t corner = std::size_t(4 * ti + 2 * ui + vi);
                for (int k = 0; k < 3; ++k) {
                    double sum = c[0] * x[0][k];
                    for (std::size_t i = 1; i < 4; ++i)
                        sum += c[i] * x[i][k];
                    values[std::size_t(k)][corner] = sum;
                }
            }
    }
    return values;
}

/// True when the box holds no zero of F: some coordinate's 8 corner values are all finite and beyond
/// ±ε_k (a value that overflowed never discards), or (point–triangle) the box lies where u + v > 1.
bool excludes_contact(PrimitivePair pair, const PrimitiveMotion& motion, const Box& box,
                      const Eigen::Vector3d& epsilon)
{
    // BEGIN EXERCISE 15.3 excludes_contact #primitive-ccd
    // HINT: Whether box (its t, u, v ranges: box.lo, box.hi) can hold no time and place of contact
    // HINT: (docs/15_body_contact.md#primitive-ccd). For a point and a triangle, a box entirely where u + v > 1
    // HINT: is outside the triangle. Otherwise F's coordinates are multilinear in (t, u, v), so each one's
    // HINT: range over the box is spanned by its 8 corner values (corner_values(pair, motion, box)[k]): the
    // HINT: box is excluded when, for some coordinate k, all 8 lie above +epsilon[k] or all below
    // HINT: −epsilon[k] (the round-off bound of a computed corner value). A value that is not finite (an
    // HINT: overflow) never excludes: a false "no contact" is the one answer CCD must never give.
    if (pair == PrimitivePair::point_triangle && box.lo[1] + box.lo[2] > 1.0)
        return true;
    const auto values = corner_values(pair, motion, box);
    for (int k = 0; k < 3; ++k) {
        bool above = true, below = true;
        for (double value : values[std::size_t(k)]) {
            above = above && std::isfinite(value) && value > epsilon[k];
            below = below && std::isfinite(value) && value < -epsilon[k];
        }
        if (above || below)
            return true;
    }
    return false;
    // END EXERCISE
}

/// ε_k = 4 γ₆ M_k + 2⁻¹⁰⁷⁰: the round-off bound of one corner value of F_k (docs: #primitive-ccd).
Eigen::Vector3d evaluation_error_bound(const PrimitiveMotion& motion)
{
    constexpr double unit_roundoff = std::numeric_limits<double>::epsilon() / 2.0;  // r = 2⁻⁵³
    const double gamma6 = 6.0 * unit_roundoff / (1.0 - 6.0 * unit_roundoff);
    const Eigen::Vector3d largest =
        motion.start.cwiseAbs().rowwise().maxCoeff().cwiseMax(motion.end.cwiseAbs().rowwise().maxCoeff());
    return (4.0 * gamma6 * largest).array() + std::ldexp(1.0, -1070);
}

}  // namespace

std::string pair_name(PrimitivePair pair)
{
    return pair == PrimitivePair::point_triangle ? "point-triangle" : "edge-edge";
}

CcdResult cubic_ccd(PrimitivePair pair, const PrimitiveMotion& motion)
{
    require_finite_motion(motion, "cubic_ccd");
    CcdResult result;
    for (double t : cubic_roots_in_unit_interval(coplanarity_cubic(motion))) {
        ++result.work;
        if (touches_in_plane(pair, motion, t)) {
            result.collides = true;
            result.time_of_impact = t;
            break;
        }
    }
    return result;
}

CcdResult inclusion_ccd(PrimitivePair pair, const PrimitiveMotion& motion, const InclusionSettings& settings)
{
    require_finite_motion(motion, "inclusion_ccd");
    const double finest = std::ldexp(1.0, -40);
    if (!(settings.tolerance >= finest && settings.tolerance <= 1.0))
        throw Error(str("inclusion_ccd: the tolerance delta must be in [2^-40, 1] (about 9.1e-13 to 1), got ",
                        settings.tolerance));
    if (settings.max_boxes < 1)
        throw Error(str("inclusion_ccd: max_boxes must be at least 1, got ", settings.max_boxes));
    const Eigen::Vector3d epsilon = evaluation_error_bound(motion);

    CcdResult result;
    std::vector<Box> level{Box{}}, next;
    for (int depth = 0; !level.empty(); ++depth) {
        const int axis = depth % 3;  // every box of a level has the same sides
        const Box& first = level.front();
        const bool finest_level = first.hi[0] - first.lo[0] <= settings.tolerance &&
                                  first.hi[1] - first.lo[1] <= settings.tolerance &&
                                  first.hi[2] - first.lo[2] <= settings.tolerance;
        next.clear();
        double next_lowest_t = infinity;
        for (std::size_t i = 0; i < level.size(); ++i) {
            const Box& box = level[i];
            if (result.work == settings.max_boxes) {  // level is sorted by lo[0]: box has its lowest t
                result.collides = true;
                result.stopped_at_limit = true;
                result.time_of_impact = std::min(box.lo[0], next_lowest_t);
                return result;
            }
            ++result.work;
            if (excludes_contact(pair, motion, box, epsilon))
                continue;
            if (finest_level) {
                result.collides = true;
                result.time_of_impact = box.lo[0];
                return result;
            }
            const double mid = 0.5 * (box.lo[std::size_t(axis)] + box.hi[std::size_t(axis)]);
            Box lower = box, upper = box;
            lower.hi[std::size_t(axis)] = mid;
            upper.lo[std::size_t(axis)] = mid;
            next.push_back(lower);
            next.push_back(upper);
            next_lowest_t = std::min(next_lowest_t, box.lo[0]);
        }
        std::stable_sort(next.begin(), next.end(), [](const Box& a, const Box& b) { return a.lo[0] < b.lo[0]; });
        std::swap(level, next);
    }
    return result;
}

// ---- the benchmark's query files ---------------------------------------------------------------

PrimitivePair ccd_query_pair(const std::filesystem::path& path)
{
    const std::string folder = path.parent_path().filename().string();
    if (folder == "vertex-face")
        return PrimitivePair::point_triangle;
    if (folder == "edge-edge")
        return PrimitivePair::edge_edge;
    throw Error(str("CCD query file '", path.string(), "': its folder '", folder,
                    "' does not say what it holds; the benchmark keeps point-triangle queries in a folder ",
                    "named vertex-face and edge-edge queries in one named edge-edge"));
}

std::vector<CcdQuery> read_ccd_queries(const std::filesystem::path& path)
{
    std::ifstream file(path);
    if (!file)
        throw Error(str("cannot read the CCD query file '", path.string(), "'"));
    const auto where = [&path](int line) { return str("CCD query file '", path.string(), "', line ", line, ": "); };
    std::vector<CcdQuery> queries;
    std::string text;
    int line = 0;
    while (std::getline(file, text)) {
        ++line;
        if (!text.empty() && text.back() == '\r')
            text.pop_back();
        // The fields, each an integer (optional sign, digits; spaces around it allowed), read as the
        // nearest double: exact below 2⁵³, and exact for a power of two of any size (the benchmark's
        // denominators, up to 2⁶⁶).
        std::array<double, 7> row{};
        std::size_t count = 0, begin = 0;
        const auto bad_row = [&](const auto&... got) {
            return Error(str(where(line), "expected a row of 7 integers separated by commas (x, y, z as numerator, ",
                             "denominator pairs, then the truth 0 or 1), got ", got...));
        };
        while (true) {
            const std::size_t comma = std::min(text.find(',', begin), text.size());
            std::string_view field(text.data() + begin, comma - begin);
            while (!field.empty() && (field.front() == ' ' || field.front() == '\t'))
                field.remove_prefix(1);
            while (!field.empty() && (field.back() == ' ' || field.back() == '\t'))
                field.remove_suffix(1);
            const std::string_view digits = field.substr(!field.empty() && field.front() == '-' ? 1 : 0);
            if (digits.empty() || digits.find_first_not_of("0123456789") != std::string_view::npos || count == 7)
                throw bad_row("'", text, "'");
            const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), row[count]);
            if (error != std::errc() || end != field.data() + field.size())
                throw Error(str(where(line), "the integer '", field, "' is out of the range of a double"));
            ++count;
            if (comma == text.size())
                break;
            begin = comma + 1;
        }
        if (count != 7)
            throw bad_row(count, " integers: '", text, "'");
        for (int k = 0; k < 3; ++k)
            if (row[std::size_t(2 * k + 1)] == 0.0)
                throw Error(str(where(line), "the denominator of coordinate ", "xyz"[k], " is 0"));
        if (row[6] != 0.0 && row[6] != 1.0)
            throw Error(str(where(line), "the truth (7th integer) must be 0 or 1, got ", row[6]));
        const int row_in_query = (line - 1) % 8;
        if (row_in_query == 0) {
            queries.emplace_back();
            queries.back().first_line = line;
            queries.back().collides = row[6] == 1.0;
        } else if (queries.back().collides != (row[6] == 1.0)) {
            throw Error(str(where(line), "the truth ", row[6], " differs from the ", queries.back().collides ? 1 : 0,
                            " of the query's first row (line ", queries.back().first_line, ")"));
        }
        PrimitiveMotion& motion = queries.back().motion;
        Eigen::Matrix<double, 3, 4>& points = row_in_query < 4 ? motion.start : motion.end;
        for (int k = 0; k < 3; ++k)
            points(k, row_in_query % 4) = row[std::size_t(2 * k)] / row[std::size_t(2 * k + 1)];
    }
    if (line == 0)
        throw Error(str("CCD query file '", path.string(), "' holds no row"));
    if (line % 8 != 0)
        throw Error(str("CCD query file '", path.string(), "' has ", line, " rows, not a multiple of 8 (a query ",
                        "is 8 rows: its four vertices at t = 0, then at t = 1)"));
    return queries;
}

}  // namespace fem::contact
