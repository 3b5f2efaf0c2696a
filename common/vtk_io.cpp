#include "common/vtk_io.hpp"
#include "common/vtk_convert.hpp"
#include "common/vtk_errors.hpp"
#include "common/vtu_check.hpp"

#include "common/error.hpp"
#include "common/files.hpp"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkIdList.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLImageDataWriter.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace fem::io {
namespace {

int vtk_cell_type(Eigen::Index vertices_per_cell)
{
    switch (vertices_per_cell) {
    case 1: return VTK_VERTEX;
    case 2: return VTK_LINE;
    case 3: return VTK_TRIANGLE;
    case 4: return VTK_TETRA;
    default:
        throw Error(str("cells must have 1, 2, 3 or 4 vertices (point, line, triangle, tetrahedron), got ",
                        vertices_per_cell));
    }
}

void validate_fields(const std::vector<Field>& fields, Eigen::Index rows, const char* kind)
{
    for (const Field& field : fields) {
        if (field.name.empty())
            throw Error(str("a ", kind, " field has no name"));
        if (field.values.rows() != rows)
            throw Error(str(kind, " field '", field.name, "' has ", field.values.rows(),
                            " rows, expected one per ", kind, ": ", rows));
        if (field.values.cols() < 1)
            throw Error(str(kind, " field '", field.name, "' has no components"));
        for (Eigen::Index r = 0; r < field.values.rows(); ++r)
            for (Eigen::Index c = 0; c < field.values.cols(); ++c)
                if (!std::isfinite(field.values(r, c)))
                    throw Error(str(kind, " field '", field.name, "' has the non-finite value ",
                                    field.values(r, c), " at ", kind, " ", r, ", component ", c,
                                    "; only finite values are written"));
    }
}

vtkSmartPointer<vtkDoubleArray> to_vtk_array(const Field& field)
{
    auto array = vtkSmartPointer<vtkDoubleArray>::New();
    array->SetName(field.name.c_str());
    array->SetNumberOfComponents(static_cast<int>(field.values.cols()));
    array->SetNumberOfTuples(field.values.rows());
    for (Eigen::Index r = 0; r < field.values.rows(); ++r)
        for (Eigen::Index c = 0; c < field.values.cols(); ++c)
            array->SetComponent(r, static_cast<int>(c), field.values(r, c));
    return array;
}

Field from_vtk_array(vtkDataArray* array)
{
    Field field;
    field.name = array->GetName() ? array->GetName() : "";
    field.values.resize(array->GetNumberOfTuples(), array->GetNumberOfComponents());
    for (Eigen::Index r = 0; r < field.values.rows(); ++r)
        for (Eigen::Index c = 0; c < field.values.cols(); ++c)
            field.values(r, c) = array->GetComponent(r, static_cast<int>(c));
    return field;
}

vtkSmartPointer<vtkPoints> to_vtk_points(const MatrixX3d& points)
{
    auto vtk_points = vtkSmartPointer<vtkPoints>::New();
    vtk_points->SetDataTypeToDouble();
    vtk_points->SetNumberOfPoints(points.rows());
    for (Eigen::Index i = 0; i < points.rows(); ++i)
        vtk_points->SetPoint(i, points(i, 0), points(i, 1), points(i, 2));
    return vtk_points;
}

vtkSmartPointer<vtkCellArray> to_vtk_cells(const MatrixXiR& cells)
{
    auto vtk_cells = vtkSmartPointer<vtkCellArray>::New();
    vtkNew<vtkIdList> ids;
    ids->SetNumberOfIds(cells.cols());
    for (Eigen::Index e = 0; e < cells.rows(); ++e) {
        for (Eigen::Index k = 0; k < cells.cols(); ++k)
            ids->SetId(k, cells(e, k));
        vtk_cells->InsertNextCell(ids);
    }
    return vtk_cells;
}

void attach_fields(vtkDataSet* data, const std::vector<Field>& point_data,
                   const std::vector<Field>& cell_data)
{
    for (const Field& f : point_data)
        data->GetPointData()->AddArray(to_vtk_array(f));
    for (const Field& f : cell_data)
        data->GetCellData()->AddArray(to_vtk_array(f));
    if (!point_data.empty())
        data->GetPointData()->SetActiveScalars(point_data.front().name.c_str());
    if (!cell_data.empty())
        data->GetCellData()->SetActiveScalars(cell_data.front().name.c_str());
}

/// Runs a configured VTK XML writer into memory and writes the file from there (atomically).
/// VTK 9.1's XML writers free invalid pointers when a write to a file fails (a full disk): they
/// never touch a file here.
template <typename Writer>
void run_writer(Writer* writer, const std::filesystem::path& path)
{
    writer->WriteToOutputStringOn();
    writer->SetDataModeToBinary();
    const detail::VtkErrors errors(writer);
    if (writer->Write() != 1 || writer->GetErrorCode() != 0 || errors.any())
        throw Error(str("VTK could not write '", path.string(), "'", errors.any() ? ": " + errors.text() : ""));
    write_file(path, writer->GetOutputString());
}

std::string xml_escape(const std::string& text)
{
    std::string escaped;
    for (char c : text) {
        switch (c) {
        case '&': escaped += "&amp;"; break;
        case '"': escaped += "&quot;"; break;
        case '<': escaped += "&lt;"; break;
        case '>': escaped += "&gt;"; break;
        default: escaped += c;
        }
    }
    return escaped;
}

}  // namespace

