// Chapter 04: tetrahedral shape functions, the deformation gradient and the Jacobian matrix.
// docs/04_tet_jacobians.md
#include "04_tet_jacobians/tet_jacobians.hpp"

#include "common/error.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string_view>

namespace fem::tet {
namespace {

void require_finite_vertices(const TetVertices& X, std::string_view where)
{
    for (int i = 0; i < 4; ++i)
        for (int c = 0; c < 3; ++c)
            if (!std::isfinite(X(i, c)))
                throw Error(str(where, ": vertex ", i, " has the non-finite coordinate ", X(i, c),
                                "; coordinates must be finite numbers"));
}

/// fem::Error unless the tet has finite vertices and non-zero volume, by the criterion of
/// fem::validate: |6V| > 1e-12 · (longest edge)³.
void require_solid(const TetVertices& X, std::string_view where)
{
    require_finite_vertices(X, where);
    double longest = 0.0;
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
            longest = std::max(longest, (X.row(i) - X.row(j)).norm());
    const double volume6 = edge_matrix(X).determinant();
    if (!(std::abs(volume6) > 1e-12 * longest * longest * longest))
        throw Error(str(where, ": the tetrahedron is flat (6 × volume = ", volume6, ", longest edge ",
                        longest, "); shape functions need a tet of non-zero volume, "
                        "|6V| > 1e-12 · (longest edge)³"));
}

}  // namespace

TetVertices tet_vertices(const TetMesh& mesh, const MatrixX3d& positions, int t)
{
    if (t < 0 || t >= mesh.T.rows())
        throw Error(str("tet_vertices: tetrahedron ", t, " does not exist; the mesh has ", mesh.T.rows(),
                        " (numbered from 0)"));
    if (positions.rows() != mesh.V.rows())
        throw Error(str("tet_vertices: ", positions.rows(), " positions for a mesh of ", mesh.V.rows(),
                        " vertices; give one row per vertex"));
    TetVertices X;
    for (int i = 0; i < 4; ++i) {
        const int v = mesh.T(t, i);
        if (v < 0 || v >= positions.rows())
            throw Error(str("tet_vertices: tetrahedron ", t, " refers to vertex ", v,
                            "; vertices are numbered 0 to ", positions.rows() - 1));
        X.row(i) = positions.row(v);
    }
    return X;
}

double signed_volume(const TetVertices& X)
{
    // BEGIN EXERCISE 04.1 signed_volume #signed-volume
    // HINT: a triple product of the three edges leaving X₀, divided by 6.
    const Eigen::Vector3d e1 = (X.row(1) - X.row(0)).transpose();
    const Eigen::Vector3d e2 = (X.row(2) - X.row(0)).transpose();
    const Eigen::Vector3d e3 = (X.row(3) - X.row(0)).transpose();
    return e1.dot(e2.cross(e3)) / 6.0;
    // END EXERCISE
}

Eigen::Matrix3d edge_matrix(const TetVertices& X)
{
    Eigen::Matrix3d T;
    for (int i = 0; i < 3; ++i)
        T.col(i) = (X.row(i + 1) - X.row(0)).transpose();
    return T;
}

Eigen::Vector4d shape_functions(const TetVertices& X, const Eigen::Vector3d& p)
{
    require_solid(X, "shape_functions");
    for (int c = 0; c < 3; ++c)
        require_finite(p[c], "shape_functions: the point's coordinates");
    // BEGIN EXERCISE 04.2 shape_functions #shape-functions
    // HINT: solve T (φ₁, φ₂, φ₃)ᵀ = p − X₀ with T = edge_matrix(X); φ₀ makes the sum 1.
    const Eigen::Vector3d tail = edge_matrix(X).partialPivLu().solve(p - X.row(0).transpose());
    Eigen::Vector4d phi;
    phi << 1.0 - tail.sum(), tail;
    return phi;
    // END EXERCISE
}

ShapeGradients shape_gradients(const TetVertices& X)
{
    require_solid(X, "shape_gradients");
    // BEGIN EXERCISE 04.3 shape_gradients #shape-function-gradients
    // HINT: φ₁…φ₃ = T⁻¹ (X − X₀), so their gradients are the rows of T⁻¹; φ₀ = 1 − φ₁ − φ₂ − φ₃.
    const Eigen::Matrix3d T_inverse = edge_matrix(X).inverse();
    ShapeGradients G;
    G.row(0) = -T_inverse.colwise().sum();
    G.bottomRows<3>() = T_inverse;
    return G;
    // END EXERCISE
}

Eigen::Matrix3d deformation_gradient(const TetVertices& X, const TetVertices& x)
{
    require_solid(X, "deformation_gradient (rest tet)");
    require_finite_vertices(x, "deformation_gradient (deformed tet)");
    // BEGIN EXERCISE 04.4 deformation_gradient #deformation-gradient
    // HINT: x(X) = Σ xᵢ φᵢ(X), so ∂x/∂X = Σ xᵢ ∇φᵢᵀ: a 3×4 times a 4×3 product.
    return x.transpose() * shape_gradients(X);
    // END EXERCISE
}

Jacobian jacobian_matrix(const TetVertices& X)
{
    require_solid(X, "jacobian_matrix");
    // BEGIN EXERCISE 04.5 jacobian_matrix #the-jacobian-matrix
    // HINT: F(a,b) = Σᵢ q_e(3i + a) · dφᵢ/dX_b, and F(a,b) is entry 3a + b of the row-major vec(F).
    const ShapeGradients G = shape_gradients(X);
    Jacobian B = Jacobian::Zero();
    for (int i = 0; i < 4; ++i)
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                B(3 * a + b, 3 * i + a) = G(i, b);
    return B;
    // END EXERCISE
}

Jacobian coordinate_major_jacobian(const TetVertices& X)
{
    const Eigen::Matrix<double, 3, 4> G = shape_gradients(X).transpose();
    Jacobian J = Jacobian::Zero();
    for (int a = 0; a < 3; ++a)
        J.block<3, 4>(3 * a, 4 * a) = G;
    return J;
}

Eigen::Matrix<double, 12, 12> coordinate_major_permutation()
{
    Eigen::Matrix<double, 12, 12> P = Eigen::Matrix<double, 12, 12>::Zero();
    for (int i = 0; i < 4; ++i)
        for (int a = 0; a < 3; ++a)
            P(4 * a + i, 3 * i + a) = 1.0;
    return P;
}

PointLocation locate_point(const TetMesh& mesh, const Eigen::Vector3d& p, double tolerance)
{
    if (mesh.T.rows() == 0)
        throw Error("locate_point: the mesh has no tetrahedra");
    for (int c = 0; c < 3; ++c)
        require_finite(p[c], "locate_point: the point's coordinates");
    if (!(tolerance >= 0.0 && std::isfinite(tolerance)))
        throw Error(str("locate_point: the tolerance must be a finite number ≥ 0, got ", tolerance));
    for (int t = 0; t < mesh.T.rows(); ++t)
        require_solid(tet_vertices(mesh, mesh.V, t), str("locate_point: tetrahedron ", t));
    // BEGIN EXERCISE 04.6 locate_point #locating-a-point
    // HINT: p is in tet t when every shape function of t at p is ≥ −tolerance; remember the tet
    // HINT: whose smallest φ is largest, for a point that no tet contains.
    PointLocation best;
    double best_min = -std::numeric_limits<double>::infinity();
    for (int t = 0; t < mesh.T.rows(); ++t) {
        const Eigen::Vector4d phi = shape_functions(tet_vertices(mesh, mesh.V, t), p);
        const double smallest = phi.minCoeff();
        if (smallest >= -tolerance)
            return PointLocation{true, t, phi};
        if (smallest > best_min) {
            best_min = smallest;
            best = PointLocation{false, t, phi};
        }
    }
    return best;
    // END EXERCISE
}

std::vector<Eigen::Matrix3d> deformation_gradients(const TetMesh& mesh, const MatrixX3d& x)
{
    if (x.rows() != mesh.V.rows())
        throw Error(str("deformation_gradients: ", x.rows(), " deformed positions for a mesh of ",
                        mesh.V.rows(), " vertices; give one row per vertex"));
    std::vector<Eigen::Matrix3d> F(mesh.T.rows());
    for (int t = 0; t < mesh.T.rows(); ++t) {
        const TetVertices X = tet_vertices(mesh, mesh.V, t);
        require_solid(X, str("deformation_gradients: rest tetrahedron ", t));
        F[t] = deformation_gradient(X, tet_vertices(mesh, x, t));
    }
    return F;
}

}  // namespace fem::tet
