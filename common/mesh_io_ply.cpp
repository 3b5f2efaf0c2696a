// PLY surfaces, read and written. Reading is hand-written (VTK 9.1's PLY reader aborts the process
// on a truncated ASCII file): the header's elements and properties, then their values from text
// tokens (a TextFile, common/text_file.hpp) or binary data of either byte order; the elements vertex
// (x, y, z) and face (the list vertex_indices) make the surface, others are read past. The writer
// writes binary little-endian PLY. docs/03_triangle_gradients.md#meshes-from-files
#include "common/mesh_io_internal.hpp"
#include "common/text_file.hpp"

#include "common/error.hpp"
#include "common/files.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace fem::io::detail {
namespace {

namespace fs = std::filesystem;

enum class PlyFormat { ascii, binary_little_endian, binary_big_endian };

/// The longest PLY list the reader accepts (a face with more corners is no surface we can use; a
/// larger number is a corrupt file, and a cast of it to an integer would overflow).
constexpr double max_ply_list_length = 1e6;

struct PlyType {
    int bytes = 0;
    bool is_signed = false;
    bool is_float = false;
};

PlyType ply_type(const TextFile& file, std::string_view name)
{
    if (name == "char" || name == "int8") return {1, true, false};
    if (name == "uchar" || name == "uint8") return {1, false, false};
    if (name == "short" || name == "int16") return {2, true, false};
    if (name == "ushort" || name == "uint16") return {2, false, false};
    if (name == "int" || name == "int32") return {4, true, false};
    if (name == "uint" || name == "uint32") return {4, false, false};
    if (name == "float" || name == "float32") return {4, true, true};
    if (name == "double" || name == "float64") return {8, true, true};
    file.fail(str("unknown PLY property type '", name,
                  "'; PLY allows char, uchar, short, ushort, int, uint, float, double (or int8 ... float64)"));
}

struct PlyProperty {
    std::string name;
    PlyType type;
    bool is_list = false;
    PlyType count_type;
};

struct PlyElement {
    std::string name;
    long long count = 0;
    int header_line = 0;
    std::vector<PlyProperty> properties;
};

/// Reads PLY values one at a time, from text tokens or from binary data.
class PlyValues {
public:
    PlyValues(TextFile& file, PlyFormat format) : file_(file), format_(format) {}

    /// Starts element instance `index` of `element` (ASCII: reads its line).
    void begin(const PlyElement& element, long long index)
    {
        element_ = &element;
        index_ = index;
        if (format_ == PlyFormat::ascii) {
            if (!file_.next_line())
                throw Error(str(file_.name(), ": the file ends at line ", file_.line(), " before ",
                                element.name, " ", index, " of the ", element.count,
                                " its header (line ", element.header_line, ") announces"));
            next_token_ = 0;
        }
    }

    /// Checks that an ASCII line held no more values than its element's properties.
    void end()
    {
        if (format_ == PlyFormat::ascii && next_token_ != file_.tokens().size())
            file_.fail(str(element_->name, " ", index_, " has ", file_.tokens().size(),
                           " values, but its properties (header line ", element_->header_line,
                           ") take ", next_token_));
    }

    double value(const PlyType& type, const std::string& what)
    {
        if (format_ == PlyFormat::ascii) {
            const auto& tokens = file_.tokens();
            if (next_token_ >= tokens.size())
                file_.fail(str(element_->name, " ", index_, " has too few values: ", what, " is missing (",
                               tokens.size(), " values on the line)"));
            const std::string_view token = tokens[next_token_++];
            return type.is_float ? file_.number(token, what)
                                 : static_cast<double>(file_.integer(token, what));
        }
        unsigned char bytes[8];
        if (!file_.read_bytes(bytes, static_cast<std::size_t>(type.bytes)))
            throw Error(str(file_.name(), ": the binary data ends inside ", element_->name, " ", index_,
                            " of the ", element_->count, " its header (line ", element_->header_line,
                            ") announces (reading ", what, ")"));
        const bool swap = (format_ == PlyFormat::binary_big_endian) != (std::endian::native == std::endian::big);
        if (swap)
            std::reverse(bytes, bytes + type.bytes);
        if (type.is_float) {
            if (type.bytes == 4) {
                float f;
                std::memcpy(&f, bytes, 4);
                return f;
            }
            double d;
            std::memcpy(&d, bytes, 8);
            return d;
        }
        std::uint64_t u = 0;
        for (int b = type.bytes - 1; b >= 0; --b)
            u = (u << 8) | bytes[b];  // bytes are little-endian now
        if (type.is_signed && (u >> (8 * type.bytes - 1)) != 0)
            return static_cast<double>(static_cast<std::int64_t>(u) - (std::int64_t(1) << (8 * type.bytes)));
        return static_cast<double>(u);
    }

