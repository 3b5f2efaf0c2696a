// The motion recorder: every frame in the .pvd with rest positions and displacement, PNG frames
// of one camera and one colour range, and frames without a displacement refused before writing.
#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/motion.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using Catch::Matchers::Contains;

namespace {

/// A tet moving its top vertex up by 0.1 t.
fem::io::MeshData moving_tet(double t)
{
    fem::MatrixX3d rest(4, 3);
    rest << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
    fem::MatrixXiR cells(1, 4);
    cells << 0, 1, 2, 3;
    fem::MatrixX3d u = fem::MatrixX3d::Zero(4, 3);
    u(3, 2) = 0.1 * t;
    fem::io::MeshData frame = fem::io::displaced_mesh(rest, cells, u);
    frame.cell_data.push_back({"stress", Eigen::MatrixXd::Constant(1, 1, 10.0 * t)});
    return frame;
}

}  // namespace

TEST_CASE("motion recorder: a .pvd of rest shapes with displacement, PNG frames every k-th", "[common][vtk]")
{
    const auto dir = fem::test::fresh_output_dir("motion");
    fem::io::MotionRecorder recorder(dir / "tet.pvd", 2);
    for (int k = 0; k <= 4; ++k)
        recorder.add(0.5 * k, moving_tet(0.5 * k));
    CHECK(recorder.frames() == 5);
    const auto entries = fem::io::read_pvd(dir / "tet.pvd");
    REQUIRE(entries.size() == 5);
    CHECK(entries[4].first == 2.0);
    const fem::io::MeshData last = fem::io::read_vtu(dir / entries[4].second);
    CHECK(last.points == moving_tet(0.0).points);  // rest positions in every frame
    CHECK(last.field("displacement").values(3, 2) == Approx(0.2));

    fem::fig::RenderOptions options;
    options.field = "stress";
    options.title = "a tet";
    const int written = recorder.render_png_frames(dir / "tet", options, 2.0);
    if (fem::fig::display_available()) {
        CHECK(written == 3);  // frames 0, 2, 4
        CHECK(std::filesystem::is_regular_file(dir / "tet_0002.png"));
        CHECK_FALSE(std::filesystem::exists(dir / "tet_0003.png"));
    } else {
        CHECK(written == 0);
    }
    CHECK_THROWS_AS(recorder.render_png_frames(dir / "tet", options, std::nan("")), fem::Error);
}

TEST_CASE("motion recorder: a frame without displacement is refused and nothing is written", "[common][vtk]")
{
    const auto dir = fem::test::fresh_output_dir("motion_bad");
    fem::io::MotionRecorder recorder(dir / "bad.pvd");
    fem::io::MeshData frame = moving_tet(1.0);
    frame.point_data.clear();
    CHECK_THROWS_WITH(recorder.add(0.0, frame), Contains("displacement"));
    CHECK(recorder.frames() == 0);
    CHECK_FALSE(std::filesystem::exists(dir / "bad.pvd"));
    CHECK_THROWS_AS(fem::io::MotionRecorder(dir / "x.pvd", -1), fem::Error);
}

TEST_CASE("motion recorder: a surface series writes .vtp frames, a tet frame is refused by the .vtp writer",
          "[common][vtk]")
{
    const auto dir = fem::test::fresh_output_dir("motion_surface");
    fem::io::MotionRecorder recorder(dir / "skin.pvd", 0, fem::io::FrameFile::surface);
    fem::MatrixX3d rest(3, 3);
    rest << 0, 0, 0, 1, 0, 0, 0, 1, 0;
    fem::MatrixXiR triangle(1, 3);
    triangle << 0, 1, 2;
    fem::MatrixX3d u = fem::MatrixX3d::Zero(3, 3);
    u(2, 2) = 0.25;
    recorder.add(0.0, fem::io::displaced_mesh(rest, triangle, u));
    const auto entries = fem::io::read_pvd(dir / "skin.pvd");
    REQUIRE(entries.size() == 1);
    CHECK(std::filesystem::path(entries[0].second).extension() == ".vtp");
    CHECK(std::filesystem::is_regular_file(dir / entries[0].second));
    CHECK_THROWS_AS(recorder.add(1.0, moving_tet(1.0)), fem::Error);  // tets are no surface
    CHECK(fem::io::read_pvd(dir / "skin.pvd").size() == 1);
}
