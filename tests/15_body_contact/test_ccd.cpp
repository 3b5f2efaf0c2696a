// Chapter 15: continuous collision detection of a point and a triangle and of two edges — the
// inclusion method has no false negative on the CCD benchmark's unit-test queries (against the
// benchmark's ground truth), and its time of impact is never later than the cubic's root;
// hand-made motions whose answer is known in closed form; the naive cubic's false negatives; the
// query-file reader's errors. docs/15_body_contact.md#primitive-ccd
#include "15_body_contact/ccd.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/random.hpp"

#include "../common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <fstream>
#include <limits>

using namespace fem;
using namespace fem::contact;

namespace {

const double delta = InclusionSettings{}.tolerance;

/// A motion from the four start and four end positions, one row each.
PrimitiveMotion motion(const Eigen::Matrix<double, 4, 3>& start, const Eigen::Matrix<double, 4, 3>& end)
{
    PrimitiveMotion m;
    m.start = start.transpose();
    m.end = end.transpose();
    return m;
}

/// The triangle (0,0,0), (1,0,0), (0,1,0), fixed, and the point going from `from` to `to`.
PrimitiveMotion point_over_unit_triangle(const Eigen::Vector3d& from, const Eigen::Vector3d& to)
{
    Eigen::Matrix<double, 4, 3> start, end;
    start << from.transpose(), 0, 0, 0, 1, 0, 0, 0, 1, 0;
    end << to.transpose(), 0, 0, 0, 1, 0, 0, 0, 1, 0;
    return motion(start, end);
}

/// The fixed edge (0,0,0)–(1,0,0) and the edge (0.25, y, z₀)–(0.75, y, z₀) moving to z₁: parallel to it.
PrimitiveMotion parallel_edges(double y, double z0, double z1)
{
    Eigen::Matrix<double, 4, 3> start, end;
    start << 0, 0, 0, 1, 0, 0, 0.25, y, z0, 0.75, y, z0;
    end << 0, 0, 0, 1, 0, 0, 0.25, y, z1, 0.75, y, z1;
    return motion(start, end);
}

struct Counts {
    int queries = 0, truly_colliding = 0, false_negatives = 0, false_positives = 0;
};

template <class Method>
Counts count_errors(const std::string& folder, const Method& method)
{
    Counts counts;
    for (const char* name : {"data_0_0.csv", "data_0_1.csv"}) {
        const std::filesystem::path file = data_path(str("ccd-unit-tests/", folder, "/", name));
        const PrimitivePair pair = ccd_query_pair(file);
        for (const CcdQuery& query : read_ccd_queries(file)) {
            const CcdResult result = method(pair, query.motion);
            ++counts.queries;
            counts.truly_colliding += query.collides;
            counts.false_negatives += query.collides && !result.collides;
            counts.false_positives += !query.collides && result.collides;
        }
    }
    return counts;
}

CcdResult inclusion(PrimitivePair pair, const PrimitiveMotion& m) { return inclusion_ccd(pair, m); }
CcdResult cubic(PrimitivePair pair, const PrimitiveMotion& m) { return cubic_ccd(pair, m); }

}  // namespace

TEST_CASE("inclusion CCD: no false negative on the benchmark's 250 vertex-face and 74 edge-edge queries", "[ex15.3]")
{
    const Counts vertex_face = count_errors("vertex-face", inclusion);
    CHECK(vertex_face.queries == 250);
    CHECK(vertex_face.truly_colliding == 124);
    CHECK(vertex_face.false_negatives == 0);
    const Counts edge_edge = count_errors("edge-edge", inclusion);
    CHECK(edge_edge.queries == 74);
    CHECK(edge_edge.truly_colliding == 36);
    CHECK(edge_edge.false_negatives == 0);
}

