// Chapter 13: the skinning matrix W, the skinned product x = W Q, the outside rule, normals and bad
// input, against known answers: partition of unity, exact rest and affine reproduction, a
// quadratic field's O(h²) interpolation error, distances to a cube, Eigen's sparse product.
// docs/13_skinning.md
#include "13_skinning/skinning.hpp"

#include "11_corotational/corotational.hpp"

#include "10_linear_dynamics/time_integration.hpp"

#include "07_sparse_storage/sparse_formats.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh_io.hpp"
#include "common/random.hpp"

#include "../common/bunny_meshes.hpp"
#include "../common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <Eigen/SparseCore>

#include <cmath>
#include <limits>
#include <vector>

using namespace fem;
using namespace fem::skin;
using Catch::Matchers::Contains;
using fem::test::bunny_surface;
using fem::test::bunny_tets;
using fem::test::EntriesNear;
using fem::test::entries_of;

namespace {

/// x = W Q by Eigen's sparse product (an independent route to the skinned positions).
MatrixX3d eigen_product(const sparse::CsrMatrix& W, const MatrixX3d& Q)
{
    const Eigen::SparseMatrix<double> W_eigen = sparse::to_eigen(W);
    return W_eigen * Q;
}

/// The affine map x ↦ A x + b of the tests.
MatrixX3d affine(const MatrixX3d& X)
{
    Eigen::Matrix3d A;
    A << 1.3, -0.4, 0.2, 0.5, 0.8, -0.6, 0.1, 0.7, 1.1;
    return (X * A.transpose()).rowwise() + Eigen::RowVector3d(2.0, -1.0, 0.5);
}

/// The first `count` triangles of a surface and the vertices they use (renumbered in order).
TriMesh first_triangles(const TriMesh& surface, Eigen::Index count)
{
    std::vector<int> renumber(surface.V.rows(), -1);
    std::vector<Eigen::Index> kept;
    TriMesh part;
    part.F = surface.F.topRows(count);
    for (Eigen::Index f = 0; f < count; ++f)
        for (int i = 0; i < 3; ++i) {
            int& v = renumber[part.F(f, i)];
            if (v < 0) {
                v = static_cast<int>(kept.size());
                kept.push_back(part.F(f, i));
            }
            part.F(f, i) = v;
        }
    part.V.resize(static_cast<Eigen::Index>(kept.size()), 3);
    for (std::size_t k = 0; k < kept.size(); ++k)
        part.V.row(static_cast<Eigen::Index>(k)) = surface.V.row(kept[k]);
    return part;
}

/// A surface of three triangles fanned around a centre (a tetrahedron's open side), with its
/// vertices at the given points.
TriMesh fan(const MatrixX3d& V)
{
    MatrixX3i F(V.rows() - 1, 3);
    for (Eigen::Index i = 1; i < V.rows(); ++i)
        F.row(i - 1) << 0, int(i), int(i % (V.rows() - 1) + 1);
    return TriMesh{V, F};
}

}  // namespace

TEST_CASE("W: four weights a row, summing to 1, between -tol and 1 + tol for inside points, the rest surface exactly",
          "[ex13.4]")
{
    const TetMesh mesh = bunny_tets();
    const TriMesh surface = midpoint_subdivision(bunny_surface(), 1);
    const SkinOptions options;
    const Skin skin = build_skin(mesh, surface, options);
    REQUIRE(skin.W.rows == surface.V.rows());
    REQUIRE(skin.W.cols == mesh.V.rows());
    sparse::validate(skin.W);
    CHECK(skin.outside.empty());
    for (int s = 0; s < skin.W.rows; ++s) {
        REQUIRE(skin.W.IA[s + 1] - skin.W.IA[s] == 4);
        double sum = 0.0;
        for (int k = skin.W.IA[s]; k < skin.W.IA[s + 1]; ++k) {
            sum += skin.W.A[k];
            CHECK(skin.W.A[k] >= -options.tolerance);
            CHECK(skin.W.A[k] <= 1.0 + options.tolerance);
        }
        CHECK(sum == Approx(1.0).margin(1e-14));
    }
    // W X_sim = X_skin: the rest surface, to round-off of the coordinates (about 10 units).
    CHECK_THAT(entries_of(eigen_product(skin.W, mesh.V)), EntriesNear(surface.V, 1e-13 * 10.0));
}

