#include "12_hyperelastic_newton/newton.hpp"

#include "12_hyperelastic_newton/volume_filter.hpp"

#include "04_tet_jacobians/tet_jacobians.hpp"

#include "common/error.hpp"
#include "common/vtk_io.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fem::hyper {
namespace {

void require_sizes(const dynamics::Body& body, const dynamics::State& state, double time_step, const Eigen::VectorXd& v)
{
    require_positive(time_step, "time step dt [s]");
    const Eigen::Index n = body.dofs().full_size();
    if (v.size() != n || state.u.size() != n || state.v.size() != n)
        throw Error(str("backward Euler objective: v, u and q̇ must have 3n = ", n, " entries, got ", v.size(), ", ",
                        state.u.size(), " and ", state.v.size()));
}

/// fem::Error unless damping's α, β are the body's: a damped body's objective needs its StepDamping.
void require_damping(const dynamics::Body& body, const StepDamping& damping)
{
    const dynamics::Damping& scene = body.scene().damping;
    if (damping.coefficients().alpha != scene.alpha || damping.coefficients().beta != scene.beta)
        throw Error(str("backward Euler objective: the body's Rayleigh damping is alpha = ", scene.alpha, ", beta = ",
                        scene.beta, " but the step's StepDamping has alpha = ", damping.coefficients().alpha,
                        ", beta = ", damping.coefficients().beta, "; pass StepDamping(body, state.u)"));
}

}  // namespace

StepDamping::StepDamping(dynamics::Body& body, const Eigen::VectorXd& u_start)
    : coefficients_(body.scene().damping), M_(&body.mass_matrix())
{
    if (coefficients_.beta != 0.0)
        K_start_ = body.model().definite_stiffness(u_start);  // a copy: the model refills its own
}

Eigen::VectorXd StepDamping::times(const Eigen::VectorXd& v) const
{
    if (M_ != nullptr && v.size() != M_->rows())
        throw Error(str("StepDamping: v must have 3n = ", M_->rows(), " entries, got ", v.size()));
    Eigen::VectorXd Dv = Eigen::VectorXd::Zero(v.size());
    if (coefficients_.alpha != 0.0)
        Dv += coefficients_.alpha * (*M_ * v);
    if (coefficients_.beta != 0.0)
        Dv += coefficients_.beta * (K_start_ * v);
    return Dv;
}

double backward_euler_objective(dynamics::Body& body, const dynamics::State& state, double time_step,
                                const Eigen::VectorXd& v, double* magnitude, const StepDamping& damping)
{
    require_sizes(body, state, time_step, v);
    require_damping(body, damping);
    const double elastic = body.model().energy(state.u + time_step * v);
    if (!std::isfinite(elastic))
        return std::numeric_limits<double>::infinity();
    double kinetic = 0.0, work = 0.0, dissipation = 0.0;
    // BEGIN EXERCISE 12.7 objective #backward-euler-as-minimisation
    // HINT: The non-elastic terms of the backward Euler objective E(v), each in joules
    // HINT: (docs/12_hyperelastic_newton.md#backward-euler-as-minimisation): `kinetic`, about the previous velocity
    // HINT: state.v (the notes' qᵗ there is a slip: "Where the notes slip"); `work`, the load's work over the
    // HINT: step, stored positive (the return subtracts it); `dissipation`, half the damping's work with D held
    // HINT: fixed (damping.times(v) is D v). The elastic term is done above; M and f_ext are on `body`.
    const Eigen::VectorXd change = v - state.v;
    kinetic = 0.5 * change.dot(body.mass_matrix() * change);
    work = time_step * v.dot(body.external_forces());
    dissipation = 0.5 * time_step * v.dot(damping.times(v));
    // END EXERCISE
    if (magnitude != nullptr)
        *magnitude = std::abs(kinetic) + std::abs(elastic) + std::abs(work) + std::abs(dissipation);
    return kinetic + elastic - work + dissipation;
}