const Field& MeshData::field(const std::string& name) const
{
    for (const auto* fields : {&point_data, &cell_data})
        for (const Field& f : *fields)
            if (f.name == name)
                return f;
    throw Error(str("the mesh has no field named '", name, "'"));
}

MatrixX3d vertex_rows(const Eigen::VectorXd& q)
{
    if (q.size() % 3 != 0)
        throw Error(str("a vertex-major vector needs 3 entries per vertex, got ", q.size(), " entries"));
    return Eigen::Map<const MatrixX3d>(q.data(), q.size() / 3, 3);
}

MeshData displaced_mesh(const MatrixX3d& rest, const MatrixXiR& cells, const MatrixX3d& displacement)
{
    if (displacement.rows() != rest.rows())
        throw Error(str("displacement has ", displacement.rows(), " rows, expected one per point: ", rest.rows()));
    MeshData mesh;
    mesh.points = rest;
    mesh.cells = cells;
    mesh.point_data.push_back({displacement_field, displacement});
    return mesh;
}

MeshData warped(const MeshData& mesh, double scale)
{
    if (!std::isfinite(scale))
        throw Error(str("warp scale must be finite, got ", scale));
    for (const Field& u : mesh.point_data) {
        if (u.name != displacement_field)
            continue;
        if (u.values.cols() != 3 || u.values.rows() != mesh.points.rows())
            throw Error(str("point field '", displacement_field, "' must have 3 components and one row per point (",
                            mesh.points.rows(), "), got ", u.values.rows(), "x", u.values.cols()));
        MeshData deformed = mesh;
        deformed.points += scale * u.values;
        return deformed;
    }
    throw Error(str("the mesh has no point field '", displacement_field, "' to warp by"));
}

void validate(const MeshData& mesh)
{
    for (Eigen::Index i = 0; i < mesh.points.rows(); ++i)
        for (int c = 0; c < 3; ++c)
            if (!std::isfinite(mesh.points(i, c)))
                throw Error(str("point ", i, " has the non-finite coordinate ", mesh.points(i, c)));
    if (mesh.cells.rows() > 0)
        vtk_cell_type(mesh.cells.cols());
    for (Eigen::Index e = 0; e < mesh.cells.rows(); ++e)
        for (Eigen::Index k = 0; k < mesh.cells.cols(); ++k) {
            const int v = mesh.cells(e, k);
            if (v < 0 || v >= mesh.points.rows())
                throw Error(str("cell ", e, " refers to point ", v, "; points are numbered 0 to ",
                                mesh.points.rows() - 1));
        }
    validate_fields(mesh.point_data, mesh.points.rows(), "point");
    validate_fields(mesh.cell_data, mesh.cells.rows(), "cell");
}

void validate(const ImageGrid& grid)
{
    for (int d = 0; d < 3; ++d) {
        if (grid.dims[d] < 1)
            throw Error(str("grid dimension ", d, " has ", grid.dims[d], " points; at least 1 is needed"));
        require_positive(grid.spacing[d], "grid spacing");
        require_finite(grid.origin[d], "grid origin");
    }
    validate_fields(grid.point_data,
                    Eigen::Index(grid.dims[0]) * grid.dims[1] * grid.dims[2], "point");
}

namespace detail {

vtkSmartPointer<vtkUnstructuredGrid> to_vtk(const MeshData& mesh)
{
    validate(mesh);
    auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
    grid->SetPoints(to_vtk_points(mesh.points));
    if (mesh.cells.rows() > 0)
        grid->SetCells(vtk_cell_type(mesh.cells.cols()), to_vtk_cells(mesh.cells));
    attach_fields(grid, mesh.point_data, mesh.cell_data);
    return grid;
}

vtkSmartPointer<vtkImageData> to_vtk(const ImageGrid& grid)
{
    validate(grid);
    auto image = vtkSmartPointer<vtkImageData>::New();
    image->SetDimensions(grid.dims.data());
    image->SetSpacing(grid.spacing.data());
    image->SetOrigin(grid.origin.data());
    attach_fields(image, grid.point_data, {});
    return image;
}

}  // namespace detail

