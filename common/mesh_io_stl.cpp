// STL surfaces, read and written. Reading is hand-written: VTK 9.1's STL reader asks for gigabytes on
// a damaged ASCII file, and a binary one shorter than its facet count announces reads as fewer
// facets without an error. A binary file is told from an ASCII one by its size and its bytes; the
// ASCII form is read from a TextFile (common/text_file.hpp). The corners STL repeats in every facet
// are merged into shared vertices. The writer writes binary STL.
// docs/03_triangle_gradients.md#meshes-from-files
#include "common/mesh_io_internal.hpp"
#include "common/text_file.hpp"

#include "common/error.hpp"
#include "common/files.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace fem::io::detail {
namespace {

namespace fs = std::filesystem;

/// A 32-bit little-endian word of a binary STL, in the machine's byte order.
std::uint32_t little_endian_word(const char* bytes)
{
    std::uint32_t word = 0;
    std::memcpy(&word, bytes, 4);
    if constexpr (std::endian::native == std::endian::big)
        word = ((word & 0xffu) << 24) | ((word & 0xff00u) << 8) | ((word >> 8) & 0xff00u) | (word >> 24);
    return word;
}

/// True for a complete binary STL (80-byte header, facet count, 50 bytes per facet, nothing else),
/// false for an ASCII one ("solid" first, no NUL byte in the first 84 bytes), fem::Error otherwise.
bool is_binary_stl(const fs::path& path)
{
    const auto size = fs::file_size(path);
    std::ifstream in(path, std::ios::binary);
    char header[84] = {};
    in.read(header, 84);
    const std::size_t read = static_cast<std::size_t>(std::min<std::uintmax_t>(size, 84));
    const std::uint32_t count = little_endian_word(header + 80);
    if (size >= 84 && size == 84 + 50ull * count)
        return true;
    std::string_view start(header, read);
    start.remove_prefix(std::min(start.find_first_not_of(" \t\r\n"), start.size()));
    // Many CAD exporters start the 80-byte header of a BINARY file with "solid" too: text has no NUL
    // bytes, binary facet data (float zeros, small counts) nearly always has some.
    const bool looks_binary = std::find(header, header + read, '\0') != header + read;
    if (start.substr(0, 5) == "solid" && !looks_binary)
        return false;
    if (size < 84)
        throw Error(str("'", path.string(), "' is not an STL file: ", size,
                        " bytes, too short for a binary STL (84 bytes at least) and not starting with 'solid'"));
    throw Error(str("'", path.string(), "' is not a complete binary STL file: its header announces ", count,
                    " facets (84 + 50·", count, " = ", 84 + 50ull * count, " bytes), the file has ", size,
                    " bytes (truncated?), and it is not ASCII STL (",
                    looks_binary ? "it holds binary data" : "it does not start with 'solid'", ")"));
}

/// The corners of a binary STL's facets, three per facet in file order (the size is checked).
std::vector<Eigen::Vector3d> read_binary_stl(const fs::path& path)
{
    const std::size_t facets = (fs::file_size(path) - 84) / 50;
    std::ifstream in(path, std::ios::binary);
    in.seekg(84);
    std::vector<Eigen::Vector3d> corners;
    corners.reserve(3 * facets);
    char record[50];  // normal, three corners (3 floats each), a 2-byte attribute
    for (std::size_t f = 0; f < facets; ++f) {
        if (!in.read(record, 50))
            throw Error(str("'", path.string(), "': reading facet ", f, " of ", facets, " failed"));
        for (int k = 0; k < 3; ++k) {
            Eigen::Vector3d corner;
            for (int c = 0; c < 3; ++c)
                corner[c] = std::bit_cast<float>(little_endian_word(record + 12 * (k + 1) + 4 * c));
            corners.push_back(corner);
        }
    }
    return corners;
}

/// The corners of an ASCII STL's facets, three per facet in file order, and the line of each facet:
/// `solid [name]`, then per facet `facet normal nx ny nz`, `outer loop`, three `vertex x y z`,
/// `endloop`, `endfacet`, and `endsolid [name]` (one solid after another is allowed).
std::vector<Eigen::Vector3d> read_ascii_stl(const fs::path& path, std::vector<int>& facet_lines)
{
    TextFile file(path, '\0');
    std::vector<Eigen::Vector3d> corners;
    bool in_solid = false;
    // The next line, inside the last facet: `keyword` and `more` tokens after it (`layout`).
    const auto expect = [&](std::string_view keyword, std::size_t more, const char* layout) {
        if (!file.next_line())
            throw Error(str(file.name(), ": the file ends inside facet ", facet_lines.size() - 1, " (line ",
                            facet_lines.back(), "); expected '", layout, "'"));
        const auto& t = file.tokens();
        if (t[0] != keyword || t.size() != more + 1)
            file.fail(str("expected '", layout, "' in facet ", facet_lines.size() - 1, ", got '", t[0], "' and ",
                          t.size() - 1, " more"));
    };
    while (file.next_line()) {
        const auto& t = file.tokens();
        if (!in_solid) {
            if (t[0] != "solid")
                file.fail(str("expected 'solid [name]', got '", t[0], "'"));
            in_solid = true;
        } else if (t[0] == "endsolid") {
            in_solid = false;
        } else if (t[0] == "facet") {
            facet_lines.push_back(file.line());
            if (t.size() != 5 || t[1] != "normal")
                file.fail("expected 'facet normal nx ny nz'");
            for (int c = 0; c < 3; ++c)
                file.number(t[c + 2], "a component of the normal");
            expect("outer", 1, "outer loop");
            for (int k = 0; k < 3; ++k) {
                expect("vertex", 3, "vertex x y z");
                Eigen::Vector3d corner;
                for (int c = 0; c < 3; ++c)
                    corner[c] = file.number(file.tokens()[c + 1], coordinate_names[c]);
                corners.push_back(corner);
            }
            expect("endloop", 0, "endloop");
            expect("endfacet", 0, "endfacet");
        } else {
            file.fail(str("expected 'facet normal nx ny nz' or 'endsolid', got '", t[0], "'"));
        }
    }
    if (in_solid)
        throw Error(str(file.name(), ": the file ends before 'endsolid' (after line ", file.line(), ")"));
    return corners;
}

}  // namespace

