// The memory-mapped text file of the mesh readers (common/text_file.hpp, internal to common/): the
// readable-file check, the mapping of the file (mmap, read-only) and its release, the walk to the
// next line's tokens, and the errors that name the file and the line.
// docs/engineering.md#reading-meshes
#include "common/text_file.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

namespace fem::io::detail {

namespace fs = std::filesystem;

namespace {

/// isspace() of the "C" locale: ' ', '\t', '\n', '\v', '\f', '\r'.
constexpr bool is_space(char c) { return c == ' ' || (c >= '\t' && c <= '\r'); }

}  // namespace

void require_readable_file(const fs::path& path)
{
    if (!fs::exists(path))
        throw Error(str("cannot read '", path.string(), "': no such file"));
    if (!fs::is_regular_file(path))
        throw Error(str("cannot read '", path.string(), "': not a regular file"));
}

TextFile::TextFile(const fs::path& path, char comment) : name_(path.string()), comment_(comment)
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

TextFile::~TextFile()
{
    if (text_ != nullptr)
        ::munmap(const_cast<char*>(text_), size_);
}

bool TextFile::next_line()
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

void TextFile::fail(const std::string& what) const
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

void TextFile::fail_to_parse(std::string_view token, std::string_view what, const char* kind) const
{
    fail(str("expected ", what, " (", kind, "), got '", token, "'"));
}

}  // namespace fem::io::detail