void write_vtu(const std::filesystem::path& path, const MeshData& mesh)
{
    vtkNew<vtkXMLUnstructuredGridWriter> writer;
    writer->SetInputData(detail::to_vtk(mesh));
    run_writer(writer.Get(), path);
}

MeshData read_vtu(const std::filesystem::path& path)
{
    if (!std::filesystem::is_regular_file(path))
        throw Error(str("cannot read '", path.string(), "': no such file"));
    detail::check_vtu_layout(path);  // VTK's reader trusts the file's counts and block headers
    vtkNew<vtkXMLUnstructuredGridReader> reader;
    reader->SetFileName(path.c_str());
    const detail::VtkErrors errors(reader);
    reader->Update();
    vtkUnstructuredGrid* grid = reader->GetOutput();
    if (reader->GetErrorCode() != 0 || errors.any() || grid == nullptr || grid->GetPoints() == nullptr)
        throw Error(str("cannot read '", path.string(), "' as a VTK unstructured grid (.vtu)",
                        errors.any() ? ": " + errors.text() : ""));
    return detail::from_vtk(grid, path.string());
}

namespace detail {

MeshData from_vtk(vtkUnstructuredGrid* grid, const std::string& file)
{
    MeshData mesh;
    mesh.points.resize(grid->GetNumberOfPoints(), 3);
    for (vtkIdType i = 0; i < grid->GetNumberOfPoints(); ++i) {
        double p[3];
        grid->GetPoint(i, p);
        mesh.points.row(i) << p[0], p[1], p[2];
    }
    const vtkIdType cell_count = grid->GetNumberOfCells();
    if (cell_count > 0) {
        // Cells are checked by their VTK type, never by asking VTK for a cell object: a type VTK does
        // not know gives no object at all. All cells must be of one of the four kinds the course
        // writes, and of one kind.
        const int type = grid->GetCellType(0);
        vtkIdType per_cell = 0;
        switch (type) {
        case VTK_VERTEX: per_cell = 1; break;
        case VTK_LINE: per_cell = 2; break;
        case VTK_TRIANGLE: per_cell = 3; break;
        case VTK_TETRA: per_cell = 4; break;
        default:
            throw Error(str("'", file, "': cell 0 has VTK cell type ", type, "; the course reads vertices (",
                            VTK_VERTEX, "), lines (", VTK_LINE, "), triangles (", VTK_TRIANGLE, ") and tetrahedra (",
                            VTK_TETRA, ")"));
        }
        mesh.cells.resize(cell_count, per_cell);
        vtkNew<vtkIdList> ids;
        for (vtkIdType e = 0; e < cell_count; ++e) {
            if (grid->GetCellType(e) != type)
                throw Error(str("'", file, "': cell ", e, " has VTK cell type ", grid->GetCellType(e),
                                ", cell 0 has ", type, "; mixed cell types are not supported"));
            grid->GetCellPoints(e, ids);
            if (ids->GetNumberOfIds() != per_cell)
                throw Error(str("'", file, "': cell ", e, " has ", ids->GetNumberOfIds(), " points; its type ",
                                type, " has ", per_cell));
            for (vtkIdType k = 0; k < per_cell; ++k) {
                const vtkIdType id = ids->GetId(k);
                if (id < 0 || id >= grid->GetNumberOfPoints())
                    throw Error(str("'", file, "': cell ", e, " refers to point ", id, ", the file has ",
                                    grid->GetNumberOfPoints(), " points"));
                mesh.cells(e, k) = static_cast<int>(id);
            }
        }
    }
    for (int a = 0; a < grid->GetPointData()->GetNumberOfArrays(); ++a)
        if (vtkDataArray* array = grid->GetPointData()->GetArray(a))
            mesh.point_data.push_back(from_vtk_array(array));
    for (int a = 0; a < grid->GetCellData()->GetNumberOfArrays(); ++a)
        if (vtkDataArray* array = grid->GetCellData()->GetArray(a))
            mesh.cell_data.push_back(from_vtk_array(array));
    try {
        validate(mesh);
    } catch (const Error& error) {
        throw Error(str("'", file, "': ", error.what()));
    }
    return mesh;
}

}  // namespace detail

