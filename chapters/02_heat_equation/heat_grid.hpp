#pragma once
// Chapter 02: the unit square as a grid, Dirichlet boundary values, and the 5-point Laplacian,
// matrix-free and assembled. docs/02_heat_equation.md
//
// The grid has (n+2)×(n+2) points (x_i, y_j) = (i h, j h), i, j = 0 … n+1, h = 1/(n+1). The n×n
// interior points are the unknowns; the boundary ring (i or j ∈ {0, n+1}) holds the Dirichlet
// values g. A grid function u is a vector of the n² unknowns, numbered k = (i−1) + n (j−1):
// i (the x index) runs fastest.

#include "common/vtk_io.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <functional>
#include <string>

namespace fem::heat {

/// A function of the position (x, y) in the unit square: boundary values, initial states.
using SpatialFunction = std::function<double(double x, double y)>;

/// The unit square sampled with n×n unknowns. docs/02_heat_equation.md#the-grid
struct Grid {
    int n = 32;  ///< unknowns per direction

    /// Grid spacing h = 1/(n+1).
    double h() const { return 1.0 / (n + 1); }
    /// The coordinate i h of grid line i = 0 … n+1 (x_i or y_j).
    double coordinate(int i) const { return i * h(); }
    /// The number of unknowns, n².
    Eigen::Index unknowns() const { return Eigen::Index{n} * n; }
    /// The number k = (i−1) + n (j−1) of the unknown at interior point (i, j), 1 ≤ i, j ≤ n.
    Eigen::Index unknown(int i, int j) const { return (i - 1) + Eigen::Index{n} * (j - 1); }
};

/// fem::Error unless 1 ≤ n ≤ 20000 (the sparse matrices index their 5n² entries with int).
void validate(const Grid& grid);

/// The Dirichlet values g on the boundary ring, each edge with n+2 values (corners included):
/// bottom[i] = g(x_i, 0), top[i] = g(x_i, 1), left[j] = g(0, y_j), right[j] = g(1, y_j),
/// i, j = 0 … n+1. The 5-point stencil never reads the four corners; images show bottom's and
/// top's. docs/02_heat_equation.md#dirichlet-boundary-values
struct BoundaryValues {
    Eigen::VectorXd bottom, top, left, right;
};

/// fem::Error unless every edge has n+2 values and every value is finite (names the edge and index).
void validate(const Grid& grid, const BoundaryValues& g);

/// g sampled on the boundary ring of the grid. fem::Error for an invalid grid, or if g is not
/// finite at some boundary point (names the point).
BoundaryValues boundary_values(const Grid& grid, const SpatialFunction& g);

/// The same value on the whole boundary (0: a cold frame). fem::Error if value is not finite.
BoundaryValues constant_boundary(const Grid& grid, double value);

/// f at the n² unknowns: u_k = f(x_i, y_j). fem::Error if f is not finite at some point.
Eigen::VectorXd sample(const Grid& grid, const SpatialFunction& f);

/// The 5-point stencil as one sweep over the unknowns:
///     out_{i,j} = α u_{i,j} + β (u_{i+1,j} + u_{i−1,j} + u_{i,j+1} + u_{i,j−1} − 4 u_{i,j}),
/// where a neighbour on the boundary ring is read from g. α = 0, β = 1/h² gives the discrete
/// Laplacian (apply_laplacian); α = 1, β = cΔt/h² one explicit Euler step. u has n² entries; out
/// (resized) must be a different vector. Matrix-free: reads u once and writes out once.
/// fem::Error for an invalid grid or g, a wrong size of u, or out aliasing u.
/// docs/02_heat_equation.md#the-5-point-stencil
void stencil_sweep(const Grid& grid, const BoundaryValues& g, const Eigen::VectorXd& u, double alpha,
                   double beta, Eigen::VectorXd& out);

/// The discrete Laplacian Δ_h u at every unknown, (u_E + u_W + u_N + u_S − 4 u_C) / h², with the
/// boundary neighbours taken from g: stencil_sweep with α = 0, β = 1/h². Same errors.
/// docs/02_heat_equation.md#the-5-point-stencil
void apply_laplacian(const Grid& grid, const BoundaryValues& g, const Eigen::VectorXd& u,
                     Eigen::VectorXd& out);

/// The n²×n² sparse matrix L of the 5-point stencil with zero boundary values: −4/h² on the
/// diagonal, 1/h² for each neighbour that is an unknown (at most 4 per row). Symmetric negative
/// definite. With the boundary lift b, Δ_h u = L u + b. Assembled from Eigen triplets.
/// fem::Error for an invalid grid. docs/02_heat_equation.md#the-assembled-laplacian
Eigen::SparseMatrix<double> laplacian_matrix(const Grid& grid);

/// The boundary lift b (n² entries): b_k = (sum of g over the boundary neighbours of unknown k)/h²,
/// zero for an unknown with no boundary neighbour, so that Δ_h u = L u + b.
/// fem::Error for an invalid grid or g. docs/02_heat_equation.md#dirichlet-boundary-values
Eigen::VectorXd boundary_lift(const Grid& grid, const BoundaryValues& g);

/// The eigenvalue of L for the sine mode sin(kπx) sin(lπy), 1 ≤ k, l ≤ n:
///     λ_kl = −(4/h²) (sin²(kπh/2) + sin²(lπh/2))   (→ −π²(k² + l²) as h → 0).
/// fem::Error for an invalid grid or k, l outside 1 … n. docs/02_heat_equation.md#sine-modes
double laplacian_eigenvalue(const Grid& grid, int k, int l);

/// The sine mode sin(kπx) sin(lπy) at the unknowns (zero on the boundary), k, l ≥ 1.
/// docs/02_heat_equation.md#sine-modes
Eigen::VectorXd sine_mode(const Grid& grid, int k, int l);

/// The exact solution of u_t = c Δu from the sine mode with zero boundary values:
/// u(x, y, t) = exp(−c π² (k² + l²) t) sin(kπx) sin(lπy). docs/02_heat_equation.md#sine-modes
double sine_mode_solution(int k, int l, double c, double x, double y, double t);

/// A hot square: u = 1 at the unknowns with 1/4 < x < 3/4 and 1/4 < y < 3/4, 0 elsewhere.
Eigen::VectorXd hot_square(const Grid& grid);

/// The whole (n+2)×(n+2) grid as an image for VTK and the heat-map PNGs: point (i, j) at
/// (i h, j h, 0), one point field `field` holding u inside and g on the boundary ring.
/// fem::Error for an invalid grid or g, or a wrong size of u.
io::ImageGrid to_image(const Grid& grid, const BoundaryValues& g, const Eigen::VectorXd& u,
                       const std::string& field = "temperature");

}  // namespace fem::heat
