#pragma once
// Chapter 15: the check that IPC's promise holds — no edge of a surface passes through a triangle
// of a surface (of the same body, another body, or an obstacle). A barrier keeps every pair of
// primitives at a positive distance, so a run is intersection-free when, at every configuration it
// accepts, no surface edge meets a surface triangle it does not share a vertex with. This is the
// independent referee of the tests and of the debug check of the contact potential
// (ContactOptions::check_intersections): it uses no distance, no barrier and no time of impact.
// docs/15_body_contact.md#never-an-intersection
//
// Segment (p, q) meets triangle (a, b, c) when p and q are not strictly on one side of the
// triangle's plane and the line through p and q does not pass strictly outside one of the
// triangle's edges: with orient(a, b, c, d) = (b − a) × (c − a) · (d − a),
//   orient(a, b, c, p) and orient(a, b, c, q) not of one strict sign, and
//   orient(p, q, a, b), orient(p, q, b, c), orient(p, q, c, a) not of both strict signs.
// Each sign is certified: orient is computed in double with Shewchuk's a-priori error bound
// (|error| ≤ (7 + 56ε) ε × the permanent, ε = 2⁻⁵³); a value within its bound counts as zero. When
// these signs leave it open — a segment in the triangle's plane, as an edge and a triangle of one
// flat face of a mesh are — the shadows on the three coordinate planes are tried: a separating line
// there (the segment's line, or a triangle edge's with the segment strictly beyond it, by certified
// 2D orientations) proves them apart in space. So "apart" is only ever answered when it is proven;
// a touch or an uncertain sign counts as meeting (the check never misses an intersection; it may
// flag a configuration within round-off of touching, which a barrier with d̂ ≫ round-off never
// produces).

#include "15_body_contact/broad_phase.hpp"
#include "15_body_contact/ccd.hpp"
#include "14_contact/obstacles.hpp"

#include "common/mesh.hpp"

#include <Eigen/Core>

#include <memory>
#include <string>
#include <vector>

