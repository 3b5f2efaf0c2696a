// Chapter 15: the obstacles' edges and corners against the body's surface (feature_barrier.hpp):
// its derivatives against central differences, and the knife — a wedge's ridge and a box's edge
// pressed into a one-cell block's face between its vertices, which the vertices' barrier alone let
// in 3–4 cm. docs/15_body_contact.md#edges-and-corners-of-obstacles
#include "15_body_contact/body_contact.hpp"
#include "14_contact/contact_scenes.hpp"
#include "15_body_contact/mesh_obstacle.hpp"
#include "14_contact/obstacles.hpp"

#include "04_tet_jacobians/tet_jacobians.hpp"

#include "../14_contact/contact_derivatives.hpp"

#include "common/random.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

using namespace fem;
using namespace fem::contact;

namespace {

/// A wedge lying along y, edge down: its ridge the segment from (0.05, −0.1, ridge) to
/// (0.05, 0.2, ridge), its flanks rising 1 in 1 to z = ridge + 0.1 (an open sheet of four
/// triangles), moving with velocity.
std::shared_ptr<const Obstacle> wedge(double ridge, const Eigen::Vector3d& velocity)
{
    TriMesh sheet;
    sheet.V.resize(6, 3);
    sheet.V << 0.05, -0.1, ridge, 0.05, 0.2, ridge, -0.05, -0.1, ridge + 0.1, -0.05, 0.2, ridge + 0.1, 0.15, -0.1,
        ridge + 0.1, 0.15, 0.2, ridge + 0.1;
    sheet.F.resize(4, 3);
    sheet.F << 0, 1, 3, 0, 3, 2, 0, 4, 5, 0, 5, 1;
    return std::make_shared<MeshObstacle>(sheet, 0.0, velocity);
}

/// Whether some obstacle edge (shifted by shift) has a point inside a tet of the body at u: along
/// the segment a + λ (b − a) each of the tet's barycentric coordinates is linear in λ, so the
/// segment is inside the tet on the interval of λ ∈ [0, 1] where all four are > 0 — nonempty
/// exactly when the edge enters the tet (the knife's check, exact up to round-off).
bool edge_inside_body(const dynamics::Body& body, const Eigen::VectorXd& u, const ObstacleFeatures& features,
                      const Eigen::Vector3d& shift)
{
    const MatrixX3d x = body.positions(u);
    for (Eigen::Index e = 0; e < features.edges.rows(); ++e) {
        const Eigen::Vector3d a = features.corners.row(features.edges(e, 0)).transpose() + shift;
        const Eigen::Vector3d b = features.corners.row(features.edges(e, 1)).transpose() + shift;
        for (int t = 0; t < static_cast<int>(body.mesh().T.rows()); ++t) {
            const tet::TetVertices corners = tet::tet_vertices(body.mesh(), x, t);
            const Eigen::Vector4d at_a = tet::shape_functions(corners, a), at_b = tet::shape_functions(corners, b);
            double low = 0.0, high = 1.0;  // the λ where every coordinate is > 0
            for (int i = 0; i < 4; ++i) {
                const double slope = at_b[i] - at_a[i];
                if (slope > 0.0)
                    low = std::max(low, -at_a[i] / slope);
                else if (slope < 0.0)
                    high = std::min(high, -at_a[i] / slope);
                else if (!(at_a[i] > 0.0))
                    high = -1.0;  // this coordinate is ≤ 0 all along
            }
            if (low < high)
                return true;
        }
    }
    return false;
}

}  // namespace

