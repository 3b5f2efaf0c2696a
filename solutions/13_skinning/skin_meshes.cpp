// Chapter 13: meshes for skinning: the winding number, a tet lattice enclosing a surface, midpoint
// subdivision. docs/13_skinning.md#the-coarse-mesh
#include "13_skinning/skinning.hpp"

#include "common/error.hpp"

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <map>
#include <numbers>

namespace fem::skin {

// --- Meshes for skinning ---------------------------------------------------------------------------

double winding_number(const TriMesh& surface, const Eigen::Vector3d& p)
{
    double total = 0.0;
    for (Eigen::Index f = 0; f < surface.F.rows(); ++f) {
        const Eigen::Vector3d a = surface.V.row(surface.F(f, 0)).transpose() - p,
                              b = surface.V.row(surface.F(f, 1)).transpose() - p,
                              c = surface.V.row(surface.F(f, 2)).transpose() - p;
        const double la = a.norm(), lb = b.norm(), lc = c.norm();
        const double numerator = a.dot(b.cross(c));
        const double denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        total += 2.0 * std::atan2(numerator, denominator);
    }
    return total / (4.0 * std::numbers::pi);
}

TetMesh enclosing_lattice(const TriMesh& surface, int cells)
{
    if (cells < 1)
        throw Error(str("enclosing_lattice: cells must be ≥ 1, got ", cells));
    validate(surface, "the surface to enclose");
    const Eigen::Vector3d low = surface.V.colwise().minCoeff().transpose(), high = surface.V.colwise().maxCoeff().transpose();
    const double side = (high - low).maxCoeff() / cells;
    // Cubes of one side; the lattice centred on the surface's box, one cube wider than needed where
    // the box is not a whole number of cubes.
    Eigen::Vector3i n;
    for (int c = 0; c < 3; ++c)
        n[c] = std::max(1, static_cast<int>(std::ceil((high[c] - low[c]) / side * (1.0 + 1e-9))));
    const Eigen::Vector3d origin = 0.5 * (low + high) - 0.5 * side * n.cast<double>();
    TetMesh lattice = box_mesh(n[0], n[1], n[2], side * n.cast<double>());
    lattice.V.rowwise() += origin.transpose();

    const auto cube_of = [&](const Eigen::Vector3d& p) {
        Eigen::Vector3i cube;
        for (int c = 0; c < 3; ++c)
            cube[c] = std::clamp(static_cast<int>(std::floor((p[c] - origin[c]) / side)), 0, n[c] - 1);
        return cube;
    };
    std::vector<char> keep(static_cast<std::size_t>(n[0] * n[1] * n[2]), 0);
    const auto index = [&](int i, int j, int k) { return i + std::size_t(n[0]) * (j + std::size_t(n[1]) * k); };
    for (Eigen::Index f = 0; f < surface.F.rows(); ++f) {
        Eigen::Vector3d a = surface.V.row(surface.F(f, 0)).transpose(), b = a;
        for (int i = 1; i < 3; ++i) {
            a = a.cwiseMin(surface.V.row(surface.F(f, i)).transpose());
            b = b.cwiseMax(surface.V.row(surface.F(f, i)).transpose());
        }
        const Eigen::Vector3i from = cube_of(a), to = cube_of(b);
        for (int k = from[2]; k <= to[2]; ++k)
            for (int j = from[1]; j <= to[1]; ++j)
                for (int i = from[0]; i <= to[0]; ++i)
                    keep[index(i, j, k)] = 1;
    }
    for (int k = 0; k < n[2]; ++k)
        for (int j = 0; j < n[1]; ++j)
            for (int i = 0; i < n[0]; ++i)
                if (!keep[index(i, j, k)]) {
                    const Eigen::Vector3d centre = origin + side * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
                    keep[index(i, j, k)] = winding_number(surface, centre) > 0.5;
                }
    // box_mesh numbers cube (i, j, k)'s six tets 6c … 6c + 5, c = i + nx (j + ny k).
    std::vector<int> renumber(lattice.V.rows(), -1);
    std::vector<std::array<int, 4>> tets;
    for (std::size_t c = 0; c < keep.size(); ++c)
        if (keep[c])
            for (int t = 6 * static_cast<int>(c); t < 6 * static_cast<int>(c) + 6; ++t)
                tets.push_back({lattice.T(t, 0), lattice.T(t, 1), lattice.T(t, 2), lattice.T(t, 3)});
    TetMesh kept;
    int used = 0;
    for (const auto& t : tets)
        for (int v : t)
            if (renumber[v] < 0)
                renumber[v] = used++;
    kept.V.resize(used, 3);
    for (Eigen::Index v = 0; v < lattice.V.rows(); ++v)
        if (renumber[v] >= 0)
            kept.V.row(renumber[v]) = lattice.V.row(v);
    kept.T.resize(static_cast<Eigen::Index>(tets.size()), 4);
    for (std::size_t t = 0; t < tets.size(); ++t)
        for (int i = 0; i < 4; ++i)
            kept.T(static_cast<Eigen::Index>(t), i) = renumber[tets[t][i]];
    return kept;
}

TriMesh midpoint_subdivision(const TriMesh& surface, int levels)
{
    if (levels < 0)
        throw Error(str("midpoint_subdivision: levels must be ≥ 0, got ", levels));
    TriMesh mesh = surface;
    for (int level = 0; level < levels; ++level) {
        std::map<std::pair<int, int>, int> midpoint;
        std::vector<Eigen::RowVector3d> points;
        for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
            points.push_back(mesh.V.row(v));
        const auto middle = [&](int a, int b) {
            const auto key = std::minmax(a, b);
            const auto [it, added] = midpoint.try_emplace(key, static_cast<int>(points.size()));
            if (added)
                points.push_back(0.5 * (mesh.V.row(a) + mesh.V.row(b)));
            return it->second;
        };
        MatrixX3i F(4 * mesh.F.rows(), 3);
        for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
            const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
            const int ab = middle(a, b), bc = middle(b, c), ca = middle(c, a);
            F.row(4 * f) << a, ab, ca;
            F.row(4 * f + 1) << ab, b, bc;
            F.row(4 * f + 2) << ca, bc, c;
            F.row(4 * f + 3) << ab, bc, ca;
        }
        MatrixX3d V(static_cast<Eigen::Index>(points.size()), 3);
        for (std::size_t v = 0; v < points.size(); ++v)
            V.row(static_cast<Eigen::Index>(v)) = points[v];
        mesh = TriMesh{V, F};
    }
    return mesh;
}

}  // namespace fem::skin
