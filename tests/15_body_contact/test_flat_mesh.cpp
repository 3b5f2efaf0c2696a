// Chapter 15: a flat region of a mesh obstacle holds a body as a plane does — over it a point feels
// one barrier, the plane's, with no lateral push from the triangles next to the one it stands over;
// the barriers' sum stays continuous across flat edges, over flat corners, round the region's
// border, across two triangles folded by less than the flat test's angle and round every vertex of
// the bowl (its quads split in coplanar pairs); a block at rest on a flat mesh floor stays where it stands, as on the half-space, and one
// that sticks to a tilted one creeps as on the half-space. docs/15_body_contact.md#mesh-obstacles
#include "15_body_contact/body_contact.hpp"
#include "14_contact/barrier.hpp"
#include "14_contact/contact_scenes.hpp"
#include "15_body_contact/mesh_obstacle.hpp"
#include "14_contact/obstacles.hpp"
#include "../14_contact/slope_creep.hpp"

#include "common/files.hpp"
#include "common/mesh.hpp"
#include "common/mesh_io.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

using namespace fem;
using namespace fem::contact;
using fem::test::degree;

namespace {

/// The plane z = 0 as a mesh: square_mesh(cells, jitter) scaled to side × side, turned by `angle`
/// about z and moved so that its vertex `vertex` stands at `at` [m].
TriMesh flat_floor(int cells, double jitter, double side, double angle, int vertex, const Eigen::Vector2d& at)
{
    TriMesh floor = square_mesh(cells, jitter);
    const Eigen::Matrix2d turn = side * Eigen::Rotation2Dd(angle).toRotationMatrix();
    const Eigen::Vector2d shift = at - turn * floor.V.row(vertex).head<2>().transpose();
    for (Eigen::Index v = 0; v < floor.V.rows(); ++v)
        floor.V.row(v).head<2>() = (turn * floor.V.row(v).head<2>().transpose() + shift).transpose();
    return floor;
}

/// The middle vertex of square_mesh(cells) (cells even).
int middle_vertex(int cells)
{
    return cells / 2 * (cells + 2);
}

/// Where the flat floors put a vertex: 0.36 mm beside the corner (0.1, 0.1) of the block's base
/// (BlockSettings' 0.1 m cube at the corner (0, 0)), within d̂ of it [m].
const Eigen::Vector2d beside_block(0.1 + 3e-4, 0.1 - 2e-4);

/// The barrier κ Σ b(dᵢ) over the pieces a point p sees within d̂, with its gradient and Hessian
/// from the pieces' (Σ κ b'ᵢ gᵢ, Σ κ (b''ᵢ gᵢ gᵢᵀ + b'ᵢ Hᵢ)), and how many pieces there are.
struct PointBarrier {
    double energy = 0.0;
    Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
    Eigen::Matrix3d hessian = Eigen::Matrix3d::Zero();
    int pieces = 0;
};

constexpr double dhat = 1e-3, kappa = 1e4;

PointBarrier point_barrier(const Obstacle& obstacle, const Eigen::Vector3d& p)
{
    std::vector<DistancePiece> pieces;
    obstacle.local_pieces(p, dhat, pieces);
    PointBarrier sum;
    sum.pieces = static_cast<int>(pieces.size());
    for (const DistancePiece& piece : pieces) {
        const BarrierValue b = barrier(piece.distance, dhat);
        sum.energy += kappa * b.value;
        sum.gradient += kappa * b.first * piece.gradient;
        sum.hessian += kappa * (b.second * piece.gradient * piece.gradient.transpose() + b.first * piece.hessian);
    }
    return sum;
}

/// The most the energy changes between two neighbouring points of a path, over what the larger of
/// their gradients allows along the step (a continuous energy stays near or below 1; a barrier
/// counted twice or dropped on one side of a line jumps by b(d), many times that).
double worst_jump(const Obstacle& obstacle, const std::vector<Eigen::Vector3d>& path)
{
    double worst = 0.0;
    PointBarrier last = point_barrier(obstacle, path[0]);
    for (std::size_t k = 1; k < path.size(); ++k) {
        const PointBarrier next = point_barrier(obstacle, path[k]);
        const double allowed = (path[k] - path[k - 1]).norm() * std::max(last.gradient.norm(), next.gradient.norm());
        worst = std::max(worst, std::abs(next.energy - last.energy) / (allowed + 1e-12 * kappa));
        last = next;
    }
    return worst;
}

/// A straight path of n + 1 points from a to b.
std::vector<Eigen::Vector3d> segment_path(const Eigen::Vector3d& a, const Eigen::Vector3d& b, int n)
{
    std::vector<Eigen::Vector3d> path;
    for (int k = 0; k <= n; ++k)
        path.push_back(a + (b - a) * (double(k) / n));
    return path;
}

/// The 1 m floor of 200 jittered triangles (some obtuse) turned by 17°, its middle vertex beside
/// the block's corner.
struct JitteredFloor {
    MeshObstacle mesh{flat_floor(10, 0.2, 1.0, 17.0 * degree, middle_vertex(10), beside_block)};
    Eigen::Vector3d middle = mesh.surface().V.row(middle_vertex(10)).transpose();
};

}  // namespace

