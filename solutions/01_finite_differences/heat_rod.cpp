// Chapter 01: the 1D heat equation with forward Euler in time and central differences in space.
// docs/01_finite_differences.md#the-1d-heat-equation
#include "01_finite_differences/heat_rod.hpp"

#include "common/error.hpp"

#include <cmath>
#include <numbers>

namespace fem::fd {

void validate(const HeatRod& rod)
{
    require_positive(rod.length, "rod length");
    require_positive(rod.c, "diffusivity c");
    if (rod.points < 3)
        throw Error(str("a rod needs at least 3 grid points (two ends and one interior point), got ",
                        rod.points));
    require_finite(rod.u_left, "the left end temperature");
    require_finite(rod.u_right, "the right end temperature");
}

double explicit_stability_limit(double h, double c)
{
    require_positive(h, "grid spacing h");
    require_positive(c, "diffusivity c");
    // BEGIN EXERCISE 01.7 explicit_stability_limit #stability
    // HINT: the highest grid mode is multiplied by 1 − 4 c Δt / h² per step; keep it ≥ −1.
    return h * h / (2.0 * c);
    // END EXERCISE
}

void ftcs_step(const HeatRod& rod, double dt, const Eigen::VectorXd& u, Eigen::VectorXd& u_next)
{
    if (u.size() != rod.points)
        throw Error(str("ftcs_step: u has ", u.size(), " entries, the rod has ", rod.points, " points"));
    u_next.resize(rod.points);
    const double h = rod.h();
    // BEGIN EXERCISE 01.6 ftcs_step #the-1d-heat-equation
    // HINT: r = c Δt / h²; interior points move by r times the second difference; ends stay fixed.
    const double r = rod.c * dt / (h * h);
    const Eigen::Index n = u.size();
    for (Eigen::Index i = 1; i + 1 < n; ++i)
        u_next[i] = u[i] + r * (u[i + 1] - 2.0 * u[i] + u[i - 1]);
    u_next[0] = rod.u_left;
    u_next[n - 1] = rod.u_right;
    // END EXERCISE
}

HeatRun simulate_heat_rod(const HeatRod& rod, const Eigen::VectorXd& u0, double dt, int steps,
                          const HeatObserver& observer, int every)
{
    validate(rod);
    require_positive(dt, "time step dt");
    if (steps < 0)
        throw Error(str("the number of steps must be ≥ 0, got ", steps));
    if (every < 1)
        throw Error(str("observe every k steps needs k ≥ 1, got ", every));
    if (u0.size() != rod.points)
        throw Error(str("the initial state has ", u0.size(), " values, the rod has ", rod.points,
                        " grid points"));
    if (!u0.allFinite())
        throw Error("the initial state has a non-finite value");

    // The maximum principle: the exact solution never leaves [−B, B].
    const double bound = std::max({u0.cwiseAbs().maxCoeff(), std::abs(rod.u_left), std::abs(rod.u_right)});
    const double allowed = bound * (1.0 + 1e-9) + 1e-300;

    HeatRun run;
    run.u = u0;
    if (observer)
        observer(0, 0.0, run.u);
    Eigen::VectorXd next(rod.points);
    for (int step = 1; step <= steps; ++step) {
        ftcs_step(rod, dt, run.u, next);
        const double largest = next.cwiseAbs().maxCoeff();  // NaN compares false below
        if (!(largest <= allowed)) {
            run.blew_up = true;
            run.blow_up_step = step;
            return run;
        }
        run.u.swap(next);
        run.steps_taken = step;
        run.time = step * dt;
        if (observer && (step % every == 0 || step == steps))
            observer(step, run.time, run.u);
    }
    return run;
}

Eigen::VectorXd sine_mode(const HeatRod& rod, int k)
{
    validate(rod);
    Eigen::VectorXd u(rod.points);
    for (int i = 0; i < rod.points; ++i)
        u[i] = std::sin(k * std::numbers::pi * rod.x(i) / rod.length);
    u[0] = 0.0;
    u[rod.points - 1] = 0.0;
    return u;
}

double sine_mode_solution(const HeatRod& rod, int k, double x, double t)
{
    const double wave_number = k * std::numbers::pi / rod.length;
    return std::exp(-rod.c * wave_number * wave_number * t) * std::sin(wave_number * x);
}

Eigen::VectorXd hot_middle(const HeatRod& rod)
{
    validate(rod);
    Eigen::VectorXd u(rod.points);
    for (int i = 0; i < rod.points; ++i) {
        const double x = rod.x(i);
        u[i] = (x > rod.length / 3.0 && x < 2.0 * rod.length / 3.0) ? 1.0 : 0.0;
    }
    u[0] = rod.u_left;
    u[rod.points - 1] = rod.u_right;
    return u;
}

}  // namespace fem::fd
