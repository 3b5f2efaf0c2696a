#pragma once
// Figures drawn with VTK: line charts (log-log where it fits) offscreen to PNG and SVG, with a CSV of
// the same numbers (figures_chart.cpp); meshes or grids coloured by a field, offscreen to PNG
// (figures_mesh.cpp); an on-screen window showing a mesh as its PNG would (MeshWindow,
// figures_window.cpp); what they share, figures.cpp. Debian's VTK renders only through an X display
// and aborts without one, so every function here first checks that a display can be opened: without
// one the PNG writers draw nothing, return false and say once how to get them (`xvfb-run -a`), and a
// MeshWindow refuses with fem::Error. VTK files and CSVs never depend on a display.

#include "common/vtk_io.hpp"

#include <array>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace fem::fig {

/// The version of the drawing code in figures*.cpp (and motion.cpp's frames), defined in figures.cpp
/// (so that a bump recompiles one file). Every PNG written here carries it as a PNG text chunk, key
/// figure_version_key, value this number; bump it whenever a change alters what a figure looks
/// like. tools/check_figures.py (ctest figures_current) fails for a figure under docs/figures with
/// an older version or none: redraw it with the chapter's executable (tools/check_docs.py --update).
extern const int figure_code_version;
/// The key of the PNG text chunk that holds figure_code_version.
inline constexpr const char* figure_version_key = "fem-figure-version";

/// True when an X display can be opened (probed once per process).
bool display_available();

/// True when PNGs are wanted (figures_wanted) and an X display can be opened. When they are wanted
/// but there is no display it prints, once per process, a note saying the PNGs were skipped and
/// how to get them (run under `xvfb-run -a`), so a missing picture is never silent.
bool can_draw(bool figures_wanted);

/// One line of a chart.
struct Series {
    std::string name;
    std::vector<double> x;
    std::vector<double> y;
    bool markers_only = false;  ///< draw the points as markers, not joined by a line (e.g. one point)
    /// A dashed line: for a series that lies on another one (drawn after it), so both show.
    bool dashed = false;
};

/// Slide resolution: a figure of width × height is drawn at pixel_scale times as many pixels each
/// way, its texts, lines and markers scaled alike, so the layout the callers chose stays.
inline constexpr int pixel_scale = 2;

/// The labels of one axis's ticks (round values: a few significant digits), in one notation as a
/// person writes them: plain (0.002, 50000) when every nonzero tick lies in [0.001, 100000), else
/// powers of ten for all (10⁻⁶, 2·10⁻⁵, 1.5·10⁵), never a mix of the two; a negative value gets a
/// true minus sign (U+2212: −0.002, −2·10⁻⁶), as wide as the plus, never a hyphen.
/// values: n tick values; returns n labels, in the same order.
std::vector<std::string> tick_labels(const std::vector<double>& values);

/// The nearest-rank percentile of values: the smallest value with at least `percent` percent of
/// them at or below it (percent in (0, 100]; 100 gives the largest). values: n ≥ 1 numbers in any
/// order. fem::Error for no values or a percent outside (0, 100].
double percentile(std::vector<double> values, double percent);

/// The lines a clipped colour bar carries under its title: "clipped at the 99th percentile" and
/// "max 66500 Pa" (percent as clip_percentile; largest the field's largest value, rounded to 3
/// significant digits and written as tick_labels writes it; unit may be empty).
std::string clip_note(double percent, double largest, const std::string& unit);

/// A corner of a chart's plot area, where its legend may go.
enum class Corner { top_left, top_right, bottom_left, bottom_right };

struct LineChart {
    std::string title;
    std::string x_label;
    std::string y_label;
    bool log_x = false;
    bool log_y = false;
    std::vector<Series> series;
    /// Layout pixels (the PNG has pixel_scale times as many): 16:9, 1920 × 1080 pixels, a full slide.
    int width = 960;
    int height = 540;
    /// The corner the legend goes to if no line or marker passes there; otherwise the first free
    /// one of top right, top left, bottom right, bottom left; if none is free, the y range grows
    /// until the legend fits above or below the data. A legend never covers data.
    Corner legend = Corner::top_right;
};

