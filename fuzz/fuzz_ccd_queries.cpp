// The libFuzzer target of chapter 15's reader of the CCD benchmark's query files (read_ccd_queries,
// solutions/15_body_contact/ccd.cpp). Each input is written to vertex-face/fuzz-input.csv in this process's
// scratch folder and read; every query read then goes through both CCD methods (the inclusion
// method with at most 10⁴ boxes, so that an input stays fast). Expected: the read succeeds, or it
// raises an fem::Error whose message names the file. A finding: a crash, a sanitizer report, another
// exception, an fem::Error that does not name the file, a timeout, or memory beyond the limit.
// tools/fuzz.sh runs it (target ccd_queries).

#include "15_body_contact/ccd.hpp"

#include "common/error.hpp"
#include "fuzz/scratch.hpp"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string_view>

extern "C" int LLVMFuzzerInitialize(int*, char***)
{
    fem::fuzz::initialize();
    std::filesystem::create_directories(fem::fuzz::scratch() / "vertex-face");
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::filesystem::path path = fem::fuzz::scratch() / "vertex-face" / "fuzz-input.csv";
    {
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
        if (!out.flush()) {
            std::fprintf(stderr, "fuzz_ccd_queries: cannot write %s\n", path.c_str());
            std::abort();
        }
    }
    try {
        using namespace fem::contact;
        for (const CcdQuery& query : read_ccd_queries(path))
            for (PrimitivePair pair : {PrimitivePair::point_triangle, PrimitivePair::edge_edge}) {
                cubic_ccd(pair, query.motion);
                inclusion_ccd(pair, query.motion, {1e-6, 10'000});
            }
    } catch (const fem::Error& error) {
        if (std::string_view(error.what()).find("fuzz-input") == std::string_view::npos) {
            std::fprintf(stderr, "fuzz_ccd_queries: an fem::Error that does not name the file: %s\n", error.what());
            std::abort();
        }
    }
    return 0;
}
