// The scenes capstone: bodies that meet each other ([contact] bodies, scene_group.hpp). Two blocks
// thrown at each other through the scene API (momentum, the half-turn symmetry that swaps them, no
// edge through a face, they part), far-apart bodies stepped as separate solves (equal to the runs
// without body contact), the joint mass from each body's density, the start check, the fields, and
// no edge through a face in any frame of the new gallery scenes' quick runs.
// docs/scenes.md#bodies-against-bodies
#include "scene_text.hpp"

#include "scenes/runner.hpp"
#include "scenes/scene_group.hpp"

#include "15_body_contact/broad_phase.hpp"
#include "15_body_contact/intersections.hpp"

#include "12_hyperelastic_newton/force_models.hpp"

#include "06_assembly/assembly.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <filesystem>
#include <fstream>
#include <numeric>
#include <string>
#include <vector>

using namespace fem;
using namespace fem::scenes;

namespace {

/// Writes mesh as TetGen's <stem>.node and <stem>.ele in the tests' output folder; returns the .node.
std::filesystem::path write_tetgen(const TetMesh& mesh, const std::string& stem)
{
    const std::filesystem::path dir = FEM_TEST_OUTPUT_DIR;
    std::filesystem::create_directories(dir);
    std::ofstream node(dir / (stem + ".node"));
    node.precision(17);
    node << mesh.V.rows() << " 3 0 0\n";
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
        node << v << " " << mesh.V(v, 0) << " " << mesh.V(v, 1) << " " << mesh.V(v, 2) << "\n";
    std::ofstream ele(dir / (stem + ".ele"));
    ele << mesh.T.rows() << " 4 0\n";
    for (Eigen::Index t = 0; t < mesh.T.rows(); ++t)
        ele << t << " " << mesh.T(t, 0) << " " << mesh.T(t, 1) << " " << mesh.T(t, 2) << " " << mesh.T(t, 3) << "\n";
    return dir / (stem + ".node");
}

/// A scene of two bodies: the text of each [[body]] (name, mesh, material and the rest), then extra.
std::string two_bodies(const std::string& first, const std::string& second, const std::string& extra,
                       double frame_rate = 30.0)
{
    return str("title = \"two bodies\"\ngravity = [0.0, 0.0, 0.0]\n[[body]]\n", first, "\n[[body]]\n", second, "\n",
               extra, "\n[output]\npvd = false\npng = false\ncsv = false\ncharts = false\nvideo = \"none\"\n",
               "frame_rate = ", frame_rate, "\n");
}

const std::string rubber = "material = { model = \"stable-neo-hookean\", youngs_modulus = 1e5, poisson_ratio = 0.3, density = 1000.0 }";

/// Σ m_v v_v of a body between two frames a time dt apart: backward Euler's u⁺ = u + Δt v⁺ gives v⁺
/// exactly from the positions of consecutive steps.
Eigen::Vector3d momentum(const Eigen::VectorXd& masses, const MatrixX3d& before, const MatrixX3d& after, double dt)
{
    return ((after - before).transpose() * masses) / dt;
}

/// The joined surface of the frame k's bodies and the body of each vertex.
std::string crossing_at(const RunResult& run, std::size_t k, const TetMesh& joined, const std::vector<int>& owner)
{
    MatrixX3d x(joined.V.rows(), 3);
    Eigen::Index row = 0;
    for (const std::vector<MatrixX3d>& body : run.frames) {
        x.middleRows(row, body[k].rows()) = body[k];
        row += body[k].rows();
    }
    const contact::SurfacePrimitives surface = contact::surface_primitives(joined);
    return contact::describe(contact::first_edge_through_triangle(x, surface.edges, surface.triangles, owner),
                             surface.edges, surface.triangles);
}

std::vector<int> vertex_owners(const SceneSpec& scene)
{
    std::vector<int> owner;
    for (std::size_t i = 0; i < scene.bodies.size(); ++i)
        owner.insert(owner.end(), static_cast<std::size_t>(scene.bodies[i].mesh.V.rows()), static_cast<int>(i));
    return owner;
}

std::vector<int> all_bodies(const SceneSpec& scene)
{
    std::vector<int> all(scene.bodies.size());
    std::iota(all.begin(), all.end(), 0);
    return all;
}

}  // namespace

