// Chapter 10: what the modes answer — the explicit stability limit (power iteration), Rayleigh
// damping's ratio, the θ-step of one modal oscillator and its exact motion, the modal solution of a
// loaded body, a beam's first frequency. The eigensolvers themselves are in mode_solvers.cpp.
// docs/10_linear_dynamics.md#modes
#include "10_linear_dynamics/modes.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace fem::dynamics {
namespace {

constexpr double pi = 3.14159265358979323846;

void require_oscillator(double omega, double xi, double time_step, double theta)
{
    if (!(std::isfinite(omega) && omega >= 0.0))
        throw Error(str("oscillator: omega must be finite and >= 0 [rad/s], got ", omega));
    if (!(std::isfinite(xi) && xi >= 0.0))
        throw Error(str("oscillator: the damping ratio xi must be finite and >= 0, got ", xi));
    require_positive(time_step, "time step dt [s]");
    if (!(theta >= 0.5 && theta <= 1.0))
        throw Error(str("theta must lie in [0.5, 1], got ", theta));
}

}  // namespace

PowerIteration power_iteration(const SparseMatrix& K, const Eigen::VectorXd& masses, double tolerance, int max_iterations)
{
    if (K.rows() != K.cols() || K.rows() != masses.size() || masses.size() == 0)
        throw Error(str("power iteration: K (", K.rows(), "x", K.cols(), ") and the masses (", masses.size(),
                        ") must be of one size n >= 1"));
    if (!(masses.array() > 0.0).all() || !masses.allFinite())
        throw Error("power iteration: every lumped mass must be finite and > 0");
    if (!(tolerance > 0.0 && tolerance < 1.0))
        throw Error(str("power iteration: the tolerance must lie in (0, 1), got ", tolerance));
    if (max_iterations < 1)
        throw Error(str("power iteration: max_iterations must be >= 1, got ", max_iterations));
    PowerIteration result;
    Eigen::VectorXd x(masses.size());
    for (Eigen::Index i = 0; i < x.size(); ++i)
        x[i] = 1.0 + ((i % 2 == 0) ? 0.5 : -0.5);
    // BEGIN EXERCISE 10.8 power_iteration #the-explicit-stability-limit
    // HINT: The power method on M⁻¹K (docs/10_linear_dynamics.md#the-explicit-stability-limit): its Rayleigh
    // HINT: quotient tends to λ_max = ω_max² from below. M is diagonal: `masses` holds its entries, so applying M⁻¹
    // HINT: is a division and no matrix is built. x arrives holding a start of mixed signs (keep it normalised,
    // HINT: or it overflows). Converged: λ changed by at most `tolerance` relative to λ since the previous iterate.
    // HINT: Fill result.omega (in rad/s, not λ), result.iterations, and result.converged (false when the cap is hit).
    x.normalize();
    double previous = 0.0;
    for (int k = 1; k <= max_iterations; ++k) {
        const Eigen::VectorXd y = K * x;
        const double lambda = x.dot(y) / x.dot(masses.cwiseProduct(x));
        result.omega = std::sqrt(std::max(lambda, 0.0));
        result.iterations = k;
        if (k > 1 && std::abs(lambda - previous) <= tolerance * std::abs(lambda)) {
            result.converged = true;
            break;
        }
        previous = lambda;
        x = y.cwiseQuotient(masses);
        x.normalize();
    }
    // END EXERCISE
    return result;
}

double damping_ratio(const Damping& damping, double omega)
{
    require_positive(omega, "angular frequency omega [rad/s]");
    return damping.alpha / (2.0 * omega) + damping.beta * omega / 2.0;
}

