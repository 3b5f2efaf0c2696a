#pragma once
// Internal to common/: the in-memory conversion of our mesh and grid types to VTK data sets,
// shared by the file writers (vtk_io.cpp) and the renderer (figures.cpp).

#include "common/vtk_io.hpp"

#include <vtkImageData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>

namespace fem::io::detail {

/// The mesh as a VTK unstructured grid with its point and cell fields (validated first).
vtkSmartPointer<vtkUnstructuredGrid> to_vtk(const MeshData& mesh);

/// The mesh (cells: points, lines or triangles) as VTK poly data with its fields (validated first);
/// fem::Error for tetrahedra.
vtkSmartPointer<vtkPolyData> to_vtk_polydata(const MeshData& mesh);

/// The grid as VTK image data with its point fields (validated first).
vtkSmartPointer<vtkImageData> to_vtk(const ImageGrid& grid);

}  // namespace fem::io::detail
