#pragma once
// The memory bandwidth of this machine, measured in the same run as a kernel, so that a kernel's
// speed can be reported as a fraction of what the memory delivers (chapters 02 and 07).
// docs/02_heat_equation.md#speed-against-memory-bandwidth

#include <cstddef>

namespace fem {

/// The bandwidth in GB/s (1 GB = 10⁹ bytes) one thread sustains on the STREAM "triad"
/// a[i] = b[i] + s·c[i] over three arrays of `elements` doubles each: the best of repeated sweeps
/// during at least min_seconds (the minimum filters out the rest of the machine).
///
/// Bytes counted per element: 3 × 8 (read b[i], read c[i], write a[i]), STREAM's convention. The
/// write-allocate read that most caches make before writing a[i] is *not* counted, so the traffic
/// on the memory bus is up to 4/3 of the counted one; count the bytes of a kernel the same way.
///
/// To measure main memory rather than a cache, 3 × 8 × elements must be well above the last-level
/// cache: the default 2²³ elements gives 192 MB. Timings are never asserted (they are machine
/// dependent). fem::Error if elements is 0 or min_seconds is not a finite number > 0.
double measure_triad_bandwidth(std::size_t elements = std::size_t{1} << 23, double min_seconds = 0.2);

}  // namespace fem
