#pragma once
// Test matrices of chapter 09, built without the chapter's own code: symmetric positive definite
// matrices with a chosen spectrum (Q Λ Qᵀ with a random orthogonal Q), Kershaw's matrix (SPD, yet
// its incomplete Cholesky factorization breaks down), and a dense reference solve.

#include "common/random.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/QR>
#include <Eigen/SparseCore>

#include <random>
#include <vector>

namespace fem::cg::test {

/// ‖x − reference‖ / ‖reference‖ of two vectors of one length (reference nonzero).
inline double relative_error(const Eigen::VectorXd& x, const Eigen::VectorXd& reference)
{
    return (x - reference).norm() / reference.norm();
}

/// Q diag(eigenvalues) Qᵀ with Q orthogonal (the Q of a random matrix's QR), made exactly
/// symmetric, as a dense matrix.
inline Eigen::MatrixXd spd_with_spectrum(const Eigen::VectorXd& eigenvalues, unsigned seed)
{
    const Eigen::Index n = eigenvalues.size();
    std::mt19937 rng(seed);
    std::normal_distribution<double> normal;
    Eigen::MatrixXd G(n, n);
    for (Eigen::Index i = 0; i < n; ++i)
        for (Eigen::Index j = 0; j < n; ++j)
            G(i, j) = normal(rng);
    const Eigen::MatrixXd Q = Eigen::HouseholderQR<Eigen::MatrixXd>(G).householderQ();
    const Eigen::MatrixXd A = Q * eigenvalues.asDiagonal() * Q.transpose();
    return 0.5 * (A + A.transpose());
}

/// Kershaw's 4×4 matrix (1978): symmetric positive definite, but not an M-matrix (A_03 > 0), and
/// IC(0) on its pattern meets the pivot 3 − 4/3 − 20/3 = −5 in its last row.
inline Eigen::MatrixXd kershaw_matrix()
{
    Eigen::MatrixXd A(4, 4);
    A << 3, -2, 0, 2,
        -2, 3, -2, 0,
         0, -2, 3, -2,
         2, 0, -2, 3;
    return A;
}

/// The 1D Laplacian tridiag(−1, 2, −1) of size n (its Cholesky factor has no fill).
inline Eigen::MatrixXd tridiagonal_laplacian(int n)
{
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < n; ++i) {
        A(i, i) = 2.0;
        if (i + 1 < n)
            A(i, i + 1) = A(i + 1, i) = -1.0;
    }
    return A;
}

/// The solution of A x = b by Eigen's dense Cholesky (the independent reference).
inline Eigen::VectorXd dense_solve(const Eigen::MatrixXd& A, const Eigen::VectorXd& b)
{
    return Eigen::LLT<Eigen::MatrixXd>(A).solve(b);
}

}  // namespace fem::cg::test