TEST_CASE("W carries any affine motion of the coarse mesh exactly, and is the identity's rows on its own vertices",
          "[ex13.4]")
{
    const TetMesh mesh = bunny_tets();
    const TriMesh surface = bunny_surface();
    const Skin skin = build_skin(mesh, surface);
    CHECK_THAT(entries_of(eigen_product(skin.W, affine(mesh.V))), EntriesNear(affine(surface.V), 1e-12 * 10.0));
    // The lattice: the bunny inside cubes, weights of all four corners.
    const TetMesh lattice = enclosing_lattice(surface, 5);
    const Skin coarse = build_skin(lattice, surface);
    CHECK(coarse.outside.empty());
    CHECK_THAT(entries_of(eigen_product(coarse.W, affine(lattice.V))), EntriesNear(affine(surface.V), 1e-12 * 10.0));
    // TetGen kept the bunny's vertices as its first nodes (data/README.md): W is the identity's rows.
    REQUIRE((mesh.V.topRows(surface.V.rows()) - surface.V).cwiseAbs().maxCoeff() == 0.0);
    const Eigen::MatrixXd W = Eigen::MatrixXd(sparse::to_eigen(skin.W));
    CHECK_THAT(entries_of(W.leftCols(surface.V.rows())), EntriesNear(Eigen::MatrixXd::Identity(surface.V.rows(), surface.V.rows()), 1e-12));
    CHECK(W.rightCols(mesh.V.rows() - surface.V.rows()).cwiseAbs().maxCoeff() <= 1e-12);
}

TEST_CASE("skinning a smooth motion: the error of a quadratic field falls as h^2 with the lattice's cube size", "[ex13.4]")
{
    // The field x(X) = X + ε (X_y², X_z X_x, X_x²): W interpolates it linearly in each tet, with an
    // error ≤ (ε/2)·|second derivative|·h² per vertex; halving h divides it by about four.
    const TriMesh surface = bunny_surface();
    const auto field = [](const MatrixX3d& X) {
        MatrixX3d x = X;
        x.col(0) += 0.01 * X.col(1).cwiseProduct(X.col(1));
        x.col(1) += 0.01 * X.col(2).cwiseProduct(X.col(0));
        x.col(2) += 0.01 * X.col(0).cwiseProduct(X.col(0));
        return x;
    };
    std::vector<double> errors;
    for (int cells : {4, 8, 16}) {
        const TetMesh lattice = enclosing_lattice(surface, cells);
        const Skin skin = build_skin(lattice, surface);
        errors.push_back((eigen_product(skin.W, field(lattice.V)) - field(surface.V)).rowwise().norm().maxCoeff());
    }
    INFO("errors " << errors[0] << " " << errors[1] << " " << errors[2]);
    CHECK(errors[1] < errors[0] / 2.5);
    CHECK(errors[2] < errors[1] / 2.5);
    CHECK(errors[2] > 0.0);
}

TEST_CASE("skinned positions by hand: Eigen's sparse product on a random W, for all three columns at once", "[ex13.7]")
{
    sparse::CooMatrix coo;
    coo.rows = 50;
    coo.cols = 30;
    const Eigen::VectorXd values = random_vector(200, 7);
    for (int k = 0; k < 200; ++k)
        coo.add((k * 37) % 50, (k * 11 + k / 7) % 30, values[k]);
    const sparse::CsrMatrix W = sparse::coo_to_csr(coo);
    const MatrixX3d Q = random_matrix(30, 3, 3);
    CHECK_THAT(entries_of(skinned_positions(W, Q)), EntriesNear(eigen_product(W, Q), 1e-14));
    CHECK_THROWS_AS(skinned_positions(W, MatrixX3d(29, 3)), Error);
}

