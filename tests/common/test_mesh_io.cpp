// Mesh files: the bunny reads with its known counts, every format round-trips, and every kind of
// bad file is refused with an fem::Error naming the file, the line (or element) and the problem.
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh.hpp"
#include "common/mesh_io.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {

void write_text(const fs::path& path, const std::string& text)
{
    std::ofstream out(path, std::ios::binary);
    out << text;
}

/// For every vertex of `read`, the vertex of `written` at the same position within `tolerance`
/// (relative to the bounding box), found by brute force; -1 if none or several.
std::vector<int> match_vertices(const fem::MatrixX3d& written, const fem::MatrixX3d& read, double tolerance)
{
    const double scale = (written.colwise().maxCoeff() - written.colwise().minCoeff()).norm();
    std::vector<int> match(read.rows(), -1);
    for (Eigen::Index i = 0; i < read.rows(); ++i)
        for (Eigen::Index j = 0; j < written.rows(); ++j)
            if ((read.row(i) - written.row(j)).norm() <= tolerance * scale)
                match[i] = match[i] == -1 ? static_cast<int>(j) : -2;
    return match;
}

/// A triangle as its vertex numbers rotated to start with the smallest (orientation kept).
std::array<int, 3> canonical(int a, int b, int c)
{
    if (b < a && b < c)
        return {b, c, a};
    if (c < a && c < b)
        return {c, a, b};
    return {a, b, c};
}

/// Checks that `read` is `written` up to a renumbering of the vertices and positions within
/// `tolerance` (relative): same counts, and the same oriented triangles.
void check_same_surface(const fem::TriMesh& written, const fem::TriMesh& read, double tolerance)
{
    REQUIRE(read.V.rows() == written.V.rows());
    REQUIRE(read.F.rows() == written.F.rows());
    const std::vector<int> match = match_vertices(written.V, read.V, tolerance);
    REQUIRE(std::count_if(match.begin(), match.end(), [](int m) { return m < 0; }) == 0);
    std::map<std::array<int, 3>, int> triangles;
    for (Eigen::Index f = 0; f < written.F.rows(); ++f)
        ++triangles[canonical(written.F(f, 0), written.F(f, 1), written.F(f, 2))];
    for (Eigen::Index f = 0; f < read.F.rows(); ++f)
        --triangles[canonical(match[read.F(f, 0)], match[read.F(f, 1)], match[read.F(f, 2)])];
    for (const auto& [triangle, count] : triangles)
        CHECK(count == 0);
}

/// A small tet mesh: a unit cube of 6 tets (8 nodes), as TetGen text with numbering from `base`.
std::string cube_node(int base, const std::string& override_line = "", int line_to_override = -1)
{
    const fem::TetMesh cube = fem::box_mesh(1, 1, 1);
    std::string text = "# a unit cube\n8 3 0 0\n";
    for (int v = 0; v < 8; ++v) {
        std::string line = fem::str(v + base, "  ", cube.V(v, 0), " ", cube.V(v, 1), " ", cube.V(v, 2), "\n");
        text += (v == line_to_override) ? override_line + "\n" : line;
    }
    return text;
}

std::string cube_ele(int base, const std::string& override_line = "", int line_to_override = -1)
{
    const fem::TetMesh cube = fem::box_mesh(1, 1, 1);
    std::string text = "6 4 0\n";
    for (int t = 0; t < 6; ++t) {
        std::string line = fem::str(t + base, " ", cube.T(t, 0) + base, " ", cube.T(t, 1) + base, " ",
                                    cube.T(t, 2) + base, " ", cube.T(t, 3) + base, "\n");
        text += (t == line_to_override) ? override_line + "\n" : line;
    }
    return text;
}

}  // namespace

TEST_CASE("the bunny reads with its known counts: 1839 vertices, 3674 triangles, closed", "[common][mesh_io]")
{
    const fem::TriMesh bunny = fem::io::read_tri_mesh(fem::data_path("bunny.obj"));
    CHECK(bunny.V.rows() == 1839);
    CHECK(bunny.F.rows() == 3674);
    // Closed and manifold: every edge is shared by exactly two triangles, in opposite directions,
    // and the Euler characteristic V − E + F is 2 (a sphere).
    std::map<std::pair<int, int>, int> directed;
    for (Eigen::Index f = 0; f < bunny.F.rows(); ++f)
        for (int k = 0; k < 3; ++k)
            ++directed[{bunny.F(f, k), bunny.F(f, (k + 1) % 3)}];
    for (const auto& [edge, count] : directed) {
        CHECK(count == 1);
        CHECK(directed.count({edge.second, edge.first}) == 1);
    }
    const long edges = static_cast<long>(directed.size()) / 2;
    CHECK(bunny.V.rows() - edges + bunny.F.rows() == 2);
    // The first vertex as the file writes it.
    CHECK(bunny.V(0, 0) == 1.301895);
    CHECK(bunny.V(0, 2) == 2.550061);
}

