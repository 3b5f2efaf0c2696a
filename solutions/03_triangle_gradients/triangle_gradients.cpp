// Chapter 03: barycentric coordinates, hat-function gradients, the gradient operator G and the
// lecture's block Jacobian. docs/03_triangle_gradients.md
#include "03_triangle_gradients/triangle_gradients.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"

#include <Eigen/Geometry>

#include <vector>

namespace fem::tri {
namespace {

/// fem::Error unless triangle abc has a positive area (relative to its longest edge, as validate).
void check_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                    const char* function)
{
    TriMesh single;
    single.V.resize(3, 3);
    single.V << a.transpose(), b.transpose(), c.transpose();
    single.F.resize(1, 3);
    single.F << 0, 1, 2;
    validate(single, function);
}

/// hat_gradients without the check (gradient_operator validates the whole mesh once).
Eigen::Matrix3d local_gradients(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c)
{
    // BEGIN EXERCISE 03.2 hat_gradients #hat-function-gradients
    // HINT: n = (b − a) × (c − a) has length 2A; n̂ × e turns the edge e by +90° in the plane.
    // HINT: Column i is ∇φ_i = n̂ × e_i / (2A) with e_a = c − b, e_b = a − c, e_c = b − a.
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double twice_area = n.norm();
    const Eigen::Vector3d unit_normal = n / twice_area;
    Eigen::Matrix3d G;
    G.col(0) = unit_normal.cross(c - b) / twice_area;
    G.col(1) = unit_normal.cross(a - c) / twice_area;
    G.col(2) = unit_normal.cross(b - a) / twice_area;
    return G;
    // END EXERCISE
}

}  // namespace

Eigen::Vector3d barycentric_coordinates(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                        const Eigen::Vector3d& b, const Eigen::Vector3d& c)
{
    check_triangle(a, b, c, "barycentric_coordinates");
    // BEGIN EXERCISE 03.1 barycentric_coordinates #barycentric-coordinates
    // HINT: λ_a is the signed area of the triangle (p, b, c) over the area of (a, b, c); measure
    // HINT: signed areas along the normal n = (b − a) × (c − a).
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double n2 = n.squaredNorm();
    const double la = (c - b).cross(p - b).dot(n) / n2;
    const double lb = (a - c).cross(p - c).dot(n) / n2;
    return Eigen::Vector3d(la, lb, 1.0 - la - lb);
    // END EXERCISE
}

Eigen::Matrix3d hat_gradients(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c)
{
    check_triangle(a, b, c, "hat_gradients");
    return local_gradients(a, b, c);
}

Eigen::VectorXd triangle_areas(const MatrixX3d& V, const MatrixX3i& F)
{
    validate(TriMesh{V, F}, "triangle_areas");
    Eigen::VectorXd areas(F.rows());
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
        const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
        areas[f] = 0.5 * (b - a).cross(c - a).norm();
    }
    return areas;
}

SparseMatrix gradient_operator(const MatrixX3d& V, const MatrixX3i& F)
{
    validate(TriMesh{V, F}, "gradient_operator");
    // BEGIN EXERCISE 03.3 gradient_operator #the-gradient-operator
    // HINT: For triangle f, G_f = local_gradients(...) (hat_gradients without its check) is 3×3:
    // HINT: entry (d, k) goes to row 3f + d and to the column of the triangle's k-th vertex.
    // HINT: Collect Eigen::Triplet<double>s, then setFromTriplets.
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(9 * static_cast<std::size_t>(F.rows()));
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
        const Eigen::Matrix3d G_f = local_gradients(V.row(F(f, 0)), V.row(F(f, 1)), V.row(F(f, 2)));
        for (int d = 0; d < 3; ++d)
            for (int k = 0; k < 3; ++k)
                triplets.emplace_back(static_cast<int>(3 * f + d), F(f, k), G_f(d, k));
    }
    SparseMatrix G(3 * F.rows(), V.rows());
    G.setFromTriplets(triplets.begin(), triplets.end());
    return G;
    // END EXERCISE
}

MatrixX3d face_gradients(const MatrixX3d& V, const MatrixX3i& F, const Eigen::VectorXd& u)
{
    if (u.size() != V.rows())
        throw Error(str("face_gradients: u has ", u.size(), " values, expected one per vertex: ", V.rows()));
    const Eigen::VectorXd gradients = gradient_operator(V, F) * u;
    MatrixX3d result(F.rows(), 3);
    for (Eigen::Index f = 0; f < F.rows(); ++f)
        result.row(f) = gradients.segment<3>(3 * f).transpose();
    return result;
}

Matrix9d block_jacobian(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c)
{
    check_triangle(a, b, c, "block_jacobian");
    // BEGIN EXERCISE 03.4 block_jacobian #the-block-jacobian
    // HINT: Three copies of the local gradient matrix G_abc on the diagonal: one per coordinate
    // HINT: function u_x, u_y, u_z.
    const Eigen::Matrix3d G = hat_gradients(a, b, c);
    Matrix9d J = Matrix9d::Zero();
    for (int block = 0; block < 3; ++block)
        J.block<3, 3>(3 * block, 3 * block) = G;
    return J;
    // END EXERCISE
}

SparseMatrix coordinate_major_permutation(int n)
{
    if (n < 1)
        throw Error(str("coordinate_major_permutation: n must be ≥ 1 vertices, got ", n));
    // BEGIN EXERCISE 03.5 coordinate_major_permutation #the-block-jacobian
    // HINT: One 1 per row: row c·n + v picks entry 3v + c of the vertex-major vector.
    std::vector<Eigen::Triplet<double>> triplets;
    for (int v = 0; v < n; ++v)
        for (int c = 0; c < 3; ++c)
            triplets.emplace_back(c * n + v, 3 * v + c, 1.0);
    SparseMatrix P(3 * n, 3 * n);
    P.setFromTriplets(triplets.begin(), triplets.end());
    return P;
    // END EXERCISE
}

}  // namespace fem::tri
