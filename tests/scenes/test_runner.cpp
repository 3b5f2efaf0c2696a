// The runner: loads and prescribed motion against closed forms, determinism, an interrupted run,
// bad scene files refused by fem_scene before it writes anything, PNG frames and the video, a skin
// (the live view's tests: test_live_view.cpp). docs/scenes.md#the-runner
#include "scenes/runner.hpp"
#include "scenes/scene_process.hpp"
#include "scenes/scene_text.hpp"

#include "06_assembly/assembly.hpp"

#include "common/error.hpp"
#include "common/mesh_io.hpp"
#include "common/vtk_io.hpp"

#include <catch2/catch.hpp>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <thread>

using namespace fem;
using namespace fem::scenes;
using testing::gallery;
using testing::output;
using testing::read_text;
using testing::start_scene;

namespace {

using testing::scene_from;

/// A free 0.1 m cube (no pin, no gravity) pushed by one load for 0.2 s at Δt = 0.02 s.
std::string pushed_cube(const std::string& model, const std::string& load)
{
    return "gravity = [0.0, 0.0, 0.0]\n[[body]]\n"
           "mesh = { generator = \"box\", size = [0.1, 0.1, 0.1], cells = [2, 2, 2] }\n"
           "material = { model = \"" + model + "\", youngs_modulus = 1e5, poisson_ratio = 0.3, density = 500.0 }\n"
           "[[body.load]]\n" + load + "\n"
           "[time]\nstep = 0.02\nduration = 0.2\n";
}

}  // namespace

TEST_CASE("a point or surface load moves the centre of mass as F t^2 / 2m does under backward Euler", "[scenes]")
{
    // Internal forces sum to zero, so backward Euler gives the total momentum Σ m v = F t_k exactly
    // and the centre of mass Σ m u / m = Δt² F/m · n(n+1)/2 after n steps.
    struct Case {
        std::string model, load;
        Eigen::Vector3d total;  // the load's total force [N]
    };
    const std::vector<Case> cases{
        {"linear", "type = \"point\"\nvertices = [0]\nforce = [0.0, 0.0, 3.0]", {0.0, 0.0, 3.0}},
        {"corotational", "type = \"point\"\nvertices = [0, 26]\nforce = [1.0, -2.0, 0.5]", {1.0, -2.0, 0.5}},
        // 100 Pa on the 0.1 × 0.1 face x = 0.1: 1 N along x.
        {"linear", "type = \"surface\"\nplane = { point = [0.1, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }\n"
                   "traction = [100.0, 0.0, 0.0]", {1.0, 0.0, 0.0}},
    };
    for (const Case& c : cases) {
        INFO(c.model << " " << c.load);
        const SceneSpec scene = scene_from("pushed_cube", pushed_cube(c.model, c.load));
        const RunResult run = run_positions(scene);
        const TetMesh& mesh = scene.bodies[0].mesh;
        const Eigen::VectorXd m = assembly::vertex_masses(mesh, scene.bodies[0].material.density);
        const MatrixX3d u = run.frames[0].back() - mesh.V;
        const Eigen::Vector3d weighted = (u.array().colwise() * m.array()).colwise().sum().transpose();
        const int n = run.steps;
        REQUIRE(n == 10);
        const Eigen::Vector3d expected = 0.02 * 0.02 * c.total * (n * (n + 1) / 2.0);
        CHECK((weighted - expected).norm() < 1e-12 * expected.norm());
    }
}