TEST_CASE("a surface written as .obj, .vtu, .stl and .ply reads back as the same mesh", "[common][mesh_io]")
{
    const auto dir = fem::test::fresh_output_dir("mesh_io_roundtrip");
    const fem::TriMesh bunny = fem::io::read_tri_mesh(fem::data_path("bunny.obj"));

    SECTION("OBJ and VTU keep every bit")
    {
        for (const char* name : {"bunny.obj", "bunny.vtu"}) {
            fem::io::write_tri_mesh(dir / name, bunny);
            const fem::TriMesh back = fem::io::read_tri_mesh(dir / name);
            CHECK(back.V == bunny.V);
            CHECK(back.F == bunny.F);
        }
    }
    SECTION("STL and PLY store 32-bit floats: the same mesh within float precision")
    {
        for (const char* name : {"bunny.stl", "bunny.ply"}) {
            fem::io::write_tri_mesh(dir / name, bunny);
            const fem::TriMesh back = fem::io::read_tri_mesh(dir / name);
            check_same_surface(bunny, back, 1e-7);
            CHECK_FALSE(back.V == bunny.V);  // rounded to float: not bit-identical
        }
    }
    SECTION("a mesh with distinct vertex positions survives STL's merging of corners")
    {
        const fem::TriMesh square = fem::square_mesh(5, 0.2, 3);
        fem::io::write_tri_mesh(dir / "square.stl", square);
        check_same_surface(square, fem::io::read_tri_mesh(dir / "square.stl"), 1e-7);
    }
}

TEST_CASE("a tet mesh written as .node/.ele and .vtu reads back exactly", "[common][mesh_io]")
{
    const auto dir = fem::test::fresh_output_dir("mesh_io_tets");
    fem::TetMesh box = fem::box_mesh(3, 2, 2, Eigen::Vector3d(0.3, 1.0 / 3.0, 0.7));
    box.V.col(2) += 0.01 * box.V.col(0).array().sin().matrix();  // positions with every bit set
    for (const char* name : {"box.node", "box.vtu"}) {
        fem::io::write_tet_mesh(dir / name, box);
        const fem::TetMesh back = fem::io::read_tet_mesh(dir / name);
        CHECK(back.V == box.V);
        CHECK(back.T == box.T);
    }
    CHECK(fs::is_regular_file(dir / "box.ele"));
    // The pair can be named by either file or by its stem.
    CHECK(fem::io::read_tet_mesh(dir / "box.ele").T == box.T);
    CHECK(fem::io::read_tet_mesh(dir / "box").T == box.T);
}

TEST_CASE("TetGen files numbered from 1 read like those numbered from 0", "[common][mesh_io]")
{
    const auto dir = fem::test::fresh_output_dir("mesh_io_tetgen_base");
    write_text(dir / "zero.node", cube_node(0));
    write_text(dir / "zero.ele", cube_ele(0));
    write_text(dir / "one.node", cube_node(1));
    write_text(dir / "one.ele", cube_ele(1));
    const fem::TetMesh zero = fem::io::read_tet_mesh(dir / "zero.node");
    const fem::TetMesh one = fem::io::read_tet_mesh(dir / "one.node");
    const fem::TetMesh cube = fem::box_mesh(1, 1, 1);
    CHECK(zero.V == cube.V);
    CHECK(zero.T == cube.T);
    CHECK(one.V == cube.V);
    CHECK(one.T == cube.T);
    CHECK(fem::total_volume(one) == Approx(1.0));
}

