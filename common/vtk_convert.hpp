#pragma once
// Internal to common/: the in-memory conversion of our mesh and grid types to VTK data sets,
// shared by the file writers (vtk_io.cpp) and the renderer (figures.cpp), and back (the .vtu reader;
// fuzz/fuzz_vtu_grid.cpp fuzzes it).

#include "common/vtk_io.hpp"

#include <vtkImageData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>

#include <string>

namespace fem::io::detail {

/// The mesh as a VTK unstructured grid with its point and cell fields (validated first).
vtkSmartPointer<vtkUnstructuredGrid> to_vtk(const MeshData& mesh);

/// The mesh (cells: points, lines or triangles) as VTK poly data with its fields (validated first);
/// fem::Error for tetrahedra.
vtkSmartPointer<vtkPolyData> to_vtk_polydata(const MeshData& mesh);

/// The mesh of an unstructured grid that VTK read from `file`: its points, its cells (all of one of
/// the four kinds of MeshData: checked by VTK cell type and point range, never through a VTK cell
/// object, which an unknown type does not have) and its point and cell fields, then validate()d.
/// fem::Error naming `file` for anything else: another or a mixed cell type, a cell with the wrong
/// number of points or a point out of range, a non-finite value, a field with a row count that
/// does not match.
MeshData from_vtk(vtkUnstructuredGrid* grid, const std::string& file);

/// The grid as VTK image data with its point fields (validated first).
vtkSmartPointer<vtkImageData> to_vtk(const ImageGrid& grid);

}  // namespace fem::io::detail
