// Study 5 of ch15_body_contact: the stack at rest against its closed form, swept over d̂ and Newton's
// tolerance — three one-cell cubes on the floor, one mesh with self-contact (as test_stack.cpp);
// the vertical barrier force between blocks k and k + 1 against the weight of the blocks above, the
// gaps the blocks rest at against d̂, the stack's height against the tightest solve's, and what each
// tolerance costs in Newton iterations and time per step.
// docs/15_body_contact.md#newtons-tolerance-against-the-closed-form
#include "15_body_contact/body_contact.hpp"
#include "15_body_contact/body_scenes.hpp"
#include "14_contact/obstacles.hpp"
#include "15_body_contact/self_barrier.hpp"
#include "studies.hpp"

#include "12_hyperelastic_newton/force_models.hpp"
#include "12_hyperelastic_newton/newton.hpp"

#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include "common/files.hpp"
#include "common/mesh.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>

namespace fem::contact::study {
namespace {

/// What one settled stack measured.
struct StackRun {
    double iterations_per_step = 0.0, seconds_per_step = 0.0;
    /// The worst over the interfaces and the last steps of |F_z − W_above| / W_above (F: the barrier
    /// force on the blocks above, W_above their weight) and of ‖F − W_above ẑ − Σ_above m Δv/Δt‖ / W_above.
    double force_error = 0.0, residual_error = 0.0;
    double gaps[3] = {0, 0, 0};  ///< at the end, the nearest distances: block 0 to the floor, 0 to 1, 1 to 2 [m]
    double height = 0.0;         ///< the top face's mean height at the end [m]
};

/// Three one-cell cubes of 30, 20 and 10 cm (27, 8 and 1 kg), each on the one below and off its
/// centre, the lowest on the floor z = 0 — test_stack.cpp's stack (block_stack), its gaps in units of d̂: at rest
/// 1.2 d̂ apart, started 0.5 d̂ apart. Stepped `steps` times at Δt = 1/100 s with Newton's relative
/// tolerance `tolerance`; the closed form checked after each of the last 50.
StackRun settled_stack(double reach, double tolerance, int steps)
{
    const double g = 9.81, time_step = 1.0 / 100.0;
    BlockStack blocks = block_stack(reach);
    dynamics::Scene scene;
    scene.mesh = std::move(blocks.mesh);
    scene.material = {1e6, 0.3, 1000.0};
    scene.gravity = Eigen::Vector3d(0, 0, -g);
    scene.time_step = time_step;
    BodyContactOptions options;
    options.self_contact = true;
    options.activation_distance = reach;
    dynamics::Body body(scene, hyper::make_force_model("stable-neo-hookean", scene.mesh, scene.material));
    ContactPotential contact =
        body_contact_potential(body, {std::make_shared<HalfSpace>(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ())},
                               options);
    hyper::NewtonOptions newton_options;
    newton_options.relative_tolerance = tolerance;
    newton_options.max_iterations = 200;
    hyper::NewtonBackwardEuler newton(newton_options);
    newton.set_potential(&contact);
    dynamics::State state = dynamics::initial_state(body, blocks.start, {});

    // The closed form of docs/14's "A stack at rest": summed over the blocks above interface k, the
    // internal forces cancel, so F_{k→k+1} − W_above ẑ = Σ_above m Δv/Δt − Σ_above r/Δt. Measured
    // after each of the last `window` steps, the worst kept.
    const Eigen::VectorXd& m = body.dof_masses();
    double weight[3] = {0, 0, 0};
    for (int v = 0; v < 24; ++v)
        weight[stack_block(v)] += m[3 * v] * g;
    StackRun run;
    const auto measure = [&](const dynamics::State& before) {
        Eigen::Vector3d momentum_change[3] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
        for (int v = 0; v < 24; ++v)
            momentum_change[stack_block(v)] += m[3 * v] * (state.v - before.v).segment<3>(3 * v);
        Eigen::Vector3d on_upper[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
        for (const SurfacePair& pair : contact.term<BodyContactTerm>()->barrier().pairs(state.u, true)) {
            const int lower = stack_block(*std::min_element(pair.vertices, pair.vertices + 4));
            const int upper = stack_block(*std::max_element(pair.vertices, pair.vertices + 4));
            if (lower == upper)
                continue;
            run.gaps[1 + lower] = std::min(run.gaps[1 + lower], pair.distance);
            for (int i = 0; i < 4; ++i)
                if (stack_block(pair.vertices[i]) == upper)
                    on_upper[lower] -= contact.stiffness() * pair.barrier.gradient.segment<3>(3 * i);
        }
        for (int k = 0; k < 2; ++k) {
            const double above = k == 0 ? weight[1] + weight[2] : weight[2];
            const Eigen::Vector3d dynamic =
                (k == 0 ? momentum_change[1] + momentum_change[2] : momentum_change[2]) / time_step;
            run.force_error = std::max(run.force_error, std::abs(on_upper[k].z() - above) / above);
            run.residual_error =
                std::max(run.residual_error, (on_upper[k] - above * Eigen::Vector3d::UnitZ() - dynamic).norm() / above);
        }
    };
    const int window = 50;
    double seconds = 0.0;
    int iterations = 0;
    for (int s = 0; s < steps; ++s) {
        const dynamics::State before = state;
        const Timer timer;
        iterations += contact_step(newton, contact, body, time_step, state).newton_iterations;
        seconds += timer.seconds();
        if (s >= steps - window) {
            std::fill(run.gaps, run.gaps + 3, reach);  // the last step's gaps
            measure(before);
        }
    }
    run.iterations_per_step = double(iterations) / steps;
    run.seconds_per_step = seconds / steps;
    const MatrixX3d x = body.positions(state.u);
    for (int v = 0; v < 8; ++v)
        run.gaps[0] = std::min(run.gaps[0], x(v, 2));
    for (int v = 16; v < 24; ++v)  // the top block's top face: its four highest vertices
        run.height += x(v, 2) > 0.55 ? x(v, 2) / 4.0 : 0.0;
    return run;
}

}  // namespace

void stack_study(const RunContext& run)
{
    std::cout << "\n== 5. A stack at rest against its closed form, swept over d-hat and Newton's tolerance: the\n"
                 "   force between blocks against the weight above, the gaps against d-hat, the cost\n\n";
    // --quick: one d̂ and two tolerances, settled over 1 s instead of 1.5 s.
    const std::vector<double> reaches = run.quick ? std::vector<double>{1e-3} : std::vector<double>{1e-3, 1e-4, 1e-5};
    const std::vector<double> tolerances =
        run.quick ? std::vector<double>{1e-9, 1e-3} : std::vector<double>{1e-9, 1e-6, 1e-4, 1e-3, 1e-2};
    const int steps = run.quick ? 100 : 150;
    Table table(str("A stack of three blocks at rest (test_stack.cpp), settled over ", steps,
                    " steps of 1/100 s: the closed form's errors (the worst of the last 50 steps) against d-hat and "
                    "Newton's tolerance"),
                {{"dhat [m]", Format::scientific, 0}, {"Newton tolerance", Format::scientific, 0},
                 {"Newton iterations per step", Format::fixed, 2}, {"time per step [ms]", Format::fixed, 2},
                 {"force error / weight", Format::scientific, 1},
                 // Newton's residual: where it sits below 10⁻⁷ (a tight tolerance), its digits are where the
                 // last iteration happened to stop, not a property of the stack.
                 {"with momentum change / weight [±1e-7]", Format::scientific, 1},
                 {"floor gap / dhat", Format::scientific, 1}, {"gap 0-1 / dhat", Format::scientific, 1},
                 {"gap 1-2 / dhat", Format::scientific, 1},
                 {"height - tightest / dhat", Format::scientific, 1}});
    for (double reach : reaches) {
        double tightest = 0.0;  // the top's height at the first (tightest) tolerance
        for (double tolerance : tolerances) {
            const StackRun stack = settled_stack(reach, tolerance, steps);
            if (tolerance == tolerances.front())
                tightest = stack.height;
            table.add_row({reach, tolerance, stack.iterations_per_step, 1e3 * stack.seconds_per_step, stack.force_error,
                           stack.residual_error, stack.gaps[0] / reach, stack.gaps[1] / reach, stack.gaps[2] / reach,
                           (stack.height - tightest) / reach});
        }
    }
    table.print(std::cout);
    table.write_csv(run.file("stack_tolerance_table.csv"));
}

}  // namespace fem::contact::study
