#pragma once
// What a scene run writes besides its frames: the history of every step (steps.csv) and its charts,
// the video, the merged frame of several bodies, and the progress bar. docs/scenes.md#outputs

#include "scenes/scene_file.hpp"

#include "10_linear_dynamics/time_integration.hpp"

#include "common/cli.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"
#include "common/vtk_io.hpp"

#include <string>
#include <vector>

namespace fem::scenes {

/// The frame of several bodies as one mesh: points, cells and fields concatenated in body order
/// (cell indices shifted), keeping the fields output.fields names (and the displacement always).
/// Every part must have the same fields.
io::MeshData merged_frame(const std::vector<io::MeshData>& parts, const OutputSpec& output);

/// The history of a run, one row per step and body: chapter 10's StepRecord with the body's name
/// and model (steps.csv). docs/scenes.md#outputs
class StepHistory {
public:
    StepHistory();
    /// One row: the body's record after a step (or at step 0).
    void add(const std::string& body, const std::string& model, const dynamics::StepRecord& record);
    /// steps.csv.
    void write_csv(const std::filesystem::path& file) const { table_.write_csv(file); }
    /// The charts energies (kinetic, elastic, H − W_in per body), step_time and, when any step took
    /// Newton iterations, newton_iterations (PNG + CSV, fig::save_chart).
    void save_charts(const SceneSpec& scene, std::size_t body_count, const RunContext& run) const;

private:
    Table table_;
};

/// A video <stem>.mp4 or .gif of the PNG frames <stem>_NNNN.png (ffmpeg), one line instead when
/// ffmpeg is missing or fails (the frames are there either way). A lecturer talks over it, so it
/// lasts at least min_video_seconds: a shorter motion plays in slow motion (the frames at
/// frame_count / min_video_seconds per second instead of output.frame_rate; the printed line says
/// by how much). An MP4 is 1280×720 (16:9), each frame scaled to fit on white.
void make_video(const RunContext& run, const std::string& stem, const OutputSpec& output);

/// The shortest video make_video writes [s].
inline constexpr double min_video_seconds = 5.0;

/// The frames per second a video of `frames` frames plays at: output.frame_rate, or fewer,
/// frames / min_video_seconds, when that would last less than min_video_seconds (slow motion).
double video_frame_rate(int frames, const OutputSpec& output);

/// A one-line progress bar on stderr (only when it is a terminal): done, time left, steps per
/// second, Newton iterations per step.
class Progress {
public:
    Progress(int steps, bool enabled);
    void update(int step, int newton);
    void finish();

private:
    int steps_;
    bool enabled_;
    long newton_ = 0;
    Timer clock_;
    double shown_ = -1.0;
};

}  // namespace fem::scenes
