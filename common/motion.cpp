#include "common/motion.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace fem::io {

std::string frame_title(const std::string& title, double time, double warp_scale)
{
    std::ostringstream rounded;
    rounded.setf(std::ios::fixed);
    rounded.precision(2);
    rounded << time;
    std::string t = rounded.str();
    while (t.size() > 1 && t.find('.') != std::string::npos && (t.back() == '0' || t.back() == '.'))
        t.pop_back();
    std::string out = str(title, ", t = ", t == "-0" ? "0" : t, " s");
    if (warp_scale != 1.0)
        out += str("\ndisplacement drawn \u00D7", warp_scale, " (grey: the body at rest)");
    return out;
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

int MotionRecorder::render_png_frames(const std::filesystem::path& stem, const fig::RenderOptions& options,
                                      double warp_scale) const
{
    std::vector<std::pair<double, MeshData>> deformed;
    for (const auto& [time, mesh] : kept_)
        deformed.emplace_back(time, warped(mesh, warp_scale));
    if (deformed.empty() || !fig::can_draw(true))
        return 0;
    fig::RenderOptions shared = options;
    std::array<double, 6> box{};
    for (int axis = 0; axis < 3; ++axis) {
        box[2 * axis] = std::numeric_limits<double>::infinity();
        box[2 * axis + 1] = -std::numeric_limits<double>::infinity();
    }
    double low = std::numeric_limits<double>::infinity(), high = -low;
    std::vector<double> pooled;  // every shown value of the kept frames, for a clipped range
    for (const auto& [time, mesh] : deformed) {
        for (int axis = 0; axis < 3; ++axis) {
            box[2 * axis] = std::min(box[2 * axis], mesh.points.col(axis).minCoeff());
            box[2 * axis + 1] = std::max(box[2 * axis + 1], mesh.points.col(axis).maxCoeff());
        }
        const Eigen::MatrixXd& values = mesh.field(options.field).values;
        const Eigen::VectorXd shown = values.cols() == 1 || options.component < 0
                                          ? Eigen::VectorXd(values.rowwise().norm())
                                          : Eigen::VectorXd(values.col(options.component));
        low = std::min(low, values.cols() == 1 ? values.minCoeff() : shown.minCoeff());
        high = std::max(high, values.cols() == 1 ? values.maxCoeff() : shown.maxCoeff());
        if (options.clip_percentile < 100.0)
            for (Eigen::Index i = 0; i < values.rows(); ++i)
                pooled.push_back(values.cols() == 1 ? values(i, 0) : shown(i));
    }
    if (!shared.range) {
        const auto all = field_ranges_.find(options.field);
        const bool whole_run = all != field_ranges_.end() &&
                               (options.component < 0 || deformed.front().second.field(options.field).values.cols() == 1);
        shared.range = whole_run ? all->second : std::make_pair(low, high);
        if (whole_run && shared.range_note.empty() && added_ > kept_.size())
            shared.range_note = str("range of all ", added_, " frames");
        // Clipped: the top at the percentile of the kept frames' values, pooled (the percentile
        // needs the values; the whole run keeps only its range).
        const double top = pooled.empty() ? shared.range->second : fig::percentile(pooled, options.clip_percentile);
        if (top < shared.range->second && top > shared.range->first) {
            const std::string note = fig::clip_note(options.clip_percentile, shared.range->second, options.unit);
            shared.range_note = shared.range_note.empty() ? note : shared.range_note + "\n" + note;
            shared.range->second = top;
        }
    }
    if (warp_scale != 1.0 && !shared.outline) {
        shared.outline = kept_.front().second;  // its points are the rest positions
        if (!options.frame_bounds)               // the camera frames the rest shape too
            for (int axis = 0; axis < 3; ++axis) {
                box[2 * axis] = std::min(box[2 * axis], shared.outline->points.col(axis).minCoeff());
                box[2 * axis + 1] = std::max(box[2 * axis + 1], shared.outline->points.col(axis).maxCoeff());
            }
    }
    if (!shared.frame_bounds)  // a box the caller fixed (e.g. a live view's) is kept
        shared.frame_bounds = box;
    int written = 0;
    for (const auto& [time, mesh] : deformed) {
        char suffix[32];
        std::snprintf(suffix, sizeof suffix, "_%04d.png", written);
        std::filesystem::path path = stem;
        path += suffix;
        fig::RenderOptions frame_options = shared;
        frame_options.title = frame_title(options.title, time, warp_scale);
        written += fig::render_mesh_png(path, mesh, frame_options) ? 1 : 0;
    }
    return written;
}

}  // namespace fem::io
