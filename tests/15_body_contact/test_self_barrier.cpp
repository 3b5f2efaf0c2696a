// Chapter 15: bodies against bodies and a body against itself (self_barrier.hpp, broad_phase.hpp):
// the barrier's derivatives against central differences, the three broad phases against each other
// and against every pair's distance, two blocks thrown at each other (momentum, symmetry, no edge
// through a face, and they part), and two bars crossed at right angles, which only their edges hold
// apart. docs/15_body_contact.md#bodies-against-bodies-and-self-contact
#include "15_body_contact/broad_phase.hpp"
#include "15_body_contact/body_contact.hpp"
#include "15_body_contact/distances.hpp"
#include "15_body_contact/intersections.hpp"
#include "15_body_contact/self_barrier.hpp"

#include "contact_bodies.hpp"

#include "12_hyperelastic_newton/force_models.hpp"
#include "12_hyperelastic_newton/newton.hpp"

#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"
#include "common/random.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

using namespace fem;
using namespace fem::contact;
using fem::test::box_at;
using fem::test::entries_of;
using fem::test::momentum;
using fem::test::EntriesNear;
using fem::test::two_bodies;

namespace {

/// The barrier with a fixed κ as a potential (energy, gradient) for test::central_differences.
struct SelfPotential {
    const SelfContactBarrier& barrier;
    double stiffness;
    double energy(const Eigen::VectorXd& u) const { return barrier.energy(u, stiffness); }
    Eigen::VectorXd gradient(const Eigen::VectorXd& u) const
    {
        Eigen::VectorXd g = Eigen::VectorXd::Zero(u.size());
        barrier.add_gradient(u, stiffness, g);
        return g;
    }
};

/// Two bodies, one mesh (two_bodies: the first `half` vertices the first body), without gravity, thrown
/// at each other at ±speed along axis, stepped by chapter 12's Newton backward Euler with
/// self-contact as its potential (contact_step).
struct Bodies : test::ContactRun {
    SurfacePrimitives surface;

    Bodies(const TetMesh& mesh, Eigen::Index half, int axis, double speed)
        : ContactRun(test::free_scene(mesh), self_contact(), {}, {}, thrown(mesh, half, axis, speed)),
          surface(surface_primitives(mesh))
    {
    }
    static BodyContactOptions self_contact()
    {
        BodyContactOptions options;
        options.self_contact = true;
        options.check_intersections = true;  // every Newton iterate and line-search trial
        return options;
    }
    /// ±speed along axis: + on the first half of the vertices, − on the rest (3n).
    static Eigen::VectorXd thrown(const TetMesh& mesh, Eigen::Index half, int axis, double speed)
    {
        Eigen::VectorXd velocity = Eigen::VectorXd::Zero(3 * mesh.V.rows());
        for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
            velocity[3 * v + axis] = v < half ? speed : -speed;
        return velocity;
    }
    /// One step; requires that no surface pair touches and no surface edge meets a surface triangle
    /// after it, and returns the smallest distance of a pair within d̂ (+∞: none).
    double step()
    {
        ContactRun::step();
        INFO("step " << state.step);
        const double distance = contact->smallest_distance(state.u);
        REQUIRE(distance > 0.0);
        const EdgeThroughTriangle crossing = first_edge_through_triangle(body->positions(state.u), surface.edges,
                                                                         surface.triangles);
        INFO(describe(crossing, surface.edges, surface.triangles));
        REQUIRE_FALSE(crossing.found());
        return distance;
    }
};

/// Two one-cell cubes face to face 0.4 mm apart, the second turned 0.3 rad about x (the faces'
/// normal) and shifted, so that vertices stand over the other's face and edges cross at angles:
/// point–triangle and edge–edge pairs within d̂ = 1 mm. One mesh, the first cube's 8 vertices first.
TetMesh turned_cubes()
{
    const TetMesh first = box_at(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(0.1));
    TetMesh second = box_at(Eigen::Vector3d(-0.05, -0.05, -0.05), Eigen::Vector3d::Constant(0.1));
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
    second.V = (second.V * turn.transpose()).rowwise() + Eigen::RowVector3d(0.1504, 0.07, 0.04);
    return two_bodies(first, second);
}

}  // namespace

