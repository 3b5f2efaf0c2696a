#pragma once
// What the figure files share and no caller needs (figures.cpp defines it): the X display, the PNG
// and SVG writers, the font, round tick values, and the mesh renderers that both the PNGs
// (figures_mesh.cpp) and the on-screen window (figures_window.cpp) draw with. Include it only from
// common/figures*.cpp.

#include "common/figures.hpp"

#include <vtkDataSet.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSmartPointer.h>
#include <vtkTextProperty.h>
#include <vtkUnstructuredGrid.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace fem::fig::detail {

/// The process's one connection to the X server, or nullptr when there is no display.
/// Opening a connection to Xvfb fails now and then on this course's machines (the server hangs up
/// at once), and VTK aborts the process when its own attempt fails. So the connection is opened
/// here, retried a few times, and handed to every render window (SetDisplayId), which then never
/// opens one itself. An X Display* (void*, as VTK's SetDisplayId takes it, so that this header
/// needs no Xlib, whose macros clash with Eigen's names).
void* shared_display();

/// Writes what window shows to path (.png), with figure_code_version in a PNG text chunk, through
/// write_file (a full disk is a clear fem::Error, not VTK's).
void write_png(vtkRenderWindow* window, const std::filesystem::path& path);

/// Writes what window shows as a vector picture, path (.svg), through VTK's GL2PS exporter: lines,
/// markers and texts as SVG elements, so a chart scales to any slide. GL2PS cannot embed the
/// window's (white) background image and says so on stderr, which is silenced for the export; the
/// file is read back and written by write_file, so a failed export leaves no half-written SVG.
void write_svg(vtkRenderWindow* window, const std::filesystem::path& path);

/// Sets a text's font, size and colour. The figures use DejaVu Sans (Debian's fonts-dejavu-core,
/// which tools/setup.sh installs) when it is there: VTK's built-in Arial draws '|' so thin that
/// "|u|" reads "l u l", and has no Greek. Without it VTK's own font is used.
void set_font(vtkTextProperty* text, int size, bool bold = false);

/// Round values inside [low, high], for a colour bar's labels or a linear axis's ticks: the
/// multiples of the smallest step 1, 2, 2.5 or 5 times a power of ten that gives at most `most` of
/// them (the range's ends are not labelled unless they are such multiples).
std::vector<double> round_ticks(double low, double high, int most = 6);

/// The width and height in pixels of a text drawn with these properties (72 dpi, as the figures'
/// windows), as VTK's text renderer measures it.
std::pair<double, double> text_size(vtkTextProperty* properties, const std::string& text);

/// A colour bar's labels, written by us rather than by VTK (whose printf format has no true minus
/// sign: "-0.5"): the bar, the renderer its labels go to, the values to label and the bar's range.
/// Where the bar's colour strip lies is known only after a render (render_with_labels).
struct BarLabels {
    vtkSmartPointer<vtkScalarBarActor> bar;  // nullptr: no colour bar (a categorical field)
    vtkSmartPointer<vtkRenderer> texts;
    vtkSmartPointer<vtkRenderer> data;  // the renderer of the data set (its camera maps world to pixels)
    std::vector<double> ticks;
    double low = 0.0, high = 1.0;
    int font_size = 15;
};

/// Renders window, then writes labels' values (tick_labels) beside its colour strip, each centred
/// on its value's height, and renders again.
void render_with_labels(vtkRenderWindow* window, const BarLabels& labels);

/// Adds to window the renderers that draw a data set's surface coloured by a field: a white
/// backdrop, the data (lit and framed as options say) and the texts (title, colour bar or legend).
/// A mesh (lit = true) is lit by a key, a fill and a back light, with ambient light so that no face
/// is black, and shows its edges if asked; a flat grid is drawn unlit, in the colour map's own
/// colours. The PNGs and an on-screen MeshWindow share it, so they show the same picture; draw it
/// with render_with_labels, which writes the colour bar's labels.
BarLabels add_renderers(vtkRenderWindow* window, vtkDataSet* data, bool cell_field, bool lit,
                        const RenderOptions& options);

/// The grid of a mesh to draw with options (cut if asked), and whether its field is a cell field.
/// fem::Error if the mesh has no such field.
std::pair<vtkSmartPointer<vtkUnstructuredGrid>, bool> drawable(const io::MeshData& mesh, const RenderOptions& options);

}  // namespace fem::fig::detail
