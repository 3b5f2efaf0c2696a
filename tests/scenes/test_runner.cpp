// The runner: loads and prescribed motion against closed forms, determinism, an interrupted run,
// and bad scene files refused by fem_scene before it writes anything. docs/scenes.md#the-runner
#include "scenes/runner.hpp"
#include "scenes/scene_text.hpp"

#include "06_assembly/assembly.hpp"

#include "common/error.hpp"
#include "common/mesh_io.hpp"
#include "common/vtk_io.hpp"

#include <catch2/catch.hpp>

#include <X11/Xlib.h>
#include <X11/extensions/XTest.h>
#include <X11/keysym.h>

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace fem;
using namespace fem::scenes;
using testing::gallery;
using testing::output;

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

/// Starts fem_scene with these arguments in a child process; returns its id. Its output is discarded,
/// or, given output_fd, its standard output goes to a pipe whose reading end is stored there.
pid_t start_scene(const std::vector<std::string>& arguments, int* output_fd = nullptr)
{
    int pipe_ends[2] = {-1, -1};
    if (output_fd != nullptr && ::pipe(pipe_ends) != 0)
        return -1;
    const pid_t child = ::fork();
    if (child == 0) {
        std::freopen("/dev/null", "w", stdout);
        std::freopen("/dev/null", "w", stderr);
        if (output_fd != nullptr) {
            ::dup2(pipe_ends[1], STDOUT_FILENO);
            ::close(pipe_ends[0]);
            ::close(pipe_ends[1]);
        }
        std::vector<char*> argv{const_cast<char*>(FEM_SCENE_EXE)};
        for (const std::string& argument : arguments)
            argv.push_back(const_cast<char*>(argument.c_str()));
        argv.push_back(nullptr);
        ::execv(FEM_SCENE_EXE, argv.data());
        std::_Exit(127);
    }
    if (output_fd != nullptr) {
        ::close(pipe_ends[1]);
        *output_fd = pipe_ends[0];
    }
    return child;
}