namespace fem::contact {

/// The sign of orient(a, b, c, d) = (b − a) × (c − a) · (d − a) (each 3): +1 or −1 when it is
/// certain (|computed| above the error bound of the header), 0 when it is within it (zero or not
/// decidable in double). Positive when d is on the side the normal (b − a) × (c − a) points to.
int certified_orientation(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                          const Eigen::Vector3d& d);

/// Whether segment (p, q) may meet triangle (a, b, c) (each 3): false only when they are proven
/// apart by certified orientations (header); touching, coplanar and undecidable count as meeting.
bool segment_meets_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// A pair of surface primitives that may meet on a straight motion (first_crossing_on_segment).
struct SegmentCrossing {
    PrimitivePair kind = PrimitivePair::point_triangle;
    int vertices[4] = {-1, -1, -1, -1};  ///< the point and the triangle's 3, or the two edges' (mesh numbering)
    double time = 0.0;                   ///< a lower bound of their first contact in [0, 1]
    bool proven = true;                  ///< false: the inclusion CCD stopped at its box limit (not proven free)
    bool found() const { return vertices[0] >= 0; }
};

/// The inclusion CCD's tolerance δ and box limit in the path check (first_crossing_on_segment):
/// tighter than the line search's 10⁻⁶ and 4000 boxes.
inline constexpr double path_check_tolerance = 1e-9;
inline constexpr long long path_check_boxes = 10'000'000;
/// The most pieces the path check's distance bound bisects a segment into before it hands the pair
/// to the CCDs (first_crossing_on_segment).
inline constexpr int path_check_pieces = 1 << 20;

/// The first pair of candidates (surface's point–triangle pairs, then its edge–edge pairs, in their
/// order) whose primitives may meet while the mesh moves linearly from start to end (#V×3 each). A
/// pair is cleared by a distance bound (no point moves farther than its primitive's farthest vertex,
/// so on a piece [a, b] of the motion the distance stays ≥ (d(a) + d(b) − M (b − a))/2, M the two
/// primitives' farthest moves summed; [0, 1] bisected into up to path_check_pieces pieces until each
/// is positive), else by two CCDs that are not the line search's (line_search_time_of_impact:
/// coplanar filter, inclusion at 10⁻⁶, additive advancement): inclusion_ccd at δ = path_check_tolerance
/// (never misses a contact; a pair it cannot clear within path_check_boxes counts, proven = false)
/// and cubic_ccd (the roots of the coplanarity cubic): either one's hit is a crossing. tested (if
/// given) is increased by the pairs tested. None: found() false. docs/15_body_contact.md#the-path-check
SegmentCrossing first_crossing_on_segment(const SurfacePrimitives& surface, const CandidatePairs& candidates,
                                          const MatrixX3d& start, const MatrixX3d& end, long long* tested = nullptr);

/// An edge through a triangle: rows of the edges and triangles given.
struct EdgeThroughTriangle {
    int edge = -1, triangle = -1;  ///< −1: none
    bool found() const { return edge >= 0; }
};

/// The first edge (row of edges, #E×2 vertex indices into x) that meets a triangle (row of
/// triangles, #F×3) it shares no vertex with, at positions x (#V×3): candidates from chapter 13's
/// box tree over the triangles' boxes (skin::box_hierarchy, boxes_meeting) queried with each edge's
/// box, then segment_meets_triangle. The first by edge, then by triangle row; none: found() false.
/// One mesh's edges and triangles, or several bodies' and obstacles' stacked into one x with their
/// indices offset. owner (#V entries, e.g. each vertex's body; empty: every pair): only an edge and a
/// triangle whose first vertices have different owners are tested. fem::Error for an index outside
/// x, a non-finite position or an owner list of another size.
EdgeThroughTriangle first_edge_through_triangle(const MatrixX3d& x, const Eigen::MatrixX2i& edges,
                                                const MatrixX3i& triangles, const std::vector<int>& owner = {});

/// "edge (i, j) meets triangle (a, b, c)" in vertex indices of x, for a message; empty when none.
std::string describe(const EdgeThroughTriangle& crossing, const Eigen::MatrixX2i& edges, const MatrixX3i& triangles);

/// The first crossing between a body's surface (surface's primitives at positions x, #V×3) and a
/// triangle mesh apart from it (an obstacle's triangles): a body edge through one of other's
/// triangles, or one of other's edges through a body triangle, as "body edge (i, j) meets triangle
/// (a, b, c)" or "edge (a, b) meets body triangle (i, j, k)" (other's vertices numbered from #V);
/// empty when none. fem::Error as first_edge_through_triangle.
std::string first_crossing(const MatrixX3d& x, const SurfacePrimitives& surface, const TriMesh& other);

/// The debug check of the contact potential (ContactOptions::check_intersections): a body's
/// surface against the drawn triangles of its obstacles with edges and corners (boxes, meshes:
/// Obstacle::local_features not empty; their triangles are their exact surface), and, with
/// self-contact, against itself. A smooth obstacle (half-space, sphere, capsule) has no triangles of
/// its own; its vertices-outside rule is the barrier's.
class IntersectionCheck {
public:
    /// mesh: the body's rest mesh (its surface_primitives); obstacles as the contact potential's;
    /// self_contact: whether the body's own edges and triangles are checked against each other.
    IntersectionCheck(const TetMesh& mesh, const std::vector<std::shared_ptr<const Obstacle>>& obstacles,
                      bool self_contact);
    /// fem::Error naming the primitives ("at t = …: body edge (i, j) meets obstacle 2's triangle …")
    /// when, at positions x (#V×3) and the obstacles at time [s], a body edge meets a triangle of an
    /// obstacle, an obstacle edge meets a body triangle, or (self_contact) a body edge a body
    /// triangle it shares no vertex with.
    void require_none(const MatrixX3d& x, double time) const;

private:
    SurfacePrimitives surface_;
    std::vector<std::pair<int, std::shared_ptr<const Obstacle>>> obstacles_;  // (index, obstacle) with triangles
    bool self_contact_;
};

}  // namespace fem::contact
