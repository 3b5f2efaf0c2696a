#pragma once
// The course's bunny (data/), as the tests of several chapters read it.

#include "common/files.hpp"
#include "common/mesh.hpp"
#include "common/mesh_io.hpp"

namespace fem::test {

/// The bunny's closed triangle surface, data/bunny.obj.
inline TriMesh bunny_surface() { return io::read_tri_mesh(data_path("bunny.obj")); }

/// The bunny's coarse tetrahedral mesh, data/bunny_coarse.node (+ .ele), TetGen's output.
inline TetMesh bunny_tets() { return io::read_tet_mesh(data_path("bunny_coarse.node")); }

}  // namespace fem::test
