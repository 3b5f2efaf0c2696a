#pragma once
// A scene written as text in a test: the file the scene reader reads, in the tests' output folder.
#include "scenes/scene_file.hpp"

#include <filesystem>
#include <fstream>
#include <string>

namespace fem::scenes::testing {

/// A scene from its text, written into the tests' output folder (FEM_TEST_OUTPUT_DIR) as
/// <name>.toml first, then read by read_scene.
inline SceneSpec scene_from(const std::string& name, const std::string& text)
{
    const std::filesystem::path output = FEM_TEST_OUTPUT_DIR;
    std::filesystem::create_directories(output);
    const std::filesystem::path file = output / (name + ".toml");
    std::ofstream(file) << text;
    return read_scene(file);
}

}  // namespace fem::scenes::testing