TEST_CASE("self-contact barrier: energy, gradient and Hessian against central differences, PSD", "[self][ex15.5]")
{
    const TetMesh mesh = turned_cubes();
    const SelfContactBarrier barrier(mesh, 1e-3);
    const SelfPotential potential{barrier, 50.0};
    const Eigen::Index n = 3 * mesh.V.rows();
    for (unsigned seed : {1u, 2u, 3u}) {
        const Eigen::VectorXd u = 5e-5 * random_vector(n, seed);
        const double energy = potential.energy(u);
        REQUIRE(std::isfinite(energy));
        REQUIRE(energy > 0.0);
        const Eigen::VectorXd g = potential.gradient(u);
        std::vector<Eigen::Triplet<double>> triplets;
        barrier.add_hessian(u, potential.stiffness, triplets);
        Eigen::SparseMatrix<double> sparse(n, n);
        sparse.setFromTriplets(triplets.begin(), triplets.end());
        const Eigen::MatrixXd H(sparse);
        const test::CentralDifferences differences = test::central_differences(potential, u, 1e-8);
        INFO("seed " << seed << ", energy " << energy << ", |g| " << g.norm() << ", |g - g_fd| "
                     << (g - differences.gradient).norm());
        CHECK((g - differences.gradient).norm() <= 1e-5 * g.norm());
        // Both bodies feel the pair: the forces on the two sum to zero (translation invariance).
        Eigen::Vector3d total = Eigen::Vector3d::Zero();
        for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
            total += g.segment<3>(3 * v);
        CHECK(total.norm() <= 1e-10 * g.norm());
        // PSD, and H − H_exact is PSD (the projections only add).
        const Eigen::MatrixXd symmetric = 0.5 * (differences.hessian + differences.hessian.transpose());
        INFO("|H| " << H.norm() << ", |H_fd| " << symmetric.norm());
        CHECK(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues().minCoeff() >= -1e-8 * H.norm());
        CHECK(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H - symmetric).eigenvalues().minCoeff() >=
              -1e-4 * H.norm());
    }
    // A body alone at rest: its primitives that share a vertex (d = 0) are not pairs.
    const SelfContactBarrier alone(box_mesh(2, 2, 2, Eigen::Vector3d::Constant(0.1)), 1e-3);
    const Eigen::VectorXd rest = Eigen::VectorXd::Zero(3 * 27);
    CHECK(alone.energy(rest, 50.0) == 0.0);
    CHECK(alone.smallest_distance(rest, 0.2) > 0.0);
    CHECK_THROWS_AS(SelfContactBarrier(mesh, 0.0), Error);
    CHECK_THROWS_AS(alone.energy(Eigen::VectorXd::Zero(5), 1.0), Error);
}

