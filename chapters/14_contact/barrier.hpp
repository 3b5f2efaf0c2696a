#pragma once
// Chapter 14: the scalar pieces of incremental potential contact (Li et al. 2020): the log barrier
// of a distance and the smoothed Coulomb friction's mollifier. docs/14_contact.md#the-barrier
//
//   b(d) = −(d − d̂)² ln(d/d̂)  for 0 < d < d̂,   0 for d ≥ d̂,   +∞ for d ≤ 0     (IPC: the barrier)
//
// (the barrier of unit stiffness: the contact energy is κ b(d), κ [N/m]). b is C² at d̂ (b, b', b''
// all vanish there), b → +∞ as d → 0⁺, so no minimiser ever has d ≤ 0.
//
//   f₁(y) = 2y/ε − y²/ε²  for 0 ≤ y < ε,   1 for y ≥ ε        (IPC: the friction mollifier; ε = ε_v Δt)
//   f₀(y) = ∫ f₁ = y²/ε − y³/(3ε²) + ε/3  for y < ε,   y for y ≥ ε
//
// f₁ smooths the jump of Coulomb's law: a tangential displacement y over a step feels the friction
// force μλ f₁(y) (full Coulomb once y ≥ ε, a stiff spring below).

#include <Eigen/Core>

namespace fem::contact {

/// b(d), b'(d) and b''(d) of the unit-stiffness barrier at one distance.
struct BarrierValue {
    double value = 0.0, first = 0.0, second = 0.0;
};

/// b(d) = −(d − d̂)² ln(d/d̂) and its derivatives
///   b'(d)  = −2(d − d̂) ln(d/d̂) − (d − d̂)²/d,
///   b''(d) = −2 ln(d/d̂) − 4(d − d̂)/d + (d − d̂)²/d²,
/// all 0 for d ≥ d̂; value = +∞ (derivatives NaN) for d ≤ 0. fem::Error for d̂ ≤ 0.
/// docs/14_contact.md#the-barrier
BarrierValue barrier(double d, double activation_distance);

/// f₀(y), f₁(y) = f₀'(y) and f₁'(y) of the friction mollifier at one tangential displacement y ≥ 0.
struct MollifierValue {
    double f0 = 0.0, f1 = 0.0, f1_derivative = 0.0;
};

/// The mollifier of the header at y ≥ 0 with ε = ε_v Δt > 0 [m]: f₀, f₁ = 2y/ε − y²/ε²,
/// f₁' = 2/ε − 2y/ε² below ε; y, 1, 0 above. fem::Error for ε ≤ 0 or y < 0.
/// docs/14_contact.md#friction
MollifierValue friction_mollifier(double y, double epsilon);

}  // namespace fem::contact
