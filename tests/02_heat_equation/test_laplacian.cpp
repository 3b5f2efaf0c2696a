// Chapter 02: the 5-point Laplacian, matrix-free and assembled, with Dirichlet boundary values,
// against exact answers (quadratics, the Kronecker construction, sine modes).
// docs/02_heat_equation.md#the-5-point-stencil
#include "02_heat_equation/heat_grid.hpp"
#include "heat_test_support.hpp"

#include "common/error.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

using namespace fem::heat;
using fem::heat::test::max_difference;
using Catch::Matchers::Contains;
using fem::test::EntriesNear;
using fem::test::entries_of;

namespace {

/// A quadratic q = 1 + 2x − 3y + a x² + 2xy + b y² with Δq = 2a + 2b.
struct Quadratic {
    double a = 1.5, b = -0.25;
    double operator()(double x, double y) const
    {
        return 1.0 + 2.0 * x - 3.0 * y + a * x * x + 2.0 * x * y + b * y * y;
    }
    double laplacian() const { return 2.0 * a + 2.0 * b; }
};

/// The sine modes (k, l) the eigenvector tests use: low, mixed and the highest of a 20×20 grid.
const std::vector<std::pair<int, int>> sine_mode_indices{{1, 1}, {2, 3}, {7, 1}, {20, 20}};

/// A smooth non-polynomial boundary function, different on every edge.
double wavy(double x, double y) { return std::cos(3.0 * x) + std::exp(y) * (1.0 + x * y); }

}  // namespace

TEST_CASE("the discrete Laplacian of a quadratic is exact, boundary values included", "[ex02.1]")
{
    const Quadratic q;
    for (int n : {1, 2, 7, 31}) {
        const Grid grid{n};
        const BoundaryValues g = boundary_values(grid, q);
        Eigen::VectorXd lap;
        apply_laplacian(grid, g, sample(grid, q), lap);
        REQUIRE(lap.size() == grid.unknowns());
        // Round-off: values of size ~3 divided by h², about 1e-15 (n+1)² in absolute terms.
        CHECK(max_difference(lap, Eigen::VectorXd::Constant(grid.unknowns(), q.laplacian())) <
              1e-12 * (n + 1) * (n + 1));
    }
}

TEST_CASE("L u + b of a quadratic is exact too (assembled matrix and boundary lift)", "[ex02.3]")
{
    const Quadratic q;
    for (int n : {1, 3, 16}) {
        const Grid grid{n};
        const Eigen::VectorXd lap =
            laplacian_matrix(grid) * sample(grid, q) + boundary_lift(grid, boundary_values(grid, q));
        CHECK(max_difference(lap, Eigen::VectorXd::Constant(grid.unknowns(), q.laplacian())) <
              1e-12 * (n + 1) * (n + 1));
    }
}

TEST_CASE("one stencil sweep on a 3×3 grid, by hand", "[ex02.1]")
{
    const Grid grid{3};  // h = 1/4, unknowns at x, y ∈ {1/4, 1/2, 3/4}
    BoundaryValues g = constant_boundary(grid, 0.0);
    g.bottom[1] = 10.0;  // below unknown (1, 1)
    g.left[1] = 20.0;    // left of unknown (1, 1)
    g.right[2] = 30.0;   // right of unknown (3, 2)
    g.top[2] = 40.0;     // above unknown (2, 3)
    Eigen::VectorXd u(9);
    u << 1, 2, 3,   // j = 1
        4, 5, 6,    // j = 2
        7, 8, 9;    // j = 3
    const double alpha = 0.5, beta = 0.25;
    Eigen::VectorXd out;
    stencil_sweep(grid, g, u, alpha, beta, out);
    REQUIRE(out.size() == 9);
    const auto expect = [&](double centre, double e, double w, double n, double s) {
        return alpha * centre + beta * (e + w + n + s - 4.0 * centre);
    };
    CHECK(out[grid.unknown(1, 1)] == Approx(expect(1, 2, 20, 4, 10)));  // a corner: two from g
    CHECK(out[grid.unknown(2, 1)] == Approx(expect(2, 3, 1, 5, 0)));
    CHECK(out[grid.unknown(2, 2)] == Approx(expect(5, 6, 4, 8, 2)));    // the centre: all from u
    CHECK(out[grid.unknown(3, 2)] == Approx(expect(6, 30, 5, 9, 3)));
    CHECK(out[grid.unknown(2, 3)] == Approx(expect(8, 9, 7, 40, 5)));
    CHECK(out[grid.unknown(3, 3)] == Approx(expect(9, 0, 8, 0, 6)));
    // The corners of the ring are never read.
    BoundaryValues corners = g;
    for (Eigen::VectorXd* edge : {&corners.bottom, &corners.top, &corners.left, &corners.right}) {
        (*edge)[0] = 1e3;
        (*edge)[4] = -1e3;
    }
    Eigen::VectorXd again;
    stencil_sweep(grid, corners, u, alpha, beta, again);
    CHECK(max_difference(out, again) == 0.0);
}