std::string read_text(const std::filesystem::path& path)
{
    std::ifstream file(path, std::ios::binary);
    std::ostringstream text;
    text << file.rdbuf();
    return text.str();
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

TEST_CASE("the live view shows the PNG frame of the same step, pixel for pixel", "[scenes]")
{
    if (std::getenv("DISPLAY") == nullptr) {
        WARN("SKIPPED: no X display: run the tests under xvfb-run -a to check the live view");
        return;
    }
    // The cantilever, and the bunny dropped on a floor: its obstacle and the caption (scene, model,
    // time, slow motion) drawn alike by both paths. Each scene fixes the camera's box and the colour
    // range, so that the live view, which cannot know the run's, draws exactly what the PNGs do.
    struct Case {
        std::string scene, settings, png;
        int step;
    };
    const std::string bunny_box = "--set 'output.frame_box=[[-0.1, -0.01, -0.08], [0.08, 0.11, 0.08]]' "
                                  "--set 'output.colour_range=[0.0, 2000.0]' --set output.png=true";
    // [quick]: cantilever 12 frames per second at dt = 1/60 s, a frame every 5 steps: step 5 is frame
    // 1; bunny_drop 25 frames per second at dt = 1/100 s, every 4 steps: step 8 is frame 2.
    for (const Case& c : {Case{"cantilever", "", "cantilever_0001.png", 5},
                          Case{"bunny_drop", bunny_box, "bunny_drop_0002.png", 8}}) {
        CAPTURE(c.scene);
        const std::filesystem::path base = output / ("view_" + c.scene);
        std::filesystem::remove_all(base);
        const std::string scene = (gallery / (c.scene + ".toml")).string();
        const std::string files = "'" FEM_SCENE_EXE "' '" + scene + "' --quick --no-progress " + c.settings + " --out '" +
                                  (base / "files").string() + "' >/dev/null 2>&1";
        const std::string view = "'" FEM_SCENE_EXE "' '" + scene + "' --quick --no-progress " + c.settings +
                                 " --view --screenshot " + std::to_string(c.step) + " --out '" + (base / "view").string() +
                                 "' >/dev/null 2>&1";
        REQUIRE(std::system(files.c_str()) == 0);
        REQUIRE(std::system(view.c_str()) == 0);
        const std::string png = read_text(base / "files" / c.png);
        REQUIRE(png.size() > 1000);
        CHECK(read_text(base / "view" / ("view_" + std::to_string(c.step) + ".png")) == png);
        CHECK(read_text(base / "view" / (c.scene + "_0000.png")) != png);  // another step is another picture
    }
}

TEST_CASE("the live view without a display: one line says so and the run goes on headless", "[scenes]")
{
    const std::filesystem::path out = output / "headless";
    std::filesystem::remove_all(out);
    const std::filesystem::path log = output / "headless.log";
    const std::string command = "env -u DISPLAY '" FEM_SCENE_EXE "' '" + (gallery / "hanging_cube.toml").string() +
                                "' --quick --view --no-progress --out '" + out.string() + "' >'" + log.string() + "' 2>&1";
    CHECK(std::system(command.c_str()) == 0);
    const std::string printed = read_text(log);
    CHECK(printed.find("note: no display for --view (set DISPLAY); the run goes on headless") != std::string::npos);
    CHECK(std::filesystem::exists(out / "hanging_cube.pvd"));
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

namespace {

/// The top-level window whose name starts with prefix, searched from root (0: none).
Window find_window(Display* display, Window root, const std::string& prefix)
{
    char* name = nullptr;
    if (XFetchName(display, root, &name) && name != nullptr) {
        const bool found = std::string(name).rfind(prefix, 0) == 0;
        XFree(name);
        if (found)
            return root;
    }
    Window parent = 0, *children = nullptr;
    unsigned int count = 0;
    Window found = 0;
    if (XQueryTree(display, root, &root, &parent, &children, &count)) {
        for (unsigned int i = 0; i < count && found == 0; ++i)
            found = find_window(display, children[i], prefix);
        if (children != nullptr)
            XFree(children);
    }
    return found;
}

/// Sends a key press (an X key symbol, e.g. XK_space) to a window, as a user would.
void press(Display* display, Window window, KeySym key)
{
    XKeyEvent event{};
    event.type = KeyPress;
    event.display = display;
    event.window = window;
    event.root = DefaultRootWindow(display);
    event.same_screen = True;
    event.keycode = XKeysymToKeycode(display, key);
    XSendEvent(display, window, True, KeyPressMask, reinterpret_cast<XEvent*>(&event));
    event.type = KeyRelease;
    XSendEvent(display, window, True, KeyReleaseMask, reinterpret_cast<XEvent*>(&event));
    XFlush(display);
}

/// The .vtu frames a running fem_scene has written so far into its staging folder.
int frames_so_far(const std::filesystem::path& out, const std::string& stem)
{
    int count = 0;
    std::error_code ignored;
    for (const auto& staging : std::filesystem::directory_iterator(out, ignored))
        for (const auto& frame : std::filesystem::directory_iterator(staging.path() / stem, ignored))
            count += frame.path().extension() == ".vtu";
    return count;
}

/// The lines a running process prints on a pipe, read as they come.
class LineReader {
public:
    explicit LineReader(int fd) : fd_(fd) {}
    ~LineReader() { ::close(fd_); }
    LineReader(const LineReader&) = delete;
    LineReader& operator=(const LineReader&) = delete;

    /// Reads lines until one that starts with prefix and returns it; "" when the output ends or none
    /// came within timeout_seconds (ample on a loaded machine: "" means the line never comes).
    std::string wait_for(const std::string& prefix, double timeout_seconds = 120.0)
    {
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_seconds);
        for (;;) {
            for (std::size_t end; (end = buffer_.find('\n')) != std::string::npos;) {
                std::string line = buffer_.substr(0, end);
                buffer_.erase(0, end + 1);
                if (line.rfind(prefix, 0) == 0)
                    return line;
            }
            const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
            pollfd readable{fd_, POLLIN, 0};
            if (left.count() <= 0 || ::poll(&readable, 1, static_cast<int>(left.count())) <= 0)
                return "";
            char chunk[4096];
            const ssize_t count = ::read(fd_, chunk, sizeof chunk);
            if (count <= 0)
                return "";
            buffer_.append(chunk, static_cast<std::size_t>(count));
        }
    }

private:
    int fd_;
    std::string buffer_;
};

/// A fem_scene started by a test: waited for, or killed when the test ends first (a failed REQUIRE
/// leaves no window running its 600 s).
struct RunningScene {
    pid_t child;
    bool reaped = false;
    ~RunningScene()
    {
        if (!reaped) {
            ::kill(child, SIGKILL);
            ::waitpid(child, nullptr, 0);
        }
    }
    /// Waits for it to end; its waitpid status.
    int wait()
    {
        int status = 0;
        ::waitpid(child, &status, 0);
        reaped = true;
        return status;
    }
};

}  // namespace

// Deterministic: after each key the test waits for the line fem_scene prints once it has handled
// it (paused at step ..., resumed, restarted), not for a time, before it counts the frames written.
TEST_CASE("the live view's keys: space pauses, the right arrow steps, space resumes, r restarts, q stops", "[scenes]")
{
    Display* display = std::getenv("DISPLAY") ? XOpenDisplay(nullptr) : nullptr;
    if (display == nullptr) {
        WARN("SKIPPED: no X display: run the tests under xvfb-run -a to check the live view's keys");
        return;
    }
    const std::filesystem::path out = output / "keys";
    std::filesystem::remove_all(out);
    const std::string scene = (gallery / "cantilever.toml").string();
    // A title of its own: ctest runs another test's live view (same scene) on the same display at
    // times, and the keys must go to this run's window.
    const std::string title = "live_view_keys_" + std::to_string(::getpid());
    int output_fd = -1;
    const pid_t child = start_scene({scene, "--quick", "--view", "--no-figures", "--no-progress", "--set", "time.duration=600",
                                     "--set", "title=" + title, "--out", out.string()}, &output_fd);
    REQUIRE(child > 0);
    LineReader printed(output_fd);
    RunningScene running{child};
    Window window = 0;
    for (int poll = 0; poll < 1200 && (window == 0 || frames_so_far(out, "cantilever") < 3); ++poll) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        if (window == 0)
            window = find_window(display, DefaultRootWindow(display), "fem_scene: " + title);
    }
    REQUIRE(window != 0);
    press(display, window, XK_space);  // pause: the frame shown is the last one written
    REQUIRE(printed.wait_for("paused at step ") != "");
    const int paused = frames_so_far(out, "cantilever");
    std::this_thread::sleep_for(std::chrono::milliseconds(1000));
    CHECK(frames_so_far(out, "cantilever") == paused);
    press(display, window, XK_Right);  // one frame on, still paused
    REQUIRE(printed.wait_for("paused at step ") != "");
    CHECK(frames_so_far(out, "cantilever") == paused + 1);
    press(display, window, XK_c);  // another colour field: the run goes on drawing
    press(display, window, XK_space);  // resume: 12 frames a second
    REQUIRE(printed.wait_for("resumed") != "");
    for (int poll = 0; poll < 2400 && frames_so_far(out, "cantilever") < paused + 8; ++poll)
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    CHECK(frames_so_far(out, "cantilever") >= paused + 8);
    // r: the run starts over, its frames so far dropped. Pressed while paused: the pause holds, so the
    // restarted run waits at its first frame, and what it wrote can be counted.
    press(display, window, XK_space);
    REQUIRE(printed.wait_for("paused at step ") != "");
    const int before_restart = frames_so_far(out, "cantilever");
    CHECK(before_restart >= paused + 8);
    press(display, window, XK_r);
    REQUIRE(printed.wait_for("restarted") != "");
    CHECK(printed.wait_for("paused at step ") == "paused at step 0 (t = 0 s)");
    CHECK(frames_so_far(out, "cantilever") == 1);
    press(display, window, XK_q);  // stop, as Ctrl-C does
    const int status = running.wait();
    XCloseDisplay(display);
    REQUIRE(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 130);
    const auto frames = io::read_pvd(out / "cantilever.pvd");
    REQUIRE(frames.size() == 1);  // the restarted run's first frame, not those before the restart
    CHECK(frames.front().first == 0.0);
}

