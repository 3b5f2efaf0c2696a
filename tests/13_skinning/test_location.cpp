// Chapter 13: barycentric weights and the three point-location methods, against chapter 04's
// shape functions and against each other on every vertex of the bunny and on points exactly on
// vertices, edges and faces and just outside. docs/13_skinning.md
#include "13_skinning/skinning.hpp"

#include "04_tet_jacobians/tet_jacobians.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh_io.hpp"
#include "common/random.hpp"

#include "../common/bunny_meshes.hpp"
#include "../common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <memory>
#include <vector>

using namespace fem;
using namespace fem::skin;
using fem::test::bunny_surface;
using fem::test::bunny_tets;
using fem::test::EntriesNear;
using fem::test::entries_of;

namespace {

/// Points exactly on the mesh's vertices, on the midpoints of the edges and the centroids of the
/// faces of every k-th tet, and the tets' centroids.
std::vector<Eigen::Vector3d> special_points(const TetMesh& mesh, int every)
{
    std::vector<Eigen::Vector3d> points;
    for (Eigen::Index v = 0; v < mesh.V.rows(); v += every)
        points.push_back(mesh.V.row(v).transpose());
    for (Eigen::Index t = 0; t < mesh.T.rows(); t += every) {
        const tet::TetVertices X = tet::tet_vertices(mesh, mesh.V, static_cast<int>(t));
        for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j) {
                points.push_back(0.5 * (X.row(i) + X.row(j)).transpose());
                for (int k = j + 1; k < 4; ++k)
                    points.push_back((X.row(i) + X.row(j) + X.row(k)).transpose() / 3.0);
            }
        points.push_back(X.colwise().mean().transpose());
    }
    return points;
}

/// Checks that every point is found by the locator in the same tet as by brute force, and that
/// the tet holds it: weights ≥ −tolerance that reproduce the point.
void check_against_brute_force(const BarycentricFrames& frames, const PointLocator& locator,
                               const std::vector<Eigen::Vector3d>& points, double tolerance)
{
    int differ = 0, wrong = 0, missing = 0;
    for (const Eigen::Vector3d& p : points) {
        const Location reference = locate_brute_force(frames, p, tolerance);
        const Location found = locator.locate(p);
        missing += found.tet < 0;
        differ += found.tet != reference.tet;
        if (found.tet >= 0) {
            const tet::TetVertices X = tet::tet_vertices(frames.mesh(), frames.mesh().V, found.tet);
            wrong += !(found.phi.minCoeff() >= -tolerance) || (X.transpose() * found.phi - p).norm() > 1e-12 * (1.0 + p.norm());
        }
    }
    INFO(points.size() << " points, method " << method_name(locator.method()));
    CHECK(missing == 0);
    CHECK(differ == 0);
    CHECK(wrong == 0);
}

}  // namespace

TEST_CASE("barycentric weights: chapter 04's shape functions, summing to 1, reproducing the point", "[ex13.1]")
{
    const TetMesh mesh = bunny_tets();
    const BarycentricFrames frames(mesh);
    for (int t = 0; t < mesh.T.rows(); t += 97) {
        const tet::TetVertices X = tet::tet_vertices(mesh, mesh.V, t);
        for (unsigned seed = 1; seed <= 3; ++seed) {
            const Eigen::Vector3d p = X.colwise().mean().transpose() + 3.0 * Eigen::Vector3d(random_vector(3, seed + t));
            const Eigen::Vector4d phi = frames.weights(t, p);
            CHECK_THAT(entries_of(phi), EntriesNear(tet::shape_functions(X, p), 1e-11));
            CHECK(phi.sum() == Approx(1.0).margin(1e-13));
            CHECK_THAT(entries_of(Eigen::Vector3d(X.transpose() * phi)), EntriesNear(p, 1e-11));
        }
        for (int i = 0; i < 4; ++i)  // corner i has φ = e_i
            CHECK_THAT(entries_of(frames.weights(t, X.row(i).transpose())),
                       EntriesNear(Eigen::Vector4d::Unit(i), 1e-12));
    }
}

