#pragma once
// Reproducible random test data: right-hand sides, vectors to multiply, well-mixed matrices.

#include <Eigen/Core>

#include <random>

namespace fem {

/// A rows×cols matrix with entries uniform in [−1, 1], drawn column by column from a Mersenne
/// twister (std::mt19937) seeded with `seed`: the same seed gives the same matrix on every
/// platform and in every chapter, so stored results that depend on it reproduce.
inline Eigen::MatrixXd random_matrix(Eigen::Index rows, Eigen::Index cols, unsigned seed)
{
    std::mt19937 generator(seed);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    Eigen::MatrixXd M(rows, cols);
    for (Eigen::Index j = 0; j < cols; ++j)
        for (Eigen::Index i = 0; i < rows; ++i)
            M(i, j) = uniform(generator);
    return M;
}

/// A vector of n entries uniform in [−1, 1]: the single column random_matrix(n, 1, seed).
inline Eigen::VectorXd random_vector(Eigen::Index n, unsigned seed) { return random_matrix(n, 1, seed); }

}  // namespace fem
