#pragma once
// Internal to common/, not part of the public API (include it only from common/mesh_io*.cpp): what
// the mesh file formats share behind common/mesh_io.hpp. Each format reads and writes in a file of
// its own name: mesh_io_obj.cpp, mesh_io_stl.cpp, mesh_io_ply.cpp, mesh_io_tetgen.cpp (.vtu goes
// through common/vtk_io.hpp); mesh_io.cpp picks one by the extension and defines the helpers below
// that several formats use. docs/03_triangle_gradients.md#meshes-from-files

#include "common/mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <bit>
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace fem::io::detail {

// ---------------------------------------------------------------------------------------------
// The formats (each reader validates what it read, naming the file and the line or element).

/// .obj (mesh_io_obj.cpp): `v x y z` and `f i j k ...` records, the rest ignored.
TriMesh read_obj(const std::filesystem::path& path);
/// A Wavefront .obj: "v x y z" lines (17 significant digits), then "f a b c" (numbered from 1).
void write_obj(const std::filesystem::path& path, const TriMesh& mesh);

/// .stl, ASCII or binary (mesh_io_stl.cpp); corners at exactly equal positions merged into one vertex.
TriMesh read_stl(const std::filesystem::path& path);
/// A binary STL: an 80-byte header (not starting with "solid"), the facet count, and per facet its
/// unit normal and three corners as little-endian 32-bit floats, and two zero bytes.
void write_binary_stl(const std::filesystem::path& path, const TriMesh& mesh);

/// .ply, ASCII or binary of either byte order (mesh_io_ply.cpp): elements vertex and face.
TriMesh read_ply(const std::filesystem::path& path);
/// A binary little-endian PLY: the vertices as 32-bit floats x, y, z, the faces as a list of
/// 32-bit vertex indices after a one-byte count (3), as VTK's PLY writer writes them.
void write_binary_ply(const std::filesystem::path& path, const TriMesh& mesh);

/// The two files of a TetGen mesh (mesh_io_tetgen.cpp).
struct TetGenPaths {
    std::filesystem::path node, ele;
};
/// The pair a path names: either file, or their common stem without extension.
TetGenPaths tetgen_paths(const std::filesystem::path& path);
/// Reads a .node/.ele pair (numbered from 0 or 1, attributes and boundary markers dropped).
TetMesh read_tetgen(const TetGenPaths& paths, Inverted inverted);
/// Writes a .node/.ele pair (numbered from 0, 17 significant digits), the two files appearing together.
void write_tetgen(const TetGenPaths& paths, const TetMesh& mesh);

// ---------------------------------------------------------------------------------------------
// Shared by several formats (mesh_io.cpp).

/// The extension of path in lower case, with its dot (".obj"); empty if it has none.
std::string lower_extension(const std::filesystem::path& path);

/// Splits polygon `corners` into triangles (a fan from its first corner), appending them to
/// `triangles` and, for each, the line it came from to `lines`.
void add_fan(const std::vector<int>& corners, int line, std::vector<std::array<int, 3>>& triangles,
             std::vector<int>& lines);

/// The surface of `points` (rows of V) and `triangles` (rows of F, 0-based), as read.
TriMesh to_tri_mesh(const std::vector<Eigen::Vector3d>& points,
                    const std::vector<std::array<int, 3>>& triangles);

/// The origin of a mesh read from a text file: each vertex and element on its own line.
MeshOrigin line_origin(const std::string& file, const std::vector<int>& vertex_lines,
                       const std::vector<int>& element_lines);

/// Writes the text `write` puts out (numbers with 17 significant digits) to path atomically.
void write_text_file(const std::filesystem::path& path, const std::function<void(std::ostream&)>& write);

/// Appends the bytes of a number as they are in memory (little-endian on the machines we build on).
template <typename Number>
void append_bytes(std::string& bytes, Number value)
{
    static_assert(std::endian::native == std::endian::little, "the binary formats written are little-endian");
    bytes.append(reinterpret_cast<const char*>(&value), sizeof value);
}

}  // namespace fem::io::detail