TEST_CASE("the assembled Laplacian equals the Kronecker sum (T ⊗ I + I ⊗ T)/h²", "[ex02.2]")
{
    for (int n : {1, 2, 5, 12}) {
        const Grid grid{n};
        const Eigen::SparseMatrix<double> L = laplacian_matrix(grid);
        REQUIRE(L.rows() == grid.unknowns());
        REQUIRE(L.cols() == grid.unknowns());
        CHECK_THAT(entries_of(L), EntriesNear(test::kronecker_laplacian(n), 1e-9));
        // 5 entries per row, minus one for each missing neighbour on the 4n edge positions.
        CHECK(L.nonZeros() == 5 * n * n - 4 * n);
    }
}

TEST_CASE("the boundary lift of a constant is 1/h² per boundary neighbour", "[ex02.3]")
{
    const Grid grid{4};  // h = 1/5
    const double w = 25.0;
    const Eigen::VectorXd b = boundary_lift(grid, constant_boundary(grid, 1.0));
    REQUIRE(b.size() == 16);
    CHECK(b[grid.unknown(1, 1)] == Approx(2 * w));  // corner unknowns have two ring neighbours
    CHECK(b[grid.unknown(4, 4)] == Approx(2 * w));
    CHECK(b[grid.unknown(2, 1)] == Approx(w));
    CHECK(b[grid.unknown(4, 3)] == Approx(w));
    CHECK(b[grid.unknown(2, 2)] == 0.0);  // an inner unknown
    CHECK(b[grid.unknown(3, 3)] == 0.0);
    // A constant is harmonic: L 1 + b = 0.
    const Eigen::VectorXd ones = Eigen::VectorXd::Ones(16);
    CHECK((laplacian_matrix(grid) * ones + b).cwiseAbs().maxCoeff() < 1e-12);
}

TEST_CASE("L u + b equals the matrix-free stencil for any u and any boundary values", "[ex02.3]")
{
    for (int n : {1, 2, 9, 40}) {
        const Grid grid{n};
        const BoundaryValues g = boundary_values(grid, wavy);
        const Eigen::VectorXd u = sample(grid, [](double x, double y) { return std::sin(7 * x * y) + x; });
        Eigen::VectorXd matrix_free;
        apply_laplacian(grid, g, u, matrix_free);
        const Eigen::VectorXd assembled = laplacian_matrix(grid) * u + boundary_lift(grid, g);
        CHECK(max_difference(matrix_free, assembled) < 1e-12 * (n + 1) * (n + 1));
    }
}

TEST_CASE("sine modes are eigenvectors with λ = −(4/h²)(sin²(kπh/2) + sin²(lπh/2))", "[ex02.1]")
{
    // So the exact-in-time solution of u' = c Δ_h u from a sine mode is exp(cλt) times the mode:
    // it decays at the discrete rate c|λ| per unit time.
    const Grid grid{20};
    const BoundaryValues zero = constant_boundary(grid, 0.0);
    for (auto [k, l] : sine_mode_indices) {
        const double lambda = test::eigenvalue_formula(grid.n, k, l);
        CHECK(laplacian_eigenvalue(grid, k, l) == Approx(lambda).epsilon(1e-14));
        const Eigen::VectorXd v = sine_mode(grid, k, l);
        Eigen::VectorXd lap;
        apply_laplacian(grid, zero, v, lap);
        CHECK(max_difference(lap, lambda * v) < 1e-11 * std::abs(lambda));
    }
    // As h → 0 the discrete eigenvalue tends to the continuous −π²(k² + l²), with error O(h²).
    const double pi = std::numbers::pi;
    std::vector<double> error;
    for (int n : {15, 31, 63})
        error.push_back(std::abs(laplacian_eigenvalue(Grid{n}, 2, 1) + 5.0 * pi * pi));
    CHECK(std::log2(error[0] / error[1]) == Approx(2.0).margin(0.05));
    CHECK(std::log2(error[1] / error[2]) == Approx(2.0).margin(0.05));
}

