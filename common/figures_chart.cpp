// Figures: line charts (log-log where it fits), drawn with VTK's charts offscreen to PNG and SVG,
// and written as CSV with the same numbers: the axes' ranges and ticks, the series' colours and
// the legend's corner. docs: CONTRIBUTING.md#figures
#include "common/figures.hpp"

#include "common/error.hpp"
#include "common/figures_internal.hpp"
#include "common/files.hpp"
#include "common/table.hpp"

#include <vtkAxis.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContextActor.h>
#include <vtkContextScene.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotPoints.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkStringArray.h>
#include <vtkTable.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace fem::fig {

namespace {

using namespace detail;

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

}  // namespace

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

}  // namespace fem::fig