namespace {

/// Moves the pointer to pixel (x, y) of a window (from its top left), then, for type ButtonPress or
/// ButtonRelease, presses or releases the left button there (MotionNotify: only the move): real input
/// through the X server's XTEST extension, as a user's hand gives it. The window is raised first, so
/// that no other test's window on the same display takes the events.
void pointer(Display* display, Window window, int type, int x, int y)
{
    XRaiseWindow(display, window);
    int root_x = 0, root_y = 0;
    Window child = 0;
    XTranslateCoordinates(display, window, DefaultRootWindow(display), x, y, &root_x, &root_y, &child);
    XTestFakeMotionEvent(display, -1, root_x, root_y, CurrentTime);
    if (type != MotionNotify)
        XTestFakeButtonEvent(display, Button1, type == ButtonPress ? True : False, CurrentTime);
    XFlush(display);
}

/// A PNG's pixels: rgb(x, y) from the top left, each channel 0 … 255.
struct Picture {
    int width = 0, height = 0;
    vtkSmartPointer<vtkDataArray> pixels;
    std::array<double, 3> rgb(int x, int y) const
    {
        const vtkIdType i = static_cast<vtkIdType>(height - 1 - y) * width + x;  // VTK's rows start at the bottom
        return {pixels->GetComponent(i, 0), pixels->GetComponent(i, 1), pixels->GetComponent(i, 2)};
    }
};

Picture read_picture(const std::filesystem::path& png)
{
    vtkNew<vtkPNGReader> reader;
    reader->SetFileName(png.string().c_str());
    reader->Update();
    int size[3];
    reader->GetOutput()->GetDimensions(size);
    return {size[0], size[1], reader->GetOutput()->GetPointData()->GetScalars()};
}

/// The centre of the body's coloured pixels in a picture of the live view (x, y from the top
/// left): the pixels that are neither white, grey nor black, left of the colour bar.
std::pair<int, int> body_centre(const std::filesystem::path& png)
{
    const Picture picture = read_picture(png);
    double sum_x = 0.0, sum_y = 0.0, count = 0.0;
    for (int y = 0; y < picture.height; ++y)
        for (int x = 0; x < picture.width * 3 / 4; ++x) {
            const auto [r, g, b] = picture.rgb(x, y);
            if (std::max({r, g, b}) - std::min({r, g, b}) > 40.0) {
                sum_x += x;
                sum_y += y;
                count += 1.0;
            }
        }
    REQUIRE(count > 100.0);
    return {static_cast<int>(sum_x / count), static_cast<int>(sum_y / count)};
}

/// The red pixels (the pull's spring) in a picture, red above 120, green and blue below 80: how
/// many, and in how many rows (a near-vertical spring's length in pixels).
std::pair<int, int> red_pixels(const std::filesystem::path& png)
{
    const Picture picture = read_picture(png);
    int count = 0, rows = 0;
    for (int y = 0; y < picture.height; ++y) {
        int in_row = 0;
        for (int x = 0; x < picture.width; ++x) {
            const auto [r, g, b] = picture.rgb(x, y);
            in_row += r > 120.0 && g < 80.0 && b < 80.0 ? 1 : 0;
        }
        count += in_row;
        rows += in_row > 0 ? 1 : 0;
    }
    return {count, rows};
}

/// The first file of this name in the staging folders of a running fem_scene's --out.
std::filesystem::path staged(const std::filesystem::path& out, const std::string& name)
{
    std::error_code ignored;
    for (const auto& staging : std::filesystem::directory_iterator(out, ignored))
        if (std::filesystem::exists(staging.path() / name))
            return staging.path() / name;
    return {};
}

}  // namespace

