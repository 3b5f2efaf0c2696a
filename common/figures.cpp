#include "common/figures.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/table.hpp"
#include "common/vtk_convert.hpp"
#include "common/vtk_errors.hpp"

#include <X11/Xlib.h>

#include <vtkActor.h>
#include <vtkAxis.h>
#include <vtkCamera.h>
#include <vtkCellData.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkColorTransferFunction.h>
#include <vtkContextScene.h>
#include <vtkContextActor.h>
#include <vtkDataSetSurfaceFilter.h>
#include <vtkDoubleArray.h>
#include <vtkImageData.h>
#include <vtkGL2PSExporter.h>
#include <vtkLightKit.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkUnsignedCharArray.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotPoints.h>
#include <vtkPointData.h>
#include <vtkPolyDataNormals.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkCallbackCommand.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRendererCollection.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkStringArray.h>
#include <vtkTable.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTextRenderer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkVariant.h>
#include <vtkWindowToImageFilter.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>
#include <thread>

namespace fem::fig {

const int figure_code_version = 5;  // bump it when a figure's look changes (figures.hpp)

namespace {

/// The process's one connection to the X server, or nullptr when there is no display.
/// Opening a connection to Xvfb fails now and then on this course's machines (the server hangs up
/// at once), and VTK aborts the process when its own attempt fails. So the connection is opened
/// here, retried a few times, and handed to every render window (SetDisplayId), which then never
/// opens one itself.
Display* shared_display()
{
    static Display* const display = [] {
        io::detail::route_vtk_output();  // VTK's messages while drawing: one line each, not a log block
        const char* name = std::getenv("DISPLAY");
        if (name == nullptr || *name == '\0')
            return static_cast<Display*>(nullptr);
        for (int attempt = 0; attempt < 20; ++attempt) {
            if (Display* opened = XOpenDisplay(nullptr))
                return opened;
            std::this_thread::sleep_for(std::chrono::milliseconds(25));
        }
        return static_cast<Display*>(nullptr);
    }();
    return display;
}


void write_png(vtkRenderWindow* window, const std::filesystem::path& path)
{
    vtkNew<vtkWindowToImageFilter> capture;
    capture->SetInput(window);
    capture->ReadFrontBufferOff();
    capture->Update();
    // Encoded in memory, written by write_file (a full disk is a clear error, not VTK's).
    vtkNew<vtkPNGWriter> writer;
    writer->WriteToMemoryOn();
    writer->SetInputConnection(capture->GetOutputPort());
    writer->AddText(figure_version_key, std::to_string(figure_code_version).c_str());
    const io::detail::VtkErrors errors(writer);
    writer->Write();
    vtkUnsignedCharArray* png = writer->GetResult();
    if (writer->GetErrorCode() != 0 || errors.any() || png == nullptr)
        throw Error(str("VTK could not encode the PNG '", path.string(), "'", errors.any() ? ": " + errors.text() : ""));
    write_file(path, std::string_view(reinterpret_cast<const char*>(png->GetPointer(0)),
                                      static_cast<std::size_t>(png->GetNumberOfValues())));
}

/// Writes what window shows as a vector picture, path (.svg), through VTK's GL2PS exporter: lines,
/// markers and texts as SVG elements, so a chart scales to any slide. GL2PS cannot embed the
/// window's (white) background image and says so on stderr, which is silenced for the export; the
/// file is read back and written by write_file, so a failed export leaves no half-written SVG.
void write_svg(vtkRenderWindow* window, const std::filesystem::path& path)
{
    const std::filesystem::path prefix = std::filesystem::path(path).replace_extension(".gl2ps-partial");
    std::filesystem::path written = prefix;
    written += ".svg";
    vtkNew<vtkGL2PSExporter> exporter;
    exporter->SetRenderWindow(window);
    exporter->SetFileFormatToSVG();
    exporter->CompressOff();
    exporter->SetFilePrefix(prefix.c_str());
    exporter->SetTitle("fem-course figure");
    std::fflush(stderr);
    const int saved = dup(STDERR_FILENO);
    const int null = open("/dev/null", O_WRONLY);
    if (saved >= 0 && null >= 0)
        dup2(null, STDERR_FILENO);
    exporter->Write();
    std::fflush(stderr);
    if (saved >= 0 && null >= 0)
        dup2(saved, STDERR_FILENO);
    for (int fd : {saved, null})
        if (fd >= 0)
            close(fd);
    std::ifstream in(written, std::ios::binary);
    const std::string svg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    in.close();
    std::error_code ignored;
    std::filesystem::remove(written, ignored);
    if (svg.find("</svg>") == std::string::npos)
        throw Error(str("VTK's GL2PS exporter could not write the SVG '", path.string(), "'"));
    write_file(path, svg);
}

// Line colours of successive series (Tableau 10), as RGB bytes.
constexpr std::array<std::array<unsigned char, 3>, 10> line_colours{{
    {31, 119, 180}, {255, 127, 14}, {44, 160, 44}, {214, 39, 40}, {148, 103, 189},
    {140, 86, 75}, {227, 119, 194}, {127, 127, 127}, {188, 189, 34}, {23, 190, 207}}};

/// The colour of a named series, the same in every chart of the process: the first chart naming a
/// series gives it the next colour of line_colours that no series of that chart has taken yet.
/// `taken` holds the colours of the chart's earlier series.
std::size_t series_colour(const std::string& name, const std::vector<std::size_t>& taken)
{
    static std::vector<std::pair<std::string, std::size_t>> named;  // in the order first drawn
    for (const auto& [known, colour] : named)
        if (known == name && std::find(taken.begin(), taken.end(), colour) == taken.end())
            return colour;
    std::size_t colour = named.size() % line_colours.size();
    for (std::size_t tries = 0; tries < line_colours.size() &&
                                std::find(taken.begin(), taken.end(), colour) != taken.end(); ++tries)
        colour = (colour + 1) % line_colours.size();
    if (std::none_of(named.begin(), named.end(), [&](const auto& entry) { return entry.first == name; }))
        named.emplace_back(name, colour);
    return colour;
}

/// Sets a text's font, size and colour. The figures use DejaVu Sans (Debian's fonts-dejavu-core,
/// which tools/setup.sh installs) when it is there: VTK's built-in Arial draws '|' so thin that
/// "|u|" reads "l u l", and has no Greek. Without it VTK's own font is used.
void set_font(vtkTextProperty* text, int size, bool bold = false)
{
    static const std::string regular = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
    static const std::string heavy = "/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf";
    static const bool installed = std::filesystem::exists(regular) && std::filesystem::exists(heavy);
    if (installed) {
        text->SetFontFamily(VTK_FONT_FILE);
        text->SetFontFile((bold ? heavy : regular).c_str());
    }
    text->SetBold(bold && !installed);  // the bold file is bold already: no synthetic emboldening
    text->SetItalic(false);
    text->SetShadow(false);
    text->SetFontSize(size);
    text->SetColor(0.1, 0.1, 0.1);
}

bool plottable(double x, double y, const LineChart& chart)
{
    return std::isfinite(x) && std::isfinite(y) && (!chart.log_x || x > 0) && (!chart.log_y || y > 0);
}

/// One axis of a chart: linear or log10. Ranges and layout are computed in the axis's own scale
/// (log10 of the value on a log axis), where the plot is linear.
struct Scale {
    bool log = false;
    double to(double value) const { return log ? std::log10(value) : value; }
    double from(double scaled) const { return log ? std::pow(10.0, scaled) : scaled; }
};

/// The ticks of a log axis over [low, high] (log10 of the values): 1 … 9 times the powers of ten
/// over up to one decade, 1, 2 and 5 times them up to 3.5 decades, every power of ten up to 8
/// decades, every k-th one beyond.
std::vector<double> log_ticks(double low, double high)
{
    std::vector<double> ticks;
    const double span = high - low;
    const int step = span <= 8.0 ? 1 : static_cast<int>(std::ceil(span / 8.0));
    for (int power = static_cast<int>(std::floor(low)); power <= static_cast<int>(std::ceil(high)); ++power) {
        if (power % step != 0)
            continue;
        const std::vector<double> multiples = span <= 1.0   ? std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9}
                                              : span <= 3.5 ? std::vector<double>{1, 2, 5}
                                                            : std::vector<double>{1};
        for (double m : multiples) {
            const double tick = power + std::log10(m);
            if (tick >= low - 1e-9 && tick <= high + 1e-9)
                ticks.push_back(tick);
        }
    }
    return ticks;
}

/// Round values inside [low, high], for a colour bar's labels or a linear axis's ticks: the
/// multiples of the smallest step 1, 2, 2.5 or 5 times a power of ten that gives at most `most` of
/// them (the range's ends are not labelled unless they are such multiples).
std::vector<double> round_ticks(double low, double high, int most = 6)
{
    if (!(high > low) || !std::isfinite(low) || !std::isfinite(high))
        return {low};
    const double power = std::pow(10.0, std::floor(std::log10(high - low)) - 1.0);
    for (double base : {1.0, 2.0, 2.5, 5.0, 10.0, 20.0, 25.0, 50.0, 100.0}) {
        const double step = base * power;
        const double first = std::ceil(low / step - 1e-9) * step;
        const int count = static_cast<int>(std::floor((high - first) / step + 1e-9)) + 1;
        if (count <= most) {
            std::vector<double> ticks;
            for (int i = 0; i < count; ++i) {
                const double tick = first + i * step;
                ticks.push_back(std::abs(tick) < 1e-12 * step ? 0.0 : tick);
            }
            return ticks;
        }
    }
    return {low, high};
}

/// n written in superscript digits, e.g. ⁻¹².
std::string superscript(int n)
{
    static const char* const digits[10] = {"\u2070", "\u00B9", "\u00B2", "\u00B3", "\u2074",
                                           "\u2075", "\u2076", "\u2077", "\u2078", "\u2079"};
    std::string out = n < 0 ? "\u207B" : "";
    for (char c : std::to_string(std::abs(n)))
        out += digits[c - '0'];
    return out;
}

}  // namespace

