#pragma once
// Chapter 15: the barrier between an obstacle's sharp features and the body's surface: the
// obstacle's edges against the body's surface edges (IPC's edge–edge pairs) and its corners against
// the body's surface triangles (point–triangle pairs), so that a wedge, a box's edge or a mesh's
// ridge pressed into a face between its vertices is held off like a vertex is.
// docs/15_body_contact.md#edges-and-corners-of-obstacles
//
// For a pair k within d̂ (its squared distance d_k² of distances.hpp, d_k = √(d_k²)):
//
//   P_features(u) = Σ_k κ m_k b(d_k)
//
// with b the barrier of barrier.hpp and m_k the edge–edge mollifier (1 for a point–triangle pair),
// which fades an edge pair's barrier out as the two edges turn parallel (where their distance stops
// being smooth: a body edge lying along a box edge is then held by its vertices' barrier). The
// obstacle is kinematic: only the body's coordinates of a pair are unknowns, so a pair's gradient
// is the body's part of the 12 (6 for an edge, 9 for a triangle) and its Hessian that block,
// projected to PSD per pair. A rounded obstacle — a sphere, a point with a radius r, or a capsule, a
// segment with one (Obstacle::local_core) — is its core's corners and edges with every pair's
// distance d − r (its barrier b(d − r), the chain rule through √: rounded() in the .cpp, and the
// time of impact by additive conservative advancement on d − r), so that it is held off the body's
// faces and edges, not only its vertices. A half-space adds nothing.

#include "14_contact/obstacles.hpp"

#include "12_hyperelastic_newton/materials.hpp"

#include "13_skinning/skinning.hpp"

#include "10_linear_dynamics/body.hpp"

#include "common/mesh.hpp"

#include <Eigen/Core>
#include <Eigen/Sparse>

#include <memory>
#include <optional>
#include <vector>

namespace fem::contact {

/// The barrier of header between a body's surface and the obstacles' edges and corners.
class FeatureBarrier {
public:
    /// The surface edges and triangles of mesh (chapter 13's boundary faces) against the features
    /// (Obstacle::local_features) of every obstacle; d̂ > 0 [m] (ContactPotential checks it).
    FeatureBarrier(const TetMesh& mesh, const std::vector<std::shared_ptr<const Obstacle>>& obstacles,
                   double activation_distance);

    /// Whether some obstacle has a sharp feature (else every function below adds nothing).
    bool active() const { return !obstacles_.empty(); }

    /// Σ_k κ m_k b(d_k) over the pairs within d̂ at u (3n), the obstacles at time [J]; +∞ when a pair
    /// touches or crosses (d_k = 0: an edge through an edge, a corner on a face).
    double energy(const Eigen::VectorXd& u, double time, double stiffness) const;
    /// Adds its gradient (3n) to gradient.
    void add_gradient(const Eigen::VectorXd& u, double time, double stiffness, Eigen::VectorXd& gradient) const;
    /// Appends its Hessian's entries, each pair's block projected to PSD (6×6 or 9×9; chapter 12's
    /// project_to_psd with projection; none: as they are), to triplets.
    void add_hessian(const Eigen::VectorXd& u, double time, double stiffness,
                     std::vector<Eigen::Triplet<double>>& triplets,
                     std::optional<hyper::Projection> projection = hyper::Projection::clamp) const;
    /// Σ_o w_o · (the force of obstacle o's pairs on the body) at u [N·m/s]: its part of
    /// ContactPotential::obstacle_work before the factor Δt.
    double obstacle_power(const Eigen::VectorXd& u, double time, double stiffness) const;
    /// The smallest distance of any pair within reach at u [m] (+∞ when none is).
    double smallest_distance(const Eigen::VectorXd& u, double time, double reach) const;

    /// The earliest time of impact s ∈ [0, 1] of any pair when the body moves from u to u + du with
    /// the obstacles held at time (chapter 14's conservative inclusion CCD, ccd.hpp, on every pair
    /// whose boxes over the motion meet), or +∞ when none meets.
    double time_of_impact(const Eigen::VectorXd& u, const Eigen::VectorXd& du, double time) const;
    /// The same for the body moving from u at time to u_end at end_time while the obstacles move
    /// too: each pair's motion relative to its obstacle, x + s (x_end − x − (end_time − time) w),
    /// against the obstacle at time.
    double relative_time_of_impact(const Eigen::VectorXd& u, double time, const Eigen::VectorXd& u_end,
                                   double end_time) const;

private:
    struct Features {
        std::shared_ptr<const Obstacle> obstacle;
        double radius = 0.0;        // a rounded core's (Obstacle::local_core): pairs measure d − radius
        Eigen::MatrixX3d vertices;  // rest placement
        Eigen::MatrixX2i edges;
        skin::BoxHierarchy vertex_tree, edge_tree;
        std::vector<Eigen::Matrix<double, 2, 3>> vertex_boxes, edge_boxes;
    };
    /// One pair within reach: the body's vertices (2 or 3), its function κ-free: value m b(d),
    /// gradient and Hessian with respect to the body's coordinates (the first 6 or last 9 of 12).
    struct Pair {
        int obstacle = 0;
        int count = 0;                  // body vertices: 2 (an edge) or 3 (a triangle)
        int vertices[3] = {0, 0, 0};
        double distance = 0.0;
        double value = 0.0;             // m b(d)
        Eigen::Matrix<double, 9, 1> gradient;
        Eigen::Matrix<double, 9, 9> hessian;
    };
    /// Calls visit(pair) for every pair within reach at u (obstacles at time); with_derivatives:
    /// fills the pair's gradient and Hessian too. Returns false (stopping) at a pair with d = 0.
    template <class Visit>
    bool for_each_pair(const Eigen::VectorXd& u, double time, double reach, bool with_derivatives, Visit visit) const;
    /// The earliest time of impact of the body's motion from x0 to x1 (#V×3 each) against the
    /// obstacles at time, each obstacle's features shifted by shift × its velocity along the motion.
    double earliest_impact(const MatrixX3d& x0, const MatrixX3d& x1, double time, double shift) const;

    Eigen::MatrixX3d rest_;
    double activation_distance_;
    Eigen::MatrixX2i edges_;   // the body's surface edges
    MatrixX3i triangles_;      // the body's surface triangles
    std::vector<Features> obstacles_;
};

}  // namespace fem::contact