TEST_CASE("edge and corner barrier: energy, gradient and Hessian against central differences", "[ex15.2]")
{
    // A one-cube block over a box turned so that its top corner and two top edges come within d̂ of
    // the block's lower face and edges, not at its vertices.
    BlockSettings settings;
    settings.terms = body_contact_term_maker();  // the obstacles' edges and corners too
    settings.height = 0.0;
    settings.contact.stiffness = 50.0;
    const Eigen::Matrix3d turn = (Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitZ()) *
                                  Eigen::AngleAxisd(0.61548, Eigen::Vector3d::UnitX()) *
                                  Eigen::AngleAxisd(0.7854, Eigen::Vector3d::UnitY()))
                                     .toRotationMatrix();
    const Eigen::Vector3d half(0.03, 0.03, 0.03);
    // The box's highest corner, 0.4 mm under the block's lower face at (0.043, 0.057).
    Eigen::Vector3d highest = Eigen::Vector3d::Constant(-1e9);
    for (int k = 0; k < 8; ++k) {
        const Eigen::Vector3d sign((k & 1) ? 1.0 : -1.0, (k & 2) ? 1.0 : -1.0, (k & 4) ? 1.0 : -1.0);
        const Eigen::Vector3d corner = turn * sign.cwiseProduct(half);
        if (corner.z() > highest.z())
            highest = corner;
    }
    const Eigen::Vector3d centre = Eigen::Vector3d(0.043, 0.057, -4e-4) - highest;
    settings.obstacles = {std::make_shared<Box>(centre, half, turn)};
    BlockScene block = block_scene(settings);
    ContactPotential& contact = *block.contact;
    contact.begin_step(*block.body, block.state, settings.time_step);
    const Eigen::Index n = block.state.u.size();
    for (int seed : {1, 2, 3}) {
        const Eigen::VectorXd u = 5e-5 * random_vector(n, seed);
        const double energy = contact.energy(u);
        REQUIRE(std::isfinite(energy));
        REQUIRE(energy > 0.0);  // the corner is within d̂ of the face, no vertex is
        const Eigen::VectorXd g = contact.gradient(u);
        const Eigen::MatrixXd H = Eigen::MatrixXd(contact.hessian(u));
        const test::CentralDifferences differences = test::central_differences(contact, u, 1e-8);
        const Eigen::VectorXd& g_fd = differences.gradient;
        const Eigen::MatrixXd& H_fd = differences.hessian;
        INFO("seed " << seed << ", energy " << energy << ", |g| " << g.norm() << ", |g - g_fd| " << (g - g_fd).norm());
        CHECK((g - g_fd).norm() <= 1e-5 * g.norm());
        // The Hessian is the sum of each pair's PSD projection: PSD itself, and it adds to the exact
        // Hessian only what the projections add, so H − H_exact is PSD too.
        const Eigen::MatrixXd symmetric = 0.5 * (H_fd + H_fd.transpose());
        INFO("|H| " << H.norm() << ", |H_fd| " << symmetric.norm());
        CHECK(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues().minCoeff() >= -1e-8 * H.norm());
        CHECK(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H - symmetric).eigenvalues().minCoeff() >=
              -1e-4 * H.norm());
    }
}