Eigen::VectorXd backward_euler_gradient(dynamics::Body& body, const dynamics::State& state, double time_step,
                                        const Eigen::VectorXd& v, const StepDamping& damping)
{
    require_sizes(body, state, time_step, v);
    require_damping(body, damping);
    Eigen::VectorXd forces, gradient;
    body.model().evaluate(state.u + time_step * v, forces);
    // BEGIN EXERCISE 12.8 gradient #backward-euler-as-minimisation
    // HINT: The gradient of exercise 12.7's E with respect to v, in `gradient`, 3n entries
    // HINT: (docs/12_hyperelastic_newton.md#backward-euler-as-minimisation). `forces` above holds f(qᵗ + Δt v),
    // HINT: the internal forces −∂U/∂q: mind their sign and the chain rule's Δt. damping.times(v) is D v. It
    // HINT: vanishes at chapter 10's backward Euler step.
    gradient = body.mass_matrix() * (v - state.v) - time_step * (forces + body.external_forces() - damping.times(v));
    // END EXERCISE
    return gradient;
}

double momentum_scale(dynamics::Body& body, const dynamics::State& state, double time_step)
{
    const dynamics::FreeDofs& dofs = body.dofs();
    // stableNorm: a plain norm squares the entries and overflows past 1e154 (a density of 1e160
    // gives momenta that large), and an infinite scale would pass any gradient as converged.
    double scale = dofs.gather(body.mass_matrix() * state.v).stableNorm() +
                   time_step * dofs.gather(body.external_forces()).stableNorm() +
                   time_step * dofs.gather(state.forces).stableNorm();
    if (body.pins_move()) {  // what the pins' step pushes into the free dofs
        Eigen::VectorXd forces;
        body.model().evaluate(state.u + time_step * body.pin_velocity(), forces);
        scale += dofs.gather(body.mass_matrix() * body.pin_velocity()).stableNorm() +
                 time_step * dofs.gather(forces).stableNorm();
    }
    return scale;
}

NewtonBackwardEuler::NewtonBackwardEuler(NewtonOptions options)
    : options_(std::move(options)),
      solver_(options_.make_solver ? options_.make_solver() : cg::make_solver(options_.solver))
{
    if (!solver_)
        throw Error("Newton: the solver factory of the options returned no solver");
    const auto require_in = [](double value, double low, double high, const char* what) {
        if (!(value > low && value < high))
            throw Error(str("Newton: ", what, " must lie in (", low, ", ", high, "), got ", value));
    };
    require_in(options_.relative_tolerance, 0.0, 1.0, "the relative tolerance");
    require_in(options_.armijo, 0.0, 0.5, "the Armijo constant c");
    require_in(options_.shrink, 0.0, 1.0, "the shrink factor");
    require_in(options_.smallest_step, 0.0, 1.0, "the smallest step");
    if (!(options_.forcing >= 0.0 && options_.forcing < 1.0))
        throw Error(str("Newton: the forcing term must lie in [0, 1), got ", options_.forcing));
    if (options_.max_iterations < 1)
        throw Error(str("Newton: the iteration cap must be >= 1, got ", options_.max_iterations));
    if (!(options_.kept_volume >= 0.0 && options_.kept_volume < 1.0))
        throw Error(str("Newton: the kept volume (the fraction of each tet's volume the line search keeps) must lie ",
                        "in [0, 1) (0: no volume filter), got ", options_.kept_volume));
    if (!(options_.step_tolerance >= 0.0 && std::isfinite(options_.step_tolerance)))
        throw Error(str("Newton: the step tolerance must be a finite number >= 0 (0: off), got ", options_.step_tolerance));
}

