#pragma once
// Scenes and helpers shared by the tests of chapter 10.
#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include "06_assembly/assembly.hpp"

#include "common/mesh.hpp"

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace fem::test {

/// x in scientific notation with 3 digits, for CAPTURE (Catch2 prints small doubles as 0.0).
inline std::string sci(double x)
{
    char text[32];
    std::snprintf(text, sizeof text, "%.3e", x);
    return text;
}

/// Implicit options with one field changed.
inline dynamics::ImplicitOptions with_form(dynamics::StepForm form)
{
    dynamics::ImplicitOptions options;
    options.form = form;
    return options;
}

/// SOFA's validation cantilever (0.2 × 0.02 × 0.02 m, ρ = 1100, Y = 2e6, ν = 0.45), cut into
/// cells_along × cells_across × cells_across cubes, clamped at x = 0, no gravity unless asked.
inline dynamics::Scene cantilever_scene(int cells_along = 8, int cells_across = 2, bool gravity = false)
{
    dynamics::Scene scene;
    scene.mesh = box_mesh(cells_along, cells_across, cells_across, Eigen::Vector3d(0.2, 0.02, 0.02));
    scene.material = {2e6, 0.45, 1100.0};
    scene.pinned = assembly::vertices_on_plane(scene.mesh, 0, 0.0);
    scene.gravity = gravity ? Eigen::Vector3d(0.0, 0.0, -9.81) : Eigen::Vector3d::Zero();
    scene.time_step = 0.01;
    scene.duration = 1.0;
    return scene;
}

/// The vertex at the far top corner (x = L, y = W, z = H): the tip the tests follow.
inline int tip_vertex(const dynamics::Scene& scene)
{
    Eigen::Index best = 0;
    scene.mesh.V.rowwise().sum().maxCoeff(&best);
    return static_cast<int>(best);
}

/// The free-dof matrices of a body: K_ff and M_ff.
struct FreeMatrices {
    dynamics::SparseMatrix K, M;
};

inline FreeMatrices free_matrices(dynamics::Body& body)
{
    const Eigen::VectorXd u = Eigen::VectorXd::Zero(body.dofs().full_size());
    return {body.dofs().reduce(body.model().stiffness(u)), body.dofs().reduce(body.mass_matrix())};
}

/// ω_max of K φ = ω² M φ by Eigen's dense generalized eigensolver: for the tests' small bodies, an
/// answer apart from chapter 10's Lanczos (modes.hpp's highest_frequency, which only chapter 10
/// links: fem_add_chapter's OWN).
inline double dense_highest_frequency(const dynamics::SparseMatrix& K, const dynamics::SparseMatrix& M)
{
    const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eigen(Eigen::MatrixXd(K), Eigen::MatrixXd(M),
                                                                          Eigen::EigenvaluesOnly | Eigen::Ax_lBx);
    return std::sqrt(std::max(eigen.eigenvalues().maxCoeff(), 0.0));
}

/// The round-off bound of a trajectory computed two ways (solver orderings, step forms, routes):
/// each step's solve may differ by ε κ(A) relative, κ(A) ≈ 1 + (θ Δt ω_max)² for A = M + θ²Δt² K
/// with a lumped M, and the differences add up over the steps.
inline double trajectory_roundoff(dynamics::Body& body, double time_step, double theta, int steps)
{
    const FreeMatrices m = free_matrices(body);
    const double omega_max = dense_highest_frequency(m.K, m.M);
    const double kappa = 1.0 + std::pow(theta * time_step * omega_max, 2);
    return steps * 2.220446049250313e-16 * kappa;
}

/// ε Σ_ij |K_ij| |u_j|: how far the elastic forces K u of a displacement u may be off by round-off.
inline double force_roundoff(const dynamics::SparseMatrix& K, const Eigen::VectorXd& u)
{
    return 2.220446049250313e-16 * (K.cwiseAbs() * u.cwiseAbs()).sum();
}

/// A full vector (3n) from a free one.
inline Eigen::VectorXd expanded(const dynamics::Body& body, const Eigen::VectorXd& free)
{
    Eigen::VectorXd full = Eigen::VectorXd::Zero(body.dofs().full_size());
    body.dofs().scatter(free, full);
    return full;
}

/// G of one θ-step on q̈ + 2ξω q̇ + ω² q = 0, from the step's two equations written as
/// L (q⁺, p⁺) = R (q, p) and solved by Eigen: an independent route to oscillator_step_matrix.
inline Eigen::Matrix2d theta_step_by_solving(double omega, double xi, double dt, double theta)
{
    Eigen::Matrix2d L, R;
    L << 1.0, -theta * dt,
         theta * dt * omega * omega, 1.0 + 2.0 * theta * xi * omega * dt;
    R << 1.0, (1.0 - theta) * dt,
         -(1.0 - theta) * dt * omega * omega, 1.0 - 2.0 * (1.0 - theta) * xi * omega * dt;
    return L.fullPivLu().solve(R);
}

}  // namespace fem::test
