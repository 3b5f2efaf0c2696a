// What a contact step costs (contact_cost.hpp): the runner's record of every step of a group with
// contact adds up — its timed parts each ≥ 0 and together within the step's time, nothing timed and
// no pair out of contact — and its pairs are the pairs a brute-force count finds at the step's end.
// docs/scenes.md#what-a-contact-step-costs
#include "scene_text.hpp"

#include "scenes/runner.hpp"
#include "scenes/scene_group.hpp"

#include "15_body_contact/broad_phase.hpp"
#include "15_body_contact/distances.hpp"

#include <catch2/catch.hpp>

#include <string>
#include <vector>

using namespace fem;
using namespace fem::scenes;

namespace {

/// Every record's split adds up (header); a contact step took Newton iterations and timed work.
void check_split(const RunResult& run)
{
    for (const ContactStepRecord& r : run.contact_records) {
        INFO("step " << r.step << (r.contact ? " (contact)" : " (free)"));
        CHECK(r.cost.barrier_seconds >= 0.0);
        CHECK(r.cost.collision_seconds >= 0.0);
        CHECK(r.cost.solve_seconds >= 0.0);
        CHECK(r.rest_seconds() >= 0.0);  // the parts within the step's total
        CHECK(r.seconds == run.records[0][static_cast<std::size_t>(r.step)].seconds);
        CHECK(r.newton_iterations == run.records[0][static_cast<std::size_t>(r.step)].newton_iterations);
        if (r.contact) {
            CHECK(r.newton_iterations > 0);
            CHECK(r.cost.barrier_seconds > 0.0);
            CHECK(r.cost.solve_seconds > 0.0);
        } else {
            CHECK(r.cost.barrier_seconds == 0.0);
            CHECK(r.cost.collision_seconds == 0.0);
            CHECK(r.cost.solve_seconds == 0.0);
            CHECK(r.cost.new_patterns == 0);
            CHECK(r.pairs.total() == 0);
        }
    }
}

}  // namespace

TEST_CASE("a block dropped on the floor: each step's split adds up, and its vertex-obstacle pairs are the vertices within "
          "d-hat of the floor",
          "[scenes][contact]")
{
    // A 10 cm cube (2 cells) dropped from 2 cm onto z = 0, a frame per step.
    const SceneSpec scene = testing::scene_from(
        "cost_drop",
        "[[body]]\nname = \"block\"\n"
        "mesh = { generator = \"box\", size = [0.1, 0.1, 0.1], cells = [2, 2, 2], translate = [0.0, 0.0, 0.02] }\n"
        "material = { model = \"auto\", youngs_modulus = 1e5, poisson_ratio = 0.3, density = 1000.0 }\n"
        "[[obstacle]]\ntype = \"half-space\"\nfriction = 0.5\n"
        "[time]\nstep = 0.01\nduration = 0.25\n[output]\nframe_rate = 100\n");
    const RunResult run = run_positions(scene);
    REQUIRE(run.contact_records.size() == static_cast<std::size_t>(run.steps));  // one group, every step
    REQUIRE(run.frames[0].size() == static_cast<std::size_t>(run.steps) + 1);   // a frame per step
    check_split(run);
    const double reach = scene.contact.activation_distance;
    int contact_steps = 0, first_contact = -1;
    for (const ContactStepRecord& r : run.contact_records) {
        const MatrixX3d& x = run.frames[0][static_cast<std::size_t>(r.step)];
        // Every vertex of a 2-cell cube but its centre is on its surface, and the centre is 5 cm up.
        const int near_floor = static_cast<int>((x.col(2).array() < reach).count());
        CAPTURE(r.step);
        CHECK(r.pairs.vertex_obstacle == near_floor);
        CHECK(r.pairs.point_triangle + r.pairs.edge_edge == 0);  // no self-contact
        CHECK(r.surface_primitives == 26 + 72 + 48);              // 26 vertices, 72 edges (Euler), 48 triangles
        if (r.contact) {
            ++contact_steps;
            first_contact = first_contact < 0 ? r.step : first_contact;
        }
    }
    CHECK(contact_steps == run.contact_steps[0]);
    REQUIRE(first_contact > 1);
    // It lands and rests: within d̂ of the floor at the end, with pairs.
    CHECK(run.contact_records.back().contact);
    CHECK(run.contact_records.back().pairs.vertex_obstacle > 0);
    // The solver met the contact step's pattern for the first time at the first contact step.
    CHECK(run.contact_records[static_cast<std::size_t>(first_contact - 1)].cost.new_patterns >= 1);
}

