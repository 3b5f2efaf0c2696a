#pragma once
// Chapter 15: the broad phase of self-contact: which pairs of the surface primitives of a tet mesh
// (chapter 14's surface.hpp) — a surface vertex and a surface triangle, two
// surface edges — can come within reach during a motion, found three ways with one answer: every
// pair (brute force), chapter 13's AABB tree, and a spatial hash (a uniform grid).
// docs/15_body_contact.md#broad-phases
//
// A primitive's swept box over a motion from positions x⁰ to x¹ (#V×3 each) is the axis-aligned box
// of its vertices at both ends (it holds the primitive at every s ∈ [0, 1] of x⁰ + s (x¹ − x⁰): each
// vertex's path is a segment between its ends). A pair is a candidate when the swept box of its
// first primitive (the vertex; the edge of lower index), grown by r on every side, meets (touching
// counts) the swept box of its second, and the two share no vertex: a pair whose distance ever falls
// below r during the motion is a candidate (its boxes come within r of each other in every axis).

#include "14_contact/surface.hpp"

#include "common/mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <vector>

namespace fem::contact {

/// The candidate pairs of a motion, each list increasing (lexicographic).
struct CandidatePairs {
    std::vector<std::array<int, 2>> point_triangle;  ///< (mesh vertex, row of SurfacePrimitives::triangles)
    std::vector<std::array<int, 2>> edge_edge;       ///< (row a, row b) of SurfacePrimitives::edges, a < b
    bool operator==(const CandidatePairs&) const = default;
};

/// Every surface vertex against every surface triangle and every surface edge against every later
/// one, kept when the swept boxes (start → end, #V×3 each) meet with the first grown by r =
/// inflation ≥ 0 [m] and the pair shares no vertex (header). O(#V_s #F_s + #E_s²).
/// fem::Error for positions of the wrong size or not finite, or r < 0.
/// docs/15_body_contact.md#broad-phases
CandidatePairs brute_force_candidates(const SurfacePrimitives& surface, const MatrixX3d& start, const MatrixX3d& end,
                                      double inflation);

/// The same pairs from chapter 13's AABB tree (skin::box_hierarchy, 4 boxes a leaf) over the
/// triangles' swept boxes and one over the edges', each queried with every vertex's (edge's) grown
/// box (skin::boxes_meeting): O(n log n) to build, about O(log n + found) a query. fem::Error as
/// brute_force_candidates. docs/15_body_contact.md#broad-phases
CandidatePairs tree_candidates(const SurfacePrimitives& surface, const MatrixX3d& start, const MatrixX3d& end,
                               double inflation);

/// The same pairs from a spatial hash: a uniform grid of cell size h = max(the mean, a quarter of
/// the largest) longest side of the triangles' and edges' swept boxes (1 m when all are points),
/// cells (i, j, k) = ⌊(x − o)/h⌋ from the boxes' lowest corner o, each triangle (edge) listed in every
/// cell its box meets, each grown vertex (edge) box testing the items listed in the cells it meets.
/// Two boxes that meet share a cell (⌊·⌋ is monotone), so nothing is missed; the boxes are then
/// tested as above, so nothing is added. fem::Error as brute_force_candidates.
/// docs/15_body_contact.md#broad-phases
CandidatePairs hash_candidates(const SurfacePrimitives& surface, const MatrixX3d& start, const MatrixX3d& end,
                               double inflation);

}  // namespace fem::contact
