#include "common/tetgen.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/interrupt.hpp"
#include "common/mesh_io.hpp"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <vector>

#include <poll.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

namespace fem {

namespace {

constexpr const char* folder_prefix = "fem-tetgen-";

/// A temporary folder, removed with everything in it when this goes out of scope.
struct TemporaryFolder {
    std::filesystem::path path;
    ~TemporaryFolder()
    {
        std::error_code ignored;
        std::filesystem::remove_all(path, ignored);
    }
};

/// How a child process ended, and what it printed (stdout and stderr together).
struct ChildResult {
    int status = 0;
    std::string output;
    bool timed_out = false, stopped = false;
};

/// Runs arguments[0] (found on PATH) with its output captured, an address space of at most
/// memory bytes and at most seconds of wall-clock time (then killed), killed too when a stop
/// signal arrives.
ChildResult run_limited(const std::vector<std::string>& arguments, std::size_t memory, double seconds,
                        const std::string& what)
{
    std::vector<char*> argv;
    for (const std::string& argument : arguments)
        argv.push_back(const_cast<char*>(argument.c_str()));
    argv.push_back(nullptr);
    int pipe_ends[2];
    if (::pipe(pipe_ends) != 0)
        throw Error(str(what, ": cannot start TetGen: ", std::strerror(errno)));
    const rlim_t address_space = static_cast<rlim_t>(memory);
    const rlim_t cpu = static_cast<rlim_t>(seconds) + 1;
    const pid_t child = ::fork();
    if (child < 0) {
        ::close(pipe_ends[0]);
        ::close(pipe_ends[1]);
        throw Error(str(what, ": cannot start TetGen: ", std::strerror(errno)));
    }
    if (child == 0) {  // only async-signal-safe calls until exec
        ::dup2(pipe_ends[1], 1);
        ::dup2(pipe_ends[1], 2);
        ::close(pipe_ends[0]);
        ::close(pipe_ends[1]);
        const rlimit as{address_space, address_space}, time{cpu, cpu};
        ::setrlimit(RLIMIT_AS, &as);
        ::setrlimit(RLIMIT_CPU, &time);
        ::execvp(argv[0], argv.data());
        ::_exit(127);
    }
    ::close(pipe_ends[1]);
    ChildResult result;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    char buffer[4096];
    for (;;) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
        if (left.count() <= 0) {
            result.timed_out = true;
            break;
        }
        if (stop_requested()) {
            result.stopped = true;
            break;
        }
        pollfd readable{pipe_ends[0], POLLIN, 0};
        const int ready = ::poll(&readable, 1, static_cast<int>(std::min<long long>(left.count(), 200)));
        if (ready <= 0)
            continue;  // a timeout of this wait, or a signal: check the deadline and stop again
        const ssize_t n = ::read(pipe_ends[0], buffer, sizeof buffer);
        if (n <= 0)
            break;  // the child closed its output: it has ended
        if (result.output.size() < (1u << 20))  // TetGen's words, not a flood
            result.output.append(buffer, static_cast<std::size_t>(n));
    }
    ::close(pipe_ends[0]);
    if (result.timed_out || result.stopped)
        ::kill(child, SIGKILL);
    while (::waitpid(child, &result.status, 0) < 0 && errno == EINTR) {
    }
    return result;
}

/// TetGen's own words: its error or failed assertion if it printed one, else its last line.
std::string tetgen_reason(const std::string& output)
{
    std::string reason, last;
    std::istringstream lines(output);
    for (std::string line; std::getline(lines, line);) {
        if (!line.empty())
            last = line;
        const std::size_t assertion = line.find("Assertion");
        if (reason.empty() && assertion != std::string::npos)
            reason = line.substr(assertion);
        else if (reason.empty() && line.find("rror") != std::string::npos)
            reason = line;
    }
    return reason.empty() ? last : reason;
}

}  // namespace

TetMesh tetrahedralize(const TriMesh& surface, const std::string& switches, const std::string& what,
                       const TetgenLimits& limits)
{
    if (switches.find_first_not_of("pqaYAVQzcCfMnTo0123456789.e") != std::string::npos || switches.find('p') == std::string::npos)
        throw Error(str(what, ": TetGen switches '", switches.substr(0, 100), "' must include p (tetrahedralise a ",
                        "surface) and be plain switches such as pq1.5aY"));
    static std::atomic<int> counter{0};
    const std::filesystem::path temporary = std::filesystem::temp_directory_path();
    remove_abandoned(temporary, folder_prefix);
    const TemporaryFolder folder{temporary / str(folder_prefix, ::getpid(), "-", counter++)};
    ensure_directory(folder.path);
    // TetGen reads an .off surface (it has no .obj reader).
    std::ostringstream off;
    off.precision(17);
    off << "OFF\n" << surface.V.rows() << ' ' << surface.F.rows() << " 0\n";
    for (Eigen::Index v = 0; v < surface.V.rows(); ++v)
        off << surface.V(v, 0) << ' ' << surface.V(v, 1) << ' ' << surface.V(v, 2) << '\n';
    for (Eigen::Index f = 0; f < surface.F.rows(); ++f)
        off << "3 " << surface.F(f, 0) << ' ' << surface.F(f, 1) << ' ' << surface.F(f, 2) << '\n';
    write_file(folder.path / "surface.off", off.str());
    const ChildResult run = run_limited({"tetgen", str("-", switches, "Q"), (folder.path / "surface.off").string()},
                                        limits.memory, limits.seconds, what);
    if (run.stopped)
        throw Error(str(what, ": TetGen stopped by a signal before it finished"));
    const std::string advice = "ask for less: a larger q ratio (e.g. pq1.5) or a larger maximum volume after a";
    if (run.timed_out)
        throw Error(str(what, ": TetGen did not finish within its limit of ", limits.seconds, " s with switches '",
                        switches, "'; ", advice));
    const std::filesystem::path node = folder.path / "surface.1.node";
    const bool exited = WIFEXITED(run.status);
    if (exited && WEXITSTATUS(run.status) == 0 && std::filesystem::exists(node))
        return io::read_tet_mesh(node);
    if (exited && WEXITSTATUS(run.status) == 127)
        throw Error(str(what, ": the tetgen program is not installed (tools/setup.sh installs it)"));
    std::string reason = tetgen_reason(run.output);
    if (WIFSIGNALED(run.status) && WTERMSIG(run.status) == SIGXCPU)
        throw Error(str(what, ": TetGen exceeded its limit of ", limits.seconds, " s of processor time with switches '",
                        switches, "'; ", advice));
    // Out of memory, TetGen 1.5 throws its error code (an int) past its main: "terminate called
    // after throwing an instance of 'int'", the same words as for a few of its other failures.
    if (reason.find("emory") != std::string::npos || reason.find("bad_alloc") != std::string::npos ||
        reason.find("instance of 'int'") != std::string::npos)
        throw Error(str(what, ": TetGen gave up with switches '", switches, "' (", reason,
                        "): out of memory within its limit of ", limits.memory >> 20,
                        " MB, or a surface it cannot mesh; ", advice));
    if (reason.empty())
        reason = WIFSIGNALED(run.status) ? str("it ended with signal ", WTERMSIG(run.status)) : "no output";
    throw Error(str(what, ": TetGen could not tetrahedralise the surface (does it enclose a volume, closed and ",
                    "free of self-intersections?): ", reason));
}

}  // namespace fem
