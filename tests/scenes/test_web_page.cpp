// The web page of a run (fem_scene --html): its frame data decodes to the .vtu frames' positions to
// within the quantisation bound, and the page needs nothing from the network. docs/scenes.md#the-web-page
#include "scenes/web_page.hpp"

#include "common/error.hpp"
#include "common/random.hpp"
#include "common/vtk_io.hpp"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

using namespace fem;
using namespace fem::scenes;

namespace {

/// The raw JSON text of the value of "key" in the page's data: a string's characters without its
/// quotes, an array's numbers with their brackets, or a number.
std::string json_value(const std::string& data, const std::string& key)
{
    const std::size_t at = data.find("\"" + key + "\":");
    REQUIRE(at != std::string::npos);
    const std::size_t start = at + key.size() + 3;
    if (data[start] == '"')
        return data.substr(start + 1, data.find('"', start + 1) - start - 1);
    const std::size_t end = data[start] == '[' ? data.find(']', start) + 1 : data.find_first_of(",}", start);
    return data.substr(start, end - start);
}

/// The three numbers of a JSON array "[x,y,z]".
Eigen::Vector3d json_vector(const std::string& text)
{
    std::istringstream in(text.substr(1, text.size() - 2));
    Eigen::Vector3d v;
    char comma;
    in >> v.x() >> comma >> v.y() >> comma >> v.z();
    return v;
}

}  // namespace

TEST_CASE("positions quantised to 16 bits come back within half a step of the box", "[scenes][web_page]")
{
    std::vector<MatrixX3d> frames;
    for (unsigned k = 0; k < 5; ++k) {
        MatrixX3d x = (0.7 + random_matrix(50, 3, 37 + k).array()).matrix();  // in [-0.3, 1.7]
        x.col(2).setConstant(0.25);  // an axis of zero extent decodes exactly
        frames.push_back(x);
    }
    const QuantisedPositions q = quantise_positions(frames);
    const Eigen::Vector3d bound = quantisation_bound(q);
    CHECK(bound.x() == Approx(0.5 * (q.high.x() - q.low.x()) / 65535));
    CHECK(bound.z() == 0.0);
    double worst = 0.0;
    for (std::size_t k = 0; k < frames.size(); ++k) {
        const MatrixX3d back = dequantise_frame(q, k);
        for (int a = 0; a < 3; ++a) {
            const double error = (back.col(a) - frames[k].col(a)).cwiseAbs().maxCoeff();
            CHECK(error <= bound[a] * (1 + 1e-9) + 1e-15);
            worst = std::max(worst, error / std::max(bound[a], 1e-300));
        }
    }
    CHECK(worst > 0.9);  // the bound is tight: 250 random coordinates come within 10 % of it
    // the page's bytes: little-endian 16-bit codes, base64, back to the same codes
    std::string bytes;
    for (const std::uint16_t code : q.codes)
        bytes += {static_cast<char>(code & 255), static_cast<char>(code >> 8)};
    const QuantisedPositions read = positions_from_bytes(base64_decode(base64_encode(bytes)), q.low, q.high, q.points);
    CHECK(read.codes == q.codes);
    CHECK_THROWS_WITH(positions_from_bytes(bytes.substr(1), q.low, q.high, q.points),
                      Catch::Contains("not whole frames of 50 points"));
    frames[3](7, 1) = std::nan("");
    CHECK_THROWS_WITH(quantise_positions(frames), Catch::Contains("frame 3, point 7"));
}

TEST_CASE("base64 encodes every byte and length, and refuses what is not base64", "[scenes][web_page]")
{
    std::string all;
    for (int b = 0; b < 256; ++b)
        all += static_cast<char>(b);
    for (std::size_t n = 0; n <= 7; ++n)
        CHECK(base64_decode(base64_encode(all.substr(250 - n, n))) == all.substr(250 - n, n));
    CHECK(base64_decode(base64_encode(all)) == all);
    CHECK(base64_encode("Man") == "TWFu");
    CHECK(base64_encode("Ma") == "TWE=");
    CHECK(base64_encode("M") == "TQ==");
    CHECK_THROWS_WITH(base64_decode("TWF"), Catch::Contains("multiple of 4"));
    CHECK_THROWS_WITH(base64_decode("TW-u"), Catch::Contains("character 2"));
    CHECK_THROWS_WITH(base64_decode("T=Fu"), Catch::Contains("character 1"));
}

