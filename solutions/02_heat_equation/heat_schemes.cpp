// Chapter 02: explicit Euler, implicit Euler and Crank–Nicolson for u_t = c Δu on the grid, and a
// run that watches the maximum principle. docs/02_heat_equation.md
#include "02_heat_equation/heat_schemes.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <cmath>

namespace fem::heat {
namespace {

void check_c_dt(double c, double dt)
{
    require_positive(c, "the diffusivity c");
    require_positive(dt, "the time step dt");
}

}  // namespace

std::string scheme_name(Scheme scheme)
{
    switch (scheme) {
    case Scheme::explicit_euler:
        return "explicit Euler";
    case Scheme::implicit_euler:
        return "implicit Euler";
    case Scheme::crank_nicolson:
        return "Crank-Nicolson";
    }
    throw Error("scheme_name: unknown scheme");
}

Scheme parse_scheme(std::string_view name)
{
    if (name == "explicit")
        return Scheme::explicit_euler;
    if (name == "implicit")
        return Scheme::implicit_euler;
    if (name == "crank-nicolson" || name == "cn")
        return Scheme::crank_nicolson;
    throw Error(str("unknown scheme '", name, "': use explicit, implicit or crank-nicolson (cn)"));
}

double theta(Scheme scheme)
{
    switch (scheme) {
    case Scheme::explicit_euler:
        return 0.0;
    case Scheme::implicit_euler:
        return 1.0;
    case Scheme::crank_nicolson:
        return 0.5;
    }
    throw Error("theta: unknown scheme");
}

double explicit_stability_limit(double h, double c)
{
    require_positive(h, "the grid spacing h");
    require_positive(c, "the diffusivity c");
    // BEGIN EXERCISE 02.5 explicit_stability_limit #stability
    // HINT: the checkerboard mode has λ ≈ −8/h²; explicit Euler multiplies it by 1 + cΔtλ per step.
    return h * h / (4.0 * c);
    // END EXERCISE
}

double amplification_factor(Scheme scheme, double c, double dt, double eigenvalue)
{
    check_c_dt(c, dt);
    require_finite(eigenvalue, "the eigenvalue");
    if (eigenvalue > 0.0)
        throw Error(str("the eigenvalues of the Laplacian are ≤ 0, got ", eigenvalue));
    const double z = c * dt * eigenvalue;
    const double t = theta(scheme);
    return (1.0 + (1.0 - t) * z) / (1.0 - t * z);
}

void explicit_euler_step(const Grid& grid, const BoundaryValues& g, double c, double dt,
                         const Eigen::VectorXd& u, Eigen::VectorXd& u_next)
{
    check_c_dt(c, dt);
    validate(grid);
    // BEGIN EXERCISE 02.4 explicit_euler_step #explicit-euler
    // HINT: u⁺ = u + cΔt Δ_h u is one stencil sweep: which α and β?
    const double h = grid.h();
    stencil_sweep(grid, g, u, 1.0, c * dt / (h * h), u_next);
    // END EXERCISE
}

void explicit_euler_step_assembled(const Eigen::SparseMatrix<double>& L, const Eigen::VectorXd& b,
                                   double c, double dt, const Eigen::VectorXd& u,
                                   Eigen::VectorXd& u_next)
{
    check_c_dt(c, dt);
    if (L.rows() != L.cols() || b.size() != L.rows() || u.size() != L.rows())
        throw Error(str("explicit_euler_step_assembled: L is ", L.rows(), "×", L.cols(), ", b has ",
                        b.size(), " and u ", u.size(), " entries; they must agree"));
    if (&u_next == &u)
        throw Error("explicit_euler_step_assembled: u_next must be a different vector than u");
    u_next.noalias() = L * u;
    u_next = u + (c * dt) * (u_next + b);
}

Eigen::SparseMatrix<double> implicit_system_matrix(const Grid& grid, double c, double dt,
                                                   double theta)
{
    validate(grid);
    check_c_dt(c, dt);
    if (!(theta >= 0.0 && theta <= 1.0))
        throw Error(str("θ must lie in [0, 1] (0 explicit, ½ Crank–Nicolson, 1 implicit), got ", theta));
    // BEGIN EXERCISE 02.6 implicit_system_matrix #implicit-euler
    // HINT: A = I − θ cΔt L with L = laplacian_matrix(grid); Eigen adds sparse matrices directly.
    Eigen::SparseMatrix<double> identity(grid.unknowns(), grid.unknowns());
    identity.setIdentity();
    return identity - (theta * c * dt) * laplacian_matrix(grid);
    // END EXERCISE
}

HeatStepper::HeatStepper(const Grid& grid, const BoundaryValues& g, double c, Scheme scheme, double dt)
    : grid_(grid), boundary_(g), c_(c), dt_(dt), scheme_(scheme), theta_(theta(scheme))
{
    validate(grid_, boundary_);
    check_c_dt(c_, dt_);
    if (theta_ == 0.0)
        return;
    lift_ = boundary_lift(grid_, boundary_);
    factor_.compute(implicit_system_matrix(grid_, c_, dt_, theta_));
    if (factor_.info() != Eigen::Success)
        throw Error(str("the ", scheme_name(scheme_), " matrix I − θ cΔt L (n = ", grid_.n,
                        ", c = ", c_, ", dt = ", dt_, ") could not be factored"));
}

void HeatStepper::step(const Eigen::VectorXd& u, Eigen::VectorXd& u_next)
{
    if (u.size() != grid_.unknowns())
        throw Error(str("HeatStepper::step: u has ", u.size(), " values, the grid has ",
                        grid_.unknowns(), " unknowns"));
    if (&u_next == &u)
        throw Error("HeatStepper::step: u_next must be a different vector than u");
    if (scheme_ == Scheme::explicit_euler)
        explicit_euler_step(grid_, boundary_, c_, dt_, u, u_next);
    else
        implicit_step(u, u_next);
}

void HeatStepper::implicit_step(const Eigen::VectorXd& u, Eigen::VectorXd& u_next)
{
    // BEGIN EXERCISE 02.7 implicit_step #the-theta-scheme
    // HINT: the right-hand side u + cΔt [(1 − θ) Δ_h u + θ b] is one stencil sweep plus a multiple
    // HINT: of lift_; then u_next = factor_.solve(right-hand side). Nothing is factored here.
    const double h = grid_.h();
    stencil_sweep(grid_, boundary_, u, 1.0, (1.0 - theta_) * c_ * dt_ / (h * h), rhs_);
    rhs_ += (theta_ * c_ * dt_) * lift_;
    u_next = factor_.solve(rhs_);
    // END EXERCISE
}

HeatRun simulate_heat(HeatStepper& stepper, const Eigen::VectorXd& u0, int steps,
                      const HeatObserver& observer, int every)
{
    const Grid& grid = stepper.grid();
    if (steps < 0)
        throw Error(str("the number of steps must be ≥ 0, got ", steps));
    if (every < 1)
        throw Error(str("observe every k steps needs k ≥ 1, got ", every));
    if (u0.size() != grid.unknowns())
        throw Error(str("the initial state has ", u0.size(), " values, the grid with n = ", grid.n,
                        " has ", grid.unknowns(), " unknowns"));
    for (Eigen::Index k = 0; k < u0.size(); ++k)
        if (!std::isfinite(u0[k]))
            throw Error(str("the initial state is not finite at unknown ", k, ": ", u0[k]));

    // The range of the maximum principle: the initial state and the boundary values the stencil
    // reads (the corners of the ring play no part).
    const BoundaryValues& g = stepper.boundary();
    double lo = u0.minCoeff(), hi = u0.maxCoeff();
    for (const Eigen::VectorXd* edge : {&g.bottom, &g.top, &g.left, &g.right}) {
        lo = std::min(lo, edge->segment(1, grid.n).minCoeff());
        hi = std::max(hi, edge->segment(1, grid.n).maxCoeff());
    }
    const double tolerance = 1e-9 * std::max(std::abs(lo), std::abs(hi));
    const bool stop_on_violation = stepper.scheme() != Scheme::crank_nicolson;

    HeatRun run;
    run.u = u0;
    run.lowest = u0.minCoeff();
    run.highest = u0.maxCoeff();
    if (observer)
        observer(0, 0.0, run.u);
    Eigen::VectorXd next(u0.size());
    for (int step = 1; step <= steps; ++step) {
        stepper.step(run.u, next);
        // With NaN propagation a NaN anywhere makes low and high NaN, and ±inf shows in them.
        const double low = next.minCoeff<Eigen::PropagateNaN>();
        const double high = next.maxCoeff<Eigen::PropagateNaN>();
        const bool finite = std::isfinite(low) && std::isfinite(high);
        const bool inside = finite && low >= lo - tolerance && high <= hi + tolerance;
        if (!inside && run.first_violation < 0)
            run.first_violation = step;
        if (!finite || (!inside && stop_on_violation)) {
            run.blew_up = true;
            run.blow_up_step = step;
            return run;
        }
        run.u.swap(next);
        run.steps_taken = step;
        run.time = step * stepper.dt();
        run.lowest = std::min(run.lowest, low);
        run.highest = std::max(run.highest, high);
        if (observer && (step % every == 0 || step == steps))
            observer(step, run.time, run.u);
    }
    return run;
}

}  // namespace fem::heat