TEST_CASE("two blocks thrown at each other in one solve: momentum kept, the half-turn symmetry kept, no edge through a "
          "face, and they part",
          "[scenes][bodies][slow]")
{
    // Block a spans x in [-0.11, -0.01], turned by 0.3 rad about its x axis; block b is a turned by
    // half a turn about the z axis (x, y → −x, −y: its own tets, so the whole scene is symmetric under
    // that turn, which swaps them). a's turn leaves no edge of a parallel to a facing edge of b (b's
    // face is turned by −0.3 rad): parallel edges have no unique closest points, and the course's
    // edge–edge distance picks an endpoint by the order of the edges, which the swap does not keep.
    TetMesh a = box_mesh(2, 2, 2, Eigen::Vector3d::Constant(0.1));
    a.V.rowwise() -= Eigen::RowVector3d(0.0, 0.05, 0.05);
    a.V = a.V * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix().transpose();
    a.V.col(0).array() -= 0.11;
    TetMesh b = a;
    b.V.col(0) *= -1.0;
    b.V.col(1) *= -1.0;
    b.V.col(2) = a.V.col(2);
    // Turned tets keep their orientation (a proper rotation).
    write_tetgen(a, "block_a");
    write_tetgen(b, "block_b");
    const double dt = 1.0 / 200.0;
    const SceneSpec scene = testing::scene_from(
        "two_blocks",
        two_bodies(str("name = \"a\"\nmesh = { file = \"block_a.node\" }\n", rubber, "\ninitial_velocity = [1.0, 0.0, 0.0]"),
                   str("name = \"b\"\nmesh = { file = \"block_b.node\" }\n", rubber, "\ninitial_velocity = [-1.0, 0.0, 0.0]"),
                   "[contact]\nbodies = true\n[time]\nstep = \"1/200\"\nduration = 0.1\n[solver]\nnewton_tolerance = 1e-9\n",
                   200.0));
    REQUIRE(contact_groups(scene) == std::vector<std::vector<int>>{{0, 1}});
    const RunResult run = run_positions(scene);
    REQUIRE(run.frames.size() == 2);
    REQUIRE(run.frames[0].size() == 21);  // every step a frame
    CHECK(run.contact_steps[0] > 0);
    const Eigen::VectorXd masses = assembly::vertex_masses(a, 1000.0);
    const double scale = masses.sum() * 1.0;  // m v of one block [kg m/s]
    const TetMesh joined = joined_mesh(scene, {0, 1});
    const std::vector<int> owner = vertex_owners(scene);
    for (std::size_t k = 1; k < run.frames[0].size(); ++k) {
        INFO("step " << k);
        const Eigen::Vector3d pa = momentum(masses, run.frames[0][k - 1], run.frames[0][k], dt);
        const Eigen::Vector3d pb = momentum(masses, run.frames[1][k - 1], run.frames[1][k], dt);
        // The barrier's forces are internal: Σ p stays 0 (each Newton iterate keeps it; no pins, no gravity).
        CHECK((pa + pb).norm() <= 1e-9 * scale);
        // b's motion is a's turned by half a turn.
        MatrixX3d turned = run.frames[0][k];
        turned.col(0) *= -1.0;
        turned.col(1) *= -1.0;
        CHECK((turned - run.frames[1][k]).cwiseAbs().maxCoeff() <= 1e-7);
        CHECK(crossing_at(run, k, joined, owner).empty());
    }
    // They met (a's speed turned round) and part: a moves −x at the end, and the gap exceeds d̂.
    const std::size_t last = run.frames[0].size() - 1;
    const Eigen::Vector3d pa = momentum(masses, run.frames[0][last - 1], run.frames[0][last], dt);
    CHECK(pa.x() < -0.2 * scale);
    const double gap = run.frames[1][last].col(0).minCoeff() - run.frames[0][last].col(0).maxCoeff();
    CHECK(gap > scene.contact.activation_distance);
    // Each body's record: its own energies, and together the group's books balance (chapter 10's identity).
    for (std::size_t i = 0; i < 2; ++i) {
        const dynamics::StepRecord& r = run.records[i].back();
        const double start = run.records[i].front().energies.total();
        CHECK(std::abs(start + r.work_in - r.energies.total() - r.damping_dissipated - r.integrator_dissipated) <=
              1e-9 * start);
    }
}

