// The web page of a run: frames quantised, base64 in a page with three.js inlined.
// docs/scenes.md#the-web-page
#include "scenes/web_page.hpp"

#include "scenes/frame_look.hpp"
#include "scenes/run_outputs.hpp"

#include "13_skinning/skinning.hpp"

#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/files.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>

namespace fem::scenes {

namespace {

// Debian's libjs-three (r111), the one JavaScript library the page inlines.
const std::filesystem::path three_js = "/usr/share/javascript/three/three.min.js";
const std::filesystem::path orbit_controls_js = "/usr/share/javascript/three/examples/js/controls/OrbitControls.js";

constexpr std::string_view base64_alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

}  // namespace

QuantisedPositions quantise_positions(const std::vector<MatrixX3d>& frames)
{
    if (frames.empty())
        throw Error("quantise_positions: no frames");
    QuantisedPositions q;
    q.points = frames.front().rows();
    q.low.setConstant(std::numeric_limits<double>::infinity());
    q.high.setConstant(-std::numeric_limits<double>::infinity());
    for (std::size_t k = 0; k < frames.size(); ++k) {
        if (frames[k].rows() != q.points)
            throw Error(str("quantise_positions: frame ", k, " has ", frames[k].rows(), " points, frame 0 has ", q.points));
        for (Eigen::Index p = 0; p < q.points; ++p)
            if (!frames[k].row(p).allFinite())
                throw Error(str("quantise_positions: frame ", k, ", point ", p, ": a position that is not finite"));
        if (q.points > 0) {
            q.low = q.low.cwiseMin(frames[k].colwise().minCoeff().transpose());
            q.high = q.high.cwiseMax(frames[k].colwise().maxCoeff().transpose());
        }
    }
    if (q.points == 0) {
        q.low.setZero();
        q.high.setZero();
    }
    q.codes.reserve(frames.size() * static_cast<std::size_t>(q.points) * 3);
    for (const MatrixX3d& frame : frames)
        for (Eigen::Index p = 0; p < q.points; ++p)
            for (int a = 0; a < 3; ++a) {
                const double extent = q.high[a] - q.low[a];
                const double code = extent > 0.0 ? std::round((frame(p, a) - q.low[a]) / extent * quantisation_levels) : 0.0;
                q.codes.push_back(static_cast<std::uint16_t>(std::clamp(code, 0.0, double(quantisation_levels))));
            }
    return q;
}

MatrixX3d dequantise_frame(const QuantisedPositions& q, std::size_t k)
{
    if (k >= q.frames())
        throw Error(str("dequantise_frame: frame ", k, " of ", q.frames()));
    MatrixX3d x(q.points, 3);
    const std::size_t first = k * static_cast<std::size_t>(q.points) * 3;
    for (Eigen::Index p = 0; p < q.points; ++p)
        for (int a = 0; a < 3; ++a)
            x(p, a) = q.low[a] + q.codes[first + 3 * static_cast<std::size_t>(p) + a] * ((q.high[a] - q.low[a]) / quantisation_levels);
    return x;
}

Eigen::Vector3d quantisation_bound(const QuantisedPositions& q)
{
    return 0.5 * (q.high - q.low) / quantisation_levels;
}

std::string base64_encode(std::string_view bytes)
{
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
        std::uint32_t group = 0;
        for (std::size_t j = 0; j < 3; ++j)
            group = (group << 8) | (j < n ? static_cast<unsigned char>(bytes[i + j]) : 0u);
        for (std::size_t j = 0; j < 4; ++j)
            out += j <= n ? base64_alphabet[(group >> (18 - 6 * j)) & 63u] : '=';
    }
    return out;
}

std::string base64_decode(std::string_view text)
{
    if (text.size() % 4 != 0)
        throw Error(str("base64: a length that is a multiple of 4 expected, got ", text.size(), " characters"));
    std::string out;
    out.reserve(text.size() / 4 * 3);
    for (std::size_t i = 0; i < text.size(); i += 4) {
        std::uint32_t group = 0;
        int padding = 0;
        for (std::size_t j = 0; j < 4; ++j) {
            const char c = text[i + j];
            const std::size_t value = base64_alphabet.find(c);
            const bool pad = c == '=' && i + 4 == text.size() && j >= 2 && (j == 3 || text[i + 3] == '=');
            if (value == std::string_view::npos && !pad)
                throw Error(str("base64: character ", i + j, " ('", c, "') is not in A-Z, a-z, 0-9, +, / or final '=' padding"));
            padding += pad ? 1 : 0;
            group = (group << 6) | (pad ? 0u : static_cast<std::uint32_t>(value));
        }
        for (int j = 0; j < 3 - padding; ++j)
            out += static_cast<char>((group >> (16 - 8 * j)) & 255u);
    }
    return out;
}

