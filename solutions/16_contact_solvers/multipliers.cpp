#include "16_contact_solvers/augmented_lagrangian.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <cmath>

namespace fem::contact {
namespace {

void require_multiplier_and_penalty(double multiplier, double penalty)
{
    require_positive(penalty, "augmented Lagrangian: penalty mu [N/m]");
    if (!std::isfinite(multiplier) || multiplier < 0.0)
        throw Error(str("augmented Lagrangian: multiplier lambda must be a finite number >= 0 [N], got ", multiplier));
}

}  // namespace

AugmentedTerm augmented_term(double gap, double multiplier, double penalty)
{
    require_multiplier_and_penalty(multiplier, penalty);
    AugmentedTerm term;
    term.value = -multiplier * multiplier / (2.0 * penalty);
    const double force = multiplier - penalty * gap;  // λ − μ g: the pair's force while it pushes
    if (force > 0.0) {
        term.value += force * force / (2.0 * penalty);  // (μ/2)(λ/μ − g)²
        term.slope = -force;
        term.curvature = penalty;
    }
    return term;
}

double augmented_multiplier(double gap, double multiplier, double penalty)
{
    require_multiplier_and_penalty(multiplier, penalty);
    require_finite(gap, "augmented Lagrangian: constraint g [m]");
    // BEGIN EXERCISE 16.1 augmented_multiplier #the-multiplier-update
    // HINT: the first-order update of an inequality's multiplier: the force the term exerted at g,
    // HINT: −∂ψ/∂g = λ − μ g where that is positive, else 0 (a pair that does not push).
    return std::max(0.0, multiplier - penalty * gap);
    // END EXERCISE
}

bool keeps_constraint(double gap, double multiplier, double separation, double filter_gap)
{
    // BEGIN EXERCISE 16.2 keeps_constraint #the-active-set
    // HINT: keep a pair that pushes (λ > 0) or one within filter_gap · δ beyond its constraint.
    return multiplier > 0.0 || gap <= filter_gap * separation;
    // END EXERCISE
}

bool outer_converged(const OuterResiduals& residuals, double separation, double violation_tolerance,
                     double dual_tolerance)
{
    // BEGIN EXERCISE 16.3 outer_converged #the-stopping-rule
    // HINT: three tests at once: the largest violation, the complementarity (both against a
    // HINT: tolerance times δ) and the time of impact having reached the step's end.
    return residuals.violation <= violation_tolerance * separation &&
           residuals.complementarity <= dual_tolerance * separation && residuals.impact_complete;
    // END EXERCISE
}

}  // namespace fem::contact