TEST_CASE("bad TetGen files name the file, the line and what was expected", "[common][mesh_io]")
{
    const auto dir = fem::test::fresh_output_dir("mesh_io_tetgen_bad");
    const auto write_pair = [&](const std::string& node, const std::string& ele) {
        write_text(dir / "bad.node", node);
        write_text(dir / "bad.ele", ele);
        return dir / "bad.node";
    };

    CHECK_THROWS_WITH(fem::io::read_tet_mesh(dir / "missing.node"),
                      Contains("missing.node") && Contains("no such file"));
    write_text(dir / "lonely.node", cube_node(0));
    CHECK_THROWS_WITH(fem::io::read_tet_mesh(dir / "lonely.node"),
                      Contains("lonely.ele") && Contains("no such file"));

    SECTION("truncated .node")
    {
        std::string node = cube_node(0);
        node = node.substr(0, node.find("\n5 "));  // keeps points 0..4 of 8
        CHECK_THROWS_WITH(fem::io::read_tet_mesh(write_pair(node, cube_ele(0))),
                          Contains("bad.node") && Contains("ends after line 7") && Contains("5 of the 8 points") &&
                              Contains("line 2"));
    }
    SECTION("a point line with a missing coordinate")
    {
        CHECK_THROWS_WITH(fem::io::read_tet_mesh(write_pair(cube_node(0, "3 1.0 1.0", 3), cube_ele(0))),
                          Contains("bad.node, line 6") && Contains("expected 4 columns") && Contains("got 3"));
    }
    SECTION("a tetrahedron line with too few nodes")
    {
        CHECK_THROWS_WITH(fem::io::read_tet_mesh(write_pair(cube_node(0), cube_ele(0, "2 0 1 3", 2))),
                          Contains("bad.ele, line 4") && Contains("expected 5 columns") && Contains("got 4"));
    }
    SECTION("a node number out of range in .ele")
    {
        CHECK_THROWS_WITH(fem::io::read_tet_mesh(write_pair(cube_node(1), cube_ele(1, "4 1 2 9 5", 3))),
                          Contains("bad.ele, line 5") && Contains("tetrahedron 3") && Contains("node 9") &&
                              Contains("1 to 8"));
        // 0 is out of range when the nodes are numbered from 1.
        CHECK_THROWS_WITH(fem::io::read_tet_mesh(write_pair(cube_node(1), cube_ele(1, "1 0 2 3 4", 0))),
                          Contains("bad.ele, line 2") && Contains("node 0"));
    }
    SECTION("a NaN coordinate")
    {
        CHECK_THROWS_WITH(fem::io::read_tet_mesh(write_pair(cube_node(0, "2 0 nan 0", 2), cube_ele(0))),
                          Contains("bad.node, line 5") && Contains("vertex 2") && Contains("non-finite"));
    }
    SECTION("a coordinate that is not a number")
    {
        CHECK_THROWS_WITH(fem::io::read_tet_mesh(write_pair(cube_node(0, "2 0 1,5 0", 2), cube_ele(0))),
                          Contains("bad.node, line 5") && Contains("coordinate y") && Contains("'1,5'"));
    }
    SECTION("node numbers out of sequence, or not from 0 or 1")
    {
        CHECK_THROWS_WITH(fem::io::read_tet_mesh(write_pair(cube_node(0, "7 1 0 0", 1), cube_ele(0))),
                          Contains("bad.node, line 4") && Contains("expected 1"));
        CHECK_THROWS_WITH(fem::io::read_tet_mesh(write_pair(cube_node(2), cube_ele(0))),
                          Contains("bad.node, line 3") && Contains("from 0 or from 1"));
    }
    SECTION("a wrong header")
    {
        std::string node = cube_node(0);
        node.replace(node.find("8 3 0 0"), 7, "8 2 0 0");
        CHECK_THROWS_WITH(fem::io::read_tet_mesh(write_pair(node, cube_ele(0))),
                          Contains("bad.node, line 2") && Contains("dimension is 2"));
        std::string ele = cube_ele(0);
        ele.replace(0, 5, "6 10 0");
        CHECK_THROWS_WITH(fem::io::read_tet_mesh(write_pair(cube_node(0), ele)),
                          Contains("bad.ele, line 1") && Contains("10 nodes"));
        CHECK_THROWS_WITH(fem::io::read_tet_mesh(write_pair(cube_node(0) + "8 0 0 0\n", cube_ele(0))),
                          Contains("bad.node, line 11") && Contains("more points"));
    }
    SECTION("a degenerate tetrahedron")
    {
        // Nodes 0, 1, 2, 3 of the box are corners of the bottom face z = 0: a flat tet.
        CHECK_THROWS_WITH(fem::io::read_tet_mesh(write_pair(cube_node(0), cube_ele(0, "5 0 1 2 3", 5))),
                          Contains("bad.ele, line 7") && Contains("tetrahedron 5") && Contains("zero volume"));
    }
    SECTION("an inverted tetrahedron: rejected, or re-oriented when asked")
    {
        const fem::TetMesh cube = fem::box_mesh(1, 1, 1);
        const std::string swapped = fem::str("4 ", cube.T(4, 1), " ", cube.T(4, 0), " ", cube.T(4, 2), " ", cube.T(4, 3));
        const auto path = write_pair(cube_node(0), cube_ele(0, swapped, 4));
        CHECK_THROWS_WITH(fem::io::read_tet_mesh(path),
                          Contains("bad.ele, line 6") && Contains("tetrahedron 4") && Contains("inverted"));
        const fem::TetMesh repaired = fem::io::read_tet_mesh(path, fem::Inverted::reorient);
        CHECK(fem::tet_signed_volume6(repaired, 4) > 0.0);
        CHECK(fem::total_volume(repaired) == Approx(1.0));
    }
}

