#pragma once
// How much memory a run took: the peak resident set size of this process, which every chapter
// executable prints at the end of a run (ChapterCli::run), so that the course's memory needs are
// measured, not guessed (README.md, "Memory").

#include <cstdint>

namespace fem {

/// The largest resident set size this process has had so far [bytes]: getrusage(RUSAGE_SELF)'s
/// ru_maxrss (Linux counts it in KiB). It never falls: memory given back does not lower it.
std::int64_t peak_resident_bytes();

}  // namespace fem