/// Writes <stem>.csv (columns: series, x_label, y_label; every point of every series) and, when figures is true
/// and a display is available, <stem>.png and <stem>.svg (the same chart as a vector picture). A series name keeps one colour for the whole process
/// (the first chart that names it picks the next free colour), so a method has the same colour in
/// every chart of a chapter; a series of at most 12 points gets markers on its line. On a log axis, points with a value ≤ 0 or non-finite
/// values are left out of the PNG (they stay in the CSV). The axes span the data with 5% to spare
/// on each side (a log axis at least two powers of ten, so that it has two labels), so no line or
/// marker touches the frame. Returns whether the PNG was written.
bool save_chart(const LineChart& chart, const std::filesystem::path& stem, bool figures = true);

/// One value of a categorical field, drawn in its own colour and named in the figure's legend.
struct Category {
    double value;                  ///< the field's value, e.g. 2
    std::string name;              ///< e.g. "fill"
    std::array<double, 3> colour;  ///< RGB in [0, 1]
};

/// A plane through point with the given normal (need not be unit length).
struct CutPlane {
    std::array<double, 3> point;
    std::array<double, 3> normal;
};

/// A shape drawn beside a rendered mesh, not coloured by its field unless asked: an obstacle of a
/// scene (a floor patch, a sphere, a box, a triangle mesh) or the lattice that carries a skin.
struct Prop {
    io::MeshData shape;  ///< its surface is drawn (triangles, or the boundary of tets), points as they are
    std::array<double, 3> colour{0.55, 0.55, 0.58};  ///< RGB in [0, 1], when not coloured by the field
    /// Coloured by the mesh's field (RenderOptions::field, which shape must have) with the mesh's colour
    /// map and range, e.g. a lattice on the colour scale of the skin it carries.
    bool by_field = false;
    bool wireframe = false;  ///< its edges only, e.g. a lattice around the skin
    double opacity = 1.0;
};

/// Grows box (xmin, xmax, ymin, ymax, zmin, zmax) to hold every row of points (#P×3).
void grow_bounds(std::array<double, 6>& box, const MatrixX3d& points);

/// The box of nothing yet (every min +∞, every max −∞): grow_bounds makes it the box of what it is given.
std::array<double, 6> empty_bounds();

/// How to colour and frame a rendered mesh or grid.
struct RenderOptions {
    std::string title;                 ///< drawn at the top of the image
    std::string field;                 ///< name of a point or cell field of the mesh
    std::string unit;                  ///< the field's unit, e.g. "m", "Pa": the colour bar reads "field [unit]"
    std::string range_note;            ///< a line under the bar's title, e.g. "range of all 121 frames"
    int component = -1;                ///< -1: the magnitude for vectors, the value for scalars
    std::optional<std::pair<double, double>> range;  ///< colour range; default: the field's range
    /// Without a range given: the colour range's top at this percentile of the field's values (e.g.
    /// 99) instead of their largest, so that a few spikes (the stress in the tets at a pinned
    /// corner) do not set the scale and leave the rest of the body one dark colour. Values above
    /// it take the top colour, and the colour bar says it is clipped and gives the largest value.
    /// 100: the full range.
    double clip_percentile = 100.0;
    std::array<double, 3> view_direction{0.0, 0.0, -1.0};  ///< camera looks along this direction
    std::array<double, 3> view_up{0.0, 1.0, 0.0};
    bool show_edges = true;            ///< draw a mesh's edges (grids never show theirs)
    /// A field of a few values drawn as categories (each in its colour, named in a legend of
    /// swatches) instead of on a continuous colour map; a value that is no category is drawn white.
    std::vector<Category> categories;
    /// A mesh only: leave out every cell with a vertex on the side of this plane its normal points
    /// to, so that a field inside the body shows on the cut (e.g. the masses of inner vertices).
    std::optional<CutPlane> cut;
    /// The box (xmin, xmax, ymin, ymax, zmin, zmax) the camera frames; default: the mesh's own
    /// bounds. The frames of a motion share one box so that the camera stands still.
    std::optional<std::array<double, 6>> frame_bounds;
    /// A mesh only: this shape (its points as they are) drawn as a faint translucent grey surface
    /// behind the coloured one, e.g. the rest shape under an exaggerated motion.
    std::optional<io::MeshData> outline;
    /// A mesh only: smooth shading (normals averaged at the vertices) instead of flat facets;
    /// meant for render surfaces, which also hide their edges (show_edges = false).
    bool smooth = false;
    /// A mesh only: shapes drawn with it (an obstacle, a lattice), in the same camera and light; the
    /// camera's box (frame_bounds or the mesh's bounds) is the caller's to make hold them.
    std::vector<Prop> props;
    /// Draw the data under the title's lines, never behind them (a motion frame's title of two or
    /// three lines would cover a body framed to the top); false: over the whole height.
    bool data_under_title = false;
    int width = 900;   ///< layout pixels; the PNG has scale times as many each way
    int height = 700;
    int scale = pixel_scale;  ///< 1 for an on-screen window that must fit the screen
};

