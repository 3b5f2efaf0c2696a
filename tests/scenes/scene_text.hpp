#pragma once
// The scenes tests' folders (the gallery, their output), and a scene written as text in a test: the
// file the scene reader reads, in the tests' output folder.
#include "scenes/scene_file.hpp"

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace fem::scenes::testing {

/// The gallery's folder, scenes/ (FEM_SCENES_DIR).
inline const std::filesystem::path gallery = FEM_SCENES_DIR;

/// The tests' output folder (FEM_TEST_OUTPUT_DIR).
inline const std::filesystem::path output = FEM_TEST_OUTPUT_DIR;

/// A scene from its text, written into the tests' output folder (FEM_TEST_OUTPUT_DIR) as
/// <name>.toml first, then read by read_scene with the command line's overrides ("key=value").
inline SceneSpec scene_from(const std::string& name, const std::string& text,
                            const std::vector<std::string>& overrides = {})
{
    std::filesystem::create_directories(output);
    const std::filesystem::path file = output / (name + ".toml");
    std::ofstream(file) << text;
    return read_scene(file, overrides);
}

}  // namespace fem::scenes::testing
