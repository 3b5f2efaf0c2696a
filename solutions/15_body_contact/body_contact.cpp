// Chapter 15: bodies against bodies as terms of chapter 14's contact potential — the obstacles'
// features, the body's surface against itself with friction, the intersection referee.
// docs/15_body_contact.md
#include "15_body_contact/body_contact.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <cmath>
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
