// Stop signals (common/interrupt.hpp): SIGINT, SIGTERM and SIGHUP each ask a run to stop and are
// told apart for the exit code; a second one is left to its default action. Folders of killed runs
// (common/files.hpp's remove_abandoned) are removed, those of running ones are not.
#include "common/files.hpp"
#include "common/interrupt.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <csignal>
#include <filesystem>

#include <sys/wait.h>
#include <unistd.h>

TEST_CASE("SIGINT, SIGTERM and SIGHUP each ask to stop and are told apart, and request_stop asks without one", "[common][interrupt]")
{
    for (const int signal : {SIGINT, SIGTERM, SIGHUP}) {
        INFO(signal);
        fem::catch_stop_signals();
        CHECK_FALSE(fem::stop_requested());
        CHECK(std::raise(signal) == 0);  // the process lives on
        CHECK(fem::stop_requested());
        CHECK(fem::stop_signal() == signal);
    }
    fem::catch_stop_signals();
    fem::request_stop();
    CHECK(fem::stop_requested());
    CHECK(fem::stop_signal() == 0);
    fem::catch_stop_signals();  // no request left for the tests after this one
    for (const int signal : {SIGINT, SIGTERM, SIGHUP})
        std::signal(signal, SIG_DFL);
}

TEST_CASE("a second stop signal ends the process at once, with that signal", "[common][interrupt]")
{
    const pid_t child = ::fork();
    REQUIRE(child >= 0);
    if (child == 0) {
        fem::catch_stop_signals();
        std::raise(SIGTERM);
        std::raise(SIGTERM);
        ::_exit(0);  // not reached
    }
    int status = 0;
    REQUIRE(::waitpid(child, &status, 0) == child);
    CHECK(WIFSIGNALED(status));
    CHECK(WTERMSIG(status) == SIGTERM);
}

TEST_CASE("remove_abandoned removes the folders of processes that no longer run, and only those", "[common][files]")
{
    const std::filesystem::path dir = fem::test::fresh_output_dir("abandoned");
    const pid_t child = ::fork();
    REQUIRE(child >= 0);
    if (child == 0)
        ::_exit(0);
    REQUIRE(::waitpid(child, nullptr, 0) == child);  // a process id that no longer runs
    const std::filesystem::path dead = dir / ("fem-tetgen-" + std::to_string(child) + "-0");
    const std::filesystem::path alive = dir / ("fem-tetgen-" + std::to_string(::getpid()) + "-0");
    const std::filesystem::path other = dir / ("other-" + std::to_string(child));
    for (const auto& folder : {dead, alive, other})
        fem::write_file(folder / "surface.off", "OFF");
    fem::remove_abandoned(dir, "fem-tetgen-");
    CHECK_FALSE(std::filesystem::exists(dead));
    CHECK(std::filesystem::exists(alive));
    CHECK(std::filesystem::exists(other));
}
