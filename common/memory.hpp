#pragma once
// How much memory a run took: the peak resident set size of this process, which every chapter
// executable prints at the end of a run (ChapterCli::run), so that the course's memory needs are
// measured, not guessed (docs/engineering.md, "Memory"); and how far it rises while one piece of
// code runs (PeakMemoryRise, chapter 06's assembly routes).

#include <cstdint>
#include <optional>

namespace fem {

/// The largest resident set size this process has had so far [bytes]: getrusage(RUSAGE_SELF)'s
/// ru_maxrss (Linux counts it in KiB). It never falls: memory given back does not lower it.
std::int64_t peak_resident_bytes();

/// How far the resident memory rises above its level at construction while the object lives:
/// rise = VmHWM − VmRSS₀ [bytes], from /proc/self/status, after the kernel's peak counter VmHWM is
/// reset by writing 5 to /proc/self/clear_refs (Linux ≥ 4.0). Process-wide: it counts everything
/// the process touches meanwhile, allocator slack included.
class PeakMemoryRise {
public:
    PeakMemoryRise();
    /// max(0, VmHWM − VmRSS₀) [bytes]; nullopt where it cannot be measured (not Linux, or the
    /// reset of the peak counter failed).
    std::optional<double> rise_bytes() const;

private:
    bool reset_ok_ = false;
    std::optional<double> start_;
};

}  // namespace fem
