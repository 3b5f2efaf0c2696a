// TetGen's .node/.ele pair, read and written. The reader takes both files from TextFiles
// (common/text_file.hpp): the header lines, nodes numbered from 0 or 1 and consecutively,
// attributes and boundary markers read past, counts checked against the file's size before any
// memory is reserved, every error naming the file and the line. The writer writes both files
// (numbered from 0, 17 significant digits) so that they appear together (fem::StagedFiles).
// docs/03_triangle_gradients.md#meshes-from-files
#include "common/mesh_io_internal.hpp"
#include "common/text_file.hpp"

#include "common/error.hpp"
#include "common/files.hpp"

#include <array>
#include <ostream>
#include <string>
#include <vector>

namespace fem::io::detail {

namespace fs = std::filesystem;

TetGenPaths tetgen_paths(const fs::path& path)
{
    const std::string extension = lower_extension(path);
    fs::path stem = path;
    if (extension == ".node" || extension == ".ele")
        stem.replace_extension();
    TetGenPaths paths{stem, stem};
    paths.node += ".node";
    paths.ele += ".ele";
    return paths;
}

namespace {

/// Reads the header line of a TetGen file: one integer per name; the first two are required, the
/// others default to 0 as in TetGen. The first is the file's count of items, refused if negative.
std::vector<long long> tetgen_header(TextFile& file, const std::vector<const char*>& names)
{
    std::string layout;
    for (const char* name : names)
        layout += str(layout.empty() ? "" : " ", "<", name, ">");
    if (!file.next_line())
        throw Error(str(file.name(), ": the file is empty; its first line must be the header '", layout, "'"));
    const auto& t = file.tokens();
    if (t.size() < 2 || t.size() > names.size())
        file.fail(str("the header has ", t.size(), " columns; expected '", layout, "'"));
    std::vector<long long> values;
    for (std::size_t k = 0; k < t.size(); ++k)
        values.push_back(file.integer(t[k], names[k]));
    if (values[0] < 0)
        file.fail(str("the ", names[0], " is negative: ", values[0]));
    values.resize(names.size(), 0);
    return values;
}

/// Checks that an item's number runs on from the first one (0 or 1): returns the base.
void check_item_number(const TextFile& file, long long number, long long index, long long& base,
                       const char* what)
{
    if (index == 0) {
        if (number != 0 && number != 1)
            file.fail(str("the first ", what, " is numbered ", number,
                          "; TetGen files number from 0 or from 1"));
        base = number;
    } else if (number != base + index) {
        file.fail(str(what, " number ", number, " out of sequence: expected ", base + index,
                      " (numbers run consecutively from ", base, ")"));
    }
}

/// fem::Error unless a header's count could fit in the file: every record takes at least
/// min_bytes (e.g. "0 0 0 0\n" for a point), so a count above size / min_bytes is a corrupt header,
/// refused before any memory is reserved for it.
void require_plausible_count(const fs::path& path, long long count, long long min_bytes, const char* what,
                             int header_line)
{
    const auto size = static_cast<long long>(fs::file_size(path));
    if (count > size / min_bytes)
        throw Error(str(path.string(), ", line ", header_line, ": the header announces ", count, " ", what,
                        ", more than a file of ", size, " bytes can hold (at least ", min_bytes, " bytes each)"));
}

}  // namespace

TetMesh read_tetgen(const TetGenPaths& paths, Inverted inverted)
{
    TetMesh mesh;
    std::vector<int> node_lines, tet_lines;
    long long base = 0;
    {
        TextFile node(paths.node, '#');
        const auto header = tetgen_header(node, {"number of points", "dimension", "number of attributes",
                                                 "boundary markers (0 or 1)"});
        const int header_line = node.line();
        if (header[1] != 3)
            node.fail(str("the dimension is ", header[1], "; a tetrahedral mesh needs 3"));
        if (header[2] < 0 || header[3] < 0 || header[3] > 1)
            node.fail("the number of attributes must be ≥ 0 and the boundary marker flag 0 or 1");
        const std::size_t columns = 4 + static_cast<std::size_t>(header[2] + header[3]);
        require_plausible_count(paths.node, header[0], 8, "points", header_line);
        mesh.V.resize(header[0], 3);
        node_lines.reserve(static_cast<std::size_t>(header[0]));
        for (long long i = 0; i < header[0]; ++i) {
            if (!node.next_line())
                throw Error(str(node.name(), ": the file ends after line ", node.line(), " with ", i,
                                " of the ", header[0], " points its header (line ", header_line, ") announces"));
            const auto& t = node.tokens();
            if (t.size() != columns)
                node.fail(str("expected ", columns, " columns (point number, x, y, z",
                              header[2] > 0 ? str(", ", header[2], " attributes") : std::string(),
                              header[3] > 0 ? ", boundary marker" : "", "), got ", t.size()));
            check_item_number(node, node.integer(t[0], "the point number"), i, base, "point");
            for (int c = 0; c < 3; ++c)
                mesh.V(i, c) = node.number(t[c + 1], coordinate_names[c]);
            node_lines.push_back(node.line());
        }
        if (node.next_line())
            node.fail(str("more points follow than the ", header[0], " the header (line ", header_line,
                          ") announces"));
    }
    {
        TextFile ele(paths.ele, '#');
        const auto header = tetgen_header(ele, {"number of tetrahedra", "nodes per tetrahedron",
                                                "region attribute (0 or 1)"});
        const int header_line = ele.line();
        if (header[1] != 4)
            ele.fail(str("tetrahedra with ", header[1], " nodes; only linear tetrahedra (4 nodes) are supported"));
        if (header[2] < 0)
            ele.fail("the number of attributes must be ≥ 0");
        const std::size_t columns = 5 + static_cast<std::size_t>(header[2]);
        require_plausible_count(paths.ele, header[0], 10, "tetrahedra", header_line);
        mesh.T.resize(header[0], 4);
        tet_lines.reserve(static_cast<std::size_t>(header[0]));
        long long tet_base = 0;
        for (long long e = 0; e < header[0]; ++e) {
            if (!ele.next_line())
                throw Error(str(ele.name(), ": the file ends after line ", ele.line(), " with ", e, " of the ",
                                header[0], " tetrahedra its header (line ", header_line, ") announces"));
            const auto& t = ele.tokens();
            if (t.size() != columns)
                ele.fail(str("expected ", columns, " columns (tetrahedron number, 4 nodes",
                             header[2] > 0 ? str(", ", header[2], " attributes") : std::string(), "), got ",
                             t.size()));
            check_item_number(ele, ele.integer(t[0], "the tetrahedron number"), e, tet_base, "tetrahedron");
            for (int k = 0; k < 4; ++k) {
                constexpr std::array<const char*, 4> corner_names{"node 1 of the tetrahedron", "node 2 of the tetrahedron",
                                                                  "node 3 of the tetrahedron", "node 4 of the tetrahedron"};
                const long long v = ele.integer(t[k + 1], corner_names[k]);
                if (v < base || v >= base + mesh.V.rows())
                    ele.fail(str("tetrahedron ", e, " refers to node ", v, "; ", paths.node.string(),
                                 " numbers its ", mesh.V.rows(), " nodes ", base, " to ",
                                 base + mesh.V.rows() - 1));
                mesh.T(e, k) = static_cast<int>(v - base);
            }
            tet_lines.push_back(ele.line());
        }
        if (ele.next_line())
            ele.fail(str("more tetrahedra follow than the ", header[0], " the header (line ", header_line,
                         ") announces"));
    }
    const std::string node_name = paths.node.string(), ele_name = paths.ele.string();
    validate(mesh, MeshOrigin{ele_name,
                              [&](Eigen::Index v) { return str(node_name, ", line ", node_lines[v]); },
                              [&](Eigen::Index e) { return str(ele_name, ", line ", tet_lines[e]); }},
             inverted);
    return mesh;
}

void write_tetgen(const TetGenPaths& paths, const TetMesh& mesh)
{
    // The two files appear together: a new .node never sits beside an old .ele.
    const fs::path folder = paths.node.parent_path();
    if (paths.ele.parent_path() != folder)
        throw Error(str("the TetGen files '", paths.node.string(), "' and '", paths.ele.string(),
                        "' must be in one folder"));
    StagedFiles staged(folder);
    write_text_file(staged.staging() / paths.node.filename(), [&](std::ostream& out) {
        out << "# " << mesh.V.rows() << " points, dimension 3, no attributes, no boundary markers "
            << "(written by fem-course)\n"
            << mesh.V.rows() << " 3 0 0\n";
        for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
            out << v << ' ' << mesh.V(v, 0) << ' ' << mesh.V(v, 1) << ' ' << mesh.V(v, 2) << '\n';
    });
    write_text_file(staged.staging() / paths.ele.filename(), [&](std::ostream& out) {
        out << "# " << mesh.T.rows() << " tetrahedra, 4 nodes each (numbered from 0), no attributes\n"
            << mesh.T.rows() << " 4 0\n";
        for (Eigen::Index t = 0; t < mesh.T.rows(); ++t)
            out << t << ' ' << mesh.T(t, 0) << ' ' << mesh.T(t, 1) << ' ' << mesh.T(t, 2) << ' '
                << mesh.T(t, 3) << '\n';
    });
    staged.publish();
}

}  // namespace fem::io::detail
