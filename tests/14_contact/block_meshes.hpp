#pragma once
// Chapter 14's tests: the meshes of bodies against bodies — boxes placed in space and several bodies
// joined into one mesh of several components. docs/14_contact.md#bodies-against-bodies-and-self-contact

#include "common/mesh.hpp"

#include <Eigen/Core>

namespace fem::test {

/// One mesh of two components: a's vertices first, then b's (b's tets renumbered).
inline TetMesh two_bodies(const TetMesh& a, const TetMesh& b)
{
    TetMesh both;
    both.V.resize(a.V.rows() + b.V.rows(), 3);
    both.V << a.V, b.V;
    both.T.resize(a.T.rows() + b.T.rows(), 4);
    both.T << a.T, (b.T.array() + static_cast<int>(a.V.rows())).matrix();
    return both;
}

/// A box of cells³ cells of the given size (3) [m] with its lowest corner at corner (3) [m].
inline TetMesh box_at(const Eigen::Vector3d& corner, const Eigen::Vector3d& size, int cells = 1)
{
    TetMesh box = box_mesh(cells, cells, cells, size);
    box.V.rowwise() += corner.transpose();
    return box;
}

}  // namespace fem::test
