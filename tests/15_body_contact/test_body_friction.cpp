// Chapter 15: lagged friction between bodies (friction.hpp: BodyFriction, body_friction): one pair's
// weights and tangent basis against the distance functions, its gradient and Hessian against central
// differences for a point and a triangle and for two edges, sticking and sliding; a block sliding on a
// pinned block decelerating at μ g, a block on a tilted one sticking (tan θ < μ) or sliding at
// g (sin θ − μ cos θ), and two blocks rubbing as they bounce off each other keeping their momentum.
// docs/15_body_contact.md#friction-between-bodies
#include "15_body_contact/body_contact.hpp"
#include "14_contact/contact_scenes.hpp"
#include "15_body_contact/distances.hpp"
#include "15_body_contact/body_friction.hpp"

#include "contact_bodies.hpp"

#include "12_hyperelastic_newton/force_models.hpp"
#include "12_hyperelastic_newton/newton.hpp"

#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"
#include "common/random.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

using namespace fem;
using namespace fem::contact;
using fem::test::box_at;
using fem::test::two_bodies;

namespace {

/// The squared distance of a pair at x (3×4) by its own type (distances.hpp): what Γ x must measure.
double pair_squared_distance(PrimitivePair kind, const Eigen::Matrix<double, 3, 4>& x)
{
    const Eigen::Vector3d x0 = x.col(0), x1 = x.col(1), x2 = x.col(2), x3 = x.col(3);
    if (kind == PrimitivePair::point_triangle)
        return point_triangle_squared_distance(x0, x1, x2, x3, point_triangle_type(x0, x1, x2, x3)).value;
    return edge_edge_squared_distance(x0, x1, x2, x3, edge_edge_type(x0, x1, x2, x3)).value;
}

/// The centre-of-mass velocity (3) [m/s] of the 8 vertices first … first + 7 (a one-cell block).
Eigen::Vector3d block_velocity(const dynamics::Body& body, const Eigen::VectorXd& v, int first)
{
    Eigen::Vector3d momentum = Eigen::Vector3d::Zero();
    double mass = 0.0;
    for (int i = first; i < first + 8; ++i) {
        momentum += body.dof_masses()[3 * i] * v.segment<3>(3 * i);
        mass += body.dof_masses()[3 * i];
    }
    return momentum / mass;
}

constexpr double reach = 1e-3;  // d̂ [m] of the blocks

/// The scene of two blocks of one mesh — the lower (first 8 vertices, 40 × 40 × 10 cm) pinned, the
/// upper (10 cm) on it, 1.2 d̂ above at rest — with gravity g (3), Δt = 1/100 s.
dynamics::Scene block_on_block_scene(const Eigen::Vector3d& gravity)
{
    dynamics::Scene scene;
    scene.mesh = two_bodies(box_at(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.4, 0.4, 0.1)),
                            box_at(Eigen::Vector3d(0.04, 0.21, 0.1 + 1.2 * reach), Eigen::Vector3d::Constant(0.1)));
    scene.material = {1e6, 0.3, 1000.0};
    scene.gravity = gravity;
    scene.time_step = 1.0 / 100.0;
    for (int v = 0; v < 8; ++v)
        scene.pinned.push_back(v);
    return scene;
}

/// Self-contact with d̂ = reach and μ between the bodies.
BodyContactOptions rough_contact(double friction)
{
    BodyContactOptions options;
    options.self_contact = true;
    options.body_friction = friction;
    options.activation_distance = reach;
    return options;
}

/// The upper block's (vertices 8 … 15) displacement or velocity: value (3) on each, zero elsewhere (48).
Eigen::VectorXd on_upper_block(const Eigen::Vector3d& value)
{
    Eigen::VectorXd field = Eigen::VectorXd::Zero(3 * 16);
    for (int v = 8; v < 16; ++v)
        field.segment<3>(3 * v) = value;
    return field;
}

/// block_on_block_scene stepped with μ between the blocks, the upper block moved down by 0.7 d̂ at
/// t = 0 (so the pair is in contact from the first step, while the rest positions are further apart
/// than d̂, as self-contact asks) and thrown at v0 (3).
struct BlockOnBlock : test::ContactRun {
    BlockOnBlock(double friction, const Eigen::Vector3d& gravity, const Eigen::Vector3d& v0)
        : ContactRun(block_on_block_scene(gravity), rough_contact(friction), {},
                     on_upper_block(Eigen::Vector3d(0, 0, -0.7 * reach)), on_upper_block(v0))
    {
    }
    /// The upper block's centre-of-mass velocity (3) [m/s].
    Eigen::Vector3d velocity() const { return block_velocity(*body, state.v, 8); }
};

}  // namespace

