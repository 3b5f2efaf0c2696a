#include "common/files.hpp"

#include "common/error.hpp"

#include <atomic>
#include <system_error>
#include <unistd.h>

namespace fem {

void ensure_directory(const std::filesystem::path& directory)
{
    if (directory.empty())
        return;
    std::error_code ec;
    std::filesystem::create_directories(directory, ec);
    if (ec || !std::filesystem::is_directory(directory))
        throw Error(str("cannot create folder '", directory.string(), "': ",
                        ec ? ec.message() : "a file of that name exists"));
}

void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path& temporary)>& write)
{
    static std::atomic<int> counter{0};
    ensure_directory(path.parent_path());
    std::filesystem::path temporary = path;
    temporary += str(".tmp-", ::getpid(), "-", counter++, path.extension().string());
    try {
        write(temporary);
        if (!std::filesystem::exists(temporary))
            throw Error(str("writing '", path.string(), "' produced no file"));
    } catch (...) {
        std::error_code ignored;
        std::filesystem::remove(temporary, ignored);
        throw;
    }
    std::error_code ec;
    std::filesystem::rename(temporary, path, ec);
    if (ec) {
        std::filesystem::remove(temporary, ec);
        throw Error(str("cannot move the finished file into place at '", path.string(), "'"));
    }
}

std::filesystem::path data_path(std::string_view file_name)
{
    const std::filesystem::path path = std::filesystem::path(FEM_DATA_DIR) / file_name;
    if (!std::filesystem::exists(path))
        throw Error(str("data file '", path.string(), "' does not exist"));
    return path;
}

}  // namespace fem
