#include "common/mesh.hpp"

#include "common/error.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <random>

namespace fem {
namespace {

std::string vertex_place(const MeshOrigin& origin, Eigen::Index v)
{
    return origin.vertex ? origin.vertex(v) : origin.source;
}

std::string element_place(const MeshOrigin& origin, Eigen::Index e)
{
    return origin.element ? origin.element(e) : origin.source;
}

void check_finite_vertices(const MatrixX3d& V, const MeshOrigin& origin)
{
    for (Eigen::Index v = 0; v < V.rows(); ++v)
        for (int c = 0; c < 3; ++c)
            if (!std::isfinite(V(v, c)))
                throw Error(str(vertex_place(origin, v), ": vertex ", v, " has the non-finite coordinate ", V(v, c),
                                "; coordinates must be finite numbers"));
}

template <typename Cells>
void check_indices(const Cells& cells, Eigen::Index vertex_count, const MeshOrigin& origin,
                   const char* kind)
{
    for (Eigen::Index e = 0; e < cells.rows(); ++e)
        for (Eigen::Index k = 0; k < cells.cols(); ++k) {
            const int v = cells(e, k);
            if (v < 0 || v >= vertex_count)
                throw Error(str(element_place(origin, e), ": ", kind, " ", e, " refers to vertex ", v,
                                "; vertices are numbered 0 to ", vertex_count - 1));
            for (Eigen::Index m = 0; m < k; ++m)
                if (cells(e, m) == v)
                    throw Error(str(element_place(origin, e), ": ", kind, " ", e, " uses vertex ", v,
                                    " twice; its corners must be distinct"));
        }
}

}  // namespace

TriMesh square_mesh(int n, double jitter, unsigned seed)
{
    if (n < 1)
        throw Error(str("square_mesh: n must be ≥ 1 cells per side, got ", n));
    if (!(jitter >= 0.0 && jitter <= 0.24))
        throw Error(str("square_mesh: jitter must lie in [0, 0.24] (a fraction of the cell size), got ",
                        jitter));
    const double h = 1.0 / n;
    TriMesh mesh;
    mesh.V.resize((n + 1) * (n + 1), 3);
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> offset(-jitter * h, jitter * h);
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const bool interior = i > 0 && i < n && j > 0 && j < n;
            const double dx = interior ? offset(random) : 0.0;
            const double dy = interior ? offset(random) : 0.0;
            mesh.V.row(j * (n + 1) + i) << i * h + dx, j * h + dy, 0.0;
        }
    mesh.F.resize(2 * n * n, 3);
    int t = 0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const int a = j * (n + 1) + i;  // lower-left corner of the cell
            mesh.F.row(t++) << a, a + 1, a + n + 2;
            mesh.F.row(t++) << a, a + n + 2, a + n + 1;
        }
    return mesh;
}

TetMesh box_mesh(int nx, int ny, int nz, const Eigen::Vector3d& size)
{
    if (nx < 1 || ny < 1 || nz < 1)
        throw Error(str("box_mesh: cell counts must be ≥ 1, got ", nx, "×", ny, "×", nz));
    for (int d = 0; d < 3; ++d)
        require_positive(size[d], "box_mesh: box size");
    const auto index = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };
    TetMesh mesh;
    mesh.V.resize((nx + 1) * (ny + 1) * (nz + 1), 3);
    for (int k = 0; k <= nz; ++k)
        for (int j = 0; j <= ny; ++j)
            for (int i = 0; i <= nx; ++i)
                mesh.V.row(index(i, j, k)) << size.x() * i / nx, size.y() * j / ny, size.z() * k / nz;

    // The six paths from corner 000 to corner 111 along the cube's edges, one per order of the axes.
    constexpr int axis_orders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    mesh.T.resize(6 * nx * ny * nz, 4);
    int t = 0;
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i)
                for (const auto& order : axis_orders) {
                    int corner[3] = {i, j, k};
                    int tet[4];
                    tet[0] = index(corner[0], corner[1], corner[2]);
                    for (int step = 0; step < 3; ++step) {
                        ++corner[order[step]];
                        tet[step + 1] = index(corner[0], corner[1], corner[2]);
                    }
                    mesh.T.row(t) << tet[0], tet[1], tet[2], tet[3];
                    if (tet_signed_volume6(mesh, t) < 0.0)
                        std::swap(mesh.T(t, 2), mesh.T(t, 3));
                    ++t;
                }
    return mesh;
}

