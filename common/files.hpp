#pragma once
// Files: atomic writes (a failure never leaves a half-written file) and the data folder.

#include <filesystem>
#include <functional>
#include <string_view>

namespace fem {

/// Writes path atomically: write(temporary) fills a temporary file in the same folder, which then
/// replaces path by a rename. If write throws, the temporary is removed, path is left as it was,
/// and the exception propagates. Creates the parent folder when missing.
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path& temporary)>& write);

/// Creates a folder (and its parents) if missing; fem::Error if it cannot.
void ensure_directory(const std::filesystem::path& directory);

/// The path of a file in the project's data/ folder (compiled in, so it works from any folder).
std::filesystem::path data_path(std::string_view file_name);

}  // namespace fem
