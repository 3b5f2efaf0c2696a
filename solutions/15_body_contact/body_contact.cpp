// Chapter 15: bodies against bodies as terms of chapter 14's contact potential — the obstacles'
// features, the body's surface against itself with friction, the intersection referee.
// docs/15_body_contact.md
#include "15_body_contact/body_contact.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace fem::contact {

FeatureTerm::FeatureTerm(const TetMesh& mesh, const std::vector<std::shared_ptr<const Obstacle>>& obstacles,
                         double activation_distance)
    : features_(mesh, obstacles, activation_distance)
{
}

double FeatureTerm::barrier_energy(const Eigen::VectorXd& u, double time, double stiffness) const
{
    return features_.energy(u, time, stiffness);
}

void FeatureTerm::add_barrier_gradient(const Eigen::VectorXd& u, double time, double stiffness,
                                       Eigen::VectorXd& gradient) const
{
    features_.add_gradient(u, time, stiffness, gradient);
}

void FeatureTerm::add_barrier_hessian(const Eigen::VectorXd& u, double time, double stiffness,
                                      std::vector<Eigen::Triplet<double>>& triplets,
                                      std::optional<hyper::Projection> projection) const
{
    features_.add_hessian(u, time, stiffness, triplets, projection);
}

double FeatureTerm::obstacle_power(const Eigen::VectorXd& u, double time, double stiffness) const
{
    return features_.obstacle_power(u, time, stiffness);
}

double FeatureTerm::smallest_distance(const Eigen::VectorXd& u, double time, double reach) const
{
    return features_.smallest_distance(u, time, reach);
}

double FeatureTerm::time_of_impact(const Eigen::VectorXd& u, const Eigen::VectorXd& du, double time,
                                   double end_time) const
{
    return end_time == time ? features_.time_of_impact(u, du, time)
                            : features_.relative_time_of_impact(u, time, u + du, end_time);
}

double FeatureTerm::obstacle_time_of_impact(const Eigen::VectorXd& u, double time, double end_time) const
{
    return features_.relative_time_of_impact(u, time, u, end_time);
}

bool FeatureTerm::out_of_contact(const Eigen::VectorXd& u, double time, const Eigen::VectorXd& u_end,
                                 double end_time, double reach) const
{
    const double near = std::min({features_.smallest_distance(u, time, reach), features_.smallest_distance(u, end_time, reach),
                                  features_.smallest_distance(u_end, end_time, reach)});
    return near >= reach && features_.relative_time_of_impact(u, time, u_end, end_time) > 1.0;
}

BodyContactTerm::BodyContactTerm(const TetMesh& mesh, const BodyContactOptions& options)
    : self_(mesh, options.activation_distance, options.vertex_body, options.body_self_contact),
      friction_(mesh.V),
      activation_distance_(options.activation_distance),
      coefficient_(options.body_friction),
      pattern_reach_(options.pattern_reach)
{
    const double at_rest = self_.smallest_distance(Eigen::VectorXd::Zero(3 * mesh.V.rows()), activation_distance_);
    if (at_rest < activation_distance_)
        throw Error(str("contact: with self-contact, two surface primitives that share no vertex are ", at_rest,
                        " m apart at rest, closer than d̂ = ", activation_distance_,
                        " m: their barrier would push the body at rest; use a d̂ below ", at_rest, " m"));
}

void BodyContactTerm::begin_step(const ContactStepStart& start)
{
    friction_.lag(coefficient_ > 0.0 ? self_.pairs(start.lag, false) : std::vector<SurfacePair>{}, start.lag,
                  start.state.u, start.stiffness, coefficient_, activation_distance_);
    self_.anticipate(start.state.u, start.time_step * start.state.v, pattern_reach_ * activation_distance_);
}

double BodyContactTerm::barrier_energy(const Eigen::VectorXd& u, double /*time*/, double stiffness) const
{
    return self_.energy(u, stiffness);
}

void BodyContactTerm::add_barrier_gradient(const Eigen::VectorXd& u, double /*time*/, double stiffness,
                                           Eigen::VectorXd& gradient) const
{
    self_.add_gradient(u, stiffness, gradient);
}

void BodyContactTerm::add_barrier_hessian(const Eigen::VectorXd& u, double /*time*/, double stiffness,
                                          std::vector<Eigen::Triplet<double>>& triplets,
                                          std::optional<hyper::Projection> projection) const
{
    self_.add_hessian(u, stiffness, triplets, projection);
}

double BodyContactTerm::friction_energy(const Eigen::VectorXd& u, double epsilon) const
{
    return friction_.energy(u, epsilon);
}

