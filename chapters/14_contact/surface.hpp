#pragma once
// Chapter 14: the surface of a tet mesh as contact primitives — its vertices, which the barrier holds
// off the obstacles, and its edges and triangles, which chapter 15 holds off each other.
// docs/14_contact.md#the-contact-potential

#include "common/mesh.hpp"

#include <Eigen/Core>

#include <vector>

namespace fem::contact {

/// The boundary of a tet mesh as primitives, in indices of the mesh's vertices.
struct SurfacePrimitives {
    std::vector<int> vertices;  ///< the vertices of the boundary faces, increasing
    /// The edges of the boundary faces, each once (lower index first), in the order the faces meet them.
    Eigen::MatrixX2i edges;
    MatrixX3i triangles;        ///< chapter 13's boundary faces (skin::boundary_faces), outward
};

/// The surface primitives of mesh: its boundary faces (chapter 13), their edges and vertices.
/// docs/14_contact.md#the-contact-potential
SurfacePrimitives surface_primitives(const TetMesh& mesh);

}  // namespace fem::contact