std::vector<std::string> tick_labels(const std::vector<double>& values)
{
    const bool plain = std::all_of(values.begin(), values.end(), [](double v) {
        return v == 0.0 || (std::abs(v) >= 1e-3 * (1 - 1e-9) && std::abs(v) < 1e5);
    });
    const auto digits = [](double value, int significant) {  // no trailing zeros, no sign
        std::ostringstream out;
        out << std::setprecision(significant) << std::abs(value);
        return out.str();
    };
    std::vector<std::string> labels;
    for (double value : values) {
        const std::string sign = value < 0.0 ? "\u2212" : "";
        if (plain || value == 0.0) {
            labels.push_back(sign + digits(value, 6));  // 6 digits: 10000 stays 10000, not 1e+04
            continue;
        }
        const int exponent = static_cast<int>(std::floor(std::log10(std::abs(value)) + 1e-9));
        const std::string mantissa = digits(value / std::pow(10.0, exponent), 4);
        labels.push_back(sign + (mantissa == "1" ? std::string() : mantissa + "\u00B7") + "10" + superscript(exponent));
    }
    return labels;
}

double percentile(std::vector<double> values, double percent)
{
    if (values.empty() || !(percent > 0.0 && percent <= 100.0))
        throw Error(str("percentile: need at least one value and a percent in (0, 100], got ", values.size(),
                        " values and ", percent));
    const auto rank = static_cast<std::size_t>(std::ceil(percent / 100.0 * static_cast<double>(values.size())));
    const auto at = values.begin() + static_cast<std::ptrdiff_t>(std::clamp<std::size_t>(rank, 1, values.size()) - 1);
    std::nth_element(values.begin(), at, values.end());
    return *at;
}

std::string clip_note(double percent, double largest, const std::string& unit)
{
    std::ostringstream p;
    p << percent;
    const int last = static_cast<int>(percent) % 10, tens = static_cast<int>(percent) % 100 / 10;
    const bool whole = percent == std::floor(percent);
    const char* suffix = !whole || tens == 1 ? "th" : last == 1 ? "st" : last == 2 ? "nd" : last == 3 ? "rd" : "th";
    std::ostringstream rounded;  // 3 significant digits, then written as an axis writes it
    rounded << std::setprecision(3) << largest;
    return str("clipped at the ", p.str(), suffix, " percentile\nmax ", tick_labels({std::stod(rounded.str())}).front(),
               unit.empty() ? "" : " " + unit);
}

