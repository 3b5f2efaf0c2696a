// fem_scene: runs a scene file (scenes/*.toml) with chapters 10–14 — a body, its material and
// model, what is pinned and how it moves, what pushes, for how long — and writes a .pvd time series,
// PNG frames, a video, the energies and the cost of each step. Read chapters 10–12 first (13 and 14
// for skins and obstacles).
//
// Sample runs:
//   fem_scene scenes/cantilever.toml                       the scene as written
//   fem_scene scenes/cantilever.toml --quick               the small run ctest checks
//   fem_scene scenes/twisted_bar.toml --set body.material.model=auto --set time.step=1/120
//   fem_scene scenes/bunny.toml --compare                  every model against the reference
//
// Writes (under out/scenes/<scene>): <scene>.pvd with <scene>/<scene>_NNNN.vtu frames, PNG frames
// <scene>_NNNN.png and <scene>.mp4 (ffmpeg), steps.csv with the charts energies, step_time and
// newton_iterations; with --html, <scene>.html (a web page that plays the run); with --compare,
// models.csv. docs/scenes.md
#include "scenes/compare.hpp"
#include "scenes/live_view.hpp"
#include "scenes/runner.hpp"
#include "scenes/web_page.hpp"

#include "09_conjugate_gradient/linear_solver.hpp"

#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/parallel.hpp"
#include "common/interrupt.hpp"

#include <csignal>
#include <iostream>
#include <map>
#include <memory>

using namespace fem;
using namespace fem::scenes;

namespace {

/// The default --out: out/scenes/<scene> for one scene file (an argument ending in .toml),
/// out/scenes/compare for several.
std::string default_out(int argc, char** argv)
{
    std::vector<std::string> stems;
    for (int i = 1; i < argc; ++i) {
        const std::filesystem::path arg(argv[i]);
        if (arg.extension() == ".toml")
            stems.push_back(arg.stem().string());
    }
    return "scenes/" + (stems.size() == 1 ? stems.front() : stems.empty() ? std::string("scene") : std::string("compare"));
}

}  // namespace