TEST_CASE("self-contact barrier's Hessian unprojected and by absolute values: the central differences' Hessian, "
          "and above it", "[self][ex15.5]")
{
    // The pairs of the test above (point–triangle and edge–edge within d̂): with no projection the
    // blocks sum to ∇²P itself; with |λ| the sum is PSD and lies above the clamped one (|λ| ≥ max(λ, 0)).
    const TetMesh mesh = turned_cubes();
    const Eigen::Index half = mesh.V.rows() / 2;  // the first cube's vertices
    const SelfContactBarrier barrier(mesh, 1e-3);
    const SelfPotential potential{barrier, 50.0};
    const Eigen::Index n = 3 * mesh.V.rows();
    const auto assembled = [&](const Eigen::VectorXd& u, std::optional<hyper::Projection> projection) {
        std::vector<Eigen::Triplet<double>> triplets;
        barrier.add_hessian(u, potential.stiffness, triplets, projection);
        Eigen::SparseMatrix<double> sparse(n, n);
        sparse.setFromTriplets(triplets.begin(), triplets.end());
        return Eigen::MatrixXd(sparse);
    };
    for (unsigned seed : {1u, 2u, 3u}) {
        const Eigen::VectorXd u = 5e-5 * random_vector(n, seed);
        const test::CentralDifferences differences = test::central_differences(potential, u, 1e-8);
        const Eigen::MatrixXd symmetric = 0.5 * (differences.hessian + differences.hessian.transpose());
        const Eigen::MatrixXd exact = assembled(u, std::nullopt), clamped = assembled(u, hyper::Projection::clamp),
                              absolute = assembled(u, hyper::Projection::absolute);
        INFO("seed " << seed << ", |H| " << exact.norm() << ", |H - H_fd| " << (exact - symmetric).norm());
        CHECK((exact - symmetric).norm() <= 1e-4 * symmetric.norm());
        // Indefinite as it is (the projection has something to do here), PSD projected.
        const double scale = exact.norm();
        CHECK(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(exact).eigenvalues().minCoeff() < -1e-8 * scale);
        CHECK(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(absolute).eigenvalues().minCoeff() >= -1e-8 * scale);
        CHECK(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(absolute - clamped).eigenvalues().minCoeff() >=
              -1e-8 * scale);
        CHECK((absolute - clamped).norm() > 1e-8 * scale);
        // |λ| − max(λ, 0) = max(−λ, 0) per block: absolute − clamped = clamped − exact.
        CHECK((absolute - clamped - (clamped - exact)).norm() <= 1e-10 * scale);
        // The contact potential (κ fixed at the same 50 N/m) hands Newton these: hessian projected as
        // BodyContactOptions::barrier_projection says, exact_hessian as it is only when asked. It refuses
        // pairs within d̂ at rest: its mesh has the second cube 2 mm farther, u brings it back.
        TetMesh apart = mesh;
        Eigen::VectorXd u_apart = u;
        for (Eigen::Index v = half; v < mesh.V.rows(); ++v) {
            apart.V(v, 0) += 2e-3;
            u_apart[3 * v] -= 2e-3;
        }
        const SelfContactBarrier apart_barrier(apart, 1e-3);
        const auto apart_assembled = [&](std::optional<hyper::Projection> projection) {
            std::vector<Eigen::Triplet<double>> triplets;
            apart_barrier.add_hessian(u_apart, potential.stiffness, triplets, projection);
            Eigen::SparseMatrix<double> sparse(n, n);
            sparse.setFromTriplets(triplets.begin(), triplets.end());
            return Eigen::MatrixXd(sparse);
        };
        const Eigen::MatrixXd apart_exact = apart_assembled(std::nullopt),
                              apart_absolute = apart_assembled(hyper::Projection::absolute);
        CHECK((apart_exact - exact).norm() <= 1e-2 * scale);  // the same pairs, near the same positions
        for (bool exact_first : {false, true}) {
            BodyContactOptions options;
            options.self_contact = true;
            options.stiffness = potential.stiffness;
            options.barrier_projection = hyper::Projection::absolute;
            options.exact_barrier_hessian = exact_first;
            const test::ContactRun run(test::free_scene(apart), options);
            INFO("exact_barrier_hessian " << exact_first);
            CHECK_THAT(entries_of(run.contact->hessian(u_apart)), EntriesNear(apart_absolute, 1e-12 * scale, 1e-12));
            CHECK_THAT(entries_of(run.contact->exact_hessian(u_apart)),
                       EntriesNear(exact_first ? apart_exact : apart_absolute, 1e-12 * scale, 1e-12));
        }
    }
}

