#include "14_contact/barrier.hpp"

#include "common/error.hpp"

#include <cmath>
#include <limits>

namespace fem::contact {

BarrierValue barrier(double d, double activation_distance)
{
    require_positive(activation_distance, "activation distance d̂ [m]");
    BarrierValue b;
    if (!(d > 0.0)) {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        return {std::numeric_limits<double>::infinity(), nan, nan};
    }
    if (d >= activation_distance)
        return b;
    // BEGIN EXERCISE 14.1 barrier #the-barrier
    // HINT: with g = d − d̂ and L = ln(d/d̂): b = −g² L, b' = −2 g L − g²/d,
    // HINT: b'' = −2 L − 4 g/d + g²/d² (the product rule twice; check it against central differences).
    const double gap = d - activation_distance, log_ratio = std::log(d / activation_distance);
    b.value = -gap * gap * log_ratio;
    b.first = -2.0 * gap * log_ratio - gap * gap / d;
    b.second = -2.0 * log_ratio - 4.0 * gap / d + gap * gap / (d * d);
    // END EXERCISE
    return b;
}

}  // namespace fem::contact
