#pragma once
// The web page of a run (--html, output.html): one self-contained .html file that plays the run in
// any browser, with nothing installed and no network: the bodies' boundary surfaces and the
// obstacles over time, coloured by the frames' field with its colour bar and caption, play/pause, a
// time slider, frame stepping, orbit and zoom, and the energy plot. three.js (Debian's libjs-three,
// r111: three.min.js and examples/js/controls/OrbitControls.js) is inlined into the page.
// docs/scenes.md#the-web-page
//
// The frames are stored compactly: every surface vertex's drawn position X + warp·u quantised to
// 16 bits per coordinate over the box of every frame (quantise_positions), base64 in the page, so
// that a decoded coordinate is off by at most half a step, (high − low) / 65535 / 2 on its axis.
// The page's test hook, window.femPlayer.positions(k), gives frame k's positions as its 3D view
// decodes and draws them (float32); #positions=0,1,… in the address writes them into the page for a
// headless browser (tools/check_web_page.py reads them back against the .vtu frames).

#include "scenes/scene_file.hpp"

#include "10_linear_dynamics/time_integration.hpp"

#include "common/types.hpp"
#include "common/vtk_io.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace fem::scenes {

/// The largest code of a quantised coordinate: 16 bits.
inline constexpr int quantisation_levels = 65535;

/// Positions of P points over N frames, each coordinate quantised to 16 bits over a box:
/// code = round((x − low) / (high − low) · 65535) on each axis (an axis of zero extent: code 0).
struct QuantisedPositions {
    Eigen::Vector3d low = Eigen::Vector3d::Zero(), high = Eigen::Vector3d::Zero();  ///< the box [m]
    Eigen::Index points = 0;             ///< P
    std::vector<std::uint16_t> codes;    ///< N·P·3 codes: frame-major, then point, then x, y, z
    std::size_t frames() const { return points > 0 ? codes.size() / (3 * static_cast<std::size_t>(points)) : 0; }
};

/// Quantises frames (N matrices of P×3 positions [m], P the same in each) over the box of all of
/// them. fem::Error for no frames, frames of different sizes, or a non-finite position (naming the
/// frame and point).
QuantisedPositions quantise_positions(const std::vector<MatrixX3d>& frames);

/// The positions (P×3) of frame k: low + code / 65535 · (high − low). fem::Error for k ≥ frames().
MatrixX3d dequantise_frame(const QuantisedPositions& quantised, std::size_t k);

/// The largest error of a decoded coordinate on each axis [m]: half a step, (high − low) / 65535 / 2.
Eigen::Vector3d quantisation_bound(const QuantisedPositions& quantised);

/// RFC 4648 base64 (with '=' padding) of bytes.
std::string base64_encode(std::string_view bytes);

/// The bytes of RFC 4648 base64 text. fem::Error naming the offset of a character that is not
/// base64 or a length that is not a multiple of 4.
std::string base64_decode(std::string_view text);

/// The page's frame data, as base64_decode of the page's "positions" gives it: the 16-bit codes,
/// little-endian, in QuantisedPositions's order, with the box and the point count the page states.
/// fem::Error for a byte count that is not a whole number of frames.
QuantisedPositions positions_from_bytes(std::string_view bytes, const Eigen::Vector3d& low, const Eigen::Vector3d& high,
                                        Eigen::Index points);

/// The files three.js's page needs (Debian's libjs-three): three.min.js and OrbitControls.js.
/// fem::Error naming the missing file and the package (tools/setup.sh) when either is absent:
/// fem_scene checks it before it runs a scene with --html.
void check_web_page_library();

/// Collects a run's frames and writes its page (docs/scenes.md#the-web-page). Each frame keeps the
/// surface of the merged frame (the boundary triangles of every body's tets, chapter 13's
/// boundary_faces of the first frame) at X + warp·u, the colour field on it (a cell field per
/// triangle, its tet's value; a point field per vertex; a vector's magnitude) and the caption. With
/// the motion drawn exaggerated (warp ≠ 1) the page also draws the rest surface, faint grey, as the
/// PNG frames do.
class WebPage {
public:
    /// The page of a run of scene (which must outlive it), no frames yet.
    explicit WebPage(const SceneSpec& scene);
    /// Adds a frame: the merged frame of every body (runner.hpp), its time and the models the
    /// bodies use at it (the caption's, frame_title).
    void add_frame(const io::MeshData& frame, double time, const std::string& models);
    /// Writes the page atomically (fem::write_file) to path, with the energy plot of records: per
    /// body (names in the scene's order) chapter 10's record of every step; the plot shows each
    /// body's kinetic and elastic energy and H − W_in, as the chart energies does. Returns the
    /// positions' error bound on each axis (quantisation_bound) [m]. fem::Error without three.js
    /// (check_web_page_library) or when the file cannot be written.
    Eigen::Vector3d write(const std::filesystem::path& path,
               const std::vector<std::vector<dynamics::StepRecord>>& records) const;

private:
    const SceneSpec& scene_;
    std::vector<int> surface_points_;     // merged frame's point index of each surface vertex
    MatrixX3i triangles_;                 // into surface_points_
    std::vector<int> triangle_cells_;     // the tet of each triangle (for a cell field)
    bool cell_field_ = false;
    MatrixX3d rest_;                      // surface vertices at X (drawn faint grey when warp ≠ 1)
    std::vector<MatrixX3d> positions_;    // per frame: surface vertices at X + warp·u
    std::vector<Eigen::VectorXd> values_; // per frame: the field per triangle or surface vertex
    std::vector<double> times_;
    std::vector<std::string> captions_;
};

}  // namespace fem::scenes
