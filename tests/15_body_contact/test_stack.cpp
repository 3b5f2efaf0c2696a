// Chapter 15: a stack of three blocks at rest on the floor, one mesh of three components with
// self-contact on: the barrier force that block k + 1 puts on block k (the self-contact pairs between
// them, SelfContactBarrier::pairs) equals the weight of the blocks above.
// docs/15_body_contact.md#a-stack-at-rest
#include "15_body_contact/body_scenes.hpp"
#include "15_body_contact/body_contact.hpp"
#include "14_contact/obstacles.hpp"
#include "15_body_contact/self_barrier.hpp"

#include "contact_bodies.hpp"

#include "10_linear_dynamics/body.hpp"


#include <catch2/catch.hpp>

#include <cmath>
#include <memory>
#include <vector>

using namespace fem;
using namespace fem::contact;

TEST_CASE("a stack at rest: the barrier force between blocks k and k+1 equals the weight of the blocks above",
          "[self][ex15.5]")
{
    // Three one-cell cubes of 30, 20 and 10 cm (27, 8 and 1 kg), each on the one below and off its
    // centre (no vertex on a diagonal), the lowest on the floor z = 0 (block_stack). At rest they are
    // 1.2 d̂ apart (self-contact asks for more than d̂ between bodies at rest) and start 0.5 d̂ apart (u₀).
    const double reach = 1e-3, g = 9.81;  // d̂ [m]
    const BlockStack blocks = block_stack(reach);
    dynamics::Scene scene;
    scene.mesh = blocks.mesh;
    scene.material = {1e6, 0.3, 1000.0};
    scene.gravity = Eigen::Vector3d(0, 0, -g);
    scene.time_step = 1.0 / 100.0;
    BodyContactOptions options;
    options.self_contact = true;
    options.check_intersections = true;  // every Newton iterate and line-search trial
    options.activation_distance = reach;
    test::ContactRun stack(scene, options, {std::make_shared<HalfSpace>(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ())},
                           blocks.start, {}, 1e-10);
    // Settled: backward Euler damps the blocks' bounces on the barrier (1.5 s).
    for (int s = 0; s < 150; ++s)
        stack.step();
    const dynamics::Body& body = *stack.body;
    const ContactPotential& contact = *stack.contact;
    const dynamics::State& state = stack.state;
    const dynamics::State before = state;
    stack.step();

    const Eigen::VectorXd& m = body.dof_masses();
    double weight[3] = {0, 0, 0};  // per block [N]
    Eigen::Vector3d momentum_change[3];  // per block [kg m/s]
    for (int k = 0; k < 3; ++k)
        momentum_change[k].setZero();
    for (int v = 0; v < 24; ++v) {
        weight[stack_block(v)] += m[3 * v] * g;
        momentum_change[stack_block(v)] += m[3 * v] * (state.v - before.v).segment<3>(3 * v);
    }
    // The barrier force of block k + 1 on block k and of block k on block k + 1 (3 each) [N]: −κ ∇(m b)
    // of every pair with vertices in both, summed over each block's vertices.
    Eigen::Vector3d on_lower[2], on_upper[2];
    double nearest[2] = {reach, reach};
    for (int k = 0; k < 2; ++k)
        on_lower[k] = on_upper[k] = Eigen::Vector3d::Zero();
    for (const SurfacePair& pair : contact.term<BodyContactTerm>()->barrier().pairs(state.u, true)) {
        int lowest = 3, highest = -1;
        for (int v : pair.vertices) {
            lowest = std::min(lowest, stack_block(v));
            highest = std::max(highest, stack_block(v));
        }
        REQUIRE(highest - lowest <= 1);  // no pair reaches past the next block
        if (highest == lowest)
            continue;
        nearest[lowest] = std::min(nearest[lowest], pair.distance);
        for (int i = 0; i < 4; ++i)
            (stack_block(pair.vertices[i]) == lowest ? on_lower : on_upper)[lowest] -=
                contact.stiffness() * pair.barrier.gradient.segment<3>(3 * i);
    }
    for (int k = 0; k < 2; ++k) {
        const double above = k == 0 ? weight[1] + weight[2] : weight[2];
        // The blocks above k, together: their internal forces (elastic, their own pairs) sum to 0, so
        // Σ m Δv / Δt = F − W_above ẑ + Σ r / Δt, r the step's Newton residual. At rest both are
        // small: the force must carry the weight to 10⁻³ of it, and with the momentum change to the
        // residual's level. (Horizontally the blocks are not quite at rest: without friction they
        // creep off the faces that their weight tilts; F's horizontal part is that creep's m Δv/Δt.)
        const Eigen::Vector3d dynamic =
            (k == 0 ? momentum_change[1] + momentum_change[2] : momentum_change[2]) / scene.time_step;
        INFO("interface " << k << " / " << k + 1 << ": force on the upper " << on_upper[k].transpose()
                          << " N, on the lower " << on_lower[k].transpose() << " N, weight above " << above
                          << " N, the blocks above' momentum change / dt " << dynamic.transpose() << " N, nearest pair "
                          << nearest[k] << " m");
        CHECK(std::abs(on_upper[k].z() - above) <= 1e-3 * above);
        CHECK((on_upper[k] - above * Eigen::Vector3d::UnitZ() - dynamic).norm() <= 1e-5 * above);
        CHECK((on_lower[k] + on_upper[k]).norm() <= 1e-12 * above);  // equal and opposite
        CHECK(on_upper[k].head<2>().norm() <= 1e-2 * above);         // and nearly vertical
        CHECK(nearest[k] > 0.0);
        CHECK(nearest[k] < reach);  // they rest within d̂: d̂ is where, not how much
    }
}
