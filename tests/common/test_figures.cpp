// Figures: with a display, PNGs of the right size and with real content; without one, CSVs only.
#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iterator>
#include <set>

namespace {

/// The number of distinct RGB colours in a PNG, its size, and how many pixels within 4 pixels of
/// its edges are not the white background.
struct PngSummary {
    int width = 0, height = 0;
    std::size_t colours = 0;
    std::size_t marked_edge_pixels = 0;
    std::size_t text_pixels_right = 0;  ///< dark grey (text) pixels in the colour bar's label column
    std::size_t low_end_pixels = 0;     ///< pixels in viridis' purple low end (blue well above green)
};

PngSummary read_png(const std::filesystem::path& path)
{
    vtkNew<vtkPNGReader> reader;
    reader->SetFileName(path.c_str());
    reader->Update();
    vtkImageData* image = reader->GetOutput();
    PngSummary summary;
    int dims[3];
    image->GetDimensions(dims);
    summary.width = dims[0];
    summary.height = dims[1];
    vtkDataArray* pixels = image->GetPointData()->GetScalars();
    std::set<long> colours;
    for (vtkIdType i = 0; i < pixels->GetNumberOfTuples(); ++i) {
        long rgb = 0;
        for (int c = 0; c < 3; ++c)
            rgb = rgb * 256 + static_cast<long>(pixels->GetComponent(i, c));
        colours.insert(rgb);
        const int x = int(i % dims[0]), y = int(i / dims[0]);
        const bool at_edge = x < 4 || y < 4 || x >= dims[0] - 4 || y >= dims[1] - 4;
        if (at_edge && rgb != 0xFFFFFF)
            ++summary.marked_edge_pixels;
        // The labels of a colour bar: right of its strip (x ≥ 0.93 of the width, the strip ends
        // at about 0.92), over the strip's height (0.08 to 0.80 of the height, under its title).
        const double r = pixels->GetComponent(i, 0), g = pixels->GetComponent(i, 1), b = pixels->GetComponent(i, 2);
        const bool label_column = x >= 0.93 * dims[0] && y >= 0.08 * dims[1] && y <= 0.8 * dims[1];
        if (label_column && std::max({r, g, b}) < 90 && std::max({r, g, b}) - std::min({r, g, b}) < 10)
            ++summary.text_pixels_right;
        if (b > g + 40 && r > g)
            ++summary.low_end_pixels;
    }
    summary.colours = colours.size();
    return summary;
}

/// The figure-code version a PNG's "fem-figure-version" text chunk holds, or -1 without one.
int figure_version(const std::filesystem::path& path)
{
    std::ifstream file(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    const std::string key = std::string("tEXt") + fem::fig::figure_version_key + '\0';
    const std::size_t at = bytes.find(key);
    if (at == std::string::npos)
        return -1;
    std::size_t end = at + key.size();
    while (end < bytes.size() && std::isdigit(static_cast<unsigned char>(bytes[end])))
        ++end;
    return end > at + key.size() ? std::stoi(bytes.substr(at + key.size(), end - at - key.size())) : -1;
}

}  // namespace

TEST_CASE("a log-log chart is saved as CSV always and as PNG when a display exists", "[common][figures]")
{
    const auto dir = fem::test::fresh_output_dir("chart");
    fem::fig::LineChart chart{"error against h", "h", "error", true, true, {}};
    std::vector<double> h, e1, e2;
    for (int k = 1; k <= 12; ++k) {
        h.push_back(std::pow(10.0, -k));
        e1.push_back(h.back() + 1e-16 / h.back());
        e2.push_back(h.back() * h.back());
    }
    e2[3] = 0.0;  // a zero cannot be drawn on a log axis: kept in the CSV, left out of the PNG
    chart.series = {{"forward", h, e1}, {"central", h, e2}};
    const bool drew = fem::fig::save_chart(chart, dir / "errors");

    std::ifstream csv(dir / "errors.csv");
    int lines = 0;
    for (std::string line; std::getline(csv, line);)
        ++lines;
    CHECK(lines == 1 + 24);
    CHECK(drew == fem::fig::display_available());
    CHECK(std::filesystem::exists(dir / "errors.png") == drew);
    if (drew) {
        const auto png = read_png(dir / "errors.png");
        CHECK(png.width == chart.width * fem::fig::pixel_scale);  // slide resolution
        CHECK(png.height == chart.height * fem::fig::pixel_scale);
        CHECK((png.width == 1920 && png.height == 1080));  // by default a full 16:9 slide
        CHECK(figure_version(dir / "errors.png") == fem::fig::figure_code_version);
        std::ifstream svg(dir / "errors.svg");  // the vector twin, with the series' names as text
        const std::string text((std::istreambuf_iterator<char>(svg)), std::istreambuf_iterator<char>());
        CHECK(text.find("</svg>") != std::string::npos);
        CHECK(text.find("forward") != std::string::npos);
        CHECK(png.colours > 20);  // lines, labels and legend, not a blank canvas
        CHECK(png.marked_edge_pixels == 0);  // no text runs into the window's edge and is cut there
    }
    CHECK_FALSE(fem::fig::save_chart(chart, dir / "no_png", false));
    CHECK_FALSE(std::filesystem::exists(dir / "no_png.png"));

    chart.series[0].y.pop_back();
    CHECK_THROWS_AS(fem::fig::save_chart(chart, dir / "bad"), fem::Error);
}

TEST_CASE("a mesh coloured by a field renders with its scalar bar", "[common][figures]")
{
    const auto dir = fem::test::fresh_output_dir("render");
    fem::io::MeshData mesh;
    const int n = 10;
    mesh.points.resize(n * n, 3);
    Eigen::MatrixXd u(n * n, 1);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            mesh.points.row(j * n + i) << i / (n - 1.0), j / (n - 1.0), 0.0;
            u(j * n + i) = std::sin(3.0 * i / n) * std::cos(2.0 * j / n);
        }
    mesh.cells.resize(2 * (n - 1) * (n - 1), 3);
    int t = 0;
    for (int j = 0; j + 1 < n; ++j)
        for (int i = 0; i + 1 < n; ++i) {
            const int a = j * n + i;
            mesh.cells.row(t++) << a, a + 1, a + n + 1;
            mesh.cells.row(t++) << a, a + n + 1, a + n;
        }
    mesh.point_data = {{"u", u}};

