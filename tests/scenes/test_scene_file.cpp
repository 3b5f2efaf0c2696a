// The scene file: every bad scene is a clear error naming file, line, column and field; overrides
// are checked like the file; selectors and prescribed motions. docs/scenes.md#the-scene-file
#include "scenes/scene_file.hpp"
#include "scenes/scene_text.hpp"

#include "13_skinning/skinning.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <cstdlib>
#include <filesystem>
#include <set>

#include <sys/wait.h>

using namespace fem;
using namespace fem::scenes;
using testing::gallery;

namespace {

const std::filesystem::path bad = FEM_SCENE_BAD_DIR;

/// The message of the fem::Error read_scene throws (fails the test when it throws none).
std::string error_of(const std::filesystem::path& file, const std::vector<std::string>& overrides = {},
                     const ReadLimits& limits = {})
{
    try {
        read_scene(file, overrides, false, limits);
    } catch (const Error& e) {
        return e.what();
    }
    FAIL("no error for " << file);
    return "";
}

}  // namespace

TEST_CASE("bad scene files: each names file, line, column, field and what is allowed", "[scenes][scene_file]")
{
    // The table bad_scenes/errors.txt: file -> the texts its error must contain ("reads": none).
    const auto expected = fem::test::error_table(bad / "errors.txt");
    std::set<std::string> replayed;
    for (const auto& entry : std::filesystem::directory_iterator(bad)) {
        if (entry.path().extension() != ".toml")
            continue;  // the meshes the scenes name, and the table
        const std::string name = entry.path().filename().string();
        INFO(name);
        REQUIRE(expected.count(name) == 1);  // every bad scene is in the table
        replayed.insert(name);
        if (expected.at(name) == std::vector<std::string>{"reads"}) {
            CHECK_NOTHROW(read_scene(entry.path()));
            continue;
        }
        const std::string message = error_of(entry.path());
        INFO(message);
        for (const std::string& part : expected.at(name))
            CHECK(message.find(part) != std::string::npos);
    }
    CHECK(replayed.size() == expected.size());  // and every row of the table is a file

    const std::string missing = error_of(bad / "missing.toml");
    CHECK(missing.find("missing.toml': no such file") != std::string::npos);
    // A scene path longer than the system allows (4,096 characters): an error, not a filesystem_error.
    const std::string long_name = error_of(bad / (std::string(5000, 's') + ".toml"));
    CHECK(long_name.find("scene file '") != std::string::npos);
    CHECK(long_name.find("s.toml'") != std::string::npos);  // the name's end is kept
}

TEST_CASE("every gallery scene reads, with and without its quick overrides", "[scenes][scene_file]")
{
    int count = 0;
    for (const auto& entry : std::filesystem::directory_iterator(gallery)) {
        if (entry.path().extension() != ".toml")
            continue;
        ++count;
        INFO(entry.path());
        for (bool quick : {false, true}) {
            const SceneSpec scene = read_scene(entry.path(), {}, quick);
            CHECK(!scene.bodies.empty());
            for (const BodySpec& body : scene.bodies) {
                CHECK(body.mesh.T.rows() > 0);
                CHECK((!body.pinned.empty() || !scene.obstacles.empty() || scene.contact.bodies));  // held, caught by an obstacle, or thrown at another body
            }
        }
    }
    CHECK(count >= 5);
}