void BodyContactTerm::add_friction_gradient(const Eigen::VectorXd& u, double epsilon, Eigen::VectorXd& gradient) const
{
    friction_.add_gradient(u, epsilon, gradient);
}

void BodyContactTerm::add_friction_hessian(const Eigen::VectorXd& u, double epsilon,
                                           std::vector<Eigen::Triplet<double>>& triplets) const
{
    friction_.add_hessian(u, epsilon, triplets);
}

double BodyContactTerm::smallest_distance(const Eigen::VectorXd& u, double /*time*/, double reach) const
{
    return self_.smallest_distance(u, reach);
}

double BodyContactTerm::time_of_impact(const Eigen::VectorXd& u, const Eigen::VectorXd& du, double /*time*/,
                                       double /*end_time*/) const
{
    return self_.time_of_impact(u, du);
}

bool BodyContactTerm::out_of_contact(const Eigen::VectorXd& u, double /*time*/, const Eigen::VectorXd& u_end,
                                     double /*end_time*/, double reach) const
{
    return std::min(self_.smallest_distance(u, reach), self_.smallest_distance(u_end, reach)) >= reach &&
           self_.time_of_impact(u, u_end - u) > 1.0;
}

IntersectionTerm::IntersectionTerm(const TetMesh& mesh, const std::vector<std::shared_ptr<const Obstacle>>& obstacles,
                                   bool self_contact)
    : check_(mesh, obstacles, self_contact), rest_(mesh.V)
{
}

void IntersectionTerm::check(const Eigen::VectorXd& u, double time) const
{
    check_.require_none(rest_ + u.reshaped<Eigen::RowMajor>(rest_.rows(), 3), time);
}

PathCheckTerm::PathCheckTerm(const TetMesh& mesh, const BodyContactOptions& options)
    : pairs_(mesh, options.activation_distance, options.vertex_body, options.body_self_contact),
      rest_(mesh.V),
      vertex_body_(options.vertex_body),
      names_(options.body_names)
{
    if (vertex_body_.empty())
        vertex_body_.assign(static_cast<std::size_t>(mesh.V.rows()), 0);
    for (int v = 0; v < static_cast<int>(vertex_body_.size()); ++v) {
        const int body = vertex_body_[std::size_t(v)];
        if (body >= static_cast<int>(first_vertex_.size()))
            first_vertex_.resize(std::size_t(body) + 1, -1);
        if (first_vertex_[std::size_t(body)] < 0)
            first_vertex_[std::size_t(body)] = v;
    }
    if (!names_.empty() && names_.size() != first_vertex_.size())
        throw Error(str("path check: ", names_.size(), " body names for ", first_vertex_.size(), " bodies"));
}

std::string PathCheckTerm::body_name(int vertex) const
{
    const int body = vertex_body_[std::size_t(vertex)];
    return names_.empty() ? str("body ", body) : str("body '", names_[std::size_t(body)], "'");
}

int PathCheckTerm::own_number(int vertex) const
{
    return vertex - first_vertex_[std::size_t(vertex_body_[std::size_t(vertex)])];
}

void PathCheckTerm::check_segment(const Eigen::VectorXd& from, const Eigen::VectorXd& to, const std::string& which) const
{
    const MatrixX3d start = rest_ + from.reshaped<Eigen::RowMajor>(rest_.rows(), 3);
    const MatrixX3d end = rest_ + to.reshaped<Eigen::RowMajor>(rest_.rows(), 3);
    const CandidatePairs candidates = pairs_.kept(tree_candidates(pairs_.surface(), start, end, 0.0));
    const SegmentCrossing crossing = first_crossing_on_segment(pairs_.surface(), candidates, start, end, &pair_tests_);
    ++segments_;
    if (!crossing.found())
        return;
    const int* v = crossing.vertices;
    const std::string pair =
        crossing.kind == PrimitivePair::point_triangle
            ? str(body_name(v[0]), " vertex ", own_number(v[0]), " and ", body_name(v[1]), " triangle (",
                  own_number(v[1]), ", ", own_number(v[2]), ", ", own_number(v[3]), ")")
            : str(body_name(v[0]), " edge (", own_number(v[0]), ", ", own_number(v[1]), ") and ", body_name(v[2]),
                  " edge (", own_number(v[2]), ", ", own_number(v[3]), ")");
    throw Error(str("path check: step ", step_, " (t = ", time_, " s), ", which, ": ", pair,
                    crossing.proven ? str(" meet at ", crossing.time, " of it")
                                    : str(" could not be proven apart on it (the inclusion CCD stopped at ",
                                          path_check_boxes, " boxes)"),
                    " (each body's own vertex numbers): the line search's collision check let the step cross them; ",
                    "a bug of the contact code to report with the scene"));
}

