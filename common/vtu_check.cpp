// Internal to common/: the checks of a .vtu file's layout before VTK's XML reader sees it
// (common/vtu_check.hpp): a small XML tag reader, the <DataArray> values in ASCII, base64 or
// appended form, zlib-compressed blocks within zlib's largest ratio, and the counts and cell offsets
// checked against what the file holds. docs/engineering.md#fuzzing-the-readers
#include "common/vtu_check.hpp"

#include "common/error.hpp"

#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace fem::io::detail {
namespace {

/// zlib never compresses more than about 1032:1; a block that claims more is corrupt.
constexpr std::uint64_t max_zlib_ratio = 1032;
/// The largest compression block accepted (VTK writes 32 KB blocks).
constexpr std::uint64_t max_block_size = std::uint64_t(1) << 26;
constexpr int max_components = 1024;
/// The most points, cells or tuples (MeshData numbers them with int).
constexpr std::int64_t max_count = 2147483647;

struct Tag {
    std::string name;
    std::map<std::string, std::string, std::less<>> attributes;
    bool closing = false, self_closing = false;
    std::size_t end = 0;  // just past '>'
};

/// A DataArray: where its values are and how they are stored.
struct Array {
    std::string name;
    int value_bytes = 0;
    bool is_signed = false, is_float = false;
    std::string format;
    std::size_t content = 0;  // inline: the text after the tag; appended: the offset
    bool empty = false;       // an inline array written <DataArray .../>
};

/// One .vtu file, read into memory, and what its checks have learnt of it so far.
class VtuLayout {
public:
    /// Reads the whole file (fem::Error if it cannot be read).
    explicit VtuLayout(const std::filesystem::path& path) : name_(path.string())
    {
        std::ifstream in(path, std::ios::binary);
        if (!in)
            throw Error(str("cannot read '", name_, "'"));
        text_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }

    /// fem::Error naming the file and what is wrong with it.
    [[noreturn]] void fail(const std::string& what) const { throw Error(str("'", name_, "': ", what)); }

