#include "common/files.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
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

void write_file(const std::filesystem::path& path, std::string_view bytes)
{
    write_atomically(path, [&](const std::filesystem::path& temporary) {
        std::FILE* file = std::fopen(temporary.c_str(), "wb");
        if (!file)
            throw Error(str("cannot open '", path.string(), "' for writing: ", std::strerror(errno)));
        const bool written = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
        const int write_error = errno;
        if (std::fclose(file) != 0 || !written)
            throw Error(str("cannot write '", path.string(), "': ", std::strerror(written ? errno : write_error)));
    });
}

void remove_abandoned(const std::filesystem::path& folder, std::string_view prefix)
{
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
        const std::string name = entry.path().filename().string();
        if (!name.starts_with(prefix))
            continue;
        const long pid = std::strtol(name.c_str() + prefix.size(), nullptr, 10);
        std::error_code ignored;
        if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH)
            std::filesystem::remove_all(entry.path(), ignored);
    }
}

namespace {

constexpr std::string_view staging_prefix = ".staging-";

/// A plain entry name: no folder separator, not "." or "..", not empty.
bool plain_name(const std::string& name)
{
    return !name.empty() && name != "." && name != ".." && name.find('/') == std::string::npos;
}

}  // namespace

StagedFiles::StagedFiles(std::filesystem::path folder) : folder_(folder.empty() ? "." : std::move(folder))
{
    static std::atomic<int> counter{0};
    for (auto missing = std::filesystem::absolute(folder_); !std::filesystem::exists(missing);
         missing = missing.parent_path())
        created_ = missing;
    ensure_directory(folder_);
    remove_abandoned(folder_, staging_prefix);
    staging_ = folder_ / str(staging_prefix, ::getpid(), "-", counter++);
    std::error_code ec;
    if (!std::filesystem::create_directory(staging_, ec))
        throw Error(str("cannot create a staging folder in '", folder_.string(), "': ",
                        ec ? ec.message() : "it exists"));
}

StagedFiles::~StagedFiles()
{
    std::error_code ignored;
    std::filesystem::remove_all(staging_, ignored);
    if (published_ || created_.empty())
        return;
    // The folders made for it, from the innermost, each only when empty: nothing of others is lost.
    auto made = std::filesystem::absolute(folder_);
    while (std::filesystem::remove(made, ignored) && made != created_)
        made = made.parent_path();
}

void StagedFiles::publish(const std::vector<std::string>& obsolete)
{
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(staging_, ec))
        names.push_back(entry.path().filename().string());
    if (ec)
        throw Error(str("cannot list the staging folder '", staging_.string(), "': ", ec.message()));
    std::sort(names.begin(), names.end());
    // Old entries (replaced or obsolete) go aside into the staging folder first, so that every
    // step can be undone, and leave with it.
    const std::filesystem::path aside = staging_ / ".replaced";
    struct Move {
        std::string name;
        bool new_entry;  // moved in from staging (else: an obsolete entry only moved aside)
        bool had_old;    // an old entry of that name was moved aside
    };
    std::vector<Move> done;
    const auto undo = [&] {
        std::error_code ignored;
        for (auto m = done.rbegin(); m != done.rend(); ++m) {
            if (m->new_entry)
                std::filesystem::rename(folder_ / m->name, staging_ / m->name, ignored);
            if (m->had_old)
                std::filesystem::rename(aside / m->name, folder_ / m->name, ignored);
        }
    };
    const auto move_aside = [&](const std::string& name) {
        if (!std::filesystem::exists(std::filesystem::symlink_status(folder_ / name)))
            return false;
        std::filesystem::create_directory(aside, ec);
        std::filesystem::rename(folder_ / name, aside / name, ec);
        if (ec) {
            undo();
            throw Error(str("cannot replace '", (folder_ / name).string(), "': ", ec.message()));
        }
        return true;
    };
    for (const std::string& name : names) {
        const bool had_old = move_aside(name);
        std::filesystem::rename(staging_ / name, folder_ / name, ec);
        if (ec) {
            const std::string reason = ec.message();
            if (had_old)
                std::filesystem::rename(aside / name, folder_ / name, ec);
            undo();
            throw Error(str("cannot move '", name, "' into '", folder_.string(), "': ", reason));
        }
        done.push_back({name, true, had_old});
    }
    for (const std::string& name : obsolete)
        if (plain_name(name) && std::find(names.begin(), names.end(), name) == names.end() && move_aside(name))
            done.push_back({name, false, true});
    published_ = true;
}

std::filesystem::path data_path(std::string_view file_name)
{
    const std::filesystem::path path = std::filesystem::path(FEM_DATA_DIR) / file_name;
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))  // ec: a name too long is an Error like a missing one
        throw Error(str("data file '", path.string(), "' does not exist"));
    return path;
}

}  // namespace fem
