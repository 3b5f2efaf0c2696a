#include "common/motion.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <tuple>

namespace fem::io {

std::string time_label(double time)
{
    std::ostringstream rounded;
    rounded.setf(std::ios::fixed);
    rounded.precision(2);
    rounded << time;
    std::string t = rounded.str();
    while (t.size() > 1 && t.find('.') != std::string::npos && (t.back() == '0' || t.back() == '.'))
        t.pop_back();
    return str("t = ", t == "-0" ? "0" : t, " s");
}

std::string warp_note(double warp_scale)
{
    return warp_scale == 1.0 ? "" : str("displacement drawn \u00D7", warp_scale, " (grey: the body at rest)");
}

std::string frame_title(const std::string& title, double time, double warp_scale)
{
    const std::string note = warp_note(warp_scale);
    return str(title, ", ", time_label(time), note.empty() ? "" : "\n", note);
}

MotionRecorder::MotionRecorder(std::filesystem::path pvd_path, int png_every, FrameFile file)
    : series_(std::move(pvd_path)), png_every_(png_every), file_(file)
{
    if (png_every < 0)
        throw Error(str("png_every must be 0 (no PNG frames) or a frame interval >= 1, got ", png_every));
}

void MotionRecorder::add(double time, const MeshData& frame)
{
    warped(frame);  // checks the displacement field before anything is written
    if (file_ == FrameFile::surface)
        series_.add_surface(time, frame);
    else
        series_.add(time, frame);
    if (png_every_ > 0 && added_ % static_cast<std::size_t>(png_every_) == 0)
        kept_.emplace_back(time, frame);
    ++added_;
    for (const auto* fields : {&frame.point_data, &frame.cell_data})
        for (const Field& field : *fields) {
            if (field.values.size() == 0)
                continue;
            const Eigen::VectorXd shown = field.values.cols() == 1 ? Eigen::VectorXd(field.values.col(0))
                                                                   : Eigen::VectorXd(field.values.rowwise().norm());
            auto [it, fresh] = field_ranges_.try_emplace(field.name, shown.minCoeff(), shown.maxCoeff());
            if (!fresh)
                it->second = {std::min(it->second.first, shown.minCoeff()), std::max(it->second.second, shown.maxCoeff())};
        }
    largest_displacement_ = std::max(largest_displacement_, frame.field(displacement_field).values.rowwise().norm().maxCoeff());
    if (rest_size_ == 0.0 && frame.points.rows() > 0)
        rest_size_ = (frame.points.colwise().maxCoeff() - frame.points.colwise().minCoeff()).norm();
}

std::pair<double, double> MotionRecorder::field_range(const std::string& field) const
{
    const auto found = field_ranges_.find(field);
    if (found == field_ranges_.end())
        throw Error(str("no frame of this motion has the field '", field, "'"));
    return found->second;
}

double MotionRecorder::visible_warp(double fraction) const
{
    if (!(largest_displacement_ > 0.0) || !(rest_size_ > 0.0))
        return 1.0;
    const double wanted = fraction * rest_size_ / largest_displacement_;
    if (wanted <= 1.0)
        return 1.0;
    const double power = std::pow(10.0, std::floor(std::log10(wanted)));
    for (double m : {5.0, 2.0, 1.0})
        if (m * power <= wanted)
            return m * power;
    return power;
}

std::array<double, 6> MotionRecorder::motion_bounds(double warp_scale) const
{
    if (kept_.empty())
        throw Error("motion_bounds: no frame was kept for the PNGs (png_every = 0, or nothing added)");
    std::array<double, 6> box = fig::empty_bounds();
    for (const auto& kept : kept_)
        fig::grow_bounds(box, warped(kept.second, warp_scale).points);
    if (warp_scale != 1.0)  // the rest shape, drawn faint behind the body
        fig::grow_bounds(box, kept_.front().second.points);
    return box;
}

std::pair<std::pair<double, double>, std::string> MotionRecorder::colour_range(const fig::RenderOptions& options) const
{
    if (options.range)
        return {*options.range, options.range_note};
    double low = std::numeric_limits<double>::infinity(), high = -low;
    std::vector<double> pooled;  // every shown value of the kept frames, for a clipped range
    for (const auto& kept : kept_) {
        const Eigen::MatrixXd& values = kept.second.field(options.field).values;
        const Eigen::VectorXd shown = values.cols() == 1 || options.component < 0
                                          ? Eigen::VectorXd(values.rowwise().norm())
                                          : Eigen::VectorXd(values.col(options.component));
        low = std::min(low, values.cols() == 1 ? values.minCoeff() : shown.minCoeff());
        high = std::max(high, values.cols() == 1 ? values.maxCoeff() : shown.maxCoeff());
        if (options.clip_percentile < 100.0)
            for (Eigen::Index i = 0; i < values.rows(); ++i)
                pooled.push_back(values.cols() == 1 ? values(i, 0) : shown(i));
    }
    const auto all = field_ranges_.find(options.field);
    const bool whole_run = !kept_.empty() && all != field_ranges_.end() &&
                           (options.component < 0 || kept_.front().second.field(options.field).values.cols() == 1);
    std::pair<double, double> range = whole_run ? all->second : std::make_pair(low, high);
    std::string note = options.range_note;
    if (whole_run && note.empty() && added_ > kept_.size())
        note = str("range of all ", added_, " frames");
    // Clipped: the top at the percentile of the kept frames' values, pooled (the percentile needs
    // the values; the whole run keeps only its range).
    const double top = pooled.empty() ? range.second : fig::percentile(pooled, options.clip_percentile);
    if (top < range.second && top > range.first) {
        const std::string clipped = fig::clip_note(options.clip_percentile, range.second, options.unit);
        note = note.empty() ? clipped : note + "\n" + clipped;
        range.second = top;
    }
    return {range, note};
}

int MotionRecorder::render_png_frames(const std::filesystem::path& stem, const fig::RenderOptions& options,
                                      double warp_scale, const FrameExtras& extras) const
{
    std::vector<std::pair<double, MeshData>> deformed;
    for (const auto& [time, mesh] : kept_)
        deformed.emplace_back(time, warped(mesh, warp_scale));
    if (deformed.empty() || !fig::can_draw(true))
        return 0;
    fig::RenderOptions shared = options;
    std::tie(shared.range, shared.range_note) = colour_range(options);
    if (warp_scale != 1.0 && !shared.outline)
        shared.outline = kept_.front().second;  // its points are the rest positions
    std::vector<std::vector<fig::Prop>> props(deformed.size());
    std::array<double, 6> box = motion_bounds(warp_scale);
    for (std::size_t k = 0; k < deformed.size(); ++k)
        if (extras.props) {
            props[k] = extras.props(k, deformed[k].first);
            for (const fig::Prop& prop : props[k])
                fig::grow_bounds(box, prop.shape.points);  // the camera frames the obstacles too
        }
    if (!shared.frame_bounds)  // a box the caller fixed (e.g. a live view's) is kept
        shared.frame_bounds = box;
    int written = 0;
    for (std::size_t k = 0; k < deformed.size(); ++k) {
        const auto& [time, mesh] = deformed[k];
        char suffix[32];
        std::snprintf(suffix, sizeof suffix, "_%04d.png", written);
        std::filesystem::path path = stem;
        path += suffix;
        fig::RenderOptions frame_options = shared;
        frame_options.title = extras.title ? extras.title(k, time) : frame_title(options.title, time, warp_scale);
        frame_options.props = std::move(props[k]);
        written += fig::render_mesh_png(path, mesh, frame_options) ? 1 : 0;
    }
    return written;
}

}  // namespace fem::io