namespace detail {

vtkSmartPointer<vtkPolyData> to_vtk_polydata(const MeshData& mesh)
{
    validate(mesh);
    auto poly = vtkSmartPointer<vtkPolyData>::New();
    poly->SetPoints(to_vtk_points(mesh.points));
    if (mesh.cells.rows() > 0) {
        const auto cells = to_vtk_cells(mesh.cells);
        switch (mesh.cells.cols()) {
        case 1: poly->SetVerts(cells); break;
        case 2: poly->SetLines(cells); break;
        case 3: poly->SetPolys(cells); break;
        default:
            throw Error(str("a .vtp surface holds points, lines or triangles; got cells of ",
                            mesh.cells.cols(), " vertices (write tetrahedra with write_vtu)"));
        }
    }
    attach_fields(poly, mesh.point_data, mesh.cell_data);
    return poly;
}

}  // namespace detail

void write_vtp(const std::filesystem::path& path, const MeshData& mesh)
{
    vtkNew<vtkXMLPolyDataWriter> writer;
    writer->SetInputData(detail::to_vtk_polydata(mesh));
    run_writer(writer.Get(), path);
}

void write_vti(const std::filesystem::path& path, const ImageGrid& grid)
{
    vtkNew<vtkXMLImageDataWriter> writer;
    writer->SetInputData(detail::to_vtk(grid));
    run_writer(writer.Get(), path);
}

PvdSeries::PvdSeries(std::filesystem::path pvd_path) : pvd_path_(std::move(pvd_path))
{
    if (pvd_path_.extension() != ".pvd")
        throw Error(str("a time series file must end in .pvd, got '", pvd_path_.string(), "'"));
}

std::filesystem::path PvdSeries::next_frame_path(const char* extension) const
{
    const std::string stem = pvd_path_.stem().string();
    char number[16];
    std::snprintf(number, sizeof number, "_%04zu", entries_.size());
    return pvd_path_.parent_path() / stem / (stem + number + extension);
}

void PvdSeries::add(double time, const MeshData& frame)
{
    const auto path = next_frame_path(".vtu");
    write_vtu(path, frame);
    record(time, path);
}

void PvdSeries::add_surface(double time, const MeshData& frame)
{
    const auto path = next_frame_path(".vtp");
    write_vtp(path, frame);
    record(time, path);
}

void PvdSeries::add(double time, const ImageGrid& frame)
{
    const auto path = next_frame_path(".vti");
    write_vti(path, frame);
    record(time, path);
}

void PvdSeries::record(double time, const std::filesystem::path& frame_path)
{
    require_finite(time, "the time of a frame");
    entries_.emplace_back(time, frame_path.lexically_relative(pvd_path_.parent_path()).generic_string());
    std::ostringstream file;
    file << "<?xml version=\"1.0\"?>\n"
         << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
         << "  <Collection>\n";
    char time_text[64];
    for (const auto& [t, name] : entries_) {
        std::snprintf(time_text, sizeof time_text, "%.17g", t);
        file << "    <DataSet timestep=\"" << time_text << "\" part=\"0\" file=\""
             << xml_escape(name) << "\"/>\n";
    }
    file << "  </Collection>\n</VTKFile>\n";
    write_file(pvd_path_, file.str());
}

std::vector<std::pair<double, std::string>> read_pvd(const std::filesystem::path& path)
{
    std::ifstream file(path);
    if (!file)
        throw Error(str("cannot read '", path.string(), "': no such file"));
    std::stringstream text;
    text << file.rdbuf();
    const std::string content = text.str();
    if (content.find("type=\"Collection\"") == std::string::npos)
        throw Error(str("'", path.string(), "' is not a VTK collection (.pvd) file"));
    // The value of attribute `name` inside the tag [begin, end), or fem::Error.
    const auto attribute = [&](std::size_t begin, std::size_t end, const std::string& name) {
        const std::size_t at = content.find(" " + name + "=\"", begin);
        if (at == std::string::npos || at > end)
            throw Error(str("'", path.string(), "': a DataSet has no ", name, " attribute"));
        const std::size_t value = at + name.size() + 3;
        return content.substr(value, content.find('"', value) - value);
    };
    std::vector<std::pair<double, std::string>> entries;
    for (std::size_t tag = content.find("<DataSet"); tag != std::string::npos;
         tag = content.find("<DataSet", tag + 1)) {
        const std::size_t end = content.find('>', tag);
        const std::string time_text = attribute(tag, end, "timestep");
        char* parsed_end = nullptr;
        const double time = std::strtod(time_text.c_str(), &parsed_end);
        if (time_text.empty() || parsed_end != time_text.c_str() + time_text.size() || !std::isfinite(time))
            throw Error(str("'", path.string(), "': a DataSet has timestep=\"", time_text,
                            "\"; a timestep must be a finite number"));
        entries.emplace_back(time, attribute(tag, end, "file"));
    }
    return entries;
}

}  // namespace fem::io