TEST_CASE("inclusion CCD: its time of impact is never later than a root the cubic confirms", "[ex15.3]")
{
    // Where the cubic finds a contact, its root t_c is a true contact time up to the cubic's
    // round-off; the inclusion method's time must come no later (conservative), and in [0, 1].
    int compared = 0;
    for (const char* folder : {"vertex-face", "edge-edge"})
        for (const char* name : {"data_0_0.csv", "data_0_1.csv"}) {
            const std::filesystem::path file = data_path(str("ccd-unit-tests/", folder, "/", name));
            const PrimitivePair pair = ccd_query_pair(file);
            for (const CcdQuery& query : read_ccd_queries(file)) {
                const CcdResult naive = cubic_ccd(pair, query.motion);
                const CcdResult safe = inclusion_ccd(pair, query.motion);
                if (safe.collides) {
                    CHECK(safe.time_of_impact >= 0.0);
                    CHECK(safe.time_of_impact <= 1.0);
                }
                if (naive.collides) {
                    INFO(file.string() << ", line " << query.first_line << ": cubic root " << naive.time_of_impact);
                    REQUIRE(safe.collides);
                    CHECK(safe.time_of_impact <= naive.time_of_impact + 1e-9);
                    ++compared;
                }
            }
        }
    CHECK(compared > 50);
}

TEST_CASE("primitive CCD: a point falling straight onto a triangle's face at t = 0.5", "[ex15.3]")
{
    const PrimitiveMotion m = point_over_unit_triangle({0.2, 0.3, 1.0}, {0.2, 0.3, -1.0});
    const CcdResult naive = cubic_ccd(PrimitivePair::point_triangle, m);
    CHECK(naive.collides);
    CHECK(naive.time_of_impact == Approx(0.5).margin(1e-15));
    // F_z = 1 − 2t: a box survives only if [1 − 2t_hi, 1 − 2t_lo] reaches within ε of 0, so the
    // first surviving box of side ≤ δ starts in [0.5 − δ − ε, 0.5].
    const CcdResult safe = inclusion_ccd(PrimitivePair::point_triangle, m);
    CHECK(safe.collides);
    CHECK_FALSE(safe.stopped_at_limit);
    CHECK(safe.time_of_impact <= 0.5);
    CHECK(safe.time_of_impact >= 0.5 - delta - 1e-15);
    // A coarser tolerance answers earlier, never later.
    const CcdResult coarse = inclusion_ccd(PrimitivePair::point_triangle, m, {1e-2, 1'000'000});
    CHECK(coarse.time_of_impact <= 0.5);
    CHECK(coarse.time_of_impact >= 0.5 - 1e-2 - 1e-15);
    CHECK(coarse.work < safe.work);
}

TEST_CASE("primitive CCD: a touch exactly at t = 1, and misses by a small margin", "[ex15.3]")
{
    const PrimitiveMotion landing = point_over_unit_triangle({0.2, 0.3, 1.0}, {0.2, 0.3, 0.0});
    const CcdResult touch = inclusion_ccd(PrimitivePair::point_triangle, landing);
    CHECK(touch.collides);
    CHECK(touch.time_of_impact <= 1.0);
    CHECK(touch.time_of_impact >= 1.0 - delta - 1e-15);
    const CcdResult naive_touch = cubic_ccd(PrimitivePair::point_triangle, landing);
    CHECK(naive_touch.collides);
    CHECK(naive_touch.time_of_impact == 1.0);

    // Stops 10⁻³ above the face; falls 10⁻³ beside the edge x = 0; falls 7·10⁻⁴ beside the edge x + y = 1
    // (inside the square u, v ∈ [0, 1] of the inclusion method's boxes, outside the triangle).
    for (const PrimitiveMotion& miss : {point_over_unit_triangle({0.2, 0.3, 1.0}, {0.2, 0.3, 1e-3}),
                                        point_over_unit_triangle({-1e-3, 0.3, 1.0}, {-1e-3, 0.3, -1.0}),
                                        point_over_unit_triangle({0.5005, 0.5005, 1.0}, {0.5005, 0.5005, -1.0})}) {
        const CcdResult safe = inclusion_ccd(PrimitivePair::point_triangle, miss);
        CHECK_FALSE(safe.collides);
        CHECK(std::isinf(safe.time_of_impact));
        CHECK_FALSE(cubic_ccd(PrimitivePair::point_triangle, miss).collides);
    }
    // Edges crossing at right angles with a gap of 10⁻³ at their closest.
    Eigen::Matrix<double, 4, 3> start, end;
    start << 0, 0, 0, 1, 0, 0, 0.5, -0.5, 1, 0.5, 0.5, 1;
    end << 0, 0, 0, 1, 0, 0, 0.5, -0.5, 1e-3, 0.5, 0.5, 1e-3;
    CHECK_FALSE(inclusion_ccd(PrimitivePair::edge_edge, motion(start, end)).collides);
    end(2, 2) = end(3, 2) = -1.0;  // the same edges passing through: contact at z = 0, t = 0.5
    const CcdResult cross = inclusion_ccd(PrimitivePair::edge_edge, motion(start, end));
    CHECK(cross.collides);
    CHECK(cross.time_of_impact <= 0.5);
    CHECK(cross.time_of_impact >= 0.5 - delta - 1e-15);
}

