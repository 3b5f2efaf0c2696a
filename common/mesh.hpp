#pragma once
// Triangle and tetrahedral meshes with libigl's names, their generators and their validation.
// V: #V×3 rest positions; F: #F×3 triangles; T: #T×4 tetrahedra; row-major, 0-based indices.
// A tetrahedron (a, b, c, d) is positively oriented when (b−a)·((c−a)×(d−a)) > 0; a triangle in
// the xy-plane is positively oriented when it is counter-clockwise seen from +z.

#include "common/types.hpp"

#include <Eigen/Core>

#include <functional>
#include <string>
#include <string_view>

namespace fem {

struct TriMesh {
    MatrixX3d V;  ///< #V×3 vertex positions
    MatrixX3i F;  ///< #F×3 vertex indices of the triangles
};

struct TetMesh {
    MatrixX3d V;  ///< #V×3 vertex positions
    MatrixX4i T;  ///< #T×4 vertex indices of the tetrahedra
};

/// The unit square [0,1]² (z = 0) cut into n×n cells of side h = 1/n, each split into two
/// counter-clockwise triangles: (n+1)² vertices, 2n² triangles. jitter ∈ [0, 0.24] moves every
/// interior vertex by a random offset of at most jitter·h in x and y (seeded, reproducible), which
/// keeps every triangle positively oriented (each vertex moves less than half the smallest
/// height h/√2). fem::Error for n < 1 or jitter outside [0, 0.24].
TriMesh square_mesh(int n, double jitter = 0.0, unsigned seed = 1);

/// The box [0,size.x]×[0,size.y]×[0,size.z] cut into nx×ny×nz cubes, each split into 6
/// positively oriented tetrahedra sharing the cube's main diagonal (the Kuhn/Freudenthal split,
/// conforming across cube faces): (nx+1)(ny+1)(nz+1) vertices, 6·nx·ny·nz tetrahedra.
/// Vertex (i,j,k) has index i + (nx+1)(j + (ny+1)k). fem::Error for counts < 1 or sizes ≤ 0.
TetMesh box_mesh(int nx, int ny, int nz, const Eigen::Vector3d& size = Eigen::Vector3d::Ones());

/// A beam along x: length × width × height, with cells_along cubes along x and the cross-section
/// split into as many cells as keep them close to cubes (at least 1). Built with box_mesh.
TetMesh beam_mesh(double length, double width, double height, int cells_along);

/// What validate() does with a negatively oriented (inverted) tetrahedron.
enum class Inverted { reject, reorient };

/// Where the vertices and elements of a mesh were read from, for the messages of validate():
/// vertex(v) and element(e) name the place of vertex v and element e, e.g. "box.node, line 12".
/// An empty function names `source` instead. The readers of common/mesh_io.hpp pass one.
struct MeshOrigin {
    std::string source = "mesh";
    std::function<std::string(Eigen::Index vertex)> vertex;
    std::function<std::string(Eigen::Index element)> element;
};

/// Checks a triangle mesh: V and F non-empty, finite coordinates, indices in range, no repeated
/// vertex in a triangle, no zero-area triangle (area ≤ 1e-14 · (longest edge)²). fem::Error names
/// `source` (e.g. a file name), the element and what is allowed.
void validate(const TriMesh& mesh, std::string_view source = "mesh");
/// The same checks, each message naming the place origin gives for the vertex or element.
void validate(const TriMesh& mesh, const MeshOrigin& origin);

/// Checks a tetrahedral mesh like the triangle one, plus orientation: a zero-volume tetrahedron
/// (|6V| ≤ 1e-12 · (longest edge)³) is always an error; an inverted one is an error with
/// Inverted::reject, and is repaired by swapping its last two vertices with Inverted::reorient.
/// Returns the number of tetrahedra reoriented (always 0 with reject).
int validate(TetMesh& mesh, std::string_view source = "mesh", Inverted inverted = Inverted::reject);
/// The same checks, each message naming the place origin gives for the vertex or element.
int validate(TetMesh& mesh, const MeshOrigin& origin, Inverted inverted = Inverted::reject);

/// Six times the signed volume of tetrahedron t: (b−a)·((c−a)×(d−a)).
double tet_signed_volume6(const TetMesh& mesh, int t);

/// The total volume of a tet mesh, Σ |V_t|.
double total_volume(const TetMesh& mesh);

}  // namespace fem
