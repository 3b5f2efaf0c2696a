// What a scene's contact steps cost: contact_steps.csv and contact_cost.csv.
// docs/scenes.md#what-a-contact-step-costs
#include "scenes/contact_cost.hpp"

#include <algorithm>

namespace fem::scenes {

Table contact_steps_table(const std::vector<ContactStepRecord>& records)
{
    Table table("Contact steps",
                {{"step", Format::integer}, {"time (s)", Format::fixed, 4}, {"bodies", Format::text},
                 {"Newton iterations", Format::integer}, {"new matrix patterns", Format::integer},
                 {"point-triangle pairs", Format::integer}, {"edge-edge pairs", Format::integer},
                 {"vertex-obstacle pairs", Format::integer}, {"step time [s]", Format::scientific, 2},
                 {"barrier and broad phase [s]", Format::scientific, 2}, {"collision check [s]", Format::scientific, 2},
                 {"linear solves [s]", Format::scientific, 2}, {"rest of the step [s]", Format::scientific, 2}});
    for (const ContactStepRecord& r : records)
        if (r.contact)
            table.add_row({double(r.step), r.time, r.bodies, double(r.newton_iterations), double(r.cost.new_patterns),
                           double(r.pairs.point_triangle), double(r.pairs.edge_edge), double(r.pairs.vertex_obstacle),
                           r.seconds, r.cost.barrier_seconds, r.cost.collision_seconds, r.cost.solve_seconds,
                           r.rest_seconds()});
    return table;
}

namespace {

/// The sums over one group's records.
struct GroupCost {
    std::string bodies;
    int surface_primitives = 0, steps = 0, contact_steps = 0, most_pairs = 0;
    long long pairs = 0, newton_iterations = 0, new_patterns = 0;
    double seconds = 0.0, barrier = 0.0, collision = 0.0, solve = 0.0;
};

}  // namespace

Table contact_cost_table(const std::vector<ContactStepRecord>& records)
{
    std::vector<GroupCost> groups;
    for (const ContactStepRecord& r : records) {
        auto group = std::find_if(groups.begin(), groups.end(), [&](const GroupCost& g) { return g.bodies == r.bodies; });
        if (group == groups.end())
            group = groups.insert(groups.end(), GroupCost{.bodies = r.bodies, .surface_primitives = r.surface_primitives});
        ++group->steps;
        if (!r.contact)
            continue;
        ++group->contact_steps;
        group->pairs += r.pairs.total();
        group->most_pairs = std::max(group->most_pairs, r.pairs.total());
        group->newton_iterations += r.newton_iterations;
        group->new_patterns += r.cost.new_patterns;
        group->seconds += r.seconds;
        group->barrier += r.cost.barrier_seconds;
        group->collision += r.cost.collision_seconds;
        group->solve += r.cost.solve_seconds;
    }
    Table table("What a contact step costs (per group of bodies with contact; times per contact step)",
                {{"bodies", Format::text}, {"surface primitives", Format::integer}, {"steps", Format::integer},
                 {"contact steps", Format::integer}, {"mean pairs", Format::fixed, 1}, {"most pairs", Format::integer},
                 {"Newton iterations per contact step", Format::fixed, 2},
                 {"new matrix patterns per contact step", Format::fixed, 2},
                 {"time per contact step [ms]", Format::fixed, 1}, {"barrier and broad phase [ms]", Format::fixed, 1},
                 {"collision check [ms]", Format::fixed, 1}, {"linear solves [ms]", Format::fixed, 1},
                 {"rest of the step [ms]", Format::fixed, 1}, {"barrier share [measured]", Format::fixed, 2},
                 {"collision share [measured]", Format::fixed, 2}, {"solves share [measured]", Format::fixed, 2},
                 {"rest share [measured]", Format::fixed, 2}});
    for (const GroupCost& g : groups) {
        const double per = g.contact_steps > 0 ? 1.0 / g.contact_steps : 0.0;  // no contact step: zeros
        const double share = g.seconds > 0.0 ? 1.0 / g.seconds : 0.0;
        const double rest = g.seconds - g.barrier - g.collision - g.solve;
        table.add_row({g.bodies, double(g.surface_primitives), double(g.steps), double(g.contact_steps),
                       per * double(g.pairs), double(g.most_pairs), per * double(g.newton_iterations),
                       per * double(g.new_patterns), 1e3 * per * g.seconds, 1e3 * per * g.barrier,
                       1e3 * per * g.collision, 1e3 * per * g.solve, 1e3 * per * rest, share * g.barrier,
                       share * g.collision, share * g.solve, share * rest});
    }
    return table;
}

}  // namespace fem::scenes
