#pragma once
// Shape quality of triangles and tetrahedra: angles, aspect ratios, sizes. A badly shaped element
// makes gradients inaccurate and stiffness matrices ill-conditioned (docs/03_triangle_gradients.md
// shows the effect of an obtuse angle on the cotangent Laplacian).
//
// Aspect ratio (both element kinds): the longest edge h_max divided by the inradius r, normalised
// so that the equilateral triangle and the regular tetrahedron have exactly 1; it grows without
// bound as an element flattens.
//   triangle:     h_max / (2√3 r),  r = A / s          (A area, s half the perimeter)
//   tetrahedron:  h_max / (2√6 r),  r = 3|V| / Σ A_k   (V volume, A_k the areas of the four faces)
// (the definition used by the Verdict library and VTK's vtkMeshQuality as "aspect ratio").
// Per-element angles are in radians; the mesh summaries report degrees.

#include "common/mesh.hpp"

#include <Eigen/Core>

#include <array>

namespace fem {

/// The interior angles (radians) at corners a, b and c of triangle abc (in 3D). They sum to π.
/// fem::Error for a zero-length edge.
std::array<double, 3> triangle_angles(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                      const Eigen::Vector3d& c);

/// h_max / (2√3 r) with r = A / s: 1 for the equilateral triangle, +∞ for a zero-area one.
double triangle_aspect_ratio(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                             const Eigen::Vector3d& c);

/// The six dihedral angles (radians) of tetrahedron abcd, at its edges in the order ab, ac, ad,
/// bc, bd, cd: the angle between the two faces that meet at the edge, measured inside the
/// tetrahedron (π minus the angle between their outward normals). acos(1/3) ≈ 70.53° for the
/// regular tetrahedron. fem::Error for a zero-area face.
std::array<double, 6> tet_dihedral_angles(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c, const Eigen::Vector3d& d);

/// h_max / (2√6 r) with r = 3|V| / Σ face areas: 1 for the regular tetrahedron, +∞ for a flat one.
double tet_aspect_ratio(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                        const Eigen::Vector3d& d);

/// Quality figures of a triangle mesh (angles in degrees).
struct TriQuality {
    double min_angle_deg = 0.0;      ///< smallest interior angle of any triangle
    double max_angle_deg = 0.0;      ///< largest interior angle (> 90: the mesh has obtuse triangles)
    double max_aspect_ratio = 0.0;   ///< worst (largest) aspect ratio
    double min_area = 0.0;
    double max_area = 0.0;
    int obtuse_triangles = 0;        ///< triangles with an angle > 90°
    int worst_triangle = -1;         ///< the triangle with the largest aspect ratio
};

/// Quality figures of a tetrahedral mesh (angles in degrees, volumes signed: an inverted tet
/// shows as a negative min_volume).
struct TetQuality {
    double min_dihedral_deg = 0.0;
    double max_dihedral_deg = 0.0;
    double max_aspect_ratio = 0.0;
    double min_volume = 0.0;
    double max_volume = 0.0;
    int worst_tet = -1;              ///< the tetrahedron with the largest aspect ratio
};

/// The quality of every triangle, summarised. The mesh is validated first (fem::Error names a
/// degenerate triangle, which has no meaningful quality).
TriQuality mesh_quality(const TriMesh& mesh);

/// The quality of every tetrahedron, summarised. Validated first like the triangle mesh; inverted
/// tetrahedra are measured (their volume counts negative), not rejected.
TetQuality mesh_quality(const TetMesh& mesh);

}  // namespace fem
