// Chapter 13: the outside rule, the skinning matrix, the skin and its normals.
// docs/13_skinning.md
#include "13_skinning/skinning.hpp"

#include "common/error.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>

namespace fem::skin {

// --- Points outside ------------------------------------------------------------------------------

Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c)
{
    // BEGIN EXERCISE 13.5 closest_point_on_triangle #points-outside
    // HINT: The point of triangle abc nearest to p (docs/13_skinning.md#points-outside): it lies in one of seven
    // HINT: Voronoi regions (three corners, three edges, the face). Ericson's Real-Time Collision Detection, §5.1.5
    // HINT: (the docs' references), tells the region from dot products with the edge vectors, without a square
    // HINT: root. The tests place a point in every region.
    const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0.0 && d2 <= 0.0)
        return a;
    const Eigen::Vector3d bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0.0 && d4 <= d3)
        return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
        return a + (d1 / (d1 - d3)) * ab;
    const Eigen::Vector3d cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0.0 && d5 <= d6)
        return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
        return a + (d2 / (d2 - d6)) * ac;
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
        return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
    const double denominator = 1.0 / (va + vb + vc);
    return a + ab * (vb * denominator) + ac * (vc * denominator);
    // END EXERCISE
}

Boundary boundary_faces(const TetMesh& mesh)
{
    // The face opposite corner i, ordered so that its normal points away from corner i for a
    // positively oriented tet.
    static constexpr int opposite[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    std::map<std::array<int, 3>, int> count;
    for (Eigen::Index t = 0; t < mesh.T.rows(); ++t)
        for (const auto& face : opposite) {
            std::array<int, 3> key{mesh.T(t, face[0]), mesh.T(t, face[1]), mesh.T(t, face[2])};
            std::sort(key.begin(), key.end());
            ++count[key];
        }
    Boundary boundary;
    std::vector<std::array<int, 3>> faces;
    for (Eigen::Index t = 0; t < mesh.T.rows(); ++t)
        for (const auto& face : opposite) {
            std::array<int, 3> f{mesh.T(t, face[0]), mesh.T(t, face[1]), mesh.T(t, face[2])}, key = f;
            std::sort(key.begin(), key.end());
            if (count[key] == 1) {
                faces.push_back(f);
                boundary.tet.push_back(static_cast<int>(t));
            }
        }
    boundary.faces.resize(static_cast<Eigen::Index>(faces.size()), 3);
    for (std::size_t k = 0; k < faces.size(); ++k)
        for (int i = 0; i < 3; ++i)
            boundary.faces(static_cast<Eigen::Index>(k), i) = faces[k][i];
    return boundary;
}

Nearest nearest_boundary_tet(const TetMesh& mesh, const Boundary& boundary, const Eigen::Vector3d& p)
{
    Nearest nearest{-1, std::numeric_limits<double>::infinity()};
    for (Eigen::Index f = 0; f < boundary.faces.rows(); ++f) {
        const Eigen::Vector3d a = mesh.V.row(boundary.faces(f, 0)).transpose(), b = mesh.V.row(boundary.faces(f, 1)).transpose(),
                              c = mesh.V.row(boundary.faces(f, 2)).transpose();
        // A face whose bounding box is no nearer than the best so far cannot be nearer itself.
        const Eigen::Vector3d outside_box = (a.cwiseMin(b).cwiseMin(c) - p).cwiseMax(p - a.cwiseMax(b).cwiseMax(c)).cwiseMax(0.0);
        if (outside_box.norm() >= nearest.distance)
            continue;
        const double distance = (p - closest_point_on_triangle(p, a, b, c)).norm();
        if (distance < nearest.distance)
            nearest = Nearest{boundary.tet[f], distance};
    }
    return nearest;
}

// --- The skin ----------------------------------------------------------------------------------

double Skin::largest_outside_distance() const
{
    double largest = 0.0;
    for (const OutsidePoint& o : outside)
        largest = std::max(largest, o.distance);
    return largest;
}

sparse::CsrMatrix skinning_matrix(const TetMesh& coarse, const std::vector<int>& tet,
                                  const Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>& phi)
{
    if (static_cast<Eigen::Index>(tet.size()) != phi.rows())
        throw Error(str("skinning_matrix: ", tet.size(), " tets for ", phi.rows(), " rows of weights; give one of each per surface vertex"));
    for (std::size_t s = 0; s < tet.size(); ++s)
        if (tet[s] < 0 || tet[s] >= coarse.T.rows())
            throw Error(str("skinning_matrix: surface vertex ", s, " refers to tet ", tet[s], "; the coarse mesh has ",
                            coarse.T.rows(), " (numbered from 0)"));
    // BEGIN EXERCISE 13.4 skinning_matrix #the-skinning-matrix
    // HINT: W of docs/13_skinning.md#the-skinning-matrix, #V_skin × #V_sim (not three times either: the notes'
    // HINT: slip): row s holds phi.row(s) in the columns of the corners of tet tet[s] (coarse.T). Build it from
    // HINT: chapter 07's triplets (sparse::CooMatrix: rows, cols, add) and sparse::coo_to_csr, which sorts each
    // HINT: row's columns. A zero weight stays a stored entry: four a row.
    sparse::CooMatrix W;
    W.rows = static_cast<int>(tet.size());
    W.cols = static_cast<int>(coarse.V.rows());
    for (std::size_t s = 0; s < tet.size(); ++s)
        for (int i = 0; i < 4; ++i)
            W.add(static_cast<int>(s), coarse.T(tet[s], i), phi(static_cast<Eigen::Index>(s), i));
    return sparse::coo_to_csr(W);
    // END EXERCISE
}

Skin build_skin(const TetMesh& coarse, const TriMesh& surface, const SkinOptions& options)
{
    if (surface.V.rows() == 0 || surface.F.rows() == 0)
        throw Error(str("the surface to skin is empty (", surface.V.rows(), " vertices, ", surface.F.rows(),
                        " triangles); give a triangle mesh with at least one triangle"));
    validate(surface, "the surface to skin");
    require_location_tolerance(options.tolerance, "build_skin");
    if (!(options.max_outside_distance >= 0.0 && std::isfinite(options.max_outside_distance)))
        throw Error(str("build_skin: max_outside_distance must be a finite number ≥ 0, got ", options.max_outside_distance));
    const BarycentricFrames frames(coarse);
    const auto locator = make_locator(options.method, frames, options.tolerance);

    Skin skin;
    skin.surface = surface;
    const Eigen::Index n = surface.V.rows();
    skin.tet.resize(n);
    Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> phi(n, 4);
    Boundary boundary;  // built on the first vertex outside
    for (Eigen::Index s = 0; s < n; ++s) {
        const Eigen::Vector3d p = surface.V.row(s).transpose();
        Location found = locator->locate(p);
        if (found.tet < 0) {
            if (boundary.faces.rows() == 0)
                boundary = boundary_faces(frames.mesh());
            const Nearest nearest = nearest_boundary_tet(frames.mesh(), boundary, p);
            const double relative = nearest.distance / frames.longest_edge(nearest.tet);
            if (relative > options.max_outside_distance)
                throw Error(str("surface vertex ", s, " at (", p.x(), ", ", p.y(), ", ", p.z(), ") lies ", nearest.distance,
                                " outside the coarse mesh, ", relative, " times the longest edge of its nearest tet ",
                                nearest.tet, "; the outside rule extrapolates at most ", options.max_outside_distance,
                                " times (SkinOptions::max_outside_distance): enlarge the coarse mesh or raise the limit"));
            found = Location{nearest.tet, frames.weights(nearest.tet, p)};
            skin.outside.push_back(OutsidePoint{static_cast<int>(s), nearest.tet, nearest.distance, relative});
        }
        skin.tet[s] = found.tet;
        phi.row(s) = found.phi.transpose();
    }
    skin.W = skinning_matrix(frames.mesh(), skin.tet, phi);
    return skin;
}

MatrixX3d skinned_positions(const sparse::CsrMatrix& W, const MatrixX3d& Q)
{
    if (Q.rows() != W.cols)
        throw Error(str("skinned_positions: ", Q.rows(), " coarse positions for a skinning matrix of ", W.cols,
                        " columns; give one row per coarse vertex"));
    (void)sparse::view(W);  // checks the array sizes
    MatrixX3d x(W.rows, 3);
    // BEGIN EXERCISE 13.7 skinned_positions #the-skinned-surface
    // HINT: x = W Q (docs/13_skinning.md#the-skinned-surface): row s of x is the weighted sum of the rows of Q
    // HINT: that row s of W names. W is CSR (W.IA row offsets, W.JA columns, W.A values); x is sized. Read W once
    // HINT: for all three coordinates, not once per column (why: docs/13_skinning.md#making-it-fast).
    for (int s = 0; s < W.rows; ++s) {
        Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
        for (int k = W.IA[s]; k < W.IA[s + 1]; ++k)
            sum += W.A[k] * Q.row(W.JA[k]);
        x.row(s) = sum;
    }
    // END EXERCISE
    return x;
}

MatrixX3d vertex_normals(const MatrixX3i& F, const MatrixX3d& x)
{
    MatrixX3d normals = MatrixX3d::Zero(x.rows(), 3);
    for (Eigen::Index f = 0; f < F.rows(); ++f)
        for (int i = 0; i < 3; ++i)
            if (F(f, i) < 0 || F(f, i) >= x.rows())
                throw Error(str("vertex_normals: triangle ", f, " refers to vertex ", F(f, i), "; there are ", x.rows()));
    // BEGIN EXERCISE 13.6 vertex_normals #normals
    // HINT: Area-weighted unit vertex normals of the deformed surface x, in `normals`, zeroed above
    // HINT: (docs/13_skinning.md#normals): each triangle adds its normal, scaled by its area and oriented by its
    // HINT: corner order, to its three corners. A vertex in no triangle keeps a zero row (divide by no zero).
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
        const Eigen::Vector3d a = x.row(F(f, 0)), b = x.row(F(f, 1)), c = x.row(F(f, 2));
        const Eigen::RowVector3d n = (b - a).cross(c - a).transpose();
        for (int i = 0; i < 3; ++i)
            normals.row(F(f, i)) += n;
    }
    for (Eigen::Index v = 0; v < normals.rows(); ++v) {
        const double length = normals.row(v).norm();
        if (length > 0.0)
            normals.row(v) /= length;
    }
    // END EXERCISE
    return normals;
}

io::MeshData skin_frame(const Skin& skin, const MatrixX3d& Q)
{
    const MatrixX3d x = skinned_positions(skin.W, Q);
    io::MeshData frame = io::displaced_mesh(skin.surface.V, MatrixXiR(skin.surface.F), x - skin.surface.V);
    frame.point_data.push_back(io::Field{"normal", vertex_normals(skin.surface.F, x)});
    return frame;
}

}  // namespace fem::skin