TEST_CASE("bad OBJ files name the file, the line and what was expected", "[common][mesh_io]")
{
    const auto dir = fem::test::fresh_output_dir("mesh_io_obj_bad");
    const std::string head = "# square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";
    const auto read = [&](const std::string& text) {
        write_text(dir / "bad.obj", text);
        return fem::io::read_tri_mesh(dir / "bad.obj");
    };
    CHECK_THROWS_WITH(fem::io::read_tri_mesh(dir / "missing.obj"), Contains("missing.obj") && Contains("no such file"));
    CHECK_THROWS_WITH(read(head + "f 1 2 3\nf 1 3 7\n"),
                      Contains("bad.obj, line 7") && Contains("vertex 7") && Contains("4 vertices"));
    CHECK_THROWS_WITH(read("v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n"),
                      Contains("bad.obj, line 2") && Contains("vertex 1") && Contains("non-finite"));
    CHECK_THROWS_WITH(read("v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n"),
                      Contains("bad.obj, line 2") && Contains("three coordinates"));
    CHECK_THROWS_WITH(read(head + "f 1 2\n"), Contains("bad.obj, line 6") && Contains("three corners"));
    CHECK_THROWS_WITH(read(head + "f 0 1 2\n"), Contains("bad.obj, line 6") && Contains("from 1"));
    CHECK_THROWS_WITH(read(head + "f 1 2 x\n"), Contains("bad.obj, line 6") && Contains("'x'"));
    CHECK_THROWS_WITH(read(head + "f 1 2 3\nf 1 2 1\n"), Contains("bad.obj, line 7") && Contains("twice"));
    CHECK_THROWS_WITH(read("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"),
                      Contains("bad.obj, line 4") && Contains("zero area"));
    CHECK_THROWS_WITH(read("v 0 0 0\n"), Contains("bad.obj") && Contains("empty"));

    // Polygons are split into triangles; negative and slashed indices are understood.
    const fem::TriMesh quad = read(head + "vt 0 0\nvn 0 0 1\nf 1/1/1 2//1 -2 -1/1\n");
    CHECK(quad.F.rows() == 2);
    CHECK(quad.F.row(0) == Eigen::RowVector3i(0, 1, 2));
    CHECK(quad.F.row(1) == Eigen::RowVector3i(0, 2, 3));
}