    /// Walks the XML elements in order, checking each (check_vtu_layout's contract).
    void check()
    {
        // The XML ends where the appended data begins (raw bytes may hold anything).
        const std::size_t appended_tag = text_.find("<AppendedData");
        xml_end_ = text_.size();
        if (appended_tag != std::string::npos) {
            find_appended_data(appended_tag);
            xml_end_ = appended_tag;
        }
        std::vector<std::string> open;  // the enclosing elements
        std::size_t at = 0;
        bool seen_tag = false;
        while (true) {
            const std::size_t lt = text_.find('<', at);
            if (lt >= xml_end_)
                break;
            if (!seen_tag && text_.compare(lt, 5, "<?xml") == 0) {
                const std::size_t end = text_.find("?>", lt);
                if (end >= xml_end_)
                    fail("the XML declaration '<?xml' is not closed");
                at = end + 2;
                continue;
            }
            const Tag tag = read_tag(lt);
            at = tag.end;
            if (!seen_tag && (tag.name != "VTKFile" || tag.closing))
                fail(str("the first element is <", tag.name, ">; a .vtu file starts with <VTKFile>"));
            seen_tag = true;
            if (tag.closing) {
                if (open.empty() || open.back() != tag.name)
                    fail(str("</", tag.name, "> closes ", open.empty() ? "nothing" : "<" + open.back() + ">"));
                open.pop_back();
                continue;
            }
            start_element(tag, open.empty() ? std::string() : open.back());
            if (!tag.self_closing)
                open.push_back(tag.name);
        }
        if (!seen_tag)
            fail("no <VTKFile> element; a .vtu file is XML");
        if (pieces_ != 1)
            fail(str("it has ", pieces_, " <Piece> elements; the course reads unstructured grids of one piece"));
        if (points_ > 0 && !have_points_)
            fail(str("<Piece> announces ", points_, " points but has no <Points> array"));
        if (cells_ > 0 && (!have_types_ || !offsets_ || connectivity_ < 0))
            fail(str("<Piece> announces ", cells_, " cells but <Cells> lacks its connectivity, offsets or types"));
        if (offsets_)
            check_offsets(*offsets_);
    }

private:
    /// The tag that starts at `lt`, with its attributes.
    Tag read_tag(std::size_t lt) const
    {
        if (text_.compare(lt, 2, "<!") == 0 || text_.compare(lt, 2, "<?") == 0)
            fail("it holds an XML comment, CDATA section or declaration; the course reads plain VTK XML");
        const std::size_t gt = text_.find('>', lt);
        if (gt >= xml_end_)
            fail(str("the tag at byte ", lt, " is not closed"));
        std::string_view body(text_.data() + lt + 1, gt - lt - 1);
        if (body.find_first_of("<&") != std::string_view::npos)
            fail(str("the tag at byte ", lt, " holds '<' or an entity reference ('&'), which the course does not read"));
        Tag tag;
        tag.end = gt + 1;
        if (!body.empty() && body.front() == '/') {
            tag.closing = true;
            body.remove_prefix(1);
        } else if (!body.empty() && body.back() == '/') {
            tag.self_closing = true;
            body.remove_suffix(1);
        }
        const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
        std::size_t i = 0;
        while (i < body.size() && !space(body[i]))
            ++i;
        tag.name = body.substr(0, i);
        if (tag.name.empty())
            fail(str("the tag at byte ", lt, " has no name"));
        while (true) {
            while (i < body.size() && space(body[i]))
                ++i;
            if (i == body.size())
                break;
            const std::size_t equals = body.find('=', i);
            if (equals == std::string_view::npos || equals + 1 >= body.size() ||
                (body[equals + 1] != '"' && body[equals + 1] != '\''))
                fail(str("<", tag.name, "> has an attribute that is not name=\"value\""));
            const std::size_t close = body.find(body[equals + 1], equals + 2);
            if (close == std::string_view::npos)
                fail(str("<", tag.name, "> has an attribute value without its closing quote"));
            std::string key(body.substr(i, equals - i));
            key.erase(std::remove_if(key.begin(), key.end(), space), key.end());
            if (!tag.attributes.emplace(key, body.substr(equals + 2, close - equals - 2)).second)
                fail(str("<", tag.name, "> repeats the attribute ", key));
            i = close + 1;
        }
        return tag;
    }

    /// The value of attribute `key`, or `fallback` when the tag has none.
    std::string attribute(const Tag& tag, std::string_view key, std::string_view fallback) const
    {
        const auto found = tag.attributes.find(key);
        return found == tag.attributes.end() ? std::string(fallback) : found->second;
    }

    /// A count attribute: a decimal integer from `minimum` to `limit`.
    std::int64_t count(const Tag& tag, std::string_view key, std::int64_t limit, std::int64_t minimum = 0) const
    {
        const auto found = tag.attributes.find(key);
        if (found == tag.attributes.end())
            fail(str("<", tag.name, "> has no ", key, " attribute"));
        const std::string& text = found->second;
        std::int64_t value = -1;
        const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
        if (error != std::errc() || end != text.data() + text.size() || value < minimum || value > limit)
            fail(str("<", tag.name, "> has ", key, "=\"", text, "\"; allowed: an integer from ", minimum, " to ", limit));
        return value;
    }

