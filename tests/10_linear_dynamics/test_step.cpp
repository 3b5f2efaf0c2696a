// Chapter 10: the pieces of the implicit step, energies, scenes and their checks.
// docs/10_linear_dynamics.md#the-implicit-step
#include "dynamics_fixtures.hpp"

#include "common/error.hpp"
#include "common/parallel.hpp"
#include "common/random.hpp"

#include "../common/test_support.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <numeric>

using namespace fem::dynamics;
using fem::test::cantilever_scene;
using fem::test::EntriesNear;
using fem::test::entries_of;
using Catch::Matchers::Contains;

TEST_CASE("step matrix: M + theta dt D + theta^2 dt^2 K with D = alpha M + beta K", "[ex10.1]")
{
    Body body(cantilever_scene(3, 1));
    const SparseMatrix& M = body.mass_matrix();
    const SparseMatrix& K = body.model().stiffness(Eigen::VectorXd::Zero(body.dofs().full_size()));
    const Eigen::MatrixXd Md(M), Kd(K);
    for (const double theta : {1.0, 0.5, 0.75})
        for (const Damping d : {Damping{0.0, 0.0}, Damping{0.02, 0.0}, Damping{0.0, 0.015}, Damping{0.01, 0.02}}) {
            const double dt = 1.0 / 30.0;
            const Eigen::MatrixXd D = d.alpha * Md + d.beta * Kd;
            const Eigen::MatrixXd expected = Md + theta * dt * D + theta * theta * dt * dt * Kd;
            const Eigen::MatrixXd A(step_matrix(M, K, d, dt, theta));
            CAPTURE(theta, d.alpha, d.beta);
            CHECK_THAT(entries_of(A), EntriesNear(expected, 1e-14 * expected.cwiseAbs().maxCoeff()));
        }
    CHECK_THROWS_AS(step_matrix(M, K, {}, 0.0), fem::Error);
    CHECK_THROWS_AS(step_matrix(M, K, {}, 0.01, 0.4), fem::Error);
    CHECK_THROWS_AS(step_matrix(M, SparseMatrix(3, 3), {}, 0.01), fem::Error);
}

TEST_CASE("right-hand side: M v - dt (K u - f_ext), the lecture's form", "[ex10.2]")
{
    Body body(cantilever_scene(3, 1, true));
    const Eigen::Index n = body.dofs().full_size();
    const SparseMatrix& K = body.model().stiffness(Eigen::VectorXd::Zero(n));
    const Eigen::VectorXd u = 1e-3 * fem::random_vector(n, 3), v = fem::random_vector(n, 4);
    const Eigen::VectorXd f = -(K * u);
    const double dt = 0.02;
    const Eigen::VectorXd b = step_right_hand_side(body.mass_matrix(), v, f, body.external_forces(), dt);
    const Eigen::VectorXd lecture = body.mass_matrix() * v - dt * (K * u - body.external_forces());
    CHECK_THAT(entries_of(b), EntriesNear(lecture, 1e-14 * lecture.norm()));
    CHECK_THROWS_AS(step_right_hand_side(body.mass_matrix(), v, f, body.external_forces(), -dt), fem::Error);
    CHECK_THROWS_AS(step_right_hand_side(body.mass_matrix(), v.head(3), f, body.external_forces(), dt), fem::Error);
}

