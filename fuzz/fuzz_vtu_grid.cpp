// A libFuzzer target for the course's checks of an unstructured grid that VTK has read from a .vtu
// file (fem::io::detail::from_vtk, what read_vtu returns): the input bytes build the grid directly
// (points with special values, cells of any VTK type with any point ids, point and cell fields of
// any shape), grids that fuzz_vtu reaches only rarely through VTK's XML reader.
// Expected: a MeshData, or an fem::Error that names the file.

#include "common/error.hpp"
#include "common/vtk_convert.hpp"

#include <fuzzer/FuzzedDataProvider.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkObject.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string_view>
#include <vector>

namespace {

constexpr const char* file = "fuzz-input.vtu";

/// A coordinate or field value: mostly small numbers, sometimes a special one.
double value(FuzzedDataProvider& input)
{
    static constexpr std::array<double, 6> special{0.0, 1.0, -1.0, std::numeric_limits<double>::quiet_NaN(),
                                                   std::numeric_limits<double>::infinity(), 1e300};
    if (input.ConsumeBool())
        return special[input.ConsumeIntegralInRange<std::size_t>(0, special.size() - 1)];
    return input.ConsumeFloatingPointInRange<double>(-10.0, 10.0);
}

/// A field of `rows` rows, give or take one, with 0 to 9 components.
vtkNew<vtkDoubleArray> field(FuzzedDataProvider& input, vtkIdType rows)
{
    vtkNew<vtkDoubleArray> array;
    array->SetName(input.ConsumeBool() ? "u" : "");
    array->SetNumberOfComponents(input.ConsumeIntegralInRange(0, 9));
    const vtkIdType tuples = std::max<vtkIdType>(0, rows + input.ConsumeIntegralInRange(-1, 1));
    array->SetNumberOfTuples(tuples);
    for (vtkIdType i = 0; i < tuples * array->GetNumberOfComponents(); ++i)
        array->SetValue(i, value(input));
    return array;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***)
{
    vtkObject::GlobalWarningDisplayOff();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    FuzzedDataProvider input(data, size);
    vtkNew<vtkUnstructuredGrid> grid;
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    const int point_count = input.ConsumeIntegralInRange(0, 16);
    for (int i = 0; i < point_count; ++i)
        points->InsertNextPoint(value(input), value(input), value(input));
    grid->SetPoints(points);
    const int cell_count = input.ConsumeIntegralInRange(0, 16);
    grid->AllocateEstimate(cell_count, 4);
    for (int c = 0; c < cell_count; ++c) {
        int type = input.ConsumeIntegral<std::uint8_t>();
        if (type == VTK_POLYHEDRON)  // its point list is a face stream that VTK itself parses
            type = VTK_TETRA;
        std::vector<vtkIdType> ids(input.ConsumeIntegralInRange<std::size_t>(0, 6));
        for (vtkIdType& id : ids)
            id = input.ConsumeIntegralInRange<vtkIdType>(-2, point_count + 1);
        grid->InsertNextCell(type, static_cast<vtkIdType>(ids.size()), ids.data());
    }
    for (int f = input.ConsumeIntegralInRange(0, 3); f > 0; --f) {
        if (input.ConsumeBool())
            grid->GetPointData()->AddArray(field(input, point_count));
        else
            grid->GetCellData()->AddArray(field(input, cell_count));
    }
    try {
        fem::io::detail::from_vtk(grid, file);
    } catch (const fem::Error& error) {
        if (std::string_view(error.what()).find(file) == std::string_view::npos) {
            std::fprintf(stderr, "fuzz_vtu_grid: an fem::Error that does not name the file: %s\n", error.what());
            std::abort();
        }
    }
    return 0;
}
