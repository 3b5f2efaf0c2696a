#include "common/threads_study.hpp"

#include "common/error.hpp"
#include "common/parallel.hpp"
#include "common/timer.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <vector>

#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

namespace fem {

BusyCore::BusyCore()
{
    pid_ = ::fork();
    if (pid_ < 0)
        throw Error(str("BusyCore: fork() failed: ", std::strerror(errno)));
    if (pid_ == 0) {
        ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlive the study
        volatile unsigned long spin = 0;
        for (;;)
            spin = spin + 1;
    }
}

BusyCore::~BusyCore()
{
    if (pid_ > 0) {
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, nullptr, 0);
    }
}

namespace {

/// The median wall time of calls of work() over `seconds` of measuring (at least 3 calls); every
/// result is compared with `reference` (set by the first call when empty); identical turns false
/// on the first difference.
double median_time(const std::function<Eigen::VectorXd()>& work, double seconds, Eigen::VectorXd& reference,
                   bool& identical)
{
    std::vector<double> times;
    const Timer total;
    while (times.size() < 3 || total.seconds() < seconds) {
        const Timer once;
        const Eigen::VectorXd result = work();
        times.push_back(once.seconds());
        if (reference.size() == 0)
            reference = result;
        else if (result.size() != reference.size() || result != reference)
            identical = false;
    }
    return median(std::move(times));
}

}  // namespace

Table threads_table(const std::string& title, const std::function<Eigen::VectorXd()>& work, double seconds)
{
    if (!(seconds > 0.0))
        throw Error(str("threads_table: the measuring time must be > 0 s, got ", seconds));
    constexpr int counts[] = {1, 2};
    double quiet[2] = {}, busy[2] = {};
    bool identical[2] = {true, true};
    Eigen::VectorXd reference;
    for (int k = 0; k < 2; ++k) {
        const ScopedThreadCount threads(counts[k]);
        quiet[k] = median_time(work, seconds, reference, identical[k]);
    }
    {
        const BusyCore spinner;
        for (int k = 0; k < 2; ++k) {
            const ScopedThreadCount threads(counts[k]);
            busy[k] = median_time(work, seconds, reference, identical[k]);
        }
    }
    Table table(title, {{"threads", Format::integer},
                        {"quiet: time [s]", Format::scientific, 2},
                        {"quiet: speed-up [measured]", Format::fixed, 2},
                        {"one core busy: time [s]", Format::scientific, 2},
                        {"one core busy: 1 thread / this row [measured]", Format::fixed, 2},
                        {"results identical to 1 thread", Format::text}});
    for (int k = 0; k < 2; ++k)
        table.add_row({double(counts[k]), quiet[k], quiet[0] / quiet[k], busy[k], busy[0] / busy[k],
                       std::string(identical[k] ? "yes" : "no")});
    return table;
}

}  // namespace fem
