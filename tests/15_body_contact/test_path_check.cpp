// Chapter 15: the path check (BodyContactOptions::check_path, issue 48 item 3). A step's real path
// is Newton's piecewise-linear path — uᵗ, every accepted iterate, uᵗ⁺¹ — not the chord between two
// frames; the path check proves each of its segments free of crossings with a second CCD
// (first_crossing_on_segment: the inclusion CCD at 10⁻⁹ and the cubic), and stops a run at the first
// it cannot, naming step, segment, bodies and primitives. docs/15_body_contact.md#the-path-check
#include "15_body_contact/body_contact.hpp"
#include "15_body_contact/intersections.hpp"

#include "contact_bodies.hpp"
#include "../14_contact/contact_delegate.hpp"

#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <string>

using namespace fem;
using namespace fem::contact;

namespace {

/// The line search's collision check made blind (a planted bug): each call still reaches the
/// contact terms (the path check records the iterate), but the answer is "nothing in the way".
class BlindCollisionCheck final : public test::ContactDelegate {
public:
    using ContactDelegate::ContactDelegate;
    double largest_safe_step(const Eigen::VectorXd& u, const Eigen::VectorXd& du) const override
    {
        (void)contact_.largest_safe_step(u, du);
        return 1.0;
    }
};

/// The block over the free plate (test::block_over_plate, 2 mm plate, the block flat) fired down at
/// speed, steps of time_step, path check on (bodies named "plate" and "block"); with blind, the
/// line search's collision check is blind. Runs `steps` steps: the first error, empty when none;
/// segments: the segments the check proved.
std::string fire_at_plate(double speed, double time_step, int steps, bool blind, long long& segments)
{
    const test::ThrownBodies thrown = test::block_over_plate(speed);
    dynamics::Scene scene = test::free_scene(thrown.mesh);
    scene.time_step = time_step;
    BodyContactOptions options;
    options.self_contact = true;
    options.check_path = true;
    options.vertex_body.assign(std::size_t(thrown.mesh.V.rows()), 0);
    std::fill(options.vertex_body.end() - 8, options.vertex_body.end(), 1);  // the block's 8 vertices come last
    options.body_names = {"plate", "block"};
    test::ContactRun run(scene, options, {}, {}, thrown.velocity, 1e-6);
    BlindCollisionCheck blinded(*run.contact);
    if (blind)
        run.newton->set_potential(&blinded);
    const auto* path = run.contact->term<PathCheckTerm>();
    REQUIRE(path != nullptr);
    std::string error;
    for (int k = 0; k < steps && error.empty(); ++k) {
        try {
            run.step();
            path->end_step(run.state.u);
        } catch (const Error& e) {
            error = e.what();
        }
    }
    segments = path->segments();
    return error;
}

}  // namespace

TEST_CASE("first_crossing_on_segment: a vertex through a triangle, an edge through an edge, and the same "
          "motions passing beside", "[ex15.5]")
{
    // Two triangles of one surface: one flat at z = 0, the other's vertex 3 above it.
    SurfacePrimitives surface;
    surface.triangles.resize(2, 3);
    surface.triangles << 0, 1, 2, 3, 4, 5;
    surface.edges.resize(6, 2);
    surface.edges << 0, 1, 0, 2, 1, 2, 3, 4, 3, 5, 4, 5;
    surface.vertices = {0, 1, 2, 3, 4, 5};
    MatrixX3d start(6, 3);
    start << 0, 0, 0, 1, 0, 0, 0, 1, 0,  //
        0.2, 0.2, 0.1, 3, 3, 0.1, 3, 4, 0.1;
    CandidatePairs candidates;
    candidates.point_triangle = {{3, 0}};
    // Vertex 3 straight down from (0.2, 0.2, 0.1) to z = −0.1: through the triangle's inside at s = ½.
    MatrixX3d end = start;
    end(3, 2) = -0.1;
    long long tested = 0;
    const SegmentCrossing crossing = first_crossing_on_segment(surface, candidates, start, end, &tested);
    REQUIRE(crossing.found());
    CHECK(crossing.kind == PrimitivePair::point_triangle);
    CHECK(crossing.vertices[0] == 3);
    CHECK(crossing.time <= 0.5);
    CHECK(crossing.time > 0.49);
    CHECK(tested == 1);
    // The same fall at (0.8, 0.8): through z = 0 outside the triangle (x + y = 1 is its long edge).
    MatrixX3d beside_start = start, beside_end = end;
    beside_start(3, 0) = beside_start(3, 1) = beside_end(3, 0) = beside_end(3, 1) = 0.8;
    CHECK_FALSE(first_crossing_on_segment(surface, candidates, beside_start, beside_end).found());
    // Edge (3, 4) across x = 0.5, swept down through edge (0, 1) (the x axis from 0 to 1); then the
    // same sweep at x = 1.5, past that edge's end.
    candidates = {};
    candidates.edge_edge = {{0, 3}};
    MatrixX3d edge_start = start;
    edge_start.row(3) << 0.5, -0.5, 0.1;
    edge_start.row(4) << 0.5, 0.5, 0.1;
    MatrixX3d edge_end = edge_start;
    edge_end(3, 2) = edge_end(4, 2) = -0.1;
    CHECK(first_crossing_on_segment(surface, candidates, edge_start, edge_end).found());
    edge_start(3, 0) = edge_start(4, 0) = edge_end(3, 0) = edge_end(4, 0) = 1.5;
    CHECK_FALSE(first_crossing_on_segment(surface, candidates, edge_start, edge_end).found());
}

TEST_CASE("the path check proves every segment of a block hitting a thin plate face-on at 20 m/s, and catches "
          "a planted blind collision check, naming step, segment, bodies and primitives", "[ex15.5][slow]")
{
    // 20 m/s at Δt = 1/400 s: 5 cm a step against a plate 2 mm thick and a gap of 2 mm.
    long long segments = 0;
    const std::string clean = fire_at_plate(20.0, 1.0 / 400.0, 4, false, segments);
    CAPTURE(clean, segments);
    CHECK(clean.empty());
    CHECK(segments > 4);  // more than one segment a step: the iterates' path, not the chord
    // Blind, at Δt = 1/100 s (20 cm a step): the first step's start is the free flight, wholly
    // through the plate and past it, where no barrier acts.
    const std::string caught = fire_at_plate(20.0, 1.0 / 100.0, 1, true, segments);
    CAPTURE(caught);
    CHECK_THAT(caught, Catch::Contains("path check: step 1 (t = 0.01 s), segment ") &&
                           Catch::Contains("body 'block'") && Catch::Contains("body 'plate'") &&
                           Catch::Contains("each body's own vertex numbers"));
}
