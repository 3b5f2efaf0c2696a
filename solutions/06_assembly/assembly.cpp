// Chapter 06: selection matrices and the three routes to the global stiffness K.
// docs/06_assembly.md
#include "06_assembly/assembly.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>

namespace fem::assembly {

namespace {

// fem::Error unless there is one 12×12 matrix per tet.
void require_one_per_tet(const TetMesh& mesh, const ElementMatrices& element_matrices)
{
    if (static_cast<Eigen::Index>(element_matrices.size()) != mesh.T.rows())
        throw Error(str("assembly: got ", element_matrices.size(), " element matrices for a mesh of ",
                        mesh.T.rows(), " tets; one 12×12 matrix per tet is required"));
}

void require_tet_index(const TetMesh& mesh, int t)
{
    if (t < 0 || t >= mesh.T.rows())
        throw Error(str("tet index ", t, " is outside [0, ", mesh.T.rows(), ")"));
}

// The sorted vertices that share a tet with each vertex (the vertex itself included), as one
// CSR-like adjacency: the neighbours of v are neighbours[start[v] .. start[v+1]).
struct VertexAdjacency {
    std::vector<int> start;
    std::vector<int> neighbours;
};

VertexAdjacency vertex_adjacency(const TetMesh& mesh)
{
    const int n = static_cast<int>(mesh.V.rows());
    const int m = static_cast<int>(mesh.T.rows());
    // The tets around each vertex, by counting sort.
    std::vector<int> tet_start(n + 1, 0);
    for (int t = 0; t < m; ++t)
        for (int i = 0; i < 4; ++i)
            ++tet_start[mesh.T(t, i) + 1];
    for (int v = 0; v < n; ++v)
        tet_start[v + 1] += tet_start[v];
    std::vector<int> tets_of(tet_start[n]);
    std::vector<int> fill(tet_start.begin(), tet_start.end() - 1);
    for (int t = 0; t < m; ++t)
        for (int i = 0; i < 4; ++i)
            tets_of[fill[mesh.T(t, i)]++] = t;

    VertexAdjacency adjacency;
    adjacency.start.assign(n + 1, 0);
    adjacency.neighbours.reserve(static_cast<std::size_t>(n) * 16);
    std::vector<int> around;
    for (int v = 0; v < n; ++v) {
        around.clear();
        for (int k = tet_start[v]; k < tet_start[v + 1]; ++k)
            for (int i = 0; i < 4; ++i)
                around.push_back(mesh.T(tets_of[k], i));
        around.push_back(v);  // an isolated vertex still gets its diagonal block
        std::sort(around.begin(), around.end());
        around.erase(std::unique(around.begin(), around.end()), around.end());
        adjacency.neighbours.insert(adjacency.neighbours.end(), around.begin(), around.end());
        adjacency.start[v + 1] = static_cast<int>(adjacency.neighbours.size());
    }
    return adjacency;
}

}  // namespace

void require_valid_indices(const TetMesh& mesh)
{
    const Eigen::Index n = mesh.V.rows();
    if (n == 0 || mesh.T.rows() == 0)
        throw Error(str("assembly: the mesh has ", n, " vertices and ", mesh.T.rows(),
                        " tets; at least one of each is required"));
    for (Eigen::Index t = 0; t < mesh.T.rows(); ++t)
        for (int i = 0; i < 4; ++i) {
            const int v = mesh.T(t, i);
            if (v < 0 || v >= n)
                throw Error(str("tet ", t, ", corner ", i, ": vertex index ", v, " is outside [0, ", n,
                                ") (the mesh has ", n, " vertices; indices are 0-based)"));
            for (int j = 0; j < i; ++j)
                if (mesh.T(t, j) == v)
                    throw Error(str("tet ", t, " lists vertex ", v, " twice (corners ", j, " and ", i,
                                    "); a tet needs four different vertices"));
        }
}

SparseMatrix selection_matrix(const TetMesh& mesh, int t)
{
    require_valid_indices(mesh);
    require_tet_index(mesh, t);
    const Eigen::Index dofs = 3 * mesh.V.rows();
    std::vector<Eigen::Triplet<double>> ones;
    // BEGIN EXERCISE 06.1 selection_matrix #selection-matrices
    // HINT: row 3i + c of E_t picks coordinate c of corner i, i.e. global dof 3 T(t, i) + c.
    for (int i = 0; i < 4; ++i)
        for (int c = 0; c < 3; ++c)
            ones.emplace_back(3 * i + c, 3 * mesh.T(t, i) + c, 1.0);
    // END EXERCISE
    SparseMatrix E(12, dofs);
    E.setFromTriplets(ones.begin(), ones.end());
    return E;
}

SparseMatrix scatter_matrix(const TetMesh& mesh)
{
    require_valid_indices(mesh);
    const Eigen::Index m = mesh.T.rows();
    // One 1 per column: build the CSC arrays directly (12m columns, 12m nonzeros).
    SparseMatrix S(3 * mesh.V.rows(), 12 * m);
    S.resizeNonZeros(12 * m);
    for (Eigen::Index k = 0; k <= 12 * m; ++k)
        S.outerIndexPtr()[k] = static_cast<int>(k);
    std::fill(S.valuePtr(), S.valuePtr() + 12 * m, 1.0);
    int* row = S.innerIndexPtr();
    // BEGIN EXERCISE 06.2 scatter_matrix #the-composition-route
    // HINT: column 12t + 3i + c of S is column 3i + c of E_tᵀ: its single 1 sits in row 3 T(t, i) + c.
    for (Eigen::Index t = 0; t < m; ++t)
        for (int i = 0; i < 4; ++i)
            for (int c = 0; c < 3; ++c)
                row[12 * t + 3 * i + c] = 3 * mesh.T(t, i) + c;
    // END EXERCISE
    return S;
}

SparseMatrix block_diagonal(const ElementMatrices& element_matrices)
{
    const Eigen::Index m = static_cast<Eigen::Index>(element_matrices.size());
    if (m == 0)
        throw Error("block_diagonal: no element matrices; at least one is required");
    if (144 * m > std::numeric_limits<int>::max())
        throw Error(str("block_diagonal: ", m, " blocks of 144 entries exceed Eigen's int indices"));
    SparseMatrix K(12 * m, 12 * m);
    K.resizeNonZeros(144 * m);
    for (Eigen::Index t = 0; t < m; ++t)
        for (int b = 0; b < 12; ++b) {
            const Eigen::Index column = 12 * t + b;
            K.outerIndexPtr()[column] = static_cast<int>(12 * column);
            for (int a = 0; a < 12; ++a) {
                K.innerIndexPtr()[12 * column + a] = static_cast<int>(12 * t + a);
                K.valuePtr()[12 * column + a] = element_matrices[t](a, b);
            }
        }
    K.outerIndexPtr()[12 * m] = static_cast<int>(144 * m);
    return K;
}

ElementMatrices element_stiffnesses(const TetMesh& mesh, const elastic::Lame& material)
{
    require_valid_indices(mesh);
    elastic::require_stable(material);
    ElementMatrices K(mesh.T.rows());
    for (int t = 0; t < static_cast<int>(mesh.T.rows()); ++t) {
        try {
            K[t] = elastic::element_stiffness(tet::tet_vertices(mesh, mesh.V, t), material);
        } catch (const Error& error) {
            throw Error(str("tet ", t, ": ", error.what()));
        }
    }
    return K;
}

SparseMatrix assemble_by_composition(const TetMesh& mesh, const ElementMatrices& element_matrices)
{
    require_valid_indices(mesh);
    require_one_per_tet(mesh, element_matrices);
    const SparseMatrix S = scatter_matrix(mesh);
    const SparseMatrix K_blocks = block_diagonal(element_matrices);
    const SparseMatrix SK = S * K_blocks;
    return SK * SparseMatrix(S.transpose());
}

std::vector<Eigen::Triplet<double>> element_triplets(const TetMesh& mesh,
                                                     const ElementMatrices& element_matrices)
{
    require_valid_indices(mesh);
    require_one_per_tet(mesh, element_matrices);
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(144 * element_matrices.size());
    // BEGIN EXERCISE 06.3 element_triplets #the-triplet-route
    // HINT: element dof 3i + c is global dof 3 T(t, i) + c; emit every entry of K_t, repeats and all.
    for (Eigen::Index t = 0; t < mesh.T.rows(); ++t) {
        int dof[12];
        for (int i = 0; i < 4; ++i)
            for (int c = 0; c < 3; ++c)
                dof[3 * i + c] = 3 * mesh.T(t, i) + c;
        const Matrix12d& K_t = element_matrices[t];
        for (int b = 0; b < 12; ++b)
            for (int a = 0; a < 12; ++a)
                triplets.emplace_back(dof[a], dof[b], K_t(a, b));
    }
    // END EXERCISE
    return triplets;
}

SparseMatrix assemble_by_triplets(const TetMesh& mesh, const ElementMatrices& element_matrices)
{
    const std::vector<Eigen::Triplet<double>> triplets = element_triplets(mesh, element_matrices);
    SparseMatrix K(3 * mesh.V.rows(), 3 * mesh.V.rows());
    K.setFromTriplets(triplets.begin(), triplets.end());
    return K;
}

AssemblyPattern::AssemblyPattern(const TetMesh& mesh)
{
    require_valid_indices(mesh);
    vertex_count_ = mesh.V.rows();
    element_count_ = mesh.T.rows();
    const int n = static_cast<int>(vertex_count_);
    const VertexAdjacency adjacency = vertex_adjacency(mesh);
    const std::int64_t nonzeros = 9 * static_cast<std::int64_t>(adjacency.neighbours.size());
    if (nonzeros > std::numeric_limits<int>::max())
        throw Error(str("AssemblyPattern: ", nonzeros, " nonzeros exceed Eigen's int indices"));

    // The CSR arrays: vertex v's rows 3v, 3v+1, 3v+2 each hold the columns 3w, 3w+1, 3w+2 of
    // every neighbour w, in ascending order.
    pattern_.resize(3 * vertex_count_, 3 * vertex_count_);
    pattern_.resizeNonZeros(static_cast<Eigen::Index>(nonzeros));
    row_lengths_.resize(n);
    std::vector<int> vertex_start(n);  // offset of row 3v in the value array
    int* row_start = pattern_.outerIndexPtr();
    int* columns = pattern_.innerIndexPtr();
    int offset = 0;
    for (int v = 0; v < n; ++v) {
        const int first = adjacency.start[v];
        const int count = adjacency.start[v + 1] - first;
        row_lengths_[v] = 3 * count;
        vertex_start[v] = offset;
        for (int c = 0; c < 3; ++c) {
            row_start[3 * v + c] = offset;
            for (int k = 0; k < count; ++k)
                for (int d = 0; d < 3; ++d)
                    columns[offset++] = 3 * adjacency.neighbours[first + k] + d;
        }
    }
    row_start[3 * n] = offset;
    std::fill(pattern_.valuePtr(), pattern_.valuePtr() + offset, 0.0);

    // Per tet: where block (i, j) starts (row 3 T(t,i), column 3 T(t,j)), then the row lengths.
    records_.resize(20 * static_cast<std::size_t>(element_count_));
    for (Eigen::Index t = 0; t < element_count_; ++t) {
        int* record = &records_[20 * t];
        for (int i = 0; i < 4; ++i) {
            const int v = mesh.T(t, i);
            const int* first = &adjacency.neighbours[adjacency.start[v]];
            const int* last = &adjacency.neighbours[adjacency.start[v + 1]];
            // BEGIN EXERCISE 06.4 AssemblyPattern #the-pattern-route
            // HINT: find w = T(t, j) among v's sorted neighbours (std::lower_bound); block (i, j)
            // HINT: starts 3 × (its position) entries after the start of row 3v.
            for (int j = 0; j < 4; ++j) {
                const int* found = std::lower_bound(first, last, mesh.T(t, j));
                record[4 * i + j] = vertex_start[v] + 3 * static_cast<int>(found - first);
            }
            // END EXERCISE
            record[16 + i] = row_lengths_[v];
        }
    }
}

void AssemblyPattern::assemble(const ElementMatrices& element_matrices, CsrMatrix& K) const
{
    if (static_cast<Eigen::Index>(element_matrices.size()) != element_count_)
        throw Error(str("AssemblyPattern::assemble: got ", element_matrices.size(),
                        " element matrices for a pattern of ", element_count_, " tets"));
    if (K.rows() != dof_count() || K.cols() != dof_count() || !K.isCompressed() ||
        K.nonZeros() != nonzero_count())
        throw Error(str("AssemblyPattern::assemble: K is ", K.rows(), "×", K.cols(), " with ",
                        K.nonZeros(), " entries; it must be a copy of zero_matrix() (", dof_count(),
                        "×", dof_count(), ", ", nonzero_count(), " entries)"));
    double* values = K.valuePtr();
    std::fill(values, values + nonzero_count(), 0.0);
    for (Eigen::Index t = 0; t < element_count_; ++t)
        add_element(t, element_matrices[static_cast<std::size_t>(t)], values);
}

void AssemblyPattern::add_element(Eigen::Index t, const Matrix12d& K_t, double* values) const
{
    if (t < 0 || t >= element_count_)
        throw Error(str("AssemblyPattern::add_element: tet ", t, " is outside [0, ", element_count_, ")"));
    const int* record = &records_[static_cast<std::size_t>(20 * t)];
    // BEGIN EXERCISE 06.5 assemble #the-pattern-route
    // HINT: record[4 i + j] is block (i, j)'s offset, record[16 + i] the row length of vertex i:
    // HINT: row c of the block starts at offset + c · row length; add K_t(3i + c, 3j + d) at + d.
    for (int i = 0; i < 4; ++i) {
        const int stride = record[16 + i];
        for (int j = 0; j < 4; ++j) {
            double* block = values + record[4 * i + j];
            for (int c = 0; c < 3; ++c)
                for (int d = 0; d < 3; ++d)
                    block[c * stride + d] += K_t(3 * i + c, 3 * j + d);
        }
    }
    // END EXERCISE
}

CsrMatrix AssemblyPattern::assemble(const ElementMatrices& element_matrices) const
{
    CsrMatrix K = pattern_;
    assemble(element_matrices, K);
    return K;
}

int AssemblyPattern::block_offset(int t, int i, int j) const
{
    if (t < 0 || t >= element_count_)
        throw Error(str("AssemblyPattern::block_offset: tet index ", t, " is outside [0, ",
                        element_count_, ")"));
    if (i < 0 || i > 3 || j < 0 || j > 3)
        throw Error(str("AssemblyPattern::block_offset: corners (", i, ", ", j,
                        ") must both lie in [0, 3]"));
    return records_[20 * static_cast<std::size_t>(t) + 4 * i + j];
}

int AssemblyPattern::row_length(int v) const
{
    if (v < 0 || v >= vertex_count_)
        throw Error(str("AssemblyPattern::row_length: vertex index ", v, " is outside [0, ",
                        vertex_count_, ")"));
    return row_lengths_[v];
}

std::size_t AssemblyPattern::memory_bytes() const
{
    const auto nonzeros = static_cast<std::size_t>(nonzero_count());
    return nonzeros * (sizeof(double) + sizeof(int)) +
           static_cast<std::size_t>(dof_count() + 1) * sizeof(int) +
           (records_.size() + row_lengths_.size()) * sizeof(int);
}

SparseMatrix csc_of_symmetric(const CsrMatrix& A)
{
    if (!A.isCompressed())
        throw Error("csc_of_symmetric: the CSR matrix must be compressed (call makeCompressed())");
    return Eigen::Map<const SparseMatrix>(A.cols(), A.rows(), A.nonZeros(), A.outerIndexPtr(),
                                          A.innerIndexPtr(), A.valuePtr());
}

SparseMatrix stiffness_matrix(const TetMesh& mesh, const elastic::Lame& material)
{
    const ElementMatrices K_e = element_stiffnesses(mesh, material);
    return csc_of_symmetric(AssemblyPattern(mesh).assemble(K_e));
}

}  // namespace fem::assembly