namespace {

/// Every vertex of the bunny and the special points of TetGen's tets: the brute force's tet.
void check_on_bunny(const BarycentricFrames& frames, const PointLocator& locator, double tolerance)
{
    const TriMesh surface = bunny_surface();
    std::vector<Eigen::Vector3d> points;
    for (Eigen::Index v = 0; v < surface.V.rows(); ++v)
        points.push_back(surface.V.row(v).transpose());
    check_against_brute_force(frames, locator, points, tolerance);
    check_against_brute_force(frames, locator, special_points(frames.mesh(), 29), tolerance);
}

}  // namespace

TEST_CASE("point location by a uniform grid: the brute force's tet for the bunny and for points on vertices, edges, faces",
          "[ex13.2]")
{
    const BarycentricFrames frames(bunny_tets());
    const UniformGrid grid(frames, 1e-9);
    check_on_bunny(frames, grid, 1e-9);
    CHECK(grid.mean_tets_per_cell() > 0.0);
}

TEST_CASE("point location by an AABB tree: the brute force's tet for the bunny and for points on vertices, edges, faces",
          "[ex13.3]")
{
    const BarycentricFrames frames(bunny_tets());
    const AabbTree tree(frames, 1e-9);
    check_on_bunny(frames, tree, 1e-9);
    CHECK(tree.depth() <= 20);
}

namespace {

/// Points just outside boundary faces (on the outward normal through the face centroid) at
/// `fraction` of the height of the face's tet over it: with tolerance τ, inside for fraction < τ.
std::vector<Eigen::Vector3d> beyond_faces(const TetMesh& mesh, double fraction)
{
    const Boundary boundary = boundary_faces(mesh);
    std::vector<Eigen::Vector3d> points;
    for (Eigen::Index f = 0; f < boundary.faces.rows(); f += 11) {
        const Eigen::Vector3d a = mesh.V.row(boundary.faces(f, 0)), b = mesh.V.row(boundary.faces(f, 1)),
                              c = mesh.V.row(boundary.faces(f, 2));
        const Eigen::Vector3d normal = (b - a).cross(c - a).normalized();
        const int t = boundary.tet[f];
        const double height = std::abs(6.0 * tet::signed_volume(tet::tet_vertices(mesh, mesh.V, t))) / (b - a).cross(c - a).norm();
        points.push_back((a + b + c) / 3.0 + fraction * height * normal);
    }
    return points;
}

}  // namespace

namespace {

/// Beyond the tolerance the locator finds no tet (nor does brute force); within it, the face's tet.
void check_just_outside(const BarycentricFrames& frames, const PointLocator& locator, double tolerance)
{
    for (const Eigen::Vector3d& p : beyond_faces(frames.mesh(), 3.0 * tolerance)) {
        CHECK(locate_brute_force(frames, p, tolerance).tet == -1);
        CHECK(locator.locate(p).tet == -1);
    }
    check_against_brute_force(frames, locator, beyond_faces(frames.mesh(), 0.25 * tolerance), tolerance);
}

}  // namespace

TEST_CASE("points just outside, by the grid: none beyond the tolerance, the face's tet within it", "[ex13.2]")
{
    const BarycentricFrames frames(bunny_tets());
    check_just_outside(frames, UniformGrid(frames, 1e-3), 1e-3);
}

TEST_CASE("points just outside, by the tree: none beyond the tolerance, the face's tet within it", "[ex13.3]")
{
    const BarycentricFrames frames(bunny_tets());
    check_just_outside(frames, AabbTree(frames, 1e-3), 1e-3);
}

