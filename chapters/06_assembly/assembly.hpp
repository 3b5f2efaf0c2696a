#pragma once
// Chapter 06: assembling the global matrices of a tet mesh. docs/06_assembly.md
//
// A mesh with n vertices and m tets. The global vector q = (x₀, y₀, z₀, x₁, …) is VERTEX-MAJOR
// (3n entries): vertex v owns the dofs 3v, 3v+1, 3v+2. Element t = (a, b, c, d) owns the 12
// element dofs q_e = (x_a, y_a, z_a, x_b, …, z_d), also vertex-major, in the order of its row of T
// (the order of chapter 04's B and chapter 05's K_e).
//
// The selection matrix E_t (12×3n) picks q_e = E_t q out of q. Everything global is a sum over
// elements moved into place by E_t:
//   K = Σ_t E_tᵀ K_e E_t,   M = Σ_t E_tᵀ M_e E_t,   f = Σ_t E_tᵀ f_e.
// The chapter builds K three ways and compares them (docs/06_assembly.md#three-routes-to-k):
//   (a) composition: K = S K' Sᵀ with S = [E_0ᵀ … E_{m−1}ᵀ] (3n×12m) and K' = diag(K_0 … K_{m−1});
//   (b) COO triplets (row, column, value), 144 per element, summed by Eigen's setFromTriplets;
//   (c) scatter into a precomputed CSR pattern: where each element's 3×3 blocks go is found once
//       (16 offsets per tet), then every assembly is a pure values[offset] += K_e(a, b)
//       (AssemblyPattern; reused whenever the K_e change but the mesh does not).
//
// Matrices are Eigen sparse matrices storing both triangles; SparseMatrix is column-major (CSC),
// CsrMatrix row-major (CSR). For the symmetric K and M the two hold the same three arrays.

#include "05_strain_stress/strain_stress.hpp"
#include "common/mesh.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <cstddef>
#include <vector>

namespace fem::assembly {

using SparseMatrix = Eigen::SparseMatrix<double>;                 ///< CSC, Eigen's default
using CsrMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;   ///< CSR
using Matrix12d = elastic::Matrix12d;                             ///< K_e or M_e
using ElementMatrices = std::vector<Matrix12d>;                   ///< one 12×12 matrix per tet

/// The lecture's limit on the Rayleigh coefficients: 0 ≤ α, β ≤ 0.02.
inline constexpr double max_rayleigh_coefficient = 0.02;

// --- Checks ---------------------------------------------------------------------------------

/// fem::Error unless the mesh has at least one vertex and one tet, every vertex index of T lies in
/// [0, #V) and no tet repeats a vertex; the message names the tet, its corner and the index.
/// (Zero-volume tets are reported by the element functions of chapters 04/05.)
void require_valid_indices(const TetMesh& mesh);

// --- Selection matrices and the three routes to K ------------------------------------------

/// E_t (12×3n): E_t(3i + c, 3 T(t, i) + c) = 1 for corner i ∈ {0…3} and coordinate c ∈ {0,1,2},
/// zero elsewhere, so that q_e = E_t q. Its transpose scatters: E_tᵀ f_e adds the element force to
/// the four vertices. fem::Error for t outside [0, #T) or bad indices.
/// docs/06_assembly.md#selection-matrices
SparseMatrix selection_matrix(const TetMesh& mesh, int t);

/// S = [E_0ᵀ E_1ᵀ … E_{m−1}ᵀ] (3n×12m): column 12t + 3i + c holds a single 1 in row 3 T(t, i) + c.
/// S takes the stacked element vectors (f_0; f_1; …) to the global f = Σ E_tᵀ f_t.
/// fem::Error for bad indices. docs/06_assembly.md#the-composition-route
SparseMatrix scatter_matrix(const TetMesh& mesh);

/// K' = diag(K_0, …, K_{m−1}) (12m×12m), the element matrices as diagonal blocks.
/// docs/06_assembly.md#the-composition-route
SparseMatrix block_diagonal(const ElementMatrices& element_matrices);

/// K_e = elastic::element_stiffness of every tet (rest positions mesh.V), in the order of T.
/// fem::Error for bad indices, a zero-volume tet (naming it) or an unstable material.
/// docs/06_assembly.md#element-matrices
ElementMatrices element_stiffnesses(const TetMesh& mesh, const elastic::Lame& material);

/// Route (a): K = S K' Sᵀ, literally by Eigen sparse products (the lecture's "compose easy
/// matrices"). 3n×3n. fem::Error if element_matrices.size() ≠ #T or bad indices.
/// docs/06_assembly.md#the-composition-route
SparseMatrix assemble_by_composition(const TetMesh& mesh, const ElementMatrices& element_matrices);

/// The COO triplets of route (b): for each tet t, corner pair (i, j), coordinates (c, d) the
/// triplet (3 T(t,i) + c, 3 T(t,j) + d, K_t(3i + c, 3j + d)); 144 per tet, in tet order, with
/// repeated (row, column) pairs that a conversion must sum. fem::Error as assemble_by_composition.
/// docs/06_assembly.md#the-triplet-route
std::vector<Eigen::Triplet<double>> element_triplets(const TetMesh& mesh,
                                                     const ElementMatrices& element_matrices);

/// Route (b): K from element_triplets by Eigen's setFromTriplets (sorts, sums duplicates).
/// 3n×3n. fem::Error as assemble_by_composition. docs/06_assembly.md#the-triplet-route
SparseMatrix assemble_by_triplets(const TetMesh& mesh, const ElementMatrices& element_matrices);

/// Route (c): the CSR sparsity pattern of K (3n×3n; dof 3v+c couples to dof 3w+d exactly when
/// vertices v and w share a tet, both triangles stored, columns sorted in each row) and, for every
/// tet, where its K_e entries go in the value array. Built once from the connectivity; assemble()
/// then only scatter-adds, so the pattern is reused whenever the K_e change but the mesh does not
/// (chapter 11 re-assembles every step).
///
/// The three rows of a vertex v hold the same columns: 3 per vertex w that shares a tet with v
/// (v included), so every 3×3 block of K_e lands as 3 runs of 3 consecutive values. The pattern
/// stores one offset per block, 16 per tet:
///   entry (3i + c, 3j + d) of K_t goes to K.valuePtr()[block_offset(t, i, j) + c · row_length(T(t,i)) + d].
/// docs/06_assembly.md#the-pattern-route
class AssemblyPattern {
public:
    /// Builds the pattern and the block offsets. fem::Error for bad indices.
    explicit AssemblyPattern(const TetMesh& mesh);