void PathCheckTerm::begin_step(const ContactStepStart& start)
{
    if (!path_.empty() && last_checked_.size() == path_.back().size() && last_checked_ != path_.back())
        check_segment(path_.back(), last_checked_, str("segment ", path_.size(), " of a solve's path (to its end)"));
    path_ = {start.state.u};
    step_ = start.state.step + 1;
    time_ = start.state.time + start.time_step;
}

void PathCheckTerm::check(const Eigen::VectorXd& u, double /*time*/) const { last_checked_ = u; }

double PathCheckTerm::time_of_impact(const Eigen::VectorXd& u, const Eigen::VectorXd& /*du*/, double /*time*/,
                                     double /*end_time*/) const
{
    if (!path_.empty() && u != path_.back()) {
        check_segment(path_.back(), u,
                      str("segment ", path_.size(), " of its path (", path_.size() == 1 ? str("the step's start") : str("iterate ", path_.size() - 1),
                          " to iterate ", path_.size(), ")"));
        path_.push_back(u);
    }
    return std::numeric_limits<double>::infinity();
}

void PathCheckTerm::end_step(const Eigen::VectorXd& u_end) const
{
    if (!path_.empty() && u_end != path_.back())
        check_segment(path_.back(), u_end,
                      str("segment ", path_.size(), " of its path (",
                          path_.size() == 1 ? str("the step's start") : str("iterate ", path_.size() - 1), " to its end)"));
    path_.clear();
}

void PathCheckTerm::check_chord(const Eigen::VectorXd& u, const Eigen::VectorXd& u_end, int step, double time) const
{
    step_ = step;
    time_ = time;
    check_segment(u, u_end, "its step without contact (one straight segment)");
}

std::vector<std::unique_ptr<ContactTerm>> body_contact_terms(const dynamics::Body& body,
                                                             const std::vector<std::shared_ptr<const Obstacle>>& obstacles,
                                                             const BodyContactOptions& options)
{
    if (!(std::isfinite(options.body_friction) && options.body_friction >= 0.0))
        throw Error(str("contact: the friction coefficient between bodies must be >= 0, got ", options.body_friction));
    if (options.body_friction > 0.0 && !options.self_contact)
        throw Error(str("contact: friction between bodies (", options.body_friction,
                        ") needs self-contact on: without it no pair of the body's surface is held"));
    if (!(std::isfinite(options.pattern_reach) && options.pattern_reach >= 0.0))
        throw Error(str("contact: the reach of the anticipated Hessian pattern must be >= 0 (a multiple of d̂; 0: none), got ",
                        options.pattern_reach));
    require_positive(options.activation_distance, "contact activation distance d̂ [m]");
    std::vector<std::unique_ptr<ContactTerm>> terms;
    auto features = std::make_unique<FeatureTerm>(body.mesh(), obstacles, options.activation_distance);
    if (features->barrier().active())
        terms.push_back(std::move(features));
    if (options.self_contact)
        terms.push_back(std::make_unique<BodyContactTerm>(body.mesh(), options));
    if (options.check_intersections)
        terms.push_back(std::make_unique<IntersectionTerm>(body.mesh(), obstacles, options.self_contact));
    if (options.check_path) {
        if (!options.self_contact)
            throw Error("contact: the path check (check_path) checks the pairs between bodies and of a body against "
                        "itself: it needs self-contact on");
        terms.push_back(std::make_unique<PathCheckTerm>(body.mesh(), options));
    }
    return terms;
}

ContactPotential body_contact_potential(const dynamics::Body& body, std::vector<std::shared_ptr<const Obstacle>> obstacles,
                                        const BodyContactOptions& options)
{
    for (const auto& obstacle : obstacles)
        if (!obstacle)
            throw Error("contact: an obstacle is null");
    std::vector<std::unique_ptr<ContactTerm>> terms = body_contact_terms(body, obstacles, options);
    return ContactPotential(body, std::move(obstacles), options, std::move(terms));
}

ContactTermMaker body_contact_term_maker(BodyContactOptions options)
{
    return [options](const dynamics::Body& body, const std::vector<std::shared_ptr<const Obstacle>>& obstacles,
                     const ContactOptions& contact) {
        BodyContactOptions with_contact = options;
        static_cast<ContactOptions&>(with_contact) = contact;
        return body_contact_terms(body, obstacles, with_contact);
    };
}

}  // namespace fem::contact