TriMesh read_stl(const fs::path& path)
{
    require_readable_file(path);
    const std::string file = path.string();
    std::vector<int> facet_lines;  // ASCII only
    const std::vector<Eigen::Vector3d> corners =
        is_binary_stl(path) ? read_binary_stl(path) : read_ascii_stl(path, facet_lines);
    const auto facet = [&](Eigen::Index f) {
        return facet_lines.empty() ? str(file, ", facet ", f)
                                   : str(file, ", facet ", f, " (line ", facet_lines[static_cast<std::size_t>(f)], ")");
    };

    // Check the facets as written (each its own three corners), so that a message names the facet.
    TriMesh facets;
    facets.V.resize(static_cast<Eigen::Index>(corners.size()), 3);
    facets.F.resize(facets.V.rows() / 3, 3);
    for (Eigen::Index v = 0; v < facets.V.rows(); ++v) {
        facets.V.row(v) = corners[static_cast<std::size_t>(v)].transpose();
        facets.F(v / 3, v % 3) = static_cast<int>(v);
    }
    validate(facets, MeshOrigin{file, [&](Eigen::Index v) { return facet(v / 3); }, facet});

    // STL repeats each corner in every facet that has it: corners at exactly equal positions are one
    // vertex (the coordinates are finite now, so they order strictly).
    std::map<std::array<double, 3>, int> vertex_of;
    std::vector<Eigen::Vector3d> points;
    std::vector<std::array<int, 3>> triangles(static_cast<std::size_t>(facets.F.rows()));
    for (std::size_t v = 0; v < corners.size(); ++v) {
        const auto [at, added] =
            vertex_of.try_emplace({corners[v][0], corners[v][1], corners[v][2]}, static_cast<int>(points.size()));
        if (added)
            points.push_back(corners[v]);
        triangles[v / 3][v % 3] = at->second;
    }
    return to_tri_mesh(points, triangles);
}

void write_binary_stl(const fs::path& path, const TriMesh& mesh)
{
    std::string bytes(80, ' ');
    bytes.replace(0, 24, "binary STL by fem-course");
    append_bytes(bytes, static_cast<std::uint32_t>(mesh.F.rows()));
    for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
        const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
        const Eigen::Vector3f normal = (b - a).cross(c - a).normalized().cast<float>();
        for (const Eigen::Vector3f& v : {normal, Eigen::Vector3f(a.cast<float>()), Eigen::Vector3f(b.cast<float>()),
                                         Eigen::Vector3f(c.cast<float>())})
            for (int k = 0; k < 3; ++k)
                append_bytes(bytes, v[k]);
        append_bytes(bytes, std::uint16_t{0});
    }
    write_file(path, bytes);
}

}  // namespace fem::io::detail