int main(int argc, char** argv)
{
    ChapterCli cli("fem_scene", default_out(argc, argv),
                   "Runs a scene file with the cheapest model that is accurate enough (docs/scenes.md)");
    std::vector<std::string> files;
    std::vector<std::string> settings;
    bool compare = false, no_progress = false, html = false;
    cli.app.add_option("scene", files, "The scene file (TOML), e.g. scenes/cantilever.toml; several with --compare")
        ->required();
    cli.app.add_option("--set", settings,
                       "Override a field: key=value in TOML syntax, e.g. body.material.model=auto, time.step=1/120, "
                       "body.0.material.youngs_modulus=2e5 (no index: every body)")
        ->allow_extra_args(false)  // one key=value per --set (a scene file after it stays the scene)
        ->take_all();              // and every --set kept
    cli.app.add_flag("--compare", compare,
                     "Run every model and auto against the stable neo-Hookean reference and print the table (models_<scene>.csv)");
    cli.app.add_flag("--html", html,
                     "Also write <scene>.html: one self-contained web page that plays the run (as output.html = true)");
    cli.app.add_flag("--no-progress", no_progress, "No progress bar on stderr (it shows only on a terminal anyway)");
    bool check_path = false;
    cli.app.add_flag("--check-path", check_path,
                     "Debug: prove every segment of every step's path between bodies free of crossings with a second "
                     "CCD (as [contact] check_path = true); stops at the first crossing, naming it");
    bool view = false;
    std::vector<int> screenshots;
    cli.app.add_flag("--view", view,
                     "Play the run live in a window (space: pause, right arrow: step, r: restart, c: colour field, "
                     "q: stop; press the mouse on the body and drag to pull it); without a display the run goes on "
                     "headless");
    bool forever = false;
    cli.app.add_flag("--forever", forever,
                     "With --view: run until q, past the scene's duration, writing no files (for a lecture)");
    double pull_stiffness = 0.0;
    cli.app.add_option("--pull-stiffness", pull_stiffness,
                       "With --view: the mouse's spring stiffness [N/m] (0: the body's mass x (2 pi 1 Hz)^2)")
        ->check(check::real(0.0, 1e9, check::Ends::closed))->capture_default_str();
    cli.app.add_option("--screenshot", screenshots,
                       "With --view: save the window at this step as view_<step>.png in --out (repeatable)")
        ->check(check::at_least<int>(0));
    std::vector<SceneSpec> scenes;
    std::shared_ptr<const SkinObserver> skin;  // the run's (the first scene's), bound once
    // Every scene is read and checked before the output folder is touched.
    cli.check_options([&] {
        bool quick = false;
        for (int i = 1; i < argc; ++i)
            quick = quick || std::string(argv[i]) == "--quick";
        if (files.size() > 1 && !compare)
            throw Error(str("scene: give one scene file, or several with --compare (got ", files.size(), ")"));
        if (!screenshots.empty() && !view)
            throw Error("--screenshot: needs --view");
        if (view && compare)
            throw Error("--view: plays one run; --compare runs many without frames");
        if (forever && !view)
            throw Error("--forever: needs --view (it runs until the window's q)");
        if (html && forever)
            throw Error("--html: writes a file, and --forever writes none");
        if (forever && !fig::display_available())
            throw Error("--forever: needs a display for --view (set DISPLAY, or run under xvfb-run -a): it runs "
                        "until the window's q");
        if (forever && !screenshots.empty())
            throw Error("--screenshot: writes a file, and --forever writes none");
        if (cli.app.count("--pull-stiffness") > 0 && !view)
            throw Error("--pull-stiffness: needs --view (the mouse pulls in the live view)");
        if (html && compare)
            throw Error("--html: writes the page of one run; --compare runs many without frames");
        for (const std::string& file : files) {
            scenes.push_back(read_scene(file, settings, quick));
            scenes.back().output.html = scenes.back().output.html || html;
            scenes.back().contact.check_path = scenes.back().contact.check_path || check_path;
            if (scenes.back().contact.check_path && !bodies_meet(scenes.back()))
                throw Error(str(file, ": --check-path (or [contact] check_path) checks the pairs between bodies and of a ",
                                "body against itself, and this scene has none: set [contact] bodies = true with two or ",
                                "more bodies, or a body's self_contact = true"));
            if (scenes.back().output.html && !compare) {
                check_web_page_library();
                cli.writes_entry(scenes.back().file.stem().string() + ".html");
            }
            cli.protect_inputs(input_files(scenes.back()));  // --out must not overlap what is read
            if (!compare)  // the frames folder <scene>/ must not replace a folder of someone else's
                cli.writes_entry(scenes.back().file.stem().string());
            if (const SceneSpec& scene = scenes.back(); scene.skin) {
                std::shared_ptr<const SkinObserver> bound = make_skin_observer(*scene.skin, scene.bodies[skin_body(scene)]);
                if (scenes.size() == 1)
                    skin = std::move(bound);  // refused before anything runs; kept for the run
            }
        }
    });
    bool stopped = false;
    const int code = cli.run(argc, argv, [&](const RunContext& run) {
        set_blas_threads(1);
        catch_stop_signals();  // a stop signal ends a run or a comparison after its current step
        for (const SceneSpec& scene : scenes) {
            std::cout << scene.title << " (" << scene.file.filename().string() << "): " << scene.bodies.size()
                      << " bodies, dt = " << scene.time_step << " s, " << scene.duration << " s, solver " << scene.solver
                      << "\n";
            for (const BodySpec& body : scene.bodies)
                std::cout << "  " << body.name << ": " << body.mesh.V.rows() << " vertices, " << body.mesh.T.rows()
                          << " tets, " << body.pinned.size() << " pinned, model " << body.model << '\n';
            if (compare)
                compare_models(scene, &run);
        }
        if (compare) {
            stopped = stop_requested();
            return;
        }
        RunOptions options;
        options.run = forever ? nullptr : &run;  // --forever: a lecture's live run, no files
        options.forever = forever;
        options.progress = !no_progress && !forever;
        options.skin = skin;
        std::unique_ptr<LiveView> live;
        if (view && fig::display_available()) {
            std::map<int, std::filesystem::path> pictures;
            for (const int step : screenshots)
                pictures[step] = run.file(str("view_", step, ".png"));
            live = std::make_unique<LiveView>(scenes.front(), pictures);
            options.on_frame = [&](const io::MeshData& frame, int step, double time, const std::string& models) {
                live->frame(frame, step, time, models);
            };
            options.pull = [&] { return live->pull(); };
            options.pull_stiffness = pull_stiffness;
        } else if (view) {
            std::cout << "note: no display for --view (set DISPLAY); the run goes on headless\n";
        }
        RunResult result;
        for (;;) {
            try {
                result = run_scene(scenes.front(), options);
                break;
            } catch (const LiveView::Restart&) {  // the live view's r: the run starts over
                std::cout << "restarted" << std::endl;  // flushed: a script driving the window waits for it
                std::filesystem::remove_all(run.file(scenes.front().file.stem().string()));
            }
        }
        std::cout << result.steps << " steps in " << result.seconds << " s ("
                  << (result.steps > 0 ? 1e3 * result.seconds / result.steps : 0.0) << " ms per step), "
                  << result.frame_count << " frames, " << result.newton_iterations << " Newton iterations\n";
        if (scenes.front().contact.check_path)
            std::cout << "path check: " << result.path_segments << " segments of the steps' paths proven free of "
                      << "crossings (" << result.path_pair_tests << " primitive pair tests)\n";
        stopped = result.interrupted;
    });
    // Stopped: the files so far were published (a valid .pvd); the exit code says by what (128 +
    // the signal, as a shell expects; the live view's q counts as Ctrl-C).
    return code == 0 && stopped ? 128 + (stop_signal() != 0 ? stop_signal() : SIGINT) : code;
}