TEST_CASE("bodies that cannot reach each other are separate solves, equal to the run without body contact",
          "[scenes][bodies]")
{
    const auto text = [](bool bodies) {
        return two_bodies(
            str("name = \"a\"\nmesh = { generator = \"box\", size = [0.1, 0.1, 0.1], cells = [2, 2, 2] }\n", rubber,
                "\ninitial_velocity = [0.1, 0.0, 0.0]"),
            str("name = \"b\"\nmesh = { generator = \"box\", size = [0.1, 0.1, 0.1], cells = [2, 2, 2], translate = [1.0, "
                "0.0, 0.0] }\nmaterial = { model = \"stable-neo-hookean\", youngs_modulus = 3e5, poisson_ratio = 0.4, "
                "density = 500.0 }\ninitial_velocity = [-0.1, 0.2, 0.0]"),
            str("[contact]\nbodies = ", bodies ? "true" : "false", "\n[time]\nstep = \"1/100\"\nduration = 0.2\n"));
    };
    const SceneSpec together = testing::scene_from("far_apart", text(true));
    const SceneSpec apart = testing::scene_from("far_apart_off", text(false));
    // 0.9 m between them; in 0.2 s at 0.1 and 0.22 m/s each travels at most 0.044 m.
    CHECK(travel_bound(together, together.bodies[1]) == Approx(0.2 * std::sqrt(0.05)).epsilon(1e-12));
    REQUIRE(contact_groups(together) == std::vector<std::vector<int>>{{0}, {1}});
    const RunResult with = run_positions(together), without = run_positions(apart);
    for (std::size_t i = 0; i < 2; ++i)
        for (std::size_t k = 0; k < with.frames[i].size(); ++k)
            CHECK((with.frames[i][k] - without.frames[i][k]).cwiseAbs().maxCoeff() <= 1e-15);
    // Moved within reach (5 cm apart): one solve.
    SceneSpec near = together;
    near.bodies[1].mesh.V.col(0).array() -= 0.85;
    CHECK(contact_groups(near) == std::vector<std::vector<int>>{{0, 1}});
}

