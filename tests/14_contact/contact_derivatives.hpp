#pragma once
// Chapter 14's tests (and chapter 15's): the contact potential's gradient and Hessian, barrier and
// friction, against central differences of its energy and gradient, on a block sliding just above
// given obstacles. docs/14_contact.md#checks

#include "14_contact/contact.hpp"
#include "14_contact/contact_scenes.hpp"

#include "12_hyperelastic_newton/materials.hpp"

#include "common/random.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace fem::test {

/// The block of the checks 0.2 mm above obstacles (kind names them in messages), sliding, κ = 50 N/m
/// and terms (chapter 15's, e.g. body_contact_term_maker(); none: the obstacles alone): the potential's
/// gradient against central differences of its energy, and its Hessian against those of its gradient,
/// inside ε_v Δt, near it and beyond it. Without pair_blocks, per vertex block: the Hessian is the PSD
/// projection of the exact one; with pair_blocks (terms whose pairs span several vertices, each
/// projected on its own), H − H_exact ⪰ 0. Always H ⪰ 0.
inline void check_contact_derivatives(const std::string& kind,
                                      const std::vector<std::shared_ptr<const contact::Obstacle>>& obstacles,
                                      const contact::ContactTermMaker& terms = {}, bool pair_blocks = false)
{
    contact::BlockSettings settings;
    settings.height = 2e-4;
    settings.friction = 0.4;
    settings.contact.stiffness = 50.0;
    settings.obstacles = obstacles;
    settings.terms = terms;
    const double dt = settings.time_step;
    contact::BlockScene block = contact::block_scene(settings);
    contact::ContactPotential& contact = *block.contact;
    // The state at t: sliding sideways, friction pairs from it; then u displaced a little.
    dynamics::State state = block.state;
    contact.begin_step(*block.body, state, dt);
    REQUIRE(!contact.friction_pairs().empty());
    const Eigen::Index n = state.u.size();
    for (double scale : {1e-7, 3e-6, 1e-4}) {  // inside ε_v Δt = 1e-5, near it, beyond it (sliding)
        Eigen::VectorXd u = scale * random_vector(n, 7);
        for (Eigen::Index i = 2; i < n; i += 3)
            u[i] = 1e-5 * random_vector(n, 8)[i];  // keep within d̂
        REQUIRE(std::isfinite(contact.energy(u)));
        const Eigen::VectorXd g = contact.gradient(u);
        const Eigen::MatrixXd H = Eigen::MatrixXd(contact.hessian(u));
        const CentralDifferences differences = central_differences(contact, u, 1e-9);
        const Eigen::VectorXd& g_fd = differences.gradient;
        const Eigen::MatrixXd& H_fd = differences.hessian;
        INFO(kind << ", scale " << scale);
        CHECK((g - g_fd).norm() <= 1e-6 * g.norm());
        if (!pair_blocks) {
            // Per vertex block: the Hessian is the PSD projection of the exact one (for the floor and
            // for friction the exact block is PSD already; a sphere's b'∇²d is negative).
            for (Eigen::Index v = 0; v < n / 3; ++v) {
                const Eigen::Matrix3d exact = H_fd.block<3, 3>(3 * v, 3 * v);
                const Eigen::Matrix3d projected = hyper::project_to_psd<3>(exact, hyper::Projection::clamp);
                CHECK((H.block<3, 3>(3 * v, 3 * v) - projected).norm() <= 1e-5 * (1.0 + exact.norm()));
            }
        } else {
            // The pairs that span several vertices are each projected on their own: H then exceeds the
            // exact Hessian by what the projections add, H − H_exact ⪰ 0.
            const Eigen::MatrixXd exact = 0.5 * (H_fd + H_fd.transpose());
            CHECK(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H - exact).eigenvalues().minCoeff() >=
                  -1e-5 * (1.0 + exact.norm()));
        }
        CHECK(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues().minCoeff() >= -1e-8 * H.norm());
    }
}

}  // namespace fem::test
