// The mesh files of common/mesh_io.hpp: read_tri_mesh, write_tri_mesh, read_tet_mesh and
// write_tet_mesh pick the format by the file's extension. Each format reads and writes in a file of
// its own name (mesh_io_obj.cpp, mesh_io_stl.cpp, mesh_io_ply.cpp, mesh_io_tetgen.cpp; .vtu through
// common/vtk_io.hpp); this file also holds the helpers they share (common/mesh_io_internal.hpp).
// docs/03_triangle_gradients.md#meshes-from-files
#include "common/mesh_io.hpp"
#include "common/mesh_io_internal.hpp"
#include "common/text_file.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/vtk_io.hpp"

#include <algorithm>
#include <cctype>
#include <iomanip>
#include <sstream>
#include <string>

namespace fem::io {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// What several formats share (declared in common/mesh_io_internal.hpp)

namespace detail {

std::string lower_extension(const fs::path& path)
{
    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return extension;
}

void add_fan(const std::vector<int>& corners, int line, std::vector<std::array<int, 3>>& triangles,
             std::vector<int>& lines)
{
    for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
        triangles.push_back({corners[0], corners[k], corners[k + 1]});
        lines.push_back(line);
    }
}

TriMesh to_tri_mesh(const std::vector<Eigen::Vector3d>& points,
                    const std::vector<std::array<int, 3>>& triangles)
{
    TriMesh mesh;
    mesh.V.resize(static_cast<Eigen::Index>(points.size()), 3);
    for (std::size_t v = 0; v < points.size(); ++v)
        mesh.V.row(static_cast<Eigen::Index>(v)) = points[v].transpose();
    mesh.F.resize(static_cast<Eigen::Index>(triangles.size()), 3);
    for (std::size_t f = 0; f < triangles.size(); ++f)
        for (int k = 0; k < 3; ++k)
            mesh.F(static_cast<Eigen::Index>(f), k) = triangles[f][k];
    return mesh;
}

MeshOrigin line_origin(const std::string& file, const std::vector<int>& vertex_lines,
                       const std::vector<int>& element_lines)
{
    return MeshOrigin{file,
                      [file, vertex_lines](Eigen::Index v) {
                          return str(file, ", line ", vertex_lines[static_cast<std::size_t>(v)]);
                      },
                      [file, element_lines](Eigen::Index e) {
                          return str(file, ", line ", element_lines[static_cast<std::size_t>(e)]);
                      }};
}

void write_text_file(const fs::path& path, const std::function<void(std::ostream&)>& write)
{
    std::ostringstream out;
    out << std::setprecision(17);
    write(out);
    write_file(path, out.str());
}

}  // namespace detail

// ---------------------------------------------------------------------------------------------
// .vtu (read and written by common/vtk_io.hpp; here the cells are checked for their kind), and the
// choice by extension

namespace {

io::MeshData read_vtu_cells(const fs::path& path, int corners, const char* kind)
{
    detail::require_readable_file(path);
    io::MeshData data = read_vtu(path);
    if (data.cells.rows() > 0 && data.cells.cols() != corners)
        throw Error(str("'", path.string(), "' holds cells of ", data.cells.cols(), " points; a ", kind,
                        " mesh needs cells of ", corners));
    return data;
}

MeshOrigin cell_origin(const std::string& file)
{
    return MeshOrigin{file, [file](Eigen::Index v) { return str(file, ", point ", v); },
                      [file](Eigen::Index e) { return str(file, ", cell ", e); }};
}

[[noreturn]] void unknown_extension(const fs::path& path, const char* allowed)
{
    throw Error(str("'", path.string(), "': unknown mesh file type '", path.extension().string(),
                    "'; allowed: ", allowed));
}

}  // namespace

TriMesh read_tri_mesh(const fs::path& path)
{
    const std::string extension = detail::lower_extension(path);
    if (extension == ".obj")
        return detail::read_obj(path);
    if (extension == ".stl")
        return detail::read_stl(path);
    if (extension == ".ply")
        return detail::read_ply(path);
    if (extension == ".vtu") {
        const io::MeshData data = read_vtu_cells(path, 3, "triangle");
        TriMesh mesh;
        mesh.V = data.points;
        if (data.cells.rows() > 0)
            mesh.F = data.cells;
        validate(mesh, cell_origin(path.string()));
        return mesh;
    }
    unknown_extension(path, ".obj, .stl, .ply, .vtu");
}

void write_tri_mesh(const fs::path& path, const TriMesh& mesh)
{
    validate(mesh, path.string());
    io::MeshData data;
    data.points = mesh.V;
    data.cells = mesh.F;
    const std::string extension = detail::lower_extension(path);
    if (extension == ".vtu") {
        write_vtu(path, data);
    } else if (extension == ".obj") {
        detail::write_obj(path, mesh);
    } else if (extension == ".stl") {
        detail::write_binary_stl(path, mesh);
    } else if (extension == ".ply") {
        detail::write_binary_ply(path, mesh);
    } else {
        unknown_extension(path, ".obj, .stl, .ply, .vtu");
    }
}

TetMesh read_tet_mesh(const fs::path& path, Inverted inverted)
{
    const std::string extension = detail::lower_extension(path);
    if (extension == ".vtu") {
        const io::MeshData data = read_vtu_cells(path, 4, "tetrahedral");
        TetMesh mesh;
        mesh.V = data.points;
        if (data.cells.rows() > 0)
            mesh.T = data.cells;
        validate(mesh, cell_origin(path.string()), inverted);
        return mesh;
    }
    if (extension == ".node" || extension == ".ele" || extension.empty())
        return detail::read_tetgen(detail::tetgen_paths(path), inverted);
    unknown_extension(path, ".node/.ele (TetGen), .vtu");
}

void write_tet_mesh(const fs::path& path, const TetMesh& mesh)
{
    TetMesh checked = mesh;
    validate(checked, path.string());
    const std::string extension = detail::lower_extension(path);
    if (extension == ".vtu") {
        io::MeshData data;
        data.points = mesh.V;
        data.cells = mesh.T;
        write_vtu(path, data);
    } else if (extension == ".node" || extension == ".ele") {
        detail::write_tetgen(detail::tetgen_paths(path), mesh);
    } else {
        unknown_extension(path, ".node/.ele (TetGen), .vtu");
    }
}

}  // namespace fem::io