TEST_CASE("the twisted bar's moving end is where a half turn puts it, and the bar follows", "[scenes]")
{
    const SceneSpec scene = read_scene(gallery / "twisted_bar.toml", {"body.material.model=corotational"}, true);
    const BodySpec& bar = scene.bodies[0];
    const RunResult run = run_positions(scene);
    // [quick] ends the turn at 0.25 s = the last frame: a half turn about the axis y = z = 0.
    const MatrixX3d& x = run.frames[0].back();
    int moved = 0;
    for (Eigen::Index v = 0; v < bar.mesh.V.rows(); ++v) {
        if (std::abs(bar.mesh.V(v, 0) - 0.2) > 1e-12)
            continue;
        ++moved;
        const Eigen::RowVector3d turned(bar.mesh.V(v, 0), -bar.mesh.V(v, 1), -bar.mesh.V(v, 2));
        CHECK((x.row(v) - turned).norm() < 1e-15);
    }
    CHECK(moved == 9);
    // The free middle of the bar turned by about a quarter turn with it (the bar twists evenly).
    const Eigen::Index middle = [&] {
        for (Eigen::Index v = 0; v < bar.mesh.V.rows(); ++v)
            if (std::abs(bar.mesh.V(v, 0) - 0.1) < 1e-12 && std::abs(bar.mesh.V(v, 1) - 0.02) < 1e-12 &&
                std::abs(bar.mesh.V(v, 2) - 0.02) < 1e-12)
                return v;
        return Eigen::Index(-1);
    }();
    REQUIRE(middle >= 0);
    const double angle = std::atan2(x(middle, 2), x(middle, 1)) - std::atan2(0.02, 0.02);
    CHECK(angle > 0.3 * std::acos(-1.0));
    CHECK(angle < 0.7 * std::acos(-1.0));
}

TEST_CASE("determinism: the same scene twice gives the same numbers to the last bit", "[scenes]")
{
    const SceneSpec scene = read_scene(gallery / "stiff_soft_pair.toml", {}, true);
    const RunResult first = run_positions(scene), second = run_positions(scene);
    REQUIRE(first.frames.size() == 2);
    for (std::size_t b = 0; b < 2; ++b)
        for (std::size_t f = 0; f < first.frames[b].size(); ++f)
            CHECK((first.frames[b][f].array() == second.frames[b][f].array()).all());
}

TEST_CASE("determinism: fem_scene with 1 and 2 threads writes identical frames and energies", "[scenes]")
{
    const std::filesystem::path base = output / "threads";
    std::filesystem::remove_all(base);
    for (int threads : {1, 2}) {
        const std::string command = "OMP_NUM_THREADS=" + std::to_string(threads) + " '" FEM_SCENE_EXE "' '" +
                                    (gallery / "stiff_soft_pair.toml").string() + "' --quick --no-figures --out '" +
                                    (base / std::to_string(threads)).string() + "' >/dev/null 2>&1";
        REQUIRE(std::system(command.c_str()) == 0);
    }
    int frames = 0;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(base / "1")) {
        if (entry.path().extension() != ".vtu" && entry.path().extension() != ".pvd")
            continue;
        ++frames;
        const std::filesystem::path twin = base / "2" / std::filesystem::relative(entry.path(), base / "1");
        CHECK(read_text(entry.path()) == read_text(twin));
    }
    CHECK(frames > 2);
    // steps.csv: every column but the measured step time.
    const auto without_time = [](const std::filesystem::path& path) {
        std::istringstream lines(read_text(path));
        std::string kept;
        for (std::string line; std::getline(lines, line);)
            kept += line.substr(0, line.rfind(',')) + '\n';
        return kept;
    };
    CHECK(without_time(base / "1" / "steps.csv") == without_time(base / "2" / "steps.csv"));
}