TEST_CASE("a skin frame: rest points, the displacement W Q - X, the deformed normals", "[ex13.7]")
{
    const TetMesh mesh = box_mesh(2, 2, 2);
    Skin skin;
    skin.surface = fan((MatrixX3d(4, 3) << 0.5, 0.5, 0.5, 0.2, 0.3, 0.4, 0.8, 0.2, 0.6, 0.4, 0.9, 0.3).finished());
    // A known W: its rows pick the coarse vertices 0, 1, 2, 3.
    sparse::CooMatrix coo;
    coo.rows = 4;
    coo.cols = static_cast<int>(mesh.V.rows());
    for (int s = 0; s < 4; ++s)
        coo.add(s, s, 1.0);
    skin.W = sparse::coo_to_csr(coo);
    const MatrixX3d Q = mesh.V * 2.0;
    const io::MeshData frame = skin_frame(skin, Q);
    CHECK_THAT(entries_of(frame.points), EntriesNear(skin.surface.V, 0.0));
    CHECK_THAT(entries_of(frame.field("displacement").values),
               EntriesNear(Eigen::MatrixXd(Q.topRows(4) - skin.surface.V), 1e-15));
    CHECK(frame.field("normal").values.rows() == 4);
}

TEST_CASE("closest point on a triangle: corners, edges and the face, against a dense sampling", "[ex13.5]")
{
    const Eigen::Vector3d a(0.0, 0.0, 0.0), b(2.0, 0.0, 0.0), c(0.5, 1.5, 0.0);
    // Known answers in each Voronoi region.
    CHECK_THAT(entries_of(closest_point_on_triangle({-1.0, -1.0, 0.3}, a, b, c)), EntriesNear(a, 1e-15));
    CHECK_THAT(entries_of(closest_point_on_triangle({3.0, -0.5, 0.0}, a, b, c)), EntriesNear(b, 1e-15));
    CHECK_THAT(entries_of(closest_point_on_triangle({0.5, 3.0, -1.0}, a, b, c)), EntriesNear(c, 1e-15));
    CHECK_THAT(entries_of(closest_point_on_triangle({1.0, -2.0, 0.5}, a, b, c)), EntriesNear(Eigen::Vector3d(1.0, 0.0, 0.0), 1e-15));
    CHECK_THAT(entries_of(closest_point_on_triangle({0.8, 0.4, 2.0}, a, b, c)), EntriesNear(Eigen::Vector3d(0.8, 0.4, 0.0), 1e-15));
    // Random points: no point of a fine sampling of the triangle is closer.
    for (unsigned seed = 1; seed <= 30; ++seed) {
        const Eigen::Vector3d p = 3.0 * Eigen::Vector3d(random_vector(3, seed));
        const double found = (p - closest_point_on_triangle(p, a, b, c)).norm();
        double sampled = std::numeric_limits<double>::infinity();
        for (int i = 0; i <= 200; ++i)
            for (int j = 0; i + j <= 200; ++j)
                sampled = std::min(sampled, (p - (a + (b - a) * (i / 200.0) + (c - a) * (j / 200.0))).norm());
        CHECK(found <= sampled + 1e-14);
        CHECK(found >= sampled - 0.02);
    }
}

