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

TEST_CASE("motion recorder: the range and the exaggeration cover every frame, not only the kept ones", "[common][vtk]")
{
    const auto dir = fem::test::fresh_output_dir("motion_range");
    fem::io::MotionRecorder recorder(dir / "tet.pvd", 3);  // keeps frames 0 and 3 of 0..4
    for (int k = 0; k <= 4; ++k)
        recorder.add(0.5 * k, moving_tet(0.5 * k));
    // Frame 4 (t = 2) is not kept for the PNGs but holds the largest stress (20) and |u| (0.2).
    CHECK(recorder.field_range("stress").first == 0.0);
    CHECK(recorder.field_range("stress").second == Approx(20.0));
    CHECK(recorder.field_range("displacement").second == Approx(0.2));
    CHECK_THROWS_AS(recorder.field_range("no such field"), fem::Error);
    // The rest tet's diagonal is √3: a quarter of it over 0.2 is 2.17, rounded down to 2.
    CHECK(recorder.visible_warp() == 2.0);
    CHECK(recorder.visible_warp(0.01) == 1.0);  // already visible: never shrunk below true scale
    CHECK(recorder.visible_warp(2.0) == 10.0);  // 17.3 rounded down to 1, 2 or 5 times a power of ten
}

TEST_CASE("motion frame titles: the time rounded to 0.01 s, the exaggeration on a line of its own", "[common][vtk]")
{
    CHECK(fem::io::frame_title("beam", 2.0 / 3.0, 1.0) == "beam, t = 0.67 s");
    CHECK(fem::io::frame_title("beam", 0.5, 1.0) == "beam, t = 0.5 s");
    CHECK(fem::io::frame_title("beam", 0.0, 1.0) == "beam, t = 0 s");
    CHECK(fem::io::frame_title("beam", 1.0, 5.0) == "beam, t = 1 s\ndisplacement drawn \u00D75 (grey: the body at rest)");
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
