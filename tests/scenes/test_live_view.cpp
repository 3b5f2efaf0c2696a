// The live view of --view (live_view.hpp): the same picture as the PNG frame of the same step, the
// run going on headless without a display, and its keys and mouse driven through the X server as a
// user's hand drives them. Run under xvfb-run -a (without a display each test says it skipped).
// docs/scenes.md#the-live-view
#include "scenes/scene_process.hpp"
#include "scenes/scene_text.hpp"

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
#include <thread>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace fem;
using namespace fem::scenes;
using testing::gallery;
using testing::output;
using testing::read_text;
using testing::start_scene;

TEST_CASE("the live view shows the PNG frame of the same step, pixel for pixel", "[scenes][slow]")
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

TEST_CASE("the live view frames the body at the start: the coarse bunny fills 40 % of the window's height, uncut",
          "[scenes]")
{
    if (std::getenv("DISPLAY") == nullptr) {
        WARN("SKIPPED: no X display: run the tests under xvfb-run -a to check the live view");
        return;
    }
    // bunny.toml fixes no camera box: the window frames the body as drawn so far, grown by a tenth of
    // its size (it framed the rest shape grown by half its size each way before, and the bunny spanned
    // 156 of the 720 rows).
    const std::filesystem::path out = output / "view_framing";
    std::filesystem::remove_all(out);
    const std::string view = "'" FEM_SCENE_EXE "' '" + (gallery / "bunny.toml").string() +
                             "' --quick --no-progress --no-figures --view --screenshot 0 --out '" + out.string() +
                             "' >/dev/null 2>&1";
    REQUIRE(std::system(view.c_str()) == 0);
    const Picture picture = read_picture(out / "view_0.png");
    int top = picture.height, bottom = -1;
    for (int y = 0; y < picture.height; ++y)
        for (int x = 0; x < picture.width * 3 / 4; ++x) {
            const auto [r, g, b] = picture.rgb(x, y);
            if (std::max({r, g, b}) - std::min({r, g, b}) > 40.0) {
                top = std::min(top, y);
                bottom = std::max(bottom, y);
            }
        }
    CAPTURE(top, bottom, picture.height);
    CHECK(bottom - top > 0.4 * picture.height);
    CHECK(top > 0);
    CHECK(bottom < picture.height - 1);
}