namespace {

/// d with H d = −gradient for the exact or definite Hessian at x; slope = gradientᵀd. False if the
/// exact Hessian is not positive definite or gives no descent direction. A definite Hessian is
/// positive definite by construction (M + Δt² K_PSD + Δt² ∇²P_PSD, M positive definite); where its
/// factorization fails all the same, its diagonal spans more than a double resolves (a contact pair
/// a hair apart, κ b''(d) beside a vertex's mass, which chapter 15's minimum separation prevents) or
/// a potential's "definite" Hessian is not: fem::Error in the course's words, naming problem.what,
/// the diagonal's span and what to change, never the factorization's.
bool newton_direction(const NewtonProblem& problem, cg::LinearSolver& solver, const Eigen::VectorXd& x, bool definite,
                      const Eigen::VectorXd& gradient, Eigen::VectorXd& direction, double& slope, int& iterations)
{
    const dynamics::SparseMatrix& hessian = problem.hessian(x, definite);
    try {
        solver.prepare(hessian);
        direction = solver.solve(-gradient);
    } catch (const Error&) {
        if (!definite)
            return false;  // the exact Hessian is indefinite: the caller falls back to the definite one
        const Eigen::VectorXd diagonal = hessian.diagonal().cwiseAbs();
        throw Error(str("Newton: ", problem.what, ": the system of the Newton step (mass, stiffness and the extra ",
                        "potential's Hessian, each made positive semi-definite) is not positive definite to working ",
                        "precision: its diagonal runs from ", diagonal.minCoeff(), " to ", diagonal.maxCoeff(),
                        diagonal.allFinite() ? "" : " and holds a value that is not finite",
                        "; a stiffness (Young's modulus, the contact's kappa or a pair of surfaces nearly touching) ",
                        "beyond what the masses resolve in one step: use a smaller dt"));
    }
    iterations += solver.stats().iterations;
    slope = gradient.dot(direction);
    return slope < 0.0;
}

/// fem::Error when tet, the one the volume filter cuts a step at, is squeezed at positions x (#V×3)
/// below collapsed_volume_ratio of its rest volume: its material cannot stop the step (what: the step).
void refuse_collapsing_tet(const dynamics::Body& body, const MatrixX3d& x, int tet, const std::string& what)
{
    const TetMesh& mesh = body.mesh();
    const double ratio = tet::signed_volume(tet::tet_vertices(mesh, x, tet)) /
                         tet::signed_volume(tet::tet_vertices(mesh, mesh.V, tet));
    if (ratio >= collapsed_volume_ratio)
        return;
    throw Error(str("Newton: ", what, ": tet ", tet, " is squeezed to ", ratio, " of its rest volume and the step ",
                    "pushes it further, toward inside out (the line search's volume filter keeps every tet's volume ",
                    "positive, so the step is refused here): the material ", body.model().name(),
                    (body.model().name() == "neo-hookean" ? "" : ", whose energy stays finite as a tet flattens,"),
                    " cannot stop this impact or squeeze; use the material neo-hookean, whose energy grows without ",
                    "bound as det F -> 0, or slower bodies"));
}

}  // namespace

