#pragma once
// Helpers shared by the tests of every chapter.

#include "common/files.hpp"

#include <filesystem>
#include <string>

namespace fem::test {

/// A fresh, empty folder for the files one test writes: <build>/test_output/<chapter>/<name>.
inline std::filesystem::path fresh_output_dir(const std::string& name)
{
    const std::filesystem::path dir = std::filesystem::path(FEM_TEST_OUTPUT_DIR) / name;
    std::filesystem::remove_all(dir);
    fem::ensure_directory(dir);
    return dir;
}

}  // namespace fem::test
