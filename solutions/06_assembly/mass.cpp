// Chapter 06: lumped and consistent mass, Rayleigh damping and the gravity load.
// docs/06_assembly.md#lumped-mass
#include "06_assembly/assembly.hpp"

#include "common/error.hpp"

#include <cmath>

namespace fem::assembly {

namespace {

// |V_t| of the rest tet, with fem::Error (naming the tet) for a flat one: the test of chapter 04,
// |6V| ≤ 1e-12 · (longest edge)³.
double rest_volume(const TetMesh& mesh, int t)
{
    const tet::TetVertices X = tet::tet_vertices(mesh, mesh.V, t);
    double longest = 0.0;
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
            longest = std::max(longest, (X.row(i) - X.row(j)).norm());
    const double volume = std::abs(tet::signed_volume(X));
    if (!(6.0 * volume > 1e-12 * longest * longest * longest))
        throw Error(str("tet ", t, " has zero volume (", volume, " for longest edge ", longest,
                        "); every tet needs |6V| > 1e-12 · (longest edge)³"));
    return volume;
}

void require_density(double density)
{
    require_positive(density, "density ρ [kg/m³]");
}

}  // namespace

Eigen::VectorXd vertex_masses(const TetMesh& mesh, double density)
{
    require_density(density);
    require_valid_indices(mesh);
    Eigen::VectorXd m = Eigen::VectorXd::Zero(mesh.V.rows());
    for (int t = 0; t < static_cast<int>(mesh.T.rows()); ++t) {
        const double volume = rest_volume(mesh, t);
        // BEGIN EXERCISE 06.6 vertex_masses #lumped-mass
        // HINT: the tet's mass ρV is shared equally by its four corners.
        for (int i = 0; i < 4; ++i)
            m[mesh.T(t, i)] += 0.25 * density * volume;
        // END EXERCISE
    }
    return m;
}

SparseMatrix lumped_mass_matrix(const TetMesh& mesh, double density)
{
    const Eigen::VectorXd m = vertex_masses(mesh, density);
    SparseMatrix M(3 * m.size(), 3 * m.size());
    M.reserve(Eigen::VectorXi::Constant(3 * m.size(), 1));
    for (Eigen::Index v = 0; v < m.size(); ++v)
        for (int c = 0; c < 3; ++c)
            M.insert(3 * v + c, 3 * v + c) = m[v];
    M.makeCompressed();
    return M;
}

Matrix12d element_consistent_mass(const tet::TetVertices& X, double density)
{
    require_density(density);
    TetMesh one;
    one.V = X;
    one.T.resize(1, 4);
    one.T << 0, 1, 2, 3;
    const double volume = rest_volume(one, 0);
    Matrix12d M = Matrix12d::Zero();
    // BEGIN EXERCISE 06.7 element_consistent_mass #consistent-mass
    // HINT: ∫ φ_i φ_j dV = V/20 · (1 + δ_ij); each coordinate moves on its own (times I₃).
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            M.block<3, 3>(3 * i, 3 * j) =
                density * volume / 20.0 * (i == j ? 2.0 : 1.0) * Eigen::Matrix3d::Identity();
    // END EXERCISE
    return M;
}

SparseMatrix consistent_mass_matrix(const TetMesh& mesh, double density)
{
    require_density(density);
    require_valid_indices(mesh);
    ElementMatrices M_e(mesh.T.rows());
    for (int t = 0; t < static_cast<int>(mesh.T.rows()); ++t) {
        try {
            M_e[t] = element_consistent_mass(tet::tet_vertices(mesh, mesh.V, t), density);
        } catch (const Error& error) {
            throw Error(str("tet ", t, ": ", error.what()));
        }
    }
    return csc_of_symmetric(AssemblyPattern(mesh).assemble(M_e));
}

SparseMatrix rayleigh_damping(const SparseMatrix& M, const SparseMatrix& K, double alpha, double beta)
{
    if (M.rows() != M.cols() || K.rows() != K.cols() || M.rows() != K.rows())
        throw Error(str("rayleigh_damping: M is ", M.rows(), "×", M.cols(), " and K is ", K.rows(),
                        "×", K.cols(), "; both must be square and of the same size"));
    const double coefficients[2] = {alpha, beta};
    const char* names[2] = {"α (mass-proportional) [1/s]", "β (stiffness-proportional) [s]"};
    for (int k = 0; k < 2; ++k)
        if (!(coefficients[k] >= 0.0 && coefficients[k] <= max_rayleigh_coefficient))
            throw Error(str("rayleigh_damping: ", names[k], " = ", coefficients[k],
                            " is outside the lecture's range [0, ", max_rayleigh_coefficient,
                            "]; negative damping adds energy, and larger values overdamp"));
    return alpha * M + beta * K;
}

Eigen::VectorXd gravity_load(const TetMesh& mesh, double density, const Eigen::Vector3d& g)
{
    for (int c = 0; c < 3; ++c)
        require_finite(g[c], "gravity g");
    const Eigen::VectorXd m = vertex_masses(mesh, density);
    Eigen::VectorXd f(3 * m.size());
    for (Eigen::Index v = 0; v < m.size(); ++v)
        f.segment<3>(3 * v) = m[v] * g;
    return f;
}

}  // namespace fem::assembly