namespace {

/// How got differs from expected, candidate pairs of one motion: the first few pairs each lacks or
/// adds, per kind, as "(i, j)"; empty when they are the same.
std::string candidate_difference(const CandidatePairs& got, const CandidatePairs& expected)
{
    constexpr std::size_t shown = 5;
    std::ostringstream out;
    const auto compare = [&](const char* kind, const std::vector<std::array<int, 2>>& mine,
                             const std::vector<std::array<int, 2>>& theirs) {
        for (const auto& [list, other, what] : {std::tuple{&theirs, &mine, "missing"}, std::tuple{&mine, &theirs, "extra"}}) {
            std::vector<std::array<int, 2>> only;
            std::set_difference(list->begin(), list->end(), other->begin(), other->end(), std::back_inserter(only));
            if (only.empty())
                continue;
            out << only.size() << " " << kind << " pairs " << what << ":";
            for (std::size_t k = 0; k < std::min(shown, only.size()); ++k)
                out << " (" << only[k][0] << ", " << only[k][1] << ")";
            out << (only.size() > shown ? " …; " : "; ");
        }
        if (!std::is_sorted(mine.begin(), mine.end()))
            out << kind << " pairs not in increasing order; ";
    };
    compare("point-triangle", got.point_triangle, expected.point_triangle);
    compare("edge-edge", got.edge_edge, expected.edge_edge);
    return out.str();
}

}  // namespace

TEST_CASE("broad phase: brute force, the AABB tree and the spatial hash find the same pairs, every pair within r",
          "[self][ex15.5]")
{
    const TetMesh block = box_mesh(3, 2, 2, Eigen::Vector3d(0.3, 0.2, 0.2));
    const TetMesh pair_of_blocks = two_bodies(box_at(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(0.1), 2),
                                              box_at(Eigen::Vector3d(0.11, 0.02, 0.03), Eigen::Vector3d::Constant(0.1), 2));
    std::size_t compared = 0;
    for (const TetMesh* mesh : {&block, &pair_of_blocks}) {
        const SurfacePrimitives surface = surface_primitives(*mesh);
        for (unsigned seed = 1; seed <= 4; ++seed)
            for (double inflation : {0.0, 1e-3, 0.03}) {
                const Eigen::Index n = mesh->V.rows();
                const MatrixX3d start = mesh->V + 0.03 * random_matrix(n, 3, seed);
                const MatrixX3d end = start + 0.05 * random_matrix(n, 3, 100 + seed);
                const CandidatePairs brute = brute_force_candidates(surface, start, end, inflation);
                INFO("seed " << seed << ", r = " << inflation << ": " << brute.point_triangle.size()
                             << " point-triangle, " << brute.edge_edge.size() << " edge-edge");
                CHECK(candidate_difference(tree_candidates(surface, start, end, inflation), brute) == "");
                CHECK(candidate_difference(hash_candidates(surface, start, end, inflation), brute) == "");
                compared += brute.point_triangle.size() + brute.edge_edge.size();
                // Held still (start = end), every pair that shares no vertex and is within r is a
                // candidate, and no candidate shares a vertex.
                const CandidatePairs still = hash_candidates(surface, start, start, inflation);
                const auto has = [](const auto& list, int i, int j) {
                    return std::binary_search(list.begin(), list.end(), std::array<int, 2>{i, j});
                };
                const auto at = [&](int v) -> Eigen::Vector3d { return start.row(v).transpose(); };
                for (int v : surface.vertices)
                    for (int t = 0; t < static_cast<int>(surface.triangles.rows()); ++t) {
                        const auto tri = surface.triangles.row(t);
                        const bool shared = (tri.array() == v).any();
                        CHECK_FALSE((shared && has(still.point_triangle, v, t)));
                        if (shared)
                            continue;
                        const Eigen::Vector3d p = at(v), a = at(tri(0)), b = at(tri(1)), c = at(tri(2));
                        const double d2 = point_triangle_squared_distance(p, a, b, c, point_triangle_type(p, a, b, c)).value;
                        if (d2 < inflation * inflation)
                            CHECK(has(still.point_triangle, v, t));
                    }
                for (int a = 0; a < static_cast<int>(surface.edges.rows()); ++a)
                    for (int b = a + 1; b < static_cast<int>(surface.edges.rows()); ++b) {
                        const auto ea = surface.edges.row(a), eb = surface.edges.row(b);
                        const bool shared = ea(0) == eb(0) || ea(0) == eb(1) || ea(1) == eb(0) || ea(1) == eb(1);
                        CHECK_FALSE((shared && has(still.edge_edge, a, b)));
                        if (shared)
                            continue;
                        const Eigen::Vector3d a0 = at(ea(0)), a1 = at(ea(1)), b0 = at(eb(0)), b1 = at(eb(1));
                        const double d2 = edge_edge_squared_distance(a0, a1, b0, b1, edge_edge_type(a0, a1, b0, b1)).value;
                        if (d2 < inflation * inflation)
                            CHECK(has(still.edge_edge, a, b));
                    }
            }
    }
    CHECK(compared > 1000);  // the cases hold pairs to compare
    const SurfacePrimitives surface = surface_primitives(block);
    CHECK_THROWS_AS(tree_candidates(surface, block.V, block.V, -1.0), Error);
    CHECK_THROWS_AS(hash_candidates(surface, block.V, block.V.topRows(3), 0.0), Error);
}

