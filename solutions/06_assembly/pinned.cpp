// Chapter 06: pinned vertices through a selection matrix P, the reduced system PᵀAP, and a solve
// that refuses a singular (free-floating) matrix. docs/06_assembly.md#pinned-vertices
#include "06_assembly/assembly.hpp"

#include "common/error.hpp"

#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>

namespace fem::assembly {

std::vector<int> vertices_on_plane(const TetMesh& mesh, int axis, double value, double tolerance)
{
    if (axis < 0 || axis > 2)
        throw Error(str("vertices_on_plane: axis ", axis, " must be 0 (x), 1 (y) or 2 (z)"));
    require_finite(value, "vertices_on_plane: plane value");
    if (!(tolerance >= 0.0) || !std::isfinite(tolerance))
        throw Error(str("vertices_on_plane: tolerance ", tolerance, " must be a finite number ≥ 0"));
    std::vector<int> found;
    for (int v = 0; v < static_cast<int>(mesh.V.rows()); ++v)
        if (std::abs(mesh.V(v, axis) - value) <= tolerance)
            found.push_back(v);
    return found;
}

SparseMatrix free_selection_matrix(int vertex_count, const std::vector<int>& pinned_vertices)
{
    if (vertex_count < 1)
        throw Error(str("free_selection_matrix: vertex_count ", vertex_count, " must be ≥ 1"));
    std::vector<int> pinned_at(vertex_count, -1);  // where vertex v appears in the list, or −1
    for (int k = 0; k < static_cast<int>(pinned_vertices.size()); ++k) {
        const int v = pinned_vertices[k];
        if (v < 0 || v >= vertex_count)
            throw Error(str("free_selection_matrix: pinned vertex ", v, " (entry ", k,
                            ") is outside [0, ", vertex_count, ")"));
        if (pinned_at[v] >= 0)
            throw Error(str("free_selection_matrix: vertex ", v, " is pinned twice (entries ",
                            pinned_at[v], " and ", k, ")"));
        pinned_at[v] = k;
    }
    std::vector<Eigen::Triplet<double>> ones;
    int free_count = 0;
    // BEGIN EXERCISE 06.8 free_selection_matrix #pinned-vertices
    // HINT: walk the vertices in order; each free vertex v gets the next three columns k, k+1, k+2,
    // HINT: with a 1 in rows 3v, 3v+1, 3v+2.
    for (int v = 0; v < vertex_count; ++v) {
        if (pinned_at[v] >= 0)
            continue;
        for (int c = 0; c < 3; ++c)
            ones.emplace_back(3 * v + c, 3 * free_count + c, 1.0);
        ++free_count;
    }
    // END EXERCISE
    SparseMatrix P(3 * static_cast<Eigen::Index>(vertex_count), 3 * static_cast<Eigen::Index>(free_count));
    P.setFromTriplets(ones.begin(), ones.end());
    return P;
}

SparseMatrix reduce(const SparseMatrix& A, const SparseMatrix& P)
{
    if (A.rows() != P.rows() || A.cols() != P.rows())
        throw Error(str("reduce: A is ", A.rows(), "×", A.cols(), " but P has ", P.rows(),
                        " rows; A must be ", P.rows(), "×", P.rows()));
    return SparseMatrix(P.transpose() * A * P);
}

Eigen::VectorXd expand(const SparseMatrix& P, const Eigen::VectorXd& u_free)
{
    if (u_free.size() != P.cols())
        throw Error(str("expand: u has ", u_free.size(), " entries; P has ", P.cols(),
                        " columns (3 per free vertex)"));
    return P * u_free;
}

Eigen::VectorXd solve_spd(const SparseMatrix& A, const Eigen::VectorXd& b)
{
    if (A.rows() != A.cols() || b.size() != A.rows() || A.rows() == 0)
        throw Error(str("solve_spd: A is ", A.rows(), "×", A.cols(), " and b has ", b.size(),
                        " entries; A must be square, non-empty and match b"));
    // SimplicialLDLT reads one triangle: a non-symmetric or non-finite A would be answered wrongly.
    double largest_entry = 0.0, asymmetry = 0.0;
    for (Eigen::Index col = 0; col < A.outerSize(); ++col)
        for (SparseMatrix::InnerIterator it(A, col); it; ++it) {
            if (!std::isfinite(it.value()))
                throw Error(str("solve_spd: A(", it.row(), ", ", it.col(), ") is ", it.value(),
                                "; every entry must be finite"));
            largest_entry = std::max(largest_entry, std::abs(it.value()));
        }
    for (Eigen::Index i = 0; i < b.size(); ++i)
        if (!std::isfinite(b[i]))
            throw Error(str("solve_spd: b(", i, ") is ", b[i], "; every entry must be finite"));
    const SparseMatrix difference = A - SparseMatrix(A.transpose());
    for (Eigen::Index col = 0; col < difference.outerSize(); ++col)
        for (SparseMatrix::InnerIterator it(difference, col); it; ++it)
            asymmetry = std::max(asymmetry, std::abs(it.value()));
    if (asymmetry > 1e-12 * largest_entry)
        throw Error(str("solve_spd: A is not symmetric: max |A_ij - A_ji| = ", asymmetry, " against max |A_ij| = ",
                        largest_entry, " (allowed: 1e-12 of it)"));
    Eigen::SimplicialLDLT<SparseMatrix> ldlt(A);
    if (ldlt.info() != Eigen::Success)
        throw Error("solve_spd: the LDLᵀ factorisation failed (a zero pivot): the matrix is singular; "
                    "a free-floating stiffness has 6 rigid modes, pin at least 3 non-collinear vertices");
    const Eigen::VectorXd D = ldlt.vectorD();
    const double largest = D.cwiseAbs().maxCoeff();
    Eigen::Index where = 0;
    const double smallest = D.minCoeff(&where);
    if (!(smallest > 1e-10 * largest))
        throw Error(str("solve_spd: pivot ", where, " of LDLᵀ is ", smallest, " against a largest of ",
                        largest, ": the matrix is ", smallest < 0 ? "indefinite" : "singular",
                        " (not SPD); a free-floating stiffness has 6 rigid modes, pin at least 3 "
                        "non-collinear vertices"));
    Eigen::VectorXd x = ldlt.solve(b);
    if (!x.allFinite())
        throw Error("solve_spd: the solution is not finite");
    return x;
}

}  // namespace fem::assembly
