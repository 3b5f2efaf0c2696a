// Chapter 03: Poisson and heat on triangle meshes against manufactured and analytic solutions and
// against a direct solve of the full system; the quadrature rule against exact integrals.
// docs/03_triangle_gradients.md#poisson-on-a-triangle-mesh
#include "03_triangle_gradients/poisson_heat.hpp"

#include "01_finite_differences/finite_differences.hpp"
#include "common/error.hpp"
#include "common/mesh.hpp"
#include "meshes.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/SparseLU>

#include <cmath>
#include <numbers>

using namespace fem::tri;
using Catch::Matchers::Contains;
using Eigen::Vector3d;
using fem::test::EntriesNear;
using fem::test::entries_of;

namespace {

constexpr double pi = std::numbers::pi;

double sine_mode(const Vector3d& x) { return std::sin(pi * x.x()) * std::sin(pi * x.y()); }
Vector3d sine_mode_gradient(const Vector3d& x)
{
    return pi * Vector3d(std::cos(pi * x.x()) * std::sin(pi * x.y()), std::sin(pi * x.x()) * std::cos(pi * x.y()), 0.0);
}

/// The boundary vertices of the square with the given values of g there.
Dirichlet boundary_values(const fem::TriMesh& mesh, const std::function<double(const Vector3d&)>& g)
{
    Dirichlet fixed;
    fixed.vertices = boundary_vertices(mesh.F, static_cast<int>(mesh.V.rows()));
    fixed.values.resize(static_cast<Eigen::Index>(fixed.vertices.size()));
    for (std::size_t k = 0; k < fixed.vertices.size(); ++k)
        fixed.values[static_cast<Eigen::Index>(k)] = g(mesh.V.row(fixed.vertices[k]).transpose());
    return fixed;
}

/// Solves (M f)-Poisson with u = 0 on the square's boundary for −Δu = 2π² sin(πx) sin(πy).
ErrorNorms manufactured_poisson(int n, double jitter)
{
    const fem::TriMesh mesh = fem::square_mesh(n, jitter, 17);
    Eigen::VectorXd f(mesh.V.rows());
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
        f[v] = 2 * pi * pi * sine_mode(mesh.V.row(v).transpose());
    const Eigen::VectorXd u = solve_poisson(fem_laplacian(mesh.V, mesh.F), lumped_mass(mesh.V, mesh.F), f,
                                            boundary_values(mesh, [](const Vector3d&) { return 0.0; }));
    return error_norms(mesh.V, mesh.F, u, sine_mode, sine_mode_gradient);
}

/// The full system with Dirichlet rows replaced by identity rows, solved by SparseLU: an
/// independent route to the same answer as the reduced systems.
Eigen::VectorXd solve_full(const SparseMatrix& A, const Eigen::VectorXd& rhs, const Dirichlet& fixed)
{
    std::vector<bool> is_fixed(static_cast<std::size_t>(A.rows()), false);
    for (int v : fixed.vertices)
        is_fixed[v] = true;
    std::vector<Eigen::Triplet<double>> triplets;
    for (int col = 0; col < A.outerSize(); ++col)
        for (SparseMatrix::InnerIterator it(A, col); it; ++it)
            if (!is_fixed[it.row()])
                triplets.emplace_back(static_cast<int>(it.row()), col, it.value());
    Eigen::VectorXd b = rhs;
    for (std::size_t k = 0; k < fixed.vertices.size(); ++k) {
        triplets.emplace_back(fixed.vertices[k], fixed.vertices[k], 1.0);
        b[fixed.vertices[k]] = fixed.values[static_cast<Eigen::Index>(k)];
    }
    SparseMatrix full(A.rows(), A.cols());
    full.setFromTriplets(triplets.begin(), triplets.end());
    Eigen::SparseLU<SparseMatrix> lu(full);
    REQUIRE(lu.info() == Eigen::Success);
    return lu.solve(b);
}

}  // namespace