TEST_CASE("two blocks thrown at each other: momentum kept, the motion point-symmetric, no edge through a face, "
          "and they part", "[self][ex15.5]")
{
    // Block one: 2×2×2 cells of 10 cm at the origin, moving +x at 0.5 m/s. Block two: block one
    // reflected through the point c (x → 2c − x, tets turned back to positive volume), 2 mm away and
    // shifted 3 cm in y, 2 cm in z, so that they meet off centre (and spin); it moves at −0.5 m/s.
    // The scene is symmetric under x → 2c − x with v → −v, and so must the motion be.
    const TetMesh one = box_at(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(0.1), 2);
    const Eigen::RowVector3d centre(0.101, 0.065, 0.06);
    TetMesh two = one;
    two.V = (-one.V).rowwise() + 2.0 * centre;
    two.T.col(2).swap(two.T.col(3));
    const TetMesh mesh = two_bodies(one, two);
    const Eigen::Index half = one.V.rows(), n = mesh.V.rows();
    Bodies bodies(mesh, half, 0, 0.5);
    double scale = 0.0;  // Σ m |v|: the size of the momenta that cancel
    for (Eigen::Index v = 0; v < n; ++v)
        scale += bodies.body->dof_masses()[3 * v] * 0.5;
    double worst_momentum = 0.0, worst_symmetry = 0.0, smallest = 1.0;
    for (int step = 0; step < 40; ++step) {
        smallest = std::min(smallest, bodies.step());
        const MatrixX3d x = bodies.body->positions(bodies.state.u);
        worst_momentum = std::max(worst_momentum, momentum(*bodies.body, bodies.state.v, 0, n).norm() / scale);
        const MatrixX3d mirrored = (-x.bottomRows(half)).rowwise() + 2.0 * centre;
        worst_symmetry = std::max(worst_symmetry, (x.topRows(half) - mirrored).cwiseAbs().maxCoeff());
    }
    const Eigen::Vector3d first = momentum(*bodies.body, bodies.state.v, 0, half);
    INFO("smallest distance " << smallest << " m, worst relative momentum " << worst_momentum
                              << ", worst asymmetry " << worst_symmetry << " m, block one's momentum at the end "
                              << first.transpose());
    CHECK(smallest < 1e-3);           // they met, within d̂
    CHECK(worst_momentum <= 1e-9);    // Σ m v = 0 throughout
    CHECK(worst_symmetry <= 1e-9);    // x_one = 2c − x_two throughout (0.1 m blocks)
    CHECK(first.x() < 0.0);           // block one now moves back, away from block two
    CHECK(bodies.contact->smallest_distance(bodies.state.u) >= 1e-3);  // and they parted: no pair within d̂
}

