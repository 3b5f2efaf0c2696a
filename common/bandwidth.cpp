#include "common/bandwidth.hpp"

#include "common/error.hpp"
#include "common/timer.hpp"

#include <vector>

namespace fem {

double measure_triad_bandwidth(std::size_t elements, double min_seconds)
{
    if (elements == 0)
        throw Error("measure_triad_bandwidth: the arrays need at least 1 element, got 0");
    require_positive(min_seconds, "measure_triad_bandwidth: min_seconds");
    // Filled here, by the thread that measures, so that the pages are mapped before timing.
    std::vector<double> a(elements, 0.0), b(elements, 1.0), c(elements, 2.0);
    const double s = 0.5;
    double* const pa = a.data();
    const double* const pb = b.data();
    const double* const pc = c.data();
    const double seconds = best_time(
        [&] {
            for (std::size_t i = 0; i < elements; ++i)
                pa[i] = pb[i] + s * pc[i];
        },
        min_seconds, 1000);
    // Read a result, so that the compiler must perform the sweeps.
    volatile double sink = a[elements / 2];
    (void)sink;
    return 3.0 * sizeof(double) * static_cast<double>(elements) / seconds * 1e-9;
}

}  // namespace fem
