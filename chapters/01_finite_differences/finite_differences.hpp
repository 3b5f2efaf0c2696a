#pragma once
// Chapter 01: finite differences. docs/01_finite_differences.md
//
// Derivatives of a smooth function f sampled with step h: one-sided stencils (error O(h)), the
// central stencil (O(h²)), the central second difference (O(h²)), and the observed order of
// convergence from a sequence of steps. Round-off caps how small h may usefully be.

#include <functional>
#include <vector>

namespace fem::fd {

using ScalarFunction = std::function<double(double)>;

/// Forward difference (f(x+h) − f(x)) / h ≈ f'(x), truncation error −(h/2) f''(ξ).
/// fem::Error unless h is finite and > 0. docs/01_finite_differences.md#one-sided-differences
double forward_difference(const ScalarFunction& f, double x, double h);

/// Backward difference (f(x) − f(x−h)) / h ≈ f'(x), truncation error +(h/2) f''(ξ).
/// fem::Error unless h is finite and > 0. docs/01_finite_differences.md#one-sided-differences
double backward_difference(const ScalarFunction& f, double x, double h);

/// Central difference (f(x+h) − f(x−h)) / (2h) ≈ f'(x), truncation error −(h²/6) f'''(ξ).
/// fem::Error unless h is finite and > 0. docs/01_finite_differences.md#central-differences
double central_difference(const ScalarFunction& f, double x, double h);

/// Central second difference (f(x+h) − 2 f(x) + f(x−h)) / h² ≈ f''(x), truncation error
/// −(h²/12) f''''(ξ). fem::Error unless h is finite and > 0.
/// docs/01_finite_differences.md#the-second-derivative
double central_second_difference(const ScalarFunction& f, double x, double h);

/// Observed orders between successive runs: p_i = log(e_i / e_{i+1}) / log(h_i / h_{i+1}),
/// i = 0 … n−2, for an error that behaves like C hᵖ. h and error have n ≥ 2 entries; fem::Error
/// if their sizes differ, n < 2, or any h or error is ≤ 0 or not finite.
/// docs/01_finite_differences.md#observed-order-of-convergence
std::vector<double> observed_orders(const std::vector<double>& h, const std::vector<double>& error);

/// The least-squares slope of log(error) against log(h): one order for a whole sequence.
/// Same requirements as observed_orders. docs/01_finite_differences.md#observed-order-of-convergence
double fitted_order(const std::vector<double>& h, const std::vector<double>& error);

}  // namespace fem::fd