TEST_CASE("energies: kinetic, elastic and the potential of gravity", "[ex10.3]")
{
    Body body(cantilever_scene(3, 1, true));
    const Eigen::Index n = body.dofs().full_size();
    const SparseMatrix& K = body.model().stiffness(Eigen::VectorXd::Zero(n));
    Eigen::VectorXd u = 1e-3 * fem::random_vector(n, 5), v = fem::random_vector(n, 6);
    u = u.cwiseProduct(body.dofs().free_mask());
    v = v.cwiseProduct(body.dofs().free_mask());
    const State state = initial_state(body, u, v);
    const Energies e = energies(body, state);
    CHECK(e.kinetic == Approx(0.5 * v.dot(body.mass_matrix() * v)).epsilon(1e-13));
    CHECK(e.elastic == Approx(0.5 * u.dot(K * u)).epsilon(1e-13));
    // Gravity's potential: m g z summed over vertices, relative to the rest shape.
    const Eigen::VectorXd masses = fem::assembly::vertex_masses(body.mesh(), body.scene().material.density);
    double height_energy = 0.0;
    for (Eigen::Index vtx = 0; vtx < masses.size(); ++vtx)
        height_energy += masses[vtx] * 9.81 * u[3 * vtx + 2];
    CHECK(e.gravitational == Approx(height_energy).epsilon(1e-12));
    CHECK(e.total() == Approx(e.kinetic + e.elastic + e.gravitational));
    CHECK(e.magnitude() == Approx(e.kinetic + e.elastic + std::abs(e.gravitational)));
    CHECK(energies(body, initial_state(body)).total() == 0.0);
}

TEST_CASE("scenes: every bad field is refused with its name and what is allowed", "[ch10]")
{
    const Scene good = cantilever_scene(2, 1);
    CHECK_NOTHROW(validate(good));
    const auto refused = [&](auto change, const std::string& words) {
        Scene scene = good;
        change(scene);
        CHECK_THROWS_WITH(validate(scene), Contains(words));
        CHECK_THROWS_WITH(Body(scene), Contains(words));
    };
    refused([](Scene& s) { s.time_step = 0.0; }, "time step");
    refused([](Scene& s) { s.time_step = -0.01; }, "time step");
    refused([](Scene& s) { s.time_step = std::nan(""); }, "time step");
    refused([](Scene& s) { s.duration = 1.05; s.time_step = 0.1; }, "not a whole number of steps");
    refused([](Scene& s) { s.duration = -1.0; }, "duration");
    refused([](Scene& s) { s.material.poisson_ratio = 0.5; }, "Poisson");
    refused([](Scene& s) { s.material.poisson_ratio = 0.7; }, "Poisson");
    // λ/μ = 5e13: the sparse Cholesky broke down; the bound (λ/μ ≤ 1e8) refuses it before any solve
    refused([](Scene& s) { s.material.poisson_ratio = 0.49999999999999; }, "lambda/mu at most");
    Scene at_bound = good;
    at_bound.material.poisson_ratio = highest_poisson_ratio;
    CHECK_NOTHROW(validate(at_bound));
    const double lame_ratio = 2.0 * highest_poisson_ratio / (1.0 - 2.0 * highest_poisson_ratio);
    CHECK(lame_ratio == Approx(largest_lame_ratio).epsilon(1e-6));
    refused([](Scene& s) { s.material.youngs_modulus = 0.0; }, "Young");
    refused([](Scene& s) { s.material.youngs_modulus = INFINITY; }, "Young");
    refused([](Scene& s) { s.material.density = -1.0; }, "density");
    refused([](Scene& s) { s.damping.alpha = -0.01; }, "alpha");
    refused([](Scene& s) { s.damping.beta = std::nan(""); }, "beta");
    refused([](Scene& s) { s.damping.beta = 0.5; }, "beta");
    refused([](Scene& s) { s.gravity.z() = std::nan(""); }, "gravity");
    refused([](Scene& s) { s.pinned.push_back(static_cast<int>(s.mesh.V.rows())); }, "outside the mesh");
    refused([](Scene& s) { s.pinned.push_back(-1); }, "outside the mesh");
    refused([](Scene& s) { s.pinned.push_back(s.pinned.front()); }, "listed twice");
    refused([](Scene& s) {  // every vertex pinned: the step's system would be 0x0
        s.pinned.resize(static_cast<std::size_t>(s.mesh.V.rows()));
        std::iota(s.pinned.begin(), s.pinned.end(), 0);
    }, "nothing is left to move");
    refused([](Scene& s) { std::swap(s.mesh.T(0, 2), s.mesh.T(0, 3)); }, "scene mesh");
    refused([](Scene& s) { s.mesh.V(0, 0) = std::nan(""); }, "mesh");

    CHECK(step_count(1.0, 1.0 / 60.0) == 60);
    CHECK(step_count(0.3, 0.1) == 3);
    CHECK(step_count(0.0, 0.1) == 0);
    CHECK_THROWS_WITH(step_count(1.05, 0.1), Contains("10.5 steps"));

    // Starting states must fit the body (pinned vertices may start displaced or moving: moving pins).
    Body body(good);
    const Eigen::Index n = body.dofs().full_size();
    CHECK_THROWS_WITH(initial_state(body, Eigen::VectorXd::Zero(n - 1)), Contains("entries"));
    Eigen::VectorXd bad = Eigen::VectorXd::Zero(n);
    bad[n - 1] = std::nan("");
    CHECK_THROWS_WITH(initial_state(body, {}, bad), Contains("non-finite"));
}