namespace {

/// Ticks at round values over [low, high] on a linear axis: the multiples of the step 1, 2, 2.5 or
/// 5 times a power of ten that gives at most 8 of them, labelled by tick_labels (VTK's own choice
/// grows with the pixels: at slide resolution it crowded 28 labels on an axis).
void set_linear_ticks(vtkAxis* axis, double low, double high)
{
    vtkNew<vtkDoubleArray> positions;
    vtkNew<vtkStringArray> labels;
    const std::vector<double> ticks = round_ticks(low, high, 8);
    for (double tick : ticks)
        positions->InsertNextValue(tick);
    for (const std::string& label : tick_labels(ticks))
        labels->InsertNextValue(label);
    axis->SetCustomTickPositions(positions, labels);
}

/// The range [low, high] (in the axis's scale) that shows data from low to high with room around
/// it: 5% of the span on each side, so that neither a line nor a marker touches the frame. A log
/// axis grows to the next 1-2-5 values if it would otherwise have fewer than two ticks.
std::pair<double, double> padded_range(double low, double high, bool log)
{
    double span = high - low;
    if (!(span > 0.0))  // one value: a window around it
        span = log ? 0.5 : std::max(std::abs(high), 1.0);
    low -= 0.05 * span;
    high += 0.05 * span;
    if (log && log_ticks(low, high).size() < 2) {
        const auto below = [](double x) {  // the largest 1-2-5 value ≤ 10^x, as log10
            const double power = std::floor(x);
            double best = power;
            for (double m : {2.0, 5.0})
                if (power + std::log10(m) <= x)
                    best = power + std::log10(m);
            return best;
        };
        const auto above = [](double x) {  // the smallest 1-2-5 value ≥ 10^x, as log10
            const double power = std::floor(x);
            for (double m : {1.0, 2.0, 5.0})
                if (power + std::log10(m) >= x)
                    return power + std::log10(m);
            return power + 1.0;
        };
        low = below(low);
        high = above(high);
    }
    return {low, high};
}

/// Gives a log axis the ticks of log_ticks, labelled by tick_labels (VTK's own choice leaves some
/// axes with a single label).
void set_log_ticks(vtkAxis* axis, double low, double high)
{
    vtkNew<vtkDoubleArray> positions;
    vtkNew<vtkStringArray> labels;
    std::vector<double> values;
    for (double tick : log_ticks(low, high)) {
        positions->InsertNextValue(tick);
        values.push_back(std::pow(10.0, tick));
    }
    for (const std::string& label : tick_labels(values))
        labels->InsertNextValue(label);
    axis->SetCustomTickPositions(positions, labels);
}

/// Ticks at whole numbers over [low, high] (a linear axis whose data are all whole numbers, such as
/// iteration counts, where VTK's own ticks would fall on halves): every 1, 2, 5, 10, 20, … of them,
/// the smallest step that gives at most 12 ticks.
void set_integer_ticks(vtkAxis* axis, double low, double high)
{
    double step = 1.0;
    for (int k = 0; (high - low) / step > 12.0; ++k)
        step = std::array{2.0, 5.0, 10.0}[k % 3] * std::pow(10.0, k / 3);
    vtkNew<vtkDoubleArray> positions;
    vtkNew<vtkStringArray> labels;
    for (double tick = std::ceil(low / step) * step; tick <= high; tick += step) {
        positions->InsertNextValue(tick);
        labels->InsertNextValue(std::to_string(std::lround(tick)));
    }
    axis->SetCustomTickPositions(positions, labels);
}

/// A rectangle in pixels (origin bottom left, as VTK's context items use).
struct PixelBox {
    double left, bottom, right, top;
    bool contains(double x, double y) const { return x >= left && x <= right && y >= bottom && y <= top; }
};

/// True when the segment from (x0, y0) to (x1, y1) meets the box (Liang–Barsky clipping).
bool segment_meets(const PixelBox& box, double x0, double y0, double x1, double y1)
{
    const double dx = x1 - x0, dy = y1 - y0;
    const double p[4] = {-dx, dx, -dy, dy};
    const double q[4] = {x0 - box.left, box.right - x0, y0 - box.bottom, box.top - y0};
    double enter = 0.0, leave = 1.0;
    for (int k = 0; k < 4; ++k) {
        if (p[k] == 0.0) {
            if (q[k] < 0.0)
                return false;  // parallel to this edge and outside it
            continue;
        }
        const double t = q[k] / p[k];
        if (p[k] < 0.0)
            enter = std::max(enter, t);
        else
            leave = std::min(leave, t);
        if (enter > leave)
            return false;
    }
    return true;
}

/// The drawn series of a chart in the axes' scales, and how to map them to pixels once the chart is
/// laid out (its plot area, Point1 to Point2, is known only after a render).
struct ChartLayout {
    struct Curve {
        std::vector<double> x, y;  // in the axes' scales
        bool markers = false;      // markers only, no line
    };
    std::vector<Curve> curves;
    Scale sx, sy;
    double x_low = 0, x_high = 1, y_low = 0, y_high = 1;  // the axis ranges, in the axes' scales
    double left = 0, bottom = 0, right = 1, top = 1;      // the plot area in pixels

    /// Whether every x (y) of the chart is a whole number, over a span of at most 50 (iteration
    /// counts, say): a linear axis then gets whole-number ticks (set_integer_ticks).
    bool whole_numbers_x() const { return whole_numbers(&Curve::x); }
    bool whole_numbers_y() const { return whole_numbers(&Curve::y); }
    bool whole_numbers(std::vector<double> Curve::*values) const
    {
        double low = std::numeric_limits<double>::infinity(), high = -low;
        for (const Curve& c : curves)
            for (double v : c.*values) {
                if (v != std::round(v))
                    return false;
                low = std::min(low, v);
                high = std::max(high, v);
            }
        return !curves.empty() && high - low <= 50.0;
    }

    double pixel_x(double x) const { return left + (x - x_low) / (x_high - x_low) * (right - left); }
    double pixel_y(double y) const { return bottom + (y - y_low) / (y_high - y_low) * (top - bottom); }

    /// Whether any line or marker of the chart is drawn inside the box.
    bool covers(const PixelBox& box) const
    {
        const double marker_radius = 9.0 * pixel_scale;  // half a 14-pixel marker, and a little air
        const PixelBox grown{box.left - marker_radius, box.bottom - marker_radius, box.right + marker_radius,
                             box.top + marker_radius};
        for (const Curve& c : curves)
            for (std::size_t i = 0; i < c.x.size(); ++i) {
                const double px = pixel_x(c.x[i]), py = pixel_y(c.y[i]);
                if (c.markers ? grown.contains(px, py) : box.contains(px, py))
                    return true;
                if (!c.markers && i > 0 && segment_meets(box, pixel_x(c.x[i - 1]), pixel_y(c.y[i - 1]), px, py))
                    return true;
            }
        return false;
    }

    /// Where a legend of the given size sits in a corner of the plot area, inset by a margin.
    PixelBox legend_box(Corner corner, double width, double height) const
    {
        constexpr double inset = 8.0;
        const bool at_left = corner == Corner::top_left || corner == Corner::bottom_left;
        const bool at_top = corner == Corner::top_left || corner == Corner::top_right;
        const double x0 = at_left ? left + inset : right - inset - width;
        const double y0 = at_top ? top - inset - height : bottom + inset;
        return {x0, y0, x0 + width, y0 + height};
    }