TEST_CASE("two bars crossed at right angles, pushed together: only their edges meet, and hold", "[self][ex15.5]")
{
    // Bar one along x (30 × 10 × 5 cm, one cell: vertices only at its ends), bar two along y above it,
    // 2 mm higher; where they cross, no vertex of either stands over the other's faces: the contact
    // is edge against edge, which a vertex-only barrier would let through.
    const double gap = 2e-3;
    const TetMesh one = box_at(Eigen::Vector3d(0.0, 0.1, 0.0), Eigen::Vector3d(0.3, 0.1, 0.05));
    const TetMesh two = box_at(Eigen::Vector3d(0.1, 0.0, 0.05 + gap), Eigen::Vector3d(0.1, 0.3, 0.05));
    const TetMesh mesh = two_bodies(one, two);
    const Eigen::Index half = one.V.rows();
    Bodies bodies(mesh, half, 2, 0.5);
    const SurfacePrimitives& surface = bodies.surface;
    // The vertices' distance to the other bar's surface triangles (what a vertex-only barrier sees).
    const auto vertex_distance = [&](const MatrixX3d& x) {
        double nearest = 1.0;
        for (int v : surface.vertices)
            for (Eigen::Index t = 0; t < surface.triangles.rows(); ++t) {
                const auto tri = surface.triangles.row(t);
                if ((v < half) == (tri(0) < half))
                    continue;  // the same bar
                const Eigen::Vector3d p = x.row(v).transpose(), a = x.row(tri(0)).transpose(),
                                      b = x.row(tri(1)).transpose(), c = x.row(tri(2)).transpose();
                nearest = std::min(nearest, std::sqrt(point_triangle_squared_distance(
                                                          p, a, b, c, point_triangle_type(p, a, b, c)).value));
            }
        return nearest;
    };
    double smallest = 1.0, vertices_at_smallest = 0.0;
    for (int step = 0; step < 40; ++step) {
        const double distance = bodies.step();
        if (distance < smallest) {
            smallest = distance;
            vertices_at_smallest = vertex_distance(bodies.body->positions(bodies.state.u));
        }
    }
    INFO("smallest distance " << smallest << " m; then the nearest vertex was " << vertices_at_smallest
                              << " m from the other bar");
    CHECK(smallest < 1e-3);                 // they met within d̂ …
    CHECK(vertices_at_smallest > 1e-2);     // … where no vertex was near the other bar
    const Eigen::Vector3d lower = momentum(*bodies.body, bodies.state.v, 0, half);
    CHECK(lower.z() < 0.0);                 // the lower bar moves down again: they bounced
}

TEST_CASE("self-contact's refusals: no obstacle without it, and primitives closer than d-hat at rest", "[self][ex15.5]")
{
    dynamics::Scene scene;
    scene.mesh = box_mesh(2, 2, 2, Eigen::Vector3d::Constant(0.1));  // cells of 5 cm
    const dynamics::Body body(scene);
    const std::vector<std::shared_ptr<const Obstacle>> none;
    CHECK_THROWS_AS(body_contact_potential(body, none, BodyContactOptions{}), Error);
    BodyContactOptions options;
    options.self_contact = true;
    CHECK_NOTHROW(body_contact_potential(body, none, options));
    // d̂ = 6 cm reaches from a surface vertex to the triangles of the neighbouring cell's far side.
    options.activation_distance = 0.06;
    CHECK_THROWS_WITH(body_contact_potential(body, none, options), Catch::Contains("closer than d̂"));
}

