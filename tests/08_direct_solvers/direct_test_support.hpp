#pragma once
// Test matrices and references of chapter 08, built without the chapter's own code: random dense
// matrices, sparse SPD matrices as Eigen sees them, and Eigen's factorizations as the reference.

#include "05_strain_stress/strain_stress.hpp"
#include "07_sparse_storage/sparse_formats.hpp"

#include "common/error.hpp"
#include "common/random.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <numeric>
#include <random>
#include <string>
#include <vector>

namespace fem::direct::test {

/// The rubber of the model problems' meshes: Young's modulus 10⁵ Pa, Poisson ratio 0.45.
inline const elastic::Lame rubber = elastic::lame_parameters(1e5, 0.45);

/// The message of the fem::Error that work() throws, or "" if it throws none. Other exceptions
/// (an unfinished exercise's fem::NotImplemented) propagate and fail the test.
template <typename Work>
std::string fem_error_message(Work&& work)
{
    try {
        work();
    } catch (const fem::Error& error) {
        return error.what();
    }
    return "";
}

/// A well-conditioned symmetric positive definite matrix B Bᵀ / n + I.
inline Eigen::MatrixXd random_spd(int n, unsigned seed)
{
    const Eigen::MatrixXd B = random_matrix(n, n, seed);
    return B * B.transpose() / n + Eigen::MatrixXd::Identity(n, n);
}

/// A random permutation of 0 … n−1 (perm[new] = old).
inline std::vector<int> random_permutation(int n, unsigned seed)
{
    std::vector<int> p(n);
    std::iota(p.begin(), p.end(), 0);
    std::mt19937 rng(seed);
    std::shuffle(p.begin(), p.end(), rng);
    return p;
}

/// P A Pᵀ with (P A Pᵀ)(k, l) = A(perm[k], perm[l]), by Eigen's own permutation.
inline Eigen::SparseMatrix<double> eigen_permuted(const Eigen::SparseMatrix<double>& A, const std::vector<int>& perm)
{
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> P(static_cast<int>(perm.size()));
    for (int k = 0; k < static_cast<int>(perm.size()); ++k)
        P.indices()[perm[k]] = k;  // Eigen's twistedBy takes old → new
    Eigen::SparseMatrix<double> C;
    C = A.selfadjointView<Eigen::Lower>().twistedBy(P);
    return C;
}

/// Eigen's Cholesky factor of A in its own numbering (no ordering), as a sparse matrix: its pattern
/// is the symbolic pattern of L.
inline Eigen::SparseMatrix<double> eigen_factor_natural(const Eigen::SparseMatrix<double>& A)
{
    Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::NaturalOrdering<int>> llt(A);
    Eigen::SparseMatrix<double> L = llt.matrixL();
    return L;
}

/// The sparse matrix as a CSC matrix of chapter 07, both triangles stored.
inline sparse::CscMatrix csc(const Eigen::SparseMatrix<double>& A)
{
    return sparse::csc_from_eigen(A);
}

/// The lower triangle (diagonal included) of a CSC matrix, as CSC.
inline sparse::CscMatrix lower_only(const sparse::CscMatrix& A)
{
    const Eigen::SparseMatrix<double> L = sparse::to_eigen(A).triangularView<Eigen::Lower>();
    return sparse::csc_from_eigen(L);
}

}  // namespace fem::direct::test
