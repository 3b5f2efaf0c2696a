// Figures: what the charts, the rendered meshes and the on-screen window share: the one X display
// connection, the PNG and SVG writers, the font, round tick values and their labels, and the
// version every PNG carries. The charts are in figures_chart.cpp, the rendered meshes and grids in
// figures_mesh.cpp, the window in figures_window.cpp.
#include "common/figures.hpp"

#include "common/error.hpp"
#include "common/figures_internal.hpp"
#include "common/files.hpp"
#include "common/vtk_errors.hpp"

#include <X11/Xlib.h>

#include <vtkGL2PSExporter.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkRenderWindow.h>
#include <vtkTextProperty.h>
#include <vtkTextRenderer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace fem::fig {

const int figure_code_version = 5;  // bump it when a figure's look changes (figures.hpp)

namespace detail {

void* shared_display()
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

void set_font(vtkTextProperty* text, int size, bool bold)
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

std::vector<double> round_ticks(double low, double high, int most)
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

std::pair<double, double> text_size(vtkTextProperty* properties, const std::string& text)
{
    int box[4] = {0, 0, 0, 0};
    vtkTextRenderer::GetInstance()->GetBoundingBox(properties, text, box, 72);
    return {box[1] - box[0] + 1, box[3] - box[2] + 1};
}

}  // namespace detail

namespace {

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
    return detail::shared_display() != nullptr;
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

}  // namespace fem::fig
