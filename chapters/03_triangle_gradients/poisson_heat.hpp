#pragma once
// Chapter 03: the Poisson and heat equations on a triangle mesh, with Dirichlet vertices, and the
// error norms that measure them against an exact solution.
// docs/03_triangle_gradients.md#poisson-on-a-triangle-mesh

#include "03_triangle_gradients/laplacian.hpp"

#include <Eigen/SparseCholesky>

#include <functional>
#include <vector>

namespace fem::tri {

/// Vertices whose values are prescribed (Dirichlet boundary conditions).
struct Dirichlet {
    std::vector<int> vertices;  ///< the fixed vertices, each at most once
    Eigen::VectorXd values;     ///< their values, in the same order
};

/// Solves the Poisson problem −Δu = f with u = g at the fixed vertices, discretised as L u = M f
/// (L the FEM Laplacian, M = diag(mass) the lumped mass, f sampled at the vertices) on the rows of
/// the free vertices F, the fixed ones B moved to the right-hand side:
///   L_FF u_F = (M f)_F − L_FB g
/// solved with Eigen's SimplicialLDLT. Returns u at every vertex (u_B = g).
/// fem::Error for sizes that do not match, a fixed vertex out of range or repeated, no free vertex,
/// or a singular L_FF (e.g. a closed surface with no fixed vertex: u is then defined only up to a
/// constant). docs/03_triangle_gradients.md#poisson-on-a-triangle-mesh
Eigen::VectorXd solve_poisson(const SparseMatrix& L, const Eigen::VectorXd& mass, const Eigen::VectorXd& f,
                              const Dirichlet& fixed);

/// Implicit (backward) Euler for the heat equation u_t = c Δu on a triangle mesh, the fixed
/// vertices held at their current values (none on a closed surface):
///   (M + Δt c L) u⁺ = M u   on the free rows, i.e.
///   (M + Δt c L)_FF u⁺_F = M_F u_F − Δt c L_FB u_B.
/// The matrix is the same every step, so it is factored once (SimplicialLDLT) in the constructor
/// and each step costs two triangular solves. Unconditionally stable, O(Δt + h²). It is chapter
/// 02's implicit scheme with the 5-point Laplacian replaced by the FEM one and the identity by M.
/// docs/03_triangle_gradients.md#heat-on-a-triangle-mesh
class ImplicitHeat {
public:
    /// L: the FEM Laplacian (|V|×|V|); mass: lumped masses (|V|, all > 0); c: diffusivity > 0;
    /// dt: time step > 0; fixed: the vertices held fixed (any order, no repeats). fem::Error for
    /// sizes that do not match, c or dt not finite and > 0, a bad fixed vertex, or a failed
    /// factorisation.
    ImplicitHeat(const SparseMatrix& L, const Eigen::VectorXd& mass, double c, double dt,
                 const std::vector<int>& fixed = {});

    /// One step: u ← u⁺. u has one value per vertex; its fixed entries are kept.
    /// fem::Error if u has the wrong size. docs/03_triangle_gradients.md#heat-on-a-triangle-mesh
    void step(Eigen::VectorXd& u) const;

    double dt() const { return dt_; }
    int free_count() const { return static_cast<int>(free_.size()); }

private:
    double c_ = 1.0;
    double dt_ = 0.0;
    std::vector<int> free_;         ///< the free vertices, ascending
    std::vector<int> fixed_;        ///< the fixed vertices, ascending
    Eigen::VectorXd mass_free_;     ///< M_F
    SparseMatrix coupling_;         ///< L_FB
    Eigen::SimplicialLDLT<SparseMatrix> solver_;  ///< factors (M + Δt c L)_FF
};

/// A quadrature rule on triangles: points in barycentric coordinates, weights summing to 1, so
/// that ∫_T g dA ≈ A_T Σ_q w_q g(Σ_i λ_qi x_i).
struct TriangleQuadrature {
    std::vector<Eigen::Vector3d> points;
    std::vector<double> weights;
    int degree = 0;  ///< exact for polynomials up to this degree
};

/// Radon's 7-point rule (the centroid and two orbits of three points), exact for polynomials of
/// degree ≤ 5. docs/03_triangle_gradients.md#measuring-the-error
const TriangleQuadrature& seven_point_rule();

/// The errors of a piecewise-linear u_h (vertex values) against an exact solution u with gradient
/// grad_u, integrated triangle by triangle with the 7-point rule:
///   l2 = ( ∫ (u_h − u)² )^½,   gradient_l2 = ( ∫ |∇u_h − ∇u|² )^½
/// where ∇u_h is the constant gradient of each triangle. On a curved surface ∇u should be the
/// tangential gradient. fem::Error if u_h has not #V values or the mesh is invalid.
struct ErrorNorms {
    double l2 = 0.0;
    double gradient_l2 = 0.0;
};
ErrorNorms error_norms(const MatrixX3d& V, const MatrixX3i& F, const Eigen::VectorXd& u_h,
                       const std::function<double(const Eigen::Vector3d&)>& u,
                       const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& grad_u);

}  // namespace fem::tri
