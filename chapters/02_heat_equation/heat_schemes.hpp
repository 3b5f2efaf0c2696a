#pragma once
// Chapter 02: time stepping u_t = c Δu on the grid: explicit (forward) Euler, implicit (backward)
// Euler and Crank–Nicolson, their stability, and a run that watches the maximum principle.
// docs/02_heat_equation.md
//
// With Δ_h u = L u + b (heat_grid.hpp) all three are the θ-scheme
//     (u⁺ − u) / Δt = c [θ (L u⁺ + b) + (1 − θ)(L u + b)],
// θ = 0 explicit Euler, θ = 1 implicit Euler, θ = ½ Crank–Nicolson, i.e.
//     (I − θ cΔt L) u⁺ = u + cΔt [(1 − θ) Δ_h u + θ b].

#include "02_heat_equation/heat_grid.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <functional>
#include <string>
#include <string_view>

namespace fem::heat {

enum class Scheme { explicit_euler, implicit_euler, crank_nicolson };

/// "explicit Euler", "implicit Euler" or "Crank-Nicolson".
std::string scheme_name(Scheme scheme);

/// The scheme named on a command line: "explicit", "implicit" or "crank-nicolson" (also "cn").
/// fem::Error naming the allowed names otherwise.
Scheme parse_scheme(std::string_view name);

/// The θ of the scheme: 0 explicit Euler, 1 implicit Euler, ½ Crank–Nicolson.
double theta(Scheme scheme);

/// The largest stable explicit Euler step in 2D, Δt = h² / (4c) (in 1D it is h²/(2c)).
/// fem::Error unless h > 0 and c > 0 are finite. docs/02_heat_equation.md#stability
double explicit_stability_limit(double h, double c);

/// The amplification factor of one step on an eigenvector of L with eigenvalue λ ≤ 0,
/// with z = cΔt λ: g = (1 + (1 − θ) z) / (1 − θ z), i.e. explicit Euler 1 + z, implicit Euler
/// 1/(1 − z), Crank–Nicolson (1 + z/2)/(1 − z/2). The scheme is stable for that mode iff |g| ≤ 1.
/// fem::Error unless c > 0, dt > 0 and λ ≤ 0 are finite. docs/02_heat_equation.md#stability
double amplification_factor(Scheme scheme, double c, double dt, double eigenvalue);

/// One explicit Euler step u⁺ = u + cΔt Δ_h u, matrix-free (stencil_sweep with α = 1,
/// β = cΔt/h²); boundary neighbours are read from g. u has n² entries; u_next (resized) must be
/// a different vector. fem::Error unless c > 0 and dt > 0, and as stencil_sweep.
/// docs/02_heat_equation.md#explicit-euler
void explicit_euler_step(const Grid& grid, const BoundaryValues& g, double c, double dt,
                         const Eigen::VectorXd& u, Eigen::VectorXd& u_next);

/// The same step with the assembled operator: u⁺ = u + cΔt (L u + b), L = laplacian_matrix,
/// b = boundary_lift. The sparse-matrix route beside the matrix-free one (same result to
/// round-off, more memory traffic). fem::Error for mismatched sizes or c, dt not > 0.
/// docs/02_heat_equation.md#speed-against-memory-bandwidth
void explicit_euler_step_assembled(const Eigen::SparseMatrix<double>& L, const Eigen::VectorXd& b,
                                   double c, double dt, const Eigen::VectorXd& u,
                                   Eigen::VectorXd& u_next);

/// The matrix of the θ-scheme's linear system, A = I − θ cΔt L (n²×n², sparse, symmetric positive
/// definite for θ ≥ 0). fem::Error for an invalid grid, c or dt not > 0, or θ outside [0, 1].
/// docs/02_heat_equation.md#implicit-euler
Eigen::SparseMatrix<double> implicit_system_matrix(const Grid& grid, double c, double dt,
                                                   double theta);

/// Steps one scheme with a fixed Δt. Explicit Euler needs nothing but the stencil; implicit Euler
/// and Crank–Nicolson assemble A = I − θ cΔt L and factor it once (Eigen's SimplicialLDLT), then
/// every step is one right-hand side and one pair of triangular solves.
/// docs/02_heat_equation.md#the-theta-scheme
class HeatStepper {
public:
    /// fem::Error for an invalid grid or g, c or dt not finite and > 0, or a failed factorization.
    /// Any Δt is accepted: explicit Euler beyond its limit is unstable, and simulate_heat says so.
    HeatStepper(const Grid& grid, const BoundaryValues& g, double c, Scheme scheme, double dt);

    /// One step from u (n² entries) to u_next (resized; must be a different vector).
    /// fem::Error for a wrong size of u or u_next aliasing u.
    void step(const Eigen::VectorXd& u, Eigen::VectorXd& u_next);

    const Grid& grid() const { return grid_; }
    const BoundaryValues& boundary() const { return boundary_; }
    double c() const { return c_; }
    double dt() const { return dt_; }
    Scheme scheme() const { return scheme_; }

private:
    /// θ-scheme step (θ > 0): solve A u⁺ = u + cΔt [(1 − θ) Δ_h u + θ b] with the stored factor.
    /// docs/02_heat_equation.md#the-theta-scheme
    void implicit_step(const Eigen::VectorXd& u, Eigen::VectorXd& u_next);

    Grid grid_;
    BoundaryValues boundary_;
    double c_;
    double dt_;
    Scheme scheme_;
    double theta_;
    Eigen::VectorXd lift_;  ///< b (θ-schemes only)
    Eigen::VectorXd rhs_;   ///< work vector of implicit_step
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> factor_;  ///< of A (θ-schemes only)
};

/// The outcome of a run, with what the maximum principle says about it. The exact solution stays
/// in [lo, hi], lo/hi = the smallest/largest of the initial state and the boundary values. So do
/// explicit Euler with Δt ≤ h²/(4c) and implicit Euler with any Δt; Crank–Nicolson only with
/// Δt ≤ h²/(2c), beyond that it may oscillate out of the range while staying bounded (|g| ≤ 1).
struct HeatRun {
    Eigen::VectorXd u;           ///< the final (or last valid) state, never NaN
    double time = 0.0;           ///< the time of u
    int steps_taken = 0;         ///< steps that produced valid states
    bool blew_up = false;        ///< the run stopped at an unstable (or non-finite) state
    int blow_up_step = -1;       ///< that step (1-based), or −1
    int first_violation = -1;    ///< the first step whose state left [lo, hi], or −1
    double lowest = 0.0;         ///< the smallest value of every valid state (initial included)
    double highest = 0.0;        ///< the largest value of every valid state
};

/// Called with (step, time, u) for the initial state and after every `every`-th and the last step.
using HeatObserver = std::function<void(int step, double time, const Eigen::VectorXd& u)>;

/// Runs `steps` steps from u0 and watches every state:
///  - a non-finite value stops any run (blew_up);
///  - a state outside [lo − tol, hi + tol] (tol = 10⁻⁹ max(|lo|, |hi|)) is recorded in
///    first_violation; for the two Euler schemes it also stops the run (blew_up), because they
///    obey the maximum principle whenever they are stable: leaving the range is the first sign of
///    the growing mode. Crank–Nicolson's oscillations are recorded and the run goes on.
/// A stopped run keeps the last valid state. fem::Error for steps < 0, every < 1, or u0 of the
/// wrong size or not finite. docs/02_heat_equation.md#the-maximum-principle
HeatRun simulate_heat(HeatStepper& stepper, const Eigen::VectorXd& u0, int steps,
                      const HeatObserver& observer = {}, int every = 1);

}  // namespace fem::heat
