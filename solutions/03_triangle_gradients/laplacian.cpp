// Chapter 03: the FEM Laplacian GᵀAG, the cotangent formula and the lumped mass.
// docs/03_triangle_gradients.md#the-fem-laplacian
#include "03_triangle_gradients/laplacian.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

namespace fem::tri {

SparseMatrix fem_laplacian(const MatrixX3d& V, const MatrixX3i& F)
{
    const SparseMatrix G = gradient_operator(V, F);  // validates the mesh
    const Eigen::VectorXd areas = triangle_areas(V, F);
    // BEGIN EXERCISE 03.6 fem_laplacian #the-fem-laplacian
    // HINT: A repeats each triangle's area three times (one per gradient row): a vector of 3|F|
    // HINT: weights, used as a diagonal matrix with .asDiagonal().
    Eigen::VectorXd weights(3 * F.rows());
    for (Eigen::Index f = 0; f < F.rows(); ++f)
        weights.segment<3>(3 * f).setConstant(areas[f]);
    const SparseMatrix AG = weights.asDiagonal() * G;
    return SparseMatrix(G.transpose() * AG);
    // END EXERCISE
}

SparseMatrix cotangent_laplacian(const MatrixX3d& V, const MatrixX3i& F)
{
    validate(TriMesh{V, F}, "cotangent_laplacian");
    // BEGIN EXERCISE 03.7 cotangent_laplacian #cotangent-weights
    // HINT: At corner k of a triangle, with edge vectors u and v leaving it, cot θ_k = u·v / |u × v|.
    // HINT: The edge (i, j) opposite corner k gets w = ½ cot θ_k: four triplets (ij, ji: −w; ii, jj: +w).
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(12 * static_cast<std::size_t>(F.rows()));
    for (Eigen::Index f = 0; f < F.rows(); ++f)
        for (int k = 0; k < 3; ++k) {
            const int corner = F(f, k), i = F(f, (k + 1) % 3), j = F(f, (k + 2) % 3);
            const Eigen::Vector3d u = V.row(i) - V.row(corner), v = V.row(j) - V.row(corner);
            const double w = 0.5 * u.dot(v) / u.cross(v).norm();
            triplets.emplace_back(i, j, -w);
            triplets.emplace_back(j, i, -w);
            triplets.emplace_back(i, i, w);
            triplets.emplace_back(j, j, w);
        }
    SparseMatrix L(V.rows(), V.rows());
    L.setFromTriplets(triplets.begin(), triplets.end());
    return L;
    // END EXERCISE
}

Eigen::VectorXd lumped_mass(const MatrixX3d& V, const MatrixX3i& F)
{
    const Eigen::VectorXd areas = triangle_areas(V, F);  // validates the mesh
    // BEGIN EXERCISE 03.8 lumped_mass #lumped-mass
    // HINT: Each triangle gives a third of its area to each of its three corners.
    Eigen::VectorXd mass = Eigen::VectorXd::Zero(V.rows());
    for (Eigen::Index f = 0; f < F.rows(); ++f)
        for (int k = 0; k < 3; ++k)
            mass[F(f, k)] += areas[f] / 3.0;
    return mass;
    // END EXERCISE
}

std::vector<int> boundary_vertices(const MatrixX3i& F, int vertex_count)
{
    std::map<std::pair<int, int>, int> edge_use;
    for (Eigen::Index f = 0; f < F.rows(); ++f)
        for (int k = 0; k < 3; ++k) {
            const int i = F(f, k), j = F(f, (k + 1) % 3);
            if (i < 0 || i >= vertex_count)
                throw Error(str("boundary_vertices: triangle ", f, " refers to vertex ", i,
                                "; vertices are numbered 0 to ", vertex_count - 1));
            if (++edge_use[{std::min(i, j), std::max(i, j)}] > 2)
                throw Error(str("boundary_vertices: edge (", std::min(i, j), ", ", std::max(i, j),
                                ") belongs to more than two triangles (triangle ", f,
                                " is the third); the mesh must be a manifold"));
        }
    std::vector<bool> on_boundary(static_cast<std::size_t>(vertex_count), false);
    for (const auto& [edge, count] : edge_use)
        if (count == 1)
            on_boundary[edge.first] = on_boundary[edge.second] = true;
    std::vector<int> vertices;
    for (int v = 0; v < vertex_count; ++v)
        if (on_boundary[v])
            vertices.push_back(v);
    return vertices;
}

int negative_weight_edges(const SparseMatrix& L)
{
    const Eigen::VectorXd diagonal = L.diagonal();
    int count = 0;
    for (int col = 0; col < L.outerSize(); ++col)
        for (SparseMatrix::InnerIterator it(L, col); it; ++it)
            if (it.row() < col &&
                it.value() > 1e-12 * std::max(std::abs(diagonal[it.row()]), std::abs(diagonal[col])))
                ++count;
    return count;
}

}  // namespace fem::tri
