// Study 2 of ch14_contact: a cube on a slope — sliding (tan θ > μ) against a = g (sin θ − μ cos θ),
// sticking (tan θ < μ) with its creep per step against ε_v Δt, over d̂, κ, Δt and the Newton
// tolerance, with friction lagged once a step (IPC) or updated within it. docs/14_contact.md#the-slope
#include "14_contact/studies.hpp"

#include "common/error.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>

namespace fem::contact::study {

void slope_study(const RunContext& run, const Settings& settings)
{
    constexpr double degree = std::numbers::pi / 180.0;
    struct Slope {
        const char* name;
        double angle, friction;
    };
    const Slope slopes[] = {{"slides", 30.0 * degree, 0.3}, {"sticks", 20.0 * degree, 0.5}};
    std::cout << "\n== 2. The slope: a 0.1 m cube on a slope of 30 deg with mu = 0.3 (slides) and 20 deg with mu = 0.5 (sticks)\n\n";
    Table table("Slope: acceleration against g (sin theta - mu cos theta), creep per step against eps_v dt",
                {{"slope", Format::text}, {"dhat [m]", Format::scientific, 1}, {"kappa", Format::text},
                 {"dt", Format::text}, {"tolerance", Format::scientific, 0}, {"friction updates", Format::text},
                 {"solves per step", Format::fixed, 2},
                 {"acceleration [m/s^2]", Format::scientific, 4}, {"closed form [m/s^2]", Format::scientific, 4},
                 {"acceleration error / g", Format::scientific, 3}, {"largest move per step / (eps_v dt)", Format::scientific, 3},
                 {"Newton iterations per step", Format::fixed, 2}, {"time per step [ms]", Format::fixed, 3}});
    for (const Slope& slope : slopes)
        for (const Case& c : sweep(settings))
        for (int updates : settings.friction_updates) {
            BlockSettings setup = block_settings(c);
            setup.friction_updates = updates;
            setup.height = 0.5 * c.activation_distance;
            setup.slope = slope.angle;
            setup.friction = slope.friction;
            BlockScene block = block_scene(setup);
            const int steps = dynamics::step_count(settings.duration, c.time_step);
            // The acceleration over the run's second half (the first settles the normal force).
            const int half = steps / 2;
            double seconds = 0.0, creep = 0.0, half_speed = 0.0, half_time = 0.0;
            int iterations = 0, solves = 0;
            for (int step = 0; step < steps; ++step) {
                const double before = block.body->positions(block.state.u).col(0).mean();
                Timer timer;
                int solved = 0;
                const dynamics::StepInfo info = block.step(&solved);
                seconds += timer.seconds();
                iterations += info.newton_iterations;
                solves += solved;
                if (step + 1 > half)
                    creep = std::max(creep, std::abs(block.body->positions(block.state.u).col(0).mean() - before));
                if (step + 1 == half) {
                    half_speed = mean_velocity(*block.body, block.state.v).x();
                    half_time = block.state.time;
                }
            }
            const double acceleration =
                (mean_velocity(*block.body, block.state.v).x() - half_speed) / (block.state.time - half_time);
            const double expected = slope_acceleration(setup.gravity, slope.angle, slope.friction);
            table.add_row({std::string(slope.name), c.activation_distance,
                           c.stiffness == 0.0 ? std::string("adaptive") : str(c.stiffness),
                           str("1/", static_cast<int>(std::lround(1.0 / c.time_step))), c.tolerance,
                           updates == 0 ? std::string("converged") : str(updates), double(solves) / steps,
                           acceleration,
                           expected, (acceleration - expected) / setup.gravity,
                           creep / (setup.contact.friction_velocity * c.time_step), double(iterations) / steps,
                           1e3 * seconds / steps});
        }
    table.print(std::cout);
    table.write_csv(run.file("slope_table.csv"));
}

}  // namespace fem::contact::study
