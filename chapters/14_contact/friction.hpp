#pragma once
// Chapter 14: lagged, smoothed Coulomb friction (Li et al. 2020, §5) of a surface vertex against an
// obstacle (chapter 15's body_friction.hpp: of two surface primitives of the bodies against each
// other). docs/14_contact.md#friction
//
// Coulomb friction is not an energy; IPC makes it one per step in two moves. *Lagging*: per pair k in
// contact at the step's start, its normal force λ_k, tangent basis T_k (3×2, orthonormal) and, for
// two primitives, the barycentric weights of their closest points are taken there and held over the
// step. *Smoothing*: the friction force's jump at zero sliding is replaced by the mollifier
//
//   f₁(y) = 2y/ε − y²/ε²  for 0 ≤ y < ε,   1 for y ≥ ε        (IPC: the friction mollifier; ε = ε_v Δt)
//   f₀(y) = ∫ f₁ = y²/ε − y³/(3ε²) + ε/3  for y < ε,   y for y ≥ ε
//
// so each pair holds the energy μ λ_k f₀(‖s_k‖) of its tangential displacement over the step
//
//   s_k = T_kᵀ r_k,   r_k = Γ_k (x − x_start)   (3: the relative displacement of the closest points)
//
// with Γ_k (3×3m) the pair's weights: I for a vertex against an obstacle (x_start = x_vᵗ + Δt w_o,
// the point the vertex sticks to on the moving obstacle), [w₀ I, w₁ I, w₂ I, w₃ I] for two
// primitives (w = (1, −β₁, −β₂, −β₃) for a point and a triangle's closest point Σ β_i x_i;
// (1 − α, α, −(1 − γ), −γ) for edges' closest points at parameters α, γ; x_start = xᵗ). The weights
// of two primitives sum to zero: their friction forces are equal and opposite.

#include "14_contact/obstacles.hpp"

#include "common/mesh.hpp"

#include <Eigen/Core>

#include <memory>
#include <vector>

namespace fem::contact {

/// f₀(y), f₁(y) = f₀'(y) and f₁'(y) of the friction mollifier at one tangential displacement y ≥ 0.
struct MollifierValue {
    double f0 = 0.0, f1 = 0.0, f1_derivative = 0.0;
};

/// The mollifier of the header at y ≥ 0 with ε = ε_v Δt > 0 [m]: f₀, f₁ = 2y/ε − y²/ε²,
/// f₁' = 2/ε − 2y/ε² below ε; y, 1, 0 above. fem::Error for ε ≤ 0 or y < 0.
/// docs/14_contact.md#friction
MollifierValue friction_mollifier(double y, double epsilon);

/// The tangent-plane basis of a normal n (3, nonzero): T (3×2) with orthonormal columns ⟂ n.
Eigen::Matrix<double, 3, 2> tangent_basis(const Eigen::Vector3d& normal);

/// One pair's lagged friction as a function of its relative displacement r (3) [m], with gradient
/// and Hessian in r.
struct LaggedFriction {
    double value = 0.0;                                     ///< [J]
    Eigen::Vector3d gradient = Eigen::Vector3d::Zero();     ///< [N]: minus the friction force
    Eigen::Matrix3d hessian = Eigen::Matrix3d::Zero();      ///< [N/m], PSD
};

/// μλ f₀(y) of s = Tᵀ r, y = ‖s‖, with scale = μλ ≥ 0 [N], T (3×2) orthonormal, ε = ε_v Δt > 0 [m]:
///   gradient  μλ f₁(y)/y · T s                          (f₁(y)/y → 2/ε as y → 0),
///   Hessian   μλ T [ (f₁'(y) y − f₁(y))/y³ · s sᵀ + f₁(y)/y · I₂ ] Tᵀ,
/// PSD by construction: the 2×2 bracket's eigenvalues are f₁'(y) ≥ 0 along s and f₁(y)/y ≥ 0 across
/// it (the radial term is −s sᵀ/(y ε²) below ε, 0 at y = 0). fem::Error as friction_mollifier.
/// docs/14_contact.md#friction
LaggedFriction lagged_friction(const Eigen::Matrix<double, 3, 2>& tangent, const Eigen::Vector3d& relative,
                               double scale, double epsilon);

/// One lagged friction pair: vertex v against obstacle o, with the normal force and tangent basis
/// of the step's start.
struct FrictionPair {
    int vertex = 0, obstacle = 0;
    double normal_force = 0.0;           ///< λ = κ Σ_p |b'(d_p(x_vᵗ))| over the obstacle's pieces [N]
    double coefficient = 0.0;            ///< μ of the obstacle
    Eigen::Matrix<double, 3, 2> tangent; ///< T: orthonormal, ⟂ ∇d(x_vᵗ)
    Eigen::Vector3d start;               ///< x_vᵗ + Δt w_o: where the vertex sticks to the obstacle
};

/// The lagged friction pairs of the surface vertices (indices into rest's rows) against the
/// obstacles with μ > 0: one per vertex v and obstacle o with 0 < d_o(x_v) < d̂ at the lag
/// (x = rest + u_lag, the obstacles at lag_time), λ = κ Σ_p |b'(d_p)| over o's pieces within d̂
/// (b of barrier.hpp with d̂ = activation_distance [m], κ = stiffness [N/m]), T = tangent_basis(∇d_o)
/// there, sticking to x_vᵗ + Δt w_o (x_vᵗ = rest + u_start; Δt = time_step [s]). u_lag, u_start: 3n.
/// In the order vertex by vertex, obstacle by obstacle. docs/14_contact.md#friction
std::vector<FrictionPair> obstacle_friction_pairs(const std::vector<std::shared_ptr<const Obstacle>>& obstacles,
                                                  const MatrixX3d& rest, const std::vector<int>& surface,
                                                  const Eigen::VectorXd& u_lag, double lag_time,
                                                  const Eigen::VectorXd& u_start, double time_step, double stiffness,
                                                  double activation_distance);

}  // namespace fem::contact