TEST_CASE("primitive CCD: parallel edges — the cubic vanishes, the inclusion method still decides", "[ex15.3]")
{
    // Two parallel lines always lie in one plane: the coplanarity cubic is 0 for every t, no root
    // is isolated, and the naive method cannot see the edges land on each other at t = 0.5.
    const PrimitiveMotion landing = parallel_edges(0.0, 1.0, -1.0);
    CHECK_FALSE(cubic_ccd(PrimitivePair::edge_edge, landing).collides);  // a false negative, by design
    // F = 0 on a whole segment of (u, v) at t = 0.5 (the edges overlap), so the boxes covering it
    // double every two levels and the search stops at max_boxes: still a collision, no later than
    // t = 0.5, and close to it (the boxes are then 2⁻¹⁶ wide in t).
    const CcdResult safe = inclusion_ccd(PrimitivePair::edge_edge, landing);
    CHECK(safe.collides);
    CHECK(safe.stopped_at_limit);
    CHECK(safe.time_of_impact <= 0.5);
    CHECK(safe.time_of_impact >= 0.5 - 1e-3);
    // The same motion 0.1 to the side passes by: both say no.
    const PrimitiveMotion passing = parallel_edges(0.1, 1.0, -1.0);
    CHECK_FALSE(inclusion_ccd(PrimitivePair::edge_edge, passing).collides);
    CHECK_FALSE(cubic_ccd(PrimitivePair::edge_edge, passing).collides);
}

TEST_CASE("primitive CCD: the naive cubic's false negatives are real: on the benchmark, at a graze, "
          "in coplanar motion", "[ex15.3]")
{
    const Counts vertex_face = count_errors("vertex-face", cubic);
    const Counts edge_edge = count_errors("edge-edge", cubic);
    CHECK(vertex_face.false_negatives + edge_edge.false_negatives > 0);

    // A graze: a = 0 and b = (1, 0, 0) fixed, c = (0, 1, 2t − 1) tilting the plane about the x axis,
    // p = (1/5, (1 − 2t)/4 + 1/4, (2t − 1)/4). The cubic is f = e_x · (c × p) = p_z − c_z p_y
    // = (2t − 1)²/4 ≥ 0: p touches the plane at t = 1/2 only, at (1/5, 1/4, 0), inside the triangle,
    // and f has no sign change there. Turned by rotations (round-off in every coordinate), the
    // computed f at its minimum is ±round-off: where it comes out > 0 the cubic sees no root.
    Eigen::Matrix<double, 4, 3> start, end;
    start << 0.2, 0.5, -0.25, 0, 0, 0, 1, 0, 0, 0, 1, -1;
    end << 0.2, 0.0, 0.25, 0, 0, 0, 1, 0, 0, 0, 1, 1;
    int missed = 0;
    const int rotations = 40;
    for (int r = 0; r < rotations; ++r) {
        const Eigen::Vector3d axis = random_vector(3, 100 + unsigned(r)).normalized();
        const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.1 + r, axis).toRotationMatrix();
        const PrimitiveMotion graze = motion(start * rotation.transpose(), end * rotation.transpose());
        missed += !cubic_ccd(PrimitivePair::point_triangle, graze).collides;
        const CcdResult safe = inclusion_ccd(PrimitivePair::point_triangle, graze);
        CHECK(safe.collides);
        CHECK(safe.time_of_impact <= 0.5);
    }
    CHECK(missed > 0);
    CHECK(missed < rotations);  // and some it happens to catch: round-off decides, not geometry

    // Coplanar motion: the point slides in the triangle's plane into it (enters at x = 0, t = 0.5);
    // the cubic is 0 for every t, no root is isolated, none tested.
    const PrimitiveMotion coplanar = point_over_unit_triangle({-0.5, 0.3, 0.0}, {0.5, 0.3, 0.0});
    CHECK_FALSE(cubic_ccd(PrimitivePair::point_triangle, coplanar).collides);
    // F = 0 on a curve of (t, u, v), so the search stops at max_boxes, conservatively.
    const CcdResult safe = inclusion_ccd(PrimitivePair::point_triangle, coplanar);
    CHECK(safe.collides);
    CHECK(safe.stopped_at_limit);
    CHECK(safe.time_of_impact <= 0.5);
    CHECK(safe.time_of_impact >= 0.5 - 1e-3);
}

