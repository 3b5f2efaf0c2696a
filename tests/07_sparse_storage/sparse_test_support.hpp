#pragma once
// Test matrices of chapter 07, built without the chapter's own code: dense Eigen matrices with a
// random pattern (the reference every product and conversion is compared with), random triplet
// lists with duplicates in random order, and the lecture's 4×6 example.

#include "07_sparse_storage/sparse_formats.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <cmath>
#include <random>
#include <vector>

namespace fem::sparse::test {

/// A rows×cols matrix whose entries are nonzero with probability `density`, values in [−1, 1];
/// rows and columns listed in `empty_rows` / `empty_cols` are all zero.
inline Eigen::MatrixXd random_dense(int rows, int cols, double density, unsigned seed,
                                    const std::vector<int>& empty_rows = {},
                                    const std::vector<int>& empty_cols = {})
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    Eigen::MatrixXd D = Eigen::MatrixXd::Zero(rows, cols);
    for (int i = 0; i < rows; ++i)
        for (int j = 0; j < cols; ++j)
            if (uniform(rng) < density)
                D(i, j) = 2.0 * uniform(rng) - 1.0;
    for (int i : empty_rows)
        D.row(i).setZero();
    for (int j : empty_cols)
        D.col(j).setZero();
    return D;
}

/// The dense matrix as Eigen's column-major sparse matrix (Eigen's own conversion).
inline Eigen::SparseMatrix<double> eigen_sparse(const Eigen::MatrixXd& D)
{
    return D.sparseView();
}

/// Random triplets for a rows×cols matrix: `entries` of them at random positions in a random
/// order, so that many positions repeat; the dense sum of all of them is returned in `sum`.
inline CooMatrix random_triplets(int rows, int cols, int entries, unsigned seed, Eigen::MatrixXd& sum)
{
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> row(0, rows - 1), col(0, cols - 1);
    std::uniform_real_distribution<double> value(-1.0, 1.0);
    CooMatrix M;
    M.rows = rows;
    M.cols = cols;
    sum = Eigen::MatrixXd::Zero(rows, cols);
    for (int k = 0; k < entries; ++k) {
        const int i = row(rng), j = col(rng);
        const double v = value(rng);
        M.add(i, j, v);
        sum(i, j) += v;
    }
    return M;
}

/// The 4×6 matrix of the lecture's CSR slide.
inline Eigen::MatrixXd lecture_matrix()
{
    Eigen::MatrixXd D(4, 6);
    D << 10, 20, 0, 0, 0, 0,
         0, 30, 0, 40, 0, 0,
         0, 0, 50, 60, 70, 0,
         0, 0, 0, 0, 0, 80;
    return D;
}

/// The lecture's CSR arrays, with JA corrected to 8 entries (the slide lists 7).
inline CsrMatrix lecture_csr()
{
    CsrMatrix M;
    M.rows = 4;
    M.cols = 6;
    M.A = {10, 20, 30, 40, 50, 60, 70, 80};
    M.IA = {0, 2, 4, 7, 8};
    M.JA = {0, 1, 1, 3, 2, 3, 4, 5};
    return M;
}

/// The same matrix in CSC, derived by hand column by column from lecture_matrix().
inline CscMatrix lecture_csc()
{
    CscMatrix M;
    M.rows = 4;
    M.cols = 6;
    M.A = {10, 20, 30, 50, 40, 60, 70, 80};
    M.IA = {0, 1, 3, 4, 6, 7, 8};
    M.JA = {0, 0, 1, 2, 1, 2, 2, 3};
    return M;
}

/// |y − reference| ≤ 1e-13 · (|A| |x|)_i + 1e-300 in every entry: the round-off of a sum of
/// products in another order, scaled by the sizes of its terms.
inline bool close_to_product(const Eigen::VectorXd& y, const Eigen::MatrixXd& D, const Eigen::VectorXd& x)
{
    if (y.size() != D.rows())
        return false;
    const Eigen::VectorXd reference = D * x;
    const Eigen::VectorXd scale = D.cwiseAbs() * x.cwiseAbs();
    for (Eigen::Index i = 0; i < y.size(); ++i)
        if (!(std::abs(y[i] - reference[i]) <= 1e-13 * scale[i] + 1e-300))
            return false;
    return true;
}

}  // namespace fem::sparse::test
