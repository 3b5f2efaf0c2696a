#pragma once
// Chapter 15: bodies against bodies as terms of chapter 14's contact potential (ContactTerm): the
// obstacles' edges and corners against the body's surface edges and triangles (FeatureBarrier), the
// body's surface against itself — several bodies in one mesh against each other, a body against
// itself — with lagged friction between them (SelfContactBarrier, BodyFriction), and the
// intersection referee (IntersectionCheck). Chapter 14's ContactPotential sums them with its
// obstacles' barrier and friction, with the same κ, d̂ and step. docs/15_body_contact.md

#include "15_body_contact/body_friction.hpp"
#include "15_body_contact/feature_barrier.hpp"
#include "15_body_contact/intersections.hpp"
#include "15_body_contact/self_barrier.hpp"

#include "14_contact/contact.hpp"
#include "14_contact/contact_scenes.hpp"

#include "10_linear_dynamics/body.hpp"

#include <Eigen/Core>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace fem::contact {

/// The constants of contact (chapter 14's ContactOptions) and those of bodies against bodies.
/// docs/15_body_contact.md#bodies-against-bodies-and-self-contact
struct BodyContactOptions : ContactOptions {
    /// Whether the body's surface primitives hold each other off too (BodyContactTerm: bodies
    /// against bodies, a body against itself; friction between them: body_friction). Off: the body
    /// passes through itself, as chapter 14's runs do.
    bool self_contact = false;
    /// μ between the body's surface primitives (bodies against bodies, a body against itself), with
    /// self_contact: lagged friction on its point–triangle and edge–edge pairs (BodyFriction); 0: none.
    /// docs/15_body_contact.md#friction-between-bodies
    double body_friction = 0.0;
    /// With self_contact, several bodies in one mesh: the body of each vertex (#V entries; empty:
    /// one body) and per body whether its own surface holds itself off (empty: every body's does);
    /// two bodies always hold each other off (SelfContactBarrier).
    std::vector<int> vertex_body;
    std::vector<bool> body_self_contact;
    /// With self_contact, the reach of the Hessian's anticipated pattern as a multiple of d̂: at each
    /// begin_step the pattern takes the vertex blocks of every pair of surface primitives whose boxes,
    /// swept over the step's predicted motion (xᵗ to xᵗ + Δt vᵗ), come within pattern_reach × d̂
    /// (SelfContactBarrier::anticipate; zeros where no pair is within d̂), so pairs that arrive
    /// during the step's Newton iterations find their blocks there and the matrix keeps its pattern
    /// (one ordering and symbolic analysis a step instead of one per arrival). The values do not
    /// change. 0: only the pairs within d̂. docs/15_body_contact.md#the-cost-of-contact
    double pattern_reach = 1.0;
    /// A debug check: at every configuration the energy is asked of (each Newton iterate and each
    /// line-search trial), no body edge meets a triangle of an obstacle with edges (a box, a mesh), no
    /// such obstacle's edge a body triangle, and, with self_contact, no body edge a body triangle
    /// (IntersectionCheck, intersections.hpp); fem::Error naming them otherwise. It costs a box tree a
    /// call: for tests and for finding a bug, not for runs. docs/15_body_contact.md#never-an-intersection
    bool check_intersections = false;
    /// A debug check (PathCheckTerm), with self_contact: every segment of every Newton solve's path
    /// (uᵗ, each accepted iterate, its end) checked for a crossing of the pairs the barrier holds
    /// apart by a second CCD (first_crossing_on_segment); fem::Error naming the step, the segment, the
    /// bodies and the primitives otherwise. docs/15_body_contact.md#the-path-check
    bool check_path = false;
    /// The name of each body of vertex_body, for the path check's messages (empty: "body 0", "body 1", …).
    std::vector<std::string> body_names;
};

/// The obstacles' edges and corners against the body's surface (FeatureBarrier) as a contact term.
class FeatureTerm final : public ContactTerm {
public:
    /// The surface of body's mesh against the features of obstacles; d̂ > 0 [m].
    FeatureTerm(const TetMesh& mesh, const std::vector<std::shared_ptr<const Obstacle>>& obstacles,
                double activation_distance);
    /// The barrier it sums.
    const FeatureBarrier& barrier() const { return features_; }

