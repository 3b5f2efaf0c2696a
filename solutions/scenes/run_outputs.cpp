// The history of a run and its charts, the video, merged frames, the progress bar.
// docs/scenes.md#outputs
#include "scenes/run_outputs.hpp"

#include "common/error.hpp"
#include "common/figures.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <unistd.h>

namespace fem::scenes {

io::MeshData merged_frame(const std::vector<io::MeshData>& parts, const OutputSpec& output)
{
    const auto wanted = [&](const std::string& name) {
        return name == io::displacement_field ||
               std::find(output.fields.begin(), output.fields.end(), name) != output.fields.end();
    };
    io::MeshData merged;
    Eigen::Index points = 0, cells = 0;
    for (const io::MeshData& part : parts) {
        points += part.points.rows();
        cells += part.cells.rows();
    }
    merged.points.resize(points, 3);
    merged.cells.resize(cells, 4);
    Eigen::Index p = 0, c = 0;
    for (const io::MeshData& part : parts) {
        merged.points.middleRows(p, part.points.rows()) = part.points;
        merged.cells.middleRows(c, part.cells.rows()) = part.cells.array() + static_cast<int>(p);
        p += part.points.rows();
        c += part.cells.rows();
    }
    const auto concat = [&](bool point_fields) {
        std::vector<io::Field> out;
        for (const io::Field& first : point_fields ? parts.front().point_data : parts.front().cell_data) {
            if (!wanted(first.name))
                continue;
            io::Field field{first.name, Eigen::MatrixXd(point_fields ? points : cells, first.values.cols())};
            Eigen::Index row = 0;
            for (const io::MeshData& part : parts) {
                const io::Field& own = part.field(first.name);
                field.values.middleRows(row, own.values.rows()) = own.values;
                row += own.values.rows();
            }
            out.push_back(std::move(field));
        }
        return out;
    };
    merged.point_data = concat(true);
    merged.cell_data = concat(false);
    return merged;
}

namespace {

// The columns of steps.csv, in order.
enum Column { step, time, body, model, kinetic, elastic, load_potential, work_in, damping, integrator, balance, newton,
              solver, step_time };

}  // namespace

StepHistory::StepHistory()
    : table_("Steps", {{"step", Format::integer}, {"time (s)", Format::fixed, 4}, {"body", Format::text},
                       {"model", Format::text}, {"kinetic (J)", Format::scientific, 6},
                       {"elastic (J)", Format::scientific, 6}, {"load potential (J)", Format::scientific, 6},
                       {"work in (J)", Format::scientific, 6}, {"damping dissipated (J)", Format::scientific, 6},
                       {"integrator dissipated (J)", Format::scientific, 6},
                       {"balance H - W_in (J)", Format::scientific, 6}, {"Newton iterations", Format::integer},
                       {"solver iterations", Format::integer}, {"step time [s]", Format::scientific, 2}})
{
}

void StepHistory::add(const std::string& body_name, const std::string& model_name, const dynamics::StepRecord& r)
{
    table_.add_row({double(r.step), r.time, body_name, model_name, r.energies.kinetic, r.energies.elastic,
                    r.energies.gravitational, r.work_in, r.damping_dissipated, r.integrator_dissipated,
                    r.energies.total() - r.work_in, double(r.newton_iterations), double(r.solver_iterations), r.seconds});
}

void StepHistory::save_charts(const SceneSpec& scene, std::size_t body_count, const RunContext& run) const
{
    const auto chart = [&](const std::string& what, const std::string& y_label) {
        fig::LineChart c;
        c.title = str(scene.title, ": ", what);
        c.x_label = "time [s]";
        c.y_label = y_label;
        return c;
    };
    const auto value = [&](std::size_t row, Column column) { return std::get<double>(table_.cell(row, column)); };
    fig::LineChart energies = chart("energies", "energy [J]");
    fig::LineChart cost = chart("wall time per step", "time per step [ms]");
    fig::LineChart iterations = chart("Newton iterations per step", "iterations");
    bool any_newton = false;
    for (std::size_t i = 0; i < body_count; ++i) {
        const std::string name = std::get<std::string>(table_.cell(i, body));
        fig::Series kinetic_series{name + " kinetic", {}, {}}, elastic_series{name + " elastic", {}, {}},
            balance_series{name + " H - W_in", {}, {}}, time_series{name, {}, {}}, newton_series{name, {}, {}};
        for (std::size_t row = i; row < table_.rows(); row += body_count) {
            const double t = value(row, time);
            for (auto [series, column] : {std::pair{&kinetic_series, kinetic}, std::pair{&elastic_series, elastic},
                                          std::pair{&balance_series, balance}}) {
                series->x.push_back(t);
                series->y.push_back(value(row, column));
            }
            if (row < body_count)
                continue;  // step 0 took no time
            time_series.x.push_back(t);
            time_series.y.push_back(1e3 * value(row, step_time));
            newton_series.x.push_back(t);
            newton_series.y.push_back(value(row, newton));
            any_newton = any_newton || newton_series.y.back() > 0.0;
        }
        energies.series.insert(energies.series.end(), {kinetic_series, elastic_series, balance_series});
        cost.series.push_back(time_series);
        iterations.series.push_back(newton_series);
    }
    fig::save_chart(energies, run.file("energies"), run.figures);
    fig::save_chart(cost, run.file("step_time"), run.figures);
    if (any_newton)
        fig::save_chart(iterations, run.file("newton_iterations"), run.figures);
}

/// ffmpeg is on the PATH.
namespace {

bool have_ffmpeg()
{
    return std::system("command -v ffmpeg >/dev/null 2>&1") == 0;
}

}  // namespace

double video_frame_rate(int frames, const OutputSpec& output)
{
    // Slow motion when the frames at their own rate would last less than min_video_seconds.
    return frames > 0 ? std::min(output.frame_rate, frames / min_video_seconds) : output.frame_rate;
}

void make_video(const RunContext& run, const std::string& stem, const OutputSpec& output)
{
    if (!have_ffmpeg()) {
        std::cout << "video: skipped, ffmpeg is not installed (tools/setup.sh installs Debian's ffmpeg)\n";
        return;
    }
    const std::filesystem::path input = run.file(stem + "_%04d.png");
    const std::filesystem::path video = run.file(stem + "." + output.video);
    const auto frame_exists = [&](int k) {
        char suffix[32];
        std::snprintf(suffix, sizeof suffix, "_%04d.png", k);
        return std::filesystem::exists(run.file(stem + suffix));
    };
    int frames = 0;
    while (frame_exists(frames))
        ++frames;
    const double rate = video_frame_rate(frames, output);
    const std::string filter =
        output.video == "mp4"
            ? "-pix_fmt yuv420p -r 30 -vf 'scale=1280:720:force_original_aspect_ratio=decrease,"
              "pad=1280:720:(ow-iw)/2:(oh-ih)/2:color=white'"
            : "-vf 'scale=iw/2:-1:flags=lanczos'";
    const std::string command = str("ffmpeg -loglevel error -nostdin -y -framerate ", rate, " -i '",
                                    input.string(), "' ", filter, " '", video.string(), "' >/dev/null 2>&1");
    if (std::system(command.c_str()) != 0) {
        // The frames are there; a failed video costs the run nothing else.
        std::cout << "video: skipped, ffmpeg could not make " << video.filename().string() << " from the PNG frames\n";
        std::filesystem::remove(video);
        return;
    }
    std::cout << "video: " << video.filename().string() << " (" << frames << " frames, "
              << std::lround(10.0 * frames / rate) / 10.0 << " s";
    if (rate < output.frame_rate)
        std::cout << ", slow motion x" << std::lround(10.0 * output.frame_rate / rate) / 10.0;
    std::cout << ")\n";
}

Progress::Progress(int steps, bool enabled) : steps_(steps), enabled_(enabled && ::isatty(STDERR_FILENO)) {}

void Progress::update(int step, int newton)
{
    newton_ += newton;
    if (!enabled_ || (clock_.seconds() - shown_ < 0.1 && step < steps_))
        return;
    shown_ = clock_.seconds();
    const double rate = step / std::max(shown_, 1e-9);
    const int width = 30, filled = steps_ > 0 ? width * step / steps_ : width;
    std::fprintf(stderr, "\r[%s%s] %3d%%  step %d/%d  %.0f steps/s  %.1f s left  Newton %.1f/step ",
                 std::string(static_cast<std::size_t>(filled), '#').c_str(),
                 std::string(static_cast<std::size_t>(width - filled), ' ').c_str(), steps_ > 0 ? 100 * step / steps_ : 100,
                 step, steps_, rate, (steps_ - step) / std::max(rate, 1e-9), step > 0 ? double(newton_) / step : 0.0);
    if (step == steps_)
        std::fprintf(stderr, "\n");
    std::fflush(stderr);
}

void Progress::finish()
{
    if (enabled_)
        std::fprintf(stderr, "\n");
}

}  // namespace fem::scenes