TEST_CASE("an interrupted run (SIGINT) leaves a valid .pvd of the frames written so far", "[scenes]")
{
    const std::filesystem::path out = output / "interrupted";
    std::filesystem::remove_all(out);
    const std::string scene = (gallery / "cantilever.toml").string();
    const pid_t child = start_scene({scene, "--no-figures", "--set", "time.duration=600", "--set",
                                     "body.material.model=stable-neo-hookean", "--out", out.string()});
    REQUIRE(child > 0);
    // Wait until the run is stepping: its first frames are in the staging folder.
    bool stepping = false;
    for (int poll = 0; poll < 600 && !stepping; ++poll) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        std::error_code ignored;
        for (const auto& entry : std::filesystem::directory_iterator(out, ignored))
            stepping = stepping || std::filesystem::exists(entry.path() / "cantilever" / "cantilever_0002.vtu");
    }
    REQUIRE(stepping);
    ::kill(child, SIGINT);
    int status = 0;
    ::waitpid(child, &status, 0);
    REQUIRE(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 130);
    const auto frames = io::read_pvd(out / "cantilever.pvd");
    CHECK(frames.size() >= 3);
    CHECK(frames.size() < 600 * 30);
    for (const auto& [time, file] : frames)
        CHECK(io::read_vtu(out / file).points.rows() > 0);
    CHECK(std::filesystem::exists(out / "steps.csv"));
}

TEST_CASE("fem_scene refuses bad scene files with one error line and writes nothing", "[scenes]")
{
    const std::filesystem::path bad = FEM_SCENE_BAD_DIR;
    for (const std::string file : {"missing.toml", "syntax.toml", "unknown_field.toml", "wrong_type.toml", "nu_half.toml",
                                   "dt_zero.toml", "no_tets.toml", "pins_nothing.toml", "tetgen_fails.toml", "skin.toml"}) {
        INFO(file);
        const std::filesystem::path out = output / "refused";
        std::filesystem::remove_all(out);
        const std::filesystem::path log = output / "refused.log";
        const std::string command = "'" FEM_SCENE_EXE "' '" + (bad / file).string() + "' --out '" + out.string() +
                                    "' >'" + log.string() + "' 2>&1";
        const int status = std::system(command.c_str());
        CHECK(WEXITSTATUS(status) == 1);
        CHECK(!std::filesystem::exists(out));
        const std::string printed = read_text(log);
        CHECK(printed.rfind("error: ", 0) == 0);
        if (file == "skin.toml")  // chapter 13's limit on vertices outside the tets, naming the skin
            CHECK((printed.find("flat_surface.obj") != std::string::npos &&
                   printed.find("outside the coarse mesh") != std::string::npos));
    }
}


TEST_CASE("PNG frames without a display: one note says they were skipped, even with no charts asked for", "[scenes]")
{
    // The frames are the only PNGs this run wants (charts = false): before, no chart asked whether it
    // could draw, so nothing said that the frames were skipped.
    const std::filesystem::path out = output / "no_display_frames";
    std::filesystem::remove_all(out);
    const std::filesystem::path log = output / "no_display_frames.log";
    const std::string command = "env -u DISPLAY '" FEM_SCENE_EXE "' '" + (gallery / "hanging_cube.toml").string() +
                                "' --quick --no-progress --set output.png=true --set output.charts=false --out '" +
                                out.string() + "' >'" + log.string() + "' 2>&1";
    CHECK(std::system(command.c_str()) == 0);
    const std::string printed = read_text(log);
    CHECK(printed.find("note: no X display, so the PNG figures were skipped") != std::string::npos);
    CHECK(std::filesystem::exists(out / "hanging_cube.pvd"));
    CHECK_FALSE(std::filesystem::exists(out / "hanging_cube_0000.png"));
}

