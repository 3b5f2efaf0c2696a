// Chapter 02: the grid, its boundary values and the 5-point Laplacian (matrix-free and assembled).
// docs/02_heat_equation.md
#include "02_heat_equation/heat_grid.hpp"

#include "common/error.hpp"

#include <cmath>
#include <numbers>
#include <vector>

namespace fem::heat {
namespace {

constexpr int largest_n = 20000;

void check_finite_at(double value, std::string_view what, double x, double y)
{
    if (!std::isfinite(value))
        throw Error(str(what, " is not finite at (x, y) = (", x, ", ", y, "): got ", value));
}

void check_unknowns(const Grid& grid, const Eigen::VectorXd& u, std::string_view what)
{
    if (u.size() != grid.unknowns())
        throw Error(str(what, " has ", u.size(), " values, the grid with n = ", grid.n, " has n² = ",
                        grid.unknowns(), " unknowns"));
}

}  // namespace

void validate(const Grid& grid)
{
    if (grid.n < 1 || grid.n > largest_n)
        throw Error(str("a grid needs 1 ≤ n ≤ ", largest_n, " unknowns per direction, got n = ", grid.n));
}

void validate(const Grid& grid, const BoundaryValues& g)
{
    validate(grid);
    const std::pair<const char*, const Eigen::VectorXd*> edges[4] = {
        {"bottom", &g.bottom}, {"top", &g.top}, {"left", &g.left}, {"right", &g.right}};
    for (const auto& [name, values] : edges) {
        if (values->size() != grid.n + 2)
            throw Error(str("the ", name, " boundary has ", values->size(),
                            " values; a grid with n = ", grid.n, " needs n + 2 = ", grid.n + 2));
        for (Eigen::Index i = 0; i < values->size(); ++i)
            if (!std::isfinite((*values)[i]))
                throw Error(str("the ", name, " boundary value ", i, " is not finite: ", (*values)[i]));
    }
}

BoundaryValues boundary_values(const Grid& grid, const SpatialFunction& g)
{
    validate(grid);
    if (!g)
        throw Error("boundary_values: no function g given");
    BoundaryValues values;
    for (Eigen::VectorXd* edge : {&values.bottom, &values.top, &values.left, &values.right})
        edge->resize(grid.n + 2);
    for (int i = 0; i <= grid.n + 1; ++i) {
        const double s = grid.coordinate(i);
        values.bottom[i] = g(s, 0.0);
        values.top[i] = g(s, 1.0);
        values.left[i] = g(0.0, s);
        values.right[i] = g(1.0, s);
        check_finite_at(values.bottom[i], "the boundary value g", s, 0.0);
        check_finite_at(values.top[i], "the boundary value g", s, 1.0);
        check_finite_at(values.left[i], "the boundary value g", 0.0, s);
        check_finite_at(values.right[i], "the boundary value g", 1.0, s);
    }
    return values;
}

BoundaryValues constant_boundary(const Grid& grid, double value)
{
    require_finite(value, "the boundary value");
    return boundary_values(grid, [value](double, double) { return value; });
}

Eigen::VectorXd sample(const Grid& grid, const SpatialFunction& f)
{
    validate(grid);
    if (!f)
        throw Error("sample: no function given");
    Eigen::VectorXd u(grid.unknowns());
    for (int j = 1; j <= grid.n; ++j)
        for (int i = 1; i <= grid.n; ++i) {
            const double x = grid.coordinate(i), y = grid.coordinate(j);
            const double value = f(x, y);
            check_finite_at(value, "the sampled function", x, y);
            u[grid.unknown(i, j)] = value;
        }
    return u;
}

void stencil_sweep(const Grid& grid, const BoundaryValues& g, const Eigen::VectorXd& u, double alpha,
                   double beta, Eigen::VectorXd& out)
{
    validate(grid, g);
    check_unknowns(grid, u, "the grid function u");
    if (&out == &u)
        throw Error("stencil_sweep: out must be a different vector than u (the sweep reads u's "
                    "neighbours after it writes out)");
    out.resize(grid.unknowns());
    // BEGIN EXERCISE 02.1 stencil_sweep #the-5-point-stencil
    // HINT: loop over the rows j = 1 … n; the row below is row j−1 of u, or g.bottom when j = 1
    // HINT: (and the row above g.top when j = n); the west neighbour of i = 1 is g.left[j], the
    // HINT: east neighbour of i = n is g.right[j]. Remember u_k sits at k = (i−1) + n (j−1).
    const int n = grid.n;
    // The update of one point from its value and the sum of its four neighbours.
    const auto update = [alpha, beta](double centre, double neighbours) {
        return alpha * centre + beta * (neighbours - 4.0 * centre);
    };
    for (int j = 1; j <= n; ++j) {
        // Row j of u and out, and the rows below and above it (from g on the ring). All four are
        // indexed by c = i − 1: g's edges hold n+2 values, so they are shifted by one.
        const double* row = u.data() + Eigen::Index{n} * (j - 1);
        const double* below = j == 1 ? g.bottom.data() + 1 : row - n;
        const double* above = j == n ? g.top.data() + 1 : row + n;
        double* result = out.data() + Eigen::Index{n} * (j - 1);
        const double west_edge = g.left[j], east_edge = g.right[j];
        if (n == 1) {
            result[0] = update(row[0], west_edge + east_edge + below[0] + above[0]);
            continue;
        }
        // The first and last points of the row take one neighbour from the ring; the points in
        // between have all four in u (a loop without branches, which the compiler vectorizes).
        result[0] = update(row[0], west_edge + row[1] + below[0] + above[0]);
        for (int c = 1; c < n - 1; ++c)
            result[c] = update(row[c], row[c - 1] + row[c + 1] + below[c] + above[c]);
        result[n - 1] = update(row[n - 1], row[n - 2] + east_edge + below[n - 1] + above[n - 1]);
    }
    // END EXERCISE
}

void apply_laplacian(const Grid& grid, const BoundaryValues& g, const Eigen::VectorXd& u,
                     Eigen::VectorXd& out)
{
    validate(grid);
    const double h = grid.h();
    stencil_sweep(grid, g, u, 0.0, 1.0 / (h * h), out);
}

Eigen::SparseMatrix<double> laplacian_matrix(const Grid& grid)
{
    validate(grid);
    const Eigen::Index size = grid.unknowns();
    Eigen::SparseMatrix<double> L(size, size);
    // BEGIN EXERCISE 02.2 laplacian_matrix #the-assembled-laplacian
    // HINT: one triplet (k, k, −4/h²) per unknown k = unknown(i, j), and (k, m, 1/h²) for each of
    // HINT: its four neighbours m that is itself an unknown (1 ≤ i±1, j±1 ≤ n); then setFromTriplets.
    const int n = grid.n;
    const double w = 1.0 / (grid.h() * grid.h());
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(static_cast<std::size_t>(5 * size));
    for (int j = 1; j <= n; ++j)
        for (int i = 1; i <= n; ++i) {
            const auto k = static_cast<int>(grid.unknown(i, j));
            triplets.emplace_back(k, k, -4.0 * w);
            if (i > 1)
                triplets.emplace_back(k, static_cast<int>(grid.unknown(i - 1, j)), w);
            if (i < n)
                triplets.emplace_back(k, static_cast<int>(grid.unknown(i + 1, j)), w);
            if (j > 1)
                triplets.emplace_back(k, static_cast<int>(grid.unknown(i, j - 1)), w);
            if (j < n)
                triplets.emplace_back(k, static_cast<int>(grid.unknown(i, j + 1)), w);
        }
    L.setFromTriplets(triplets.begin(), triplets.end());
    // END EXERCISE
    return L;
}

Eigen::VectorXd boundary_lift(const Grid& grid, const BoundaryValues& g)
{
    validate(grid, g);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(grid.unknowns());
    // BEGIN EXERCISE 02.3 boundary_lift #dirichlet-boundary-values
    // HINT: only unknowns next to the ring get a contribution: g.bottom[i] for j = 1, g.top[i] for
    // HINT: j = n, g.left[j] for i = 1, g.right[j] for i = n (a corner unknown gets two), over h².
    const int n = grid.n;
    const double w = 1.0 / (grid.h() * grid.h());
    for (int i = 1; i <= n; ++i) {
        b[grid.unknown(i, 1)] += w * g.bottom[i];
        b[grid.unknown(i, n)] += w * g.top[i];
    }
    for (int j = 1; j <= n; ++j) {
        b[grid.unknown(1, j)] += w * g.left[j];
        b[grid.unknown(n, j)] += w * g.right[j];
    }
    // END EXERCISE
    return b;
}

double laplacian_eigenvalue(const Grid& grid, int k, int l)
{
    validate(grid);
    if (k < 1 || k > grid.n || l < 1 || l > grid.n)
        throw Error(str("a sine mode of a grid with n = ", grid.n, " needs 1 ≤ k, l ≤ ", grid.n,
                        ", got (k, l) = (", k, ", ", l, ")"));
    const double h = grid.h();
    const double sk = std::sin(k * std::numbers::pi * h / 2.0);
    const double sl = std::sin(l * std::numbers::pi * h / 2.0);
    return -4.0 / (h * h) * (sk * sk + sl * sl);
}

Eigen::VectorXd sine_mode(const Grid& grid, int k, int l)
{
    if (k < 1 || l < 1)
        throw Error(str("a sine mode needs k, l ≥ 1, got (k, l) = (", k, ", ", l, ")"));
    return sample(grid, [k, l](double x, double y) {
        return std::sin(k * std::numbers::pi * x) * std::sin(l * std::numbers::pi * y);
    });
}

double sine_mode_solution(int k, int l, double c, double x, double y, double t)
{
    const double pi = std::numbers::pi;
    return std::exp(-c * pi * pi * (k * k + l * l) * t) * std::sin(k * pi * x) * std::sin(l * pi * y);
}

Eigen::VectorXd hot_square(const Grid& grid)
{
    return sample(grid, [](double x, double y) {
        return (x > 0.25 && x < 0.75 && y > 0.25 && y < 0.75) ? 1.0 : 0.0;
    });
}

io::ImageGrid to_image(const Grid& grid, const BoundaryValues& g, const Eigen::VectorXd& u,
                       const std::string& field)
{
    validate(grid, g);
    check_unknowns(grid, u, "the grid function u");
    const int points = grid.n + 2;
    io::ImageGrid image;
    image.dims = {points, points, 1};
    image.spacing = {grid.h(), grid.h(), 1.0};
    Eigen::VectorXd values(Eigen::Index{points} * points);
    for (int j = 0; j < points; ++j)
        for (int i = 0; i < points; ++i) {
            double value;
            if (j == 0)
                value = g.bottom[i];
            else if (j == points - 1)
                value = g.top[i];
            else if (i == 0)
                value = g.left[j];
            else if (i == points - 1)
                value = g.right[j];
            else
                value = u[grid.unknown(i, j)];
            values[i + Eigen::Index{points} * j] = value;
        }
    image.point_data.push_back({field, values});
    return image;
}

}  // namespace fem::heat