TEST_CASE("self-contact's time of impact: never after the first contact, never far before it", "[self][ex15.5]")
{
    // Two cubes 1 cm apart closing by 4 cm (first contact at s = 1/4, face on face: point–triangle
    // pairs), and two crossed one-cell bars 2 mm apart closing by 4 mm (first contact at s = 1/2,
    // where only edges meet: edge–edge pairs). Moving apart instead, no impact.
    struct Case {
        const char* name;
        TetMesh mesh;
        Eigen::Index half;
        int axis;
        double closing, first_contact;
    };
    const TetMesh cube = box_at(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(0.1));
    const TetMesh bar_one = box_at(Eigen::Vector3d(0.0, 0.1, 0.0), Eigen::Vector3d(0.3, 0.1, 0.05));
    const std::vector<Case> cases{
        {"cubes", two_bodies(cube, box_at(Eigen::Vector3d(0.11, 0.03, 0.02), Eigen::Vector3d::Constant(0.1))),
         cube.V.rows(), 0, 0.04, 0.25},
        {"crossed bars",
         two_bodies(bar_one, box_at(Eigen::Vector3d(0.1, 0.0, 0.052), Eigen::Vector3d(0.1, 0.3, 0.05))),
         bar_one.V.rows(), 2, 0.004, 0.5}};
    for (const Case& c : cases) {
        const SelfContactBarrier barrier(c.mesh, 1e-3);
        const Eigen::Index n = c.mesh.V.rows();
        Eigen::VectorXd du = Eigen::VectorXd::Zero(3 * n);
        for (Eigen::Index v = 0; v < n; ++v)
            du[3 * v + c.axis] = (v < c.half ? 0.5 : -0.5) * c.closing;
        const Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * n);
        const double s = barrier.time_of_impact(u, du);
        INFO(c.name << ": time of impact " << s << ", first contact at " << c.first_contact);
        CHECK(s <= c.first_contact);
        CHECK(s >= 0.9 * c.first_contact);
        CHECK(barrier.time_of_impact(u, -du) > 1.0);
    }
}

TEST_CASE("self-contact per body: two bodies always hold each other off, a body its own pairs only when asked",
          "[self][ex15.5]")
{
    // Body 0: a block of 2×2×2 cells of 5 cm, whose own primitives come within 6 cm of each other
    // (d̂ = 6 cm reaches across a cell); body 1: a one-cell block 10 cm away, whose own don't.
    const TetMesh block = box_at(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(0.1), 2);
    const TetMesh far = box_at(Eigen::Vector3d(0.2, 0.0, 0.0), Eigen::Vector3d::Constant(0.1), 1);
    const TetMesh mesh = two_bodies(block, far);
    std::vector<int> vertex_body(static_cast<std::size_t>(mesh.V.rows()), 1);
    std::fill(vertex_body.begin(), vertex_body.begin() + block.V.rows(), 0);
    const Eigen::VectorXd rest = Eigen::VectorXd::Zero(3 * mesh.V.rows());
    const double dhat = 0.06;
    const SelfContactBarrier both(mesh, dhat, vertex_body, {true, true}), between(mesh, dhat, vertex_body, {false, false});
    // With its own pairs, body 0 is closer than d̂ to itself at rest; without them nothing is within
    // reach (the bodies are 10 cm apart).
    CHECK(both.smallest_distance(rest, dhat) < dhat);
    CHECK(between.smallest_distance(rest, dhat) == std::numeric_limits<double>::infinity());
    // Moved to 4 cm apart, the bodies' pairs count either way.
    Eigen::VectorXd closer = rest;
    for (Eigen::Index v = block.V.rows(); v < mesh.V.rows(); ++v)
        closer[3 * v] = -0.06;
    CHECK(std::abs(between.smallest_distance(closer, dhat) - 0.04) < 1e-12);
    for (const SurfacePair& pair : between.pairs(closer, false))
        CHECK(vertex_body[std::size_t(pair.vertices[0])] != vertex_body[std::size_t(pair.vertices[3])]);
    // Through the contact potential: a body's own pairs closer than d̂ at rest are refused only when it
    // holds itself off.
    dynamics::Scene scene = test::free_scene(mesh);
    const dynamics::Body body(scene);
    const std::vector<std::shared_ptr<const Obstacle>> none;
    BodyContactOptions options;
    options.self_contact = true;
    options.activation_distance = dhat;
    options.vertex_body = vertex_body;
    options.body_self_contact = {false, false};
    CHECK_NOTHROW(body_contact_potential(body, none, options));
    options.body_self_contact = {true, false};
    CHECK_THROWS_WITH(body_contact_potential(body, none, options), Catch::Contains("closer than d̂"));
    options.body_self_contact = {true};
    CHECK_THROWS_WITH(body_contact_potential(body, none, options), Catch::Contains("no self-contact setting"));
}

