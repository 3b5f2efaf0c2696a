#pragma once
// Chapter 14's tests: what the contact forces of a block at rest carry, against its weight.
// docs/14_contact.md#checks

#include "14_contact/contact.hpp"
#include "14_contact/contact_scenes.hpp"

#include "12_hyperelastic_newton/newton.hpp"

#include <Eigen/Core>

#include <cmath>

namespace fem::test {

/// One more step of a block at rest, and its barrier forces summed over the vertices (3) [N], all
/// its contact forces (barrier and friction: −∇P of the contact potential) summed (3) [N], its
/// weight W = m g [N], and the bound on |Σ F_contact,z − W| [N]. The step's gradient r = M(v − vᵗ) −
/// Δt (f + f_ext + F_contact) has ‖r‖ ≤ tol · scale, and the internal forces f sum to 0 (a
/// translation stores no energy), so summed over the vertices Σ F_contact − W = (Σ m Δv − Σ r)/Δt,
/// with |Σ r_z| ≤ √#V ‖r‖ (Cauchy–Schwarz): bound = (|Σ m Δv_z| + √#V tol scale)/Δt + 10⁻¹² W.
/// At rest Σ m Δv ≈ 0.
struct RestWeight {
    Eigen::Vector3d barrier = Eigen::Vector3d::Zero(), contact = Eigen::Vector3d::Zero();
    double weight = 0.0, bound = 0.0;
};

inline RestWeight rest_weight(contact::BlockScene& block, const contact::BlockSettings& settings)
{
    const dynamics::State start = block.state;
    const double scale = hyper::momentum_scale(*block.body, start, settings.time_step);
    block.step();
    const Eigen::VectorXd forces = block.contact->barrier_forces(block.state.u);
    const Eigen::VectorXd contact = -block.contact->gradient(block.state.u);
    const Eigen::VectorXd& m = block.body->dof_masses();
    RestWeight rest;
    Eigen::Vector3d momentum_change = Eigen::Vector3d::Zero();
    for (Eigen::Index v = 0; v < forces.size() / 3; ++v) {
        rest.barrier += forces.segment<3>(3 * v);
        rest.contact += contact.segment<3>(3 * v);
        momentum_change += m[3 * v] * (block.state.v - start.v).segment<3>(3 * v);
    }
    rest.weight = m.sum() / 3.0 * settings.gravity;
    const double vertices = double(forces.size() / 3);
    rest.bound = (std::abs(momentum_change.z()) + std::sqrt(vertices) * settings.newton.relative_tolerance * scale) /
                     settings.time_step + 1e-12 * rest.weight;
    return rest;
}

}  // namespace fem::test