    /// The place of the current element instance, for messages.
    std::string place() const
    {
        return format_ == PlyFormat::ascii ? file_.place()
                                           : str(file_.name(), ", ", element_->name, " ", index_);
    }

private:
    TextFile& file_;
    PlyFormat format_;
    const PlyElement* element_ = nullptr;
    long long index_ = 0;
    std::size_t next_token_ = 0;
};

}  // namespace

TriMesh read_ply(const fs::path& path)
{
    TextFile file(path, '\0');
    if (!file.next_line() || file.tokens()[0] != "ply")
        throw Error(str(file.name(), ": not a PLY file (the first line must be 'ply')"));
    PlyFormat format = PlyFormat::ascii;
    bool have_format = false;
    std::vector<PlyElement> elements;
    while (true) {
        if (!file.next_line())
            throw Error(str(file.name(), ": the header has no 'end_header' line"));
        const auto& t = file.tokens();
        if (t[0] == "end_header")
            break;
        if (t[0] == "comment" || t[0] == "obj_info")
            continue;
        if (t[0] == "format") {
            if (t.size() != 3)
                file.fail("expected 'format <ascii|binary_little_endian|binary_big_endian> 1.0'");
            if (t[1] == "ascii") format = PlyFormat::ascii;
            else if (t[1] == "binary_little_endian") format = PlyFormat::binary_little_endian;
            else if (t[1] == "binary_big_endian") format = PlyFormat::binary_big_endian;
            else file.fail(str("unknown PLY format '", t[1], "'; expected ascii, binary_little_endian or binary_big_endian"));
            have_format = true;
        } else if (t[0] == "element") {
            if (t.size() != 3)
                file.fail("expected 'element <name> <count>'");
            const long long count = file.integer(t[2], "the element count");
            if (count < 0)
                file.fail(str("element count ", count, " is negative"));
            elements.push_back({std::string(t[1]), count, file.line(), {}});
        } else if (t[0] == "property") {
            if (elements.empty())
                file.fail("a property before any element");
            PlyProperty property;
            if (t.size() == 5 && t[1] == "list") {
                property = {std::string(t[4]), ply_type(file, t[3]), true, ply_type(file, t[2])};
                if (property.count_type.is_float)
                    file.fail("a list's count type must be an integer type");
            } else if (t.size() == 3) {
                property = {std::string(t[2]), ply_type(file, t[1]), false, {}};
            } else {
                file.fail("expected 'property <type> <name>' or 'property list <count type> <item type> <name>'");
            }
            elements.back().properties.push_back(property);
        } else {
            file.fail(str("unexpected '", t[0], "' in the PLY header"));
        }
    }
    if (!have_format)
        throw Error(str(file.name(), ": the header has no 'format' line"));

    std::vector<Eigen::Vector3d> points;
    std::vector<int> vertex_lines;
    std::vector<std::array<int, 3>> triangles;
    std::vector<int> triangle_lines;
    std::vector<std::vector<int>> faces;
    std::vector<int> face_lines;
    std::vector<std::string> face_places;
    bool have_vertices = false, have_faces = false;
    PlyValues values(file, format);
    for (const PlyElement& element : elements) {
        const bool is_vertex = element.name == "vertex", is_face = element.name == "face";
        int coordinate[3] = {-1, -1, -1};
        int indices = -1;
        for (std::size_t p = 0; p < element.properties.size(); ++p) {
            const PlyProperty& property = element.properties[p];
            for (int c = 0; c < 3; ++c)
                if (is_vertex && !property.is_list && property.name == std::string(1, "xyz"[c]))
                    coordinate[c] = static_cast<int>(p);
            if (is_face && property.is_list && (property.name == "vertex_indices" || property.name == "vertex_index"))
                indices = static_cast<int>(p);
        }
        if (is_vertex) {
            have_vertices = true;
            for (int c = 0; c < 3; ++c)
                if (coordinate[c] < 0)
                    throw Error(str(file.place(element.header_line), ": element vertex has no property ",
                                    "xyz"[c], "; a PLY surface needs x, y and z"));
        }
        if (is_face) {
            have_faces = true;
            if (indices < 0)
                throw Error(str(file.place(element.header_line),
                                ": element face has no list property vertex_indices (or vertex_index)"));
        }
        if (element.properties.empty() && element.count > 0)
            throw Error(str(file.place(element.header_line), ": element ", element.name, " has ", element.count,
                            " entries but no properties; every PLY element needs at least one property"));
        for (long long i = 0; i < element.count; ++i) {
            values.begin(element, i);
            Eigen::Vector3d point = Eigen::Vector3d::Zero();
            std::vector<int> corners;
            for (std::size_t p = 0; p < element.properties.size(); ++p) {
                const PlyProperty& property = element.properties[p];
                if (!property.is_list) {
                    const double value = values.value(property.type, str("property ", property.name));
                    for (int c = 0; c < 3; ++c)
                        if (static_cast<int>(p) == coordinate[c])
                            point[c] = value;
                    continue;
                }
                const double count = values.value(property.count_type, str("the length of list ", property.name));
                if (!(count >= 0 && count <= max_ply_list_length))
                    throw Error(str(values.place(), ": list ", property.name, " has length ", count,
                                    "; allowed are 0 to ", max_ply_list_length));
                for (long long k = 0; k < static_cast<long long>(count); ++k) {
                    const double item = values.value(property.type, str("item ", k, " of list ", property.name));
                    if (static_cast<int>(p) == indices) {
                        if (!(item >= 0 && item < static_cast<double>(std::numeric_limits<int>::max()) &&
                              item == std::floor(item)))
                            throw Error(str(values.place(), ": face ", i, " refers to vertex ", item,
                                            "; PLY numbers vertices from 0"));
                        corners.push_back(static_cast<int>(item));
                    }
                }
            }
            values.end();
            if (is_vertex) {
                points.push_back(point);
                vertex_lines.push_back(file.line());
            }
            if (is_face) {
                if (corners.size() < 3)
                    throw Error(str(values.place(), ": face ", i, " has ", corners.size(),
                                    " corners; at least 3 are needed"));
                faces.push_back(std::move(corners));
                face_lines.push_back(file.line());
                face_places.push_back(values.place());
            }
        }
    }
    if (!have_vertices || !have_faces)
        throw Error(str(file.name(), ": a PLY surface needs the elements vertex and face; the header declares ",
                        have_vertices ? "no face" : "no vertex"));
    for (std::size_t f = 0; f < faces.size(); ++f) {
        for (int corner : faces[f])
            if (corner >= static_cast<int>(points.size()))
                throw Error(str(face_places[f], ": face ", f, " refers to vertex ", corner, "; the file has ",
                                points.size(), " vertices (numbered 0 to ", points.size() - 1, ")"));
        add_fan(faces[f], static_cast<int>(f), triangles, triangle_lines);  // here: the face number
    }
    TriMesh mesh = to_tri_mesh(points, triangles);
    if (format == PlyFormat::ascii) {
        std::vector<int> element_lines;
        for (int face : triangle_lines)
            element_lines.push_back(face_lines[static_cast<std::size_t>(face)]);
        validate(mesh, line_origin(file.name(), vertex_lines, element_lines));
    } else {
        const std::string name = file.name();
        validate(mesh, MeshOrigin{name, [&](Eigen::Index v) { return str(name, ", vertex ", v); },
                                  [&](Eigen::Index t) {
                                      return str(name, ", face ", triangle_lines[static_cast<std::size_t>(t)]);
                                  }});
    }
    return mesh;
}

void write_binary_ply(const fs::path& path, const TriMesh& mesh)
{
    std::string bytes = str("ply\nformat binary_little_endian 1.0\ncomment written by fem-course\nelement vertex ",
                            mesh.V.rows(), "\nproperty float x\nproperty float y\nproperty float z\nelement face ",
                            mesh.F.rows(), "\nproperty list uchar int vertex_indices\nend_header\n");
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
        for (int k = 0; k < 3; ++k)
            append_bytes(bytes, static_cast<float>(mesh.V(v, k)));
    for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
        append_bytes(bytes, std::uint8_t{3});
        for (int k = 0; k < 3; ++k)
            append_bytes(bytes, static_cast<std::int32_t>(mesh.F(f, k)));
    }
    write_file(path, bytes);
}

}  // namespace fem::io::detail
