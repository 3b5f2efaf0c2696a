#pragma once
// The output of a moving body: a .pvd time series of .vtu frames (rest positions plus the
// "displacement" field, the course's convention, see vtk_io.hpp) and PNG frames rendered with one
// camera and one colour range for the whole motion, so that the pictures can be flipped through or
// made into a video. No chapter math: the chapters fill the frames' fields.

#include "common/figures.hpp"
#include "common/vtk_io.hpp"

#include <array>
#include <filesystem>
#include <functional>
#include <map>
#include <utility>
#include <string>
#include <vector>

namespace fem::io {

/// What the frames of a series are written as.
enum class FrameFile {
    volume,   ///< .vtu (unstructured grids: tets, or any cells)
    surface,  ///< .vtp (surfaces: triangles or lines), e.g. a skinned render surface
};

/// A motion frame's title: "<title>, t = 0.67 s" (the time rounded to 0.01 s), and when the
/// displacement is drawn exaggerated (warp_scale ≠ 1) a second line saying by how much and that the
/// grey shape is the body at rest.
std::string frame_title(const std::string& title, double time, double warp_scale);

/// "t = 0.67 s": the time rounded to 0.01 s, trailing zeros dropped ("t = 0.5 s", "t = 0 s").
std::string time_label(double time);

/// The line a frame drawn with its displacement exaggerated carries: "displacement drawn ×5 (grey:
/// the body at rest)"; "" for warp_scale = 1.
std::string warp_note(double warp_scale);

/// What a caller draws around each PNG frame of a motion (MotionRecorder::render_png_frames): frame
/// k (0, 1, … of the kept frames) at its time.
struct FrameExtras {
    /// The frame's title; unset: frame_title(options.title, time, warp_scale).
    std::function<std::string(std::size_t k, double time)> title;
    /// Shapes drawn with the frame (fig::Prop: obstacles at the frame's time, a lattice), in the
    /// frames' deformed coordinates; the camera's box holds them too (unless options.frame_bounds is set).
    std::function<std::vector<fig::Prop>(std::size_t k, double time)> props;
};

/// Records the frames of one body's motion.
class MotionRecorder {
public:
    /// pvd_path: the series, e.g. out/10_linear_dynamics/beam.pvd (frames in beam/beam_NNNN.vtu, or
    /// .vtp for FrameFile::surface). png_every: keep every k-th frame (k ≥ 1) for the PNG frames, 0
    /// for none.
    MotionRecorder(std::filesystem::path pvd_path, int png_every = 0, FrameFile file = FrameFile::volume);

    /// Writes the frame (points: rest positions; point field "displacement" required) to the series;
    /// keeps it for the PNGs when it is one of every png_every. fem::Error for a frame without a
    /// 3-column point field "displacement" or a field the writer refuses (non-finite values).
    void add(double time, const MeshData& frame);

    std::size_t frames() const { return series_.frames(); }

    /// The exaggeration that makes the largest displacement of all frames added so far about
    /// `fraction` of the rest shape's size (the diagonal of its bounding box), rounded down to 1,
    /// 2 or 5 times a power of ten and never below 1 (a large motion stays at true scale).
    double visible_warp(double fraction = 0.25) const;

    /// The range of a field over every frame added so far (a scalar's values, a vector's
    /// magnitudes), e.g. to colour two series on one scale; fem::Error for a field no frame has.
    std::pair<double, double> field_range(const std::string& field) const;

    /// The box (xmin, xmax, ymin, ymax, zmin, zmax) of the kept frames warped by warp_scale × their
    /// displacement, with the rest shape when warp_scale ≠ 1 (the box the frames' camera frames).
    /// fem::Error for no kept frame.
    std::array<double, 6> motion_bounds(double warp_scale = 1.0) const;

    /// The kept frame k (rest positions and fields, as added), k < kept_frames().
    const MeshData& kept_frame(std::size_t k) const { return kept_.at(k).second; }
    std::size_t kept_frames() const { return kept_.size(); }

    /// Renders the kept frames, warped by warp_scale × their displacement (1: true scale), to
    /// <stem>_0000.png, …: one camera framing the union of the deformed bodies' bounds (unless
    /// options.frame_bounds is set), and one colour range for options.field over all kept frames
    /// (unless options.range is set); the range of a scalar field or a vector's magnitude is taken
    /// over every frame added, not only the kept ones, and the colour bar says so. With
    /// options.clip_percentile < 100 the range's top is that percentile of the kept frames' values
    /// (all of them pooled), and the bar says it is clipped and gives the whole run's largest value. The title is
    /// extras.title's (default frame_title's); extras.props are drawn with each frame; when warp_scale ≠ 1
    /// the rest shape is drawn faint behind the body (unless options.outline is set). Returns the number of
    /// PNGs written (0 without a display, after can_draw's note, see figures.hpp). fem::Error if the field is missing from
    /// a frame or warp_scale is not finite.
    int render_png_frames(const std::filesystem::path& stem, const fig::RenderOptions& options,
                          double warp_scale = 1.0, const FrameExtras& extras = {}) const;

    /// The colour range render_png_frames gives options.field (options.range when set), and the note
    /// its bar carries ("range of all N frames", and with clip_percentile < 100 the clip_note when the
    /// percentile of the kept frames' values, pooled, lies inside the range). fem::Error as render_png_frames.
    std::pair<std::pair<double, double>, std::string> colour_range(const fig::RenderOptions& options) const;

private:
    PvdSeries series_;
    int png_every_;
    FrameFile file_;
    std::size_t added_ = 0;
    std::vector<std::pair<double, MeshData>> kept_;  // frames for the PNGs
    /// Over every frame added: each field's range (values of a scalar, magnitudes of a vector).
    std::map<std::string, std::pair<double, double>> field_ranges_;
    double largest_displacement_ = 0.0;  // of every frame added
    double rest_size_ = 0.0;             // the first frame's bounding-box diagonal
};

}  // namespace fem::io