TEST_CASE("the web page's frames are the .vtu frames to the quantisation bound, and it needs no network",
          "[scenes][web_page]")
{
    try {
        check_web_page_library();
    } catch (const Error& e) {
        WARN("SKIPPED: " << e.what());
        return;
    }
    const std::filesystem::path out = std::filesystem::path(FEM_TEST_OUTPUT_DIR) / "web_page";
    std::filesystem::remove_all(out);
    // output.html from the scene's fields (as a file sets it), the motion drawn ×3 as the PNGs draw it
    const std::string command = std::string("'") + FEM_SCENE_EXE + "' '" + FEM_SCENES_DIR +
                                "/cantilever.toml' --quick --no-figures --no-progress --set output.html=true "
                                "--set output.warp=3 --out '" + out.string() + "' >/dev/null 2>&1";
    REQUIRE(std::system(command.c_str()) == 0);
    std::ifstream file(out / "cantilever.html", std::ios::binary);
    std::stringstream text;
    text << file.rdbuf();
    const std::string page = text.str();

    // self-contained: no script, style or link fetched from anywhere
    CHECK(!std::regex_search(page, std::regex(R"((src|href)\s*=\s*["']?\s*(https?:)?//)", std::regex::icase)));
    CHECK(!std::regex_search(page, std::regex(R"(<script[^>]*\ssrc\s*=)", std::regex::icase)));
    CHECK(!std::regex_search(page, std::regex(R"(<link[^>]*\shref\s*=)", std::regex::icase)));
    CHECK(page.find("THREE.OrbitControls") != std::string::npos);  // the library is in the page

    const std::string open = "<script type=\"application/json\" id=\"fem-data\">";
    const std::size_t start = page.find(open) + open.size();
    const std::string data = page.substr(start, page.find("</script>", start) - start);
    const Eigen::Index points = std::stol(json_value(data, "points"));
    const QuantisedPositions q = positions_from_bytes(base64_decode(json_value(data, "positions")),
                                                      json_vector(json_value(data, "low")),
                                                      json_vector(json_value(data, "high")), points);
    const std::string ids = base64_decode(json_value(data, "point_ids"));
    REQUIRE(ids.size() == 4 * static_cast<std::size_t>(points));
    const Eigen::Vector3d bound = quantisation_bound(q);
    CHECK(bound.maxCoeff() < 1e-5);  // a 0.2 m beam: 16 bits hold it to micrometres

    const auto frames = io::read_pvd(out / "cantilever.pvd");
    REQUIRE(frames.size() == q.frames());
    REQUIRE(frames.size() >= 3);
    double moved = 0.0;
    for (std::size_t k = 0; k < frames.size(); ++k) {
        const io::MeshData vtu = io::read_vtu(out / frames[k].second);
        const MatrixX3d drawn = io::warped(vtu, 3.0).points;
        const MatrixX3d decoded = dequantise_frame(q, k);
        for (Eigen::Index i = 0; i < points; ++i) {
            const int id = static_cast<unsigned char>(ids[4 * i]) | static_cast<unsigned char>(ids[4 * i + 1]) << 8 |
                           static_cast<unsigned char>(ids[4 * i + 2]) << 16;
            for (int a = 0; a < 3; ++a)
                CHECK(std::abs(decoded(i, a) - drawn(id, a)) <= bound[a] * (1 + 1e-6));
            moved = std::max(moved, (drawn.row(id) - vtu.points.row(id)).norm());
        }
    }
    CHECK(moved > 0.01);  // the beam swings: the frames differ
}
