// A libFuzzer target for one file format of the course, built once per format (fuzz/CMakeLists.txt)
// with FEM_FUZZ_FORMAT set to the format: obj, ply, stl, vtu, pvd, or tetgen (a .node/.ele pair).
// Each input is written to a file of this process with that extension (for tetgen: the input up to
// the first line "===" is the .node file, the rest the .ele file) and read with the course's reader
// (fuzz/read_by_extension.hpp). Expected: the read succeeds, or it raises an fem::Error whose
// message names the file. A finding: a crash, a sanitizer report, another exception, an fem::Error
// that does not name the file, a timeout, or memory beyond libFuzzer's -malloc_limit_mb.
// tools/fuzz.sh runs these (docs/engineering.md, "Fuzzing the readers").

#include "fuzz/read_by_extension.hpp"

#include "common/error.hpp"
#include "fuzz/scratch.hpp"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace {

namespace fs = std::filesystem;

constexpr std::string_view format = FEM_FUZZ_FORMAT;
/// Where a tetgen input splits into its .node and .ele files.
constexpr std::string_view tetgen_separator = "===\n";
/// The stem of the input files: every fem::Error must name it.
constexpr std::string_view stem = "fuzz-input";

void write_bytes(const fs::path& path, std::string_view bytes)
{
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out.flush()) {
        std::fprintf(stderr, "fuzz_%s: cannot write %s\n", FEM_FUZZ_FORMAT, path.c_str());
        std::abort();
    }
}

/// Writes the input as the file(s) of the format; returns the path to read.
fs::path write_input(std::string_view input)
{
    const fs::path base = fem::fuzz::scratch() / stem;
    if (format != "tetgen") {
        const fs::path path = fs::path(base).concat("." + std::string(format));
        write_bytes(path, input);
        return path;
    }
    const std::size_t at = input.find(tetgen_separator);
    const fs::path node = fs::path(base).concat(".node");
    write_bytes(node, input.substr(0, at));
    write_bytes(fs::path(base).concat(".ele"),
                at == std::string_view::npos ? std::string_view() : input.substr(at + tetgen_separator.size()));
    return node;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***)
{
    fem::fuzz::initialize();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const fs::path path = write_input(std::string_view(reinterpret_cast<const char*>(data), size));
    try {
        fem::fuzz::read_by_extension(path);
    } catch (const fem::Error& error) {
        if (std::string_view(error.what()).find(stem) == std::string_view::npos) {
            std::fprintf(stderr, "fuzz_%s: an fem::Error that does not name the file: %s\n", FEM_FUZZ_FORMAT,
                         error.what());
            std::abort();
        }
    }
    return 0;
}