TEST_CASE("the knife: a wedge's ridge and a box's edge pressed into a one-cell block never enter it", "[ex15.4][slow]")
{
    // The block (10 cm, one cell: its top face two triangles) on the floor; a ridge along y over the
    // middle of its top face, between its vertices, 0.5 mm above it, comes down at 2 cm/s for
    // 0.2 s: 3.5 mm into where the face was. With the vertices' barrier alone it cut in that far.
    const std::string kind = GENERATE(as<std::string>{}, "wedge", "box edge");
    BlockSettings settings;
    settings.terms = body_contact_term_maker();  // the obstacles' edges and corners too
    settings.height = 1e-4;
    const double top = settings.height + settings.edge, gap = 5e-4, speed = 0.02;
    const Eigen::Vector3d down(0.0, 0.0, -speed);
    std::shared_ptr<const Obstacle> knife;
    if (kind == "wedge") {
        knife = wedge(top + gap, down);
    } else {
        // A box turned 45° about y: its lowest edge the line x = 0.05, z = top + gap along y.
        const Eigen::Matrix3d turn = Eigen::AngleAxisd(std::acos(-1.0) / 4.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
        knife = std::make_shared<Box>(Eigen::Vector3d(0.05, 0.05, top + gap + 0.05 * std::sqrt(2.0)),
                                      Eigen::Vector3d(0.05, 0.15, 0.05), turn, 0.0, down);
    }
    settings.obstacles = {std::make_shared<HalfSpace>(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()), knife};
    BlockScene block = block_scene(settings);
    const ObstacleFeatures features = knife->local_features();
    REQUIRE(features.edges.rows() > 0);
    for (int step = 0; step < 20; ++step) {
        block.step();
        INFO(kind << ", step " << step + 1);
        REQUIRE(block.contact->smallest_distance(block.state.u) > 0.0);
        REQUIRE_FALSE(edge_inside_body(*block.body, block.state.u, features, block.state.time * down));
    }
    // The block carries the press: its top vertices pushed down with the ridge (edge_inside_body
    // says the face was not cut instead), 5 cm beside it.
    const MatrixX3d x = block.body->positions(block.state.u);
    const double ridge = top + gap - speed * block.state.time;
    double highest = -1.0;
    for (Eigen::Index v = 0; v < x.rows(); ++v)
        highest = std::max(highest, x(v, 2));
    INFO(kind << ": ridge at " << ridge << " m, the block's highest vertex at " << highest << " m");
    CHECK(highest < top - 3e-3);
}

TEST_CASE("continuous collision: no point of a randomised safe step is inside any obstacle (fuzzed)", "[ex15.4]")
{
    BlockSettings settings;
    settings.height = 0.0;
    BlockScene block = block_scene(settings);
    // Around the block [0, 0.1]³ moved by up to 0.2: a tilted floor below, a ball and a turned box
    // beside it, which random steps of up to 2 m cross.
    const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, -1.0, 2.0).normalized()).toRotationMatrix();
    const std::vector<std::shared_ptr<const Obstacle>> obstacles{
        std::make_shared<HalfSpace>(Eigen::Vector3d(0.0, 0.0, -0.3), Eigen::Vector3d(0.2, 0.1, 1.0)),
        std::make_shared<Sphere>(Eigen::Vector3d(0.55, 0.05, 0.05), 0.2),
        std::make_shared<Box>(Eigen::Vector3d(-0.5, 0.05, 0.05), Eigen::Vector3d(0.15, 0.2, 0.1), rotation)};
    ContactPotential contact = body_contact_potential(*block.body, obstacles);
    const Eigen::Index n = block.state.u.size();
    int checked = 0, cut = 0;
    for (unsigned seed = 1; seed <= 300; ++seed) {
        const Eigen::VectorXd u = 0.2 * random_vector(n, seed);
        if (!std::isfinite(contact.energy(u)) || contact.smallest_distance(u) <= 0.0)
            continue;
        const Eigen::VectorXd du = 2.0 * random_vector(n, 5000 + seed);
        const double alpha = contact.largest_safe_step(u, du);
        REQUIRE(alpha > 0.0);
        REQUIRE(alpha <= 1.0);
        cut += alpha < 1.0;
        for (int k = 1; k <= 50; ++k) {  // along the whole segment, not only at its end
            const Eigen::VectorXd trial = u + (alpha * k / 50.0) * du;
            INFO("seed " << seed << ", alpha " << alpha << ", k " << k);
            CHECK(contact.smallest_distance(trial) > 0.0);
        }
        ++checked;
    }
    CHECK(checked > 50);
    CHECK(cut > 20);  // the fuzz reaches the cut, not only free steps
}

TEST_CASE("contact potential on a mesh: the barriers summed over the triangles within dhat, against central "
          "differences", "[ex15.2]")
{
    // A shallow four-sided dimple under the corner (0, 0, 0.0002): its lowest vertex right under
    // it, its rim 4 cm away 0.1 mm higher. The corner feels all four triangles (faces, edges and
    // the vertex compete within d̂): the sum of their barriers is what P holds.
    TriMesh dimple;
    dimple.V.resize(5, 3);
    dimple.V << 0.0, 0.0, 0.0, 0.04, 0.0, 1e-4, 0.0, 0.04, 1e-4, -0.04, 0.0, 1e-4, 0.0, -0.04, 1e-4;
    dimple.F.resize(4, 3);
    dimple.F << 0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1;
    const std::vector<std::shared_ptr<const Obstacle>> obstacles{std::make_shared<MeshObstacle>(dimple, 0.4)};
    std::vector<DistancePiece> felt;
    obstacles[0]->pieces(Eigen::Vector3d(0.0, 0.0, 2e-4), 0.0, ContactOptions{}.activation_distance, felt);
    REQUIRE(felt.size() == 4);
    // The dimple's corners and edges add pairs that span the face's vertices (FeatureTerm).
    test::check_contact_derivatives("mesh", obstacles, body_contact_term_maker(), true);
}
