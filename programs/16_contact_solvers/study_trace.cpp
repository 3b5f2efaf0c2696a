// The trace of ch16_contact_solvers' runs: the problem it solves. Chapter 14's trace showed IPC's
// impact steps cut by the time of impact in their first iterations and then draining the momentum
// over many iterations that each move the surface; here every Newton iteration of every step in
// contact is counted by kind, for IPC and for the augmented Lagrangian's inner solves.
// docs/16_contact_solvers.md#the-problem-it-solves
#include "studies.hpp"

#include "12_hyperelastic_newton/newton.hpp"

#include <Eigen/Core>

#include <memory>
#include <vector>

namespace fem::contact::study {
namespace {

/// What one Newton iteration did to the surface.
struct Iteration {
    int step = 0;         ///< the step it belongs to (0-based)
    bool cut = false;     ///< its first trial was cut by the time of impact (safe step < 1)
    double moved = 0.0;   ///< α ‖Δu‖∞: the largest displacement of a vertex it made [m]
};

/// Forwards every call to the contact potential and records each iteration: Newton calls
/// largest_safe_step(u, Δu) once per iteration before its line search (after one call per solve
/// for its start, which is skipped), then gradient at the accepted iterate u + α Δu.
class RecordingPotential final : public hyper::StepPotential {
public:
    explicit RecordingPotential(hyper::StepPotential& inner) : inner_(inner) {}
    void begin_step(dynamics::Body& body, const dynamics::State& state, double time_step) override
    {
        inner_.begin_step(body, state, time_step);
        start_call_ = true;
        pending_ = false;
    }
    double energy(const Eigen::VectorXd& u) const override { return inner_.energy(u); }
    Eigen::VectorXd gradient(const Eigen::VectorXd& u) const override
    {
        if (pending_) {  // the iterate the line search accepted: α from its displacement along Δu
            const double alpha = (u - from_).dot(direction_) / direction_.squaredNorm();
            iterations.back().moved = alpha * direction_.lpNorm<Eigen::Infinity>();
            pending_ = false;
        }
        return inner_.gradient(u);
    }
    dynamics::SparseMatrix hessian(const Eigen::VectorXd& u) const override { return inner_.hessian(u); }
    dynamics::SparseMatrix exact_hessian(const Eigen::VectorXd& u) const override { return inner_.exact_hessian(u); }
    double largest_safe_step(const Eigen::VectorXd& u, const Eigen::VectorXd& du) const override
    {
        const double safe = inner_.largest_safe_step(u, du);
        if (start_call_) {
            start_call_ = false;
            return safe;
        }
        iterations.push_back({step, safe < 1.0, 0.0});
        if (du.squaredNorm() > 0.0) {
            from_ = u, direction_ = du;
            pending_ = true;
        }
        return safe;
    }
    Eigen::VectorXd start_velocity(const dynamics::Body& body, const dynamics::State& state,
                                   double time_step) const override
    {
        return inner_.start_velocity(body, state, time_step);
    }

    int step = 0;  ///< the step now running (the run's observer counts)
    mutable std::vector<Iteration> iterations;

private:
    hyper::StepPotential& inner_;
    mutable bool start_call_ = false, pending_ = false;
    mutable Eigen::VectorXd from_, direction_;
};

}  // namespace

TracedRun traced_run(const SolverScene& scene, ContactSolver solver, const AugmentedLagrangianOptions& options)
{
    std::unique_ptr<RecordingPotential> recorder;
    TracedRun traced;
    traced.run = run_scene(
        scene, solver, options, false,
        [&](const dynamics::Body&, const dynamics::State&, const dynamics::State&, const Eigen::VectorXd&) {
            ++recorder->step;
        },
        [&](hyper::StepPotential& contact) -> hyper::StepPotential& {
            recorder = std::make_unique<RecordingPotential>(contact);
            return *recorder;
        });
    if (recorder == nullptr)  // the free run: no potential to record
        return traced;
    const double gap = options.gap;
    for (const Iteration& iteration : recorder->iterations) {
        if (iteration.step >= static_cast<int>(traced.run.steps.size()) ||
            !traced.run.steps[static_cast<std::size_t>(iteration.step)].in_contact)
            continue;
        ++(iteration.cut ? traced.cut : iteration.moved > 1e-2 * gap ? traced.moving : traced.tail);
    }
    return traced;
}

}  // namespace fem::contact::study