TEST_CASE("flat mesh: over a flat edge and a flat vertex a point feels the plane's one barrier, continuous and with "
          "derivatives that central differences confirm", "[ex15.1]")
{
    const JitteredFloor floor;
    const HalfSpace plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
    const TriMesh& s = floor.mesh.surface();
    const double height = 4e-4;
    const Eigen::Vector3d up = height * Eigen::Vector3d::UnitZ();
    // Paths across an edge at the middle vertex (through its midpoint, then exactly through its
    // end), through the vertex and passing it by 10⁻⁵ m; each from 2 mm before to 2 mm past.
    std::vector<std::vector<Eigen::Vector3d>> paths;
    for (Eigen::Index f = 0; f < s.F.rows(); ++f)
        for (int i = 0; i < 3; ++i)
            if (s.F(f, i) == middle_vertex(10) && paths.size() < 6) {
                const Eigen::Vector3d a = floor.middle, b = s.V.row(s.F(f, (i + 1) % 3)).transpose();
                const Eigen::Vector3d across = Eigen::Vector3d::UnitZ().cross(b - a).normalized();
                const Eigen::Vector3d mid = 0.5 * (a + b) + up;
                paths.push_back(segment_path(mid - 2e-3 * across, mid + 2e-3 * across, 4000));
                paths.push_back(segment_path(a + up - 2e-3 * across, a + up + 2e-3 * across, 4000));
                const Eigen::Vector3d by = 1e-5 * (b - a).normalized();
                paths.push_back(segment_path(a + up + by - 2e-3 * across, a + up + by + 2e-3 * across, 4000));
            }
    REQUIRE(paths.size() == 6);
    for (const std::vector<Eigen::Vector3d>& path : paths) {
        for (const Eigen::Vector3d& p : path) {
            const PointBarrier mesh = point_barrier(floor.mesh, p), half = point_barrier(plane, p);
            INFO("at " << p.transpose() << ": " << mesh.pieces << " pieces");
            REQUIRE(mesh.pieces == 1);
            REQUIRE(std::abs(mesh.energy - half.energy) <= 1e-12 * half.energy);
            REQUIRE((mesh.gradient - half.gradient).norm() <= 1e-12 * half.gradient.norm());
        }
        CHECK(worst_jump(floor.mesh, path) <= 1.01);
    }

    // Central differences of the pieces' sum at points near the flat edges and vertices, some over
    // the floor and some off its border, within d̂ of it.
    int checked = 0;
    for (unsigned seed = 1; seed <= 400; ++seed) {
        const Eigen::Index f = static_cast<Eigen::Index>(seed * 7919u % s.F.rows());
        const Eigen::Vector3d a = s.V.row(s.F(f, 0)), b = s.V.row(s.F(f, 1));
        const double t = (seed % 3 == 0) ? 0.0 : 0.37 * (seed % 5) / 4.0;  // a corner or along the edge
        const Eigen::Vector3d p = a + t * (b - a) + 1e-3 * Eigen::Vector3d(std::cos(seed * 2.1), std::sin(seed * 2.1), 0.0) * 0.6 +
                                  Eigen::Vector3d(0.0, 0.0, 3e-4 + 1e-4 * (seed % 4));
        const PointBarrier at = point_barrier(floor.mesh, p);
        if (at.pieces == 0)
            continue;
        const double h = 1e-8;
        Eigen::Vector3d energy_fd;
        Eigen::Matrix3d hessian_fd;
        for (int i = 0; i < 3; ++i) {
            const Eigen::Vector3d e = h * Eigen::Vector3d::Unit(i);
            const PointBarrier plus = point_barrier(floor.mesh, p + e), minus = point_barrier(floor.mesh, p - e);
            energy_fd[i] = (plus.energy - minus.energy) / (2.0 * h);
            hessian_fd.col(i) = (plus.gradient - minus.gradient) / (2.0 * h);
        }
        INFO("seed " << seed << " at " << p.transpose() << ", " << at.pieces << " pieces");
        CHECK((at.gradient - energy_fd).norm() <= 1e-6 * at.gradient.norm());
        CHECK((at.hessian - hessian_fd).norm() <= 1e-5 * (1.0 + at.hessian.norm()));
        ++checked;
    }
    CHECK(checked > 300);
}

