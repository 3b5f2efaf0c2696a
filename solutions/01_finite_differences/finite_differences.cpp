// Chapter 01: finite difference stencils and observed orders. docs/01_finite_differences.md
#include "01_finite_differences/finite_differences.hpp"

#include "common/error.hpp"

#include <cmath>

namespace fem::fd {
namespace {

void check_step(double h)
{
    require_positive(h, "the finite difference step h");
}

void check_convergence_data(const std::vector<double>& h, const std::vector<double>& error)
{
    if (h.size() != error.size())
        throw Error(str("observed order: ", h.size(), " steps h but ", error.size(),
                        " errors; give one error per step"));
    if (h.size() < 2)
        throw Error(str("observed order: needs at least 2 runs, got ", h.size()));
    for (std::size_t i = 0; i < h.size(); ++i) {
        require_positive(h[i], str("observed order: step h[", i, "]"));
        require_positive(error[i], str("observed order: error[", i, "] (an exact result has no order)"));
    }
}

}  // namespace

double forward_difference(const ScalarFunction& f, double x, double h)
{
    check_step(h);
    // BEGIN EXERCISE 01.1 forward_difference #one-sided-differences
    // HINT: the slope of the secant through x and x + h.
    return (f(x + h) - f(x)) / h;
    // END EXERCISE
}

double backward_difference(const ScalarFunction& f, double x, double h)
{
    check_step(h);
    // BEGIN EXERCISE 01.2 backward_difference #one-sided-differences
    // HINT: the slope of the secant through x − h and x.
    return (f(x) - f(x - h)) / h;
    // END EXERCISE
}

double central_difference(const ScalarFunction& f, double x, double h)
{
    check_step(h);
    // BEGIN EXERCISE 01.3 central_difference #central-differences
    // HINT: the secant through x − h and x + h; its Taylor series loses the h² f''/2 terms.
    return (f(x + h) - f(x - h)) / (2.0 * h);
    // END EXERCISE
}

double central_second_difference(const ScalarFunction& f, double x, double h)
{
    check_step(h);
    // BEGIN EXERCISE 01.4 central_second_difference #the-second-derivative
    // HINT: the difference of the forward and backward slopes, divided by h.
    return (f(x + h) - 2.0 * f(x) + f(x - h)) / (h * h);
    // END EXERCISE
}

std::vector<double> observed_orders(const std::vector<double>& h, const std::vector<double>& error)
{
    check_convergence_data(h, error);
    // BEGIN EXERCISE 01.5 observed_orders #observed-order-of-convergence
    // HINT: if e = C hᵖ for two runs, then e_i / e_{i+1} = (h_i / h_{i+1})ᵖ.
    std::vector<double> orders;
    for (std::size_t i = 0; i + 1 < h.size(); ++i)
        orders.push_back(std::log(error[i] / error[i + 1]) / std::log(h[i] / h[i + 1]));
    return orders;
    // END EXERCISE
}

double fitted_order(const std::vector<double>& h, const std::vector<double>& error)
{
    check_convergence_data(h, error);
    const double n = static_cast<double>(h.size());
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (std::size_t i = 0; i < h.size(); ++i) {
        const double x = std::log(h[i]), y = std::log(error[i]);
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    const double spread = n * sxx - sx * sx;
    if (!(spread > 0))
        throw Error("observed order: all steps h are equal; vary h to measure an order");
    return (n * sxy - sx * sy) / spread;
}

}  // namespace fem::fd
