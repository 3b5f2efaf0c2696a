#include "12_hyperelastic_newton/newton.hpp"

#include "common/error.hpp"

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

}  // namespace

double backward_euler_objective(dynamics::Body& body, const dynamics::State& state, double time_step,
                                const Eigen::VectorXd& v, double* magnitude)
{
    require_sizes(body, state, time_step, v);
    const double elastic = body.model().energy(state.u + time_step * v);
    if (!std::isfinite(elastic))
        return std::numeric_limits<double>::infinity();
    const Eigen::VectorXd change = v - state.v;
    const double kinetic = 0.5 * change.dot(body.mass_matrix() * change);
    const double work = time_step * v.dot(body.external_forces());
    if (magnitude != nullptr)
        *magnitude = std::abs(kinetic) + std::abs(elastic) + std::abs(work);
    return kinetic + elastic - work;
}

Eigen::VectorXd backward_euler_gradient(dynamics::Body& body, const dynamics::State& state, double time_step,
                                        const Eigen::VectorXd& v)
{
    require_sizes(body, state, time_step, v);
    Eigen::VectorXd forces;
    body.model().evaluate(state.u + time_step * v, forces);
    return body.mass_matrix() * (v - state.v) - time_step * (forces + body.external_forces());
}

double momentum_scale(const dynamics::Body& body, const dynamics::State& state, double time_step)
{
    const dynamics::FreeDofs& dofs = body.dofs();
    return dofs.gather(body.mass_matrix() * state.v).norm() + time_step * dofs.gather(body.external_forces()).norm() +
           time_step * dofs.gather(state.forces).norm();
}

NewtonBackwardEuler::NewtonBackwardEuler(NewtonOptions options)
    : options_(std::move(options)), solver_(cg::make_solver(options_.solver))
{
    const auto require_in = [](double value, double low, double high, const char* what) {
        if (!(value > low && value < high))
            throw Error(str("Newton: ", what, " must lie in (", low, ", ", high, "), got ", value));
    };
    require_in(options_.relative_tolerance, 0.0, 1.0, "the relative tolerance");
    require_in(options_.armijo, 0.0, 0.5, "the Armijo constant c");
    require_in(options_.shrink, 0.0, 1.0, "the shrink factor");
    require_in(options_.smallest_step, 0.0, 1.0, "the smallest step");
    if (options_.max_iterations < 1)
        throw Error(str("Newton: the iteration cap must be >= 1, got ", options_.max_iterations));
}

bool NewtonBackwardEuler::newton_direction(dynamics::Body& body, const Eigen::VectorXd& u, double time_step,
                                           bool definite, const Eigen::VectorXd& gradient, Eigen::VectorXd& direction,
                                           double& slope, int& iterations)
{
    dynamics::ForceModel& model = body.model();
    const dynamics::SparseMatrix& K = definite ? model.definite_stiffness(u) : model.stiffness(u);
    try {
        solver_->prepare(body.dofs().reduce(dynamics::step_matrix(body.mass_matrix(), K, dynamics::Damping{}, time_step, 1.0)));
        direction = solver_->solve(-gradient);
    } catch (const Error&) {
        if (definite)
            throw;  // a definite Hessian that fails to factor is a real error, not a choice
        return false;
    }
    iterations += solver_->stats().iterations;
    slope = gradient.dot(direction);
    return slope < 0.0;
}

dynamics::StepInfo NewtonBackwardEuler::step(dynamics::Body& body, double time_step, dynamics::State& state)
{
    require_positive(time_step, "time step dt [s]");
    const dynamics::Damping& damping = body.scene().damping;
    if (damping.alpha != 0.0 || damping.beta != 0.0)
        throw Error("Newton backward Euler: Rayleigh damping is not part of its objective yet; set alpha = beta = 0");
    const dynamics::FreeDofs& dofs = body.dofs();
    const double scale = momentum_scale(body, state, time_step);
    gradient_history_.clear();
    step_lengths_.clear();
    definite_fallbacks_ = 0;
    dynamics::StepInfo info;
    // The start: the last velocity, unless it already leaves the material's domain (a neo-Hookean
    // tet inverted by qᵗ + Δt q̇ᵗ); then v = 0, which keeps qᵗ, where E is finite.
    Eigen::VectorXd v = state.v;
    if (!std::isfinite(backward_euler_objective(body, state, time_step, v)))
        v.setZero();
    for (int iteration = 0;; ++iteration) {
        const Eigen::VectorXd gradient = dofs.gather(backward_euler_gradient(body, state, time_step, v));
        const double norm = gradient.norm();
        gradient_history_.push_back(scale > 0.0 ? norm / scale : norm);
        if (norm <= options_.relative_tolerance * scale)
            break;
        if (iteration == options_.max_iterations)
            throw Error(str("Newton: step ", state.step + 1, " (t = ", state.time + time_step, " s) did not converge in ",
                            options_.max_iterations, " iterations: |grad E| / scale = ", norm / scale,
                            " (tolerance ", options_.relative_tolerance, "); use a smaller dt or raise the cap"));
        // The Newton direction: H d = −∇E on the free dofs, H = M + Δt² K(qᵗ + Δt v).
        const Eigen::VectorXd u = state.u + time_step * v;
        Eigen::VectorXd direction;
        double slope = 0.0;
        bool found = newton_direction(body, u, time_step, options_.hessian == HessianChoice::definite, gradient,
                                      direction, slope, info.solver_iterations);
        if (!found && options_.hessian == HessianChoice::exact_then_definite) {
            ++definite_fallbacks_;
            found = newton_direction(body, u, time_step, true, gradient, direction, slope, info.solver_iterations);
        }
        if (!found)
            throw Error(str("Newton: step ", state.step + 1, ": the Hessian is not positive definite, so Newton has no ",
                            "descent direction (∇Eᵀd = ", slope, "); use HessianChoice::exact_then_definite or definite"));
        Eigen::VectorXd d_full = Eigen::VectorXd::Zero(v.size());
        dofs.scatter(direction, d_full);
        // Backtracking: the largest α = shrinkᵏ with E(v + α d) ≤ E(v) + c α ∇Eᵀd.
        double alpha = 1.0;
        if (options_.line_search) {
            double magnitude = 0.0;
            const double start = backward_euler_objective(body, state, time_step, v, &magnitude);
            // E is a sum of terms that cancel; differences below its round-off carry no information.
            const double noise = objective_round_off * magnitude;
            while (!(backward_euler_objective(body, state, time_step, v + alpha * d_full) <=
                     start + options_.armijo * alpha * slope + noise)) {
                alpha *= options_.shrink;
                if (alpha < options_.smallest_step)
                    throw Error(str("Newton: step ", state.step + 1, ": the line search found no decrease down to α = ",
                                    options_.smallest_step));
            }
        }
        step_lengths_.push_back(alpha);
        v += alpha * d_full;
        ++info.newton_iterations;
    }
    info.prepared = info.newton_iterations > 0;
    dynamics::commit_step(body.model(), time_step, state.u + time_step * v, v, state);
    return info;
}

}  // namespace fem::hyper
