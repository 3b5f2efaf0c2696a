#pragma once
// Chapter 14's tests (and chapter 15's): the block fired at an obstacle far faster than a drop, every
// configuration Newton evaluates watched: none may be inside an obstacle. docs/14_contact.md#checks

#include "contact_delegate.hpp"

#include "14_contact/contact.hpp"
#include "14_contact/contact_scenes.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <limits>
#include <memory>

namespace fem::test {

/// A contact potential that records the smallest distance of every configuration the line search
/// and the step start evaluate: none of them may be inside an obstacle.
class WatchedContact final : public ContactDelegate {
public:
    using ContactDelegate::ContactDelegate;
    double energy(const Eigen::VectorXd& u) const override
    {
        smallest = std::min(smallest, contact_.smallest_distance(u));
        ++evaluations;
        return contact_.energy(u);
    }
    mutable double smallest = std::numeric_limits<double>::infinity();
    mutable int evaluations = 0;
};

/// Fires the block at 100 m/s (100 × a drop's ~1 m/s: one step of 1/100 s would carry it 1 m) at
/// the obstacle, 0.1 m below it, and watches every configuration Newton evaluates for 10 steps.
/// terms: the potential's contact terms (chapter 15's; none: the obstacles alone). Returns the
/// lowest z of the block at the end.
inline double fire_at(std::shared_ptr<const contact::Obstacle> obstacle, double speed = 100.0,
                      const contact::ContactTermMaker& terms = {})
{
    contact::BlockSettings settings;
    settings.height = 0.2;
    settings.gravity = 0.0;
    settings.newton.max_iterations = 500;
    settings.obstacles = {std::move(obstacle)};
    settings.terms = terms;
    contact::BlockScene block = contact::block_scene(settings);
    const contact::ContactPotential& contact = *block.contact;
    WatchedContact watched(*block.contact);
    block.integrator->set_potential(&watched);
    Eigen::VectorXd v = Eigen::VectorXd::Zero(block.state.u.size());
    for (Eigen::Index i = 2; i < v.size(); i += 3)
        v[i] = -speed;
    block.state = dynamics::initial_state(*block.body, {}, v);
    for (int step = 0; step < 10; ++step) {
        block.step();
        INFO("step " << step);
        REQUIRE(contact.smallest_distance(block.state.u) > 0.0);
    }
    INFO(watched.evaluations << " evaluations");
    CHECK(watched.smallest > 0.0);
    CHECK(watched.smallest < settings.contact.activation_distance);  // it did reach the obstacle
    return contact::lowest_height(*block.body, block.state.u);
}

}  // namespace fem::test