TEST_CASE("Poisson reproduces a linear solution exactly on a jittered mesh", "[ex03.9]")
{
    // −Δu = 0 for u = 1 + 2x − y; linear functions are in the FEM space, so u_h = u.
    const fem::TriMesh mesh = fem::square_mesh(10, 0.24, 8);
    const auto exact = [](const Vector3d& x) { return 1.0 + 2.0 * x.x() - x.y(); };
    const Eigen::VectorXd u = solve_poisson(fem_laplacian(mesh.V, mesh.F), lumped_mass(mesh.V, mesh.F),
                                            Eigen::VectorXd::Zero(mesh.V.rows()), boundary_values(mesh, exact));
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
        CHECK(u[v] == Approx(exact(mesh.V.row(v).transpose())).margin(1e-12));
}

TEST_CASE("Poisson on the square agrees with a direct solve of the full system", "[ex03.9]")
{
    const fem::TriMesh mesh = fem::square_mesh(12, 0.2, 4);
    const SparseMatrix L = fem_laplacian(mesh.V, mesh.F);
    const Eigen::VectorXd m = lumped_mass(mesh.V, mesh.F);
    const Eigen::VectorXd f = mesh.V.col(0).array().exp().matrix();
    const Dirichlet fixed = boundary_values(mesh, [](const Vector3d& x) { return x.y() * x.y(); });
    const Eigen::VectorXd u = solve_poisson(L, m, f, fixed);
    const Eigen::VectorXd reference = solve_full(L, m.cwiseProduct(f), fixed);
    CHECK_THAT(entries_of(u), EntriesNear(reference, 1e-11));
}

TEST_CASE("manufactured Poisson: O(h²) in L2 and O(h) in the gradient on jittered meshes", "[ex03.9]")
{
    std::vector<double> h, l2, gradient;
    for (int n : {8, 16, 32, 64}) {
        const ErrorNorms e = manufactured_poisson(n, 0.2);
        h.push_back(1.0 / n);
        l2.push_back(e.l2);
        gradient.push_back(e.gradient_l2);
    }
    for (double order : fem::fd::observed_orders(h, l2))
        CHECK(order == Approx(2.0).margin(0.15));
    for (double order : fem::fd::observed_orders(h, gradient))
        CHECK(order == Approx(1.0).margin(0.15));
    // The error is small in absolute terms too: ‖u‖ = 1/2 and ‖∇u‖ = π/√2.
    CHECK(l2.back() < 1e-3);
}

TEST_CASE("Poisson refuses what it cannot solve", "[ex03.9]")
{
    const fem::TriMesh sphere = fem::test::bumpy_sphere();
    const SparseMatrix L = fem_laplacian(sphere.V, sphere.F);
    const Eigen::VectorXd m = lumped_mass(sphere.V, sphere.F);
    const Eigen::VectorXd f = Eigen::VectorXd::Zero(sphere.V.rows());
    CHECK_THROWS_WITH(solve_poisson(L, m, f, {}), Contains("singular") && Contains("fixed vertex"));
    CHECK_NOTHROW(solve_poisson(L, m, f, Dirichlet{{5}, Eigen::VectorXd::Ones(1)}));
    CHECK_THROWS_WITH(solve_poisson(L, m, f, Dirichlet{{5, 5}, Eigen::VectorXd::Ones(2)}), Contains("twice"));
    CHECK_THROWS_WITH(solve_poisson(L, m, f, Dirichlet{{-1}, Eigen::VectorXd::Ones(1)}), Contains("out of range"));
    CHECK_THROWS_WITH(solve_poisson(L, m, f, Dirichlet{{5}, Eigen::VectorXd::Ones(2)}), Contains("fixed values"));
    CHECK_THROWS_WITH(solve_poisson(L, m, Eigen::VectorXd::Zero(3), {}), Contains("one per vertex"));
    Eigen::VectorXd bad_mass = m;
    bad_mass[3] = 0.0;
    CHECK_THROWS_WITH(solve_poisson(L, bad_mass, f, {}), Contains("mass of vertex 3"));
}