QuantisedPositions positions_from_bytes(std::string_view bytes, const Eigen::Vector3d& low, const Eigen::Vector3d& high,
                                        Eigen::Index points)
{
    const std::size_t frame_bytes = 6 * static_cast<std::size_t>(points);
    if (frame_bytes == 0 || bytes.size() % frame_bytes != 0)
        throw Error(str("positions: ", bytes.size(), " bytes are not whole frames of ", points, " points (6 bytes each)"));
    QuantisedPositions q{low, high, points, std::vector<std::uint16_t>(bytes.size() / 2)};
    for (std::size_t i = 0; i < q.codes.size(); ++i)
        q.codes[i] = static_cast<std::uint16_t>(static_cast<unsigned char>(bytes[2 * i]) |
                                                (static_cast<unsigned char>(bytes[2 * i + 1]) << 8));
    return q;
}

void check_web_page_library()
{
    for (const std::filesystem::path& file : {three_js, orbit_controls_js})
        if (!std::filesystem::is_regular_file(file))
            throw Error(str("--html: the page inlines three.js from Debian's libjs-three, and ", file.string(),
                            " is missing: install it (tools/setup.sh, or apt-get install libjs-three)"));
}

namespace {

/// The whole of a script file the page inlines; fem::Error naming it when it cannot be read.
std::string read_script_file(const std::filesystem::path& file)
{
    std::ifstream in(file, std::ios::binary);
    if (!in)
        throw Error(str("cannot read ", file.string()));
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// A JSON string literal of text (UTF-8 kept; quotes, backslashes and control characters escaped,
/// and '<' as \u003c, so that no "</script>" can end the data's script element).
std::string json_string(const std::string& text)
{
    std::string out = "\"";
    for (const char c : text) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (c == '\n') {
            out += "\\n";
        } else if (static_cast<unsigned char>(c) < 0x20 || c == '<') {
            char escaped[8];
            std::snprintf(escaped, sizeof escaped, "\\u%04x", static_cast<unsigned char>(c));
            out += escaped;
        } else {
            out += c;
        }
    }
    return out + "\"";
}

/// A JSON number with `digits` significant digits (a value that is not finite: 0, never NaN in JSON).
std::string json_number(double value, int digits = 9)
{
    std::ostringstream out;
    out.precision(digits);
    out << (std::isfinite(value) ? value : 0.0);
    return out.str();
}

/// "[a, b, …]" of numbers.
template <typename Range>
std::string json_numbers(const Range& values, int digits = 9)
{
    std::string out = "[";
    for (const auto& v : values)
        out += (out.size() > 1 ? "," : "") + json_number(double(v), digits);
    return out + "]";
}

/// The bytes of values, little-endian (the page reads them as typed arrays on a little-endian
/// machine: every browser's).
template <typename T>
std::string le_bytes(const std::vector<T>& values)
{
    std::string out;
    out.reserve(values.size() * sizeof(T));
    for (const T& v : values)
        for (std::size_t b = 0; b < sizeof(T); ++b)
            out += static_cast<char>((static_cast<std::uint64_t>(v) >> (8 * b)) & 255u);
    return out;
}

/// The bytes of a float32 array of values, little-endian.
std::string float32_bytes(const MatrixX3d& points)
{
    std::vector<std::uint32_t> bits;
    for (Eigen::Index p = 0; p < points.rows(); ++p)
        for (int a = 0; a < 3; ++a) {
            const float f = static_cast<float>(points(p, a));
            std::uint32_t b;
            std::memcpy(&b, &f, sizeof b);
            bits.push_back(b);
        }
    return le_bytes(bits);
}

/// The triangle indices of cells (#F×3) as uint32 bytes.
std::string triangle_bytes(const MatrixXiR& cells)
{
    std::vector<std::uint32_t> indices;
    for (Eigen::Index f = 0; f < cells.rows(); ++f)
        for (Eigen::Index c = 0; c < cells.cols(); ++c)
            indices.push_back(static_cast<std::uint32_t>(cells(f, c)));
    return le_bytes(indices);
}

/// The shown value of each row of a field: the value of a scalar, the magnitude of a vector.
Eigen::VectorXd shown_values(const io::Field& field)
{
    return field.values.cols() == 1 ? Eigen::VectorXd(field.values.col(0)) : Eigen::VectorXd(field.values.rowwise().norm());
}

/// Replaces the one placeholder in page by text (fem::Error if it is not there: a bug).
void fill(std::string& page, const std::string& placeholder, const std::string& text)
{
    const std::size_t at = page.find(placeholder);
    if (at == std::string::npos)
        throw Error(str("web page template: no ", placeholder));
    page.replace(at, placeholder.size(), text);
}

/// The player: HTML, CSS and JavaScript around the placeholders @TITLE@, @THREE@, @ORBIT@ and @DATA@.
extern const char* const player_template;

}  // namespace

WebPage::WebPage(const SceneSpec& scene) : scene_(scene) {}