    Eigen::Index dof_count() const { return 3 * vertex_count_; }   ///< 3n
    Eigen::Index element_count() const { return element_count_; }  ///< m
    Eigen::Index nonzero_count() const { return pattern_.nonZeros(); }

    /// A 3n×3n CSR matrix with the pattern and all values zero, to pass to assemble().
    const CsrMatrix& zero_matrix() const { return pattern_; }

    /// K = Σ_t E_tᵀ K_t E_t into K's existing values: K must have this pattern (a copy of
    /// zero_matrix() or an earlier result); its values are overwritten, nothing is allocated.
    /// fem::Error if element_matrices.size() ≠ #T or K is not 3n×3n with nonzero_count() entries.
    void assemble(const ElementMatrices& element_matrices, CsrMatrix& K) const;

    /// The same into a fresh matrix.
    CsrMatrix assemble(const ElementMatrices& element_matrices) const;

    /// Adds one tet's K_t (12×12) into the value array of a matrix with this pattern: entry
    /// (3i + c, 3j + d) goes to values[block_offset(t, i, j) + c · row_length(T(t, i)) + d]. What
    /// assemble() does per tet, for callers that make each K_t just before adding it (chapters
    /// 11–12 re-assemble every step without storing #T matrices). values must hold
    /// nonzero_count() entries. fem::Error for t outside [0, #T).
    void add_element(Eigen::Index t, const Matrix12d& K_t, double* values) const;

    /// Where entry (3i, 3j) of K_t goes in the value array (see the class comment).
    /// fem::Error for t outside [0, #T) or i, j outside [0, 3].
    int block_offset(int t, int i, int j) const;

    /// The number of stored entries in each of vertex v's three rows: 3 × (the number of vertices
    /// that share a tet with v, v included). fem::Error for v outside [0, n).
    int row_length(int v) const;