TEST_CASE("implicit heat: one step equals a direct solve of (M + Δt c L) u⁺ = M u", "[ex03.10]")
{
    const fem::TriMesh mesh = fem::square_mesh(10, 0.2, 6);
    const SparseMatrix L = fem_laplacian(mesh.V, mesh.F);
    const Eigen::VectorXd m = lumped_mass(mesh.V, mesh.F);
    const double c = 0.7, dt = 3e-3;
    const Dirichlet fixed = boundary_values(mesh, [](const Vector3d& x) { return x.x(); });
    Eigen::VectorXd u = (mesh.V.col(0).array() * 3.0).sin().matrix();
    for (std::size_t k = 0; k < fixed.vertices.size(); ++k)
        u[fixed.vertices[k]] = fixed.values[static_cast<Eigen::Index>(k)];
    SparseMatrix A = c * dt * L;
    for (Eigen::Index v = 0; v < A.rows(); ++v)
        A.coeffRef(v, v) += m[v];
    const Eigen::VectorXd reference = solve_full(A, m.cwiseProduct(u), fixed);
    const ImplicitHeat heat(L, m, c, dt, fixed.vertices);
    heat.step(u);
    CHECK_THAT(entries_of(u), EntriesNear(reference, 1e-12));
}

TEST_CASE("implicit heat: the sine mode decays like exp(−2π² c t), error O(h²) with Δt = h²", "[ex03.10]")
{
    const double c = 1.0, t_end = 0.05;
    std::vector<double> h, error;
    for (int n : {16, 32, 64}) {
        const fem::TriMesh mesh = fem::square_mesh(n, 0.2, 12);
        const double dt0 = 1.0 / (n * n);
        const int steps = static_cast<int>(std::ceil(t_end / dt0));
        const ImplicitHeat heat(fem_laplacian(mesh.V, mesh.F), lumped_mass(mesh.V, mesh.F), c, t_end / steps,
                                boundary_vertices(mesh.F, static_cast<int>(mesh.V.rows())));
        Eigen::VectorXd u(mesh.V.rows());
        for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
            u[v] = sine_mode(mesh.V.row(v).transpose());
        for (int s = 0; s < steps; ++s)
            heat.step(u);
        const double decay = std::exp(-2 * pi * pi * c * t_end);
        const auto exact = [&](const Vector3d& x) { return decay * sine_mode(x); };
        const auto exact_gradient = [&](const Vector3d& x) { return Vector3d(decay * sine_mode_gradient(x)); };
        h.push_back(1.0 / n);
        error.push_back(error_norms(mesh.V, mesh.F, u, exact, exact_gradient).l2);
    }
    for (double order : fem::fd::observed_orders(h, error))
        CHECK(order == Approx(2.0).margin(0.15));
}

TEST_CASE("implicit heat on a closed surface: heat is conserved, the range shrinks, any Δt is stable",
          "[ex03.10]")
{
    const fem::TriMesh sphere = fem::test::bumpy_sphere();
    const SparseMatrix L = fem_laplacian(sphere.V, sphere.F);
    const Eigen::VectorXd m = lumped_mass(sphere.V, sphere.F);
    Eigen::VectorXd u = Eigen::VectorXd::Zero(sphere.V.rows());
    u[0] = 1.0;  // a hot pole
    const double heat_before = m.dot(u);
    for (double dt : {1e-3, 1e3}) {
        const ImplicitHeat heat(L, m, 1.0, dt);
        CHECK(heat.free_count() == sphere.V.rows());
        Eigen::VectorXd v = u;
        for (int step = 0; step < 5; ++step) {
            const double max_before = v.maxCoeff();
            heat.step(v);
            // 1ᵀ L = 0, so 1ᵀ M u⁺ = 1ᵀ M u exactly; the solve's round-off grows with Δt c.
            CHECK(m.dot(v) == Approx(heat_before).epsilon(1e-12 * (1.0 + dt)));
            CHECK(v.maxCoeff() <= max_before + 1e-14);
        }
        if (dt > 1.0)  // long after: the constant with the same heat, heat / area
            CHECK((v.array() - heat_before / m.sum()).abs().maxCoeff() < 1e-9);
    }
}

