#pragma once
// Chapter 01: the 1D heat equation u_t = c u_xx on a rod, with the lecture's scheme: forward
// (explicit) Euler in time, the central second difference in space (FTCS), Dirichlet ends.
// docs/01_finite_differences.md#the-1d-heat-equation

#include <Eigen/Core>

#include <functional>

namespace fem::fd {

/// A rod [0, length] sampled at `points` equally spaced grid points x_i = i h, h = length/(points−1);
/// the two end points hold the fixed (Dirichlet) temperatures u_left and u_right.
struct HeatRod {
    double length = 1.0;
    double c = 1.0;  ///< diffusivity in u_t = c u_xx (m²/s)
    int points = 51;
    double u_left = 0.0;
    double u_right = 0.0;

    /// Grid spacing h = length / (points − 1).
    double h() const { return length / (points - 1); }
    /// Position of grid point i.
    double x(int i) const { return i * h(); }
};

/// fem::Error unless length > 0, c > 0, points ≥ 3 and the end values are finite.
void validate(const HeatRod& rod);

/// The largest stable FTCS time step, Δt = h² / (2c). fem::Error unless h > 0 and c > 0.
/// docs/01_finite_differences.md#stability
double explicit_stability_limit(double h, double c);

/// One FTCS step: u⁺_i = u_i + (c Δt / h²)(u_{i+1} − 2 u_i + u_{i−1}) at interior points,
/// u⁺_0 = u_left and u⁺_{n−1} = u_right. u and u_next have rod.points entries (resized if needed).
/// docs/01_finite_differences.md#the-1d-heat-equation
void ftcs_step(const HeatRod& rod, double dt, const Eigen::VectorXd& u, Eigen::VectorXd& u_next);

/// The outcome of a run. A run that leaves the range allowed by the maximum principle stops and
/// is flagged: u then holds the last state that was still inside the range, never NaN.
struct HeatRun {
    Eigen::VectorXd u;       ///< the final (or last valid) state
    double time = 0.0;       ///< the time of u
    int steps_taken = 0;     ///< steps that produced valid states
    bool blew_up = false;    ///< true when a step left the allowed range
    int blow_up_step = -1;   ///< the step (1-based) that left it, or −1
};

/// Called with (step, time, u) for the initial state and after every `every`-th step.
using HeatObserver = std::function<void(int step, double time, const Eigen::VectorXd& u)>;

/// Runs `steps` FTCS steps of size dt from u0 and watches for blow-up: the exact solution obeys
/// the maximum principle, max|u(t)| ≤ B = max(max|u0|, |u_left|, |u_right|), and so does FTCS
/// when Δt ≤ h²/(2c). A state with max|u| > B (1 + 1e-9) or a non-finite value stops the run
/// with blew_up = true. fem::Error for dt ≤ 0, steps < 0, or u0 of the wrong size.
/// docs/01_finite_differences.md#stability
HeatRun simulate_heat_rod(const HeatRod& rod, const Eigen::VectorXd& u0, double dt, int steps,
                          const HeatObserver& observer = {}, int every = 1);

/// The sine mode u_i = sin(kπ x_i / L), zero at both ends (rod.u_left, rod.u_right ignored).
Eigen::VectorXd sine_mode(const HeatRod& rod, int k);

/// The exact solution from a sine mode with zero ends: u(x,t) = exp(−c (kπ/L)² t) sin(kπx/L).
double sine_mode_solution(const HeatRod& rod, int k, double x, double t);

/// A hot middle third: u = 1 for L/3 < x < 2L/3, 0 elsewhere (the ends take the rod's values).
Eigen::VectorXd hot_middle(const HeatRod& rod);

}  // namespace fem::fd