    /// Checks an opening tag inside `parent` (empty for the root): the file's settings, the piece's
    /// counts, a data array.
    void start_element(const Tag& tag, const std::string& parent)
    {
        if (tag.name == "VTKFile") {
            if (attribute(tag, "type", "") != "UnstructuredGrid")
                fail(str("<VTKFile type=\"", attribute(tag, "type", ""), "\">; a .vtu file is an UnstructuredGrid"));
            const std::string order = attribute(tag, "byte_order", "LittleEndian");
            if (order != "LittleEndian" && order != "BigEndian")
                fail(str("byte_order=\"", order, "\"; allowed: LittleEndian, BigEndian"));
            big_endian_ = order == "BigEndian";
            const std::string header = attribute(tag, "header_type", "UInt32");
            if (header != "UInt32" && header != "UInt64")
                fail(str("header_type=\"", header, "\"; allowed: UInt32, UInt64"));
            header_bytes_ = header == "UInt32" ? 4 : 8;
            const std::string compressor = attribute(tag, "compressor", "");
            if (!compressor.empty() && compressor != "vtkZLibDataCompressor")
                fail(str("compressor=\"", compressor, "\"; the course reads uncompressed files and vtkZLibDataCompressor"));
            compressed_ = !compressor.empty();
        } else if (tag.name == "Piece") {
            ++pieces_;
            points_ = count(tag, "NumberOfPoints", max_count);
            cells_ = count(tag, "NumberOfCells", max_count);
        } else if (tag.name == "DataArray") {
            data_array(tag, parent);
        }
    }

    /// Checks a DataArray against what its place needs.
    void data_array(const Tag& tag, const std::string& parent)
    {
        Array array;
        array.name = attribute(tag, "Name", "");
        const std::string type = attribute(tag, "type", "");
        static const std::map<std::string, std::pair<int, int>, std::less<>> types{
            {"Int8", {1, 1}},  {"UInt8", {1, 0}},  {"Int16", {2, 1}},  {"UInt16", {2, 0}},  {"Int32", {4, 1}},
            {"UInt32", {4, 0}}, {"Int64", {8, 1}}, {"UInt64", {8, 0}}, {"Float32", {4, 2}}, {"Float64", {8, 2}}};
        const auto found = types.find(type);
        if (found == types.end())
            fail(str("DataArray '", array.name, "' has type=\"", type, "\"; allowed: Int8 ... UInt64, Float32, Float64"));
        array.value_bytes = found->second.first;
        array.is_signed = found->second.second != 0;
        array.is_float = found->second.second == 2;
        const std::int64_t components =
            tag.attributes.count("NumberOfComponents") ? count(tag, "NumberOfComponents", max_components, 1) : 1;
        array.format = attribute(tag, "format", "ascii");
        if (array.format == "appended") {
            if (appended_begin_ == std::string::npos)
                fail(str("DataArray '", array.name, "' is appended, but the file has no <AppendedData>"));
            array.content = static_cast<std::size_t>(count(tag, "offset", std::int64_t(1) << 62));
        } else if (array.format == "ascii" || array.format == "binary") {
            array.content = tag.end;
            array.empty = tag.self_closing;
        } else {
            fail(str("DataArray '", array.name, "' has format=\"", array.format, "\"; allowed: ascii, binary, appended"));
        }
        const std::uint64_t values = value_count(array);

        // The tuples its place needs, and what they are for the message.
        std::optional<std::int64_t> tuples;
        const char* of = "";
        if (parent == "Points") {
            have_points_ = true;
            if (components != 3)
                fail(str("the points have ", components, " components; points have 3"));
            tuples = points_, of = "points";
        } else if (parent == "PointData") {
            tuples = points_, of = "points";
        } else if (parent == "CellData") {
            tuples = cells_, of = "cells";
        } else if (parent == "FieldData") {
            tuples = count(tag, "NumberOfTuples", max_count), of = "tuples (NumberOfTuples)";
        } else if (parent == "Cells" && array.name == "types") {
            have_types_ = true;
            tuples = cells_, of = "cells";
        } else if (parent == "Cells" && array.name == "connectivity") {
            if (array.is_float)
                fail("the connectivity has a floating-point type; point ids are integers");
            connectivity_ = static_cast<std::int64_t>(values);
        } else if (parent == "Cells" && array.name == "offsets") {
            if (array.is_float)
                fail("the cell offsets have a floating-point type; offsets are integers");
            if (values != static_cast<std::uint64_t>(cells_) && values != static_cast<std::uint64_t>(cells_) + 1)
                fail(str("the cell offsets hold ", values, " values for ", cells_, " cells"));
            offsets_ = array;
        } else {
            fail(str("a DataArray '", array.name, "' inside <", parent.empty() ? "nothing" : parent,
                     ">; the course reads points, cells (connectivity, offsets, types), point, cell and field data"));
        }
        if (tuples && values != static_cast<std::uint64_t>(*tuples * components))
            fail(str("DataArray '", array.name, "' holds ", values, " values; ", *tuples, " ", of, " × ", components,
                     " components need ", *tuples * components));
    }