    /// Bytes held: the pattern's arrays (values, column indices, row starts) plus the offsets.
    std::size_t memory_bytes() const;

private:
    Eigen::Index vertex_count_ = 0;
    Eigen::Index element_count_ = 0;
    CsrMatrix pattern_;               // 3n×3n, values zero
    std::vector<int> row_lengths_;    // per vertex
    // 20 ints per tet: the 16 block offsets (block (i, j) at 4 i + j), then the row lengths of
    // its 4 vertices, so that assemble() reads one contiguous record per tet.
    std::vector<int> records_;
};

/// A symmetric matrix given in CSR as Eigen's default CSC, by copying the three arrays unchanged:
/// CSR arrays read as CSC describe the transpose, which for a symmetric A is A itself (no sorting,
/// no transposition). For an unsymmetric A the result is Aᵀ. docs/06_assembly.md#the-pattern-route
SparseMatrix csc_of_symmetric(const CsrMatrix& A);

/// The global stiffness K (3n×3n, vertex-major dofs, both triangles stored) of the mesh with rest
/// positions mesh.V: element_stiffnesses, then route (c). The matrix the later chapters use.
/// fem::Error for bad indices, zero-volume tets or an unstable material.
/// docs/06_assembly.md#the-pattern-route
SparseMatrix stiffness_matrix(const TetMesh& mesh, const elastic::Lame& material);

// --- Mass, damping, gravity ------------------------------------------------------------------

/// The lumped vertex masses m_v = Σ_{t ∋ v} ¼ ρ V_t (n entries): each tet gives a quarter of its
/// mass to each corner. This is the barycentric (equal-share) lumping, not the Voronoi one the
/// lecture names. They sum to ρ · total volume. fem::Error unless density is finite and > 0, for
/// bad indices or a zero-volume tet. docs/06_assembly.md#lumped-mass
Eigen::VectorXd vertex_masses(const TetMesh& mesh, double density);

/// The lumped mass matrix M = diag(m_0, m_0, m_0, m_1, …) (3n×3n, sparse diagonal).
/// Errors as vertex_masses. docs/06_assembly.md#lumped-mass
SparseMatrix lumped_mass_matrix(const TetMesh& mesh, double density);

/// The consistent element mass M_e = ρ ∫ Φᵀ Φ dV (12×12): block (i, j) = ρ V/20 · (1 + δ_ij) · I₃,
/// i.e. ρV/10 on the diagonal blocks and ρV/20 off them; total ρV per coordinate.
/// fem::Error for a non-positive density or a zero-volume tet. docs/06_assembly.md#consistent-mass
Matrix12d element_consistent_mass(const tet::TetVertices& X, double density);

/// The consistent mass matrix M = Σ_t E_tᵀ M_t E_t (3n×3n, the pattern of K). Each of its rows
/// sums to the lumped mass of that row's vertex. Errors as vertex_masses.
/// docs/06_assembly.md#consistent-mass
SparseMatrix consistent_mass_matrix(const TetMesh& mesh, double density);

/// Rayleigh damping D = α M + β K (same shapes as M and K). fem::Error unless M and K are square
/// and of equal size and 0 ≤ α, β ≤ max_rayleigh_coefficient (the lecture's range).
/// docs/06_assembly.md#rayleigh-damping
SparseMatrix rayleigh_damping(const SparseMatrix& M, const SparseMatrix& K, double alpha, double beta);

/// The gravity load f = M_lumped (g, g, …, g): f_v = m_v g (3n entries). The consistent mass gives
/// the same vector, since its rows sum to the lumped masses. fem::Error as vertex_masses or for a
/// non-finite g. docs/06_assembly.md#gravity
Eigen::VectorXd gravity_load(const TetMesh& mesh, double density,
                             const Eigen::Vector3d& g = Eigen::Vector3d(0.0, 0.0, -9.81));

// --- Pinned vertices ---------------------------------------------------------------------------

/// The vertices whose coordinate `axis` (0, 1, 2) lies within tolerance of `value`, ascending,
/// e.g. the clamped end x = 0 of a beam. fem::Error for a bad axis or a negative tolerance.
/// docs/06_assembly.md#pinned-vertices
std::vector<int> vertices_on_plane(const TetMesh& mesh, int axis, double value, double tolerance = 1e-9);

/// P (3n × 3n_free): the columns of the 3n×3n identity that belong to the free (not pinned)
/// vertices, in ascending order; q = P u keeps the pinned dofs at zero and u = Pᵀ q drops them.
/// fem::Error for a pinned index outside [0, vertex_count) or listed twice.
/// docs/06_assembly.md#pinned-vertices
SparseMatrix free_selection_matrix(int vertex_count, const std::vector<int>& pinned_vertices);

/// The reduced system matrix Pᵀ A P (3n_free × 3n_free). fem::Error if A is not 3n×3n for P's 3n rows.
/// docs/06_assembly.md#pinned-vertices
SparseMatrix reduce(const SparseMatrix& A, const SparseMatrix& P);

/// The map back: q = P u (3n), zero at the pinned dofs. fem::Error if u has not P.cols() entries.
/// docs/06_assembly.md#pinned-vertices
Eigen::VectorXd expand(const SparseMatrix& P, const Eigen::VectorXd& u_free);

/// Solves A x = b for a symmetric positive definite A by sparse LDLᵀ (Eigen's SimplicialLDLT).
/// fem::Error when A is not SPD: the factorisation fails, or a pivot d_i ≤ 1e-10 · max d (singular,
/// e.g. a free-floating K with its 6 rigid modes: pin vertices), or sizes mismatch; also when A
/// or b holds a non-finite entry, or A is not symmetric (max |A_ij − A_ji| > 1e-12 max |A_ij|; the
/// factorization reads one triangle and would answer a non-symmetric A wrongly).
/// docs/06_assembly.md#pinned-vertices
Eigen::VectorXd solve_spd(const SparseMatrix& A, const Eigen::VectorXd& b);

}  // namespace fem::assembly
