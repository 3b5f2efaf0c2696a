// VTK files round-trip through VTK's own readers, and bad data is refused before anything is written.
#include "common/error.hpp"
#include "common/test_support.hpp"
#include "common/vtk_convert.hpp"
#include "common/vtk_io.hpp"

#include <catch2/catch.hpp>
#include <vtkNew.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <cmath>
#include <fstream>

using Catch::Matchers::Contains;

namespace {

fem::io::MeshData two_tets()
{
    fem::io::MeshData mesh;
    mesh.points.resize(5, 3);
    mesh.points << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1;
    mesh.cells.resize(2, 4);
    mesh.cells << 0, 1, 2, 3, 1, 2, 3, 4;
    Eigen::MatrixXd u(5, 1), v(5, 3), s(2, 1), F(2, 9);
    u << 0.5, -1.25, 3, 4, 1e-300;
    v.setRandom();
    s << 7, -8;
    F.setRandom();
    mesh.point_data = {{"temperature", u}, {"velocity", v}};
    mesh.cell_data = {{"volume", s}, {"F", F}};
    return mesh;
}

}  // namespace

TEST_CASE("a .vtu file reads back exactly what was written", "[common][vtk]")
{
    const auto dir = fem::test::fresh_output_dir("vtu");
    const auto mesh = two_tets();
    fem::io::write_vtu(dir / "tets.vtu", mesh);
    const auto back = fem::io::read_vtu(dir / "tets.vtu");
    CHECK(back.points == mesh.points);
    CHECK(back.cells == mesh.cells);
    REQUIRE(back.point_data.size() == 2);
    REQUIRE(back.cell_data.size() == 2);
    CHECK(back.field("temperature").values == mesh.field("temperature").values);
    CHECK(back.field("velocity").values == mesh.field("velocity").values);
    CHECK(back.field("F").values == mesh.field("F").values);
    CHECK(back.field("volume").values == mesh.field("volume").values);
}

TEST_CASE("a .vtu in any data mode of VTK's writer passes the checks made before VTK reads it", "[common][vtk]")
{
    // ParaView and VTK write ASCII, inline base64 or appended (raw or base64) data, compressed or not,
    // with 32- or 64-bit block headers, in either byte order: check_vtu_layout must take them all.
    const auto dir = fem::test::fresh_output_dir("vtu_modes");
    const auto mesh = two_tets();
    int written = 0;
    for (int mode : {vtkXMLWriter::Ascii, vtkXMLWriter::Binary, vtkXMLWriter::Appended})
        for (bool compressed : {false, true})
            for (bool header64 : {false, true})
                for (bool encode : {false, true})
                    for (bool big_endian : {false, true}) {
                        vtkNew<vtkXMLUnstructuredGridWriter> writer;
                        writer->SetInputData(fem::io::detail::to_vtk(mesh));
                        writer->SetDataMode(mode);
                        writer->SetCompressorType(compressed ? vtkXMLWriter::ZLIB : vtkXMLWriter::NONE);
                        writer->SetHeaderType(header64 ? vtkXMLWriter::UInt64 : vtkXMLWriter::UInt32);
                        writer->SetEncodeAppendedData(encode);
                        writer->SetByteOrder(big_endian ? vtkXMLWriter::BigEndian : vtkXMLWriter::LittleEndian);
                        const auto path = dir / fem::str("mode", written++, ".vtu");
                        writer->SetFileName(path.c_str());
                        REQUIRE(writer->Write() == 1);
                        INFO(path.string());
                        const auto back = fem::io::read_vtu(path);
                        CHECK(back.points == mesh.points);
                        CHECK(back.cells == mesh.cells);
                        CHECK(back.field("velocity").values == mesh.field("velocity").values);
                        CHECK(back.field("F").values == mesh.field("F").values);
                    }
}

TEST_CASE("lines and triangles are written as .vtu and .vtp", "[common][vtk]")
{
    const auto dir = fem::test::fresh_output_dir("vtp");
    fem::io::MeshData rod;
    rod.points.resize(3, 3);
    rod.points << 0, 0, 0, 0.5, 0, 0, 1, 0, 0;
    rod.cells.resize(2, 2);
    rod.cells << 0, 1, 1, 2;
    rod.point_data = {{"u", Eigen::MatrixXd::Ones(3, 1)}};
    fem::io::write_vtu(dir / "rod.vtu", rod);
    CHECK(fem::io::read_vtu(dir / "rod.vtu").cells == rod.cells);

    fem::io::MeshData triangle;
    triangle.points = rod.points;
    triangle.points(2, 1) = 1.0;
    triangle.cells.resize(1, 3);
    triangle.cells << 0, 1, 2;
    fem::io::write_vtp(dir / "triangle.vtp", triangle);
    CHECK(std::filesystem::file_size(dir / "triangle.vtp") > 100);

    fem::io::MeshData tets = two_tets();
    CHECK_THROWS_AS(fem::io::write_vtp(dir / "tets.vtp", tets), fem::Error);
}