double explicit_stability_limit(double omega, double xi)
{
    require_positive(omega, "angular frequency omega [rad/s]");
    if (!(std::isfinite(xi) && xi >= 0.0))
        throw Error(str("the damping ratio xi must be finite and >= 0, got ", xi));
    // BEGIN EXERCISE 10.6 explicit_stability_limit #the-explicit-stability-limit
    // HINT: The largest Δt at which symplectic Euler keeps one damped mode (ω, ξ) bounded: both eigenvalues of its
    // HINT: 2×2 map in the unit disc. docs/10_linear_dynamics.md#the-explicit-stability-limit derives the condition
    // HINT: from the map's trace and determinant; solve it for Δt. Check: 2/ω at ξ = 0, smaller as ξ grows.
    return 2.0 / omega * (std::sqrt(1.0 + xi * xi) - xi);
    // END EXERCISE
}

Eigen::Matrix2d oscillator_step_matrix(double omega, double xi, double time_step, double theta)
{
    require_oscillator(omega, xi, time_step, theta);
    Eigen::Matrix2d G;
    // BEGIN EXERCISE 10.7 oscillator_step_matrix #one-mode-one-oscillator
    // HINT: G is one θ-step acting on (q, p = q̇) of the damped oscillator q̈ + 2ξωq̇ + ω²q = 0: solve the step's
    // HINT: two equations for p⁺ and q⁺ (docs/10_linear_dynamics.md#one-mode-one-oscillator derives p⁺; the step
    // HINT: is the θ-method of #the-implicit-step on one mode). Row 1 of G gives q⁺, row 2 p⁺; column 1 multiplies
    // HINT: q, column 2 p. Check: at θ = 1 and ξ = 0 its eigenvalues are 1/(1 ∓ iωΔt).
    const double h = time_step, w2 = omega * omega;
    const double a = 1.0 + 2.0 * theta * xi * omega * h + theta * theta * w2 * h * h;
    const double p_from_q = -h * w2 / a;
    const double p_from_p = (1.0 - theta * (1.0 - theta) * w2 * h * h - 2.0 * (1.0 - theta) * xi * omega * h) / a;
    G << 1.0 + theta * h * p_from_q, theta * h * p_from_p + (1.0 - theta) * h,
         p_from_q, p_from_p;
    // END EXERCISE
    return G;
}

Eigen::Matrix2d symplectic_oscillator_step_matrix(double omega, double xi, double time_step)
{
    require_oscillator(omega, xi, time_step, 1.0);
    const double h = time_step, w2 = omega * omega;
    const double p_from_q = -h * w2, p_from_p = 1.0 - 2.0 * xi * omega * h;
    Eigen::Matrix2d G;
    G << 1.0 + h * p_from_q, h * p_from_p,
         p_from_q, p_from_p;
    return G;
}

double modal_recurrence_deviation(Body& body, Integrator& integrator, const Eigen::VectorXd& start, Eigen::Index dof,
                                  const Eigen::Matrix2d& G, int steps)
{
    if (dof < 0 || dof >= body.dofs().full_size())
        throw Error(str("modal recurrence: dof ", dof, " is outside [0, ", body.dofs().full_size(), ")"));
    if (steps < 1)
        throw Error(str("modal recurrence: steps must be >= 1, got ", steps));
    Simulation simulation(body, integrator, initial_state(body, start));
    Eigen::Vector2d modal(1.0, 0.0);
    double deviation = 0.0, largest = 0.0;
    simulation.run(steps, [&](const State& state, const StepRecord&) {
        if (state.step > 0)
            modal = G * modal;
        deviation = std::max(deviation, std::abs(state.u[dof] - modal[0] * start[dof]));
        largest = std::max(largest, std::abs(state.u[dof]));
    });
    return deviation / largest;
}