TEST_CASE("a standing scene pins what lies on the ground, the sideways push grows with height", "[ch10]")
{
    const fem::TetMesh box = fem::box_mesh(2, 4, 2, Eigen::Vector3d(1.0, 2.0, 1.0));
    const Scene scene = standing_scene(box, Material{}, 0.5, 0.5);
    validate(scene);
    CHECK(scene.gravity == Eigen::Vector3d(0.0, -9.81, 0.0));
    CHECK(scene.pinned.size() == 2u * 9u);  // the layers y = 0 and y = 0.5, 3 × 3 vertices each
    for (int v : scene.pinned)
        CHECK(box.V(v, 1) <= 0.5);
    const Eigen::VectorXd push = sideways_push(scene, 0.0, 2.0, 0.5);
    for (Eigen::Index v = 0; v < box.V.rows(); ++v) {
        const bool pinned = box.V(v, 1) <= 0.5;
        CHECK(push[3 * v] == Approx(pinned ? 0.0 : 0.25 * box.V(v, 1)).margin(1e-15));
        CHECK(push[3 * v + 1] == 0.0);
        CHECK(push[3 * v + 2] == 0.0);
    }
    CHECK_THROWS_WITH(sideways_push(scene, 1.0, 1.0, 0.5), Contains("above"));
}

TEST_CASE("free dofs: gather, scatter, reduce and the kept-dofs projection agree with chapter 06's P", "[ch10]")
{
    const Scene scene = cantilever_scene(3, 1);
    Body body(scene);
    const FreeDofs& dofs = body.dofs();
    REQUIRE(dofs.size() == dofs.full_size() - 3 * static_cast<Eigen::Index>(scene.pinned.size()));
    const Eigen::VectorXd q = fem::random_vector(dofs.full_size(), 7);
    CHECK((dofs.gather(q) - dofs.P().transpose() * q).norm() == 0.0);
    Eigen::VectorXd back = Eigen::VectorXd::Zero(dofs.full_size());
    dofs.scatter(dofs.gather(q), back);
    CHECK((back - dofs.P() * dofs.gather(q)).norm() == 0.0);

    const SparseMatrix& K = body.model().stiffness(q);
    const Eigen::MatrixXd kept(dofs.project(K)), reduced(dofs.reduce(K));
    for (Eigen::Index i = 0; i < dofs.full_size(); ++i)
        for (Eigen::Index j = 0; j < dofs.full_size(); ++j) {
            const bool free_i = dofs.free_mask()[i] != 0.0, free_j = dofs.free_mask()[j] != 0.0;
            const double expected = free_i && free_j ? Eigen::MatrixXd(K)(i, j) : (i == j ? 1.0 : 0.0);
            if (kept(i, j) != expected) {
                FAIL_CHECK("projected K(" << i << ", " << j << ") = " << kept(i, j) << ", expected " << expected);
                return;
            }
        }
    CHECK(reduced.rows() == dofs.size());
    CHECK_THROWS_AS(dofs.gather(q.head(5)), fem::Error);
    CHECK_THROWS_AS(FreeDofs(4, {0, 4}), fem::Error);
}