/// Renders the mesh's surface coloured by options.field, with a colour bar, to a PNG file: lit by a
/// light kit (no face goes black), with its edges unless options.show_edges is false.
/// Returns false (and writes nothing) without a display; fem::Error if the field is missing.
bool render_mesh_png(const std::filesystem::path& path, const io::MeshData& mesh,
                     const RenderOptions& options);

/// An on-screen window showing a mesh coloured by a field, redrawn frame by frame: the same picture
/// (camera, lights, colour bar, title) render_mesh_png writes for the same options, so a frame on
/// screen and its PNG agree. For a lecture: the scenes runner's --view (docs/scenes.md#the-live-view).
class MeshWindow {
public:
    /// Opens the window, options.width × options.height pixels. fem::Error without a display.
    MeshWindow(const RenderOptions& options, const std::string& window_name);
    ~MeshWindow();
    MeshWindow(const MeshWindow&) = delete;
    MeshWindow& operator=(const MeshWindow&) = delete;

    /// Draws mesh as render_mesh_png would (fem::Error if the field is missing).
    void show(const io::MeshData& mesh, const RenderOptions& options);
    /// Handles the window's pending events and returns the keys pressed since the last call: one
    /// character each, ' ' for space, '>' for the right arrow, letters as typed. Mouse events update
    /// pointer_drag.
    std::string poll_keys();

    /// A point of the shown mesh dragged by the mouse: pressing the left button within
    /// pick_radius pixels of some point of the mesh last shown picks, of those, the one nearest the
    /// camera; while the button is held, target follows the pointer on the plane through the picked
    /// point that faces the camera (the point's depth kept); releasing ends the drag.
    struct PointerDrag {
        int point = -1;  ///< the picked point's index in the shown mesh's points; −1: no drag
        Eigen::Vector3d target = Eigen::Vector3d::Zero();  ///< world coordinates, as the shown mesh's
    };
    /// The drag as of the last poll_keys.
    PointerDrag pointer_drag() const;
    /// The pixels around the pointer in which a press picks a mesh point (times RenderOptions::scale).
    static constexpr double pick_radius = 20.0;
    /// Writes what the window shows to a PNG.
    void save_png(const std::filesystem::path& path);
    /// Renames the window (its title bar).
    void set_name(const std::string& name);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// Renders a 2D or 3D regular grid coloured by a point field (a heat map for a 2D grid), unlit, so
/// that its colours are exactly the colour map's.
bool render_grid_png(const std::filesystem::path& path, const io::ImageGrid& grid,
                     const RenderOptions& options);

}  // namespace fem::fig