TEST_CASE("the assembled Laplacian has the same sine-mode eigenvectors", "[ex02.2]")
{
    const Grid grid{20};
    const Eigen::SparseMatrix<double> L = laplacian_matrix(grid);
    for (auto [k, l] : sine_mode_indices) {
        const double lambda = test::eigenvalue_formula(grid.n, k, l);
        const Eigen::VectorXd v = sine_mode(grid, k, l);
        CHECK(max_difference(L * v, lambda * v) < 1e-11 * std::abs(lambda));
    }
}

TEST_CASE("the image of a grid function holds u inside and g on the ring", "[heat][vtk]")
{
    const Grid grid{3};
    const BoundaryValues g = boundary_values(grid, [](double x, double y) { return 10 * x + 100 * y; });
    const Eigen::VectorXd u = Eigen::VectorXd::LinSpaced(9, 1.0, 9.0);
    const fem::io::ImageGrid image = to_image(grid, g, u);
    CHECK(image.dims == std::array<int, 3>{5, 5, 1});
    CHECK(image.spacing[0] == 0.25);
    const Eigen::MatrixXd& values = image.point_data.at(0).values;
    REQUIRE(values.rows() == 25);
    CHECK(values(1 + 5 * 1, 0) == 1.0);           // unknown (1, 1)
    CHECK(values(3 + 5 * 3, 0) == 9.0);           // unknown (3, 3)
    CHECK(values(4 + 5 * 0, 0) == Approx(10.0));  // corner (1, 0)
    CHECK(values(0 + 5 * 2, 0) == Approx(50.0));  // left edge (0, 1/2)
    CHECK(values(2 + 5 * 4, 0) == Approx(105.0)); // top edge (1/2, 1)
}

TEST_CASE("bad grids, boundary values and grid functions are rejected with fem::Error", "[heat][errors]")
{
    CHECK_THROWS_WITH(laplacian_matrix(Grid{0}), Contains("1 ≤ n"));
    CHECK_THROWS_AS(sample(Grid{-3}, wavy), fem::Error);
    CHECK_THROWS_AS(constant_boundary(Grid{0}, 1.0), fem::Error);
    CHECK_THROWS_AS(laplacian_matrix(Grid{100000}), fem::Error);

    const Grid grid{4};
    CHECK_THROWS_AS(constant_boundary(grid, std::nan("")), fem::Error);
    CHECK_THROWS_WITH(boundary_values(grid, [](double x, double) { return x > 0.9 ? std::numeric_limits<double>::infinity() : x; }),
                      Contains("not finite at (x, y) = (1"));
    CHECK_THROWS_WITH(sample(grid, [](double x, double y) { return std::log(x - y); }),
                      Contains("not finite"));

    const BoundaryValues g = constant_boundary(grid, 0.0);
    const Eigen::VectorXd u = Eigen::VectorXd::Zero(grid.unknowns());
    Eigen::VectorXd out;
    CHECK_THROWS_WITH(apply_laplacian(grid, g, Eigen::VectorXd::Zero(15), out), Contains("15 values"));
    BoundaryValues short_edge = g;
    short_edge.left.resize(4);
    CHECK_THROWS_WITH(apply_laplacian(grid, short_edge, u, out), Contains("left boundary has 4"));
    BoundaryValues nan_edge = g;
    nan_edge.top[2] = std::nan("");
    CHECK_THROWS_WITH(apply_laplacian(grid, nan_edge, u, out), Contains("top boundary value 2"));
    CHECK_THROWS_WITH(boundary_lift(grid, nan_edge), Contains("not finite"));
    Eigen::VectorXd same = u;
    CHECK_THROWS_WITH(stencil_sweep(grid, g, same, 1.0, 1.0, same), Contains("different vector"));
    CHECK_THROWS_AS(laplacian_eigenvalue(grid, 0, 1), fem::Error);
    CHECK_THROWS_AS(laplacian_eigenvalue(grid, 1, 5), fem::Error);
    CHECK_THROWS_AS(sine_mode(grid, 1, 0), fem::Error);
    CHECK_THROWS_AS(to_image(grid, g, Eigen::VectorXd::Zero(3)), fem::Error);
}