TEST_CASE("reduced step matrix: P^T (a M + k K) P refilled in one fixed pattern, and refused for another",
          "[ch10]")
{
    Scene scene = cantilever_scene(3, 1);
    Body body(scene);
    const FreeDofs& dofs = body.dofs();
    const SparseMatrix& M = body.mass_matrix();
    const SparseMatrix K = body.model().stiffness(Eigen::VectorXd::Zero(dofs.full_size()));
    ReducedStepMatrix reduced(M, K, dofs);
    // Each refill against the matrices built from scratch: the same sums, entry by entry.
    for (const double k : {1e-4, 3e-3}) {
        const SparseMatrix K_changed = (1.0 + 1e3 * k) * K;  // new values, same pattern
        const SparseMatrix expected = dofs.reduce(SparseMatrix(1.02 * M + k * K_changed));
        const SparseMatrix& A = reduced.assemble(M, K_changed, 1.02, k);
        REQUIRE(A.rows() == dofs.size());
        CHECK(A.nonZeros() == expected.nonZeros());
        CHECK_THAT(entries_of(A), EntriesNear(expected, 1e-15 * expected.norm()));
    }
    // The θ-step's weights: a = 1 + θΔtα, k = θΔtβ + θ²Δt².
    const Damping damping{0.01, 0.002};
    const double dt = 0.01, theta = 0.5, h = theta * dt;
    const SparseMatrix expected = dofs.reduce(SparseMatrix((1.0 + h * damping.alpha) * M + (h * damping.beta + h * h) * K));
    CHECK_THAT(entries_of(reduced.assemble(M, K, damping, dt, theta)), EntriesNear(expected, 1e-15 * expected.norm()));
    CHECK_THROWS_AS(reduced.assemble(M, K, damping, 0.0, theta), fem::Error);
    // Another pattern (the consistent mass couples neighbours) is refused, not misread.
    scene.mass = MassModel::consistent;
    const Body consistent(scene);
    CHECK(reduced.fits(M, K));
    CHECK_FALSE(reduced.fits(consistent.mass_matrix(), K));
    CHECK_THROWS_WITH(reduced.assemble(consistent.mass_matrix(), K, 1.0, 1.0), Contains("pattern"));
}

TEST_CASE("symmetric_times: A x of a symmetric sparse matrix, the same bits on 1 and 2 threads", "[ch10]")
{
    Body body(cantilever_scene(6, 2));
    const SparseMatrix& K = body.model().stiffness(Eigen::VectorXd::Zero(body.dofs().full_size()));
    const Eigen::MatrixXd Kd(K);
    const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(K.cols(), -1.0, 2.0).array().sin();
    Eigen::VectorXd one_thread;
    {
        const fem::ScopedThreadCount one(1);
        one_thread = symmetric_times(K, x);
    }
    // Against the dense product (an independent sum): equal to round-off.
    CHECK((one_thread - Kd * x).lpNorm<Eigen::Infinity>() <= 1e-12 * (Kd.cwiseAbs() * x.cwiseAbs()).maxCoeff());
    {
        const fem::ScopedThreadCount two(2);
        CHECK(symmetric_times(K, x) == one_thread);
    }
    // An uncompressed matrix (free room in its columns) gives the same.
    SparseMatrix loose = K;
    loose.uncompress();
    loose.reserve(Eigen::VectorXi::Constant(K.cols(), 3));
    CHECK(symmetric_times(loose, x) == one_thread);
    CHECK_THROWS_WITH(symmetric_times(K, Eigen::VectorXd::Zero(3)), Contains("symmetric product") && Contains("3 entries"));
}