TEST_CASE("self-contact's motion candidates: the pairs within d-hat at every point of the motion, as brute force "
          "finds them, from one broad phase",
          "[self][ex15.5]")
{
    // Two blocks of 2³ cells 1.5 mm apart, each vertex moved at random (so that the pairs within d̂
    // change along the motion, and some cross); time_of_impact keeps the motion's candidates, and
    // pairs() at x + α du must then find, without a tree of its own, every pair brute force finds.
    const TetMesh mesh = two_bodies(box_at(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(0.01), 2),
                                    box_at(Eigen::Vector3d(0.0115, 0.002, -0.003), Eigen::Vector3d::Constant(0.01), 2));
    const double reach = 1e-3;
    const SelfContactBarrier barrier(mesh, reach);
    const SurfacePrimitives& surface = barrier.surface();
    const Eigen::Index n = 3 * mesh.V.rows();
    using Key = std::array<int, 5>;  // kind, 4 vertices
    const auto brute_force = [&](const Eigen::VectorXd& u) {
        const MatrixX3d x = mesh.V + u.reshaped<Eigen::RowMajor>(mesh.V.rows(), 3);
        const CandidatePairs candidates = brute_force_candidates(surface, x, x, reach);
        const auto at = [&](int v) -> Eigen::Vector3d { return x.row(v).transpose(); };
        std::vector<Key> within;
        for (const auto& [p, t] : candidates.point_triangle) {
            const int a = surface.triangles(t, 0), b = surface.triangles(t, 1), c = surface.triangles(t, 2);
            if (point_triangle_squared_distance(at(p), at(a), at(b), at(c),
                                                point_triangle_type(at(p), at(a), at(b), at(c))).value < reach * reach)
                within.push_back({int(PrimitivePair::point_triangle), p, a, b, c});
        }
        for (const auto& [e, f] : candidates.edge_edge) {
            const int a0 = surface.edges(e, 0), a1 = surface.edges(e, 1), b0 = surface.edges(f, 0), b1 = surface.edges(f, 1);
            if (edge_edge_squared_distance(at(a0), at(a1), at(b0), at(b1),
                                           edge_edge_type(at(a0), at(a1), at(b0), at(b1))).value < reach * reach)
                within.push_back({int(PrimitivePair::edge_edge), a0, a1, b0, b1});
        }
        std::sort(within.begin(), within.end());
        return within;
    };
    const auto found = [&](const Eigen::VectorXd& u) {
        std::vector<Key> within;
        for (const SurfacePair& pair : barrier.pairs(u, false))
            within.push_back({int(pair.kind), pair.vertices[0], pair.vertices[1], pair.vertices[2], pair.vertices[3]});
        std::sort(within.begin(), within.end());
        return within;
    };
    std::size_t most = 0;
    for (unsigned seed : {1u, 2u, 3u, 4u, 5u}) {
        const Eigen::VectorXd u = 3e-4 * random_vector(n, seed), du = 2e-3 * random_vector(n, seed + 100);
        barrier.time_of_impact(u, du);
        const long long trees = barrier.broad_phases();
        for (double alpha : {0.0, 0.1, 0.25, 0.4, 0.5, 0.6, 0.75, 0.9, 1.0}) {
            INFO("seed " << seed << ", alpha " << alpha);
            const std::vector<Key> expected = brute_force(u + alpha * du);
            CHECK(found(u + alpha * du) == expected);
            most = std::max(most, expected.size());
        }
        CHECK(barrier.broad_phases() == trees);  // every point above from the motion's candidates
        // Off the motion (twice the step): a tree of its own, the same answer as brute force.
        const Eigen::VectorXd beyond = u + 2.0 * du;
        CHECK(found(beyond) == brute_force(beyond));
        CHECK(barrier.broad_phases() == trees + 1);
    }
    CHECK(most > 10);  // the motions bring many pairs within d̂
}