TEST_CASE("overrides of --set are checked like the file and reach every body without an index", "[scenes][scene_file]")
{
    const std::filesystem::path pair = gallery / "stiff_soft_pair.toml";
    const SceneSpec all = read_scene(pair, {"body.material.model=corotational", "time.step=1/120"});
    REQUIRE(all.bodies.size() == 2);
    CHECK(all.bodies[0].model == "corotational");
    CHECK(all.bodies[1].model == "corotational");
    CHECK(all.time_step == 1.0 / 120.0);
    const SceneSpec one = read_scene(pair, {"body.1.material.youngs_modulus=2e5"});
    CHECK(one.bodies[0].material.youngs_modulus == 1e6);
    CHECK(one.bodies[1].material.youngs_modulus == 2e5);

    const std::string nu = error_of(pair, {"body.0.material.poisson_ratio=0.5"});
    CHECK(nu.find("--set body.0.material.poisson_ratio=0.5") != std::string::npos);
    CHECK(nu.find("body[0].material.poisson_ratio") != std::string::npos);
    const std::string unknown = error_of(pair, {"time.substeps=3"});
    CHECK(unknown.find("time.substeps: unknown field") != std::string::npos);
    const std::string model = error_of(pair, {"body.material.model=plastic"});
    CHECK(model.find("linear, corotational, stvk, neo-hookean, stable-neo-hookean, stable-neo-hookean-paper, auto") != std::string::npos);
    CHECK(error_of(pair, {"time.step"}).find("expected key=value") != std::string::npos);
    CHECK(error_of(pair, {"body.5.name=x"}).find("no 5") != std::string::npos);
    // An index beyond any integer type: the same error, not std::out_of_range (issue 23, row 2).
    const std::string huge = error_of(pair, {"body.99999999999999999999.x=1"});
    CHECK(huge.find("--set body.99999999999999999999.x=1: body has 2 entries, no 99999999999999999999") !=
          std::string::npos);
    // Nested beyond max_nesting in the key or the value: refused before they are parsed (row 1).
    std::string deep_key = "a";
    for (int i = 0; i < 40; ++i)
        deep_key += ".a";
    CHECK(error_of(pair, {deep_key + "=1"}).find("the key has 41 parts; at most 32") != std::string::npos);
    CHECK(error_of(pair, {"gravity=" + std::string(50000, '[')}).find("nested deeper than 32 levels") !=
          std::string::npos);
    // An override that sets a table, or makes one, is named by the errors inside it (issue 23, row 12).
    CHECK(error_of(pair, {"body.material={model=1}"}).find("--set body.material={model=1}") != std::string::npos);
    CHECK(error_of(pair, {"body.-1.name=x"}).find("--set body.-1.name=x") != std::string::npos);
    CHECK(error_of(pair, {"gravity=[[1], 2, 3]"}).find("got an array") != std::string::npos);
    // A body name is printable, one word, nothing a CSV row splits at.
    for (const std::string name : {"\"a\\nb\"", "\"a\\u0000b\"", "\"a,b\""})
        CHECK(error_of(pair, {"body.0.name=" + name}).find("body[0].name: must be a non-empty name of printable") !=
              std::string::npos);
    // Without PNG frames the default video is none (a null dereference the fuzzer found: the check
    // named the video field, which the file did not have).
    CHECK(read_scene(pair, {"output.png=false"}).output.video == "none");
    CHECK(error_of(pair, {"output.png=false", "output.video=mp4"}).find("output.video: is made from the PNG frames") !=
          std::string::npos);
    // Every error of an override names the scene file too.
    CHECK(error_of(pair, {"time.step"}).find("stiff_soft_pair.toml") != std::string::npos);
}

TEST_CASE("a skin section is read and checked: the file and the body it names", "[scenes][scene_file]")
{
    // The scene reads; binding the skin (chapter 13) is the runner's, which refuses this one.
    const SceneSpec scene = read_scene(bad / "skin.toml");
    REQUIRE(scene.skin.has_value());
    CHECK(scene.skin->body == "body0");

    // The gallery's skinned bunny: a lattice (chapter 13) instead of TetGen, its fields checked.
    const std::filesystem::path skinned = gallery / "skinned_bunny.toml";
    const SceneSpec lattice = read_scene(skinned);
    CHECK(lattice.bodies.front().mesh_spec.lattice == 6);
    CHECK(lattice.bodies.front().mesh.T.rows() % 6 == 0);  // whole cubes of six tets
    CHECK(error_of(skinned, {"body.mesh.tetgen=pq1.5Y"}).find("either tetgen or lattice") != std::string::npos);
    const std::string lattice0 = error_of(skinned, {"body.mesh.lattice=0"});
    CHECK(lattice0.find("body[0].mesh.lattice") != std::string::npos);
    CHECK(lattice0.find("skinned_bunny.toml") == lattice0.rfind("skinned_bunny.toml"));  // its place once (row 12)
    // A lattice is counted before it is built: its memory, and its winding-number terms (cubes of the
    // surface's bounding box times triangles), which for lattice = 100 took minutes (issue 23, the fuzzer).
    ReadLimits small;
    small.lattice_work = 2e6;
    CHECK_NOTHROW(read_scene(skinned, {}, false, small));
    const std::string work = error_of(skinned, {"body.mesh.lattice=8"}, small);
    CHECK(work.find("body[0].mesh.lattice: up to ") != std::string::npos);
    CHECK(work.find("3674 triangles are") != std::string::npos);
    CHECK(work.find("at most 2e+06 are allowed: use a smaller lattice") != std::string::npos);
    small.memory = std::size_t(1) << 20;
    CHECK(error_of(skinned, {}, small).find("body[0].mesh.lattice: a run of this mesh needs about") != std::string::npos);
    CHECK(error_of(skinned, {"skin.body=nobody"}).find("no body is called 'nobody'") != std::string::npos);
    const std::string no_skin = error_of(skinned, {"skin.file=nothing.obj"});
    CHECK(no_skin.find("skin.file: no such file: ") != std::string::npos);
    CHECK(no_skin.find((gallery / "nothing.obj").string()) != std::string::npos);  // the first place looked
}

TEST_CASE("selectors: box, plane, list, and the vertices of a box mesh they pick", "[scenes][scene_file]")
{
    const TetMesh mesh = box_mesh(2, 2, 2, Eigen::Vector3d(1.0, 1.0, 1.0));  // 27 vertices on a 3x3x3 grid
    Selector plane;
    plane.kind = Selector::Kind::plane;
    plane.point = Eigen::Vector3d(0.5, 0.0, 0.0);
    plane.normal = Eigen::Vector3d::UnitX();
    CHECK(select_vertices(mesh, plane).size() == 9);
    plane.below = true;
    CHECK(select_vertices(mesh, plane).size() == 18);
    Selector box;
    box.low = Eigen::Vector3d(0.9, 0.9, 0.9);
    box.high = Eigen::Vector3d(1.0, 1.0, 1.0);
    const std::vector<int> corner = select_vertices(mesh, box);
    REQUIRE(corner.size() == 1);
    CHECK(mesh.V.row(corner[0]).isApprox(Eigen::RowVector3d(1.0, 1.0, 1.0)));
    Selector list;
    list.kind = Selector::Kind::vertices;
    list.vertices = {3, 1, 3};
    CHECK(select_vertices(mesh, list) == std::vector<int>{1, 3});
    list.vertices = {27};
    CHECK_THROWS_AS(select_vertices(mesh, list), Error);
}

