// How much memory a piece of code takes (common/memory.hpp), and the BLAS's thread switch
// (common/parallel.hpp): a rise measured against the bytes a test touches itself.
#include "common/error.hpp"
#include "common/memory.hpp"
#include "common/parallel.hpp"

#include <catch2/catch.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>

using Catch::Matchers::Contains;

TEST_CASE("PeakMemoryRise counts the bytes touched while it lives, and peak_resident_bytes covers them",
          "[common][memory]")
{
    constexpr std::size_t touched = 64'000'000;
    const fem::PeakMemoryRise rise;
    {
        const auto block = std::make_unique<char[]>(touched);
        std::memset(block.get(), 1, touched);  // resident only once written
        volatile char read_back = block[touched - 1];
        CHECK(read_back == 1);
    }
    const std::optional<double> bytes = rise.rise_bytes();
    if (!bytes) {
        WARN("SKIPPED: /proc/self/clear_refs or /proc/self/status is not available (not Linux)");
        return;
    }
    CAPTURE(*bytes);
    CHECK(*bytes >= 0.95 * double(touched));
    CHECK(fem::peak_resident_bytes() >= std::int64_t(touched));
}

TEST_CASE("set_blas_threads refuses fewer than one thread", "[common][threads]")
{
    CHECK_THROWS_AS(fem::set_blas_threads(0), fem::Error);
    CHECK_THROWS_WITH(fem::set_blas_threads(-3), Contains("at least 1 thread, got -3"));
}
