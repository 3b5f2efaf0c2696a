#pragma once
// Independent references for the tests of chapter 02: the 5-point Laplacian built as a Kronecker
// sum of 1D second-difference matrices (not by the chapter's code), the discrete eigenvalue
// written out, the explicit stability limit written out, and the max-norm distance between grid
// functions.

#include "02_heat_equation/heat_grid.hpp"

#include <Eigen/Core>

#include <cmath>
#include <numbers>

namespace fem::heat::test {

/// L = (T ⊗ I + I ⊗ T) / h², T = tridiag(1, −2, 1) of size n: the 2D second difference with zero
/// boundary values, as a dense matrix, for unknowns numbered k = (i−1) + n (j−1).
inline Eigen::MatrixXd kronecker_laplacian(int n)
{
    const double h = 1.0 / (n + 1);
    Eigen::MatrixXd T = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < n; ++i) {
        T(i, i) = -2.0;
        if (i + 1 < n)
            T(i, i + 1) = T(i + 1, i) = 1.0;
    }
    const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(n, n);
    Eigen::MatrixXd L(n * n, n * n);
    for (int a = 0; a < n; ++a)  // block row (the y index j−1)
        for (int b = 0; b < n; ++b)
            L.block(a * n, b * n, n, n) = T(a, b) * I + I(a, b) * T;  // T_y ⊗ I_x + I_y ⊗ T_x
    return L / (h * h);
}

/// The eigenvalue of the 5-point Laplacian for sin(kπx) sin(lπy), written out independently.
inline double eigenvalue_formula(int n, int k, int l)
{
    const double h = 1.0 / (n + 1), pi = std::numbers::pi;
    return -(4.0 / (h * h)) *
           (std::pow(std::sin(k * pi * h / 2.0), 2) + std::pow(std::sin(l * pi * h / 2.0), 2));
}

/// The explicit stability limit h²/(4c) written out, so that the tests of the exercises before
/// explicit_stability_limit (02.5) do not need it to pick their time steps.
inline double explicit_limit_formula(double h, double c)
{
    return h * h / (4.0 * c);
}

/// max_k |a_k − b_k|
inline double max_difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b)
{
    return (a - b).cwiseAbs().maxCoeff();
}

}  // namespace fem::heat::test