NewtonResult newton_minimize(const NewtonProblem& problem, Eigen::VectorXd x0, const NewtonOptions& options,
                             cg::LinearSolver& solver)
{
    NewtonResult result;
    result.x = std::move(x0);
    Eigen::VectorXd& x = result.x;
    // Inexact Newton: an iterative solver's tolerance follows the gradient, never below its own.
    const double solver_tolerance = solver.options().relative_tolerance;
    const struct Restore {
        cg::LinearSolver& solver;
        double tolerance;
        ~Restore() { solver.set_relative_tolerance(tolerance); }
    } restore{solver, solver_tolerance};
    // E(x) and the size of its terms: the line search's accepted trial is the next start.
    double objective = std::numeric_limits<double>::quiet_NaN(), magnitude = 0.0;
    for (int iteration = 0;; ++iteration) {
        const Eigen::VectorXd gradient = problem.gradient(x);
        const double norm = gradient.stableNorm();  // no overflow for entries up to 1e308
        if (!std::isfinite(norm) || !std::isfinite(problem.scale))
            throw Error(str("Newton: ", problem.what, ": |gradient| = ", norm, " and its scale ", problem.scale,
                            " must be finite: the scene's values (density, Young's modulus, speeds, sizes) ",
                            "give forces beyond the range of a double"));
        const double relative = problem.scale > 0.0 ? norm / problem.scale : norm;
        result.gradient_history.push_back(relative);
        if (norm <= options.relative_tolerance * problem.scale || norm <= smallest_measurable_norm)
            return result;
        if (options.forcing > 0.0)
            solver.set_relative_tolerance(std::max(solver_tolerance, std::min(options.forcing, relative)));
        if (iteration == options.max_iterations)
            throw Error(str("Newton: ", problem.what, " did not converge in ", options.max_iterations,
                            " iterations: |gradient| / scale = ", norm / problem.scale, " (tolerance ",
                            options.relative_tolerance, "); use a smaller dt (a scene's time.step), or in code raise ",
                            "NewtonOptions::max_iterations"));
        Eigen::VectorXd direction;
        double slope = 0.0;
        bool found = newton_direction(problem, solver, x, options.hessian == HessianChoice::definite, gradient, direction,
                                      slope, result.solver_iterations);
        if (!found && options.hessian == HessianChoice::exact_then_definite) {
            ++result.definite_fallbacks;
            found = newton_direction(problem, solver, x, true, gradient, direction, slope, result.solver_iterations);
        }
        if (!found)
            throw Error(str("Newton: ", problem.what, ": the Hessian is not positive definite, so Newton has no ",
                            "descent direction (gradientᵀd = ", slope, "); use HessianChoice::exact_then_definite or definite"));
        // Backtracking: the largest α = shrinkᵏ with E(x + α d) ≤ E(x) + c α ∇ᵀd, from 1 or from
        // the largest step that keeps E finite (a potential's continuous collision check).
        double alpha = problem.largest_step ? std::min(1.0, problem.largest_step(x, direction)) : 1.0;
        if (!(alpha >= options.smallest_step))
            throw Error(str("Newton: ", problem.what, ": the largest safe step along d is α = ", alpha,
                            ", below the smallest step ", options.smallest_step));
        if (options.line_search) {
            if (std::isnan(objective))
                objective = problem.objective(x, &magnitude);
            const double start = objective;
            // E is a sum of terms that cancel; differences below its round-off carry no information.
            const double noise = objective_round_off * magnitude;
            // BEGIN EXERCISE 12.9 line_search #newton-with-line-search
            // HINT: Armijo backtracking (docs/12_hyperelastic_newton.md#newton-with-line-search): `alpha` arrives as
            // HINT: the first trial (1, or the largest safe step: do not reset it); shrink it by options.shrink until E
            // HINT: at x + α d lies below `start` by at least options.armijo's share of the decrease `slope` (∇Eᵀd < 0)
            // HINT: predicts for that α, `noise` (E's round-off) allowed. Where both E's change and that decrease are
            // HINT: below objective_resolution × `magnitude`, E's test is round-off either way: decide by the trapezoid
            // HINT: rule on the slopes ∇Eᵀd at x and at x + α d instead. The notes' target leaves α out: their fourth
            // HINT: slip. problem.objective(y, &magnitude) is +∞ where the material is undefined. Throw fem::Error once
            // HINT: α falls below options.smallest_step. The accepted trial's E and magnitude must end in `objective`
            // HINT: and `magnitude` (the next iteration starts there), its α in `alpha`.
            for (;;) {
                objective = problem.objective(x + alpha * direction, &magnitude);
                const double resolution = objective_resolution * magnitude;
                const bool below_resolution = std::abs(objective - start) <= resolution && -alpha * slope <= resolution;
                if (below_resolution ? 0.5 * (slope + problem.gradient(x + alpha * direction).dot(direction)) <=
                                           options.armijo * slope
                                     : objective <= start + options.armijo * alpha * slope + noise)
                    break;
                alpha *= options.shrink;
                if (alpha < options.smallest_step)
                    throw Error(str("Newton: ", problem.what, ": the line search found no decrease down to α = ",
                                    options.smallest_step));
            }
            // END EXERCISE
        }
        result.step_lengths.push_back(alpha);
        x += alpha * direction;
        ++result.iterations;
        if (direction.lpNorm<Eigen::Infinity>() <= options.step_tolerance)
            return result;  // the step's length test (never with step_tolerance = 0: d ≠ 0 here)
    }
}

