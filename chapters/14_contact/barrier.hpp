#pragma once
// Chapter 14: the log barrier of incremental potential contact (Li et al. 2020), a function of one
// distance (friction's mollifier: friction.hpp). docs/14_contact.md#the-barrier
//
//   b(d) = −(d − d̂)² ln(d/d̂)  for 0 < d < d̂,   0 for d ≥ d̂,   +∞ for d ≤ 0     (IPC: the barrier)
//
// (the barrier of unit stiffness: the contact energy is κ b(d), κ [N/m]). b is C² at d̂ (b, b', b''
// all vanish there), b → +∞ as d → 0⁺, so no minimiser ever has d ≤ 0.

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

}  // namespace fem::contact
