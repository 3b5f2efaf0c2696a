// Study 1 of ch14_contact: a cube dropped from h onto the floor — the speed at contact against
// √(2gh), the rebound, the smallest distance, and the cost, over d̂, κ, Δt and the Newton tolerance;
// a .pvd of the drop. docs/14_contact.md#the-drop
#include "14_contact/studies.hpp"

#include "common/error.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"
#include "common/vtk_io.hpp"

#include <algorithm>
#include <iostream>
#include <limits>

namespace fem::contact::study {

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
    for (const Case& c : sweep(settings)) {
        BlockSettings block_setup = block_settings(c);
        block_setup.height = settings.drop_height;
        BlockScene block = block_scene(block_setup);
        const int steps = dynamics::step_count(settings.duration, c.time_step);
        std::optional<io::PvdSeries> series;
        if (first)
            series.emplace(run.file("drop.pvd"));
        if (series)
            series->add(0.0, dynamics::body_frame(*block.body, block.state));
        double fastest = 0.0, smallest = std::numeric_limits<double>::infinity(), rebound = 0.0, seconds = 0.0;
        int iterations = 0;
        bool bounced = false;
        for (int step = 0; step < steps; ++step) {
            Timer timer;
            const dynamics::StepInfo info = block.step();
            seconds += timer.seconds();
            iterations += info.newton_iterations;
            const double falling = -mean_velocity(*block.body, block.state.v).z();
            fastest = std::max(fastest, falling);
            smallest = std::min(smallest, block.contact->smallest_distance(block.state.u));
            bounced = bounced || falling < 0.0;  // moving up: after the first contact
            if (bounced)
                rebound = std::max(rebound, lowest_height(*block.body, block.state.u));
            if (series && (step + 1) % 2 == 0)
                series->add(block.state.time, dynamics::body_frame(*block.body, block.state));
        }
        first = false;
        const double expected = drop_speed(block_setup.gravity, settings.drop_height);
        table.add_row({c.activation_distance, c.stiffness == 0.0 ? std::string("adaptive") : str(c.stiffness),
                       str("1/", static_cast<int>(std::lround(1.0 / c.time_step))), c.tolerance,
                       block.contact->stiffness(), (fastest - expected) / expected, rebound / settings.drop_height,
                       smallest / c.activation_distance, double(iterations) / steps, 1e3 * seconds / steps});
    }
    table.print(std::cout);
    table.write_csv(run.file("drop_table.csv"));
}

}  // namespace fem::contact::study
