#include "10_linear_dynamics/tip_path.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"

#include <cmath>

namespace fem::dynamics {

void TipPath::record(const Body& body, const State& state)
{
    const MatrixX3d x_now = body.positions(state.u);
    times.push_back(state.time);
    x.push_back(x_now(tip, 0));
    z.push_back(x_now(tip, 2));
    const double rest = total_volume(body.mesh());
    largest_volume_change =
        std::max(largest_volume_change, std::abs(total_volume(TetMesh{x_now, body.mesh().T}) / rest - 1.0));
}

double largest_tip_distance(const TipPath& run, const TipPath& reference)
{
    const double ratio = run.time_step / reference.time_step;
    const long steps = std::lround(ratio);
    if (steps < 1 || std::abs(ratio - double(steps)) > 1e-9 * ratio)
        throw Error(str("largest_tip_distance: the reference's dt ", reference.time_step, " s does not divide the run's ",
                        run.time_step, " s"));
    if (run.times.empty() || (run.times.size() - 1) * static_cast<std::size_t>(steps) >= reference.times.size())
        throw Error("largest_tip_distance: the reference is shorter than the run");
    double distance = 0.0;
    for (std::size_t k = 0; k < run.times.size(); ++k) {
        const std::size_t r = k * static_cast<std::size_t>(steps);
        distance = std::max(distance, std::hypot(run.x[k] - reference.x[r], run.z[k] - reference.z[r]));
    }
    return distance;
}

}  // namespace fem::dynamics