TEST_CASE("points outside a cube: the nearest tet, the distances, extrapolated weights carrying affine motions, the limit",
          "[ex13.5]")
{
    // The unit cube as six tets; surface vertices at known distances outside: 0.2 beyond x = 1,
    // 0.1 above z = 1, 0.3 below y = 0, and one inside.
    const TetMesh cube = box_mesh(1, 1, 1);
    MatrixX3d V(4, 3);
    V << 0.5, 0.5, 0.5, 1.2, 0.5, 0.5, 0.4, 0.6, 1.1, 0.5, -0.3, 0.5;
    const TriMesh surface = fan(V);
    SkinOptions options;
    options.max_outside_distance = 0.5;
    const Skin skin = build_skin(cube, surface, options);
    REQUIRE(skin.outside.size() == 3);
    const double distances[] = {0.2, 0.1, 0.3};
    for (int k = 0; k < 3; ++k) {
        CHECK(skin.outside[k].vertex == k + 1);
        CHECK(skin.outside[k].distance == Approx(distances[k]).margin(1e-14));
        CHECK(skin.outside[k].relative_distance == Approx(distances[k] / std::sqrt(3.0)).margin(1e-14));
    }
    CHECK(skin.largest_outside_distance() == Approx(0.3).margin(1e-14));
    // Extrapolated weights: a negative one for each outside vertex, the sum still 1, and the affine
    // motion carried exactly.
    CHECK(*std::min_element(skin.W.A.begin(), skin.W.A.end()) < 0.0);
    CHECK_THAT(entries_of(eigen_product(skin.W, affine(cube.V))), EntriesNear(affine(V), 1e-14));
    // A surface larger than the bunny's tets: outside vertices counted, all carried affinely.
    TriMesh grown = first_triangles(bunny_surface(), 400);
    const Eigen::RowVector3d centre = bunny_surface().V.colwise().mean();
    grown.V = ((grown.V.rowwise() - centre) * 1.02).rowwise() + centre;
    const TetMesh tets = bunny_tets();
    const Skin large = build_skin(tets, grown, options);
    CHECK(large.outside.size() > 50);
    for (const OutsidePoint& o : large.outside) {
        const Nearest nearest = nearest_boundary_tet(tets, boundary_faces(tets), grown.V.row(o.vertex).transpose());
        CHECK(o.distance == Approx(nearest.distance).margin(1e-12));
        CHECK(o.distance > 0.0);
        break;  // one full check; the rest by the affine motion below
    }
    CHECK_THAT(entries_of(eigen_product(large.W, affine(tets.V))), EntriesNear(affine(grown.V), 1e-11));
    // Beyond the limit: an error naming the vertex and the limit.
    options.max_outside_distance = 0.1;  // below vertex 1's 0.2/√3 = 0.115
    CHECK_THROWS_WITH(build_skin(cube, surface, options), Contains("surface vertex 1") && Contains("0.1 times"));
}

TEST_CASE("normals: a flat patch points along z, a sphere's radially, and they turn with a rotated surface", "[ex13.6]")
{
    MatrixX3d flat(4, 3);
    flat << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
    MatrixX3i quad(2, 3);
    quad << 0, 1, 2, 0, 2, 3;
    const MatrixX3d n = vertex_normals(quad, flat);
    for (int v = 0; v < 4; ++v)
        CHECK_THAT(entries_of(n.row(v)), EntriesNear(Eigen::RowVector3d(0, 0, 1), 1e-15));
    // An octahedron refined and pushed onto the unit sphere.
    MatrixX3d octahedron(6, 3);
    octahedron << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
    MatrixX3i faces(8, 3);
    faces << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
    // The normals tend to the radial direction as O(h²): a level finer, about 4 times closer.
    const auto sphere_at = [&](int levels) {
        TriMesh sphere = midpoint_subdivision(TriMesh{octahedron, faces}, levels);
        sphere.V.rowwise().normalize();
        return sphere;
    };
    const TriMesh coarse = sphere_at(3), sphere = sphere_at(4);
    const double coarse_error = (vertex_normals(coarse.F, coarse.V) - coarse.V).rowwise().norm().maxCoeff();
    const MatrixX3d radial = vertex_normals(sphere.F, sphere.V);
    const double error = (radial - sphere.V).rowwise().norm().maxCoeff();
    INFO("normal errors " << coarse_error << " and " << error);
    CHECK(error < coarse_error / 3.0);
    CHECK(error < 1e-2);
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    CHECK_THAT(entries_of(vertex_normals(sphere.F, sphere.V * R.transpose())), EntriesNear(radial * R.transpose(), 1e-13));
}

