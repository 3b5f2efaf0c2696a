#include "common/figures.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/table.hpp"
#include "common/vtk_convert.hpp"

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
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotPoints.h>
#include <vtkPointData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkTable.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkUnstructuredGrid.h>
#include <vtkWindowToImageFilter.h>

#include <array>
#include <chrono>
#include <thread>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>

namespace fem::fig {
namespace {

/// The process's one connection to the X server, or nullptr when there is no display.
/// Opening a connection to Xvfb fails now and then on this course's machines (the server hangs up
/// at once), and VTK aborts the process when its own attempt fails. So the connection is opened
/// here, retried a few times, and handed to every render window (SetDisplayId), which then never
/// opens one itself.
Display* shared_display()
{
    static Display* const display = [] {
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

/// Returns whether PNGs can be drawn; says once per process why not.
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

void write_png(vtkRenderWindow* window, const std::filesystem::path& path)
{
    vtkNew<vtkWindowToImageFilter> capture;
    capture->SetInput(window);
    capture->ReadFrontBufferOff();
    capture->Update();
    write_atomically(path, [&](const std::filesystem::path& temporary) {
        vtkNew<vtkPNGWriter> writer;
        writer->SetFileName(temporary.c_str());
        writer->SetInputConnection(capture->GetOutputPort());
        writer->Write();
        if (writer->GetErrorCode() != 0)
            throw Error(str("VTK could not write '", path.string(), "'"));
    });
}

// Line colours of successive series (Tableau 10), as RGB bytes.
constexpr std::array<std::array<unsigned char, 3>, 8> line_colours{{
    {31, 119, 180}, {255, 127, 14}, {44, 160, 44}, {214, 39, 40},
    {148, 103, 189}, {140, 86, 75}, {227, 119, 194}, {127, 127, 127}}};

bool plottable(double x, double y, const LineChart& chart)
{
    return std::isfinite(x) && std::isfinite(y) && (!chart.log_x || x > 0) && (!chart.log_y || y > 0);
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

/// Draws a data set's surface coloured by a field into a PNG.
bool render_dataset(const std::filesystem::path& path, vtkDataSet* data, bool cell_field,
                    const RenderOptions& options)
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

    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(surface->GetOutputPort());
    if (cell_field)
        mapper->SetScalarModeToUseCellFieldData();
    else
        mapper->SetScalarModeToUsePointFieldData();
    mapper->SelectColorArray(options.field.c_str());
    auto colours = viridis(range[0], range[1]);
    if (component < 0) {
        colours->SetVectorModeToMagnitude();
    } else {
        colours->SetVectorModeToComponent();
        colours->SetVectorComponent(component);
    }
    mapper->SetLookupTable(colours);
    mapper->SetScalarRange(range);
    mapper->ScalarVisibilityOn();

    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    if (options.show_edges) {
        actor->GetProperty()->EdgeVisibilityOn();
        actor->GetProperty()->SetEdgeColor(0.15, 0.15, 0.15);
    }

    vtkNew<vtkScalarBarActor> bar;
    bar->SetLookupTable(colours);
    bar->SetTitle(options.field.c_str());
    bar->SetNumberOfLabels(5);
    bar->SetWidth(0.1);
    bar->SetHeight(0.7);
    bar->SetPosition(0.87, 0.15);
    bar->GetTitleTextProperty()->SetColor(0.1, 0.1, 0.1);
    bar->GetLabelTextProperty()->SetColor(0.1, 0.1, 0.1);
    bar->UnconstrainedFontSizeOn();
    bar->GetTitleTextProperty()->SetFontSize(18);
    bar->GetLabelTextProperty()->SetFontSize(14);

    vtkNew<vtkTextActor> title;
    title->SetInput(options.title.c_str());
    title->GetTextProperty()->SetFontSize(22);
    title->GetTextProperty()->SetColor(0.1, 0.1, 0.1);
    title->GetTextProperty()->SetVerticalJustificationToTop();  // a title of several lines grows downwards
    title->SetPosition(20, options.height - 14);

    vtkNew<vtkRenderer> renderer;
    renderer->AddActor(actor);
    renderer->AddActor2D(bar);
    renderer->AddActor2D(title);
    renderer->SetBackground(1.0, 1.0, 1.0);
    renderer->SetViewport(0.0, 0.0, 1.0, 1.0);
    vtkCamera* camera = renderer->GetActiveCamera();
    camera->SetPosition(-options.view_direction[0], -options.view_direction[1],
                        -options.view_direction[2]);
    camera->SetFocalPoint(0.0, 0.0, 0.0);
    camera->SetViewUp(options.view_up.data());
    if (options.frame_bounds) {
        std::array<double, 6> bounds = *options.frame_bounds;
        renderer->ResetCamera(bounds.data());
    } else {
        renderer->ResetCamera();
    }
    camera->Zoom(1.1);

    vtkNew<vtkRenderWindow> window;
    window->SetDisplayId(shared_display());
    window->SetOffScreenRendering(1);
    window->SetSize(options.width, options.height);
    window->AddRenderer(renderer);
    window->Render();
    write_png(window, path);
    return true;
}

}  // namespace

bool display_available()
{
    return shared_display() != nullptr;
}

bool save_chart(const LineChart& chart, const std::filesystem::path& stem, bool figures)
{
    std::filesystem::path csv_path = stem;
    csv_path += ".csv";
    write_atomically(csv_path, [&](const std::filesystem::path& temporary) {
        std::ofstream file(temporary);
        file << "series," << csv_field(chart.x_label) << ',' << csv_field(chart.y_label) << '\n';
        file.precision(17);
        for (const Series& s : chart.series) {
            if (s.x.size() != s.y.size())
                throw Error(str("chart '", chart.title, "', series '", s.name, "': ", s.x.size(),
                                " x values but ", s.y.size(), " y values"));
            for (std::size_t i = 0; i < s.x.size(); ++i)
                file << csv_field(s.name) << ',' << s.x[i] << ',' << s.y[i] << '\n';
        }
        file.close();
        if (!file)
            throw Error(str("cannot write '", csv_path.string(), "'"));
    });
    if (!can_draw(figures))
        return false;

    // A plain offscreen window with a context actor: vtkContextView would also create an X
    // interactor, whose initialisation crashes intermittently on a virtual display.
    vtkNew<vtkRenderer> renderer;
    renderer->SetBackground(1.0, 1.0, 1.0);
    vtkNew<vtkRenderWindow> window;
    window->SetDisplayId(shared_display());
    window->SetOffScreenRendering(1);
    window->SetSize(chart.width, chart.height);
    window->AddRenderer(renderer);
    vtkNew<vtkContextActor> context;
    context->GetScene()->SetRenderer(renderer);
    renderer->AddActor(context);
    vtkNew<vtkChartXY> xy;
    context->GetScene()->AddItem(xy);
    xy->SetTitle(chart.title);
    xy->GetTitleProperties()->SetFontSize(18);
    xy->SetShowLegend(true);
    const bool left = chart.legend == Corner::top_left || chart.legend == Corner::bottom_left;
    const bool top = chart.legend == Corner::top_left || chart.legend == Corner::top_right;
    xy->GetLegend()->SetHorizontalAlignment(left ? vtkChartLegend::LEFT : vtkChartLegend::RIGHT);
    xy->GetLegend()->SetVerticalAlignment(top ? vtkChartLegend::TOP : vtkChartLegend::BOTTOM);
    vtkAxis* x_axis = xy->GetAxis(vtkAxis::BOTTOM);
    vtkAxis* y_axis = xy->GetAxis(vtkAxis::LEFT);
    x_axis->SetTitle(chart.x_label);
    y_axis->SetTitle(chart.y_label);
    x_axis->SetLogScale(chart.log_x);
    y_axis->SetLogScale(chart.log_y);
    for (vtkAxis* axis : {x_axis, y_axis}) {
        axis->GetTitleProperties()->SetFontSize(16);
        axis->GetLabelProperties()->SetFontSize(13);
    }

    std::vector<vtkSmartPointer<vtkTable>> tables;  // the plots keep pointers into these
    for (std::size_t k = 0; k < chart.series.size(); ++k) {
        const Series& s = chart.series[k];
        auto table = vtkSmartPointer<vtkTable>::New();
        vtkNew<vtkDoubleArray> xs, ys;
        xs->SetName(chart.x_label.c_str());
        ys->SetName(s.name.c_str());
        for (std::size_t i = 0; i < s.x.size(); ++i)
            if (plottable(s.x[i], s.y[i], chart)) {
                xs->InsertNextValue(s.x[i]);
                ys->InsertNextValue(s.y[i]);
            }
        if (xs->GetNumberOfTuples() == 0)
            continue;
        table->AddColumn(xs);
        table->AddColumn(ys);
        tables.push_back(table);
        vtkPlot* line = xy->AddPlot(s.markers_only ? vtkChart::POINTS : vtkChart::LINE);
        line->SetInputData(table, 0, 1);
        const auto& rgb = line_colours[k % line_colours.size()];
        line->SetColor(rgb[0], rgb[1], rgb[2], 255);
        line->SetWidth(2.5);
        line->SetLabel(s.name);
        if (auto* points = vtkPlotPoints::SafeDownCast(line); points && s.markers_only) {
            points->SetMarkerStyle(vtkPlotPoints::DIAMOND);
            points->SetMarkerSize(14.0);
        }
    }
    window->Render();
    std::filesystem::path png_path = stem;
    png_path += ".png";
    write_png(window, png_path);
    return true;
}

bool render_mesh_png(const std::filesystem::path& path, const io::MeshData& mesh,
                     const RenderOptions& options)
{
    const auto grid = io::detail::to_vtk(mesh);
    const bool point_field = grid->GetPointData()->HasArray(options.field.c_str());
    if (!point_field && !grid->GetCellData()->HasArray(options.field.c_str()))
        throw Error(str("cannot render field '", options.field, "': the mesh has no such field"));
    if (!can_draw(true))
        return false;
    return render_dataset(path, grid, !point_field, options);
}

bool render_grid_png(const std::filesystem::path& path, const io::ImageGrid& grid,
                     const RenderOptions& options)
{
    const auto image = io::detail::to_vtk(grid);
    if (!image->GetPointData()->HasArray(options.field.c_str()))
        throw Error(str("cannot render field '", options.field, "': the grid has no such field"));
    if (!can_draw(true))
        return false;
    return render_dataset(path, image, false, options);
}

}  // namespace fem::fig