TEST_CASE("a group's joint body: each body's own density in the mass, its pins shifted, its forces on its slice",
          "[scenes][bodies]")
{
    const SceneSpec scene = testing::scene_from(
        "joint_mass",
        two_bodies(str("name = \"a\"\nmesh = { generator = \"box\", size = [0.1, 0.1, 0.1], cells = [1, 1, 2] }\n", rubber),
                   "name = \"b\"\nmesh = { generator = \"box\", size = [0.1, 0.1, 0.1], cells = [2, 1, 1], translate = [0.2, "
                   "0.0, 0.0] }\nmaterial = { model = \"corotational\", youngs_modulus = 3e5, poisson_ratio = 0.4, density = "
                   "250.0 }\n[[body.pin]]\nplane = { point = [0.2, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }",
                   "[contact]\nbodies = true"));
    const dynamics::Scene joined = joined_scene(scene, {0, 1});
    const dynamics::Body body(joined);
    const Eigen::Index na = scene.bodies[0].mesh.V.rows(), nb = scene.bodies[1].mesh.V.rows();
    const Eigen::VectorXd ma = assembly::vertex_masses(scene.bodies[0].mesh, 1000.0);
    const Eigen::VectorXd mb = assembly::vertex_masses(scene.bodies[1].mesh, 250.0);
    for (Eigen::Index v = 0; v < na; ++v)
        CHECK(body.dof_masses()[3 * v] == Approx(ma[v]).epsilon(1e-14));
    for (Eigen::Index v = 0; v < nb; ++v)
        CHECK(body.dof_masses()[3 * (na + v)] == Approx(mb[v]).epsilon(1e-14));
    REQUIRE(joined.pinned.size() == scene.bodies[1].pinned.size());
    CHECK(joined.pinned.front() == scene.bodies[1].pinned.front() + na);
    // JointForces: each part on its slice, K block diagonal.
    auto fa = hyper::make_force_model("stable-neo-hookean", scene.bodies[0].mesh, scene.bodies[0].material);
    auto fb = hyper::make_force_model("corotational", scene.bodies[1].mesh, scene.bodies[1].material);
    JointForces joint({fa.get(), fb.get()}, {na, nb});
    const Eigen::VectorXd u = 1e-3 * Eigen::VectorXd::LinSpaced(3 * (na + nb), -1.0, 1.0);
    Eigen::VectorXd f, f_a, f_b;
    const double energy = joint.evaluate(u, f);
    const double energy_a = fa->evaluate(u.head(3 * na), f_a), energy_b = fb->evaluate(u.tail(3 * nb), f_b);
    CHECK(energy == Approx(energy_a + energy_b).epsilon(1e-14));
    CHECK((f.head(3 * na) - f_a).norm() == 0.0);
    CHECK((f.tail(3 * nb) - f_b).norm() == 0.0);
    const Eigen::MatrixXd K(joint.stiffness(u));
    CHECK(K.topRightCorner(3 * na, 3 * nb).norm() == 0.0);
    CHECK((K.bottomRightCorner(3 * nb, 3 * nb) - Eigen::MatrixXd(fb->stiffness(u.tail(3 * nb)))).norm() == 0.0);
    CHECK(joint.name() == "stable-neo-hookean+corotational");
}

