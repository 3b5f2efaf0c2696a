#pragma once
// Wall-clock timing for the speed-against-error tables. Timings are printed, never asserted.

#include "common/error.hpp"

#include <algorithm>
#include <chrono>
#include <vector>

namespace fem {

/// A stopwatch: starts on construction; seconds() reads the elapsed wall time.
class Timer {
public:
    Timer() : start_(Clock::now()) {}
    void restart() { start_ = Clock::now(); }
    /// Elapsed wall-clock seconds since construction or the last restart().
    double seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

private:
    using Clock = std::chrono::steady_clock;
    Clock::time_point start_;
};

/// A stopwatch for a scope: adds the wall time from its construction to its end (a return or an
/// exception) to a sum, e.g. the seconds of every call of a function (ContactClocks of chapter 14).
class ScopeTimer {
public:
    /// Adds to seconds (it must outlive this).
    explicit ScopeTimer(double& seconds) : seconds_(seconds) {}
    ScopeTimer(const ScopeTimer&) = delete;
    ScopeTimer& operator=(const ScopeTimer&) = delete;
    ~ScopeTimer() { seconds_ += timer_.seconds(); }

private:
    double& seconds_;
    Timer timer_;
};

/// The best (smallest) wall time in seconds of one call of work(), over repeated calls that stop
/// after min_total_seconds of measuring or max_repeats calls, whichever comes first. The minimum
/// filters out noise from the rest of the machine.
template <typename Work>
double best_time(Work&& work, double min_total_seconds = 0.2, int max_repeats = 1000)
{
    double best = 1e300;
    Timer total;
    for (int repeat = 0; repeat < max_repeats; ++repeat) {
        Timer once;
        work();
        const double t = once.seconds();
        if (t < best)
            best = t;
        if (total.seconds() >= min_total_seconds)
            break;
    }
    return best;
}

/// The median of a list of times (of an even count, the upper of the two middle ones): for
/// timings whose spread is part of what they show, where a minimum would hide it. fem::Error for
/// an empty list.
inline double median(std::vector<double> times)
{
    if (times.empty())
        throw Error("median: no times");
    std::nth_element(times.begin(), times.begin() + times.size() / 2, times.end());
    return times[times.size() / 2];
}

}  // namespace fem
