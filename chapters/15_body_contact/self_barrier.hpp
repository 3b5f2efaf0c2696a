#pragma once
// Chapter 15: bodies against bodies and a body against itself — IPC's barrier (Li et al. 2020)
// between the surface primitives of one tet mesh: every surface vertex against every surface
// triangle and every surface edge against every other, both sides unknowns. Several bodies in one
// solve are one mesh with several connected components (their elasticity is block diagonal; this
// barrier couples them), so the same pairs hold two bodies apart and a body off itself.
// docs/15_body_contact.md#bodies-against-bodies-and-self-contact
//
// For a pair k whose primitives share no vertex and whose distance d_k (distances.hpp) is below d̂:
//
//   P_self(u) = Σ_k κ m_k b(d_k)
//
// with b the barrier of barrier.hpp and m_k the edge–edge mollifier (1 for a point–triangle pair;
// its threshold from the rest positions). A pair that shares a vertex is left out: its distance is
// 0 at rest (a triangle holds its own corners, two edges of one triangle meet). The pairs within d̂
// are found by the broad phase (broad_phase.hpp, chapter 13's tree); the time of impact of a motion
// by the tree over swept boxes and line_search_time_of_impact (pair_barrier.hpp) per candidate.
//
// One broad phase a Newton iteration: time_of_impact(u, du), which the line search asks first, keeps
// the candidates of the motion's swept boxes grown by d̂ + 2δ (δ = motion_margin d̂), and every later
// energy, gradient or Hessian at an x whose surface vertices each lie within δ of their own swept
// box (every line-search trial x + α du, α ∈ [0, 1], and the next iterate) takes its pairs from them
// instead of a tree of its own. Exact: a pair within d̂ at such an x has its vertices' boxes within
// d̂ of each other in every axis, so its swept boxes, grown by d̂ + 2δ, meet. At any other x the
// tree is built there, as before.
//
// The Hessian's pattern (anticipate): a pair's block appears in the Hessian when the pair comes
// within d̂, so pairs arriving over a step's Newton iterations give its matrix a new sparsity
// pattern each (a new ordering and symbolic analysis in chapter 09's direct solver). anticipate fixes
// for the step the vertex blocks of every candidate pair within a larger reach over the step's
// predicted motion, as a matrix of explicit zeros the Hessian adds, which fills none of them.
// The values are unchanged (a zero added to a sum changes no bit); only the pattern holds more.

#include "15_body_contact/broad_phase.hpp"
#include "15_body_contact/ccd.hpp"
#include "15_body_contact/distances.hpp"

#include "12_hyperelastic_newton/materials.hpp"

#include "common/mesh.hpp"

#include <Eigen/Core>
#include <Eigen/Sparse>

#include <optional>
#include <vector>

namespace fem::contact {

/// δ of the header as a fraction of d̂: how far outside its swept box a vertex may be (the round-off
/// of x + α du against x and x + du, ~10⁻¹⁶ m) for a motion's candidates to hold there.
inline constexpr double motion_margin = 1e-3;

/// One pair of surface primitives within reach: its kind, its 4 mesh vertices (p, a, b, c or ea0,
/// ea1, eb0, eb1), its distance d [m], its mollifier m (1 for a point and a triangle) and κ-free
/// m b(d), with gradient and Hessian in their 12 coordinates when asked.
struct SurfacePair {
    PrimitivePair kind = PrimitivePair::point_triangle;
    int vertices[4] = {0, 0, 0, 0};
    double distance = 0.0, mollifier = 1.0;
    PrimitiveFunction barrier;
};

/// The barrier of the header between the surface primitives of one mesh.
class SelfContactBarrier {
public:
    /// The surface primitives of mesh (surface_primitives); d̂ > 0 [m]. vertex_body: the body each
    /// vertex belongs to (#V entries; empty: the mesh is one body); body_self_contact: per body
    /// whether its own primitives hold each other off (empty: every body's do). A pair of two
    /// different bodies always counts. fem::Error for d̂ not a finite number > 0, a vertex_body of
    /// another size than #V, or a body without an entry in body_self_contact.
    SelfContactBarrier(const TetMesh& mesh, double activation_distance, std::vector<int> vertex_body = {},
                       std::vector<bool> body_self_contact = {});

    /// The primitives it pairs.
    const SurfacePrimitives& surface() const { return surface_; }

