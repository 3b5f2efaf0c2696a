// Regression tests for bad files that crashed, hung or were silently misread (issue 10's
// reproducers): each must now be an fem::Error naming the file and what is wrong. The corpus under
// tests/common/bad_files/ (the fuzzers' findings among them) is replayed file by file.
#include "common/error.hpp"
#include "common/mesh_io.hpp"
#include "common/test_support.hpp"
#include "common/vtk_io.hpp"
#include "fuzz/read_by_extension.hpp"

#include <catch2/catch.hpp>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>

using Catch::Matchers::Contains;

namespace {

std::filesystem::path write_file(const std::filesystem::path& dir, const std::string& name, const std::string& content)
{
    const auto path = dir / name;
    std::ofstream(path, std::ios::binary) << content;
    return path;
}

/// An unstructured grid in VTK's ASCII XML format with the given points, connectivity, offsets and
/// cell types.
std::string vtu(int points, int cells, const std::string& coordinates, const std::string& connectivity,
                const std::string& offsets, const std::string& types)
{
    return "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece NumberOfPoints=\"" + std::to_string(points) +
           "\" NumberOfCells=\"" + std::to_string(cells) +
           "\"><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\">" + coordinates +
           "</DataArray></Points><Cells><DataArray type=\"Int32\" Name=\"connectivity\">" + connectivity +
           "</DataArray><DataArray type=\"Int32\" Name=\"offsets\">" + offsets +
           "</DataArray><DataArray type=\"UInt8\" Name=\"types\">" + types +
           "</DataArray></Cells></Piece></UnstructuredGrid></VTKFile>";
}

}  // namespace

TEST_CASE("the corpus of bad files: each is an fem::Error naming the file and saying what is wrong", "[common][mesh_io]")
{
    const std::filesystem::path dir = FEM_BAD_FILES_DIR;
    const auto expected = fem::test::error_table(dir / "errors.txt");
    std::set<std::string> listed;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        const std::filesystem::path& path = entry.path();
        if (path.filename() == "errors.txt" || path.extension() == ".ele")
            continue;  // the table, and the second file of a TetGen pair (read with its .node)
        const std::string name = path.filename().string();
        INFO(name);
        REQUIRE(expected.count(name) == 1);
        listed.insert(name);
        for (const std::string& text : expected.at(name))
            CHECK_THROWS_WITH(fem::fuzz::read_by_extension(path), Contains(path.stem().string()) && Contains(text));
    }
    for (const auto& [name, text] : expected) {
        INFO("errors.txt lists " << name << ", which is not in " << dir.string());
        CHECK(listed.count(name) == 1);
    }
}

TEST_CASE(".vtu: unknown, mixed and out-of-range cells are refused, never dereferenced", "[common][mesh_io]")
{
    const auto dir = fem::test::fresh_output_dir("bad_vtu");
    const std::string four_points = "0 0 0 1 0 0 0 1 0 0 0 1";
    // No points, one triangle (this segfaulted).
    CHECK_THROWS_WITH(fem::io::read_vtu(write_file(dir, "null.vtu", vtu(0, 1, "", "0 1 2", "3", "5"))),
                      Contains("refers to point 0") && Contains("0 points"));
    // A cell type VTK does not know (this segfaulted too).
    CHECK_THROWS_WITH(fem::io::read_vtu(write_file(dir, "type20.vtu", vtu(4, 1, four_points, "0 1 2", "3", "20"))),
                      Contains("VTK cell type 20"));
    // A poly-line (4) with three points used to read as a triangle.
    CHECK_THROWS_WITH(fem::io::read_vtu(write_file(dir, "polyline.vtu", vtu(4, 1, four_points, "0 1 2", "3", "4"))),
                      Contains("VTK cell type 4"));
    // A tet and a triangle: mixed kinds.
    CHECK_THROWS_WITH(fem::io::read_vtu(write_file(dir, "mixed.vtu",
                                                   vtu(4, 2, four_points, "0 1 2 3 0 1 2", "4 7", "10 5"))),
                      Contains("mixed cell types"));
    // The good one still reads.
    const auto good = fem::io::read_vtu(write_file(dir, "tet.vtu", vtu(4, 1, four_points, "0 1 2 3", "4", "10")));
    CHECK(good.cells.rows() == 1);
    CHECK(good.cells.cols() == 4);
}

TEST_CASE("PLY: an element without properties and a huge list length are errors, not a hang", "[common][mesh_io]")
{
    const auto dir = fem::test::fresh_output_dir("bad_ply");
    CHECK_THROWS_WITH(fem::io::read_tri_mesh(write_file(
                          dir, "loop.ply", "ply\nformat binary_little_endian 1.0\nelement x 1000000000000000000\nend_header\n")),
                      Contains("no properties"));
    const std::string huge_list = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                  "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                  "end_header\n0 0 0\n1 0 0\n0 1 0\n9223372036854775807 0 1 2\n";
    CHECK_THROWS_WITH(fem::io::read_tri_mesh(write_file(dir, "list.ply", huge_list)), Contains("list vertex_indices"));
}

TEST_CASE("TetGen and .pvd: impossible counts and unparsable times are named", "[common][mesh_io]")
{
    const auto dir = fem::test::fresh_output_dir("bad_tetgen");
    write_file(dir, "huge.node", "9999999999 3 0 0\n0 0 0 0\n");
    write_file(dir, "huge.ele", "1 4 0\n0 0 1 2 3\n");
    CHECK_THROWS_WITH(fem::io::read_tet_mesh(dir / "huge.node"), Contains("9999999999 points") && Contains("bytes"));
    write_file(dir, "box.node", "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n");
    write_file(dir, "box.ele", "99999999 4 0\n0 0 1 2 3\n");
    CHECK_THROWS_WITH(fem::io::read_tet_mesh(dir / "box.node"), Contains("99999999 tetrahedra"));
    const auto pvd = write_file(dir, "bad.pvd", "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">"
                                                "<Collection><DataSet timestep=\"x\" file=\"a.vtu\"/></Collection></VTKFile>\n");
    CHECK_THROWS_WITH(fem::io::read_pvd(pvd), Contains("bad.pvd") && Contains("timestep=\"x\""));
}

TEST_CASE("STL: a binary file whose header starts with 'solid' is still checked for its size", "[common][mesh_io]")
{
    const auto dir = fem::test::fresh_output_dir("bad_stl");
    std::string header = "solid exported by a CAD program";
    header.resize(80, ' ');
    const std::uint32_t facets = 4;
    std::string count(4, '\0');
    std::memcpy(count.data(), &facets, 4);  // little-endian on x86, as the format says
    const std::string truncated = header + count + std::string(2 * 50, '\0');  // 2 of the 4 facets
    CHECK_THROWS_WITH(fem::io::read_tri_mesh(write_file(dir, "cut.stl", truncated)),
                      Contains("announces 4 facets") && Contains("binary data"));
}
