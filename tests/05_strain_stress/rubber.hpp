#pragma once
// The rubber of the tests of chapters 05 and 06, its Lamé parameters written out by hand (not by the
// chapter's lame_parameters, which the tests check).

#include "05_strain_stress/strain_stress.hpp"

namespace fem::test {

/// Rubber, Y = 1e5 Pa and ν = 0.45: λ = νY/((1+ν)(1−2ν)), μ = Y/(2(1+ν)), written out by hand.
inline const elastic::Lame rubber{0.45e5 / (1.45 * 0.1), 1e5 / 2.9};

}  // namespace fem::test