void WebPage::add_frame(const io::MeshData& frame, double time, const std::string& models)
{
    const io::MeshData drawn = io::warped(frame, scene_.output.warp);
    if (positions_.empty()) {  // the surface, once: the boundary of every body's tets
        TetMesh mesh{frame.points, frame.cells};
        const skin::Boundary boundary = skin::boundary_faces(mesh);
        std::vector<int> index(static_cast<std::size_t>(frame.points.rows()), -1);
        triangles_.resize(boundary.faces.rows(), 3);
        for (Eigen::Index f = 0; f < boundary.faces.rows(); ++f)
            for (int c = 0; c < 3; ++c) {
                int& i = index[static_cast<std::size_t>(boundary.faces(f, c))];
                if (i < 0) {
                    i = static_cast<int>(surface_points_.size());
                    surface_points_.push_back(boundary.faces(f, c));
                }
                triangles_(f, c) = i;
            }
        triangle_cells_ = boundary.tet;
        rest_.resize(static_cast<Eigen::Index>(surface_points_.size()), 3);
        for (std::size_t i = 0; i < surface_points_.size(); ++i)
            rest_.row(static_cast<Eigen::Index>(i)) = frame.points.row(surface_points_[i]);
        cell_field_ = std::any_of(frame.cell_data.begin(), frame.cell_data.end(),
                                  [&](const io::Field& f) { return f.name == scene_.output.colour; });
    }
    MatrixX3d x(static_cast<Eigen::Index>(surface_points_.size()), 3);
    for (std::size_t i = 0; i < surface_points_.size(); ++i)
        x.row(static_cast<Eigen::Index>(i)) = drawn.points.row(surface_points_[i]);
    positions_.push_back(std::move(x));
    const Eigen::VectorXd all = shown_values(frame.field(scene_.output.colour));
    values_.push_back(all);
    times_.push_back(time);
    captions_.push_back(frame_title(scene_, models, time));
}

