// Study 2 of ch14_contact: a cube on a slope — sliding (tan θ > μ) against a = g (sin θ − μ cos θ),
// sticking (tan θ < μ) with its creep per step against ε_v Δt, over d̂, κ, Δt and the Newton
// tolerance, with friction lagged once a step (IPC) or updated within it; charts of the two blocks'
// paths beside the closed forms and of the sweep's cost against the creep's error.
// docs/14_contact.md#the-slope
#include "studies.hpp"

#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/table.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>

namespace fem::contact::study {
namespace {

constexpr double degree = std::numbers::pi / 180.0;

/// A slope of the study: its angle θ [rad] and the floor's μ.
struct Slope {
    const char* name;
    double angle, friction;
};

/// The study's two slopes: one the cube slides down, one it sticks to.
constexpr Slope slopes[] = {{"slides", 30.0 * degree, 0.3}, {"sticks", 20.0 * degree, 0.5}};

/// The charts of the two blocks' paths (the first case of the sweep), the distance each moved down
/// the slope against time: the sliding one beside ½ a t², a = g (sin θ − μ cos θ); the sticking one
/// (in mm) beside the steady creep of sticking_creep, a line of slope ε_v (1 − √(1 − tan θ/μ)) through
/// where it is at half time (its first steps slip while the normal force builds, which no steady
/// creep describes). sliding, sticking: distances [m] against times [s], from t = 0.
void path_charts(const RunContext& run, const fig::Series& sliding, const fig::Series& sticking, const Slope& slides,
                 const Slope& sticks, double gravity, double friction_velocity)
{
    const double acceleration = slope_acceleration(gravity, slides.angle, slides.friction);
    fig::Series slide{"½ g (sin θ − μ cos θ) t²", {}, {}};
    for (int k = 0; k <= 40; ++k) {
        const double t = sliding.x.back() * k / 40.0;
        slide.x.push_back(t);
        slide.y.push_back(0.5 * acceleration * t * t);
    }
    slide.dashed = true;
    fig::LineChart chart;
    chart.title = "A 0.1 m rubber cube sliding down a slope";
    chart.x_label = "time [s]";
    chart.y_label = "distance moved down the slope [m]";
    chart.series = {sliding, slide};
    chart.legend = fig::Corner::top_left;
    fig::save_chart(chart, run.file("slope_slide"), run.figures);

    const std::size_t half = sticking.x.size() / 2;
    const double speed = friction_velocity * sticking_creep(sticks.angle, sticks.friction);
    fig::Series stick = sticking, creep{"steady creep ε_v (1 − √(1 − tan θ/μ)) t, through half time", {}, {}};
    for (double& y : stick.y)
        y *= 1e3;
    for (std::size_t k = 0; k < sticking.x.size(); ++k) {
        creep.x.push_back(sticking.x[k]);
        creep.y.push_back(stick.y[half] + 1e3 * speed * (sticking.x[k] - sticking.x[half]));
    }
    creep.dashed = true;
    chart.title = "A 0.1 m rubber cube that sticks to a slope: its creep";
    chart.y_label = "distance moved down the slope [mm]";
    chart.series = {stick, creep};
    chart.legend = fig::Corner::bottom_right;
    fig::save_chart(chart, run.file("slope_stick"), run.figures);
}

}  // namespace

double swept_steps(const Settings& settings)
{
    double steps = 0.0;
    for (const Case& c : sweep(settings))
        steps += settings.duration / c.time_step;
    return steps * (1.0 + std::size(slopes) * double(settings.friction_updates.size()));
}

void slope_study(const RunContext& run, const Settings& settings)
{
    std::cout << "\n== 2. The slope: a 0.1 m cube on a slope of 30 deg with mu = 0.3 (slides) and 20 deg with mu = 0.5 (sticks)\n\n";
    Table table("Slope: acceleration against g (sin theta - mu cos theta), creep per step against eps_v dt",
                {{"slope", Format::text}, {"dhat [m]", Format::scientific, 1}, {"kappa", Format::text},
                 {"dt", Format::text}, {"tolerance", Format::scientific, 0}, {"friction updates", Format::text},
                 {"solves per step", Format::fixed, 2},
                 {"acceleration [m/s^2]", Format::scientific, 4}, {"closed form [m/s^2]", Format::scientific, 4},
                 {"acceleration error / g", Format::scientific, 3}, {"largest move per step / (eps_v dt)", Format::scientific, 3},
                 {"Newton iterations per step", Format::fixed, 2}, {"time per step [ms]", Format::fixed, 3}});
    const std::vector<Case> cases = sweep(settings);
    // The charts: each block's path in the first case with the first friction update count; the
    // sticking block's cost against its creep's error for every d̂, κ and Δt at the last tolerance
    // (one series a d̂ and κ, one point a Δt).
    std::vector<fig::Series> paths;
    fig::LineChart costs;
    costs.title = "The sticking cube over d̂, κ and Δt: the cost against the error of its creep";
    std::string time_steps;
    for (double dt : settings.time_steps)
        time_steps += (time_steps.empty() ? "" : ", ") + time_step_label(dt);
    costs.x_label = str("Newton iterations per simulated second (along a line: Δt = ", time_steps, " s)");
    costs.y_label = "creep's error: |mean creep / closed form − 1|";
    costs.log_x = costs.log_y = true;
    double gravity = 0.0, friction_velocity = 0.0;
    for (const Slope& slope : slopes)
        for (const Case& c : cases)
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
            double seconds = 0.0, creep = 0.0, half_speed = 0.0, half_time = 0.0, half_place = 0.0;
            int iterations = 0, solves = 0;
            const bool charted = &c == &cases.front() && updates == settings.friction_updates.front();
            const auto along = [&](const dynamics::State& state) {  // the mean x of the vertices [m]
                return block.body->positions(state.u).col(0).mean();
            };
            const double start = along(block.state);
            double before = start;
            fig::Series path{str(slope.name, " (θ = ", std::lround(slope.angle / degree), "°, μ = ", slope.friction,
                                 ", Δt = ", time_step_label(c.time_step), " s)"), {}, {}};
            dynamics::Simulation simulation(*block.body, *block.stepper, block.state);
            simulation.run(steps, [&](const dynamics::State& state, const dynamics::StepRecord& record) {
                const double place = along(state);
                if (charted) {
                    path.x.push_back(state.time);
                    path.y.push_back(place - start);
                }
                if (state.step == 0)
                    return;  // the start: no step yet
                seconds += record.seconds;
                iterations += record.newton_iterations;
                solves += block.stepper->last_solves();
                if (state.step > half)
                    creep = std::max(creep, std::abs(place - before));
                if (state.step == half) {
                    half_speed = mean_velocity(*block.body, state.v).x();
                    half_time = state.time;
                    half_place = place;
                }
                before = place;
            });
            block.state = simulation.state();
            if (charted)
                paths.push_back(std::move(path));
            gravity = setup.gravity;
            friction_velocity = setup.contact.friction_velocity;
            if (slope.friction > std::tan(slope.angle) && updates == settings.friction_updates.front() &&
                c.tolerance == settings.tolerances.back()) {
                const std::string name = str("d̂ = ", 1e3 * c.activation_distance, " mm, κ ",
                                             c.stiffness == 0.0 ? std::string("adaptive") : str(c.stiffness, " N/m"));
                auto series = std::find_if(costs.series.begin(), costs.series.end(),
                                           [&](const fig::Series& s) { return s.name == name; });
                if (series == costs.series.end())
                    series = costs.series.insert(costs.series.end(), fig::Series{name, {}, {}});
                const double mean_creep = (along(block.state) - half_place) / (steps - half);
                const double expected =
                    sticking_creep(slope.angle, slope.friction) * setup.contact.friction_velocity * c.time_step;
                series->x.push_back(iterations / settings.duration);
                series->y.push_back(std::abs(mean_creep / expected - 1.0));
            }
            const double acceleration =
                (mean_velocity(*block.body, block.state.v).x() - half_speed) / (block.state.time - half_time);
            const double expected = slope_acceleration(setup.gravity, slope.angle, slope.friction);
            table.add_row({std::string(slope.name), c.activation_distance,
                           c.stiffness == 0.0 ? std::string("adaptive") : str(c.stiffness),
                           time_step_label(c.time_step), c.tolerance,
                           updates == 0 ? std::string("converged") : str(updates), double(solves) / steps,
                           acceleration,
                           expected, (acceleration - expected) / setup.gravity,
                           creep / (setup.contact.friction_velocity * c.time_step), double(iterations) / steps,
                           1e3 * seconds / steps});
        }
    table.print(std::cout);
    table.write_csv(run.file("slope_table.csv"));
    path_charts(run, paths[0], paths[1], slopes[0], slopes[1], gravity, friction_velocity);
    for (fig::Series& s : costs.series)
        s.markers_only = s.x.size() == 1;  // a single Δt: a point, not a line
    costs.legend = fig::Corner::top_right;
    fig::save_chart(costs, run.file("slope_cost"), run.figures);
}

}  // namespace fem::contact::study
