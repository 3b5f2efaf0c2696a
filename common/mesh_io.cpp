#include "common/mesh_io.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/vtk_io.hpp"

#include <Eigen/Geometry>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace fem::io {
namespace {

namespace fs = std::filesystem;

std::string lower_extension(const fs::path& path)
{
    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return extension;
}

void require_readable_file(const fs::path& path)
{
    if (!fs::exists(path))
        throw Error(str("cannot read '", path.string(), "': no such file"));
    if (!fs::is_regular_file(path))
        throw Error(str("cannot read '", path.string(), "': not a regular file"));
}

// ---------------------------------------------------------------------------------------------
// Text files: lines split into whitespace-separated tokens, with the line number for messages.

/// isspace() of the "C" locale: ' ', '\t', '\n', '\v', '\f', '\r'.
constexpr bool is_space(char c) { return c == ' ' || (c >= '\t' && c <= '\r'); }

/// A text file mapped into memory (mmap, read-only), then walked line by line in one pass: a line's
/// tokens are views into that memory (no copy of the file, no allocation per line), numbers are
/// parsed by std::from_chars.
class TextFile {
public:
    /// comment: the character that starts a comment up to the end of the line ('\0': none).
    TextFile(const fs::path& path, char comment) : name_(path.string()), comment_(comment)
    {
        require_readable_file(path);
        const int descriptor = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
        if (descriptor < 0)
            throw Error(str("cannot open '", name_, "' for reading: ", std::strerror(errno)));
        struct stat status {};
        if (::fstat(descriptor, &status) != 0) {
            const int reason = errno;
            ::close(descriptor);
            throw Error(str("cannot read '", name_, "': ", std::strerror(reason)));
        }
        if (status.st_size > 0) {
            size_ = static_cast<std::size_t>(status.st_size);
            void* mapped = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, descriptor, 0);
            if (mapped == MAP_FAILED) {
                const int reason = errno;
                ::close(descriptor);
                throw Error(str("cannot read '", name_, "': ", std::strerror(reason)));
            }
            ::madvise(mapped, size_, MADV_SEQUENTIAL);
            text_ = static_cast<const char*>(mapped);
        }
        ::close(descriptor);  // the mapping stays valid
    }
    TextFile(const TextFile&) = delete;
    TextFile& operator=(const TextFile&) = delete;
    ~TextFile()
    {
        if (text_ != nullptr)
            ::munmap(const_cast<char*>(text_), size_);
    }

    /// Moves to the next line that holds a token; false at the end of the file.
    bool next_line()
    {
        tokens_.clear();
        while (next_ < size_) {
            const char* begin = text_ + next_;
            const std::size_t left = size_ - next_;
            const auto* newline = static_cast<const char*>(std::memchr(begin, '\n', left));
            const std::size_t length = newline ? static_cast<std::size_t>(newline - begin) : left;
            next_ += newline ? length + 1 : length;
            ++line_;
            std::string_view rest(begin, length);
            if (comment_ != '\0')
                rest = rest.substr(0, rest.find(comment_));
            std::size_t at = 0;
            while (true) {
                while (at < rest.size() && is_space(rest[at]))
                    ++at;
                if (at == rest.size())
                    break;
                std::size_t end = at;
                while (end < rest.size() && !is_space(rest[end]))
                    ++end;
                tokens_.push_back(rest.substr(at, end - at));
                at = end;
            }
            if (!tokens_.empty())
                return true;
        }
        return false;
    }

    /// Copies the next `count` bytes after the current line (binary data after a text header) into
    /// bytes; false, copying nothing, if fewer are left.
    bool read_bytes(unsigned char* bytes, std::size_t count)
    {
        if (count > size_ - next_)
            return false;
        std::memcpy(bytes, text_ + next_, count);
        next_ += count;
        return true;
    }

    const std::vector<std::string_view>& tokens() const { return tokens_; }
    int line() const { return line_; }
    const std::string& name() const { return name_; }
    std::string place() const { return place(line_); }
    std::string place(int line) const { return str(name_, ", line ", line); }

    /// fem::Error at this line; bytes that are not printable (a NUL would end the message where it is
    /// printed) are written as \xNN.
    [[noreturn]] void fail(const std::string& what) const
    {
        std::string shown;
        for (const char c : what) {
            const auto byte = static_cast<unsigned char>(c);
            if (byte < 0x20 || byte == 0x7f)
                shown += str("\\x", "0123456789abcdef"[byte >> 4], "0123456789abcdef"[byte & 15]);
            else
                shown += c;
        }
        throw Error(str(place(), ": ", shown));
    }

    double number(std::string_view token, std::string_view what) const
    {
        if (!token.empty() && token.front() == '+')
            token.remove_prefix(1);
        double value = 0.0;
        const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
        if (error != std::errc() || end != token.data() + token.size())
            fail(str("expected ", what, " (a number), got '", token, "'"));
        return value;
    }

