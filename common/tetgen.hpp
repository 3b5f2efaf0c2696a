#pragma once
// TetGen, Debian's tetgen program, run in a child process with a time and a memory limit: the
// tetrahedra inside a closed triangle surface. docs/scenes.md#limits

#include "common/mesh.hpp"

#include <cstddef>
#include <string>

namespace fem {

/// What a TetGen run may use. Switches that ask too much (a quality bound TetGen cannot reach,
/// such as q1.0, or a tiny maximum volume) run into one of them instead of running for ever.
struct TetgenLimits {
    double seconds = 120.0;                      ///< wall-clock time [s]
    std::size_t memory = std::size_t(4) << 30;   ///< the child's address space [bytes]
};

/// Tetrahedralises a closed triangle surface with the tetgen program and the given switches
/// ("pq1.5aY": a piecewise linear complex, quality 1.5, the surface kept). The surface goes to a
/// temporary folder (fem-tetgen-<pid>-<n> in the system's temporary folder), removed on every way
/// out; folders of killed runs are removed by the next call. fem::Error starting with what, with
/// TetGen's reason when it fails (an open or self-intersecting surface), when it is not installed,
/// when the switches are not plain TetGen switches with p, when it exceeds a limit (naming the
/// limit), or when a stop signal (common/interrupt.hpp) arrives while it runs.
TetMesh tetrahedralize(const TriMesh& surface, const std::string& switches, const std::string& what,
                       const TetgenLimits& limits = {});

}  // namespace fem