TEST_CASE("implicit heat refuses bad parameters", "[ex03.10]")
{
    const fem::TriMesh mesh = fem::square_mesh(4);
    const SparseMatrix L = fem_laplacian(mesh.V, mesh.F);
    const Eigen::VectorXd m = lumped_mass(mesh.V, mesh.F);
    CHECK_THROWS_WITH(ImplicitHeat(L, m, 0.0, 0.1), Contains("diffusivity"));
    CHECK_THROWS_WITH(ImplicitHeat(L, m, 1.0, -0.1), Contains("time step"));
    CHECK_THROWS_WITH(ImplicitHeat(L, m.head(3), 1.0, 0.1), Contains("one per vertex"));
    const ImplicitHeat heat(L, m, 1.0, 0.1);
    Eigen::VectorXd wrong(3);
    CHECK_THROWS_WITH(heat.step(wrong), Contains("one per vertex"));
}

TEST_CASE("the 7-point rule integrates polynomials up to degree 5 exactly, not degree 6", "[ch03]")
{
    // ∫_T λ_a^i λ_b^j λ_c^k dA = 2A i! j! k! / (i + j + k + 2)!
    const auto factorial = [](int n) { return std::tgamma(n + 1.0); };
    const TriangleQuadrature& rule = seven_point_rule();
    double weights = 0.0;
    for (double w : rule.weights)
        weights += w;
    CHECK(weights == Approx(1.0).epsilon(1e-15));
    for (int degree = 0; degree <= 6; ++degree) {
        double worst = 0.0;
        for (int i = 0; i <= degree; ++i)
            for (int j = 0; i + j <= degree; ++j) {
                const int k = degree - i - j;
                double sum = 0.0;
                for (std::size_t q = 0; q < rule.points.size(); ++q)
                    sum += rule.weights[q] * std::pow(rule.points[q][0], i) * std::pow(rule.points[q][1], j) *
                           std::pow(rule.points[q][2], k);
                // A = 1/2 for the barycentric weights as given (they sum to 1 over the unit area).
                const double exact = 2.0 * factorial(i) * factorial(j) * factorial(k) / factorial(degree + 2);
                worst = std::max(worst, std::abs(sum - exact) / exact);
            }
        if (degree <= rule.degree)
            CHECK(worst < 1e-13);
        else
            CHECK(worst > 1e-6);
    }
}

TEST_CASE("error norms: zero for an interpolated linear function, the area for a constant 1", "[ex03.3]")
{
    const fem::TriMesh mesh = fem::square_mesh(5, 0.2, 3);
    const Vector3d g(2.0, -1.0, 0.0);
    const Eigen::VectorXd u = mesh.V * g;
    const ErrorNorms exact = error_norms(mesh.V, mesh.F, u, [&](const Vector3d& x) { return g.dot(x); },
                                         [&](const Vector3d&) { return g; });
    CHECK(exact.l2 < 1e-14);
    CHECK(exact.gradient_l2 < 1e-12);
    const ErrorNorms one = error_norms(mesh.V, mesh.F, Eigen::VectorXd::Zero(mesh.V.rows()),
                                       [](const Vector3d&) { return 1.0; }, [](const Vector3d&) { return Vector3d(0, 0, 1); });
    CHECK(one.l2 == Approx(1.0).epsilon(1e-13));          // (∫ 1)^½ over the unit square
    CHECK(one.gradient_l2 == Approx(1.0).epsilon(1e-13));
}