TEST_CASE("two blocks thrown at each other: each step's split adds up, and its pairs are a brute-force count's",
          "[scenes][contact]")
{
    const std::string rubber =
        "material = { model = \"stable-neo-hookean\", youngs_modulus = 1e5, poisson_ratio = 0.3, density = 1000.0 }\n";
    const SceneSpec scene = testing::scene_from(
        "cost_two_blocks",
        str("gravity = [0.0, 0.0, 0.0]\n"
            "[[body]]\nname = \"a\"\nmesh = { generator = \"box\", size = [0.1, 0.1, 0.1], cells = [1, 1, 1], "
            "translate = [-0.111, 0.0, 0.0] }\n",
            rubber, "initial_velocity = [1.0, 0.0, 0.0]\n",
            "[[body]]\nname = \"b\"\nmesh = { generator = \"box\", size = [0.1, 0.1, 0.1], cells = [1, 1, 1], "
            "translate = [0.011, 0.02, 0.01] }\n",
            rubber, "initial_velocity = [-1.0, 0.0, 0.0]\n",
            "[contact]\nbodies = true\n[time]\nstep = \"1/200\"\nduration = 0.03\n[output]\nframe_rate = 200\n"));
    REQUIRE(contact_groups(scene) == std::vector<std::vector<int>>{{0, 1}});
    const RunResult run = run_positions(scene);
    REQUIRE(run.contact_records.size() == static_cast<std::size_t>(run.steps));
    check_split(run);
    // The brute-force count: every vertex of one block against every triangle of the other, every
    // edge of one against every edge of the other (the blocks do not hold themselves off).
    const TetMesh joined = joined_mesh(scene, {0, 1});
    const contact::SurfacePrimitives surface = contact::surface_primitives(joined);
    const Eigen::Index split = scene.bodies[0].mesh.V.rows();
    const auto owner = [&](int v) { return v < split ? 0 : 1; };
    const double reach = scene.contact.activation_distance;
    bool met = false;
    for (const ContactStepRecord& r : run.contact_records) {
        const std::size_t k = static_cast<std::size_t>(r.step);
        MatrixX3d x(joined.V.rows(), 3);
        x << run.frames[0][k], run.frames[1][k];
        ContactPairs brute;
        for (int p : surface.vertices)
            for (Eigen::Index t = 0; t < surface.triangles.rows(); ++t) {
                const Eigen::Vector3d a = x.row(surface.triangles(t, 0)), b = x.row(surface.triangles(t, 1)),
                                      c = x.row(surface.triangles(t, 2)), q = x.row(p);
                if (owner(p) != owner(surface.triangles(t, 0)) &&
                    contact::point_triangle_squared_distance(q, a, b, c, contact::point_triangle_type(q, a, b, c)).value <
                        reach * reach)
                    ++brute.point_triangle;
            }
        for (Eigen::Index i = 0; i < surface.edges.rows(); ++i)
            for (Eigen::Index j = i + 1; j < surface.edges.rows(); ++j) {
                const Eigen::Vector3d a0 = x.row(surface.edges(i, 0)), a1 = x.row(surface.edges(i, 1)),
                                      b0 = x.row(surface.edges(j, 0)), b1 = x.row(surface.edges(j, 1));
                if (owner(surface.edges(i, 0)) != owner(surface.edges(j, 0)) &&
                    contact::edge_edge_squared_distance(a0, a1, b0, b1, contact::edge_edge_type(a0, a1, b0, b1)).value <
                        reach * reach)
                    ++brute.edge_edge;
            }
        CAPTURE(r.step);
        CHECK(r.pairs.point_triangle == brute.point_triangle);
        CHECK(r.pairs.edge_edge == brute.edge_edge);
        CHECK(r.pairs.vertex_obstacle == 0);  // no obstacles
        met = met || (r.contact && r.pairs.total() > 0);
    }
    CHECK(met);
    CHECK(run.contact_steps[0] > 0);
    CHECK(run.contact_steps[0] < run.steps);  // they start more than d̂ apart: the first steps are free
}