    // --- where the values are ---------------------------------------------------------------

    /// Reads the <AppendedData> tag at `tag_at`: its encoding, and where its bytes begin (after '_').
    void find_appended_data(std::size_t tag_at)
    {
        const Tag tag = read_tag(tag_at);
        const std::string encoding = attribute(tag, "encoding", "");
        if (encoding != "raw" && encoding != "base64")
            fail(str("<AppendedData encoding=\"", encoding, "\">; allowed: raw, base64"));
        appended_base64_ = encoding == "base64";
        const std::size_t underscore = text_.find_first_not_of(" \t\r\n", tag.end);
        if (underscore == std::string::npos || text_[underscore] != '_')
            fail("<AppendedData> does not start with '_'");
        appended_begin_ = underscore + 1;
    }

    /// The base64 characters from `at` to the first other character.
    std::string_view base64_run(std::size_t at) const
    {
        static constexpr std::string_view alphabet =
            "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/=";
        const std::size_t end = std::min(text_.find_first_not_of(alphabet, at), text_.size());
        return std::string_view(text_).substr(at, end - at);
    }

    /// Decodes base64 text into `bytes` bytes; fem::Error if the text is too short.
    std::string decode_base64(std::string_view chars, std::uint64_t bytes, const Array& array) const
    {
        if (chars.size() / 4 < (bytes + 2) / 3)
            fail(str("DataArray '", array.name, "' needs ", bytes, " bytes, its base64 text holds fewer"));
        std::string out;
        out.reserve(bytes + 2);
        for (std::size_t i = 0; out.size() < bytes; i += 4) {
            std::uint32_t group = 0;
            for (std::size_t k = 0; k < 4; ++k) {
                const char c = chars[i + k];
                const std::uint32_t v = c >= 'A' && c <= 'Z' ? c - 'A'
                                        : c >= 'a' && c <= 'z' ? c - 'a' + 26
                                        : c >= '0' && c <= '9' ? c - '0' + 52
                                        : c == '+' ? 62 : c == '/' ? 63 : 0;
                group = (group << 6) | v;
            }
            for (int k = 2; k >= 0; --k)
                out.push_back(static_cast<char>((group >> (8 * k)) & 0xff));
        }
        out.resize(bytes);
        return out;
    }

    /// Reads encoded bytes of an array: base64 text (inline, or appended base64) or raw appended bytes.
    class Reader {
    public:
        /// Starts at the array's first byte: after its tag (inline) or at its offset (appended).
        Reader(const VtuLayout& file, const Array& array) : file_(file), array_(array)
        {
            if (array.format == "binary") {
                const std::size_t start = file.text_.find_first_not_of(" \t\r\n", array.content);
                base64_ = true;
                at_ = std::min(start, file.xml_end_);
            } else {
                base64_ = file.appended_base64_;
                if (array.content > file.text_.size() - file.appended_begin_)
                    file.fail(str("DataArray '", array.name, "' has offset ", array.content, ", beyond the appended data"));
                at_ = file.appended_begin_ + array.content;
            }
        }

