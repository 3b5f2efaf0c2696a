// Wavefront .obj surfaces, read and written: the reader takes `v` and `f` records (faces split into
// triangles, indices 1-based or negative, `i/t/n` forms) from a TextFile (common/text_file.hpp),
// naming the line of every error; the writer puts out vertices and triangles with 17 significant
// digits. docs/03_triangle_gradients.md#meshes-from-files
#include "common/mesh_io_internal.hpp"
#include "common/text_file.hpp"

#include "common/error.hpp"

#include <array>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace fem::io::detail {

namespace fs = std::filesystem;

TriMesh read_obj(const fs::path& path)
{
    TextFile file(path, '#');
    std::vector<Eigen::Vector3d> points;
    std::vector<int> vertex_lines;
    std::vector<std::vector<int>> faces;  // corners as written (1-based or negative)
    constexpr std::array<const char*, 3> vertex_coordinate_names{"coordinate x of a vertex", "coordinate y of a vertex",
                                                                 "coordinate z of a vertex"};
    std::vector<int> face_lines;
    while (file.next_line()) {
        const auto& tokens = file.tokens();
        if (tokens[0] == "v") {
            if (tokens.size() < 4)
                file.fail(str("a vertex needs three coordinates 'v x y z', got ", tokens.size() - 1));
            Eigen::Vector3d p;
            for (int c = 0; c < 3; ++c)
                p[c] = file.number(tokens[c + 1], vertex_coordinate_names[c]);
            points.push_back(p);
            vertex_lines.push_back(file.line());
        } else if (tokens[0] == "f") {
            if (tokens.size() < 4)
                file.fail(str("a face needs at least three corners 'f i j k', got ", tokens.size() - 1));
            std::vector<int> corners;
            for (std::size_t k = 1; k < tokens.size(); ++k) {
                const std::string_view token = tokens[k].substr(0, tokens[k].find('/'));
                const long long index = file.integer(token, "a vertex number");
                // Negative numbers count back from the last vertex read so far.
                const long long resolved = index < 0 ? static_cast<long long>(points.size()) + 1 + index
                                                     : index;
                if (index == 0 || resolved < 1)
                    file.fail(str("face corner ", k, " refers to vertex ", index,
                                  "; OBJ numbers vertices from 1 (or from −1 backwards), and ",
                                  points.size(), " vertices precede this line"));
                if (resolved > std::numeric_limits<int>::max())
                    file.fail(str("face corner ", k, " refers to vertex ", index, ", beyond any mesh"));
                corners.push_back(static_cast<int>(resolved));
            }
            faces.push_back(std::move(corners));
            face_lines.push_back(file.line());
        }
        // Other records (vt, vn, vp, g, o, s, usemtl, mtllib, l, p, ...) carry nothing a
        // triangle mesh needs.
    }
    std::vector<std::array<int, 3>> triangles;
    std::vector<int> triangle_lines;
    for (std::size_t f = 0; f < faces.size(); ++f) {
        for (int& corner : faces[f]) {
            if (corner > static_cast<int>(points.size()))
                throw Error(str(file.place(face_lines[f]), ": a face refers to vertex ", corner,
                                "; the file has ", points.size(), " vertices (numbered 1 to ",
                                points.size(), ")"));
            --corner;  // to 0-based
        }
        add_fan(faces[f], face_lines[f], triangles, triangle_lines);
    }
    TriMesh mesh = to_tri_mesh(points, triangles);
    validate(mesh, line_origin(file.name(), vertex_lines, triangle_lines));
    return mesh;
}

void write_obj(const fs::path& path, const TriMesh& mesh)
{
    write_text_file(path, [&](std::ostream& out) {
        out << "# " << mesh.V.rows() << " vertices, " << mesh.F.rows() << " triangles (written by fem-course)\n";
        for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
            out << "v " << mesh.V(v, 0) << ' ' << mesh.V(v, 1) << ' ' << mesh.V(v, 2) << '\n';
        for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
            out << "f " << mesh.F(f, 0) + 1 << ' ' << mesh.F(f, 1) + 1 << ' ' << mesh.F(f, 2) + 1 << '\n';
    });
}

}  // namespace fem::io::detail