TEST_CASE("bad PLY files are refused, never crash, and name the line or element", "[common][mesh_io]")
{
    const auto dir = fem::test::fresh_output_dir("mesh_io_ply_bad");
    const std::string header = "ply\nformat ascii 1.0\ncomment a square\nelement vertex 4\nproperty float x\n"
                               "property float y\nproperty float z\nelement face 2\n"
                               "property list uchar int vertex_indices\nend_header\n";
    const std::string vertices = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n";
    const auto read = [&](const std::string& text) {
        write_text(dir / "bad.ply", text);
        return fem::io::read_tri_mesh(dir / "bad.ply");
    };
    const fem::TriMesh good = read(header + vertices + "3 0 1 2\n3 0 2 3\n");
    CHECK(good.F.rows() == 2);
    CHECK(good.V(2, 1) == 1.0);
    // VTK 9.1's own PLY reader aborts the process on this truncated file.
    CHECK_THROWS_WITH(read(header + vertices + "3 0 1 2\n"),
                      Contains("bad.ply") && Contains("ends at line 15") && Contains("face 1 of the 2"));
    CHECK_THROWS_WITH(read(header + vertices + "3 0 1 2\n3 0 2 4\n"),
                      Contains("bad.ply, line 16") && Contains("vertex 4") && Contains("0 to 3"));
    CHECK_THROWS_WITH(read(header + "0 0 0\n1 nan 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n"),
                      Contains("bad.ply, line 12") && Contains("vertex 1") && Contains("non-finite"));
    CHECK_THROWS_WITH(read(header + "0 0 0\n1 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n"),
                      Contains("bad.ply, line 12") && Contains("too few values"));
    CHECK_THROWS_WITH(read("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n"),
                      Contains("bad.ply, line 3") && Contains("no property y"));
    CHECK_THROWS_WITH(read("solid nonsense\n"), Contains("bad.ply") && Contains("not a PLY file"));

    // A binary file cut short.
    const fem::TriMesh bunny = fem::io::read_tri_mesh(fem::data_path("bunny.obj"));
    fem::io::write_tri_mesh(dir / "bunny.ply", bunny);
    const auto size = fs::file_size(dir / "bunny.ply");
    fs::resize_file(dir / "bunny.ply", size - 100);
    CHECK_THROWS_WITH(fem::io::read_tri_mesh(dir / "bunny.ply"),
                      Contains("bunny.ply") && Contains("binary data ends inside face"));
}

TEST_CASE("PLY: either byte order, any numeric types, extra properties and elements skipped", "[common][mesh_io]")
{
    const auto dir = fem::test::fresh_output_dir("mesh_io_ply_kinds");
    const fem::TriMesh square = fem::square_mesh(2, 0.2, 5);
    // Big-endian binary: vertices as (double x, double y, double z, uchar flag), faces as a list of
    // ushort with an int count, then an element nobody asked for.
    std::string text = fem::str("ply\nformat binary_big_endian 1.0\nelement vertex ", square.V.rows(),
                                "\nproperty double x\nproperty double y\nproperty double z\nproperty uchar flag\n"
                                "element face ", square.F.rows(),
                                "\nproperty list int ushort vertex_indices\nelement extra 1\nproperty short s\n"
                                "end_header\n");
    const auto big_endian = [&](const void* data, int bytes) {
        const auto* b = static_cast<const char*>(data);
        for (int k = bytes - 1; k >= 0; --k)
            text += b[k];  // the machines we build on are little-endian
    };
    for (Eigen::Index v = 0; v < square.V.rows(); ++v) {
        for (int c = 0; c < 3; ++c)
            big_endian(&square.V(v, c), 8);
        text += '\x07';
    }
    for (Eigen::Index f = 0; f < square.F.rows(); ++f) {
        const std::int32_t count = 3;
        big_endian(&count, 4);
        for (int k = 0; k < 3; ++k) {
            const std::uint16_t index = static_cast<std::uint16_t>(square.F(f, k));
            big_endian(&index, 2);
        }
    }
    text += std::string("\xff\xfe", 2);
    write_text(dir / "big.ply", text);
    const fem::TriMesh back = fem::io::read_tri_mesh(dir / "big.ply");
    CHECK(back.V == square.V);
    CHECK(back.F == square.F);

    // ASCII with a quad, a normal per vertex and a colour per face.
    write_text(dir / "quad.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float nx\nproperty float x\n"
                                 "property float y\nproperty float z\nelement face 1\nproperty uchar red\n"
                                 "property list uchar uint vertex_index\nend_header\n"
                                 "9 0 0 0\n9 1 0 0\n9 1 1 0\n9 0 1 0\n255 4 0 1 2 3\n");
    const fem::TriMesh quad = fem::io::read_tri_mesh(dir / "quad.ply");
    CHECK(quad.V.col(0).sum() == 2.0);
    CHECK(quad.F.rows() == 2);
    CHECK(quad.F.row(1) == Eigen::RowVector3i(0, 2, 3));
}

