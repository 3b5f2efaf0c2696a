// The triad bandwidth measurement: a finite positive number of GB/s, and clear errors on bad input.
// (No assertion on its size: timings depend on the machine.)
#include "common/bandwidth.hpp"
#include "common/error.hpp"

#include <catch2/catch.hpp>

#include <cmath>

TEST_CASE("the triad bandwidth is a finite positive number of GB/s", "[common][bandwidth]")
{
    const double gigabytes_per_second = fem::measure_triad_bandwidth(std::size_t{1} << 16, 0.01);
    CHECK(std::isfinite(gigabytes_per_second));
    CHECK(gigabytes_per_second > 0.0);
}

TEST_CASE("the triad bandwidth rejects empty arrays and a bad measuring time", "[common][bandwidth]")
{
    CHECK_THROWS_AS(fem::measure_triad_bandwidth(0, 0.01), fem::Error);
    CHECK_THROWS_AS(fem::measure_triad_bandwidth(1024, 0.0), fem::Error);
    CHECK_THROWS_AS(fem::measure_triad_bandwidth(1024, std::nan("")), fem::Error);
}