    /// The data's extent along y, in the axis's scale, over the pixel columns [from, to].
    std::pair<double, double> y_extent_between(double from, double to) const
    {
        double low = std::numeric_limits<double>::infinity(), high = -low;
        for (const Curve& c : curves)
            for (std::size_t i = 0; i < c.x.size(); ++i) {
                const double px = pixel_x(c.x[i]);
                const bool inside = px >= from && px <= to;
                const bool crossing = !c.markers && i > 0 &&
                                      std::min(px, pixel_x(c.x[i - 1])) <= to && std::max(px, pixel_x(c.x[i - 1])) >= from;
                if (inside || crossing) {
                    low = std::min({low, c.y[i], crossing ? c.y[i - 1] : c.y[i]});
                    high = std::max({high, c.y[i], crossing ? c.y[i - 1] : c.y[i]});
                }
            }
        return {low, high};
    }
};

/// A horizontally centred text actor (set_font's font, size in points) whose position is its
/// bottom centre; the caller adds it to a renderer and places it.
vtkSmartPointer<vtkTextActor> text_actor(const std::string& text, int size, bool bold)
{
    auto actor = vtkSmartPointer<vtkTextActor>::New();
    actor->SetInput(text.c_str());
    set_font(actor->GetTextProperty(), size, bold);
    actor->GetTextProperty()->SetJustificationToCentered();
    actor->GetTextProperty()->SetVerticalJustificationToBottom();
    return actor;
}

/// The width and height in pixels of a text drawn with these properties (72 dpi, as the figures'
/// windows), as VTK's text renderer measures it.
std::pair<double, double> text_size(vtkTextProperty* properties, const std::string& text)
{
    int box[4] = {0, 0, 0, 0};
    vtkTextRenderer::GetInstance()->GetBoundingBox(properties, text, box, 72);
    return {box[1] - box[0] + 1, box[3] - box[2] + 1};
}

/// The pixel size of the legend vtkChartLegend draws for these names (its own formula: the widest
/// label, the symbol and padding across; a line of "Tgyf" height and padding per entry).
std::pair<double, double> legend_size(vtkTextProperty* labels, const std::vector<std::string>& names)
{
    constexpr int padding = 5, symbol_width = 25;
    const double line = text_size(labels, "Tgyf").second;
    double widest = 0.0;
    for (const std::string& name : names)
        widest = std::max(widest, text_size(labels, name).first);
    return {widest + 2 * padding + symbol_width + 4, names.size() * (line + padding) + padding + 4};
}

/// A perceptually ordered colour map (viridis, sampled at 5 points).
vtkSmartPointer<vtkColorTransferFunction> viridis(double low, double high)
{
    auto map = vtkSmartPointer<vtkColorTransferFunction>::New();
    constexpr double stops[5][3] = {{0.267, 0.005, 0.329}, {0.229, 0.322, 0.546},
                                    {0.128, 0.567, 0.551}, {0.369, 0.789, 0.383},
                                    {0.993, 0.906, 0.144}};
    if (!(high > low))
        high = low + 1.0;
    for (int i = 0; i < 5; ++i)
        map->AddRGBPoint(low + (high - low) * i / 4.0, stops[i][0], stops[i][1], stops[i][2]);
    return map;
}

/// The colours of a categorical field: value k of options.categories in its colour, anything else in
/// the background colour (white), with the names as the legend's annotations.
vtkSmartPointer<vtkLookupTable> category_colours(const std::vector<Category>& categories)
{
    auto table = vtkSmartPointer<vtkLookupTable>::New();
    table->IndexedLookupOn();
    table->SetNumberOfTableValues(static_cast<vtkIdType>(categories.size()));
    for (std::size_t k = 0; k < categories.size(); ++k) {
        const Category& c = categories[k];
        table->SetTableValue(static_cast<vtkIdType>(k), c.colour[0], c.colour[1], c.colour[2], 1.0);
        table->SetAnnotation(vtkVariant(c.value), c.name);
    }
    table->SetNanColor(1.0, 1.0, 1.0, 1.0);
    return table;
}

/// The mesh without the cells that have a vertex on the normal's side of the plane (the points and
/// point fields stay; the cell fields keep the rows of the cells that stay).
io::MeshData cut_away(const io::MeshData& mesh, const CutPlane& plane)
{
    const Eigen::Vector3d point(plane.point.data()), normal(plane.normal.data());
    const double tolerance = 1e-9 * (mesh.points.colwise().maxCoeff() - mesh.points.colwise().minCoeff()).norm();
    std::vector<Eigen::Index> kept;
    for (Eigen::Index c = 0; c < mesh.cells.rows(); ++c) {
        bool behind = true;
        for (Eigen::Index k = 0; k < mesh.cells.cols(); ++k)
            behind = behind && (mesh.points.row(mesh.cells(c, k)).transpose() - point).dot(normal) <= tolerance;
        if (behind)
            kept.push_back(c);
    }
    io::MeshData out{mesh.points, MatrixXiR(kept.size(), mesh.cells.cols()), mesh.point_data, {}};
    for (std::size_t i = 0; i < kept.size(); ++i)
        out.cells.row(static_cast<Eigen::Index>(i)) = mesh.cells.row(kept[i]);
    for (const io::Field& field : mesh.cell_data) {
        io::Field rows{field.name, Eigen::MatrixXd(kept.size(), field.values.cols())};
        for (std::size_t i = 0; i < kept.size(); ++i)
            rows.values.row(static_cast<Eigen::Index>(i)) = field.values.row(kept[i]);
        out.cell_data.push_back(rows);
    }
    return out;
}

/// A colour bar's labels, written by us rather than by VTK (whose printf format has no true minus
/// sign: "-0.5"): the bar, the renderer its labels go to, the values to label and the bar's range.
/// Where the bar's colour strip lies is known only after a render (render_with_labels).
struct BarLabels {
    vtkSmartPointer<vtkScalarBarActor> bar;  // nullptr: no colour bar (a categorical field)
    vtkSmartPointer<vtkRenderer> texts;
    std::vector<double> ticks;
    double low = 0.0, high = 1.0;
    int font_size = 15;
};

/// Renders window, then writes labels' values (tick_labels) beside its colour strip, each centred
/// on its value's height, and renders again.
void render_with_labels(vtkRenderWindow* window, const BarLabels& labels)
{
    window->Render();
    if (!labels.bar)
        return;
    int strip[4];  // x, y, width, height in pixels
    labels.bar->GetScalarBarRect(strip, labels.texts);
    const std::vector<std::string> texts = tick_labels(labels.ticks);
    for (std::size_t k = 0; k < labels.ticks.size(); ++k) {
        const double at = labels.high > labels.low ? (labels.ticks[k] - labels.low) / (labels.high - labels.low) : 0.5;
        auto label = vtkSmartPointer<vtkTextActor>::New();
        label->SetInput(texts[k].c_str());
        set_font(label->GetTextProperty(), labels.font_size);
        label->GetTextProperty()->SetVerticalJustificationToCentered();
        label->SetPosition(strip[0] + strip[2] + 0.4 * labels.font_size, strip[1] + at * strip[3]);
        labels.texts->AddActor2D(label);
    }
    window->Render();
}

/// Adds to window the renderers that draw a data set's surface coloured by a field: a white
/// backdrop, the data (lit and framed as options say) and the texts (title, colour bar or legend).
/// A mesh (lit = true) is lit by a key, a fill and a back light, with ambient light so that no face
/// is black, and shows its edges if asked; a flat grid is drawn unlit, in the colour map's own
/// colours. The PNGs and an on-screen MeshWindow share it, so they show the same picture; draw it
/// with render_with_labels, which writes the colour bar's labels.
BarLabels add_renderers(vtkRenderWindow* window, vtkDataSet* data, bool cell_field, bool lit, const RenderOptions& options)
{
    vtkNew<vtkDataSetSurfaceFilter> surface;
    surface->SetInputData(data);
    surface->Update();

    vtkDataArray* array = cell_field ? data->GetCellData()->GetArray(options.field.c_str())
                                     : data->GetPointData()->GetArray(options.field.c_str());
    const int component = array->GetNumberOfComponents() == 1 ? 0 : options.component;
    double range[2];
    array->GetRange(range, component);
    if (options.range)
        std::tie(range[0], range[1]) = *options.range;
    std::string clipped;  // the bar's note when its top is clipped
    if (!options.range && options.clip_percentile < 100.0 && options.categories.empty()) {
        std::vector<double> shown(static_cast<std::size_t>(array->GetNumberOfTuples()));
        for (vtkIdType i = 0; i < array->GetNumberOfTuples(); ++i) {
            double magnitude = 0.0;
            for (int c = 0; c < array->GetNumberOfComponents(); ++c)
                magnitude += array->GetComponent(i, c) * array->GetComponent(i, c);
            shown[static_cast<std::size_t>(i)] = component < 0 ? std::sqrt(magnitude) : array->GetComponent(i, component);
        }
        const double top = percentile(shown, options.clip_percentile);
        if (top < range[1] && top > range[0]) {
            clipped = clip_note(options.clip_percentile, range[1], options.unit);
            range[1] = top;
        }
    }

    const int s = options.scale;
    vtkNew<vtkPolyDataMapper> mapper;
    vtkNew<vtkPolyDataNormals> normals;  // smooth shading: vertex normals averaged over the faces
    if (options.smooth) {
        normals->SetInputConnection(surface->GetOutputPort());
        normals->SplittingOff();
        normals->ConsistencyOn();
        mapper->SetInputConnection(normals->GetOutputPort());
    } else {
        mapper->SetInputConnection(surface->GetOutputPort());
    }
    if (cell_field)
        mapper->SetScalarModeToUseCellFieldData();
    else
        mapper->SetScalarModeToUsePointFieldData();
    mapper->SelectColorArray(options.field.c_str());
    vtkSmartPointer<vtkScalarsToColors> colours;
    if (options.categories.empty()) {
        auto continuous = viridis(range[0], range[1]);
        if (component < 0) {
            continuous->SetVectorModeToMagnitude();
        } else {
            continuous->SetVectorModeToComponent();
            continuous->SetVectorComponent(component);
        }
        colours = continuous;
        mapper->SetScalarRange(range);
        mapper->InterpolateScalarsBeforeMappingOn();  // colours between vertices from the map, not blended
    } else {
        colours = category_colours(options.categories);
    }
    mapper->SetLookupTable(colours);
    mapper->ScalarVisibilityOn();

    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    vtkProperty* look = actor->GetProperty();
    if (lit) {
        look->SetAmbient(0.25);
        look->SetDiffuse(0.8);
        look->SetSpecular(0.0);
        if (options.show_edges) {
            look->EdgeVisibilityOn();
            look->SetEdgeColor(0.25, 0.25, 0.25);
            look->SetLineWidth(1.0f * s);
        }
    } else {
        look->SetAmbient(1.0);
        look->SetDiffuse(0.0);
        look->SetSpecular(0.0);
    }

    // A continuous field gets a colour bar on the right, its title a text of its own above it (so
    // that a long field name is never cut to the bar's width); a categorical one a row of swatches
    // along the bottom instead.
    std::vector<vtkSmartPointer<vtkActor2D>> keys;
    BarLabels bar_labels;
    if (options.categories.empty()) {
        // Labels at round values (1, 2, 2.5 or 5 times a power of ten), written by tick_labels
        // (2000, 0.0035, −0.5; never "665." or "2.66e+03") in render_with_labels; VTK lays the
        // bar out for its own labels of the same values, drawn transparent, so the room is kept.
        auto bar = vtkSmartPointer<vtkScalarBarActor>::New();
        bar->SetLookupTable(colours);
        vtkNew<vtkDoubleArray> ticks;
        bar_labels.ticks = round_ticks(range[0], range[1]);
        for (double tick : bar_labels.ticks)
            ticks->InsertNextValue(tick);
        bar->SetUseCustomLabels(true);
        bar->SetCustomLabels(ticks);
        bar->SetLabelFormat("%g");
        bar->SetWidth(0.09);
        bar->SetHeight(0.72);
        bar->SetPosition(0.88, 0.08);
        bar->UnconstrainedFontSizeOn();
        set_font(bar->GetLabelTextProperty(), 15 * s);
        bar->GetLabelTextProperty()->SetOpacity(0.0);
        keys.push_back(bar);
        bar_labels.bar = bar;
        bar_labels.low = range[0];
        bar_labels.high = range[1];
        bar_labels.font_size = 15 * s;
        const std::string name = options.unit.empty() ? options.field : str(options.field, " [", options.unit, "]");
        auto bar_title = vtkSmartPointer<vtkTextActor>::New();
        std::string bar_text = name;
        for (const std::string& note : {options.range_note, clipped})
            if (!note.empty())
                bar_text += "\n" + note;
        bar_title->SetInput(bar_text.c_str());
        set_font(bar_title->GetTextProperty(), 17 * s, true);
        bar_title->GetTextProperty()->SetJustificationToRight();
        bar_title->GetTextProperty()->SetVerticalJustificationToBottom();
        bar_title->SetPosition((options.width - 16) * s, 0.82 * options.height * s);
        keys.push_back(bar_title);
    } else {
        double x = 20.0 * s;
        for (const Category& c : options.categories) {
            // A filled square in the category's colour under an outlined one, then the name.
            for (const auto& [glyph, rgb] : {std::pair{"\u25A0", c.colour}, std::pair{"\u25A1", std::array{0.3, 0.3, 0.3}}}) {
                auto swatch = vtkSmartPointer<vtkTextActor>::New();
                swatch->SetInput(glyph);
                set_font(swatch->GetTextProperty(), 24 * s);
                swatch->GetTextProperty()->SetColor(rgb[0], rgb[1], rgb[2]);
                swatch->SetPosition(x, 14.0 * s);
                keys.push_back(swatch);
            }
            auto name = vtkSmartPointer<vtkTextActor>::New();
            name->SetInput(c.name.c_str());
            set_font(name->GetTextProperty(), 17 * s);
            name->SetPosition(x + 30.0 * s, 18.0 * s);
            keys.push_back(name);
            x += 30.0 * s + text_size(name->GetTextProperty(), c.name).first + 35.0 * s;
        }
    }

    vtkNew<vtkTextActor> title;
    title->SetInput(options.title.c_str());
    set_font(title->GetTextProperty(), 20 * s);
    title->GetTextProperty()->SetVerticalJustificationToTop();  // a title of several lines grows downwards
    title->SetPosition(20 * s, (options.height - 14) * s);

    // Three renderers: a white backdrop, the data (left of the colour bar's strip, so that neither
    // the bar nor its title ever covers it), and the texts over the whole window.
    const bool bar_strip = options.categories.empty();
    // An outline gets a renderer of its own under the data's (same viewport and camera): the body,
    // drawn on the layer above, covers it wherever the two overlap, so it shows only around the body.
    vtkNew<vtkRenderer> backdrop, beneath, renderer;
    auto texts = vtkSmartPointer<vtkRenderer>::New();
    bar_labels.texts = texts;
    backdrop->SetBackground(1.0, 1.0, 1.0);
    renderer->SetBackground(1.0, 1.0, 1.0);
    double top = 1.0;
    if (options.data_under_title) {  // the title's lines (about 26 layout pixels each) stay clear
        const auto lines = 1 + std::count(options.title.begin(), options.title.end(), '\n');
        top = std::max(0.5, 1.0 - (20.0 + 26.0 * static_cast<double>(lines)) / options.height);
    }
    renderer->SetViewport(0.0, 0.0, bar_strip ? 0.84 : 1.0, top);
    renderer->AddActor(actor);
    for (const Prop& prop : options.props) {  // obstacles, a lattice: in the data's camera and lights
        vtkNew<vtkDataSetSurfaceFilter> prop_surface;
        auto prop_grid = io::detail::to_vtk(prop.shape);
        prop_surface->SetInputData(prop_grid);
        vtkNew<vtkPolyDataMapper> prop_mapper;
        vtkNew<vtkPolyDataNormals> prop_normals;  // a ball smooth, a box's edges kept (split at 30°)
        prop_normals->SetInputConnection(prop_surface->GetOutputPort());
        prop_mapper->SetInputConnection(prop.wireframe ? prop_surface->GetOutputPort() : prop_normals->GetOutputPort());
        if (prop.by_field) {
            if (prop_grid->GetPointData()->HasArray(options.field.c_str()))
                prop_mapper->SetScalarModeToUsePointFieldData();
            else if (prop_grid->GetCellData()->HasArray(options.field.c_str()))
                prop_mapper->SetScalarModeToUseCellFieldData();
            else
                throw Error(str("cannot draw a prop by the field '", options.field, "': it has no such field"));
            prop_mapper->SelectColorArray(options.field.c_str());
            prop_mapper->SetLookupTable(colours);
            prop_mapper->SetScalarRange(range);
            prop_mapper->ScalarVisibilityOn();
        } else {
            prop_mapper->ScalarVisibilityOff();
        }
        vtkNew<vtkActor> prop_actor;
        prop_actor->SetMapper(prop_mapper);
        vtkProperty* prop_look = prop_actor->GetProperty();
        prop_look->SetColor(prop.colour[0], prop.colour[1], prop.colour[2]);
        prop_look->SetOpacity(prop.opacity);
        prop_look->SetAmbient(0.3);
        prop_look->SetDiffuse(0.7);
        prop_look->SetSpecular(0.0);
        if (prop.wireframe) {
            prop_look->SetRepresentationToWireframe();
            prop_look->SetLineWidth(1.5f * s);
            prop_look->LightingOff();
        }
        renderer->AddActor(prop_actor);
    }
    const int layers = options.outline ? 3 : 2;
    if (options.outline) {  // light grey, lit softly, no edges
        vtkNew<vtkDataSetSurfaceFilter> outline_surface;
        outline_surface->SetInputData(io::detail::to_vtk(*options.outline));
        vtkNew<vtkPolyDataMapper> outline_mapper;
        outline_mapper->SetInputConnection(outline_surface->GetOutputPort());
        outline_mapper->ScalarVisibilityOff();
        vtkNew<vtkActor> outline_actor;
        outline_actor->SetMapper(outline_mapper);
        outline_actor->GetProperty()->SetColor(0.84, 0.84, 0.84);
        outline_actor->GetProperty()->SetAmbient(0.7);
        outline_actor->GetProperty()->SetDiffuse(0.3);
        beneath->SetBackground(1.0, 1.0, 1.0);
        beneath->SetViewport(renderer->GetViewport());
        beneath->SetActiveCamera(renderer->GetActiveCamera());
        beneath->InteractiveOff();
        beneath->AddActor(outline_actor);
        renderer->SetLayer(1);
    }
    texts->SetLayer(layers - 1);
    texts->InteractiveOff();
    for (const auto& key : keys)
        texts->AddActor2D(key);
    texts->AddActor2D(title);
    vtkCamera* camera = renderer->GetActiveCamera();
    camera->SetPosition(-options.view_direction[0], -options.view_direction[1],
                        -options.view_direction[2]);
    camera->SetFocalPoint(0.0, 0.0, 0.0);
    camera->SetViewUp(options.view_up.data());
    if (lit) {
        renderer->RemoveAllLights();
        vtkNew<vtkLightKit> lights;  // key, fill, back and head lights, attached to the camera
        lights->AddLightsToRenderer(renderer);
    }
    if (options.frame_bounds) {
        std::array<double, 6> bounds = *options.frame_bounds;
        renderer->ResetCamera(bounds.data());
    } else {
        renderer->ResetCamera();
    }
    camera->Zoom(1.1);

    window->SetNumberOfLayers(layers);
    window->AddRenderer(backdrop);
    if (options.outline)
        window->AddRenderer(beneath);
    window->AddRenderer(renderer);
    window->AddRenderer(texts);
    return bar_labels;
}

/// Draws a data set's surface coloured by a field into a PNG (add_renderers, offscreen).
bool render_dataset(const std::filesystem::path& path, vtkDataSet* data, bool cell_field, bool lit,
                    const RenderOptions& options)
{
    vtkNew<vtkRenderWindow> window;
    window->SetDisplayId(shared_display());
    window->SetOffScreenRendering(1);
    window->SetSize(options.width * options.scale, options.height * options.scale);
    render_with_labels(window, add_renderers(window, data, cell_field, lit, options));
    write_png(window, path);
    return true;
}

/// The grid of a mesh to draw with options (cut if asked), and whether its field is a cell field.
/// fem::Error if the mesh has no such field.
std::pair<vtkSmartPointer<vtkUnstructuredGrid>, bool> drawable(const io::MeshData& mesh, const RenderOptions& options)
{
    auto grid = io::detail::to_vtk(options.cut ? cut_away(mesh, *options.cut) : mesh);
    const bool point_field = grid->GetPointData()->HasArray(options.field.c_str());
    if (!point_field && !grid->GetCellData()->HasArray(options.field.c_str()))
        throw Error(str("cannot render field '", options.field, "': the mesh has no such field"));
    return {grid, !point_field};
}

}  // namespace