TEST_CASE("friction between primitives: weights, tangent bases, gradient and Hessian against central differences",
          "[self][ex15.5]")
{
    // Point–triangle and edge–edge pairs of every closest-feature type, 0.5 mm to 2 cm apart.
    struct Case {
        const char* name;
        PrimitivePair kind;
        Eigen::Matrix<double, 3, 4> x;
    };
    const auto columns = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                            const Eigen::Vector3d& d) {
        Eigen::Matrix<double, 3, 4> x;
        x << a, b, c, d;
        return x;
    };
    const Eigen::Vector3d o(0, 0, 0), ex(0.1, 0.01, 0), ey(0.02, 0.1, 0.003);
    const std::vector<Case> cases{
        {"point over the face", PrimitivePair::point_triangle, columns({0.03, 0.025, 5e-4}, o, ex, ey)},
        {"point beside an edge", PrimitivePair::point_triangle, columns({0.05, -0.004, 5e-4}, o, ex, ey)},
        {"point beyond a corner", PrimitivePair::point_triangle, columns({-0.004, -0.003, 6e-4}, o, ex, ey)},
        {"edges crossing", PrimitivePair::edge_edge, columns(o, ex, {0.05, -0.05, 5e-4}, {0.03, 0.06, 7e-4})},
        {"an end against an edge", PrimitivePair::edge_edge, columns(o, ex, {0.05, 0.004, 6e-4}, {0.06, 0.08, 0.01})},
        {"two ends", PrimitivePair::edge_edge, columns(o, ex, {0.104, 0.012, 5e-4}, {0.15, 0.05, 0.02})},
    };
    const double epsilon = 1e-5, force = 3.0, mu = 0.4;  // ε = ε_v Δt [m], λ [N]
    const int vertices[4] = {0, 1, 2, 3};
    for (const Case& c : cases) {
        const Eigen::Vector4d w = closest_point_weights(c.kind, c.x);
        const Eigen::Matrix<double, 3, 2> T = pair_tangent_basis(c.kind, c.x, w);
        const Eigen::Vector3d gap = c.x * w;  // Γ x: the closest points' difference
        INFO(c.name << ": weights " << w.transpose() << ", Γx " << gap.transpose());
        CHECK(std::abs(w.sum()) <= 1e-15);
        CHECK(std::abs(gap.squaredNorm() - pair_squared_distance(c.kind, c.x)) <= 1e-12 * gap.squaredNorm());
        CHECK((T.transpose() * T - Eigen::Matrix2d::Identity()).norm() <= 1e-14);
        CHECK((T.transpose() * gap).norm() <= 1e-12 * gap.norm());  // the tangent plane ⟂ the normal
        const Eigen::Matrix<double, 3, 4> start = c.x + 1e-5 * random_matrix(3, 4, 7).matrix();
        const BodyFrictionPair pair = body_friction_pair(c.kind, vertices, c.x, start, force, mu);
        for (double regime : {0.4, 3.0}) {  // y / ε: sticking, sliding
            Eigen::Matrix<double, 3, 4> move = random_matrix(3, 4, 11).matrix();
            move *= regime * epsilon / (T.transpose() * move * w).norm();
            Vector12d x = Eigen::Map<const Vector12d>(Eigen::Matrix<double, 3, 4>(start + move).data());
            x += 1e-3 * epsilon * random_vector(12, 13);  // and some normal motion, which friction ignores
            const PrimitiveFunction f = body_friction(pair, x, epsilon);
            const double h = 1e-3 * epsilon;
            Vector12d gradient_fd;
            Matrix12d hessian_fd;
            for (int i = 0; i < 12; ++i) {
                Vector12d plus = x, minus = x;
                plus[i] += h;
                minus[i] -= h;
                const PrimitiveFunction up = body_friction(pair, plus, epsilon), down = body_friction(pair, minus, epsilon);
                gradient_fd[i] = (up.value - down.value) / (2.0 * h);
                hessian_fd.col(i) = (up.gradient - down.gradient) / (2.0 * h);
            }
            INFO("y/ε = " << regime << ", |g| " << f.gradient.norm() << ", |H| " << f.hessian.norm());
            CHECK((f.gradient - gradient_fd).norm() <= 1e-6 * f.gradient.norm());
            CHECK((f.hessian - hessian_fd).norm() <= 1e-6 * f.hessian.norm());
            // The forces on the two primitives are equal and opposite, and the Hessian PSD.
            Eigen::Vector3d total = Eigen::Vector3d::Zero();
            for (int k = 0; k < 4; ++k)
                total += f.gradient.segment<3>(3 * k);
            CHECK(total.norm() <= 1e-14 * f.gradient.norm());
            CHECK(Eigen::SelfAdjointEigenSolver<Matrix12d>(f.hessian).eigenvalues().minCoeff() >= -1e-12 * f.hessian.norm());
            // Sliding: the full Coulomb force μλ on the closest point of the first primitive (w₀ = 1).
            if (regime > 1.0)
                CHECK(f.gradient.head<3>().norm() == Approx(mu * force * std::abs(w[0])).epsilon(1e-12));
        }
    }
    CHECK_THROWS_AS(body_friction_pair(PrimitivePair::point_triangle, vertices, cases[0].x, cases[0].x, -1.0, mu), Error);
}

