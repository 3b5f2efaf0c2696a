// Figures: meshes and grids coloured by a field, rendered with VTK offscreen to PNG: the lights,
// the camera, the colour map or categories, the colour bar and its labels, the cut and the props.
// The on-screen window (figures_window.cpp) draws with the same renderers.
#include "common/figures.hpp"

#include "common/error.hpp"
#include "common/figures_internal.hpp"
#include "common/vtk_convert.hpp"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellData.h>
#include <vtkColorTransferFunction.h>
#include <vtkDataSetSurfaceFilter.h>
#include <vtkDoubleArray.h>
#include <vtkLightKit.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataNormals.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSmartPointer.h>
#include <vtkTextActor.h>
#include <vtkUnstructuredGrid.h>
#include <vtkVariant.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace fem::fig {

using namespace detail;

namespace {

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

}  // namespace

namespace detail {

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
    bar_labels.data = renderer;
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

}  // namespace detail

namespace {

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

}  // namespace

namespace detail {

std::pair<vtkSmartPointer<vtkUnstructuredGrid>, bool> drawable(const io::MeshData& mesh, const RenderOptions& options)
{
    auto grid = io::detail::to_vtk(options.cut ? cut_away(mesh, *options.cut) : mesh);
    const bool point_field = grid->GetPointData()->HasArray(options.field.c_str());
    if (!point_field && !grid->GetCellData()->HasArray(options.field.c_str()))
        throw Error(str("cannot render field '", options.field, "': the mesh has no such field"));
    return {grid, !point_field};
}

}  // namespace detail

bool render_mesh_png(const std::filesystem::path& path, const io::MeshData& mesh,
                     const RenderOptions& options)
{
    const auto [grid, cell_field] = drawable(mesh, options);
    if (!can_draw(true))
        return false;
    return render_dataset(path, grid, cell_field, true, options);
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