Eigen::Vector2d exact_oscillator(double omega, double xi, double q0, double p0, double t)
{
    require_positive(omega, "angular frequency omega [rad/s]");
    if (!(std::isfinite(xi) && xi >= 0.0))
        throw Error(str("the damping ratio xi must be finite and >= 0, got ", xi));
    require_finite(t, "time t [s]");
    if (std::abs(xi - 1.0) < 1e-9) {  // critically damped
        const double decay = std::exp(-omega * t), c = p0 + omega * q0;
        return {decay * (q0 + c * t), decay * (p0 - omega * c * t)};
    }
    if (xi < 1.0) {
        const double wd = omega * std::sqrt(1.0 - xi * xi), decay = std::exp(-xi * omega * t);
        const double c = std::cos(wd * t), s = std::sin(wd * t);
        return {decay * (q0 * c + (p0 + xi * omega * q0) / wd * s),
                decay * (p0 * c - (omega * omega * q0 + xi * omega * p0) / wd * s)};
    }
    const double root = std::sqrt(xi * xi - 1.0);
    const double r1 = -omega * (xi - root), r2 = -omega * (xi + root);
    const double c1 = (p0 - r2 * q0) / (r1 - r2), c2 = q0 - c1;
    return {c1 * std::exp(r1 * t) + c2 * std::exp(r2 * t), r1 * c1 * std::exp(r1 * t) + r2 * c2 * std::exp(r2 * t)};
}

ModalSolution::ModalSolution(const SparseMatrix& K, const SparseMatrix& M, const Eigen::VectorXd& f,
                             const Damping& damping, const Eigen::VectorXd& u0, const Eigen::VectorXd& v0)
    : modes_(lowest_modes_dense(K, M, static_cast<int>(K.rows())))
{
    const Eigen::Index n = K.rows();
    if (f.size() != n || u0.size() != n || v0.size() != n)
        throw Error(str("modal solution: f, u0 and v0 need n = ", n, " entries, got ", f.size(), ", ", u0.size(),
                        " and ", v0.size()));
    if (!(damping.alpha >= 0.0 && damping.beta >= 0.0))
        throw Error("modal solution: the Rayleigh coefficients must be >= 0");
    if (!(modes_.omega[0] > 0.0))
        throw Error("modal solution: K is singular (a free body has rigid modes): pin vertices");
    const Eigen::MatrixXd& Phi = modes_.shapes;
    static_ = Phi * (Phi.transpose() * f).cwiseQuotient(modes_.omega.cwiseAbs2());
    q0_ = Phi.transpose() * (M * (u0 - static_));
    p0_ = Phi.transpose() * (M * v0);
    xi_.resize(n);
    for (Eigen::Index k = 0; k < n; ++k)
        xi_[k] = damping_ratio(damping, modes_.omega[k]);
}

Eigen::Vector2d ModalSolution::coordinate(Eigen::Index k, double t) const
{
    return exact_oscillator(modes_.omega[k], xi_[k], q0_[k], p0_[k], t);
}

Eigen::VectorXd ModalSolution::displacement(double t) const
{
    Eigen::VectorXd q(modes_.omega.size());
    for (Eigen::Index k = 0; k < q.size(); ++k)
        q[k] = coordinate(k, t)[0];
    return static_ + modes_.shapes * q;
}

double ModalSolution::displacement(double t, Eigen::Index dof) const
{
    if (dof < 0 || dof >= static_.size())
        throw Error(str("modal solution: dof ", dof, " is outside [0, ", static_.size(), ")"));
    double u = static_[dof];
    for (Eigen::Index k = 0; k < modes_.omega.size(); ++k)
        u += modes_.shapes(dof, k) * coordinate(k, t)[0];
    return u;
}


double euler_bernoulli_first_frequency(double youngs_modulus, double density, double length, double area,
                                       double second_moment)
{
    require_positive(youngs_modulus, "Young's modulus Y [Pa]");
    require_positive(density, "density rho [kg/m^3]");
    require_positive(length, "length L [m]");
    require_positive(area, "cross-section area A [m^2]");
    require_positive(second_moment, "second moment of area I [m^4]");
    const double beta1 = 1.8751040687119611;  // first root of cos(b) cosh(b) = -1
    return beta1 * beta1 / (2.0 * pi) * std::sqrt(youngs_modulus * second_moment / (density * area * std::pow(length, 4)));
}

}  // namespace fem::dynamics