TEST_CASE("friction between bodies: refusals, and no pair without contact or without μ", "[self][ex15.5]")
{
    dynamics::Scene scene;
    scene.mesh = box_mesh(1, 1, 1, Eigen::Vector3d::Constant(0.1));
    const dynamics::Body body(scene);
    BodyContactOptions options;
    options.self_contact = true;
    options.body_friction = -0.1;
    CHECK_THROWS_WITH(body_contact_potential(body, {}, options), Catch::Contains("between bodies"));
    options.self_contact = false;
    options.body_friction = 0.3;
    const std::vector<std::shared_ptr<const Obstacle>> floor{std::make_shared<HalfSpace>(Eigen::Vector3d::Zero(),
                                                                                          Eigen::Vector3d::UnitZ())};
    CHECK_THROWS_WITH(body_contact_potential(body, floor, options), Catch::Contains("self-contact"));
    BlockOnBlock frictionless(0.0, Eigen::Vector3d(0, 0, -9.81), Eigen::Vector3d::Zero());
    frictionless.step();
    CHECK(frictionless.contact->term<BodyContactTerm>()->friction_pairs().empty());
    BlockOnBlock rough(0.3, Eigen::Vector3d(0, 0, -9.81), Eigen::Vector3d::Zero());
    rough.step();
    CHECK(!rough.contact->term<BodyContactTerm>()->friction_pairs().empty());
}

TEST_CASE("a block sliding on a pinned block decelerates at mu g and stops", "[self][ex15.5]")
{
    const double g = 9.81, mu = 0.3, v0 = 0.5;
    BlockOnBlock blocks(mu, Eigen::Vector3d(0, 0, -g), Eigen::Vector3d(v0, 0, 0));
    std::vector<double> speed{v0};
    const double stop = v0 / (mu * g);  // 0.17 s
    const int steps = static_cast<int>(std::ceil((stop + 0.1) / blocks.time_step));
    for (int s = 0; s < steps; ++s) {
        blocks.step();
        speed.push_back(blocks.velocity().x());
    }
    // The deceleration over the middle of the slide (steps 3 … 13 of 17), and v(t) = v₀ − μ g t.
    const double deceleration = (speed[3] - speed[13]) / (10 * blocks.time_step);
    INFO("deceleration " << deceleration << " m/s^2 against mu g = " << mu * g << "; v(0.1 s) " << speed[10]
                         << " against " << v0 - mu * g * 0.1 << "; final speed " << speed.back());
    CHECK(std::abs(deceleration - mu * g) <= 0.03 * mu * g);
    CHECK(std::abs(speed[10] - (v0 - mu * g * 0.1)) <= 0.03 * v0);
    CHECK(std::abs(speed.back()) <= 1e-2 * v0);  // stopped …
    CHECK(std::abs(speed[speed.size() - 5]) <= 1e-2 * v0);  // … and stays
    CHECK(blocks.contact->smallest_distance(blocks.state.u) > 0.0);
}