        /// The next `bytes` bytes (base64: one run of text, padded to whole groups).
        std::string next(std::uint64_t bytes)
        {
            if (base64_) {
                const std::string_view run = file_.base64_run(at_);
                const std::string decoded = file_.decode_base64(run, bytes, array_);
                at_ += 4 * ((bytes + 2) / 3);
                return decoded;
            }
            if (bytes > file_.text_.size() - at_)
                file_.fail(str("DataArray '", array_.name, "' needs ", bytes, " bytes at byte ", at_, "; the file ends first"));
            std::string raw = file_.text_.substr(at_, bytes);
            at_ += bytes;
            return raw;
        }

    private:
        const VtuLayout& file_;
        const Array& array_;
        bool base64_ = false;
        std::size_t at_ = 0;
    };

    /// Value `index` of `size` bytes (unsigned) in the file's byte order.
    std::uint64_t word(const std::string& bytes, std::size_t index, int size) const
    {
        const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + index * size);
        std::uint64_t value = 0;
        for (int k = 0; k < size; ++k)
            value = (value << 8) | b[big_endian_ ? k : size - 1 - k];
        return value;
    }

    /// The bytes of an array's values (binary or appended): `size` is set to their number, after the
    /// header has been checked against the file; they are returned when `decode` is true (inflated
    /// when compressed), else an empty string.
    std::string payload(const Array& array, bool decode, std::uint64_t& size) const
    {
        Reader reader(*this, array);
        if (!compressed_) {
            // One header word (the byte count), then the bytes; base64 encodes both in one run.
            size = word(reader.next(header_bytes_), 0, header_bytes_);
            if (size > text_.size())
                fail(str("DataArray '", array.name, "' announces ", size, " bytes in a file of ", text_.size()));
            if (array.format == "appended" && !appended_base64_)
                return reader.next(size);
            return Reader(*this, array).next(header_bytes_ + size).substr(header_bytes_);
        }
        // zlib blocks: [number of blocks, block size, last block size, compressed size of each block].
        const std::string first = reader.next(header_bytes_);
        const std::uint64_t blocks = word(first, 0, header_bytes_);
        if (blocks > text_.size() / header_bytes_)
            fail(str("DataArray '", array.name, "' announces ", blocks, " compressed blocks in a file of ", text_.size(), " bytes"));
        Reader header_reader(*this, array);
        const std::string header = header_reader.next((3 + blocks) * header_bytes_);
        const std::uint64_t block_size = word(header, 1, header_bytes_), last = word(header, 2, header_bytes_);
        if (blocks > 0 && (block_size == 0 || block_size > max_block_size || last > block_size))
            fail(str("DataArray '", array.name, "' has compressed blocks of ", block_size, " bytes (the last ", last,
                     "); allowed: 1 to ", max_block_size, ", the last no larger"));
        std::uint64_t compressed = 0;
        size = 0;
        std::vector<std::uint64_t> block_bytes, stored;
        for (std::uint64_t b = 0; b < blocks; ++b) {
            const std::uint64_t stored_size = word(header, 3 + b, header_bytes_);
            const std::uint64_t plain = (b + 1 == blocks && last != 0) ? last : block_size;
            if (stored_size > text_.size())  // before any sum or product of it can overflow
                fail(str("DataArray '", array.name, "': compressed block ", b, " announces ", stored_size,
                         " bytes in a file of ", text_.size()));
            if (plain > max_zlib_ratio * stored_size + 64)
                fail(str("DataArray '", array.name, "': compressed block ", b, " of ", stored_size,
                         " bytes claims ", plain, " bytes, more than zlib can compress into it"));
            compressed += stored_size;
            size += plain;
            block_bytes.push_back(plain);
            stored.push_back(stored_size);
            if (compressed > text_.size())
                fail(str("DataArray '", array.name, "' announces ", compressed, " compressed bytes in a file of ",
                         text_.size()));
        }
        const std::string data = header_reader.next(compressed);  // checks that the file holds them
        if (!decode)
            return std::string();
        std::string out;
        std::size_t at = 0;
        for (std::size_t b = 0; b < block_bytes.size(); ++b) {
            std::string block(block_bytes[b], '\0');
            uLongf length = block_bytes[b];
            if (uncompress(reinterpret_cast<Bytef*>(block.data()), &length,
                           reinterpret_cast<const Bytef*>(data.data() + at), stored[b]) != Z_OK ||
                length != block_bytes[b])
                fail(str("DataArray '", array.name, "': compressed block ", b, " does not inflate to ",
                         block_bytes[b], " bytes"));
            out += block;
            at += stored[b];
        }
        return out;
    }