    fem::fig::RenderOptions options;
    options.title = "u on a square";
    options.field = "u";
    options.show_edges = true;
    const bool drew = fem::fig::render_mesh_png(dir / "square.png", mesh, options);
    CHECK(drew == fem::fig::display_available());
    if (drew) {
        const auto png = read_png(dir / "square.png");
        CHECK(png.width == options.width * options.scale);
        CHECK(figure_version(dir / "square.png") == fem::fig::figure_code_version);
        CHECK(png.colours > 50);  // a colour ramp, not a flat fill
        CHECK(png.text_pixels_right > 100);  // the bar's labels are written (VTK's own are transparent)
    }

    // One spike sets the scale: nearly the whole square takes the low end's purple, unless the
    // range is clipped at a percentile, which spreads the colours over the rest again.
    mesh.point_data[0].values(n * n / 2 + n / 2) = 1e3;
    const bool spiked = fem::fig::render_mesh_png(dir / "spike.png", mesh, options);
    options.clip_percentile = 90.0;
    fem::fig::render_mesh_png(dir / "spike_clipped.png", mesh, options);
    if (spiked) {
        const auto full = read_png(dir / "spike.png"), clipped = read_png(dir / "spike_clipped.png");
        CHECK(clipped.low_end_pixels * 3 < full.low_end_pixels);
    }
    options.clip_percentile = 100.0;
    options.field = "no_such_field";
    CHECK_THROWS_AS(fem::fig::render_mesh_png(dir / "bad.png", mesh, options), fem::Error);
    CHECK_FALSE(std::filesystem::exists(dir / "bad.png"));
}

TEST_CASE("tick labels: one notation per axis, a true minus sign for negative values", "[common][figures]")
{
    using fem::fig::tick_labels;
    const std::string minus = "\u2212";
    CHECK(tick_labels({-0.5, 0.0, 0.5}) == std::vector<std::string>{minus + "0.5", "0", "0.5"});
    CHECK(tick_labels({-2e-3, 1e-3}) == std::vector<std::string>{minus + "0.002", "0.001"});
    // powers of ten for all when one tick is outside [0.001, 100000): the sign before the mantissa
    CHECK(tick_labels({-2e-6, 0.0, 1e-6}) ==
          std::vector<std::string>{minus + "2\u00B710\u207B\u2076", "0", "10\u207B\u2076"});
    CHECK(tick_labels({-1e5, 1.5e5}) == std::vector<std::string>{minus + "10\u2075", "1.5\u00B710\u2075"});
    for (const std::string& label : tick_labels({-3.0, -2e-7, -4e8}))
        CHECK(label.find('-') == std::string::npos);  // never a hyphen
}

TEST_CASE("percentiles and the note of a clipped colour bar", "[common][figures]")
{
    using fem::fig::percentile;
    CHECK(percentile({5, 1, 3, 2, 4}, 100) == 5);
    CHECK(percentile({5, 1, 3, 2, 4}, 60) == 3);  // 3 of 5 values at or below it
    CHECK(percentile({5, 1, 3, 2, 4}, 1) == 1);
    CHECK_THROWS_AS(percentile({}, 50), fem::Error);
    CHECK_THROWS_AS(percentile({1.0}, 0), fem::Error);
    CHECK_THROWS_AS(percentile({1.0}, 101), fem::Error);
    CHECK(fem::fig::clip_note(99, 66512.3, "Pa") == "clipped at the 99th percentile\nmax 66500 Pa");
    CHECK(fem::fig::clip_note(92, 2.04e-6, "m") == "clipped at the 92nd percentile\nmax 2.04\u00B710\u207B\u2076 m");
}
