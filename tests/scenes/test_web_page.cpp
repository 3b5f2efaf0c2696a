// The web page of a run (fem_scene --html): its frame data decodes to the .vtu frames' positions to
// within the quantisation bound, and the page needs nothing from the network. docs/scenes.md#the-web-page
#include "scenes/web_page.hpp"

#include "13_skinning/skinning.hpp"

#include "common/error.hpp"
#include "common/random.hpp"
#include "common/vtk_io.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
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

/// The numbers of a JSON array "[a,b,…]".
std::vector<double> json_array(const std::string& text)
{
    std::vector<double> values;
    std::istringstream in(text.substr(1, text.size() - 2));
    for (std::string number; std::getline(in, number, ',');)
        values.push_back(std::stod(number));
    return values;
}

/// The three numbers of a JSON array "[x,y,z]".
Eigen::Vector3d json_vector(const std::string& text)
{
    const std::vector<double> v = json_array(text);
    REQUIRE(v.size() == 3);
    return {v[0], v[1], v[2]};
}

/// Value i of a little-endian uint32 array's bytes.
int uint32_at(const std::string& bytes, std::size_t i)
{
    int value = 0;
    for (int b = 3; b >= 0; --b)
        value = value << 8 | static_cast<unsigned char>(bytes[4 * i + b]);
    return value;
}

/// Runs the quick cantilever with output.html = true (as a scene file sets it) and the --set
/// options given into the tests' folder web_page_<name>, and returns the folder and the page's text.
std::pair<std::filesystem::path, std::string> cantilever_page(const std::string& name, const std::string& settings)
{
    const std::filesystem::path out = std::filesystem::path(FEM_TEST_OUTPUT_DIR) / ("web_page_" + name);
    std::filesystem::remove_all(out);
    const std::string command = std::string("'") + FEM_SCENE_EXE + "' '" + FEM_SCENES_DIR +
                                "/cantilever.toml' --quick --no-figures --no-progress --set output.html=true " + settings +
                                " --out '" + out.string() + "' >/dev/null 2>&1";
    REQUIRE(std::system(command.c_str()) == 0);
    std::ifstream file(out / "cantilever.html", std::ios::binary);
    std::stringstream text;
    text << file.rdbuf();
    return {out, text.str()};
}

/// The JSON data of a page: the text of its script element fem-data.
std::string page_data(const std::string& page)
{
    const std::string open = "<script type=\"application/json\" id=\"fem-data\">";
    const std::size_t start = page.find(open);
    REQUIRE(start != std::string::npos);
    return page.substr(start + open.size(), page.find("</script>", start) - start - open.size());
}

/// Whether the library three.js is installed; a test that needs it is skipped without.
/// text in lower case (ASCII).
std::string lower(std::string text)
{
    std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
    return text;
}

/// The first "src=" or "href=" value (any case, spaces and a quote allowed around '=') that starts
/// with "http:", "https:" or "//": an address the browser would fetch; empty when there is none.
/// (Scanned by hand: std::regex draws a false -Wmaybe-uninitialized from g++ 12 under the sanitizers.)
std::string fetched_address(const std::string& page)
{
    const std::string text = lower(page);
    for (const std::string attribute : {"src", "href"})
        for (std::size_t at = text.find(attribute); at != std::string::npos; at = text.find(attribute, at + 1)) {
            std::size_t i = at + attribute.size();
            while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i])))
                ++i;
            if (i >= text.size() || text[i] != '=')
                continue;
            ++i;
            while (i < text.size() && (std::isspace(static_cast<unsigned char>(text[i])) || text[i] == '"' || text[i] == '\''))
                ++i;
            const std::string value = text.substr(i, 8);
            if (value.rfind("http:", 0) == 0 || value.rfind("https:", 0) == 0 || value.rfind("//", 0) == 0)
                return page.substr(at, 60);
        }
    return "";
}

/// Whether some tag opened by `open` (e.g. "<script", any case) has the attribute (" src=", spaces
/// allowed before '=') before its '>'.
bool tag_has_attribute(const std::string& page, const std::string& open, const std::string& attribute)
{
    const std::string text = lower(page);
    for (std::size_t at = text.find(open); at != std::string::npos; at = text.find(open, at + 1)) {
        const std::string tag = text.substr(at, text.find('>', at) - at);
        for (std::size_t a = tag.find(attribute); a != std::string::npos; a = tag.find(attribute, a + 1)) {
            if (a == 0 || !std::isspace(static_cast<unsigned char>(tag[a - 1])))
                continue;
            std::size_t i = a + attribute.size();
            while (i < tag.size() && std::isspace(static_cast<unsigned char>(tag[i])))
                ++i;
            if (i < tag.size() && tag[i] == '=')
                return true;
        }
    }
    return false;
}