void grow_bounds(std::array<double, 6>& box, const MatrixX3d& points)
{
    if (points.rows() == 0)
        return;
    for (int axis = 0; axis < 3; ++axis) {
        box[2 * axis] = std::min(box[2 * axis], points.col(axis).minCoeff());
        box[2 * axis + 1] = std::max(box[2 * axis + 1], points.col(axis).maxCoeff());
    }
}

std::array<double, 6> empty_bounds()
{
    const double inf = std::numeric_limits<double>::infinity();
    return {inf, -inf, inf, -inf, inf, -inf};
}

bool display_available()
{
    return shared_display() != nullptr;
}

bool can_draw(bool figures_wanted)
{
    if (!figures_wanted)
        return false;
    if (display_available())
        return true;
    static bool told = false;
    if (!told) {
        told = true;
        std::cout << "note: no X display, so the PNG figures were skipped (VTK files and CSVs are "
                     "written); run under `xvfb-run -a` to get them\n";
    }
    return false;
}

bool save_chart(const LineChart& chart, const std::filesystem::path& stem, bool figures)
{
    std::filesystem::path csv_path = stem;
    csv_path += ".csv";
    std::ostringstream file;
    file << "series," << csv_field(chart.x_label) << ',' << csv_field(chart.y_label) << '\n';
    file.precision(17);
    for (const Series& s : chart.series) {
        if (s.x.size() != s.y.size())
            throw Error(str("chart '", chart.title, "', series '", s.name, "': ", s.x.size(),
                            " x values but ", s.y.size(), " y values"));
        for (std::size_t i = 0; i < s.x.size(); ++i)
            file << csv_field(s.name) << ',' << s.x[i] << ',' << s.y[i] << '\n';
    }
    write_file(csv_path, file.str());
    if (!can_draw(figures))
        return false;

    // A plain offscreen window with a context actor: vtkContextView would also create an X
    // interactor, whose initialisation crashes intermittently on a virtual display.
    vtkNew<vtkRenderer> renderer;
    renderer->SetBackground(1.0, 1.0, 1.0);
    vtkNew<vtkRenderWindow> window;
    window->SetDisplayId(shared_display());
    window->SetOffScreenRendering(1);
    const int s = pixel_scale;
    const int width = chart.width * s, height = chart.height * s;
    window->SetSize(width, height);
    window->AddRenderer(renderer);
    vtkNew<vtkContextActor> context;
    context->GetScene()->SetRenderer(renderer);
    renderer->AddActor(context);
    vtkNew<vtkChartXY> xy;
    context->GetScene()->AddItem(xy);
    // The chart's title and x axis title are text actors, not the chart's own: VTK 9.1's context
    // device draws a top-aligned string (those two) shifted by its descent, so its descenders
    // were cut and the top of its glyphs showed again under it. The chart gets the window less a
    // strip at the top and one at the bottom, where the two actors go.
    const double margin = 8.0 * s;
    auto title = text_actor(chart.title, 18 * s, false);
    auto x_title = text_actor(chart.x_label, 16 * s, true);
    const double title_height = text_size(title->GetTextProperty(), chart.title).second;
    const double x_title_height = text_size(x_title->GetTextProperty(), chart.x_label).second;
    const double top_strip = chart.title.empty() ? 0.0 : title_height + margin;  // the chart adds its own border
    const double bottom_strip = chart.x_label.empty() ? margin : x_title_height + 2 * margin;
    xy->SetAutoSize(false);
    xy->SetSize(vtkRectf(0.0f, float(bottom_strip), float(width), float(height - bottom_strip - top_strip)));
    title->SetPosition(0.5 * width, height - margin);
    title->GetTextProperty()->SetVerticalJustificationToTop();
    renderer->AddActor2D(title);
    renderer->AddActor2D(x_title);
    vtkAxis* x_axis = xy->GetAxis(vtkAxis::BOTTOM);
    vtkAxis* y_axis = xy->GetAxis(vtkAxis::LEFT);
    x_axis->SetTitle("");  // (drawn by x_title)
    y_axis->SetTitle(chart.y_label);
    x_axis->SetLogScale(chart.log_x);
    y_axis->SetLogScale(chart.log_y);
    for (vtkAxis* axis : {x_axis, y_axis}) {
        set_font(axis->GetTitleProperties(), 16 * s, true);
        set_font(axis->GetLabelProperties(), 13 * s);
        axis->GetPen()->SetWidth(1.0f * s);
        axis->GetGridPen()->SetWidth(1.0f * s);
        axis->SetTickLength(5.0f * s);
    }
    // The legend is placed by hand (CUSTOM): in the first corner the data leave free (see below).
    vtkChartLegend* legend = xy->GetLegend();
    xy->SetShowLegend(true);
    legend->SetInline(true);
    legend->SetHorizontalAlignment(vtkChartLegend::CUSTOM);
    legend->SetVerticalAlignment(vtkChartLegend::CUSTOM);
    set_font(legend->GetLabelProperties(), 13 * s);

    ChartLayout layout;
    layout.sx.log = chart.log_x;
    layout.sy.log = chart.log_y;
    std::vector<std::string> names;
    std::vector<vtkSmartPointer<vtkTable>> tables;  // the plots keep pointers into these
    std::vector<std::size_t> colours_taken;
    for (std::size_t k = 0; k < chart.series.size(); ++k) {
        const Series& series = chart.series[k];
        auto table = vtkSmartPointer<vtkTable>::New();
        vtkNew<vtkDoubleArray> xs, ys;
        xs->SetName(chart.x_label.c_str());
        ys->SetName(series.name.c_str());
        ChartLayout::Curve curve{{}, {}, series.markers_only};
        for (std::size_t i = 0; i < series.x.size(); ++i)
            if (plottable(series.x[i], series.y[i], chart)) {
                xs->InsertNextValue(series.x[i]);
                ys->InsertNextValue(series.y[i]);
                curve.x.push_back(layout.sx.to(series.x[i]));
                curve.y.push_back(layout.sy.to(series.y[i]));
            }
        if (curve.x.empty())
            continue;
        layout.curves.push_back(curve);
        names.push_back(series.name);
        table->AddColumn(xs);
        table->AddColumn(ys);
        tables.push_back(table);
        vtkPlot* line = xy->AddPlot(series.markers_only ? vtkChart::POINTS : vtkChart::LINE);
        line->SetInputData(table, 0, 1);
        const std::size_t colour = series_colour(series.name, colours_taken);
        colours_taken.push_back(colour);
        const auto& rgb = line_colours[colour];
        line->SetColor(rgb[0], rgb[1], rgb[2], 255);
        line->SetWidth(2.5f * s);
        if (series.dashed)
            line->GetPen()->SetLineType(vtkPen::DASH_LINE);
        line->SetLabel(series.name);
        constexpr std::size_t short_series = 12;  // this many points or fewer get markers on the line
        if (auto* points = vtkPlotPoints::SafeDownCast(line)) {
            if (series.markers_only) {
                points->SetMarkerStyle(vtkPlotPoints::DIAMOND);
                points->SetMarkerSize(14.0f * s);
            } else if (curve.x.size() <= short_series) {
                points->SetMarkerStyle(vtkPlotPoints::CIRCLE);
                points->SetMarkerSize(7.0f * s);
            } else {
                points->SetMarkerStyle(vtkPlotPoints::NONE);
            }
        }
    }

    // Fixed axis ranges with room around the data (padded_range).
    if (!layout.curves.empty()) {
        double x_low = std::numeric_limits<double>::infinity(), x_high = -x_low, y_low = x_low, y_high = -x_low;
        for (const ChartLayout::Curve& c : layout.curves) {
            x_low = std::min(x_low, *std::min_element(c.x.begin(), c.x.end()));
            x_high = std::max(x_high, *std::max_element(c.x.begin(), c.x.end()));
            y_low = std::min(y_low, *std::min_element(c.y.begin(), c.y.end()));
            y_high = std::max(y_high, *std::max_element(c.y.begin(), c.y.end()));
        }
        std::tie(layout.x_low, layout.x_high) = padded_range(x_low, x_high, chart.log_x);
        std::tie(layout.y_low, layout.y_high) = padded_range(y_low, y_high, chart.log_y);
    }
    const auto apply_ranges = [&] {
        x_axis->SetBehavior(vtkAxis::FIXED);
        y_axis->SetBehavior(vtkAxis::FIXED);
        x_axis->SetUnscaledRange(layout.sx.from(layout.x_low), layout.sx.from(layout.x_high));
        y_axis->SetUnscaledRange(layout.sy.from(layout.y_low), layout.sy.from(layout.y_high));
        if (chart.log_x)
            set_log_ticks(x_axis, layout.x_low, layout.x_high);
        else if (layout.whole_numbers_x())
            set_integer_ticks(x_axis, layout.x_low, layout.x_high);
        else
            set_linear_ticks(x_axis, layout.x_low, layout.x_high);
        if (chart.log_y)
            set_log_ticks(y_axis, layout.y_low, layout.y_high);
        else if (layout.whole_numbers_y())
            set_integer_ticks(y_axis, layout.y_low, layout.y_high);
        else
            set_linear_ticks(y_axis, layout.y_low, layout.y_high);
        window->Render();  // lays the chart out: the plot area is known after it
        layout.left = xy->GetPoint1()[0];
        layout.bottom = xy->GetPoint1()[1];
        layout.right = xy->GetPoint2()[0];
        layout.top = xy->GetPoint2()[1];
    };
    apply_ranges();

    // The legend goes to the preferred corner if no line or marker passes there, else to the first
    // free one of the others; if every corner is taken, the y range grows at the top or the bottom
    // (whichever needs less) until the legend fits above or below the data.
    const auto [legend_width, legend_height] = legend_size(legend->GetLabelProperties(), names);
    std::vector<Corner> corners{chart.legend};
    for (Corner c : {Corner::top_right, Corner::top_left, Corner::bottom_right, Corner::bottom_left})
        if (c != chart.legend)
            corners.push_back(c);
    // (The sizes are captured by value: clang 14, which builds the fuzz targets, cannot capture a
    // structured binding by reference.)
    const auto free_corner = std::find_if(corners.begin(), corners.end(),
                                          [&, width = legend_width, height = legend_height](Corner c) {
        return !layout.covers(layout.legend_box(c, width, height));
    });
    Corner corner = chart.legend;
    if (free_corner != corners.end()) {
        corner = *free_corner;
    } else if (!layout.curves.empty()) {
        const double needed = (legend_height + 20.0) / (layout.top - layout.bottom);  // of the plot height
        double best_growth = std::numeric_limits<double>::infinity(), best_low = layout.y_low, best_high = layout.y_high;
        for (Corner c : corners) {
            const PixelBox box = layout.legend_box(c, legend_width, legend_height);
            const auto [low, high] = layout.y_extent_between(box.left, box.right);
            const bool at_top = c == Corner::top_left || c == Corner::top_right;
            const double span = layout.y_high - layout.y_low;
            // the data under (over) the legend may use 1 − needed of the new height
            const double new_span = at_top ? (high - layout.y_low) / (1.0 - needed) : (layout.y_high - low) / (1.0 - needed);
            if (needed < 0.8 && new_span / span < best_growth) {
                best_growth = new_span / span;
                corner = c;
                best_low = at_top ? layout.y_low : layout.y_high - std::max(new_span, span);
                best_high = at_top ? layout.y_low + std::max(new_span, span) : layout.y_high;
            }
        }
        layout.y_low = best_low;
        layout.y_high = best_high;
        apply_ranges();
    }
    const PixelBox box = layout.legend_box(corner, legend_width, legend_height);
    legend->SetPoint(vtkVector2f(float(box.left), float(box.bottom)));
    x_title->SetPosition(0.5 * (layout.left + layout.right), margin);  // centred under the plot area
    window->Render();
    std::filesystem::path png_path = stem;
    png_path += ".png";
    write_png(window, png_path);
    std::filesystem::path svg_path = stem;
    svg_path += ".svg";
    write_svg(window, svg_path);
    return true;
}