// Deterministic as the keys' test: after each mouse event it waits for the line fem_scene prints.
TEST_CASE("the live view's mouse: pressing on the body pulls it toward the pointer, its work booked, until released",
          "[scenes]")
{
    Display* display = std::getenv("DISPLAY") ? XOpenDisplay(nullptr) : nullptr;
    if (display == nullptr) {
        WARN("SKIPPED: no X display: run the tests under xvfb-run -a to check the live view's mouse");
        return;
    }
    const std::filesystem::path out = output / "pull";
    std::filesystem::remove_all(out);
    // The title finds the window, and is the caption of the pull's picture (docs/scenes.md).
    const std::string title = "The cantilever pulled by the mouse";
    int output_fd = -1;
    // At rest until pulled (no gravity), so that the body stays where the first frame's picture shows
    // it; corotational throughout: auto's switches would book work of their own. The second
    // picture, at step 90 (frame 18 of 5 steps each), is taken while the button is held: the
    // pointer is pressed at frame 3 or so and held until that picture is written.
    const int pulled_step = 90;
    const pid_t child = start_scene({(gallery / "cantilever.toml").string(), "--quick", "--view", "--no-figures",
                                     "--no-progress", "--set", "time.duration=600", "--set", "title=\"" + title + "\"",
                                     "--set", "body.material.model=corotational", "--set", "gravity=[0.0, 0.0, 0.0]",
                                     "--screenshot", "0", "--screenshot", std::to_string(pulled_step), "--out",
                                     out.string()},
                                    &output_fd);
    REQUIRE(child > 0);
    LineReader printed(output_fd);
    RunningScene running{child};
    Window window = 0;
    std::filesystem::path picture;
    for (int poll = 0; poll < 1200 && (window == 0 || picture.empty() || frames_so_far(out, "cantilever") < 3); ++poll) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        if (window == 0)
            window = find_window(display, DefaultRootWindow(display), "fem_scene: " + title);
        if (picture.empty())
            picture = staged(out, "view_0.png");
    }
    REQUIRE(window != 0);
    REQUIRE(!picture.empty());
    const auto [centre_x, y] = body_centre(picture);
    const int x = centre_x + 150;  // near the free end (the beam is 430 pixels long here, pinned on the left)
    pointer(display, window, ButtonPress, x, y);
    pointer(display, window, MotionNotify, x, y + 150);  // down, in the view
    const std::string pulling = printed.wait_for("pulling vertex ");
    CHECK(pulling.find("of body 'beam'") != std::string::npos);
    const int frames = frames_so_far(out, "cantilever");
    CHECK(frames < pulled_step / 5);  // pulling before the second picture
    std::filesystem::path pulled;
    for (int poll = 0; poll < 2400 && (frames_so_far(out, "cantilever") < frames + 12 || pulled.empty()); ++poll) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        pulled = staged(out, "view_" + std::to_string(pulled_step) + ".png");
    }
    REQUIRE(!pulled.empty());
    const int written = frames_so_far(out, "cantilever");  // the next frame: the picture is closed by then
    for (int poll = 0; poll < 2400 && frames_so_far(out, "cantilever") < written + 1; ++poll)
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    // The spring is drawn plain to see: a red rod and a ball at the vertex, more than 2.5 red pixels
    // a row on average over the rows it crosses (a line of one pixel: about 1), and over 60 rows
    // long; the picture before the pull has none.
    CHECK(red_pixels(picture).first == 0);
    const auto [red, rows] = red_pixels(pulled);
    CHECK(rows > 60);
    CHECK(red > 2.5 * rows);
    pointer(display, window, ButtonRelease, x, y + 150);
    const std::string released = printed.wait_for("released vertex ");
    CHECK(released != "");
    press(display, window, XK_q);
    const int status = running.wait();
    XCloseDisplay(display);
    REQUIRE(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 130);
    // The pull put work in (steps.csv's "work in (J)", the 8th column), which nothing else here does.
    std::ifstream steps(out / "steps.csv");
    std::string line, last;
    while (std::getline(steps, line))
        last = line;
    std::stringstream fields(last);
    std::string field;
    for (int column = 0; column < 8; ++column)
        std::getline(fields, field, ',');
    CHECK(std::stod(field) > 0.0);
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
