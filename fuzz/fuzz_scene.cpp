// A libFuzzer target for the scene reader (chapters/scenes/scene_file.hpp): read_scene on a scene
// file and a few --set overrides. An input is the scene's TOML text, then optionally a line "===" and
// one override a line ("key=value", as after --set; the line "--quick" applies the scene's [quick]
// table). The scene is written to a file of this process and read with TetGen forbidden (a surface
// mesh is an error here: the fuzzer must not start programs; the chapter's tests run TetGen), a
// memory budget of 256 MB for the run the scene describes and a lattice of at most 5e5 winding-number
// terms (each input must take well under the 10 s of tools/fuzz.sh, on a busy machine too). Expected: the read succeeds, or it raises
// an fem::Error whose message names the scene file. A finding: a crash, a sanitizer report, another
// exception, an fem::Error that does not name the file, a timeout, or memory beyond libFuzzer's
// -malloc_limit_mb. tools/fuzz.sh runs it (docs/engineering.md, "Fuzzing the readers").

#include "scenes/scene_file.hpp"

#include "common/error.hpp"
#include "fuzz/scratch.hpp"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace {

namespace fs = std::filesystem;

/// Where the scene text ends and the overrides begin.
constexpr std::string_view separator = "\n===\n";
/// The stem of the scene file: every fem::Error must name it.
constexpr std::string_view stem = "fuzz-input";
/// At most this many overrides are read (the rest of the input is ignored).
constexpr std::size_t max_overrides = 4;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***)
{
    fem::fuzz::initialize();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string_view input(reinterpret_cast<const char*>(data), size);
    const std::size_t at = input.find(separator);
    const fs::path path = fem::fuzz::scratch() / (std::string(stem) + ".toml");
    {
        const std::string_view scene = input.substr(0, at);
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out.write(scene.data(), static_cast<std::streamsize>(scene.size()));
        if (!out.flush()) {
            std::fprintf(stderr, "fuzz_scene: cannot write %s\n", path.c_str());
            std::abort();
        }
    }
    std::vector<std::string> overrides;
    bool quick = false;
    if (at != std::string_view::npos) {
        std::string_view rest = input.substr(at + separator.size());
        while (!rest.empty() && overrides.size() < max_overrides) {
            const std::size_t end = rest.find('\n');
            const std::string_view line = rest.substr(0, end);
            if (line == "--quick")
                quick = true;
            else
                overrides.emplace_back(line);
            rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
        }
    }
    fem::scenes::ReadLimits limits;
    limits.tetgen = false;
    limits.memory = std::size_t(256) << 20;
    // About 0.8 s instrumented on an idle core (a lattice of 4 about data/bunny.obj): 2e6 took 12 s
    // while the machine's load was 8 on 2 cores, a timeout of the fuzzer's own making.
    limits.lattice_work = 5e5;
    try {
        fem::scenes::read_scene(path, overrides, quick, limits);
    } catch (const fem::Error& error) {
        if (std::string_view(error.what()).find(stem) == std::string_view::npos) {
            std::fprintf(stderr, "fuzz_scene: an fem::Error that does not name the scene file: %s\n", error.what());
            std::abort();
        }
    }
    return 0;
}
