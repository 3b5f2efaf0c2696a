// Study 1 of ch14_contact: a cube dropped from h onto the floor — the speed at contact against
// √(2gh), the rebound, the smallest distance, and the cost, over d̂, κ, Δt and the Newton tolerance;
// a .pvd of the drop; charts of its height and contact force against time beside the closed forms.
// docs/14_contact.md#the-drop
#include "studies.hpp"

#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/table.hpp"
#include "common/vtk_io.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>

namespace fem::contact::study {
namespace {

/// The total force the barrier puts on the body along z (the floor's normal) at u [N].
double contact_force(const ContactPotential& contact, const Eigen::VectorXd& u)
{
    const Eigen::VectorXd forces = contact.barrier_forces(u);
    return Eigen::Map<const Eigen::VectorXd, 0, Eigen::InnerStride<3>>(forces.data() + 2, forces.size() / 3).sum();
}

/// The charts of the drops over Δt (the first d̂, κ and tolerance of the sweep): the lowest point's
/// height beside the free fall h − g t²/2 until it reaches the floor, and the contact force beside
/// the weight m g once the block rests.
void drop_charts(const RunContext& run, const std::vector<fig::Series>& heights, const std::vector<fig::Series>& forces,
                 double height, double gravity, double mass, double duration)
{
    const double landing = std::sqrt(2.0 * height / gravity);
    fig::Series fall{"free fall h − g t²/2", {}, {}};
    fig::Series weight{"weight m g", {}, {}};
    fall.dashed = weight.dashed = true;
    for (int k = 0; k <= 40; ++k) {
        const double t = landing * k / 40.0;
        fall.x.push_back(t);
        fall.y.push_back(height - 0.5 * gravity * t * t);
        weight.x.push_back(landing + (duration - landing) * k / 40.0);
        weight.y.push_back(mass * gravity);
    }
    fig::LineChart chart;
    chart.title = str("A 0.1 m rubber cube dropped ", height, " m onto the floor: its lowest point");
    chart.x_label = "time [s]";
    chart.y_label = "height of the lowest vertex [m]";
    chart.series = heights;
    chart.series.push_back(fall);
    fig::save_chart(chart, run.file("drop_height"), run.figures);
    chart.title = "The same drops: the barrier's force on the cube";
    chart.y_label = "total contact force [N]";
    chart.series = forces;
    chart.series.push_back(weight);
    fig::save_chart(chart, run.file("drop_force"), run.figures);
}

}  // namespace

std::vector<Case> sweep(const Settings& settings)
{
    std::vector<Case> cases;
    for (double dhat : settings.activation_distances)
        for (double kappa : settings.stiffnesses)
            for (double dt : settings.time_steps)
                for (double tolerance : settings.tolerances)
                    cases.push_back({dhat, kappa, dt, tolerance});
    return cases;
}

BlockSettings block_settings(const Case& c)
{
    BlockSettings block;
    block.time_step = c.time_step;
    block.contact.activation_distance = c.activation_distance;
    block.contact.stiffness = c.stiffness;
    block.newton.relative_tolerance = c.tolerance;
    return block;
}

double block_weight()
{
    const BlockSettings block;
    return block.material.density * std::pow(block.edge, 3) * block.gravity;
}

void drop_study(const RunContext& run, const Settings& settings)
{
    std::cout << "\n== 1. The drop: a 0.1 m cube falls " << settings.drop_height << " m onto the floor\n\n";
    Table table(str("Drop from h = ", settings.drop_height, " m: speed at contact against sqrt(2gh), rebound, cost"),
                {{"dhat [m]", Format::scientific, 1}, {"kappa", Format::text}, {"dt", Format::text},
                 {"tolerance", Format::scientific, 0}, {"final kappa [N/m]", Format::scientific, 3},
                 {"speed error / sqrt(2gh)", Format::scientific, 3}, {"rebound / h", Format::scientific, 3},
                 {"smallest distance / dhat", Format::scientific, 3}, {"Newton iterations per step", Format::fixed, 2},
                 {"time per step [ms]", Format::fixed, 3}});
    bool first = true;
    std::vector<fig::Series> heights, forces;  // the charts' drops: the first d̂, κ and tolerance, every Δt
    double gravity = 0.0, mass = 0.0;
    for (const Case& c : sweep(settings)) {
        BlockSettings block_setup = block_settings(c);
        block_setup.height = settings.drop_height;
        BlockScene block = block_scene(block_setup);
        const int steps = dynamics::step_count(settings.duration, c.time_step);
        std::optional<io::PvdSeries> series;
        if (first)
            series.emplace(run.file("drop.pvd"));
        const bool charted = c.activation_distance == settings.activation_distances.front() &&
                             c.stiffness == settings.stiffnesses.front() && c.tolerance == settings.tolerances.front();
        fig::Series height{str("Δt = ", time_step_label(c.time_step), " s"), {}, {}};
        fig::Series force{height.name, {}, {}};
        gravity = block_setup.gravity;
        mass = block.body->dof_masses().sum() / 3.0;
        double fastest = 0.0, smallest = std::numeric_limits<double>::infinity(), rebound = 0.0, seconds = 0.0;
        int iterations = 0;
        bool bounced = false;
        dynamics::Simulation simulation(*block.body, *block.stepper, block.state);
        simulation.run(steps, [&](const dynamics::State& state, const dynamics::StepRecord& record) {
            if (series && state.step % 2 == 0)
                series->add(state.time, dynamics::body_frame(*block.body, state));
            if (charted) {
                height.x.push_back(state.time);
                height.y.push_back(lowest_height(*block.body, state.u));
                force.x.push_back(state.time);
                force.y.push_back(contact_force(*block.contact, state.u));
            }
            if (state.step == 0)
                return;  // the start: no step yet
            seconds += record.seconds;
            iterations += record.newton_iterations;
            const double falling = -mean_velocity(*block.body, state.v).z();
            fastest = std::max(fastest, falling);
            smallest = std::min(smallest, block.contact->smallest_distance(state.u));
            bounced = bounced || falling < 0.0;  // moving up: after the first contact
            if (bounced)
                rebound = std::max(rebound, lowest_height(*block.body, state.u));
        });
        first = false;
        if (charted) {
            heights.push_back(std::move(height));
            forces.push_back(std::move(force));
        }
        const double expected = drop_speed(block_setup.gravity, settings.drop_height);
        table.add_row({c.activation_distance, c.stiffness == 0.0 ? std::string("adaptive") : str(c.stiffness),
                       time_step_label(c.time_step), c.tolerance,
                       block.contact->stiffness(), (fastest - expected) / expected, rebound / settings.drop_height,
                       smallest / c.activation_distance, double(iterations) / steps, 1e3 * seconds / steps});
    }
    table.print(std::cout);
    table.write_csv(run.file("drop_table.csv"));
    drop_charts(run, heights, forces, settings.drop_height, gravity, mass, settings.duration);
}

}  // namespace fem::contact::study