Eigen::Vector3d WebPage::write(const std::filesystem::path& path, const std::vector<std::vector<dynamics::StepRecord>>& records) const
{
    check_web_page_library();
    const QuantisedPositions q = quantise_positions(positions_);
    // The colour range, as the PNG frames take it (MotionRecorder's): the scene's, or the run's,
    // its top clipped at the field's percentile (the stress's 99th) with a note saying so.
    const fig::RenderOptions view = frame_view(scene_);
    std::pair<double, double> range;
    std::string note;
    if (scene_.output.colour_range) {
        range = *scene_.output.colour_range;
    } else {
        std::vector<double> pooled;
        for (const Eigen::VectorXd& v : values_)
            pooled.insert(pooled.end(), v.data(), v.data() + v.size());
        range = {*std::min_element(pooled.begin(), pooled.end()), *std::max_element(pooled.begin(), pooled.end())};
        const double top = fig::percentile(pooled, view.clip_percentile);
        if (top < range.second && top > range.first) {
            note = fig::clip_note(view.clip_percentile, range.second, view.unit);
            range.second = top;
        }
    }
    // The colours: 8 bits over the range, per triangle (a cell field) or surface vertex, frame-major.
    std::vector<std::uint8_t> colours;
    const double span = range.second > range.first ? range.second - range.first : 1.0;
    for (const Eigen::VectorXd& v : values_) {
        const auto code = [&](double value) {
            return static_cast<std::uint8_t>(std::lround(std::clamp((value - range.first) / span, 0.0, 1.0) * 255.0));
        };
        if (cell_field_)
            for (const int tet : triangle_cells_)
                colours.push_back(code(v[tet]));
        else
            for (const int p : surface_points_)
                colours.push_back(code(v[p]));
    }
    // The obstacles at t = 0 (each moves by t·w), drawn under the motion's box as the PNGs draw them;
    // the camera frames the motion and the obstacles at every frame, or the scene's frame_box.
    std::array<double, 6> box{q.low.x(), q.high.x(), q.low.y(), q.high.y(), q.low.z(), q.high.z()};
    const bool outline = scene_.output.warp != 1.0;  // the rest shape under an exaggerated motion
    if (outline)
        fig::grow_bounds(box, rest_);
    const std::array<double, 6> motion_box = box;
    for (const double t : times_)
        for (const fig::Prop& prop : obstacle_props(scene_, motion_box, t))
            fig::grow_bounds(box, prop.shape.points);
    const std::array<double, 6> view_box = scene_.output.frame_box.value_or(box);
    std::string obstacles = "[";
    const std::vector<fig::Prop> props = obstacle_props(scene_, motion_box, 0.0);
    for (std::size_t i = 0; i < props.size(); ++i)
        obstacles += str(i > 0 ? "," : "", "{\"positions\":\"", base64_encode(float32_bytes(props[i].shape.points)),
                         "\",\"triangles\":\"", base64_encode(triangle_bytes(props[i].shape.cells)),
                         "\",\"velocity\":", json_numbers(scene_.obstacles[i].obstacle->velocity()), ",\"colour\":",
                         json_numbers(props[i].colour, 4), "}");
    obstacles += "]";
    // The energy plot: each body's kinetic and elastic energy and H − W_in (the chart energies's
    // series), at most about 2000 steps of each (every k-th step, and the last).
    std::string series = "[";
    std::vector<double> energy_times;
    const std::size_t steps = records.empty() ? 0 : records.front().size();
    const std::size_t every = std::max<std::size_t>(1, steps / 2000);
    for (std::size_t s = 0; s < steps; s += every)
        energy_times.push_back(records.front()[s].time);
    if (steps > 0 && (steps - 1) % every != 0)
        energy_times.push_back(records.front().back().time);
    for (std::size_t b = 0; b < records.size(); ++b) {
        std::array<std::vector<double>, 3> values;
        const auto sample = [&](const dynamics::StepRecord& r) {
            values[0].push_back(r.energies.kinetic);
            values[1].push_back(r.energies.elastic);
            values[2].push_back(r.energies.total() - r.work_in);
        };
        for (std::size_t s = 0; s < records[b].size(); s += every)
            sample(records[b][s]);
        if (!records[b].empty() && (records[b].size() - 1) % every != 0)
            sample(records[b].back());
        const std::string& name = scene_.bodies[b].name;
        const std::array<std::string, 3> labels{name + " kinetic", name + " elastic", name + " H - W_in"};
        for (int i = 0; i < 3; ++i)
            series += str(series.size() > 1 ? "," : "", "{\"name\":", json_string(labels[i]),
                          ",\"values\":", json_numbers(values[i], 6), "}");
    }
    series += "]";
    std::string caption_list = "[";
    for (const std::string& caption : captions_)
        caption_list += (caption_list.size() > 1 ? "," : "") + json_string(caption);
    caption_list += "]";
    const std::vector<std::uint32_t> triangles(triangles_.data(), triangles_.data() + triangles_.size());
    const std::vector<std::uint32_t> points(surface_points_.begin(), surface_points_.end());
    const std::string data = str(
        "{\"format\":\"fem-scene-page 1\",\"title\":", json_string(scene_.title),
        ",\"frames\":", times_.size(), ",\"times\":", json_numbers(times_),
        ",\"fps\":", json_number(video_frame_rate(static_cast<int>(times_.size()), scene_.output)),
        ",\"captions\":", caption_list,
        ",\"field\":", json_string(scene_.output.colour), ",\"unit\":", json_string(view.unit),
        ",\"range\":", json_numbers(std::array<double, 2>{range.first, range.second}), ",\"range_note\":", json_string(note),
        ",\"colour_on\":\"", cell_field_ ? "triangles" : "points", "\"",
        ",\"warp\":", json_number(scene_.output.warp, 17), ",\"points\":", q.points, ",\"point_ids\":\"", base64_encode(le_bytes(points)), "\"",
        ",\"triangles\":\"", base64_encode(le_bytes(triangles)), "\"",
        ",\"low\":", json_numbers(q.low, 17), ",\"high\":", json_numbers(q.high, 17),
        ",\"positions\":\"", base64_encode(le_bytes(q.codes)), "\"",
        ",\"colours\":\"", base64_encode(le_bytes(colours)), "\"",
        ",\"view_box\":", json_numbers(view_box, 17),
        ",\"view_direction\":", json_numbers(scene_.output.view_direction),
        ",\"view_up\":", json_numbers(scene_.output.view_up),
        ",\"obstacles\":", obstacles,
        ",\"rest\":\"", outline ? base64_encode(float32_bytes(rest_)) : std::string(), "\"",
        ",\"energy\":{\"times\":", json_numbers(energy_times), ",\"series\":", series, "}}");
    std::string page = player_template;
    std::string title = scene_.title;
    for (const auto& [from, to] : {std::pair<char, std::string>{'&', "&amp;"}, {'<', "&lt;"}, {'>', "&gt;"}})
        for (std::size_t at = title.find(from); at != std::string::npos; at = title.find(from, at + to.size()))
            title.replace(at, 1, to);
    // From the last placeholder to the first: what is filled in never holds the next one searched.
    fill(page, "@DATA@", data);
    fill(page, "@ORBIT@", read_script_file(orbit_controls_js));
    fill(page, "@THREE@", read_script_file(three_js));
    fill(page, "@TITLE@", title);
    write_file(path, page);
    return quantisation_bound(q);
}

