#pragma once
// Triangle and tetrahedral meshes to and from files.
//
//   surfaces (TriMesh):   .obj  .stl  .ply  .vtu
//   volumes (TetMesh):    TetGen's .node + .ele pair, .vtu
//
// Every reader checks what it reads and calls validate() (common/mesh.hpp) with the file as the
// origin, so a bad file raises an fem::Error that names the file, the line (in the text formats:
// .obj, ASCII .ply, .node, .ele) or the element, and what was expected: a missing or truncated file,
// a line with too few columns, a number that does not parse, a non-finite coordinate, an index out of
// range, a degenerate element, an inverted tetrahedron (rejected, or re-oriented when asked).
// Polygons with more than three corners are split into triangles (a fan from the first corner).
// Messages name vertices and elements by their 0-based position in the mesh that was read.
//
// Precision: .obj (17 significant digits), .node/.ele (17 digits) and .vtu (binary doubles) keep
// every bit of a double. STL stores 32-bit floats by definition, and the PLY writer writes 32-bit
// floats (binary little-endian, like VTK's): a mesh written to .stl or .ply reads back rounded to
// float precision (about 6e-8 relative). .obj, .stl and .ply are written here, not by VTK, whose
// writers of these formats report no error when the disk is full.
//
// Every write is atomic (fem::write_atomically): a failed write leaves no half-written file, and the
// message gives the system's reason (e.g. "No space left on device"). The .node and .ele files of
// a TetGen pair appear together (fem::StagedFiles): a failure leaves both old files as they were.

#include "common/mesh.hpp"

#include <filesystem>

namespace fem::io {

/// Reads a triangle surface by its extension:
///  - .obj: `v x y z` and `f i j k ...` records (indices 1-based or negative, `i/t/n` forms), other
///    records (vt, vn, g, o, s, usemtl, l, ...) ignored; read by a line-aware parser;
///  - .stl: ASCII or binary (the binary size checked against its facet count), read by a hand-written
///    parser; the corners STL repeats for every facet are merged into shared vertices (exactly equal
///    positions only);
///  - .ply: ASCII or binary (either byte order), element `vertex` with x, y, z and element `face`
///    with the list `vertex_indices` (or `vertex_index`); other elements and properties skipped;
///  - .vtu: an unstructured grid of triangles (fem::io::read_vtu).
/// fem::Error for an unknown extension, a missing, unreadable or malformed file, or a mesh that
/// fails validate(). docs/03_triangle_gradients.md#meshes-from-files
TriMesh read_tri_mesh(const std::filesystem::path& path);

/// Writes a triangle surface by its extension: .obj (17 significant digits), .stl (binary, 32-bit
/// floats) or .ply (binary little-endian, 32-bit floats), each written by common/mesh_io_<format>.cpp,
/// not by VTK; or .vtu (fem::io::write_vtu). Validates the mesh first.
void write_tri_mesh(const std::filesystem::path& path, const TriMesh& mesh);

/// Reads a tetrahedral mesh: TetGen's .node/.ele pair (path names either file, or their common
/// stem without extension), or a .vtu of tetrahedra. TetGen files number their nodes from 0 or
/// from 1, as the first node of the .node file declares; node numbers must then run consecutively,
/// and the .ele file refers to nodes in that numbering. Attributes and boundary markers are read
/// past and dropped; second-order (10-node) tetrahedra are refused. Inverted tetrahedra are an
/// error with Inverted::reject, and re-oriented (last two vertices swapped) with Inverted::reorient.
/// docs/03_triangle_gradients.md#meshes-from-files
TetMesh read_tet_mesh(const std::filesystem::path& path, Inverted inverted = Inverted::reject);

/// Writes a tetrahedral mesh: .node or .ele (both files are written, with the same stem, numbered
/// from 0, 17 significant digits, appearing together) or .vtu. Validates the mesh first (inverted
/// tets are an error).
void write_tet_mesh(const std::filesystem::path& path, const TetMesh& mesh);

}  // namespace fem::io
