#pragma once
// Eigen types used across the course. Meshes follow libigl's names: V (#V×3 rest positions),
// F (#F×3 triangles), T (#T×4 tetrahedra); row-major, 0-based indices.

#include <Eigen/Core>

#include <limits>

namespace fem {

using MatrixX3d = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;  ///< #V×3 positions
using MatrixXiR = Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;  ///< cells
using MatrixX3i = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;  ///< #F×3 triangles
using MatrixX4i = Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor>;  ///< #T×4 tetrahedra

/// +∞: "never" of a time of impact, "none within reach" of a distance.
inline constexpr double infinity = std::numeric_limits<double>::infinity();

}  // namespace fem
