#pragma once
// Meshes and independent reference answers shared by the tests of chapter 06.

#include "05_strain_stress/strain_stress.hpp"
#include "../05_strain_stress/rubber.hpp"
#include "common/mesh.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SparseCore>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

namespace fem::test {

/// A box mesh with its interior vertices moved at random (by at most 0.15 of a cell, which keeps
/// every Kuhn tet positively oriented) and its vertices numbered in a random order, so that no
/// route can rely on a regular numbering.
inline TetMesh distorted_mesh(int nx, int ny, int nz, unsigned seed = 7)
{
    const Eigen::Vector3d size(1.3, 0.8, 0.6);
    TetMesh box = box_mesh(nx, ny, nz, size);
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> shift(-0.15, 0.15);
    const Eigen::Vector3d cell(size.x() / nx, size.y() / ny, size.z() / nz);
    for (Eigen::Index v = 0; v < box.V.rows(); ++v)
        for (int c = 0; c < 3; ++c)
            if (box.V(v, c) > 1e-9 && box.V(v, c) < size[c] - 1e-9)
                box.V(v, c) += shift(random) * cell[c];
    std::vector<int> order(box.V.rows());
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), random);  // old vertex v becomes order[v]
    TetMesh mesh;
    mesh.V.resize(box.V.rows(), 3);
    for (Eigen::Index v = 0; v < box.V.rows(); ++v)
        mesh.V.row(order[v]) = box.V.row(v);
    mesh.T.resize(box.T.rows(), 4);
    for (Eigen::Index t = 0; t < box.T.rows(); ++t)
        for (int i = 0; i < 4; ++i)
            mesh.T(t, i) = order[box.T(t, i)];
    return mesh;
}

/// The reference K = Σ_t E_tᵀ K_t E_t as a DENSE matrix, by the plain index loop: entry (a, b) of
/// K_t is added at (3 T(t, a/3) + a%3, 3 T(t, b/3) + b%3).
inline Eigen::MatrixXd dense_assembly(const TetMesh& mesh, const std::vector<elastic::Matrix12d>& K_e)
{
    const Eigen::Index dofs = 3 * mesh.V.rows();
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(dofs, dofs);
    for (Eigen::Index t = 0; t < mesh.T.rows(); ++t)
        for (int a = 0; a < 12; ++a)
            for (int b = 0; b < 12; ++b)
                K(3 * mesh.T(t, a / 3) + a % 3, 3 * mesh.T(t, b / 3) + b % 3) += K_e[t](a, b);
    return K;
}

/// Random symmetric 12×12 element matrices (not stiffnesses): a route must place any matrix right.
inline std::vector<elastic::Matrix12d> random_element_matrices(Eigen::Index count, unsigned seed)
{
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<elastic::Matrix12d> K(count);
    for (auto& k : K) {
        for (int a = 0; a < 12; ++a)
            for (int b = 0; b < 12; ++b)
                k(a, b) = u(random);
        k = (k + k.transpose()).eval();
    }
    return K;
}

/// The six rigid modes of a mesh at rest positions V (3n×6): translations along x, y, z and the
/// infinitesimal rotations ω × X about the three axes.
inline Eigen::MatrixXd rigid_modes(const MatrixX3d& V)
{
    Eigen::MatrixXd R = Eigen::MatrixXd::Zero(3 * V.rows(), 6);
    for (Eigen::Index v = 0; v < V.rows(); ++v) {
        const Eigen::Vector3d X = V.row(v).transpose();
        for (int c = 0; c < 3; ++c) {
            R(3 * v + c, c) = 1.0;
            R.block<3, 1>(3 * v, 3 + c) = Eigen::Vector3d::Unit(c).cross(X);
        }
    }
    return R;
}

/// The relative difference ‖A − B‖_F / ‖B‖_F.
inline double relative_difference(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B)
{
    return (A - B).norm() / B.norm();
}

}  // namespace fem::test
