#pragma once
// Fixtures shared by the tests of chapters 04 and 05: a tetrahedron with no symmetry, random
// matrices, and vec(F) written out entry by entry (independent of the code under test).

#include "04_tet_jacobians/tet_jacobians.hpp"

#include <Eigen/Core>

#include <random>

namespace fem::test {

/// A tet with no symmetry, so no component of a test deformation vanishes by accident.
inline tet::TetVertices skew_tet()
{
    tet::TetVertices X;
    X << 0.1, -0.2, 0.3,
         1.3, 0.1, -0.1,
         0.4, 1.1, 0.2,
         0.2, 0.3, 0.9;
    return X;
}

/// A 3×3 matrix with entries uniform in [−1, 1].
inline Eigen::Matrix3d random_matrix(std::mt19937& random)
{
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Eigen::Matrix3d A;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
            A(a, b) = u(random);
    return A;
}

/// Row-major vec(A) = (A00, A01, A02, A10, …), written out entry by entry.
inline Eigen::Matrix<double, 9, 1> row_major_vec(const Eigen::Matrix3d& A)
{
    Eigen::Matrix<double, 9, 1> v;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
            v[3 * a + b] = A(a, b);
    return v;
}

}  // namespace fem::test