TEST_CASE("inclusion CCD: the bound eps is needed: a point landing on an edge where F's computed value is "
          "round-off", "[ex15.3]")
{
    // The triangle (a, b, c) fixed in the plane z = 0 and the point falling straight down onto
    // q = (3/4) a + (1/4) b, on the edge ab, at t = 1: b = 4q − 3a exactly (checked below in long
    // double, whose 64 bits hold these sums exactly). F = 0 at the corner (t, u, v) = (1, 1/4, 0) of the
    // boxes, but its computed x or y there is the rounding of (3/4) a, not 0 — with ε = 0 every box
    // touching that corner would be discarded (found by a search over random a and q; this is one).
    const Eigen::Vector3d a(-0.57391473863983855, -0.71793962358741026, 0.0);
    const Eigen::Vector3d c(-0.92077770850113749, -0.28044855689828785, 0.0);
    const Eigen::Vector3d q(-0.28615496110971739, -0.70876633081530827, 0.0);
    Eigen::Vector3d b;
    for (int k = 0; k < 3; ++k) {
        const long double exact = 4.0L * q[k] - 3.0L * a[k];
        b[k] = double(exact);
        REQUIRE(static_cast<long double>(b[k]) == exact);
    }
    // F at (1, 1/4, 0) summed as inclusion_ccd sums it: q − (3/4) a − (1/4) b − 0 c.
    const Eigen::Vector3d corner = ((q + (-0.75 * a)) + (-0.25 * b)) + (-0.0 * c);
    CHECK(corner.cwiseAbs().maxCoeff() > 0.0);       // round-off, where the exact value is 0
    CHECK(corner.cwiseAbs().maxCoeff() < 1e-15);     // and within ε ≈ 2.7·10⁻¹⁵ M (M ≤ 1 here)
    Eigen::Matrix<double, 4, 3> start, end;
    start << (q + Eigen::Vector3d(0, 0, 1)).transpose(), a.transpose(), b.transpose(), c.transpose();
    end << q.transpose(), a.transpose(), b.transpose(), c.transpose();
    const CcdResult safe = inclusion_ccd(PrimitivePair::point_triangle, motion(start, end));
    CHECK(safe.collides);
    CHECK(safe.time_of_impact <= 1.0);
    CHECK(safe.time_of_impact >= 1.0 - delta - 1e-15);
}

TEST_CASE("inclusion CCD: a corner value that overflowed never excludes a box", "[ex15.3]")
{
    // A point at x = +1.5e308 over a triangle in the plane x = −1.5e308 (a unit triangle in y, z, the
    // point over its inside): F's x coordinate, p − (1 − u − v) a − u b − v c, is 3e308 > DBL_MAX at
    // every corner of every box: +∞, while ε_x stays finite. A value that overflowed says nothing: the
    // box must not be excluded on it (y and z vanish at u = 0.2, v = 0.3), so the search goes on and,
    // unable to exclude a box, answers conservatively: a contact.
    constexpr double huge = 1.5e308;
    Eigen::Matrix<double, 4, 3> start;
    start << huge, 0.2, 0.3, -huge, 0, 0, -huge, 1, 0, -huge, 0, 1;
    const CcdResult result = inclusion_ccd(PrimitivePair::point_triangle, motion(start, start), {1e-6, 200});
    INFO("inclusion_ccd: collides " << result.collides << ", time of impact " << result.time_of_impact << ", boxes "
                                    << result.work << " (a box excluded on an overflowed value answers no contact)");
    CHECK(result.collides);
    CHECK(result.time_of_impact <= 1.0);
}

TEST_CASE("inclusion CCD: stopped at its box limit it still answers conservatively", "[ex15.3]")
{
    const PrimitiveMotion m = point_over_unit_triangle({0.2, 0.3, 1.0}, {0.2, 0.3, -1.0});
    const CcdResult capped = inclusion_ccd(PrimitivePair::point_triangle, m, {1e-6, 10});
    CHECK(capped.stopped_at_limit);
    CHECK(capped.collides);
    CHECK(capped.work == 10);
    CHECK(capped.time_of_impact <= 0.5);
}

