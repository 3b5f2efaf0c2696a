// The memory a scene's run needs: the estimate of one body's run, and the budget the bodies of a
// scene share, checked as each body is read. docs/scenes.md#limits
#include "scene_parts.hpp"

#include <cmath>
#include <fstream>
#include <limits>
#include <sys/resource.h>

namespace fem::scenes {
namespace {

// The memory estimate's constants (memory_estimate).
constexpr double fill_per_vertex_block = 1.0;  ///< factor blocks per vertex^(4/3)
constexpr double bytes_per_tet = 3000.0;       ///< the mesh, per-tet matrices and frames
constexpr double bytes_per_vertex = 4000.0;    ///< positions, velocities, the matrices' rows
/// A mesh obstacle's triangle: the surface, its boxes and AABB tree, the flat neighbours and fans,
/// the edge map of its features and the start checks (measured: 520 bytes, a million triangles
/// 0.52 GB beside a 41 MB run), doubled to err high.
constexpr double bytes_per_obstacle_triangle = 1000.0;

/// The memory this process may still use [bytes]: the system's available memory (MemAvailable of
/// /proc/meminfo), or the address-space limit (ulimit -v) when it is lower.
double available_memory()
{
    double available = std::numeric_limits<double>::infinity();
    std::ifstream meminfo("/proc/meminfo");
    for (std::string key; meminfo >> key;) {
        double kilobytes = 0.0;
        meminfo >> kilobytes;
        if (key == "MemAvailable:")
            available = kilobytes * 1024.0;
        meminfo.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
    }
    rlimit limit{};
    if (::getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
        available = std::min(available, static_cast<double>(limit.rlim_cur));
    return available;
}

}  // namespace

namespace detail {

namespace {

/// Adds bytes to the scene's estimate, refusing at field key of node when the sum passes the budget:
/// "<what> needs about N MB (<why>)[ besides M MB for the bodies and obstacles before it], more than
/// the B MB available: <change>".
void spend(const Fields& fields, const toml::node& node, const std::string& key, double bytes, const std::string& what,
           const std::string& why, const std::string& change)
{
    const Source& source = fields.source();
    const double budget = source.limits.memory > 0 ? static_cast<double>(source.limits.memory) : available_memory();
    if (source.estimated_bytes + bytes > budget)
        fields.fail(node, key, str(what, " needs about ", std::ceil(bytes / 1e6), " MB (", why, ")",
                                   source.estimated_bytes > 0 ? str(" besides ", std::ceil(source.estimated_bytes / 1e6),
                                                                    " MB for the bodies and obstacles before it")
                                                              : std::string(),
                                   ", more than the ", std::floor(budget / 1e6), " MB available: ", change));
    source.estimated_bytes += bytes;
}

}  // namespace

void check_memory(const Fields& fields, const toml::node& node, const std::string& key, long long vertices,
                  long long tets, const std::string& change)
{
    const MemoryEstimate need = memory_estimate(vertices, tets);
    spend(fields, node, key, need.bytes, "a run of this mesh",
          str(tets, " tets, ", need.dofs, " unknowns, about ", need.factor_nonzeros, " factor entries"), change);
}

void check_obstacle_memory(const Fields& fields, const toml::node& node, const std::string& key, long long triangles)
{
    spend(fields, node, key, bytes_per_obstacle_triangle * static_cast<double>(triangles), "this mesh obstacle",
          str(triangles, " triangles, at ", bytes_per_obstacle_triangle, " bytes each: its tree, flat fans, features and ",
              "the start checks; a million measured 0.52 GB"),
          "use a coarser surface");
}

}  // namespace detail

MemoryEstimate memory_estimate(long long vertices, long long tets)
{
    MemoryEstimate e;
    e.dofs = 3 * vertices;
    // A fill-reducing ordering of a 3D mesh of n vertices leaves about n^(4/3) nonzero 3x3 blocks in
    // the Cholesky factor (nested dissection's bound, George 1973); the per-tet and per-vertex bytes
    // cover the mesh, the matrices, every model's per-tet data and the frames, chosen to err high.
    e.factor_nonzeros = 9.0 * fill_per_vertex_block * std::pow(static_cast<double>(vertices), 4.0 / 3.0);
    e.bytes = bytes_per_tet * static_cast<double>(tets) + bytes_per_vertex * static_cast<double>(vertices) +
              12.0 * e.factor_nonzeros;
    return e;
}

}  // namespace fem::scenes
