// Chapter 12: the line search's volume filter (chapters/12_hyperelastic_newton/volume_filter.hpp).
// docs/12_hyperelastic_newton.md#the-volume-filter
#include "12_hyperelastic_newton/volume_filter.hpp"

#include "12_hyperelastic_newton/materials.hpp"

#include "common/error.hpp"
#include "common/parallel.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace fem::hyper {

Eigen::Vector4d determinant_cubic(const Eigen::Matrix3d& E, const Eigen::Matrix3d& dE)
{
    return {E.determinant(), cofactor(E).cwiseProduct(dE).sum(), cofactor(dE).cwiseProduct(E).sum(), dE.determinant()};
}

double first_crossing(const Eigen::Vector4d& c, double floor)
{
    if (!c.allFinite() || !std::isfinite(floor))
        throw Error(str("first_crossing: the cubic's coefficients (", c.transpose(), ") and the floor ", floor,
                        " must be finite"));
    if (!(c[0] > floor))
        throw Error(str("first_crossing: the cubic must start above the floor, got c0 = ", c[0], " <= ", floor));
    const double start = c[0] - floor;  // g(s) = start + c₁ s + c₂ s² + c₃ s³ > 0 at s = 0
    if (start > std::abs(c[1]) + std::abs(c[2]) + std::abs(c[3]))
        return 1.0;  // |c₁ s + c₂ s² + c₃ s³| < start on [0, 1]: the common case of a free step
    const auto g = [&](double s) { return start + s * (c[1] + s * (c[2] + s * c[3])); };
    // The pieces of [0, 1] where g is monotone: split at the roots of g' = c₁ + 2c₂ s + 3c₃ s² in (0, 1).
    std::array<double, 4> ends{0.0, 1.0, 1.0, 1.0};
    int count = 1;  // pieces; ends[0 … count] bound them
    const auto split = [&](double s) {
        if (!(s > 0.0 && s < 1.0))
            return;
        int k = count++;
        for (; k > 0 && ends[static_cast<std::size_t>(k - 1)] > s; --k)  // insert s in order
            ends[static_cast<std::size_t>(k)] = ends[static_cast<std::size_t>(k - 1)];
        ends[static_cast<std::size_t>(k)] = s;
    };
    const double a = 3.0 * c[3], b = 2.0 * c[2];
    if (a == 0.0) {
        if (b != 0.0)
            split(-c[1] / b);
    } else {
        const double discriminant = b * b - 4.0 * a * c[1];
        if (discriminant >= 0.0) {
            // The two roots without cancellation: q = −(b + sign(b) √D)/2, s = q/a and c₁/q.
            const double q = -0.5 * (b + std::copysign(std::sqrt(discriminant), b));
            split(q / a);
            if (q != 0.0)
                split(c[1] / q);
        }
    }
    ends[static_cast<std::size_t>(count)] = 1.0;
    for (int k = 0; k < count; ++k) {
        double low = ends[static_cast<std::size_t>(k)], high = ends[static_cast<std::size_t>(k + 1)];
        if (g(high) > 0.0)
            continue;  // g is monotone on the piece and positive at both ends
        // g(low) > 0 ≥ g(high): bisect to the last double, keeping g(low) > 0.
        for (;;) {
            const double middle = 0.5 * (low + high);
            if (middle <= low || middle >= high)
                break;
            (g(middle) > 0.0 ? low : high) = middle;
        }
        return low;
    }
    return 1.0;
}

double largest_volume_keeping_step(const TetMesh& mesh, const MatrixX3d& x, const MatrixX3d& dx, double fraction,
                                   int* binding_tet)
{
    if (x.rows() != mesh.V.rows() || dx.rows() != mesh.V.rows())
        throw Error(str("volume filter: x and dx need one row per vertex (", mesh.V.rows(), "), got ", x.rows(),
                        " and ", dx.rows()));
    if (!(fraction >= 0.0 && fraction < 1.0))
        throw Error(str("volume filter: the fraction of a tet's volume to keep must lie in [0, 1), got ", fraction));
    if (!x.allFinite() || !dx.allFinite())
        throw Error("volume filter: the positions x and their change dx must be finite");
    std::vector<double> steps(static_cast<std::size_t>(mesh.T.rows()), 1.0);
    parallel_for(mesh.T.rows(), [&](Eigen::Index t) {
        Eigen::Matrix3d E, dE;  // the edges from vertex 0, one a column
        for (int k = 0; k < 3; ++k) {
            E.col(k) = (x.row(mesh.T(t, k + 1)) - x.row(mesh.T(t, 0))).transpose();
            dE.col(k) = (dx.row(mesh.T(t, k + 1)) - dx.row(mesh.T(t, 0))).transpose();
        }
        const Eigen::Vector4d c = determinant_cubic(E, dE);
        if (c[0] > 0.0)
            steps[static_cast<std::size_t>(t)] = first_crossing(c, fraction * c[0]);
    });
    const auto smallest = std::min_element(steps.begin(), steps.end());
    const double step = smallest == steps.end() ? 1.0 : *smallest;
    if (binding_tet != nullptr)
        *binding_tet = step < 1.0 ? static_cast<int>(smallest - steps.begin()) : -1;
    return step;
}

}  // namespace fem::hyper
