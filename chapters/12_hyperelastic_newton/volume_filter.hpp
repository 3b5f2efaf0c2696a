#pragma once
// Chapter 12: the line search's volume filter — the largest step along a Newton direction that keeps
// every tet's volume positive (a fraction of what it was), the guarantee of IPC's "inversion-free":
// no accepted iterate turns a tet inside out, whatever the material. Along the straight motion
// x + s·dx each tet's 6 × signed volume det(E + s dE) is a cubic in s (E, dE: its edge matrices),
// so the first s where it falls to a fraction of its start is a root of a cubic, found exactly.
// docs/12_hyperelastic_newton.md#the-volume-filter

#include "common/mesh.hpp"

#include <Eigen/Core>

namespace fem::hyper {

/// The coefficients c (4) of det(E + s dE) = c₀ + c₁ s + c₂ s² + c₃ s³ for 3×3 E and dE:
/// c₀ = det E, c₁ = cof(E) : dE, c₂ = cof(dE) : E, c₃ = det dE (cof: chapter 12's cofactor, the
/// derivative of det; A : B = Σ A_ij B_ij).
Eigen::Vector4d determinant_cubic(const Eigen::Matrix3d& E, const Eigen::Matrix3d& dE);

/// The smallest s in (0, 1] with c₀ + c₁ s + c₂ s² + c₃ s³ = floor, for a cubic with c₀ > floor
/// (c: 4 coefficients); returned as the largest double below that root found by bisection, so the
/// cubic is > floor on [0, s) and at s itself up to its round-off; 1 when the cubic stays above floor
/// on [0, 1]. Each monotone piece of [0, 1] (split at the roots of the derivative) is bisected in
/// turn, so no crossing is skipped. fem::Error unless c₀ > floor and every value is finite.
double first_crossing(const Eigen::Vector4d& c, double floor);

/// The volume filter: the largest α in (0, 1] such that every tet whose signed volume is positive at
/// x keeps, on the whole segment x + s·dx, s ∈ [0, α], a volume ≥ fraction × its volume at x
/// (x, dx: #V×3 positions and their change; mesh.T the tets, 0 ≤ fraction < 1). Tets of volume ≤ 0
/// at x are not held (nothing positive to keep). Each tet's first_crossing of its determinant_cubic,
/// in parallel over the tets (common/parallel.hpp), the smallest taken; binding_tet (when set)
/// receives the tet that sets it (the first of the smallest), −1 when α = 1. fem::Error for sizes
/// that do not match the mesh, a fraction outside [0, 1), or non-finite positions.
/// docs/12_hyperelastic_newton.md#the-volume-filter
double largest_volume_keeping_step(const TetMesh& mesh, const MatrixX3d& x, const MatrixX3d& dx, double fraction,
                                   int* binding_tet = nullptr);

/// A tet squeezed below this fraction of its rest volume by a step the volume filter has to cut is
/// collapsing: NewtonBackwardEuler refuses the step (fem::Error naming the tet and the material) instead
/// of letting the filter shrink it tenfold an iteration down to round-off, where its sign is lost.
/// A material whose energy is finite at det F = 0 (stable neo-Hookean) has nothing that stops an
/// impact from flattening a tet; neo-Hookean's −μ ln J + (λ/2) ln²J grows without bound there.
inline constexpr double collapsed_volume_ratio = 1e-6;

}  // namespace fem::hyper
