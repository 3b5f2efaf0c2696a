#pragma once
// One entry point to every file reader of the course, chosen by the file's extension: what the fuzz
// targets (fuzz/fuzz_reader.cpp) feed their inputs to, and what the test that replays the corpus of
// bad files (tests/common/test_bad_files.cpp) reads them with.

#include "common/mesh_io.hpp"
#include "common/vtk_io.hpp"

#include <filesystem>

namespace fem::fuzz {

/// Reads path with each of the course's readers that takes its extension, and discards what it
/// reads: .obj, .stl, .ply with read_tri_mesh; .node or .ele with read_tet_mesh (the pair, inverted
/// tetrahedra re-oriented); .vtu with read_vtu and then, when its cells are triangles or
/// tetrahedra, read_tri_mesh or read_tet_mesh; .pvd with read_pvd. Any other extension is
/// read_tri_mesh's fem::Error. A bad file must raise fem::Error; anything else is a bug.
inline void read_by_extension(const std::filesystem::path& path)
{
    const std::filesystem::path extension = path.extension();
    if (extension == ".node" || extension == ".ele") {
        io::read_tet_mesh(path, Inverted::reorient);
    } else if (extension == ".vtu") {
        const io::MeshData data = io::read_vtu(path);
        if (data.cells.cols() == 3)
            io::read_tri_mesh(path);
        else if (data.cells.cols() == 4)
            io::read_tet_mesh(path, Inverted::reorient);
    } else if (extension == ".pvd") {
        io::read_pvd(path);
    } else {
        io::read_tri_mesh(path);
    }
}

}  // namespace fem::fuzz