namespace {

/// One tet with the given corners.
TetMesh one_tet(const Eigen::Matrix<double, 4, 3>& corners)
{
    TetMesh mesh;
    mesh.V = corners;
    mesh.T.resize(1, 4);
    mesh.T << 0, 1, 2, 3;
    return mesh;
}

/// The admitted set {φᵢ ≥ −τ} of a tet is the tet scaled by 1 + 4τ about its centroid c: the point
/// Xᵢ + 4τ·reach·(Xᵢ − c) beyond corner i has φᵢ = 1 + 3τ·reach and the other three −τ·reach, so it
/// is admitted for reach ≤ 1 and not beyond. Returns these points for every corner of every k-th tet.
std::vector<Eigen::Vector3d> beyond_corners(const TetMesh& mesh, double tolerance, double reach, int every)
{
    std::vector<Eigen::Vector3d> points;
    for (Eigen::Index t = 0; t < mesh.T.rows(); t += every) {
        const tet::TetVertices X = tet::tet_vertices(mesh, mesh.V, static_cast<int>(t));
        const Eigen::RowVector3d c = X.colwise().mean();
        for (int i = 0; i < 4; ++i)
            points.push_back((X.row(i) + 4.0 * tolerance * reach * (X.row(i) - c)).transpose());
    }
    return points;
}

/// How far p lies outside tet t's (unpadded) box, in units of τ × its longest edge: the padding
/// the box tests need for p.
double padding_needed(const BarycentricFrames& frames, int t, const Eigen::Vector3d& p, double tolerance)
{
    const Eigen::Matrix<double, 2, 3> box = frames.box(t);
    const double outside = std::max({0.0, (box.row(0).transpose() - p).maxCoeff(), (p - box.row(1).transpose()).maxCoeff()});
    return outside / (tolerance * frames.longest_edge(t));
}

/// Points just inside the admitted set beyond the corners of single tets (a right-angled corner tet,
/// a needle, a sliver-like flat one) and of every 13th tet of the bunny: the locator finds the tet
/// brute force finds; just outside it, none is found in the single tets. A box padded by τ × the
/// longest edge (instead of 3τ) misses them: the needle's points need 2.9τ.
void check_beyond_corners(LocateMethod method)
{
    const double tolerance = 0.1;
    const double inside = 1.0 - 1e-9, outside = 1.0 + 1e-6;
    Eigen::Matrix<double, 4, 3> corner, needle, flat;
    corner << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
    needle << 1, 0, 0, 0, 0, 0, 0, 0, 0.1, 0, 0.1, 0;
    flat << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0.4, 0.4, 0.05;
    for (const Eigen::Matrix<double, 4, 3>* tet : {&corner, &needle, &flat}) {
        const BarycentricFrames frames(one_tet(*tet));
        const std::unique_ptr<PointLocator> locator = make_locator(method, frames, tolerance);
        const std::vector<Eigen::Vector3d> admitted = beyond_corners(frames.mesh(), tolerance, inside, 1);
        double needed = 0.0;
        for (const Eigen::Vector3d& p : admitted) {
            REQUIRE(locate_brute_force(frames, p, tolerance).tet == 0);  // the geometry above, independently
            needed = std::max(needed, padding_needed(frames, 0, p, tolerance));
        }
        INFO("tet corners\n" << *tet << "\nthe points need a box padded by " << needed
             << " x tolerance x longest edge; a locator that misses them pads its boxes by less (the admitted "
                "set is the tet scaled by 1 + 4 tolerance about its centroid: up to 3 tolerance x longest edge "
                "beyond a corner, docs/13_skinning.md#point-location)");
        CHECK(needed > 1.0);  // these points are the ones a padding of τ × the longest edge misses
        check_against_brute_force(frames, *locator, admitted, tolerance);
        for (const Eigen::Vector3d& p : beyond_corners(frames.mesh(), tolerance, outside, 1)) {
            CHECK(locate_brute_force(frames, p, tolerance).tet == -1);
            CHECK(locator->locate(p).tet == -1);
        }
        if (tet == &needle)
            CHECK(needed > 2.9);
    }
    const BarycentricFrames bunny_frames(bunny_tets());
    check_against_brute_force(bunny_frames, *make_locator(method, bunny_frames, tolerance),
                              beyond_corners(bunny_frames.mesh(), tolerance, inside, 13), tolerance);
}

}  // namespace

TEST_CASE("points just inside the tolerance beyond a corner, by the grid: the brute force's tet (boxes padded by 3 tolerance x longest edge)",
          "[ex13.2]")
{
    check_beyond_corners(LocateMethod::grid);
}

