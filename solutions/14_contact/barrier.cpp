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

MollifierValue friction_mollifier(double y, double epsilon)
{
    require_positive(epsilon, "friction smoothing ε = ε_v Δt [m]");
    if (!(y >= 0.0))
        throw Error(str("friction_mollifier: the tangential displacement y must be >= 0, got ", y));
    MollifierValue f;
    if (y >= epsilon)
        return {y, 1.0, 0.0};
    // BEGIN EXERCISE 14.4 friction_mollifier #friction
    // HINT: below ε: f₁ = 2y/ε − y²/ε², its derivative f₁' = 2/ε − 2y/ε², and its integral with
    // HINT: f₀(ε) = ε (continuous with f₀ = y above ε): f₀ = y²/ε − y³/(3ε²) + ε/3.
    f.f1 = 2.0 * y / epsilon - y * y / (epsilon * epsilon);
    f.f1_derivative = 2.0 / epsilon - 2.0 * y / (epsilon * epsilon);
    f.f0 = y * y / epsilon - y * y * y / (3.0 * epsilon * epsilon) + epsilon / 3.0;
    // END EXERCISE
    return f;
}

}  // namespace fem::contact