TetMesh beam_mesh(double length, double width, double height, int cells_along)
{
    require_positive(length, "beam length");
    require_positive(width, "beam width");
    require_positive(height, "beam height");
    if (cells_along < 1)
        throw Error(str("beam_mesh: cells along the beam must be ≥ 1, got ", cells_along));
    const double cell = length / cells_along;
    const int ny = std::max(1, static_cast<int>(std::lround(width / cell)));
    const int nz = std::max(1, static_cast<int>(std::lround(height / cell)));
    return box_mesh(cells_along, ny, nz, Eigen::Vector3d(length, width, height));
}

void validate(const TriMesh& mesh, std::string_view source)
{
    validate(mesh, MeshOrigin{std::string(source), {}, {}});
}

void validate(const TriMesh& mesh, const MeshOrigin& origin)
{
    if (mesh.V.rows() == 0 || mesh.F.rows() == 0)
        throw Error(str(origin.source, ": the mesh is empty (", mesh.V.rows(), " vertices, ", mesh.F.rows(),
                        " triangles)"));
    check_finite_vertices(mesh.V, origin);
    check_indices(mesh.F, mesh.V.rows(), origin, "triangle");
    for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
        const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                              c = mesh.V.row(mesh.F(f, 2));
        const double twice_area = (b - a).cross(c - a).norm();
        const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
        if (!(twice_area > 2e-14 * longest * longest))
            throw Error(str(element_place(origin, f), ": triangle ", f, " (vertices ", mesh.F(f, 0), ", ", mesh.F(f, 1),
                            ", ", mesh.F(f, 2), ") has zero area; triangles must not be degenerate"));
    }
}

double tet_signed_volume6(const TetMesh& mesh, int t)
{
    const Eigen::Vector3d a = mesh.V.row(mesh.T(t, 0)), b = mesh.V.row(mesh.T(t, 1)),
                          c = mesh.V.row(mesh.T(t, 2)), d = mesh.V.row(mesh.T(t, 3));
    return (b - a).dot((c - a).cross(d - a));
}

int validate(TetMesh& mesh, std::string_view source, Inverted inverted)
{
    return validate(mesh, MeshOrigin{std::string(source), {}, {}}, inverted);
}

int validate(TetMesh& mesh, const MeshOrigin& origin, Inverted inverted)
{
    if (mesh.V.rows() == 0 || mesh.T.rows() == 0)
        throw Error(str(origin.source, ": the mesh is empty (", mesh.V.rows(), " vertices, ", mesh.T.rows(),
                        " tetrahedra)"));
    check_finite_vertices(mesh.V, origin);
    check_indices(mesh.T, mesh.V.rows(), origin, "tetrahedron");
    int reoriented = 0;
    for (Eigen::Index t = 0; t < mesh.T.rows(); ++t) {
        double longest = 0.0;
        for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j)
                longest = std::max(longest, (mesh.V.row(mesh.T(t, i)) - mesh.V.row(mesh.T(t, j))).norm());
        const double volume6 = tet_signed_volume6(mesh, static_cast<int>(t));
        if (!(std::abs(volume6) > 1e-12 * longest * longest * longest))
            throw Error(str(element_place(origin, t), ": tetrahedron ", t, " (vertices ", mesh.T(t, 0),
                            ", ", mesh.T(t, 1), ", ", mesh.T(t, 2), ", ", mesh.T(t, 3),
                            ") has zero volume; tetrahedra must not be flat"));
        if (volume6 < 0.0) {
            if (inverted == Inverted::reject)
                throw Error(str(element_place(origin, t), ": tetrahedron ", t, " (vertices ",
                                mesh.T(t, 0), ", ", mesh.T(t, 1), ", ", mesh.T(t, 2), ", ", mesh.T(t, 3),
                                ") is inverted (negative volume ", volume6 / 6.0,
                                "); list its vertices so that (b−a)·((c−a)×(d−a)) > 0 (the mesh readers reorient "
                                "what they read; in code, validate with Inverted::reorient)"));
            std::swap(mesh.T(t, 2), mesh.T(t, 3));
            ++reoriented;
        }
    }
    return reoriented;
}

double total_volume(const TetMesh& mesh)
{
    double volume = 0.0;
    for (Eigen::Index t = 0; t < mesh.T.rows(); ++t)
        volume += std::abs(tet_signed_volume6(mesh, static_cast<int>(t))) / 6.0;
    return volume;
}

}  // namespace fem
