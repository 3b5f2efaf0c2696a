#pragma once
// Internal to common/, not part of the public API (include it only from the mesh readers,
// common/mesh_io*.cpp): TextFile, a text file mapped into memory and walked line by line as
// whitespace-separated tokens, its numbers parsed where they lie by std::from_chars, every error
// naming the file and the line. The readers of .obj, ASCII .stl and .ply and TetGen's .node/.ele
// use it; why it is hand-written and how fast it reads: docs/engineering.md#reading-meshes
// (tools/mesh_io_speed.cpp measures it). number() and integer() stay here, inline, so that each
// reader's loop compiles with them; their error messages are built out of line (text_file.cpp).

#include "common/error.hpp"

#include <array>
#include <charconv>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace fem::io::detail {

/// fem::Error unless path names an existing regular file ("no such file", "not a regular file"):
/// every mesh reader's first check.
void require_readable_file(const std::filesystem::path& path);

/// A text file mapped into memory (mmap, read-only), then walked line by line in one pass: a line's
/// tokens are views into that memory (no copy of the file, no allocation per line), numbers are
/// parsed by std::from_chars.
class TextFile {
public:
    /// comment: the character that starts a comment up to the end of the line ('\0': none).
    /// fem::Error naming the file and the system's reason if it cannot be read.
    TextFile(const std::filesystem::path& path, char comment);
    TextFile(const TextFile&) = delete;
    TextFile& operator=(const TextFile&) = delete;
    ~TextFile();

    /// Moves to the next line that holds a token; false at the end of the file.
    bool next_line();

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
    [[noreturn]] void fail(const std::string& what) const;

    /// The number a token spells (an optional '+' first); fail() with "expected <what> (a number),
    /// got '<token>'" otherwise.
    double number(std::string_view token, std::string_view what) const
    {
        if (!token.empty() && token.front() == '+')
            token.remove_prefix(1);
        double value = 0.0;
        const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
        if (error != std::errc() || end != token.data() + token.size())
            fail_to_parse(token, what, "a number");
        return value;
    }

    /// The integer a token spells (an optional '+' first); fail() with "expected <what> (an
    /// integer), got '<token>'" otherwise.
    long long integer(std::string_view token, std::string_view what) const
    {
        if (!token.empty() && token.front() == '+')
            token.remove_prefix(1);
        long long value = 0;
        const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
        if (error != std::errc() || end != token.data() + token.size())
            fail_to_parse(token, what, "an integer");
        return value;
    }

private:
    /// fail() with "expected <what> (<kind>), got '<token>'": out of line, so that the message's
    /// building stays out of number() and integer(), which the readers inline in their loops.
    [[noreturn]] void fail_to_parse(std::string_view token, std::string_view what, const char* kind) const;

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
inline constexpr std::array<const char*, 3> coordinate_names{"coordinate x", "coordinate y", "coordinate z"};

}  // namespace fem::io::detail
