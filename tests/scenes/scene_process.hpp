#pragma once
// fem_scene run by a test in a child process, and a file's text: what the runner's and the live
// view's tests share.
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fem::scenes::testing {

/// Starts fem_scene with these arguments in a child process; returns its id. Its output is discarded,
/// or, given output_fd, its standard output goes to a pipe whose reading end is stored there.
inline pid_t start_scene(const std::vector<std::string>& arguments, int* output_fd = nullptr)
{
    int pipe_ends[2] = {-1, -1};
    if (output_fd != nullptr && ::pipe(pipe_ends) != 0)
        return -1;
    const pid_t child = ::fork();
    if (child == 0) {
        std::freopen("/dev/null", "w", stdout);
        std::freopen("/dev/null", "w", stderr);
        if (output_fd != nullptr) {
            ::dup2(pipe_ends[1], STDOUT_FILENO);
            ::close(pipe_ends[0]);
            ::close(pipe_ends[1]);
        }
        std::vector<char*> argv{const_cast<char*>(FEM_SCENE_EXE)};
        for (const std::string& argument : arguments)
            argv.push_back(const_cast<char*>(argument.c_str()));
        argv.push_back(nullptr);
        ::execv(FEM_SCENE_EXE, argv.data());
        std::_Exit(127);
    }
    if (output_fd != nullptr) {
        ::close(pipe_ends[1]);
        *output_fd = pipe_ends[0];
    }
    return child;
}

inline std::string read_text(const std::filesystem::path& path)
{
    std::ifstream file(path, std::ios::binary);
    std::ostringstream text;
    text << file.rdbuf();
    return text.str();
}

}  // namespace fem::scenes::testing
