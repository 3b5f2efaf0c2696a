// The threads tables' machinery (common/threads_study.hpp): the spinning process really spins and
// is reaped, and the table tells results that change with the thread count from those that do not.
#include "common/error.hpp"
#include "common/parallel.hpp"
#include "common/threads_study.hpp"

#include <catch2/catch.hpp>

#include <chrono>
#include <string>
#include <thread>

#include <sys/resource.h>

namespace {

/// CPU seconds of the reaped children of this process (getrusage RUSAGE_CHILDREN, user time).
double children_cpu_seconds()
{
    rusage usage{};
    getrusage(RUSAGE_CHILDREN, &usage);
    return double(usage.ru_utime.tv_sec) + 1e-6 * double(usage.ru_utime.tv_usec);
}

}  // namespace

TEST_CASE("BusyCore spins a child process while it lives and reaps it when it goes", "[common][threads]")
{
    const double before = children_cpu_seconds();
    {
        const fem::BusyCore spinner;
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
    }
    // Reaped children add their CPU time here; a child that did not spin (or was not reaped) adds none.
    CHECK(children_cpu_seconds() - before > 0.05);
}

TEST_CASE("threads_table times 1 and 2 threads, quiet and busy, and checks the bits", "[common][threads]")
{
    const auto text = [](const fem::Table& table, std::size_t row) {
        return std::get<std::string>(table.cell(row, table.columns().size() - 1));
    };
    int calls = 0;
    const fem::Table same = fem::threads_table("same", [&] {
        ++calls;
        return Eigen::VectorXd::Constant(4, 1.0 / 3.0).eval();
    }, 0.01);
    REQUIRE(same.rows() == 2);
    CHECK(same.numbers("threads") == std::vector<double>{1.0, 2.0});
    CHECK(text(same, 0) == "yes");
    CHECK(text(same, 1) == "yes");
    CHECK(calls >= 12);  // at least 3 calls in each of the four runs
    CHECK(same.numbers("quiet: speed-up [measured]")[0] == 1.0);
    CHECK(same.numbers("one core busy: 1 thread / this row [measured]")[0] == 1.0);

    // A result that depends on the thread count is caught on the 2-thread row only.
    const fem::Table differs = fem::threads_table("differs", [] {
        return Eigen::VectorXd::Constant(1, double(fem::thread_count())).eval();
    }, 0.01);
    CHECK(text(differs, 0) == "yes");
#ifdef _OPENMP
    CHECK(text(differs, 1) == "no");
#endif
    CHECK_THROWS_AS(fem::threads_table("t", [] { return Eigen::VectorXd(); }, 0.0), fem::Error);
}
