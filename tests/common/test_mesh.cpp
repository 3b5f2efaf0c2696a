// Mesh generators and validation.
#include "common/error.hpp"
#include "common/mesh.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

using Catch::Matchers::Contains;

TEST_CASE("box_mesh: counts, positive volumes, total volume, conforming faces", "[common][mesh]")
{
    const int nx = 3, ny = 2, nz = 4;
    const Eigen::Vector3d size(1.5, 0.5, 2.0);
    fem::TetMesh box = fem::box_mesh(nx, ny, nz, size);
    CHECK(box.V.rows() == (nx + 1) * (ny + 1) * (nz + 1));
    CHECK(box.T.rows() == 6 * nx * ny * nz);
    for (int t = 0; t < box.T.rows(); ++t)
        CHECK(fem::tet_signed_volume6(box, t) > 0.0);
    CHECK(fem::total_volume(box) == Approx(size.prod()).epsilon(1e-13));
    CHECK(fem::validate(box) == 0);

    // Every face is shared by two tets inside the box, and lies on the boundary otherwise.
    std::map<std::array<int, 3>, int> faces;
    for (int t = 0; t < box.T.rows(); ++t)
        for (int skip = 0; skip < 4; ++skip) {
            std::array<int, 3> face;
            int k = 0;
            for (int c = 0; c < 4; ++c)
                if (c != skip)
                    face[k++] = box.T(t, c);
            std::sort(face.begin(), face.end());
            ++faces[face];
        }
    int boundary = 0;
    for (const auto& [face, count] : faces) {
        REQUIRE(count <= 2);
        if (count == 1) {
            ++boundary;
            // A boundary face lies in one of the six box planes.
            bool on_plane = false;
            for (int d = 0; d < 3; ++d)
                for (double plane : {0.0, size[d]})
                    on_plane = on_plane || (std::abs(box.V(face[0], d) - plane) < 1e-12 &&
                                            std::abs(box.V(face[1], d) - plane) < 1e-12 &&
                                            std::abs(box.V(face[2], d) - plane) < 1e-12);
            CHECK(on_plane);
        }
    }
    CHECK(boundary == 4 * (nx * ny + ny * nz + nz * nx));
}

TEST_CASE("beam_mesh keeps cells near cubes", "[common][mesh]")
{
    const fem::TetMesh beam = fem::beam_mesh(0.2, 0.02, 0.02, 10);
    CHECK(beam.T.rows() == 6 * 10);
    CHECK(fem::total_volume(beam) == Approx(0.2 * 0.02 * 0.02).epsilon(1e-12));
    CHECK(fem::beam_mesh(1.0, 0.25, 0.5, 8).T.rows() == 6 * 8 * 2 * 4);
    CHECK_THROWS_AS(fem::beam_mesh(-1.0, 0.1, 0.1, 4), fem::Error);
}

TEST_CASE("square_mesh: counter-clockwise triangles tiling the unit square, also jittered", "[common][mesh]")
{
    for (double jitter : {0.0, 0.24}) {
        const fem::TriMesh square = fem::square_mesh(7, jitter, 42);
        CHECK(square.V.rows() == 64);
        CHECK(square.F.rows() == 98);
        double area = 0.0;
        for (int f = 0; f < square.F.rows(); ++f) {
            const Eigen::Vector3d a = square.V.row(square.F(f, 0)), b = square.V.row(square.F(f, 1)),
                                  c = square.V.row(square.F(f, 2));
            const double signed_area = 0.5 * (b - a).cross(c - a).z();
            CHECK(signed_area > 0.0);
            area += signed_area;
        }
        CHECK(area == Approx(1.0).epsilon(1e-13));
        CHECK_NOTHROW(fem::validate(square));
    }
    CHECK_THROWS_AS(fem::square_mesh(0), fem::Error);
    CHECK_THROWS_WITH(fem::square_mesh(4, 0.5), Contains("jitter"));
}

TEST_CASE("validation names the element and what is allowed", "[common][mesh]")
{
    fem::TetMesh box = fem::box_mesh(1, 1, 1);
    auto bad = box;
    bad.T(4, 2) = 99;
    CHECK_THROWS_WITH(fem::validate(bad, "beam.ele"),
                      Contains("beam.ele") && Contains("tetrahedron 4") && Contains("vertex 99") &&
                          Contains("0 to 7"));
    bad = box;
    bad.T(2, 1) = bad.T(2, 0);
    CHECK_THROWS_WITH(fem::validate(bad), Contains("tetrahedron 2") && Contains("twice"));
    bad = box;
    bad.V(3, 1) = std::nan("");
    CHECK_THROWS_WITH(fem::validate(bad), Contains("vertex 3") && Contains("non-finite"));
    bad = box;
    bad.V.row(bad.T(1, 3)) = bad.V.row(bad.T(1, 0)) + 0.5 * (bad.V.row(bad.T(1, 1)) - bad.V.row(bad.T(1, 0)));
    CHECK_THROWS_WITH(fem::validate(bad), Contains("zero volume"));
    bad = box;
    std::swap(bad.T(5, 0), bad.T(5, 1));
    CHECK_THROWS_WITH(fem::validate(bad), Contains("tetrahedron 5") && Contains("inverted"));
    CHECK(fem::validate(bad, "mesh", fem::Inverted::reorient) == 1);
    CHECK(fem::tet_signed_volume6(bad, 5) > 0.0);
    CHECK(fem::validate(bad) == 0);
    fem::TetMesh empty;
    CHECK_THROWS_WITH(fem::validate(empty), Contains("empty"));

    fem::TriMesh square = fem::square_mesh(2);
    square.V.row(square.F(3, 2)) = 0.5 * (square.V.row(square.F(3, 0)) + square.V.row(square.F(3, 1)));
    CHECK_THROWS_WITH(fem::validate(square, "flat.obj"), Contains("flat.obj") && Contains("zero area"));
    CHECK_THROWS_AS(fem::box_mesh(0, 1, 1), fem::Error);
}