TEST_CASE("bad meshes and fields are refused and nothing is written", "[common][vtk]")
{
    const auto dir = fem::test::fresh_output_dir("vtu_bad");
    auto mesh = two_tets();
    mesh.cells(1, 3) = 5;
    CHECK_THROWS_WITH(fem::io::write_vtu(dir / "a.vtu", mesh),
                      Contains("cell 1") && Contains("point 5") && Contains("0 to 4"));
    mesh = two_tets();
    mesh.point_data[0].values(2, 0) = std::nan("");
    CHECK_THROWS_WITH(fem::io::write_vtu(dir / "b.vtu", mesh),
                      Contains("temperature") && Contains("point 2") && Contains("non-finite"));
    mesh = two_tets();
    mesh.cell_data[0].values.resize(3, 1);
    CHECK_THROWS_WITH(fem::io::write_vtu(dir / "c.vtu", mesh), Contains("volume") && Contains("3 rows"));
    mesh = two_tets();
    mesh.points(0, 1) = INFINITY;
    CHECK_THROWS_AS(fem::io::write_vtu(dir / "d.vtu", mesh), fem::Error);
    CHECK(std::filesystem::is_empty(dir));
    CHECK_THROWS_WITH(fem::io::read_vtu(dir / "missing.vtu"), Contains("missing.vtu"));
}

TEST_CASE("a .pvd series lists every frame in order and each frame reads back", "[common][vtk]")
{
    const auto dir = fem::test::fresh_output_dir("pvd");
    fem::io::PvdSeries series(dir / "heat.pvd");
    auto mesh = two_tets();
    for (int k = 0; k < 3; ++k) {
        mesh.point_data[0].values.array() += 1.0;
        series.add(0.25 * k, mesh);
    }
    const auto entries = fem::io::read_pvd(dir / "heat.pvd");
    REQUIRE(entries.size() == 3);
    CHECK(entries[2].first == 0.5);
    CHECK(entries[1].second == "heat/heat_0001.vtu");
    const auto last = fem::io::read_vtu(dir / entries[2].second);
    CHECK(last.field("temperature").values == mesh.field("temperature").values);
    CHECK_THROWS_AS(fem::io::PvdSeries(dir / "heat.txt"), fem::Error);

    // A frame that fails leaves the series as it was: still three frames, all readable.
    mesh.point_data[0].values(0, 0) = std::nan("");
    CHECK_THROWS_AS(series.add(0.75, mesh), fem::Error);
    CHECK(fem::io::read_pvd(dir / "heat.pvd").size() == 3);
}

TEST_CASE("a .vti grid is validated and written", "[common][vtk]")
{
    const auto dir = fem::test::fresh_output_dir("vti");
    fem::io::ImageGrid grid;
    grid.dims = {4, 3, 1};
    grid.spacing = {0.5, 0.5, 1.0};
    grid.point_data = {{"u", Eigen::MatrixXd::Zero(12, 1)}};
    fem::io::write_vti(dir / "grid.vti", grid);
    CHECK(std::filesystem::file_size(dir / "grid.vti") > 100);
    grid.point_data[0].values.resize(11, 1);
    CHECK_THROWS_WITH(fem::io::write_vti(dir / "bad.vti", grid), Contains("11 rows"));
    grid.point_data[0].values.resize(12, 1);
    grid.spacing[1] = 0.0;
    CHECK_THROWS_AS(fem::io::write_vti(dir / "bad.vti", grid), fem::Error);
}

TEST_CASE("displaced meshes: rest points plus a displacement field, warped once to the deformed body",
          "[common][vtk]")
{
    const auto dir = fem::test::fresh_output_dir("displaced");
    const auto rest = two_tets();
    Eigen::VectorXd q(15);
    for (int i = 0; i < 15; ++i)
        q[i] = 0.1 * i - 0.4;
    const fem::MatrixX3d u = fem::io::vertex_rows(q);
    REQUIRE(u.rows() == 5);
    CHECK(u(1, 0) == q[3]);
    CHECK(u(4, 2) == q[14]);

    fem::io::write_vtu(dir / "moved.vtu", fem::io::displaced_mesh(rest.points, rest.cells, u));
    const auto back = fem::io::read_vtu(dir / "moved.vtu");
    CHECK(back.points == rest.points);  // the file holds the rest shape ...
    CHECK(back.field("displacement").values == Eigen::MatrixXd(u));  // ... and u beside it
    const auto deformed = fem::io::warped(back);
    CHECK(deformed.points == fem::MatrixX3d(rest.points + u));
    CHECK(fem::io::warped(back, 10.0).points == fem::MatrixX3d(rest.points + 10.0 * u));

    CHECK_THROWS_WITH(fem::io::warped(rest), Contains("no point field 'displacement'"));
    CHECK_THROWS_WITH(fem::io::vertex_rows(Eigen::VectorXd::Zero(7)), Contains("3 entries per vertex"));
    CHECK_THROWS_WITH(fem::io::displaced_mesh(rest.points, rest.cells, u.topRows(4)), Contains("one per point"));
    CHECK_THROWS_WITH(fem::io::warped(back, std::nan("")), Contains("finite"));
}
