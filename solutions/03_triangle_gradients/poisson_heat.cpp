// Chapter 03: Poisson and implicit heat on a triangle mesh with Dirichlet vertices; error norms.
// docs/03_triangle_gradients.md#poisson-on-a-triangle-mesh
#include "03_triangle_gradients/poisson_heat.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <utility>

namespace fem::tri {
namespace {

/// The vertices split into free and fixed ones (both ascending) and, per vertex, its position in
/// its own list.
struct Split {
    std::vector<int> free, fixed;
    std::vector<int> position;
};

Split split_vertices(int vertex_count, const std::vector<int>& fixed, const char* function)
{
    std::vector<bool> is_fixed(static_cast<std::size_t>(vertex_count), false);
    for (std::size_t k = 0; k < fixed.size(); ++k) {
        const int v = fixed[k];
        if (v < 0 || v >= vertex_count)
            throw Error(str(function, ": fixed vertex ", v, " (entry ", k, ") is out of range; vertices are numbered 0 to ",
                            vertex_count - 1));
        if (is_fixed[v])
            throw Error(str(function, ": vertex ", v, " is listed twice among the fixed vertices"));
        is_fixed[v] = true;
    }
    Split split;
    split.position.resize(static_cast<std::size_t>(vertex_count));
    for (int v = 0; v < vertex_count; ++v) {
        auto& list = is_fixed[v] ? split.fixed : split.free;
        split.position[v] = static_cast<int>(list.size());
        list.push_back(v);
    }
    if (split.free.empty())
        throw Error(str(function, ": every vertex is fixed; there is nothing to solve for"));
    return split;
}

/// The blocks A_FF (free rows and columns) and A_FB (free rows, fixed columns) of a square matrix.
std::pair<SparseMatrix, SparseMatrix> free_blocks(const SparseMatrix& A, const Split& split)
{
    std::vector<bool> is_fixed(split.position.size(), false);
    for (int v : split.fixed)
        is_fixed[v] = true;
    std::vector<Eigen::Triplet<double>> ff, fb;
    for (int col = 0; col < A.outerSize(); ++col)
        for (SparseMatrix::InnerIterator it(A, col); it; ++it) {
            const int row = static_cast<int>(it.row());
            if (is_fixed[row])
                continue;
            (is_fixed[col] ? fb : ff).emplace_back(split.position[row], split.position[col], it.value());
        }
    const auto free_count = static_cast<Eigen::Index>(split.free.size());
    SparseMatrix A_FF(free_count, free_count), A_FB(free_count, static_cast<Eigen::Index>(split.fixed.size()));
    A_FF.setFromTriplets(ff.begin(), ff.end());
    A_FB.setFromTriplets(fb.begin(), fb.end());
    return {std::move(A_FF), std::move(A_FB)};
}

void check_system(const SparseMatrix& L, const Eigen::VectorXd& mass, const char* function)
{
    if (L.rows() != L.cols())
        throw Error(str(function, ": L must be square, got ", L.rows(), "×", L.cols()));
    if (mass.size() != L.rows())
        throw Error(str(function, ": ", mass.size(), " masses for ", L.rows(), " vertices; give one per vertex"));
    for (Eigen::Index v = 0; v < mass.size(); ++v)
        require_positive(mass[v], str(function, ": the mass of vertex ", v));
}

/// Factors the SPD matrix A, or fem::Error when it is (numerically) singular or indefinite.
void factor(Eigen::SimplicialLDLT<SparseMatrix>& solver, const SparseMatrix& A, const char* function,
            const char* why)
{
    solver.compute(A);
    bool ok = solver.info() == Eigen::Success;
    if (ok) {
        const Eigen::VectorXd D = solver.vectorD();
        ok = D.minCoeff() > 1e-13 * D.maxCoeff();
    }
    if (!ok)
        throw Error(str(function, ": the system matrix is singular or not positive definite (", why, ")"));
}

}  // namespace

Eigen::VectorXd solve_poisson(const SparseMatrix& L, const Eigen::VectorXd& mass, const Eigen::VectorXd& f,
                              const Dirichlet& fixed)
{
    check_system(L, mass, "solve_poisson");
    if (f.size() != L.rows())
        throw Error(str("solve_poisson: f has ", f.size(), " values, expected one per vertex: ", L.rows()));
    if (fixed.values.size() != static_cast<Eigen::Index>(fixed.vertices.size()))
        throw Error(str("solve_poisson: ", fixed.vertices.size(), " fixed vertices but ", fixed.values.size(),
                        " fixed values"));
    const Split split = split_vertices(static_cast<int>(L.rows()), fixed.vertices, "solve_poisson");
    Eigen::VectorXd g(split.fixed.size());  // the fixed values in the order of split.fixed
    for (std::size_t k = 0; k < fixed.vertices.size(); ++k)
        g[split.position[fixed.vertices[k]]] = fixed.values[static_cast<Eigen::Index>(k)];
    const auto [L_FF, L_FB] = free_blocks(L, split);
    Eigen::SimplicialLDLT<SparseMatrix> solver;
    factor(solver, L_FF, "solve_poisson",
           "does every connected part of the mesh have a fixed vertex? Without one, u is only defined up to a constant");
    // BEGIN EXERCISE 03.9 solve_poisson #poisson-on-a-triangle-mesh
    // HINT: The right-hand side of the free rows is (M f)_F − L_FB g; solver.solve(rhs) gives u_F.
    // HINT: Then scatter: u[split.free[k]] = u_F[k], u[split.fixed[k]] = g[k].
    Eigen::VectorXd rhs(split.free.size());
    for (std::size_t k = 0; k < split.free.size(); ++k)
        rhs[static_cast<Eigen::Index>(k)] = mass[split.free[k]] * f[split.free[k]];
    if (!split.fixed.empty())
        rhs -= L_FB * g;
    const Eigen::VectorXd u_free = solver.solve(rhs);
    Eigen::VectorXd u(L.rows());
    for (std::size_t k = 0; k < split.free.size(); ++k)
        u[split.free[k]] = u_free[static_cast<Eigen::Index>(k)];
    for (std::size_t k = 0; k < split.fixed.size(); ++k)
        u[split.fixed[k]] = g[static_cast<Eigen::Index>(k)];
    return u;
    // END EXERCISE
}

ImplicitHeat::ImplicitHeat(const SparseMatrix& L, const Eigen::VectorXd& mass, double c, double dt,
                           const std::vector<int>& fixed)
    : c_(c), dt_(dt)
{
    check_system(L, mass, "ImplicitHeat");
    require_positive(c, "ImplicitHeat: the diffusivity c");
    require_positive(dt, "ImplicitHeat: the time step dt");
    Split split = split_vertices(static_cast<int>(L.rows()), fixed, "ImplicitHeat");
    auto [L_FF, L_FB] = free_blocks(L, split);
    mass_free_.resize(static_cast<Eigen::Index>(split.free.size()));
    std::vector<Eigen::Triplet<double>> diagonal;
    for (std::size_t k = 0; k < split.free.size(); ++k) {
        mass_free_[static_cast<Eigen::Index>(k)] = mass[split.free[k]];
        diagonal.emplace_back(static_cast<int>(k), static_cast<int>(k), mass[split.free[k]]);
    }
    SparseMatrix M_FF(L_FF.rows(), L_FF.cols());
    M_FF.setFromTriplets(diagonal.begin(), diagonal.end());
    factor(solver_, SparseMatrix(M_FF + (dt * c) * L_FF), "ImplicitHeat", "M + dt c L must be positive definite");
    coupling_ = std::move(L_FB);
    free_ = std::move(split.free);
    fixed_ = std::move(split.fixed);
}

void ImplicitHeat::step(Eigen::VectorXd& u) const
{
    const auto vertex_count = static_cast<Eigen::Index>(free_.size() + fixed_.size());
    if (u.size() != vertex_count)
        throw Error(str("ImplicitHeat::step: u has ", u.size(), " values, expected one per vertex: ", vertex_count));
    // BEGIN EXERCISE 03.10 implicit_heat_step #heat-on-a-triangle-mesh
    // HINT: rhs = M_F u_F − Δt c L_FB u_B (mass_free_ holds M_F, coupling_ holds L_FB); then
    // HINT: u_F = solver_.solve(rhs), written back into u at the free vertices.
    Eigen::VectorXd rhs(static_cast<Eigen::Index>(free_.size()));
    for (std::size_t k = 0; k < free_.size(); ++k)
        rhs[static_cast<Eigen::Index>(k)] = mass_free_[static_cast<Eigen::Index>(k)] * u[free_[k]];
    if (!fixed_.empty()) {
        Eigen::VectorXd u_fixed(static_cast<Eigen::Index>(fixed_.size()));
        for (std::size_t k = 0; k < fixed_.size(); ++k)
            u_fixed[static_cast<Eigen::Index>(k)] = u[fixed_[k]];
        rhs -= (dt_ * c_) * (coupling_ * u_fixed);
    }
    const Eigen::VectorXd u_free = solver_.solve(rhs);
    for (std::size_t k = 0; k < free_.size(); ++k)
        u[free_[k]] = u_free[static_cast<Eigen::Index>(k)];
    // END EXERCISE
}

const TriangleQuadrature& seven_point_rule()
{
    static const TriangleQuadrature rule = [] {
        const double s = std::sqrt(15.0);
        const double a1 = (6.0 - s) / 21.0, b1 = (9.0 + 2.0 * s) / 21.0, w1 = (155.0 - s) / 1200.0;
        const double a2 = (6.0 + s) / 21.0, b2 = (9.0 - 2.0 * s) / 21.0, w2 = (155.0 + s) / 1200.0;
        TriangleQuadrature q;
        q.degree = 5;
        q.points = {{1.0 / 3, 1.0 / 3, 1.0 / 3}, {b1, a1, a1}, {a1, b1, a1}, {a1, a1, b1},
                    {b2, a2, a2}, {a2, b2, a2}, {a2, a2, b2}};
        q.weights = {9.0 / 40, w1, w1, w1, w2, w2, w2};
        return q;
    }();
    return rule;
}

ErrorNorms error_norms(const MatrixX3d& V, const MatrixX3i& F, const Eigen::VectorXd& u_h,
                       const std::function<double(const Eigen::Vector3d&)>& u,
                       const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& grad_u)
{
    const MatrixX3d gradients = face_gradients(V, F, u_h);  // validates the mesh and u_h's size
    const TriangleQuadrature& rule = seven_point_rule();
    double l2 = 0.0, h1 = 0.0;
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
        const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
        const double area = 0.5 * (b - a).cross(c - a).norm();
        const Eigen::Vector3d values(u_h[F(f, 0)], u_h[F(f, 1)], u_h[F(f, 2)]);
        double sum_l2 = 0.0, sum_h1 = 0.0;
        for (std::size_t q = 0; q < rule.points.size(); ++q) {
            const Eigen::Vector3d& lambda = rule.points[q];
            const Eigen::Vector3d x = lambda[0] * a + lambda[1] * b + lambda[2] * c;
            const double e = lambda.dot(values) - u(x);
            sum_l2 += rule.weights[q] * e * e;
            sum_h1 += rule.weights[q] * (gradients.row(f).transpose() - grad_u(x)).squaredNorm();
        }
        l2 += area * sum_l2;
        h1 += area * sum_h1;
    }
    return {std::sqrt(l2), std::sqrt(h1)};
}

}  // namespace fem::tri