TEST_CASE("a block on a tilted block: sticks when tan(theta) < mu, slides at g(sin - mu cos) when tan(theta) > mu",
          "[self][ex15.5]")
{
    const double g = 9.81, mu = 0.4, eps_v = ContactOptions{}.friction_velocity;
    for (double tangent : {0.5 * mu, 1.5 * mu}) {
        const double theta = std::atan(tangent);
        BlockOnBlock blocks(mu, g * Eigen::Vector3d(std::sin(theta), 0, -std::cos(theta)), Eigen::Vector3d::Zero());
        std::vector<double> speed{0.0};
        for (int s = 0; s < 30; ++s) {
            blocks.step();
            speed.push_back(blocks.velocity().x());
        }
        const double acceleration = (speed[30] - speed[10]) / (20 * blocks.time_step);
        const double expected = slope_acceleration(g, theta, mu);
        INFO("tan theta = " << tangent << ", mu = " << mu << ": acceleration " << acceleration << " against "
                            << expected << ", final speed " << speed.back() << " m/s, eps_v " << eps_v);
        if (tangent < mu) {
            // It creeps at the lagged friction's steady rate, sticking_creep ε_v (f₁(y) = tan θ/μ).
            const double creep = sticking_creep(theta, mu) * eps_v;
            CHECK(std::abs(speed.back() - creep) <= 0.1 * creep);
        } else {
            CHECK(std::abs(acceleration - expected) <= 0.03 * expected);
        }
    }
}

TEST_CASE("two blocks rubbing as they bounce off each other: momentum kept, their sliding slowed by mu times the normal impulse", "[self][ex15.5]")
{
    // Two free cubes without gravity, 1.2 mm apart face to face in x, offset in y and z, thrown at each
    // other in x while sliding past each other in y; friction (internal) must keep Σ m v and take
    // some of the relative sliding away.
    const TetMesh one = box_at(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(0.1));
    const TetMesh two = box_at(Eigen::Vector3d(0.1012, 0.03, 0.02), Eigen::Vector3d::Constant(0.1));
    const TetMesh mesh = two_bodies(one, two);
    const auto run = [&](double mu) {
        BodyContactOptions options;
        options.self_contact = true;
        options.body_friction = mu;
        Eigen::VectorXd velocity(3 * 16);
        for (int v = 0; v < 16; ++v)
            velocity.segment<3>(3 * v) = (v < 8 ? 1.0 : -1.0) * Eigen::Vector3d(0.3, 0.3, 0.0);
        test::ContactRun blocks(test::free_scene(mesh), options, {}, {}, velocity);
        const dynamics::Body& body = *blocks.body;
        const dynamics::State& state = blocks.state;
        double worst = 0.0, scale = 0.0;
        for (int v = 0; v < 16; ++v)
            scale += body.dof_masses()[3 * v] * velocity.segment<3>(3 * v).norm();
        bool rubbed = false;
        for (int s = 0; s < 40; ++s) {
            blocks.step();
            rubbed = rubbed || !blocks.contact->term<BodyContactTerm>()->friction_pairs().empty();
            Eigen::Vector3d total = Eigen::Vector3d::Zero();
            for (int v = 0; v < 16; ++v)
                total += body.dof_masses()[3 * v] * state.v.segment<3>(3 * v);
            worst = std::max(worst, total.norm() / scale);
        }
        const Eigen::Vector3d sliding = block_velocity(body, state.v, 0) - block_velocity(body, state.v, 8);
        INFO("mu " << mu << ": worst relative momentum " << worst << ", relative velocity " << sliding.transpose());
        CHECK(worst <= 1e-9);
        CHECK(sliding.x() < 0.0);  // they bounced apart
        CHECK(rubbed == (mu > 0.0));
        return sliding;
    };
    // Coulomb's law in impulses: while the faces slide, the friction impulse is μ times the normal
    // one, so the relative sliding speed falls by μ times the change of the relative normal speed.
    const double mu = 0.5;
    const Eigen::Vector3d frictionless = run(0.0), rough = run(mu);
    const double slowed = frictionless.y() - rough.y(), coulomb = mu * (0.6 - rough.x());
    INFO("relative sliding speed after the bounce: " << rough.y() << " m/s with friction, " << frictionless.y()
                                                     << " without; slowed by " << slowed << ", Coulomb's impulse "
                                                     << coulomb);
    // Without friction the sliding is nearly untouched (the faces tilt a little as they deform).
    CHECK(frictionless.y() == Approx(0.6).epsilon(0.02));
    CHECK(rough.y() > 0.0);  // it slid throughout, so Coulomb's law holds as an impulse
    CHECK(std::abs(slowed - coulomb) <= 0.05 * coulomb);
}