TEST_CASE("primitive CCD: non-finite coordinates and bad settings are refused")
{
    PrimitiveMotion m = point_over_unit_triangle({0.2, 0.3, 1.0}, {0.2, 0.3, -1.0});
    m.end(2, 0) = std::numeric_limits<double>::quiet_NaN();
    REQUIRE_THROWS_WITH(cubic_ccd(PrimitivePair::point_triangle, m), Catch::Contains("non-finite"));
    REQUIRE_THROWS_WITH(inclusion_ccd(PrimitivePair::point_triangle, m), Catch::Contains("non-finite"));
    m.end(2, 0) = std::numeric_limits<double>::infinity();
    REQUIRE_THROWS_AS(inclusion_ccd(PrimitivePair::edge_edge, m), Error);
    m.end(2, 0) = -1.0;
    for (double tolerance : {0.0, 1e-13, 2.0, std::numeric_limits<double>::quiet_NaN()})
        REQUIRE_THROWS_WITH(inclusion_ccd(PrimitivePair::point_triangle, m, {tolerance, 100}),
                            Catch::Contains("tolerance"));
    REQUIRE_THROWS_WITH(inclusion_ccd(PrimitivePair::point_triangle, m, {1e-6, 0}), Catch::Contains("max_boxes"));
}

TEST_CASE("CCD query files: read exactly, and malformed ones refused naming file and line")
{
    const std::filesystem::path folder = test::fresh_output_dir("ccd_queries") / "vertex-face";
    ensure_directory(folder);
    const auto write = [&](const std::string& name, const std::string& text) {
        std::ofstream(folder / name) << text;
        return folder / name;
    };
    std::string good;
    for (int row = 0; row < 8; ++row)
        good += str(row, ",1,-3,4,1,73786976294838206464,1\n");  // 2⁶⁶, as in the benchmark
    const std::vector<CcdQuery> queries = read_ccd_queries(write("good.csv", good));
    REQUIRE(queries.size() == 1);
    CHECK(queries[0].collides);
    CHECK(queries[0].first_line == 1);
    CHECK(queries[0].motion.start(0, 3) == 3.0);
    CHECK(queries[0].motion.start(1, 0) == -0.75);
    CHECK(queries[0].motion.end(2, 1) == std::ldexp(1.0, -66));
    CHECK(queries[0].motion.end(0, 3) == 7.0);
    CHECK(ccd_query_pair(folder / "good.csv") == PrimitivePair::point_triangle);
    CHECK(ccd_query_pair("edge-edge/data.csv") == PrimitivePair::edge_edge);
    REQUIRE_THROWS_WITH(ccd_query_pair("queries/data.csv"), Catch::Contains("vertex-face"));

    const std::string seven_rows = good.substr(0, good.rfind("7,1"));
    const struct {
        const char* name;
        std::string text, error;
    } bad[] = {
        {"six.csv", "0,1,0,1,0,1\n", "line 1: expected a row of 7 integers"},
        {"eight.csv", "0,1,0,1,0,1,0,0\n", "line 1: expected a row of 7 integers"},
        {"decimal.csv", "0,1,0.5,1,0,1,0\n", "line 1: expected a row of 7 integers"},
        {"nine_rows.csv", good + "0,1,0,1,0,1,1\n", "has 9 rows, not a multiple of 8"},
        {"seven_rows.csv", seven_rows, "has 7 rows, not a multiple of 8"},
        {"zero_denominator.csv", "0,1,1,0,0,1,0\n", "line 1: the denominator of coordinate y is 0"},
        {"truth.csv", "0,1,0,1,0,1,2\n", "line 1: the truth (7th integer) must be 0 or 1"},
        {"mixed_truth.csv", "0,1,0,1,0,1,1\n0,1,0,1,0,1,0\n", "line 2: the truth 0 differs"},
        {"huge.csv", str("0,1,0,1,", std::string(400, '9'), ",1,0\n"), "out of the range of a double"},
        {"empty.csv", "", "holds no row"},
    };
    for (const auto& b : bad) {
        const std::filesystem::path file = write(b.name, b.text);
        INFO(b.name);
        REQUIRE_THROWS_WITH(read_ccd_queries(file), Catch::Contains(file.string()) && Catch::Contains(b.error));
    }
    REQUIRE_THROWS_WITH(read_ccd_queries(folder / "missing.csv"), Catch::Contains("cannot read"));
}
