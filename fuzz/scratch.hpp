#pragma once
// What the libFuzzer targets share: a folder of this process for the files they write their inputs
// to, and their start-up (fuzz_reader.cpp, fuzz_scene.cpp).

#include <vtkObject.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace fem::fuzz {

/// This process's folder for its input files (libFuzzer's -jobs run several processes): in memory
/// (/dev/shm) where there is one, since rewriting a file on ext4 waits for the disk (about 4 ms,
/// fifteen times what a read costs).
inline const std::filesystem::path& scratch()
{
    static const std::filesystem::path dir = [] {
        const std::filesystem::path memory = "/dev/shm";
        const std::filesystem::path d = (std::filesystem::is_directory(memory) ? memory
                                                                                : std::filesystem::temp_directory_path()) /
                                        ("fem-fuzz-" + std::to_string(getpid()));
        std::filesystem::create_directories(d);
        return d;
    }();
    return dir;
}

/// What LLVMFuzzerInitialize does: VTK's readers report into the fem::Error, so their console output
/// (which would only slow the fuzzing) is off; the scratch folder is removed when the process ends.
inline void initialize()
{
    vtkObject::GlobalWarningDisplayOff();
    std::atexit([] {
        std::error_code ignored;
        std::filesystem::remove_all(scratch(), ignored);
    });
}

}  // namespace fem::fuzz