bool have_three_js()
{
    try {
        check_web_page_library();
        return true;
    } catch (const Error& e) {
        WARN("SKIPPED: " << e.what());
        return false;
    }
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
    if (!have_three_js())
        return;
    // the motion drawn ×3, as the PNGs would draw it
    const auto [out, page] = cantilever_page("positions", "--set output.warp=3");

    // self-contained: no script, style or link fetched from anywhere
    // (the scanners themselves: they find what they look for)
    REQUIRE(!fetched_address("<img SRC = 'https://example.org/a.png'>").empty());
    REQUIRE(!fetched_address("<a href=//example.org>").empty());
    REQUIRE(fetched_address("<a href=\"#frame=3\">").empty());
    REQUIRE(tag_has_attribute("<SCRIPT type=x  src = 'a.js'>", "<script", "src"));
    REQUIRE(!tag_has_attribute("<script>var src = 1;</script>", "<script", "src"));
    CHECK(fetched_address(page).empty());
    CHECK(!tag_has_attribute(page, "<script", "src"));
    CHECK(!tag_has_attribute(page, "<link", "href"));
    CHECK(page.find("THREE.OrbitControls") != std::string::npos);  // the library is in the page

    const std::string data = page_data(page);
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
            const int id = uint32_at(ids, static_cast<std::size_t>(i));
            for (int a = 0; a < 3; ++a)
                CHECK(std::abs(decoded(i, a) - drawn(id, a)) <= bound[a] * (1 + 1e-6));
            moved = std::max(moved, (drawn.row(id) - vtu.points.row(id)).norm());
        }
    }
    CHECK(moved > 0.01);  // the beam swings: the frames differ
}

TEST_CASE("the web page's surface is the tets' boundary, coloured by the .vtu frames' field on the bar's range",
          "[scenes][web_page]")
{
    if (!have_three_js())
        return;
    // a point field (the displacement's magnitude) and a cell field (the stress, per triangle: its tet's)
    for (const std::string colour : {"displacement", "von Mises stress"}) {
        CAPTURE(colour);
        const auto [out, page] = cantilever_page(colour.substr(0, 4), "--set 'output.colour=" + colour + "'");
        const std::string data = page_data(page);
        CHECK(json_value(data, "field") == colour);
        const bool per_triangle = json_value(data, "colour_on") == "triangles";
        CHECK(per_triangle == (colour != "displacement"));
        const std::vector<double> range = json_array(json_value(data, "range"));
        REQUIRE((range.size() == 2 && range[1] > range[0]));
        const std::string ids = base64_decode(json_value(data, "point_ids"));
        const std::string triangles = base64_decode(json_value(data, "triangles"));
        const std::string colours = base64_decode(json_value(data, "colours"));
        const auto frames = io::read_pvd(out / "cantilever.pvd");
        const std::size_t points = ids.size() / 4, faces = triangles.size() / 12;
        REQUIRE(colours.size() == frames.size() * (per_triangle ? faces : points));
        for (std::size_t k = 0; k < frames.size(); ++k) {
            const io::MeshData vtu = io::read_vtu(out / frames[k].second);
            const skin::Boundary boundary = skin::boundary_faces(TetMesh{vtu.points, vtu.cells});
            REQUIRE(static_cast<std::size_t>(boundary.faces.rows()) == faces);
            const io::Field& field = vtu.field(colour);
            const auto expected = [&](Eigen::Index row) {
                const double value = field.values.row(row).norm();  // a scalar's absolute value: ≥ 0 here
                return std::lround(std::clamp((value - range[0]) / (range[1] - range[0]), 0.0, 1.0) * 255.0);
            };
            for (std::size_t f = 0; f < faces; ++f)
                for (int c = 0; c < 3; ++c)
                    CHECK(uint32_at(ids, static_cast<std::size_t>(uint32_at(triangles, 3 * f + c))) ==
                          boundary.faces(static_cast<Eigen::Index>(f), c));
            for (std::size_t i = 0; i < (per_triangle ? faces : points); ++i) {
                const long code = static_cast<unsigned char>(colours[k * (per_triangle ? faces : points) + i]);
                CHECK(std::abs(code - expected(per_triangle ? boundary.tet[i] : uint32_at(ids, i))) <= 1);
            }
        }
    }
}
