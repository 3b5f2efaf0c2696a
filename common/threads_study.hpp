#pragma once
// The threads tables of chapters 08-12: one piece of work timed on 1 and 2 threads, on the machine
// as it is and again beside a process that keeps one core busy, with a check that every run gives
// the same bits as the first.
//
// Why a busy core: on a student's laptop or a shared server another program often holds a core.
// OpenMP threads that spin while they wait for each other then compete with it for that core, and
// 2 threads can take several times as long as 1 (docs/engineering.md, "Threads on a busy
// machine"). The course makes its threads wait asleep (fem::wait_passively); the "one core busy"
// columns show what that buys, measured by the study itself: it starts the spinning process
// (BusyCore) for its second run.

#include "common/table.hpp"

#include <Eigen/Core>

#include <functional>
#include <string>

namespace fem {

/// A child process that spins on one core for as long as this object lives (fork(); the child
/// runs an empty loop and nothing else). The destructor kills it (SIGKILL) and reaps it; the child
/// also dies with its parent (PR_SET_PDEATHSIG). fem::Error if fork() fails.
class BusyCore {
public:
    BusyCore();
    ~BusyCore();
    BusyCore(const BusyCore&) = delete;
    BusyCore& operator=(const BusyCore&) = delete;

private:
    int pid_ = -1;
};

/// The threads table of one piece of work: `work()` (e.g. one time step from a fixed state,
/// returning the new displacement) is timed on 1 and 2 threads (fem::ScopedThreadCount), first on
/// the machine as it is ("quiet"), then with one core held by a BusyCore. Each time is the median
/// of the calls made in `seconds` of measuring (at least 3), since under a busy core the spread is
/// the point and a minimum would hide it. Columns:
///   threads | quiet: time [s] | quiet: speed-up [measured] | one core busy: time [s] |
///   one core busy: 1 thread / this row [measured] | results identical to 1 thread
/// The speed-ups divide the 1-thread time of the same column pair by the row's; "identical" compares
/// every call's result, bit for bit, with the first call's (1 thread, quiet). fem::Error for
/// seconds ≤ 0.
Table threads_table(const std::string& title, const std::function<Eigen::VectorXd()>& work, double seconds);

}  // namespace fem