    double barrier_energy(const Eigen::VectorXd& u, double time, double stiffness) const override;
    void add_barrier_gradient(const Eigen::VectorXd& u, double time, double stiffness,
                              Eigen::VectorXd& gradient) const override;
    void add_barrier_hessian(const Eigen::VectorXd& u, double time, double stiffness,
                             std::vector<Eigen::Triplet<double>>& triplets,
                             std::optional<hyper::Projection> projection) const override;
    double obstacle_power(const Eigen::VectorXd& u, double time, double stiffness) const override;
    double smallest_distance(const Eigen::VectorXd& u, double time, double reach) const override;
    /// FeatureBarrier::time_of_impact with the obstacles held (end_time == time), else its
    /// relative_time_of_impact from u to u + du.
    double time_of_impact(const Eigen::VectorXd& u, const Eigen::VectorXd& du, double time,
                          double end_time) const override;
    double obstacle_time_of_impact(const Eigen::VectorXd& u, double time, double end_time) const override;
    std::string meeting() const override { return "an obstacle's edge or corner meets the body's surface"; }
    bool out_of_contact(const Eigen::VectorXd& u, double time, const Eigen::VectorXd& u_end, double end_time,
                        double reach) const override;

private:
    FeatureBarrier features_;
};

/// The body's surface against itself (SelfContactBarrier) with lagged friction between its pairs
/// (BodyFriction) as a contact term; neither moves with the obstacles.
class BodyContactTerm final : public ContactTerm {
public:
    /// The surface of mesh, d̂ > 0 [m] and options' body_friction, vertex_body, body_self_contact and
    /// pattern_reach. fem::Error (SelfContactBarrier's, and) when two surface primitives that share no
    /// vertex are closer than d̂ at rest (their barrier would push the body at rest: a smaller d̂ is
    /// needed).
    BodyContactTerm(const TetMesh& mesh, const BodyContactOptions& options);
    /// The barrier between the surface primitives: its pairs and their forces (SelfContactBarrier::pairs)
    /// with the potential's stiffness.
    const SelfContactBarrier& barrier() const { return self_; }
    /// The current step's lagged friction pairs (body_friction > 0).
    const std::vector<BodyFrictionPair>& friction_pairs() const { return friction_.pairs(); }

    /// The friction pairs within d̂ at the lag (BodyFriction::lag, sticking to xᵗ) and the step's
    /// anticipated pattern (SelfContactBarrier::anticipate over xᵗ to xᵗ + Δt vᵗ).
    void begin_step(const ContactStepStart& start) override;
    double barrier_energy(const Eigen::VectorXd& u, double time, double stiffness) const override;
    void add_barrier_gradient(const Eigen::VectorXd& u, double time, double stiffness,
                              Eigen::VectorXd& gradient) const override;
    void add_barrier_hessian(const Eigen::VectorXd& u, double time, double stiffness,
                             std::vector<Eigen::Triplet<double>>& triplets,
                             std::optional<hyper::Projection> projection) const override;
    double friction_energy(const Eigen::VectorXd& u, double epsilon) const override;
    void add_friction_gradient(const Eigen::VectorXd& u, double epsilon, Eigen::VectorXd& gradient) const override;
    void add_friction_hessian(const Eigen::VectorXd& u, double epsilon,
                              std::vector<Eigen::Triplet<double>>& triplets) const override;
    const dynamics::SparseMatrix* pattern() const override { return &self_.anticipated_pattern(); }
    double smallest_distance(const Eigen::VectorXd& u, double time, double reach) const override;
    double time_of_impact(const Eigen::VectorXd& u, const Eigen::VectorXd& du, double time,
                          double end_time) const override;
    std::string meeting() const override { return "the body's surface meets itself"; }
    bool out_of_contact(const Eigen::VectorXd& u, double time, const Eigen::VectorXd& u_end, double end_time,
                        double reach) const override;
    long long broad_phases() const override { return self_.broad_phases(); }

private:
    SelfContactBarrier self_;
    BodyFriction friction_;
    double activation_distance_, coefficient_, pattern_reach_;  // d̂ [m], μ, reach / d̂
};

/// The intersection referee (IntersectionCheck::require_none at every configuration the energy is
/// asked of) as a contact term that adds nothing else.
class IntersectionTerm final : public ContactTerm {
public:
    IntersectionTerm(const TetMesh& mesh, const std::vector<std::shared_ptr<const Obstacle>>& obstacles,
                     bool self_contact);
    void check(const Eigen::VectorXd& u, double time) const override;

private:
    IntersectionCheck check_;
    MatrixX3d rest_;
};