    long long integer(std::string_view token, std::string_view what) const
    {
        if (!token.empty() && token.front() == '+')
            token.remove_prefix(1);
        long long value = 0;
        const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
        if (error != std::errc() || end != token.data() + token.size())
            fail(str("expected ", what, " (an integer), got '", token, "'"));
        return value;
    }

private:
    std::string name_;
    char comment_;
    const char* text_ = nullptr;  // the whole file, mapped (nullptr when it is empty)
    std::size_t size_ = 0;        // its bytes
    std::size_t next_ = 0;        // where the next line starts in text_
    std::vector<std::string_view> tokens_;
    int line_ = 0;
};

/// What number() and integer() call the coordinates of a point (a literal: no string is built per
/// value read).
constexpr std::array<const char*, 3> coordinate_names{"coordinate x", "coordinate y", "coordinate z"};

/// Splits polygon `corners` into triangles (a fan from its first corner), appending them to
/// `triangles` and, for each, the line it came from to `lines`.
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

/// The origin of a mesh read from a text file: each vertex and element on its own line.
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

// ---------------------------------------------------------------------------------------------
// OBJ

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

// ---------------------------------------------------------------------------------------------
// STL (hand-written: VTK 9.1's STL reader asks for gigabytes on a damaged ASCII file, and a binary
// one shorter than its facet count announces reads as fewer facets without an error)

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

// ---------------------------------------------------------------------------------------------
// PLY (hand-written: VTK 9.1's PLY reader aborts the process on a truncated ASCII file)

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

// ---------------------------------------------------------------------------------------------
// .vtu

io::MeshData read_vtu_cells(const fs::path& path, int corners, const char* kind)
{
    require_readable_file(path);
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

// ---------------------------------------------------------------------------------------------
// TetGen .node / .ele

struct TetGenPaths {
    fs::path node, ele;
};

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

/// Reads the header line of a TetGen file: one integer per name; the first two are required, the
/// others default to 0 as in TetGen.
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
        if (header[0] < 0)
            node.fail(str("the number of points is negative: ", header[0]));
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
        if (header[0] < 0)
            ele.fail(str("the number of tetrahedra is negative: ", header[0]));
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

void write_text_file(const fs::path& path, const std::function<void(std::ostream&)>& write)
{
    std::ostringstream out;
    out << std::setprecision(17);
    write(out);
    write_file(path, out.str());
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

/// A Wavefront .obj: "v x y z" lines (17 significant digits), then "f a b c" (numbered from 1).
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

/// Appends the bytes of a number as they are in memory (little-endian on the machines we build on).
template <typename Number>
void append_bytes(std::string& bytes, Number value)
{
    static_assert(std::endian::native == std::endian::little, "the binary formats written are little-endian");
    bytes.append(reinterpret_cast<const char*>(&value), sizeof value);
}

/// A binary little-endian PLY: the vertices as 32-bit floats x, y, z, the faces as a list of
/// 32-bit vertex indices after a one-byte count (3), as VTK's PLY writer writes them.
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

/// A binary STL: an 80-byte header (not starting with "solid"), the facet count, and per facet its
/// unit normal and three corners as little-endian 32-bit floats, and two zero bytes.
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

[[noreturn]] void unknown_extension(const fs::path& path, const char* allowed)
{
    throw Error(str("'", path.string(), "': unknown mesh file type '", path.extension().string(),
                    "'; allowed: ", allowed));
}

}  // namespace

TriMesh read_tri_mesh(const fs::path& path)
{
    const std::string extension = lower_extension(path);
    if (extension == ".obj")
        return read_obj(path);
    if (extension == ".stl")
        return read_stl(path);
    if (extension == ".ply")
        return read_ply(path);
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
    const std::string extension = lower_extension(path);
    if (extension == ".vtu") {
        write_vtu(path, data);
    } else if (extension == ".obj") {
        write_obj(path, mesh);
    } else if (extension == ".stl") {
        write_binary_stl(path, mesh);
    } else if (extension == ".ply") {
        write_binary_ply(path, mesh);
    } else {
        unknown_extension(path, ".obj, .stl, .ply, .vtu");
    }
}

TetMesh read_tet_mesh(const fs::path& path, Inverted inverted)
{
    const std::string extension = lower_extension(path);
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
        return read_tetgen(tetgen_paths(path), inverted);
    unknown_extension(path, ".node/.ele (TetGen), .vtu");
}

void write_tet_mesh(const fs::path& path, const TetMesh& mesh)
{
    TetMesh checked = mesh;
    validate(checked, path.string());
    const std::string extension = lower_extension(path);
    if (extension == ".vtu") {
        io::MeshData data;
        data.points = mesh.V;
        data.cells = mesh.T;
        write_vtu(path, data);
    } else if (extension == ".node" || extension == ".ele") {
        write_tetgen(tetgen_paths(path), mesh);
    } else {
        unknown_extension(path, ".node/.ele (TetGen), .vtu");
    }
}

}  // namespace fem::io