TEST_CASE("points just inside the tolerance beyond a corner, by the tree: the brute force's tet (boxes padded by 3 tolerance x longest edge)",
          "[ex13.3]")
{
    check_beyond_corners(LocateMethod::tree);
}

TEST_CASE("the coarse lattice encloses the bunny: every vertex inside, brute force and chapter 04 agree", "[ex13.1]")
{
    const TriMesh surface = bunny_surface();
    const TetMesh lattice = enclosing_lattice(surface, 6);
    const BarycentricFrames frames(lattice, "lattice");
    for (Eigen::Index v = 0; v < surface.V.rows(); ++v)
        REQUIRE(locate_brute_force(frames, surface.V.row(v).transpose(), 0.0).tet >= 0);
    // Every point of every triangle lies in a kept cube: so do the vertices of the refined surface.
    const TriMesh refined = midpoint_subdivision(surface, 2);
    int outside = 0;
    for (Eigen::Index v = surface.V.rows(); v < refined.V.rows(); ++v)
        outside += locate_brute_force(frames, refined.V.row(v).transpose(), 0.0).tet < 0;
    CHECK(outside == 0);
    for (Eigen::Index v = 0; v < surface.V.rows(); v += 50) {
        const Eigen::Vector3d p = surface.V.row(v).transpose();
        const tet::PointLocation chapter04 = tet::locate_point(lattice, p, 1e-9);
        CHECK(chapter04.inside);
        CHECK(chapter04.tet == locate_brute_force(frames, p, 1e-9).tet);
    }
}

TEST_CASE("the lattice and the subdivided surface: the shapes the docs promise", "[ch13]")
{
    const TriMesh surface = bunny_surface();
    const TetMesh lattice = enclosing_lattice(surface, 6);
    CHECK(total_volume(lattice) > 0.0);
    CHECK(lattice.T.rows() % 6 == 0);
    // The lattice holds the surface's box.
    for (int c = 0; c < 3; ++c) {
        CHECK(lattice.V.col(c).minCoeff() <= surface.V.col(c).minCoeff());
        CHECK(lattice.V.col(c).maxCoeff() >= surface.V.col(c).maxCoeff());
    }
    // The winding number is 1 at the bunny's centre of mass region and 0 far away.
    CHECK(winding_number(surface, Eigen::Vector3d(100.0, 0.0, 0.0)) == Approx(0.0).margin(1e-9));
    CHECK(winding_number(surface, surface.V.colwise().mean().transpose()) == Approx(1.0).margin(1e-9));
    // Midpoint subdivision: V + E vertices (E = 3F/2 on a closed surface), 4F triangles, the same area.
    const TriMesh refined = midpoint_subdivision(surface, 1);
    CHECK(refined.F.rows() == 4 * surface.F.rows());
    CHECK(refined.V.rows() == surface.V.rows() + 3 * surface.F.rows() / 2);
    const auto area = [](const TriMesh& m) {
        double a = 0.0;
        for (Eigen::Index f = 0; f < m.F.rows(); ++f)
            a += 0.5 * (m.V.row(m.F(f, 1)) - m.V.row(m.F(f, 0))).cross(m.V.row(m.F(f, 2)) - m.V.row(m.F(f, 0))).norm();
        return a;
    };
    CHECK(area(refined) == Approx(area(surface)).epsilon(1e-12));
}

TEST_CASE("bad locator options: a tolerance outside 0 to 0.5 is refused", "[ch13]")
{
    const TetMesh mesh = box_mesh(1, 1, 1);
    const BarycentricFrames frames(mesh);
    CHECK_THROWS_AS(UniformGrid(frames, -1e-3), Error);
    CHECK_THROWS_AS(AabbTree(frames, 0.5), Error);
    CHECK_THROWS_AS(BruteForce(frames, std::nan("")), Error);
    CHECK_THROWS_AS(AabbTree(frames, 1e-9, 0), Error);
    CHECK_THROWS_WITH(parse_method("octree"), Catch::Matchers::Contains("brute-force, grid or tree"));
}