Eigen::VectorXd solve_static(dynamics::Body& body, const NewtonOptions& options)
{
    const dynamics::FreeDofs& dofs = body.dofs();
    dynamics::ForceModel& model = body.model();
    const Eigen::VectorXd& load = body.external_forces();
    const auto full = [&](const Eigen::VectorXd& x) {
        Eigen::VectorXd u = Eigen::VectorXd::Zero(dofs.full_size());
        dofs.scatter(x, u);
        return u;
    };
    NewtonProblem problem;
    problem.objective = [&](const Eigen::VectorXd& x, double* magnitude) {
        const Eigen::VectorXd u = full(x);
        const double elastic = model.energy(u), work = load.dot(u);
        if (magnitude != nullptr)
            *magnitude = std::abs(elastic) + std::abs(work);
        return std::isfinite(elastic) ? elastic - work : std::numeric_limits<double>::infinity();
    };
    problem.gradient = [&](const Eigen::VectorXd& x) {
        Eigen::VectorXd forces;
        model.evaluate(full(x), forces);
        return Eigen::VectorXd(dofs.gather(-forces - load));
    };
    dynamics::SparseMatrix hessian;
    problem.hessian = [&](const Eigen::VectorXd& x, bool definite) -> const dynamics::SparseMatrix& {
        const Eigen::VectorXd u = full(x);
        hessian = dofs.reduce(definite ? model.definite_stiffness(u) : model.stiffness(u));
        return hessian;
    };
    problem.scale = dofs.gather(load).stableNorm();
    problem.what = "the static solve";
    const std::unique_ptr<cg::LinearSolver> solver = cg::make_solver(options.solver);
    return full(newton_minimize(problem, Eigen::VectorXd::Zero(dofs.size()), options, *solver).x);
}