bool render_mesh_png(const std::filesystem::path& path, const io::MeshData& mesh,
                     const RenderOptions& options)
{
    const auto [grid, cell_field] = drawable(mesh, options);
    if (!can_draw(true))
        return false;
    return render_dataset(path, grid, cell_field, true, options);
}

// --- MeshWindow --------------------------------------------------------------------------------

struct MeshWindow::Impl {
    vtkNew<vtkRenderWindow> window;
    vtkNew<vtkRenderWindowInteractor> interactor;
    vtkNew<vtkCallbackCommand> on_key;
    std::string keys;  // pressed since the last poll
};

MeshWindow::MeshWindow(const RenderOptions& options, const std::string& window_name) : impl_(std::make_unique<Impl>())
{
    if (!display_available())
        throw Error("no X display for a window (set DISPLAY, or run under xvfb-run -a)");
    impl_->window->SetDisplayId(shared_display());
    impl_->window->SetSize(options.width * options.scale, options.height * options.scale);
    impl_->window->SetWindowName(window_name.c_str());
    impl_->interactor->SetRenderWindow(impl_->window);
    impl_->interactor->SetInteractorStyle(nullptr);  // the camera stays the PNGs' one
    impl_->on_key->SetClientData(impl_.get());
    impl_->on_key->SetCallback([](vtkObject* caller, unsigned long, void* client, void*) {
        auto* interactor = static_cast<vtkRenderWindowInteractor*>(caller);
        const std::string key = interactor->GetKeySym() ? interactor->GetKeySym() : "";
        static_cast<Impl*>(client)->keys += key == "space" ? ' ' : key == "Right" ? '>' : key.size() == 1 ? key[0] : '\0';
    });
    impl_->interactor->AddObserver(vtkCommand::KeyPressEvent, impl_->on_key);
    impl_->interactor->Initialize();
}

MeshWindow::~MeshWindow() = default;

void MeshWindow::show(const io::MeshData& mesh, const RenderOptions& options)
{
    const auto [grid, cell_field] = drawable(mesh, options);
    impl_->window->GetRenderers()->RemoveAllItems();
    render_with_labels(impl_->window, add_renderers(impl_->window, grid, cell_field, true, options));
}

std::string MeshWindow::poll_keys()
{
    impl_->interactor->ProcessEvents();
    std::string keys;
    keys.swap(impl_->keys);
    keys.erase(std::remove(keys.begin(), keys.end(), '\0'), keys.end());
    return keys;
}

void MeshWindow::save_png(const std::filesystem::path& path)
{
    write_png(impl_->window, path);
}

bool render_grid_png(const std::filesystem::path& path, const io::ImageGrid& grid,
                     const RenderOptions& options)
{
    const auto image = io::detail::to_vtk(grid);
    if (!image->GetPointData()->HasArray(options.field.c_str()))
        throw Error(str("cannot render field '", options.field, "': the grid has no such field"));
    if (!can_draw(true))
        return false;
    return render_dataset(path, image, false, false, options);
}

}  // namespace fem::fig