TEST_CASE("prescribed motion: the smooth ramp reaches the rotation and holds it", "[scenes][scene_file]")
{
    Motion turn;
    turn.kind = Motion::Kind::rotate;
    turn.axis = Eigen::Vector3d::UnitX();
    turn.center = Eigen::Vector3d(0.0, 0.5, 0.5);
    turn.angle = std::acos(-1.0);
    turn.start = 1.0;
    turn.end = 3.0;
    const Eigen::Vector3d X(0.2, 1.0, 0.5);
    CHECK(prescribed_displacement(turn, X, 0.5).norm() == 0.0);  // before the start
    // Half way, s = 1/2: a quarter turn about the axis through (0, 0.5, 0.5).
    const Eigen::Vector3d half = X + prescribed_displacement(turn, X, 2.0);
    CHECK((half - Eigen::Vector3d(0.2, 0.5, 1.0)).norm() < 1e-15);
    const Eigen::Vector3d end = X + prescribed_displacement(turn, X, 10.0);
    CHECK((end - Eigen::Vector3d(0.2, 0.0, 0.5)).norm() < 1e-15);
    // A screw: the same turn with its axis carried by 0.1 m along x, half of it half way.
    Motion screw = turn;
    screw.displacement = Eigen::Vector3d(0.1, 0.0, 0.0);
    CHECK((X + prescribed_displacement(screw, X, 2.0) - Eigen::Vector3d(0.25, 0.5, 1.0)).norm() < 1e-15);
    CHECK((X + prescribed_displacement(screw, X, 10.0) - Eigen::Vector3d(0.3, 0.0, 0.5)).norm() < 1e-15);
    Motion shift;
    shift.kind = Motion::Kind::translate;
    shift.displacement = Eigen::Vector3d(0.0, 0.0, 0.3);
    shift.start = 0.0;
    shift.end = 1.0;
    CHECK(prescribed_displacement(shift, X, 0.25).z() == Approx(0.3 * (3 * 0.0625 - 2 * 0.015625)));
}

TEST_CASE("boundary faces of a box mesh: 12 per face of cubes, outward, closing the volume", "[scenes][scene_file]")
{
    // Surface loads lump a traction onto chapter 13's boundary faces: they must be outward and complete.
    const TetMesh mesh = box_mesh(2, 1, 1, Eigen::Vector3d(2.0, 1.0, 1.0));
    const MatrixX3i F = skin::boundary_faces(mesh).faces;
    CHECK(F.rows() == 2 * (2 * 1 + 2 * 1 + 1 * 1) * 2);
    // Σ over outward faces of (x · n) area / 3 is the volume (the divergence theorem).
    double volume = 0.0;
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
        const Eigen::Vector3d a = mesh.V.row(F(f, 0)), b = mesh.V.row(F(f, 1)), c = mesh.V.row(F(f, 2));
        volume += a.dot(b.cross(c)) / 6.0;
    }
    CHECK(volume == Approx(2.0).epsilon(1e-14));
}

TEST_CASE("fem_scene refuses an --out that holds the scene or its mesh, before anything runs (issue 23, row 3)", "[scenes][scene_file]")
{
    // proj/mybar.toml reads proj/mybar/mesh.node; with --out proj the frames folder mybar/ replaced
    // the user's folder, mesh included, and the run exited 0.
    const std::filesystem::path proj = fem::test::fresh_output_dir("overlap") / "proj";
    const std::filesystem::path mesh = proj / "mybar" / "mesh.node";
    fem::write_file(mesh, "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n");
    fem::write_file(proj / "mybar" / "mesh.ele", "1 4 0\n0 0 1 2 3\n");
    fem::write_file(proj / "mybar.toml", "[[body]]\nmesh = { file = \"mybar/mesh.node\" }\n"
                                         "material = { youngs_modulus = 1e5, poisson_ratio = 0.3, density = 1000 }\n"
                                         "pin = [{ vertices = [0] }]\n[time]\nduration = 0.05\n"
                                         "[output]\npng = false\ncharts = false\n");
    for (const std::filesystem::path& out : {proj, proj / "mybar"}) {
        const std::string command = std::string(FEM_SCENE_EXE) + " '" + (proj / "mybar.toml").string() + "' --out '" +
                                    out.string() + "' --no-progress > /dev/null 2>&1";
        INFO(command);
        CHECK(WEXITSTATUS(std::system(command.c_str())) == 1);
        CHECK(std::filesystem::exists(mesh));
        CHECK_FALSE(std::filesystem::exists(proj / "mybar.pvd"));
    }
}