dynamics::StepInfo NewtonBackwardEuler::step(dynamics::Body& body, double time_step, dynamics::State& state)
{
    require_positive(time_step, "time step dt [s]");
    const dynamics::FreeDofs& dofs = body.dofs();
    const StepDamping damping(body, state.u);  // D = αM + βK_t, K_t at the step's start
    if (potential_ != nullptr)
        potential_->begin_step(body, state, time_step);
    // The full velocity: the unknowns x on the free dofs, the pins' ṽ_p (zero on free dofs) on theirs.
    const auto full = [&](const Eigen::VectorXd& x) {
        Eigen::VectorXd v = body.pin_velocity();
        dofs.scatter(x, v);
        return v;
    };
    NewtonProblem problem;
    // A direction d on the free dofs as a full displacement change Δt d (zero on the pins).
    const auto full_change = [&](const Eigen::VectorXd& d) {
        Eigen::VectorXd change = Eigen::VectorXd::Zero(dofs.full_size());
        dofs.scatter(time_step * d, change);
        return change;
    };
    problem.objective = [&](const Eigen::VectorXd& x, double* magnitude) {
        const Eigen::VectorXd v = full(x);
        double objective = backward_euler_objective(body, state, time_step, v, magnitude, damping);
        if (potential_ != nullptr && std::isfinite(objective)) {
            const double extra = potential_->energy(state.u + time_step * v);
            objective = std::isfinite(extra) ? objective + extra : std::numeric_limits<double>::infinity();
            if (magnitude != nullptr)
                *magnitude += std::abs(extra);
        }
        return objective;
    };
    problem.gradient = [&](const Eigen::VectorXd& x) {
        const Eigen::VectorXd v = full(x);
        Eigen::VectorXd gradient = backward_euler_gradient(body, state, time_step, v, damping);
        if (potential_ != nullptr)
            gradient += time_step * potential_->gradient(state.u + time_step * v);
        return Eigen::VectorXd(dofs.gather(gradient));
    };
    // The first trial along d: the volume filter's largest step (every tet keeps kept_volume of its
    // volume; a part of the line search, so plain Newton goes without), cut by the potential's
    // continuous collision check.
    const bool volume_filter = options_.line_search && options_.kept_volume > 0.0;
    if (potential_ != nullptr || volume_filter)
        problem.largest_step = [&](const Eigen::VectorXd& x, const Eigen::VectorXd& d) {
            const Eigen::VectorXd u = state.u + time_step * full(x), du = full_change(d);
            double alpha = 1.0;
            if (volume_filter) {
                int tet = -1;
                const MatrixX3d x_tets = body.positions(u);
                alpha = largest_volume_keeping_step(body.mesh(), x_tets, io::vertex_rows(du), options_.kept_volume, &tet);
                if (tet >= 0)
                    refuse_collapsing_tet(body, x_tets, tet, problem.what);
            }
            return potential_ != nullptr ? std::min(alpha, potential_->largest_safe_step(u, du)) : alpha;
        };
    // H = M + Δt D + Δt² K = (1 + Δt α) M + Δt² (K + (β/Δt) K_t), in the fixed pattern.
    const dynamics::Damping& coefficients = damping.coefficients();
    // P's Hessian joins K (both are weighted by Δt²); its vertex blocks lie in K's pattern.
    dynamics::SparseMatrix damped_K;
    problem.hessian = [&](const Eigen::VectorXd& x, bool definite) -> const dynamics::SparseMatrix& {
        const Eigen::VectorXd u = state.u + time_step * full(x);
        const dynamics::SparseMatrix* K = definite ? &body.model().definite_stiffness(u) : &body.model().stiffness(u);
        if (coefficients.beta != 0.0 || potential_ != nullptr) {
            damped_K = *K;
            if (coefficients.beta != 0.0)
                damped_K += (coefficients.beta / time_step) * damping.start_stiffness();
            if (potential_ != nullptr)
                damped_K += definite ? potential_->hessian(u) : potential_->exact_hessian(u);
            K = &damped_K;
        }
        const dynamics::SparseMatrix& M = body.mass_matrix();
        if (!reduced_ || reduced_body_ != &body || !reduced_->fits(M, *K)) {
            reduced_.emplace(M, *K, dofs);
            reduced_body_ = &body;
        }
        return reduced_->assemble(M, *K, 1.0 + time_step * coefficients.alpha, time_step * time_step);
    };
    problem.scale = momentum_scale(body, state, time_step);
    problem.what = str("step ", state.step + 1, " (t = ", state.time + time_step, " s)");
    // The start: the last velocity, unless it already leaves the material's domain (a neo-Hookean
    // tet inverted by qᵗ + Δt q̇ᵗ); then v = 0, which keeps qᵗ, where E is finite.
    // With a potential the start is the potential's start velocity (v = 0 unless a moving obstacle
    // needs another), moved toward that last velocity as far as the potential allows (its continuous
    // collision check: no vertex passes through an obstacle on the way there); with the volume
    // filter, moved from there only as far as every tet keeps kept_volume of its volume.
    Eigen::VectorXd start = dofs.gather(state.v);
    Eigen::VectorXd fallback = Eigen::VectorXd::Zero(start.size());
    if (potential_ != nullptr) {
        fallback = dofs.gather(potential_->start_velocity(body, state, time_step));
        if (!std::isfinite(problem.objective(fallback, nullptr)))
            throw Error(str("Newton: ", problem.what, ": the energy is infinite at the start velocity the potential ",
                            "gives (the body's elastic energy there, or the potential's)"));
    }
    if (problem.largest_step)
        start = fallback + std::min(1.0, problem.largest_step(fallback, start - fallback)) * (start - fallback);
    if (!std::isfinite(problem.objective(start, nullptr)))
        start = fallback;
    // A potential's force is one more load of the step (an obstacle pushing a body at rest).
    if (potential_ != nullptr)
        problem.scale += time_step * dofs.gather(potential_->gradient(state.u + time_step * full(start))).stableNorm();
    last_ = newton_minimize(problem, std::move(start), options_, *solver_);
    dynamics::StepInfo info;
    info.newton_iterations = last_.iterations;
    info.solver_iterations = last_.solver_iterations;
    info.prepared = last_.iterations > 0;
    const Eigen::VectorXd v = full(last_.x);
    info.damping_work = time_step * v.dot(damping.times(v));
    // The pins' reactions r_p = ∇E_p(v⁺)/Δt do Δt ṽ_pᵀ r_p = ṽ_pᵀ ∇E(v⁺) (ṽ is zero on free dofs).
    if (body.pins_move())
        info.boundary_work = body.pin_velocity().dot(backward_euler_gradient(body, state, time_step, v, damping));
    dynamics::commit_step(body.model(), time_step, state.u + time_step * v, v, state);
    return info;
}

}  // namespace fem::hyper
