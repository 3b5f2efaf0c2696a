#pragma once
// Meshes and fields to and from VTK's XML files, written with VTK's own writers so that ParaView
// opens every result: .vtu (unstructured grids), .vti (regular grids), .vtp (surfaces) and .pvd
// (time series, written by hand: VTK 9.1 has no .pvd writer). Every write is atomic, and refuses
// non-finite values and out-of-range indices with an fem::Error.

#include "common/types.hpp"

#include <Eigen/Core>

#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace fem::io {

/// A named field: one row per point (or cell), one column per component (1 scalar, 3 vector,
/// 9 tensor in row-major order).
struct Field {
    std::string name;
    Eigen::MatrixXd values;
};

/// Points, cells and their fields. cells has one row per cell and 1, 2, 3 or 4 columns: vertices,
/// line segments, triangles or tetrahedra (VTK_VERTEX, VTK_LINE, VTK_TRIANGLE, VTK_TETRA).
struct MeshData {
    MatrixX3d points;
    MatrixXiR cells;
    std::vector<Field> point_data;
    std::vector<Field> cell_data;

    /// The field of that name in point_data or cell_data (fem::Error if absent).
    const Field& field(const std::string& name) const;
};

/// A regular grid of dims[0]×dims[1]×dims[2] points (use 1 for unused dimensions), point (i,j,k)
/// at origin + (i,j,k)·spacing. Field rows run over points with i fastest, then j, then k.
struct ImageGrid {
    std::array<int, 3> dims{1, 1, 1};
    std::array<double, 3> spacing{1.0, 1.0, 1.0};
    std::array<double, 3> origin{0.0, 0.0, 0.0};
    std::vector<Field> point_data;
};

// --- A body that moved: the course's one convention ---------------------------------------------
//
// Every .vtu/.vtp of a deformed body stores the REST positions X as its points and the point field
// "displacement" u = x − X (one row per point, 3 columns). ParaView's Warp By Vector on
// "displacement" (scale factor 1) then draws the deformed body, and any other scale exaggerates or
// shrinks the motion; points that were already deformed would be moved twice. displaced_mesh()
// builds such a mesh and warped() gives the deformed one for a picture.

/// The name of the displacement point field of the convention above.
inline constexpr const char* displacement_field = "displacement";

/// The #V×3 rows of a vertex-major vector q = (x₀, y₀, z₀, x₁, …): row v = (q_3v, q_3v+1, q_3v+2).
/// fem::Error if q.size() is not a multiple of 3.
MatrixX3d vertex_rows(const Eigen::VectorXd& q);

/// A mesh in the convention above: points = rest (#V×3), cells as given, and point_data starting
/// with "displacement" = displacement (#V×3). Add further fields to the result.
/// fem::Error if displacement is not rest.rows() × 3.
MeshData displaced_mesh(const MatrixX3d& rest, const MatrixXiR& cells, const MatrixX3d& displacement);

/// A copy of mesh with every point moved to X + scale · u, u its "displacement" field: the
/// deformed body to render (scale 1: true scale). The copy keeps every field, displacement included.
/// fem::Error if mesh has no 3-column point field "displacement" or scale is not finite.
MeshData warped(const MeshData& mesh, double scale = 1.0);

/// Checks counts, indices and finiteness; fem::Error naming the field, row and value otherwise.
void validate(const MeshData& mesh);
void validate(const ImageGrid& grid);

/// Writes mesh as a .vtu file (binary, compressed) with vtkXMLUnstructuredGridWriter.
void write_vtu(const std::filesystem::path& path, const MeshData& mesh);

/// Reads a .vtu file written by write_vtu or ParaView (cells of one type among the four above), with
/// VTK's XML reader, and checks what it read (detail::from_vtk in common/vtk_convert.hpp): fem::Error
/// naming the file for a file VTK cannot read, another or a mixed cell type, a point out of range, a
/// non-finite value. Before VTK reads the file, its counts and data blocks are checked against what
/// it holds (detail::check_vtu_layout in common/vtu_check.hpp): VTK 9.1's reader trusts them, and a
/// corrupted file crashed it.
MeshData read_vtu(const std::filesystem::path& path);

/// Writes mesh (cells: lines or triangles) as a .vtp surface with vtkXMLPolyDataWriter.
void write_vtp(const std::filesystem::path& path, const MeshData& mesh);

/// Writes grid as a .vti image with vtkXMLImageDataWriter.
void write_vti(const std::filesystem::path& path, const ImageGrid& grid);

/// A time series: frames are written to <stem>/<stem>_0000.vtu (or .vti) beside <stem>.pvd, and
/// the .pvd collection is rewritten (atomically) after each frame, so a run that stops early still
/// leaves a valid series of the frames it finished.
class PvdSeries {
public:
    /// pvd_path: e.g. out/01_finite_differences/heat_rod.pvd
    explicit PvdSeries(std::filesystem::path pvd_path);

    void add(double time, const MeshData& frame);
    void add(double time, const ImageGrid& frame);
    /// Writes the frame (cells: lines or triangles) as a .vtp surface (write_vtp), e.g. a skin.
    void add_surface(double time, const MeshData& frame);

    std::size_t frames() const { return entries_.size(); }

private:
    std::filesystem::path next_frame_path(const char* extension) const;
    void record(double time, const std::filesystem::path& frame_path);

    std::filesystem::path pvd_path_;
    std::vector<std::pair<double, std::string>> entries_;
};

/// The (time, file) entries of a .pvd collection, file relative to the .pvd's folder.
std::vector<std::pair<double, std::string>> read_pvd(const std::filesystem::path& path);

}  // namespace fem::io