    /// How many values an array holds (whole values; bytes checked against the file).
    std::uint64_t value_count(const Array& array) const
    {
        if (array.empty)
            return 0;
        if (array.format == "ascii") {
            const std::size_t end = std::min(text_.find('<', array.content), xml_end_);
            std::uint64_t tokens = 0;
            bool in_token = false;
            for (std::size_t i = array.content; i < end; ++i) {
                const bool blank = text_[i] == ' ' || text_[i] == '\t' || text_[i] == '\n' || text_[i] == '\r';
                tokens += !blank && !in_token;
                in_token = !blank;
            }
            return tokens;
        }
        std::uint64_t bytes = 0;
        payload(array, false, bytes);
        if (bytes % array.value_bytes != 0)
            fail(str("DataArray '", array.name, "' holds ", bytes, " bytes, not a whole number of ",
                     array.value_bytes, "-byte values"));
        return bytes / array.value_bytes;
    }

    /// The offsets of the cells: each at least the one before, none beyond the connectivity.
    void check_offsets(const Array& array) const
    {
        std::vector<std::int64_t> offsets;
        if (array.format == "ascii") {
            const std::size_t end = std::min(text_.find('<', array.content), xml_end_);
            std::size_t at = array.content;
            while (true) {
                at = text_.find_first_not_of(" \t\r\n", at);
                if (at >= end)
                    break;
                const std::size_t stop = std::min(text_.find_first_of(" \t\r\n", at), end);
                std::int64_t value = 0;
                const auto [ptr, error] = std::from_chars(text_.data() + at, text_.data() + stop, value);
                if (error != std::errc() || ptr != text_.data() + stop)
                    fail(str("the cell offsets hold '", text_.substr(at, stop - at), "', not an integer"));
                offsets.push_back(value);
                at = stop;
            }
        } else {
            std::uint64_t bytes = 0;
            const std::string data = payload(array, true, bytes);
            for (std::size_t i = 0; i < data.size() / array.value_bytes; ++i) {
                std::uint64_t value = word(data, i, array.value_bytes);
                if (array.is_signed && array.value_bytes < 8 && (value >> (8 * array.value_bytes - 1)) != 0)
                    value |= ~std::uint64_t(0) << (8 * array.value_bytes);  // sign-extend
                offsets.push_back(static_cast<std::int64_t>(value));
            }
        }
        std::int64_t previous = 0;
        for (std::size_t c = 0; c < offsets.size(); ++c) {
            if (offsets[c] < previous || offsets[c] > connectivity_)
                fail(str("cell offset ", c, " is ", offsets[c], "; offsets never decrease and stay within the ",
                         connectivity_, " point ids of the connectivity"));
            previous = offsets[c];
        }
    }

    std::string name_, text_;
    std::size_t xml_end_ = 0, appended_begin_ = std::string::npos;
    bool appended_base64_ = false, big_endian_ = false, compressed_ = false;
    int header_bytes_ = 4;
    int pieces_ = 0;
    std::int64_t points_ = 0, cells_ = 0, connectivity_ = -1;
    bool have_points_ = false, have_types_ = false;
    std::optional<Array> offsets_;
};

}  // namespace

void check_vtu_layout(const std::filesystem::path& path)
{
    VtuLayout(path).check();
}

}  // namespace fem::io::detail