TEST_CASE("flat mesh: round a corner of the floor's border and along its edges the barriers' sum stays continuous",
          "[ex15.1]")
{
    const JitteredFloor floor;
    const TriMesh& s = floor.mesh.surface();
    // A circle of radius 0.5 mm, 0.2 mm up, round each corner of the square (one triangle there, or
    // two meeting at a flat edge), and one round a border vertex between two corners.
    for (const int vertex : {0, 10, 120, 110, 5}) {  // square_mesh(10)'s corners and a middle of a side
        const Eigen::Vector3d centre = s.V.row(vertex).transpose() + 2e-4 * Eigen::Vector3d::UnitZ();
        std::vector<Eigen::Vector3d> circle;
        for (int k = 0; k <= 20000; ++k) {
            const double phi = 2.0 * std::numbers::pi * k / 20000.0;
            circle.push_back(centre + 5e-4 * Eigen::Vector3d(std::cos(phi), std::sin(phi), 0.0));
        }
        INFO("round vertex " << vertex);
        CHECK(worst_jump(floor.mesh, circle) <= 1.01);
    }
}

TEST_CASE("flat mesh: two triangles folded by less than the flat test's angle, either way, keep the sum continuous "
          "across their edge", "[ex15.1]")
{
    for (const double fold : {5e-4, -5e-4}) {  // the sine of the angle: a valley (seen from +z) and a ridge
        TriMesh folded;
        folded.V.resize(4, 3);
        folded.V << 0.0, -0.5, 0.0,  //
            0.0, 0.5, 0.0,           //
            -0.5, 0.0, 0.5 * fold,   //
            0.5, 0.0, 0.5 * fold;
        folded.F.resize(2, 3);
        folded.F << 0, 1, 2,  //
            1, 0, 3;
        const MeshObstacle mesh(folded);
        REQUIRE(mesh.local_features().edges.rows() == 4);  // the border only: the fold passes as flat
        const Eigen::Vector3d up(0.0, 0.0, 4e-4);
        INFO("fold " << fold);
        CHECK(worst_jump(mesh, segment_path(up - Eigen::Vector3d(2e-3, 0.0, 0.0), up + Eigen::Vector3d(2e-3, 0.0, 0.0),
                                            40000)) <= 1.01);
    }
}

TEST_CASE("flat mesh: in the bowl, whose quads are split into coplanar pairs between creases, the barriers' sum stays "
          "continuous round every vertex", "[ex15.1]")
{
    const MeshObstacle bowl(io::read_tri_mesh(data_path("bowl.obj")));
    const TriMesh& s = bowl.surface();
    Eigen::MatrixX3d normals = Eigen::MatrixX3d::Zero(s.V.rows(), 3);  // area-weighted, at the vertices
    for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
        const Eigen::Vector3d a = s.V.row(s.F(f, 0)), b = s.V.row(s.F(f, 1)), c = s.V.row(s.F(f, 2));
        for (int k = 0; k < 3; ++k)
            normals.row(s.F(f, k)) += (b - a).cross(c - a).transpose();
    }
    double worst = 0.0;
    for (Eigen::Index v = 0; v < s.V.rows(); v += 7) {
        const Eigen::Vector3d n = normals.row(v).normalized();
        const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
        for (const double side : {2e-4, -2e-4}) {  // inside the bowl and under it
            std::vector<Eigen::Vector3d> circle;
            for (int k = 0; k <= 4000; ++k) {
                const double phi = 2.0 * std::numbers::pi * k / 4000.0;
                circle.push_back(s.V.row(v).transpose() + side * n + 5e-4 * (std::cos(phi) * t1 + std::sin(phi) * t2));
            }
            worst = std::max(worst, worst_jump(bowl, circle));
        }
    }
    INFO("the largest jump between neighbouring samples over what the gradient allows: " << worst);
    CHECK(worst <= 1.01);
}