    /// Σ_k κ m_k b(d_k) over the pairs within d̂ at u (3n) with κ = stiffness [N/m] [J]; +∞ when a pair
    /// touches or crosses (d_k = 0). fem::Error for u of a size other than 3n.
    double energy(const Eigen::VectorXd& u, double stiffness) const;
    /// Adds its gradient (3n), κ ∇(m_k b(d_k)) scattered to each pair's 4 vertices, to gradient.
    /// fem::Error where a pair touches (d = 0) or on sizes.
    void add_gradient(const Eigen::VectorXd& u, double stiffness, Eigen::VectorXd& gradient) const;
    /// Appends its Hessian's entries to triplets (3n×3n): each pair's 12×12 block κ ∇²(m_k b(d_k))
    /// projected to PSD on its own (chapter 12's project_to_psd with projection: clamp sets its negative
    /// eigenvalues to 0, absolute to |λ|), so the sum is PSD; no projection: the blocks as they are.
    /// fem::Error where a pair touches (d = 0) or on u's size.
    void add_hessian(const Eigen::VectorXd& u, double stiffness, std::vector<Eigen::Triplet<double>>& triplets,
                     std::optional<hyper::Projection> projection = hyper::Projection::clamp) const;
    /// The pairs within d̂ at u (3n), with their barrier's gradient and Hessian when with_derivatives
    /// (κ-free: the force of pair k on its 4 vertices is −κ ∇(m_k b(d_k)), SurfacePair::barrier's
    /// gradient). fem::Error where a pair touches (d = 0) or on u's size.
    std::vector<SurfacePair> pairs(const Eigen::VectorXd& u, bool with_derivatives) const;
    /// The smallest distance of any pair within reach [m] at u (3n): +∞ when none is, 0 when a pair touches.
    double smallest_distance(const Eigen::VectorXd& u, double reach) const;
    /// The earliest time of impact s ∈ [0, 1] of any pair when the surface moves from u to u + du (3n
    /// each), x + s du: the candidates of tree_candidates over the motion whose swept boxes meet (no inflation), each pair's
    /// line_search_time_of_impact (a lower bound of its first contact); +∞ when none meets. Keeps the
    /// motion's candidates within d̂ for the energy, gradient and Hessian that follow (header).
    /// fem::Error on sizes.
    double time_of_impact(const Eigen::VectorXd& u, const Eigen::VectorXd& du) const;
    /// Fixes the pattern anticipated_pattern holds from now on: the 3×3 blocks (a, b) of every two
    /// of the 4 vertices of each candidate pair (tree_candidates, a = b too) whose vertices' boxes,
    /// swept from X + u to X + u + motion (3n each), come within reach [m] of each other (header).
    /// reach = 0: none. fem::Error on sizes, or reach not a finite number ≥ 0.
    void anticipate(const Eigen::VectorXd& u, const Eigen::VectorXd& motion, double reach);
    /// anticipate's blocks as a 3n×3n matrix of explicit zeros (empty before anticipate): added to
    /// the Hessian (ContactPotential::hessian), it changes no value and holds the pattern.
    const Eigen::SparseMatrix<double>& anticipated_pattern() const { return anticipated_; }
    /// How many trees the broad phase has built since construction (each call of energy, gradient,
    /// Hessian, pairs or smallest_distance whose x lies outside the last motion's boxes, and each
    /// time_of_impact): what the motion's candidates save.
    long long broad_phases() const { return broad_phases_; }
    /// candidates without the pairs inside one body that does not hold itself off: the pairs it holds apart.
    CandidatePairs kept(CandidatePairs candidates) const;

private:
    /// Calls visit(pair) for every pair within reach at u; with_derivatives: with the barrier's
    /// gradient and Hessian. Returns false (stopping) at a pair with d = 0.
    template <class Visit>
    bool for_each_pair(const Eigen::VectorXd& u, double reach, bool with_derivatives, Visit visit) const;
    /// x (#V×3) moved by u (3n, vertex-major); fem::Error naming what when u's size is not 3n.
    MatrixX3d moved(const MatrixX3d& x, const Eigen::VectorXd& u, const char* what) const;

    /// The candidates within reach at x (#V×3): the last motion's when reach ≤ d̂ and every surface
    /// vertex of x lies within δ of its swept box, else tree_candidates at x, kept in fresh.
    const CandidatePairs& candidates_at(const MatrixX3d& x, double reach, CandidatePairs& fresh) const;

    /// The last time_of_impact's motion: each vertex's swept box (low, high: #V×3) and the candidates
    /// of those boxes grown by d̂ + 2δ (empty boxes: none yet). A cache: it changes no answer.
    struct MotionCandidates {
        MatrixX3d low, high;
        CandidatePairs pairs;
    };
    mutable MotionCandidates motion_;
    mutable long long broad_phases_ = 0;
    Eigen::SparseMatrix<double> anticipated_;  // anticipate's vertex blocks, zeros

    MatrixX3d rest_;
    double activation_distance_;
    SurfacePrimitives surface_;
    std::vector<int> vertex_body_;
    std::vector<bool> body_self_contact_;
};

}  // namespace fem::contact
