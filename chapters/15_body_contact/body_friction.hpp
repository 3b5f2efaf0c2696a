#pragma once
// Chapter 15: lagged, smoothed Coulomb friction between two surface primitives of the bodies (a point
// and a triangle, two edges): chapter 14's friction (friction.hpp: the mollifier, lagging, one
// pair's energy) with the pair's closest points as the relative displacement.
// docs/15_body_contact.md#friction-between-bodies
//
// Per pair k within d̂ at the lag, its normal force λ_k, tangent basis T_k (3×2, orthonormal) and the
// barycentric weights w of its closest points are held over the step; the pair holds μ λ_k f₀(‖s_k‖) of
//
//   s_k = T_kᵀ Γ_k (x − xᵗ),   Γ_k = [w₀ I, w₁ I, w₂ I, w₃ I]
//
// (w = (1, −β₁, −β₂, −β₃) for a point and a triangle's closest point Σ β_i x_i; (1 − α, α, −(1 − γ), −γ)
// for edges' closest points at parameters α, γ). The weights sum to zero: the two primitives' friction
// forces are equal and opposite.

#include "15_body_contact/ccd.hpp"
#include "15_body_contact/distances.hpp"
#include "15_body_contact/self_barrier.hpp"

#include "14_contact/friction.hpp"

#include "common/mesh.hpp"

#include <Eigen/Core>
#include <Eigen/Sparse>

#include <vector>

namespace fem::contact {

/// One lagged friction pair of two surface primitives of the bodies (a point and a triangle, two
/// edges; the 4 mesh vertices in PrimitivePair's order), with what the step's start fixed.
struct BodyFrictionPair {
    int vertices[4] = {0, 0, 0, 0};
    double normal_force = 0.0;              ///< λ = κ m |b'(d)| at the lag [N]
    double coefficient = 0.0;               ///< μ between the bodies
    Eigen::Matrix<double, 3, 2> tangent;    ///< T: orthonormal, ⟂ the closest points' difference
    Eigen::Vector4d weights;                ///< w: Γ = [w₀ I, w₁ I, w₂ I, w₃ I], Σ w_i = 0
    Vector12d start;                        ///< the 4 vertices at the step's start, stacked [m]
};

/// The weights w (4) of the closest points of the primitives at x (3×4, columns in PrimitivePair's
/// order), Γ x = the first primitive's closest point minus the second's: for a point and a triangle
/// by point_triangle_type (corner i: β_i = 1; edge ij: β_j = t, β_i = 1 − t with t the point's
/// parameter along it; face: the barycentric coordinates of the point's projection), w = (1, −β);
/// for two edges by edge_edge_type (an endpoint: parameter 0 or 1; an endpoint against an edge: the
/// endpoint's parameter along it; edge_edge: the lines' closest parameters), w = (1 − α, α, −(1 − γ),
/// −γ). fem::Error as the type functions. docs/15_body_contact.md#friction-between-bodies
Eigen::Vector4d closest_point_weights(PrimitivePair kind, const Eigen::Matrix<double, 3, 4>& x);

/// The tangent basis of a pair at x (3×4) by its closest-feature type: ⟂ the triangle's normal
/// (b − a) × (c − a) for a point inside the triangle, ⟂ e_a × e_b for the insides of two edges, and
/// ⟂ the closest points' difference Γ x for a point against an edge or a point (weights: those of
/// closest_point_weights). Each is the plane ⟂ Γ x while the pair is apart. fem::Error when the
/// normal is zero (a touching pair: d = 0). docs/15_body_contact.md#friction-between-bodies
Eigen::Matrix<double, 3, 2> pair_tangent_basis(PrimitivePair kind, const Eigen::Matrix<double, 3, 4>& x,
                                               const Eigen::Vector4d& weights);

/// The pair of kind at the lag x_lag (3×4: its weights and tangent basis) that sticks to x_start
/// (3×4, the vertices at the step's start), with λ = normal_force [N] ≥ 0 and μ = coefficient ≥ 0.
BodyFrictionPair body_friction_pair(PrimitivePair kind, const int (&vertices)[4], const Eigen::Matrix<double, 3, 4>& x_lag,
                                    const Eigen::Matrix<double, 3, 4>& x_start, double normal_force,
                                    double coefficient);

/// μλ f₀(‖Tᵀ Γ (x − x_start)‖) of a body pair at x (12: its 4 vertices stacked) with ε = ε_v Δt [m]:
/// lagged_friction of r = Γ (x − x_start), its gradient Γᵀ g (block i: w_i g) and Hessian Γᵀ H Γ
/// (block ij: w_i w_j H), PSD as H; translations x + (t, t, t, t) change nothing (Σ w_i = 0).
/// docs/15_body_contact.md#friction-between-bodies
PrimitiveFunction body_friction(const BodyFrictionPair& pair, const Vector12d& x, double epsilon);

/// The lagged friction between the surface primitives of one mesh (bodies against bodies, a body
/// against itself): the pairs of SelfContactBarrier within d̂ at the lag, each a BodyFrictionPair,
/// and the sum of their body_friction. docs/15_body_contact.md#friction-between-bodies
class BodyFriction {
public:
    /// The mesh's rest positions X (#V×3) [m], which u displaces.
    explicit BodyFriction(const MatrixX3d& rest) : rest_(rest) {}

    /// Replaces the pairs: one per pair within d̂ (pairs: SelfContactBarrier::pairs at u_lag), with
    /// λ = κ m |b'(d)| (κ = stiffness [N/m], b of barrier.hpp with d̂ [m]), weights and tangent basis at
    /// u_lag, sticking to the vertices at u_start (3n each), μ = coefficient ≥ 0 (none when 0).
    void lag(const std::vector<SurfacePair>& pairs, const Eigen::VectorXd& u_lag, const Eigen::VectorXd& u_start,
             double stiffness, double coefficient, double activation_distance);
    /// Σ_k body_friction of the pairs at u (3n) with ε = ε_v Δt [m] [J].
    double energy(const Eigen::VectorXd& u, double epsilon) const;
    /// Adds its gradient (3n), each pair's 12 scattered to its 4 vertices, to gradient.
    void add_gradient(const Eigen::VectorXd& u, double epsilon, Eigen::VectorXd& gradient) const;
    /// Appends its Hessian's entries (3n×3n; each pair's 12×12 block, PSD without projection).
    void add_hessian(const Eigen::VectorXd& u, double epsilon, std::vector<Eigen::Triplet<double>>& triplets) const;
    /// The pairs of the current lag.
    const std::vector<BodyFrictionPair>& pairs() const { return pairs_; }

private:
    /// The 4 vertices of pair at u, stacked (12) [m].
    Vector12d stacked(const BodyFrictionPair& pair, const Eigen::VectorXd& u) const;

    MatrixX3d rest_;
    std::vector<BodyFrictionPair> pairs_;
};

}  // namespace fem::contact