namespace {

const char* const player_template = R"page(<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>@TITLE@</title>
<!-- Written by fem_scene --html (docs/scenes.md#the-web-page). Self-contained: three.js r111
     (MIT License, Copyright 2010-2019 three.js authors) is inlined from Debian's libjs-three. -->
<style>
html, body { margin: 0; height: 100%; overflow: hidden; background: #fff; color: #222;
             font-family: "DejaVu Sans", Helvetica, Arial, sans-serif; }
#view { position: absolute; left: 0; top: 0; width: 68%; bottom: 52px; }
#caption { position: absolute; left: 0; top: 0; width: 68%; padding-top: 6px; text-align: center;
           white-space: pre-line; font-size: 15px; pointer-events: none; }
#side { position: absolute; right: 0; top: 0; width: 32%; bottom: 52px; box-sizing: border-box;
        padding: 10px 12px; border-left: 1px solid #ddd; overflow: hidden; font-size: 13px; }
#legend { display: flex; align-items: stretch; gap: 8px; height: 38%; }
#bar { width: 22px; height: 100%; border: 1px solid #888; box-sizing: border-box; }
#ticks { position: relative; width: 90px; }
#ticks div { position: absolute; left: 0; transform: translateY(-50%); }
#bar-text { flex: 1; white-space: pre-line; }
#energy { width: 100%; height: 42%; margin-top: 10px; }
#series { font-size: 11px; line-height: 1.5; max-height: 12%; overflow-y: auto; }
#series .body { display: flex; flex-wrap: wrap; gap: 0 10px; }
#series button { font: inherit; border: 0; background: none; padding: 0; cursor: pointer; color: inherit; }
#series .name { font-weight: bold; min-width: 3em; text-align: left; }
#series .swatch { display: inline-block; width: 14px; height: 3px; vertical-align: middle; margin-right: 3px; }
#series .off { opacity: 0.35; text-decoration: line-through; }
#help { color: #666; font-size: 12px; margin-top: 4px; }
#controls { position: absolute; left: 0; right: 0; bottom: 0; height: 52px; display: flex; align-items: center;
            gap: 8px; padding: 0 12px; border-top: 1px solid #ddd; box-sizing: border-box; }
#controls button { font-size: 16px; min-width: 40px; }
#slider { flex: 1; }
#frame-label { min-width: 170px; text-align: right; font-variant-numeric: tabular-nums; }
#nogl { position: absolute; left: 10%; top: 40%; width: 48%; font-size: 18px; display: none; }
</style>
</head>
<body>
<div id="view"></div>
<div id="caption"></div>
<div id="nogl">This page draws the run with WebGL, which this browser has switched off.</div>
<div id="side">
  <div id="legend"><canvas id="bar" width="1" height="256"></canvas><div id="ticks"></div><div id="bar-text"></div></div>
  <svg id="energy" xmlns="http://www.w3.org/2000/svg"></svg>
  <div id="series"></div>
  <div id="help">space: play/pause · ← →: one frame · Home/End: first/last · drag: orbit · wheel: zoom ·
    right-drag: pan · #frame=N in the address: open at frame N, paused</div>
</div>
<div id="controls">
  <button id="first" title="first frame (Home)">|◀</button>
  <button id="back" title="one frame back (←)">◀</button>
  <button id="play" title="play/pause (space)">▶</button>
  <button id="forward" title="one frame on (→)">▶|</button>
  <input id="slider" type="range" min="0" value="0" step="1">
  <span id="frame-label"></span>
</div>
<script>@THREE@</script>
<script>@ORBIT@</script>
<script type="application/json" id="fem-data">@DATA@</script>
<script>
"use strict";
(function () {
  const D = JSON.parse(document.getElementById("fem-data").textContent);
  const buffer = (b64) => { const s = atob(b64), a = new Uint8Array(s.length);
                            for (let i = 0; i < s.length; ++i) a[i] = s.charCodeAt(i); return a.buffer; };
  const N = D.frames, P = D.points;
  const codes = new Uint16Array(buffer(D.positions));   // frame-major, point, x y z (16 bits over low..high)
  const tri = new Uint32Array(buffer(D.triangles));     // surface triangles, into the P points
  const colours = new Uint8Array(buffer(D.colours));    // 8 bits over D.range, per triangle or point
  const F = tri.length / 3, perTriangle = D.colour_on === "triangles";
  const step = [0, 1, 2].map((a) => (D.high[a] - D.low[a]) / 65535);
  // frame k's surface vertices as drawn, x y z each, decoded into out (3P numbers): low + code · step
  function decode(k, out) {
    const base = 3 * P * k;
    for (let i = 0; i < 3 * P; ++i) out[i] = D.low[i % 3] + codes[base + i] * step[i % 3];
    return out;
  }

  // viridis, five stops interpolated in RGB (as the PNG frames' colour map, common/figures_mesh.cpp)
  const stops = [[0.267, 0.005, 0.329], [0.229, 0.322, 0.546], [0.128, 0.567, 0.551], [0.369, 0.789, 0.383], [0.993, 0.906, 0.144]];
  const viridis = (s) => { const x = Math.min(Math.max(s, 0), 1) * 4, i = Math.min(Math.floor(x), 3), f = x - i;
                           return [0, 1, 2].map((c) => stops[i][c] + f * (stops[i + 1][c] - stops[i][c])); };
  const lut = []; for (let c = 0; c < 256; ++c) lut.push(viridis(c / 255));

  // the colour bar and its ticks
  const bar = document.getElementById("bar"), g = bar.getContext("2d");
  for (let y = 0; y < 256; ++y) { const c = lut[255 - y];
    g.fillStyle = "rgb(" + c.map((v) => Math.round(255 * v)).join(",") + ")"; g.fillRect(0, y, 1, 1); }
  const fmt = (v) => { if (v === 0) return "0"; const a = Math.abs(v);
                       return a >= 1e-3 && a < 1e5 ? String(Number(v.toPrecision(3))) : v.toExponential(2); };
  const ticks = document.getElementById("ticks");
  for (let i = 0; i <= 4; ++i) { const d = document.createElement("div");
    d.style.top = (100 - 25 * i) + "%"; d.textContent = fmt(D.range[0] + (D.range[1] - D.range[0]) * i / 4); ticks.appendChild(d); }
  document.getElementById("bar-text").textContent = D.field + (D.unit ? " [" + D.unit + "]" : "") + (D.range_note ? "\n" + D.range_note : "");

  // the 3D view: { draw(k), resize() }, or null without WebGL (the page then says so, and plays the
  // caption and the energy plot alone)
  const view = document.getElementById("view");
  const view3d = (function () {
    let renderer;
    try { renderer = new THREE.WebGLRenderer({ antialias: true }); }
    catch (e) { document.getElementById("nogl").style.display = "block"; return null; }
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.setClearColor(0xffffff);
    view.appendChild(renderer.domElement);
    const scene = new THREE.Scene();
    const camera = new THREE.PerspectiveCamera(30, 1, 1e-3, 1e3);
    const light = new THREE.DirectionalLight(0xffffff, 0.75);
    scene.add(new THREE.AmbientLight(0xffffff, 0.35), light, light.target);

    // the bodies' surface: one vertex per triangle corner (flat facets, a colour per triangle)
    const position = new Float32Array(9 * F), colour = new Float32Array(9 * F);
    const body = new THREE.BufferGeometry();
    body.setAttribute("position", new THREE.BufferAttribute(position, 3));
    body.setAttribute("color", new THREE.BufferAttribute(colour, 3));
    scene.add(new THREE.Mesh(body, new THREE.MeshLambertMaterial({ vertexColors: THREE.VertexColors, side: THREE.DoubleSide,
                                                                   polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 })));

    // the surface's edges, dark grey, as the PNG frames draw them (each edge once)
    const edgeEnds = [], seen = new Set();
    for (let f = 0; f < F; ++f) for (let c = 0; c < 3; ++c) {
      const a = tri[3 * f + c], b = tri[3 * f + (c + 1) % 3], key = Math.min(a, b) * P + Math.max(a, b);
      if (!seen.has(key)) { seen.add(key); edgeEnds.push(a, b); }
    }
    const edgePosition = new Float32Array(3 * edgeEnds.length), vertex = new Float32Array(3 * P);
    const edges = new THREE.BufferGeometry();
    edges.setAttribute("position", new THREE.BufferAttribute(edgePosition, 3));
    scene.add(new THREE.LineSegments(edges, new THREE.LineBasicMaterial({ color: 0x404040 })));

    // under an exaggerated motion (output.warp), the body at rest, faint grey behind the body as in the
    // PNG frames: a scene of its own, drawn first, its depth cleared before the body is drawn over it
    const restScene = new THREE.Scene(), restLight = new THREE.DirectionalLight(0xffffff, 0.75);
    restScene.add(new THREE.AmbientLight(0xffffff, 0.35), restLight, restLight.target);
    if (D.rest) {
      const rest = new THREE.BufferGeometry();
      rest.setAttribute("position", new THREE.BufferAttribute(new Float32Array(buffer(D.rest)), 3));
      rest.setIndex(new THREE.BufferAttribute(tri, 1));
      rest.computeVertexNormals();
      restScene.add(new THREE.Mesh(rest, new THREE.MeshLambertMaterial({ color: 0xe0e0e0, side: THREE.DoubleSide })));
    }
    renderer.autoClear = false;

    // the obstacles, grey, each moved by t·w
    const obstacles = D.obstacles.map((o) => {
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute("position", new THREE.BufferAttribute(new Float32Array(buffer(o.positions)), 3));
      geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(buffer(o.triangles)), 1));
      geometry.computeVertexNormals();
      const mesh = new THREE.Mesh(geometry, new THREE.MeshLambertMaterial({ color: new THREE.Color(o.colour[0], o.colour[1], o.colour[2]), side: THREE.DoubleSide }));
      scene.add(mesh);
      return { mesh: mesh, velocity: o.velocity };
    });

    // the camera looks along view_direction with view_up, framing view_box
    const b = D.view_box, center = new THREE.Vector3((b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2);
    const radius = Math.max(0.5 * Math.hypot(b[1] - b[0], b[3] - b[2], b[5] - b[4]), 1e-9);
    const direction = new THREE.Vector3().fromArray(D.view_direction).normalize();
    const distance = radius / Math.sin(Math.PI / 12);  // the box's sphere in the field of view of 30°
    camera.up.fromArray(D.view_up).normalize();
    camera.position.copy(center).addScaledVector(direction, -distance);
    camera.near = distance / 100; camera.far = distance * 100;
    const controls = new THREE.OrbitControls(camera, renderer.domElement);
    controls.target.copy(center);
    controls.update();

    function render() {
      light.position.copy(camera.position).addScaledVector(camera.up, 0.5 * distance);  // a headlight, a little above
      light.target.position.copy(controls.target);
      restLight.position.copy(light.position);
      restLight.target.position.copy(light.target.position);
      renderer.clear();
      renderer.render(restScene, camera);
      renderer.clearDepth();
      renderer.render(scene, camera);
    }
    function resize() {
      const w = view.clientWidth, h = view.clientHeight;
      renderer.setSize(w, h); camera.aspect = w / Math.max(h, 1); camera.updateProjectionMatrix(); render();
    }
    // frame k: positions decoded, colours looked up, obstacles moved
    function draw(k) {
      decode(k, vertex);
      for (let f = 0; f < F; ++f) for (let c = 0; c < 3; ++c) {
        const p = tri[3 * f + c], o = 9 * f + 3 * c;
        for (let a = 0; a < 3; ++a) position[o + a] = vertex[3 * p + a];
        const rgb = lut[perTriangle ? colours[F * k + f] : colours[P * k + p]];
        colour[o] = rgb[0]; colour[o + 1] = rgb[1]; colour[o + 2] = rgb[2];
      }
      for (let e = 0; e < edgeEnds.length; ++e) for (let a = 0; a < 3; ++a) edgePosition[3 * e + a] = vertex[3 * edgeEnds[e] + a];
      body.attributes.position.needsUpdate = true; body.attributes.color.needsUpdate = true;
      edges.attributes.position.needsUpdate = true; edges.computeBoundingSphere();
      body.computeVertexNormals(); body.computeBoundingSphere();
      const time = D.times[k];
      for (const o of obstacles) o.mesh.position.set(time * o.velocity[0], time * o.velocity[1], time * o.velocity[2]);
      render();
    }
    controls.addEventListener("change", render);
    return { draw: draw, resize: resize };
  })();
  window.addEventListener("resize", () => { if (view3d) view3d.resize(); plot(); });

  // the energy plot: an SVG of each series over time, a cursor at the frame's time; its legend below it,
  // a row per body ("bottom: kinetic elastic H - W_in"): a click on a series hides or shows it, on a
  // body's name all of its series (the plot's range follows the series shown)
  const svg = document.getElementById("energy"), NS = "http://www.w3.org/2000/svg";
  const palette = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf", "#7f7f7f"];
  let cursor = null, xOf = null;
  const shown = D.energy.series.map(() => true);
  (function legend() {
    const list = document.getElementById("series"), groups = new Map();
    D.energy.series.forEach((s, k) => {
      const cut = s.name.lastIndexOf(" ", s.name.endsWith(" H - W_in") ? s.name.length - 9 : s.name.length);
      const body = cut > 0 ? s.name.slice(0, cut) : "", quantity = cut > 0 ? s.name.slice(cut + 1) : s.name;
      if (!groups.has(body)) groups.set(body, []);
      groups.get(body).push({ k: k, quantity: quantity });
    });
    for (const [body, entries] of groups) {
      const row = document.createElement("div"); row.className = "body";
      const buttons = entries.map((e) => {
        const b = document.createElement("button"); b.className = "entry"; b.dataset.series = e.k;
        b.title = "show or hide " + D.energy.series[e.k].name;
        b.innerHTML = '<span class="swatch"></span>'; b.firstChild.style.background = palette[e.k % palette.length];
        b.appendChild(document.createTextNode(e.quantity));
        b.onclick = () => { shown[e.k] = !shown[e.k]; b.classList.toggle("off", !shown[e.k]); plot(); };
        return b;
      });
      if (body) {
        const name = document.createElement("button"); name.className = "name"; name.textContent = body;
        name.title = "show or hide every series of " + body;
        name.onclick = () => { const on = !entries.every((e) => shown[e.k]);
          entries.forEach((e, i) => { shown[e.k] = on; buttons[i].classList.toggle("off", !on); }); plot(); };
        row.appendChild(name);
      }
      buttons.forEach((b) => row.appendChild(b));
      list.appendChild(row);
    }
  })();
  function element(name, attributes, text) { const e = document.createElementNS(NS, name);
    for (const k in attributes) e.setAttribute(k, attributes[k]); if (text !== undefined) e.textContent = text; svg.appendChild(e); return e; }
  function plot() {
    while (svg.firstChild) svg.removeChild(svg.firstChild);
    const W = svg.clientWidth || 300, H = svg.clientHeight || 200, L = 58, R = 22, T = 18, B = 30;
    const t = D.energy.times; if (t.length === 0) return;
    let lo = Infinity, hi = -Infinity;
    D.energy.series.forEach((s, k) => { if (shown[k]) for (const v of s.values) { lo = Math.min(lo, v); hi = Math.max(hi, v); } });
    if (!(lo <= hi)) { lo = 0; hi = 1; }
    if (!(hi > lo)) { hi = lo + 1; }
    const pad = 0.05 * (hi - lo); lo -= pad; hi += pad;
    const t0 = t[0], t1 = t[t.length - 1] > t0 ? t[t.length - 1] : t0 + 1;
    xOf = (x) => L + (W - L - R) * (x - t0) / (t1 - t0);
    const yOf = (y) => T + (H - T - B) * (1 - (y - lo) / (hi - lo));
    element("rect", { id: "plot-frame", x: L, y: T, width: W - L - R, height: H - T - B, fill: "none", stroke: "#888" });
    element("text", { x: L, y: 12, "font-size": 12 }, "energy [J]");
    element("text", { x: W - R, y: H - 4, "font-size": 12, "text-anchor": "end" }, "time [s]");
    for (let i = 0; i <= 2; ++i) { const y = lo + (hi - lo) * i / 2, x = t0 + (t1 - t0) * i / 2;
      element("text", { x: L - 4, y: yOf(y) + 4, "font-size": 11, "text-anchor": "end" }, fmt(y));
      element("text", { x: xOf(x), y: H - 16, "font-size": 11, "text-anchor": "middle" }, fmt(x)); }
    D.energy.series.forEach((s, k) => {
      if (!shown[k]) return;
      const d = s.values.map((v, i) => (i ? "L" : "M") + xOf(t[i]).toFixed(1) + " " + yOf(v).toFixed(1)).join(" ");
      element("path", { d: d, fill: "none", stroke: palette[k % palette.length], "stroke-width": 1.5 });
    });
    cursor = element("line", { y1: T, y2: H - B, stroke: "#000", "stroke-dasharray": "3 3" });
    show(frame);
  }

  // one frame: the 3D view's, the caption, the slider, the energy plot's cursor
  const slider = document.getElementById("slider"), label = document.getElementById("frame-label");
  const caption = document.getElementById("caption"), playButton = document.getElementById("play");
  slider.max = N - 1;
  let frame = 0, playing = false, clock = 0;
  function show(k) {
    frame = Math.min(Math.max(k, 0), N - 1);
    if (view3d) view3d.draw(frame);
    const time = D.times[frame];
    caption.textContent = D.captions[frame];
    slider.value = frame;
    label.textContent = "frame " + frame + " / " + (N - 1) + " · t = " + fmt(time) + " s";
    if (cursor && xOf) { const x = xOf(time); cursor.setAttribute("x1", x); cursor.setAttribute("x2", x); }
  }
  function play(on) { playing = on && N > 1; playButton.textContent = playing ? "❚❚" : "▶"; clock = performance.now(); }
  function tick(now) {
    if (playing && now - clock >= 1000 / D.fps) { clock = now; show(frame + 1 < N ? frame + 1 : 0); }
    requestAnimationFrame(tick);
  }
  playButton.onclick = () => play(!playing);
  document.getElementById("first").onclick = () => { play(false); show(0); };
  document.getElementById("back").onclick = () => { play(false); show(frame - 1); };
  document.getElementById("forward").onclick = () => { play(false); show(frame + 1); };
  slider.oninput = () => { play(false); show(Number(slider.value)); };
  window.addEventListener("keydown", (e) => {
    if (e.key === " ") { play(!playing); e.preventDefault(); }
    else if (e.key === "ArrowRight") { play(false); show(frame + 1); e.preventDefault(); }
    else if (e.key === "ArrowLeft") { play(false); show(frame - 1); e.preventDefault(); }
    else if (e.key === "Home") { play(false); show(0); }
    else if (e.key === "End") { play(false); show(N - 1); }
  });

  // #frame=N: open at frame N, paused (a link to one moment, and the browser test's two frames);
  // otherwise play from the first frame
  const asked = /[#&]frame=(\d+)/.exec(location.hash);
  if (view3d) view3d.resize();
  plot();
  show(asked ? Number(asked[1]) : 0);
  play(!asked);
  requestAnimationFrame(tick);

  // The test hook: window.femPlayer.positions(k) is frame k's surface vertices as the 3D view draws
  // them (decode into float32, as draw does), x y z each, of the .vtu points pointIds. #positions=0,3
  // in the address also writes them as JSON into a hidden pre element (id fem-positions) for a
  // headless browser's --dump-dom (tools/check_web_page.py):
  // {"point_ids": [...], "frames": {"0": [...], "3": [...]}}
  const pointIds = Array.from(new Uint32Array(buffer(D.point_ids)));
  window.femPlayer = { frames: N, pointIds: pointIds, positions: (k) => decode(k, new Float32Array(3 * P)) };
  const dump = /[#&]positions=([\d,]+)/.exec(location.hash);
  if (dump) {
    const frames = {};
    for (const k of dump[1].split(",").map(Number)) if (k < N) frames[k] = Array.from(window.femPlayer.positions(k));
    const pre = document.createElement("pre");
    pre.id = "fem-positions"; pre.style.display = "none";
    pre.textContent = JSON.stringify({ point_ids: pointIds, frames: frames });
    document.body.appendChild(pre);
  }
})();
</script>
</body>
</html>
)page";

}  // namespace

}  // namespace fem::scenes