/// The path check of BodyContactOptions::check_path as a contact term that adds nothing: it records
/// each Newton solve's path — the start uᵗ (begin_step), every accepted iterate (the line search's
/// collision check is asked there: time_of_impact), the solve's end (the last configuration the
/// energy was asked of: the accepted trial) — and checks each new segment at once with
/// first_crossing_on_segment over the candidates of its swept boxes (tree_candidates, no inflation)
/// that the barrier holds apart (SelfContactBarrier::kept). fem::Error on a crossing: "path check:
/// step 12 (t = 0.06 s), segment 3 of its path (iterate 2 to iterate 3): body 'a' vertex 5 and body
/// 'b' triangle (0, 1, 2) may meet …", each body's own vertex numbers.
/// docs/15_body_contact.md#the-path-check
class PathCheckTerm final : public ContactTerm {
public:
    /// The surface of mesh with options' activation_distance, vertex_body, body_self_contact and
    /// body_names. fem::Error as SelfContactBarrier, or for body_names neither empty nor one per body.
    PathCheckTerm(const TetMesh& mesh, const BodyContactOptions& options);
    /// Closes the last solve's path (its end: the last configuration check saw) and opens one at uᵗ.
    void begin_step(const ContactStepStart& start) override;
    /// Remembers u: the last before the next solve or end_step is the solve's end.
    void check(const Eigen::VectorXd& u, double time) const override;
    /// u is an accepted iterate: the segment from the path's last point to u is checked; +∞.
    double time_of_impact(const Eigen::VectorXd& u, const Eigen::VectorXd& du, double time,
                          double end_time) const override;
    /// After a step: its last segment, to u_end (3n), checked, and the path closed.
    void end_step(const Eigen::VectorXd& u_end) const;
    /// A step taken without contact (a chord from u to u_end, 3n each) of step `step` ending at time.
    void check_chord(const Eigen::VectorXd& u, const Eigen::VectorXd& u_end, int step, double time) const;
    /// The segments checked so far, and the pair tests they took.
    long long segments() const { return segments_; }
    long long pair_tests() const { return pair_tests_; }

private:
    void check_segment(const Eigen::VectorXd& from, const Eigen::VectorXd& to, const std::string& which) const;
    /// "body 'a'" (or "body 0") for a vertex of the mesh, and its number in its own body.
    std::string body_name(int vertex) const;
    int own_number(int vertex) const;

    SelfContactBarrier pairs_;  // the surface and the pairs held apart
    MatrixX3d rest_;
    std::vector<int> vertex_body_, first_vertex_;
    std::vector<std::string> names_;
    mutable std::vector<Eigen::VectorXd> path_;
    mutable Eigen::VectorXd last_checked_;
    mutable int step_ = 0;
    mutable double time_ = 0.0;
    mutable long long segments_ = 0, pair_tests_ = 0;
};

/// The contact terms of body against obstacles: a FeatureTerm when some obstacle has edges or
/// corners, a BodyContactTerm with options.self_contact, an IntersectionTerm with
/// options.check_intersections, a PathCheckTerm with options.check_path, in that order. fem::Error for
/// a body_friction < 0 or > 0 without self_contact, a pattern_reach not a finite number ≥ 0, check_path
/// without self_contact, and what the terms refuse.
std::vector<std::unique_ptr<ContactTerm>> body_contact_terms(const dynamics::Body& body,
                                                             const std::vector<std::shared_ptr<const Obstacle>>& obstacles,
                                                             const BodyContactOptions& options);

/// Chapter 14's ContactPotential of body against obstacles with body_contact_terms: the contact
/// potential of this chapter. fem::Error as those two (no obstacle without self_contact: nothing to
/// hold off).
ContactPotential body_contact_potential(const dynamics::Body& body, std::vector<std::shared_ptr<const Obstacle>> obstacles,
                                        const BodyContactOptions& options = {});

/// A BlockSettings::terms that adds body_contact_terms with options (the block's d̂ is the
/// potential's: options' ContactOptions part is not used).
ContactTermMaker body_contact_term_maker(BodyContactOptions options = {});

}  // namespace fem::contact
