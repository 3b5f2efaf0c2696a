#include "common/motion.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>

namespace fem::io {

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
}

int MotionRecorder::render_png_frames(const std::filesystem::path& stem, const fig::RenderOptions& options,
                                      double warp_scale) const
{
    std::vector<std::pair<double, MeshData>> deformed;
    for (const auto& [time, mesh] : kept_)
        deformed.emplace_back(time, warped(mesh, warp_scale));
    if (deformed.empty() || !fig::display_available())
        return 0;
    fig::RenderOptions shared = options;
    std::array<double, 6> box{};
    for (int axis = 0; axis < 3; ++axis) {
        box[2 * axis] = std::numeric_limits<double>::infinity();
        box[2 * axis + 1] = -std::numeric_limits<double>::infinity();
    }
    double low = std::numeric_limits<double>::infinity(), high = -low;
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
    }
    if (!shared.frame_bounds)  // a box the caller fixed (e.g. a live view's) is kept
        shared.frame_bounds = box;
    if (!shared.range)
        shared.range = std::make_pair(low, high);
    int written = 0;
    const std::string scale = warp_scale == 1.0 ? std::string() : str(" (displacement x ", warp_scale, ")");
    for (const auto& [time, mesh] : deformed) {
        char suffix[32];
        std::snprintf(suffix, sizeof suffix, "_%04d.png", written);
        std::filesystem::path path = stem;
        path += suffix;
        fig::RenderOptions frame_options = shared;
        frame_options.title = str(options.title, scale, ", t = ", time, " s");
        written += fig::render_mesh_png(path, mesh, frame_options) ? 1 : 0;
    }
    return written;
}

}  // namespace fem::io
