#pragma once
// Chapter 15: what one pair of surface primitives (a point and a triangle, two edges) contributes to
// IPC's barrier (Li et al. 2020), and the time of impact that cuts a Newton step for it — the pieces
// that the obstacles' edges and corners (feature_barrier.hpp) and the bodies against each other and
// themselves (self_barrier.hpp) share. docs/15_body_contact.md#edges-and-corners-of-obstacles
//
// A pair k with squared distance d_k² (distances.hpp) and mollifier m_k (the edge–edge mollifier;
// 1 for a point–triangle pair) holds m_k b(d_k) (b of barrier.hpp, unit stiffness), a function of
// its 12 stacked coordinates.

#include "15_body_contact/ccd.hpp"
#include "15_body_contact/distances.hpp"

#include <Eigen/Sparse>

#include <vector>

namespace fem::contact {

/// m b(d) of a pair from its squared distance d² and mollifier m (each with gradient and Hessian in
/// the same 12 coordinates), with d̂ > 0 [m]; with_derivatives: its gradient and Hessian too, by the
/// chain rule: with ∇d = ∇d²/(2d), ∇²d = ∇²d²/(2d) − ∇d² ∇d²ᵀ/(4d³), g_b = b' ∇d,
/// H_b = b'' ∇d ∇dᵀ + b' ∇²d:  ∇(m b) = m g_b + b ∇m,  ∇²(m b) = m H_b + g_b ∇mᵀ + ∇m g_bᵀ + b ∇²m.
/// For d ≥ d̂ all 0; d² > 0 is the caller's to ensure. docs/15_body_contact.md#edges-and-corners-of-obstacles
PrimitiveFunction mollified_barrier(const PrimitiveFunction& squared_distance, const PrimitiveFunction& mollifier,
                                    double activation_distance, bool with_derivatives);

/// Appends a pair's 12×12 block (block (a, b): the 3×3 of its vertices a and b) to the triplets of
/// a 3n×3n matrix, at the rows and columns of its 4 mesh vertices.
void add_pair_block(const int (&vertices)[4], const Matrix12d& block, std::vector<Eigen::Triplet<double>>& triplets);

/// The mollifier of a point–triangle pair: m = 1, ∇m = 0, ∇²m = 0 (12).
PrimitiveFunction unit_mollifier();

/// The squared distance of the primitives of motion at s ∈ [0, 1] (their closest-feature type first:
/// point_triangle_type, edge_edge_type) [m²].
double squared_distance_at(PrimitivePair pair, const PrimitiveMotion& motion, double s);

/// Additive conservative advancement (after Li et al. 2021): with the common part of the four
/// vertices' moves taken out (it moves neither primitive relative to the other), M = the largest move
/// of the first primitive's vertices plus the largest of the second's bounds how fast their distance
/// d can fall, so from s the distance stays above g for a further (d(s) − g)/M. Advanced until that
/// step is below 10⁻³ of s (at most 100 times), with g = d(0)/10, it answers an s at which the
/// distance is still ≥ g > 0: a lower bound of the time of impact of motion, one that a step can be
/// cut to without coming nearer than a tenth of the distance it started at; +∞ when s passes 1 or
/// nothing moves relative to the other. With radius r > 0 the same for d − r, the gap of a rounded
/// pair (a sphere's centre or a capsule's segment against the body), 0 when d(0) ≤ r.
/// docs/15_body_contact.md#edges-and-corners-of-obstacles
double additive_time_of_impact(PrimitivePair pair, const PrimitiveMotion& motion, double radius = 0.0);

/// The same advancement to a given gap g > 0 [m] (additive_time_of_impact's is (d(0) − r)/10): an s at
/// which d − r is still ≥ g (0 when it starts below g), +∞ when s passes 1 or nothing moves; r = radius
/// as there.
double additive_time_to_gap(PrimitivePair pair, const PrimitiveMotion& motion, double gap, double radius = 0.0);

/// The most boxes inclusion_ccd evaluates for one pair inside a line search (line_search_time_of_impact).
inline constexpr long long line_search_ccd_boxes = 4000;

/// The most intervals coplanar_free_time looks at for one pair.
inline constexpr int coplanar_filter_intervals = 200;

/// A time before which the primitives of motion cannot touch because they are never coplanar: the
/// four points are coplanar where f(t) = det[A, B, C](t) = 0 (point–triangle: A = b − a, B = c − a,
/// C = p − a; edge–edge: A = a₁ − a₀, B = b₀ − a₀, C = b₁ − a₀), a cubic in t, and touching needs
/// f = 0. On an interval [t₀, t₁] each column moves linearly, so with τ = (t − t₀)/(t₁ − t₀)
/// f = Σ_k S_k (1 − τ)^{3−k} τ^k, S_k the sum of the dets with k columns taken at t₁ and 3 − k at t₀:
/// all S_k > 3ε (or all < −3ε), ε = 10⁻¹² max|x|³ bounding their round-off, and f has no root there.
/// Intervals bisected depth first from t = 0 down to width 2⁻¹²: returns the start of the first
/// that is not cleared (or of the one in hand after coplanar_filter_intervals), +∞ when all of
/// [0, 1] is. Cheap and tight where the inclusion test is not: a pair that starts a few 10⁻⁷ m apart
/// and slides or parts (a box's corner under a face) cannot be cleared by boxes in (t, u, v) short
/// of ~10⁵ of them, while its f keeps one sign. docs/15_body_contact.md#edges-and-corners-of-obstacles
double coplanar_free_time(PrimitivePair pair, const PrimitiveMotion& motion);

/// A lower bound of the first s ∈ [0, 1] at which the primitives of motion touch (+∞: never): +∞ when
/// coplanar_free_time clears [0, 1]; else, from its answer s₀ on (the motion restricted to [s₀, 1]),
/// the larger of inclusion_ccd's time of impact (tolerance 10⁻⁶, stopped at line_search_ccd_boxes, so
/// that edges moving in one plane cost no more than that) and additive_time_of_impact's, which keeps
/// the answer above s₀ while they are apart, where the first may answer 0 within its tolerance of a
/// contact or at its box limit. When they do not touch on [0, 1] but end nearer than the gap
/// g = min(d(0), separation)/10 (separation > 0 [m], e.g. d̂), additive_time_to_gap(g): so no step
/// ends a pair a hair apart, where the barrier's Hessian (~κ d̂²/d²) would swamp the masses in double
/// precision and make Newton's system singular (docs/15_body_contact.md#the-minimum-separation);
/// separation = 0: no such gap. fem::Error as inclusion_ccd.
/// docs/15_body_contact.md#edges-and-corners-of-obstacles
double line_search_time_of_impact(PrimitivePair pair, const PrimitiveMotion& motion, double separation = 0.0);

}  // namespace fem::contact