TEST_CASE("flat mesh: a block at rest on a floor of 2 or 200 triangles stays where it stands, as on the half-space",
          "[ex15.4]")
{
    BlockSettings settings;
    settings.terms = body_contact_term_maker();  // the obstacles' edges and corners too
    settings.time_step = 1.0 / 100.0;
    const int steps = 200;  // 2 s
    Eigen::VectorXd masses;  // per degree of freedom
    const auto run = [&](const std::shared_ptr<const Obstacle>& floor) {
        BlockSettings these = settings;
        if (floor)
            these.obstacles = {floor};
        BlockScene block = block_scene(these);
        masses = block.body->dof_masses();
        std::vector<Eigen::VectorXd> states;
        for (int step = 0; step < steps; ++step) {
            block.step();
            states.push_back(block.state.u);
        }
        return states;
    };
    const std::vector<Eigen::VectorXd> half = run(nullptr);
    // Two triangles whose diagonal, at 50°, passes 0.36 mm beside the block's corner (0.1, 0.1); 200
    // jittered ones turned by 17° with a vertex there.
    const double diagonal = 50.0 * degree;
    const std::vector<std::shared_ptr<const Obstacle>> floors{
        std::make_shared<MeshObstacle>(flat_floor(1, 0.0, 1.2, diagonal - 45.0 * degree, 0,
                                                  beside_block - 0.8 * Eigen::Vector2d(std::cos(diagonal), std::sin(diagonal)))),
        std::make_shared<MeshObstacle>(JitteredFloor().mesh)};
    for (const auto& floor : floors) {
        const std::vector<Eigen::VectorXd> states = run(floor);
        // Horizontally: each vertex from where the half-space's run has it (the block spreads a little
        // under its weight, as Poisson says, on both), and the centre of mass from its start (no
        // horizontal force, no horizontal momentum).
        double apart = 0.0, drift = 0.0;
        for (int step = 0; step < steps; ++step) {
            Eigen::Vector2d moment = Eigen::Vector2d::Zero();
            for (Eigen::Index v = 0; v < states[step].size() / 3; ++v) {
                apart = std::max(apart, (states[step] - half[step]).segment<2>(3 * v).norm());
                moment += masses[3 * v] * states[step].segment<2>(3 * v);
            }
            drift = std::max(drift, moment.norm() / (masses.sum() / 3.0));
        }
        INFO(floor->name() << " of " << dynamic_cast<const MeshObstacle&>(*floor).surface().F.rows()
                           << " triangles: the vertices at most " << apart << " m from the half-space's, the centre "
                           << "of mass " << drift << " m from the start");
        CHECK(apart <= 1e-9);
        CHECK(drift <= 1e-9);
    }
}

TEST_CASE("flat mesh: a block sticking to a tilted floor of 1 m or 10 m of triangles creeps as on the half-space",
          "[ex15.4]")
{
    BlockSettings settings;
    settings.terms = body_contact_term_maker();  // the obstacles' edges and corners too
    settings.slope = 20.0 * degree;
    settings.friction = 0.5;
    settings.height = 0.5 * settings.contact.activation_distance;
    const int steps = 40;
    const double half = test::slope_creep(settings, steps).last;
    for (const auto& [side, cells] : std::vector<std::pair<double, int>>{{1.0, 10}, {10.0, 40}}) {
        BlockSettings on_mesh = settings;
        on_mesh.obstacles = {std::make_shared<MeshObstacle>(
            flat_floor(cells, 0.2, side, 17.0 * degree, middle_vertex(cells), beside_block), settings.friction)};
        const double creep = test::slope_creep(on_mesh, steps).last;
        INFO(side << " m of " << 2 * cells * cells << " triangles: creep " << creep << " m a step, on the half-space "
                  << half << " m, closed form " << test::expected_creep(settings) << " m");
        CHECK(std::abs(creep - half) <= 0.01 * half);
    }
}