TEST_CASE("bad input: an empty surface, NaN coordinates, an inverted or flat coarse tet are named", "[ch13]")
{
    const TetMesh cube = box_mesh(1, 1, 1);
    const TriMesh surface = bunny_surface();
    CHECK_THROWS_WITH(build_skin(cube, TriMesh{}), Contains("empty"));
    TriMesh nan_surface = surface;
    nan_surface.V(17, 1) = std::nan("");
    CHECK_THROWS_WITH(build_skin(bunny_tets(), nan_surface), Contains("vertex 17") || Contains("17"));
    TetMesh inverted = cube;
    std::swap(inverted.T(3, 2), inverted.T(3, 3));
    CHECK_THROWS_WITH(build_skin(inverted, surface), Contains("3") && Contains("nverted"));
    TetMesh nan_mesh = cube;
    nan_mesh.V(2, 0) = std::numeric_limits<double>::infinity();
    CHECK_THROWS_AS(build_skin(nan_mesh, surface), Error);
    TetMesh flat = cube;
    flat.V.col(2).setZero();
    CHECK_THROWS_AS(build_skin(flat, surface), Error);
    CHECK_THROWS_WITH(build_skin(TetMesh{}, surface), Contains("no tetrahedra"));
    SkinOptions options;
    options.tolerance = -1.0;
    CHECK_THROWS_WITH(build_skin(cube, surface, options), Contains("tolerance"));
    options = SkinOptions{};
    options.max_outside_distance = std::nan("");
    CHECK_THROWS_WITH(build_skin(cube, surface, options), Contains("max_outside_distance"));
}

TEST_CASE("skinning a coarse simulation: the skinned lattice approaches the fine simulation as its cubes shrink",
          "[ex13.4]")
{
    // Chapter 10's rubber bunny (9.7 cm), pushed sideways, four steps of corotational backward Euler
    // on TetGen's tets (whose surface is the bunny: the reference) and on lattices of 8 and 16 cubes,
    // each skinned: the finer lattice's surface is closer to the reference (the executable's sweep).
    TriMesh surface = bunny_surface();
    surface.V *= 0.01;
    TetMesh fine = bunny_tets();
    fine.V *= 0.01;
    const double low = surface.V.col(1).minCoeff(), high = surface.V.col(1).maxCoeff();
    const auto run = [&](const TetMesh& mesh, bool own_surface) {
        const dynamics::Scene scene =
            dynamics::standing_scene(mesh, dynamics::Material{1e5, 0.45, 1000.0}, low + 0.05 * (high - low));
        dynamics::Body body(scene, std::make_unique<corot::CorotationalElasticity>(scene.mesh, scene.material));
        dynamics::ThetaMethod integrator(1.0);
        dynamics::Simulation simulation(body, integrator,
                                        dynamics::initial_state(body, {}, dynamics::sideways_push(scene, low, high, 0.5)));
        simulation.run(4);
        const MatrixX3d x = body.positions(simulation.state().u);
        if (own_surface)  // TetGen's first nodes are the bunny's vertices (the test of W = [I 0])
            return MatrixX3d(x.topRows(surface.V.rows()));
        return eigen_product(build_skin(mesh, surface).W, x);
    };
    const MatrixX3d reference = run(fine, true);
    const double motion = (reference - surface.V).rowwise().norm().maxCoeff();
    const double coarse = (run(enclosing_lattice(surface, 8), false) - reference).rowwise().norm().maxCoeff();
    const double finer = (run(enclosing_lattice(surface, 16), false) - reference).rowwise().norm().maxCoeff();
    INFO("motion " << motion << ", error on 8 cubes " << coarse << ", on 16 cubes " << finer);
    CHECK(motion > 1e-3);
    CHECK(finer < 0.7 * coarse);
    CHECK(finer < 0.5 * motion);
}