TEST_CASE("the video: ffmpeg makes it from the PNG frames, or one line says it is missing", "[scenes]")
{
    if (std::getenv("DISPLAY") == nullptr) {
        WARN("SKIPPED: no X display, so no PNG frames to make a video of: run the tests under xvfb-run -a");
        return;
    }
    const std::string scene = (gallery / "cantilever.toml").string();
    for (bool with_ffmpeg : {true, false}) {
        if (with_ffmpeg && std::system("command -v ffmpeg >/dev/null 2>&1") != 0) {
            WARN("ffmpeg is not installed (tools/setup.sh installs it)");
            continue;
        }
        const std::filesystem::path out = output / (with_ffmpeg ? "video" : "no_video");
        std::filesystem::remove_all(out);
        const std::filesystem::path log = output / "video.log";
        // Without ffmpeg: a PATH that holds none (the runner needs no other program here).
        const std::string command = std::string(with_ffmpeg ? "" : "PATH=/nonexistent ") + "'" FEM_SCENE_EXE "' '" + scene +
                                    "' --quick --no-progress --set output.video=mp4 --set output.charts=false --out '" +
                                    out.string() + "' >'" + log.string() + "' 2>&1";
        CHECK(std::system(command.c_str()) == 0);
        const std::string printed = read_text(log);
        if (with_ffmpeg) {
            CHECK(printed.find("video: cantilever.mp4") != std::string::npos);
            const std::string mp4 = read_text(out / "cantilever.mp4");
            CHECK(mp4.size() > 1000);
            CHECK(mp4.substr(4, 4) == "ftyp");  // an MP4 container
        } else {
            CHECK(printed.find("video: skipped, ffmpeg is not installed") != std::string::npos);
            CHECK(!std::filesystem::exists(out / "cantilever.mp4"));
            CHECK(std::filesystem::exists(out / "cantilever_0003.png"));
        }
    }
}

TEST_CASE("a skin: the bunny's surface in its body's coordinates, carrying an affine motion exactly", "[scenes]")
{
    const SceneSpec scene = read_scene(gallery / "skinned_bunny.toml", {}, true);
    REQUIRE(scene.skin.has_value());
    const BodySpec& body = scene.bodies.front();
    const std::unique_ptr<SkinObserver> skin = make_skin_observer(*scene.skin, body);
    // An affine motion of the coarse tets, x = A X + b: every skin vertex must move by the same map
    // (barycentric weights reproduce affine maps, inside the tets and by the outside rule alike).
    Eigen::Matrix3d A;
    A << 1.02, 0.1, 0.0, -0.05, 0.97, 0.03, 0.0, 0.2, 1.01;
    const Eigen::Vector3d b(0.01, -0.02, 0.005);
    const MatrixX3d X = body.mesh.V;
    Eigen::VectorXd u(3 * X.rows());
    for (Eigen::Index v = 0; v < X.rows(); ++v)
        u.segment<3>(3 * v) = A * X.row(v).transpose() + b - X.row(v).transpose();
    const io::MeshData frame = skin->frame(u);
    const TriMesh surface = io::read_tri_mesh(std::filesystem::path(FEM_SCENES_DIR) / ".." / "data" / "bunny.obj");
    REQUIRE(frame.points.rows() == surface.V.rows());
    CHECK((frame.points - 0.01 * surface.V).cwiseAbs().maxCoeff() <= 1e-15);  // the body's scale applies
    const Eigen::MatrixXd& displacement = frame.field("displacement").values;
    double largest = 0.0;
    for (Eigen::Index s = 0; s < frame.points.rows(); ++s) {
        const Eigen::Vector3d Xs = frame.points.row(s).transpose();
        largest = std::max(largest, (displacement.row(s).transpose() - (A * Xs + b - Xs)).norm());
    }
    CHECK(largest <= 1e-14);  // round-off of metres-sized products
    // The runner writes the skin's .vtp series beside the tets', one skin frame for each.
    const std::filesystem::path out = output / "skinned";
    std::filesystem::remove_all(out);
    const std::string command = "'" FEM_SCENE_EXE "' '" + (gallery / "skinned_bunny.toml").string() +
                                "' --quick --no-figures --out '" + out.string() + "' >/dev/null 2>&1";
    REQUIRE(std::system(command.c_str()) == 0);
    const auto skin_frames = io::read_pvd(out / "skinned_bunny_skin.pvd");
    CHECK(skin_frames.size() == io::read_pvd(out / "skinned_bunny.pvd").size());
    CHECK(skin_frames.size() >= 2);
}