TEST_CASE("bodies that start closer than d-hat or intersecting are refused, naming both bodies and the primitives",
          "[scenes][bodies]")
{
    const auto scene_at = [](const std::string& name, double x, const std::string& size) {
        return testing::scene_from(
            name, two_bodies(str("name = \"a\"\nmesh = { generator = \"box\", size = [0.1, 0.1, 0.1] }\n", rubber),
                             str("name = \"b\"\nmesh = { generator = \"box\", size = ", size, ", translate = [", x,
                                 ", 0.0, 0.0] }\n", rubber),
                             "[contact]\nbodies = true\nactivation_distance = 1e-3"));
    };
    // 0.5 mm apart: a point–triangle (or edge–edge) pair within d̂.
    CHECK_THROWS_WITH(check_start_gaps(scene_at("gap_small", 0.1005, "[0.1, 0.1, 0.1]")),
                      Catch::Contains("body 'a'") && Catch::Contains("body 'b'") && Catch::Contains("0.0005 m away") &&
                          Catch::Contains("closer than d̂ = 0.001 m"));
    CHECK_THROWS_WITH(check_start_gaps(scene_at("gap_small", 0.1005, "[0.1, 0.1, 0.1]")),
                      Catch::Contains("vertex") || Catch::Contains("edge"));
    // The advice helps: apart by d̂ − 0.5 mm = 0.5 mm, or a d̂ below the gap; followed, both pass.
    CHECK_THROWS_WITH(check_start_gaps(scene_at("gap_small", 0.1005, "[0.1, 0.1, 0.1]")),
                      Catch::Contains("move them apart by at least 0.0005 m") &&
                          Catch::Contains("or set d̂ below the gap, 0.0005 m"));
    CHECK_NOTHROW(check_start_gaps(scene_at("gap_moved", 0.1005 + 0.0005, "[0.1, 0.1, 0.1]")));
    SceneSpec smaller = scene_at("gap_smaller", 0.1005, "[0.1, 0.1, 0.1]");
    smaller.contact.activation_distance = 0.0004;
    CHECK_NOTHROW(check_start_gaps(smaller));
    // Touching (faces in one plane, 0 m): no d̂ helps, and the refusal does not offer one; moved by
    // the d̂ it names, they pass.
    CHECK_THROWS_WITH(check_start_gaps(scene_at("touching", 0.1, "[0.1, 0.1, 0.1]")),
                      Catch::Contains("body 'a'") && Catch::Contains("body 'b'") && !Catch::Contains("set d̂") &&
                          (Catch::Contains("move them apart by at least 0.001 m") ||
                           Catch::Contains("at least d̂ = 0.001 m apart")));
    CHECK_NOTHROW(check_start_gaps(scene_at("touching_moved", 0.1 + 0.001, "[0.1, 0.1, 0.1]")));
    // Overlapping by 2 cm: edges cross faces. Both bodies named, each with its own vertex numbers:
    // b's vertices count from 0 in b (a has 8), so no number of b's reaches 8.
    const std::string pierced = [&] {
        try {
            check_start_gaps(scene_at("overlap", 0.08, "[0.1, 0.1, 0.1]"));
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string();
    }();
    CAPTURE(pierced);
    CHECK_THAT(pierced, Catch::Contains("body 'a' and body 'b' start intersecting") ||
                            Catch::Contains("body 'b' and body 'a' start intersecting"));
    CHECK_THAT(pierced, Catch::Contains("own vertex numbers") && !Catch::Contains("joined numbering") &&
                            !Catch::Contains("set") && Catch::Contains("move them apart"));
    const auto numbers = [&](const std::string& after) {  // the vertex numbers in the "(i, j, …)" after `after`
        std::vector<int> found;
        std::size_t at = pierced.find(after);
        REQUIRE(at != std::string::npos);
        at = pierced.find('(', at);
        for (std::size_t end = pierced.find(')', at); at < end;) {
            found.push_back(std::stoi(pierced.substr(at + 1)));
            at = pierced.find_first_of(",)", at + 1);
            if (pierced[at] == ')')
                break;
        }
        return found;
    };
    for (const std::string& primitive : {std::string(" edge "), std::string(" triangle ")})
        for (int v : numbers(primitive)) {
            CHECK(v >= 0);
            CHECK(v < 8);  // a one-cell box has 8 vertices
        }
    // A small block wholly inside the other: no surface near another, one inside it.
    const SceneSpec inside = testing::scene_from(
        "inside", two_bodies(str("name = \"a\"\nmesh = { generator = \"box\", size = [0.1, 0.1, 0.1] }\n", rubber),
                             str("name = \"b\"\nmesh = { generator = \"box\", size = [0.01, 0.01, 0.01], translate = "
                                 "[0.04, 0.04, 0.04] }\n", rubber),
                             "[contact]\nbodies = true"));
    CHECK_THROWS_WITH(check_start_gaps(inside), Catch::Contains("body 'b'") && Catch::Contains("starts inside body 'a'"));
    // 2 cm apart: fine; and without [contact] bodies nothing is checked.
    CHECK_NOTHROW(check_start_gaps(scene_at("gap_fine", 0.12, "[0.1, 0.1, 0.1]")));
    SceneSpec off = scene_at("gap_off", 0.08, "[0.1, 0.1, 0.1]");
    off.contact.bodies = false;
    CHECK_NOTHROW(check_start_gaps(off));
    // The runner refuses before the first step.
    CHECK_THROWS_AS(run_positions(scene_at("gap_run", 0.1005, "[0.1, 0.1, 0.1]")), Error);
}

TEST_CASE("[contact] bodies and body.self_contact: read, defaults, and refused when not true or false", "[scenes][bodies]")
{
    const std::string one = str("name = \"a\"\nmesh = { generator = \"box\" }\n", rubber);
    const std::string other = str("name = \"b\"\nmesh = { generator = \"box\", translate = [2.0, 0.0, 0.0] }\n", rubber);
    const SceneSpec defaults = testing::scene_from("fields_default", two_bodies(one, other, ""));
    CHECK_FALSE(defaults.contact.bodies);
    CHECK_FALSE(defaults.bodies[0].self_contact);
    CHECK_FALSE(has_contact(defaults));
    const SceneSpec on = testing::scene_from("fields_on", two_bodies(one + "\nself_contact = true", other,
                                                                     "[contact]\nbodies = true"));
    CHECK(on.contact.bodies);
    CHECK(on.bodies[0].self_contact);
    CHECK_FALSE(on.bodies[1].self_contact);
    CHECK(has_contact(on));
    CHECK_THROWS_WITH(testing::scene_from("fields_bad", two_bodies(one, other, "[contact]\nbodies = 1")),
                      Catch::Contains("fields_bad.toml:") && Catch::Contains("contact.bodies") &&
                          Catch::Contains("must be true or false"));
    CHECK_THROWS_WITH(testing::scene_from("fields_bad_self", two_bodies(one + "\nself_contact = \"yes\"", other, "")),
                      Catch::Contains("body[0].self_contact") && Catch::Contains("must be true or false"));
}

TEST_CASE("the new gallery scenes' quick runs: no surface edge through a surface triangle at any frame",
          "[scenes][bodies][slow]")
{
    for (const char* name : {"two_bunnies", "block_stack", "bar_coil"}) {
        const std::filesystem::path file = std::filesystem::path(FEM_SCENES_DIR) / (std::string(name) + ".toml");
        INFO(name);
        REQUIRE(std::filesystem::exists(file));
        const SceneSpec scene = read_scene(file, {}, true);
        const RunResult run = run_positions(scene);
        const TetMesh joined = joined_mesh(scene, all_bodies(scene));
        for (std::size_t k = 0; k < run.frames[0].size(); ++k) {
            INFO("frame " << k);
            CHECK(crossing_at(run, k, joined, {}).empty());
        }
    }
}

TEST_CASE("bodies stepped apart that come within d-hat all the same stop the run, naming both", "[scenes][bodies]")
{
    // A bar turned by its pinned end about the z axis sweeps its free end through the block: its pins
    // barely move (their chord is their distance from the axis), so the travel bound leaves the two
    // separate solves, and the check after every step must catch the bar arriving.
    const SceneSpec scene = testing::scene_from(
        "sweep",
        two_bodies("name = \"bar\"\nmesh = { generator = \"box\", size = [0.3, 0.02, 0.02], cells = [6, 1, 1], translate = "
                   "[0.0, -0.01, -0.01] }\nmaterial = { model = \"corotational\", youngs_modulus = 1e6, poisson_ratio = 0.3, "
                   "density = 1000.0 }\n[[body.pin]]\nplane = { point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }\n"
                   "motion = \"rotate\"\naxis = [0.0, 0.0, 1.0]\ncenter = [0.0, 0.0, 0.0]\nangle = 90.0\nstart = 0.0\nend = 1.0",
                   str("name = \"block\"\nmesh = { generator = \"box\", size = [0.05, 0.05, 0.05], translate = [0.15, 0.15, "
                       "-0.025] }\n", rubber),
                   "[contact]\nbodies = true\n[time]\nstep = \"1/60\"\nduration = 1.0"));
    REQUIRE(contact_groups(scene) == std::vector<std::vector<int>>{{0}, {1}});
    CHECK_THROWS_WITH(run_positions(scene), Catch::Contains("bodies 'bar' and 'block'") &&
                                                Catch::Contains("stepped as separate solves"));
}

TEST_CASE("friction between bodies reaches the solve: a block sliding on a slab resting on the floor stops with "
          "contact.friction, slides on without", "[scenes][bodies]")
{
    // A 5 cm block 2 mm above a 30 cm slab that rests 2 mm above a rough floor (μ = 1, which holds the
    // slab), the block sliding at 0.5 m/s; μ = 0.5 between the bodies stops it in v/(μg) ≈ 0.1 s.
    const auto scene_with = [](double friction) {
        return testing::scene_from(
            str("rub_", friction),
            str("title = \"rub\"\n[[body]]\nname = \"slab\"\nmesh = { generator = \"box\", size = [0.3, 0.3, 0.05], "
                "cells = [3, 3, 1], translate = [-0.15, -0.15, 0.002] }\n",
                rubber, "\n[[body]]\nname = \"block\"\nmesh = { generator = \"box\", size = [0.05, 0.05, 0.05], "
                "cells = [1, 1, 1], translate = [-0.1, -0.025, 0.054] }\n",
                rubber, "\ninitial_velocity = [0.5, 0.0, 0.0]\n[[obstacle]]\ntype = \"half-space\"\nfriction = 1.0\n",
                "[time]\nstep = 0.01\nduration = 0.2\n[contact]\nbodies = true\nfriction = ", friction, "\n",
                "[output]\npvd = false\npng = false\ncsv = false\ncharts = false\nvideo = \"none\"\nframe_rate = 100\n"));
    };
    const auto final_speed = [](const SceneSpec& scene) {
        const RunResult run = run_positions(scene);
        const std::vector<MatrixX3d>& block = run.frames[1];
        const std::size_t last = block.size() - 1;
        return ((block[last] - block[last - 1]).colwise().mean() / 0.01).x();
    };
    const double sliding = final_speed(scene_with(0.0)), rubbed = final_speed(scene_with(0.5));
    INFO("final speed of the block: " << sliding << " m/s without friction, " << rubbed << " m/s with mu = 0.5");
    CHECK(sliding > 0.45);
    CHECK(std::abs(rubbed) < 0.05);
}

TEST_CASE("[contact] solver: a block sliding on a slab resting on the floor, with either solver nothing crosses at any "
          "frame, the augmented Lagrangian holds the slab at d-hat and IPC's barrier inside it", "[scenes][bodies][contact]")
{
    // The block of the friction test below on its slab, frictionless between them, 0.2 s.
    const std::string solver = GENERATE(as<std::string>(), "ipc", "augmented_lagrangian");
    const SceneSpec scene = testing::scene_from(
        "slab_" + solver,
        str("title = \"slab\"\n[[body]]\nname = \"slab\"\nmesh = { generator = \"box\", size = [0.3, 0.3, 0.05], "
            "cells = [3, 3, 1], translate = [-0.15, -0.15, 0.002] }\n",
            rubber, "\n[[body]]\nname = \"block\"\nmesh = { generator = \"box\", size = [0.05, 0.05, 0.05], "
            "cells = [1, 1, 1], translate = [-0.1, -0.025, 0.054] }\n",
            rubber, "\ninitial_velocity = [0.5, 0.0, 0.0]\n[[obstacle]]\ntype = \"half-space\"\nfriction = 1.0\n",
            "[time]\nstep = 0.01\nduration = 0.2\n[contact]\nbodies = true\nsolver = \"", solver, "\"\n",
            "[output]\npvd = false\npng = false\ncsv = false\ncharts = false\nvideo = \"none\"\nframe_rate = 100\n"));
    REQUIRE(scene.contact.solver == solver);
    const RunResult run = run_positions(scene);
    REQUIRE(run.frames[0].size() == 21);
    const TetMesh joined = joined_mesh(scene, all_bodies(scene));
    const double reach = scene.contact.activation_distance;
    CAPTURE(solver);
    for (std::size_t k = 0; k < run.frames[0].size(); ++k) {
        INFO("frame " << k);
        CHECK(run.frames[0][k].col(2).minCoeff() > 0.0);  // the slab above the floor
        CHECK(run.frames[1][k].col(2).minCoeff() > 0.0);
        CHECK(crossing_at(run, k, joined, vertex_owners(scene)).empty());
        // The block over the slab's top face (its lowest vertices above the slab's highest).
        CHECK(run.frames[1][k].col(2).minCoeff() > run.frames[0][k].col(2).maxCoeff());
    }
    // At rest on the floor at the end: the augmented Lagrangian's stopping rule holds the pressed
    // vertices at d-hat within 1e-2 d-hat (violation below, complementarity above: chapter 16's
    // tolerances); IPC's barrier balances the weight well inside d-hat.
    const double lowest = run.frames[0].back().col(2).minCoeff();
    CAPTURE(lowest, reach);
    if (solver == "augmented_lagrangian")
        CHECK(std::abs(lowest - reach) <= 1e-2 * reach);
    else
        CHECK(lowest < 0.5 * reach);
}
