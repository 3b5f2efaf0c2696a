#pragma once
// Files: atomic writes (a failure never leaves a half-written file), files that appear together,
// and the data folder.

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace fem {

/// Writes path atomically: write(temporary) fills a temporary file in the same folder, which then
/// replaces path by a rename. If write throws, the temporary is removed, path is left as it was,
/// and the exception propagates. Creates the parent folder when missing.
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path& temporary)>& write);

/// Writes bytes to path atomically (see write_atomically). fem::Error with the system's reason
/// (e.g. "No space left on device", "File too large") when it cannot.
void write_file(const std::filesystem::path& path, std::string_view bytes);

/// Files that become visible together in a folder, or not at all. They are written into a hidden
/// staging folder inside it (".staging-<pid>-<n>", so that every move is a rename on one file
/// system); publish() then moves each entry in, replacing an entry of the same name (a file or a
/// whole folder). Destroyed without publish() (a write failed), it removes the staging folder, and
/// the folders it created: what was there before is left as it was. Staging folders
/// of processes that no longer run (killed mid-write) are removed when a new one is made.
class StagedFiles {
public:
    /// folder: where the files will appear (created, with its parents, when missing).
    explicit StagedFiles(std::filesystem::path folder);
    ~StagedFiles();
    StagedFiles(const StagedFiles&) = delete;
    StagedFiles& operator=(const StagedFiles&) = delete;

    /// The folder the files are written into until publish().
    const std::filesystem::path& staging() const { return staging_; }

    /// Moves every entry of staging() into the folder and removes the entries named in obsolete
    /// (plain names of earlier results that were not written again; missing ones are skipped).
    /// If a move fails, the moves done are undone and fem::Error names the entry and the reason.
    void publish(const std::vector<std::string>& obsolete = {});

private:
    std::filesystem::path folder_, staging_;
    std::filesystem::path created_;  // the outermost folder the constructor created, if any
    bool published_ = false;
};

/// Removes the entries of folder whose names are prefix followed by the id of a process that no
/// longer runs ("<prefix><pid>-..."): what a killed run left behind (a staging folder, a temporary
/// folder). Entries of running processes are left alone; failures to remove are ignored.
void remove_abandoned(const std::filesystem::path& folder, std::string_view prefix);

/// Creates a folder (and its parents) if missing; fem::Error if it cannot.
void ensure_directory(const std::filesystem::path& directory);

/// The path of a file in the project's data/ folder (compiled in, so it works from any folder).
std::filesystem::path data_path(std::string_view file_name);

}  // namespace fem