TEST_CASE("bad STL files are refused, naming the facet", "[common][mesh_io]")
{
    const auto dir = fem::test::fresh_output_dir("mesh_io_stl_bad");
    const auto facet = [](const char* a, const char* b, const char* c) {
        return fem::str(" facet normal 0 0 1\n  outer loop\n   vertex ", a, "\n   vertex ", b, "\n   vertex ", c,
                        "\n  endloop\n endfacet\n");
    };
    const auto read = [&](const std::string& text) {
        write_text(dir / "bad.stl", text);
        return fem::io::read_tri_mesh(dir / "bad.stl");
    };
    const fem::TriMesh good = read("solid s\n" + facet("0 0 0", "1 0 0", "0 1 0") + facet("1 0 0", "1 1 0", "0 1 0") +
                                   "endsolid s\n");
    CHECK(good.V.rows() == 4);  // the shared corners are merged
    CHECK(good.F.rows() == 2);
    CHECK_THROWS_WITH(read("solid s\n" + facet("0 0 0", "1 0 0", "0 1 0") + facet("1 0 0", "1 nan 0", "0 1 0") +
                           "endsolid s\n"),
                      Contains("bad.stl, facet 1") && Contains("non-finite"));
    CHECK_THROWS_WITH(read("solid s\n" + facet("0 0 0", "1 0 0", "0 1 0") + facet("1 0 0", "2 0 0", "3 0 0") +
                           "endsolid s\n"),
                      Contains("bad.stl, facet 1") && Contains("zero area"));
    CHECK_THROWS_WITH(read("solid s\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n"),
                      Contains("bad.stl") && Contains("ends inside facet 0") && Contains("vertex x y z"));
    CHECK_THROWS_WITH(read("solid s\n" + facet("0 0 0", "1 0 0", "0 1 0") + "endsolid s\n" +
                           facet("1 0 0", "1 1 0", "0 1 0")),
                      Contains("bad.stl, line 10") && Contains("expected 'solid [name]'"));
    CHECK_THROWS_WITH(read("solid s\n" + facet("0 0 0", "1 0 0", "0 1 0")),
                      Contains("bad.stl") && Contains("ends before 'endsolid'"));

    const fem::TriMesh bunny = fem::io::read_tri_mesh(fem::data_path("bunny.obj"));
    fem::io::write_tri_mesh(dir / "bunny.stl", bunny);
    fs::resize_file(dir / "bunny.stl", fs::file_size(dir / "bunny.stl") - 30);
    CHECK_THROWS_WITH(fem::io::read_tri_mesh(dir / "bunny.stl"),
                      Contains("bunny.stl") && Contains("3674 facets") && Contains("truncated"));
    CHECK_THROWS_WITH(fem::io::read_tri_mesh(dir / "missing.stl"), Contains("missing.stl") && Contains("no such file"));
}

TEST_CASE("mesh files: unknown types, wrong cell kinds, and writes that fail leave nothing", "[common][mesh_io]")
{
    const auto dir = fem::test::fresh_output_dir("mesh_io_misc");
    const fem::TriMesh square = fem::square_mesh(2);
    CHECK_THROWS_WITH(fem::io::write_tri_mesh(dir / "square.off", square), Contains(".off") && Contains(".obj"));
    CHECK_THROWS_WITH(fem::io::read_tri_mesh(dir / "square.off"), Contains("unknown mesh file type"));

    // A .vtu of triangles is no tet mesh, and the reverse.
    fem::io::write_tri_mesh(dir / "square.vtu", square);
    CHECK_THROWS_WITH(fem::io::read_tet_mesh(dir / "square.vtu"), Contains("cells of 3 points"));
    fem::io::write_tet_mesh(dir / "cube.vtu", fem::box_mesh(1, 1, 1));
    CHECK_THROWS_WITH(fem::io::read_tri_mesh(dir / "cube.vtu"), Contains("cells of 4 points"));

    // Invalid meshes are refused before anything is written.
    fem::TriMesh bad = square;
    bad.V(4, 0) = std::nan("");
    for (const char* name : {"bad.obj", "bad.stl", "bad.ply", "bad.vtu"}) {
        CHECK_THROWS_WITH(fem::io::write_tri_mesh(dir / name, bad), Contains("non-finite"));
        CHECK_FALSE(fs::exists(dir / name));
    }
    fem::TetMesh inverted = fem::box_mesh(1, 1, 1);
    std::swap(inverted.T(0, 0), inverted.T(0, 1));
    CHECK_THROWS_WITH(fem::io::write_tet_mesh(dir / "inverted.node", inverted), Contains("inverted"));
    CHECK_FALSE(fs::exists(dir / "inverted.node"));
    CHECK_FALSE(fs::exists(dir / "inverted.ele"));
    // Writes create missing folders and leave no temporary files behind.
    fem::io::write_tri_mesh(dir / "sub" / "square.obj", square);
    CHECK(std::distance(fs::directory_iterator(dir / "sub"), fs::directory_iterator()) == 1);
}
