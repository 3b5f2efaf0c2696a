// ch02_heat_equation: the 2D heat equation u_t = c Δu on the unit square with explicit Euler,
// implicit Euler and Crank–Nicolson: speed against error, the matrix-free step against the memory
// bandwidth, stability, and the hot square diffusing.
//
// Sample runs:
//   ch02_heat_equation                       full run, files in out/02_heat_equation
//   ch02_heat_equation --quick               the small run ctest checks
//   ch02_heat_equation --method cn --dt 1e-3 --steps 40       CN rings on the hot square
//   ch02_heat_equation --method explicit --dt 1.4e-5 --steps 1500
//   ch02_heat_equation --method explicit     (default Δt is 13× its limit: blows up, says so)
//
// Writes: tables pareto_table.csv, orders_table.csv, throughput_table.csv, stability_table.csv;
// the chart pareto (PNG + CSV); the time series hot_square.pvd (+ frames in hot_square/) and heat
// maps hot_square_0.png … hot_square_3.png; large_dt_implicit_euler.png / _crank_nicolson.png.
// docs/02_heat_equation.md

#include "01_finite_differences/finite_differences.hpp"
#include "02_heat_equation/heat_grid.hpp"
#include "02_heat_equation/heat_schemes.hpp"

#include "common/bandwidth.hpp"
#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"
#include "common/vtk_io.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

using namespace fem;
using namespace fem::heat;

namespace {

struct Settings {
    double c = 1.0;                  // diffusivity, every study
    int n = 128;                     // the time series: unknowns per direction
    double dt = 2e-4;                // the time series: time step
    int steps = 100;                 // the time series: number of steps
    std::string method = "implicit"; // the time series: scheme
};

constexpr Scheme all_schemes[] = {Scheme::explicit_euler, Scheme::implicit_euler, Scheme::crank_nicolson};

/// The final time of the speed-against-error study: exp(−2π² c t) ≈ 0.37 for c = 1.
constexpr double pareto_t_end = 0.05;

/// The sine mode (1,1) with a cold boundary, run to t_end: max-norm error against the exact
/// solution, and the wall time of a whole run (the factorization included).
struct Measured {
    double error = 0.0;
    double seconds = 0.0;
};

Measured sine_mode_run(int n, double c, Scheme scheme, int steps, double t_end)
{
    const Grid grid{n};
    const BoundaryValues zero = constant_boundary(grid, 0.0);
    const Eigen::VectorXd u0 = sine_mode(grid, 1, 1);
    HeatRun heat;
    Measured result;
    result.seconds = best_time(
        [&] {
            HeatStepper stepper(grid, zero, c, scheme, t_end / steps);
            heat = simulate_heat(stepper, u0, steps);
        },
        0.05, 10);
    if (heat.blew_up)
        throw Error(str(scheme_name(scheme), " with n = ", n, " and ", steps, " steps blew up at step ",
                        heat.blow_up_step, "; the study must stay inside the stability limit"));
    const Eigen::VectorXd exact =
        sample(grid, [&](double x, double y) { return sine_mode_solution(1, 1, c, x, y, heat.time); });
    result.error = (heat.u - exact).cwiseAbs().maxCoeff();
    return result;
}

/// How a scheme refines Δt with the grid along its curve of the speed-against-error chart: the
/// coarsest grid takes first_steps steps, and each halving of h multiplies the steps by
/// steps_factor (2: Δt ∝ h, 4: Δt ∝ h²). Explicit Euler ignores both: its Δt follows its limit.
struct Refinement {
    Scheme scheme;
    std::string label;
    int steps_factor;
    int first_steps;
};

/// Steps to t_end with Δt = 0.8 h²/(4c), the explicit scheme's step in the studies. With c = 1,
/// t_end = 0.05 and n + 1 a multiple of 2 this is exactly (n+1)²/4 steps.
int explicit_steps(int n, double c, double t_end)
{
    return static_cast<int>(std::ceil(t_end / (0.8 * explicit_stability_limit(1.0 / (n + 1), c)) - 1e-9));
}

// 1. Speed against error: each scheme refined along its natural path, error at t_end against the
//    exact solution, steps and wall time; the work-precision ("Pareto") chart.
void pareto_study(const RunContext& run, const Settings& settings)
{
    // h = 1/16 … 1/256: n + 1 = 16 … 256 grid cells per side.
    const std::vector<int> sizes = run.quick ? std::vector<int>{15, 31, 63}
                                             : std::vector<int>{15, 31, 63, 127, 255};
    const std::vector<Refinement> paths = {
        {Scheme::explicit_euler, "explicit Euler, dt = 0.8 h^2/(4c)", 0, 0},
        {Scheme::implicit_euler, "implicit Euler, dt ~ h", 2, 5},
        {Scheme::implicit_euler, "implicit Euler, dt ~ h^2", 4, 5},
        {Scheme::crank_nicolson, "Crank-Nicolson, dt ~ h", 2, 5},
    };
    Table table(str("Speed against error: sine mode (1,1), c = ", settings.c, ", t = ", pareto_t_end,
                    ", max-norm error against exp(-2 pi^2 c t) sin(pi x) sin(pi y)"),
                {{"scheme", Format::text}, {"refinement", Format::text}, {"n", Format::integer},
                 {"h", Format::scientific, 3}, {"dt", Format::scientific, 3},
                 {"dt / limit", Format::fixed, 2}, {"steps", Format::integer},
                 {"error", Format::scientific, 3}, {"order", Format::fixed, 2},
                 {"time [s]", Format::scientific, 2}});
    fig::LineChart chart{"Heat equation: error against wall time (work-precision, lower left wins)",
                         "wall time [s]", "max-norm error at t = 0.05", true, true, {}};
    chart.legend = fig::Corner::bottom_left;  // the curves run from top left to bottom right
    for (const Refinement& path : paths) {
        fig::Series series{path.label, {}, {}};
        std::vector<double> hs, errors;
        int steps = path.first_steps;
        for (int n : sizes) {
            const double h = 1.0 / (n + 1);
            const int run_steps = path.scheme == Scheme::explicit_euler
                                      ? explicit_steps(n, settings.c, pareto_t_end)
                                      : steps;
            const Measured m = sine_mode_run(n, settings.c, path.scheme, run_steps, pareto_t_end);
            const double dt = pareto_t_end / run_steps;
            hs.push_back(h);
            errors.push_back(m.error);
            const Cell order = hs.size() < 2 ? Cell(std::string("-"))
                                             : Cell(fd::observed_orders(hs, errors).back());
            table.add_row({scheme_name(path.scheme), path.label.substr(path.label.find(", ") + 2),
                           double(n), h, dt, dt / explicit_stability_limit(h, settings.c),
                           double(run_steps), m.error, order, m.seconds});
            series.x.push_back(m.seconds);
            series.y.push_back(m.error);
            steps *= path.steps_factor;
        }
        chart.series.push_back(series);
    }
    table.print(std::cout);
    table.write_csv(run.file("pareto_table.csv"));
    fig::save_chart(chart, run.out_dir / "pareto", run.figures);
}

// 2. Observed orders: in space with each scheme's Δt tied to h, and in time on a fixed grid
//    against the exact-in-time solution exp(cλt) of the sine mode (no space error in it).
void orders_study(const RunContext& run, const Settings& settings)
{
    const double c = settings.c, t_end = pareto_t_end;
    Table table(str("Observed orders (fitted slopes), sine mode (1,1), c = ", c, ", t = ", t_end),
                {{"scheme", Format::text}, {"space order", Format::fixed, 3},
                 {"space: dt rule", Format::text}, {"time order", Format::fixed, 3},
                 {"time: steps", Format::text}});
    const Grid fixed{16};
    const double lambda = laplacian_eigenvalue(fixed, 1, 1);
    for (Scheme scheme : all_schemes) {
        // h = 1/8 … 1/64 and Δt exactly ∝ h² (Euler) or ∝ h (CN): for t_end = 0.05,
        // Δt = 0.8 h²/(4c) → (n+1)²/4 steps, Δt = 0.8 h²/c → (n+1)²/16 steps, Δt = h/10 → (n+1)/2.
        std::vector<double> h, space_error;
        for (int n : {7, 15, 31, 63}) {
            const double spacing = 1.0 / (n + 1);
            const double dt = scheme == Scheme::explicit_euler   ? 0.2 * spacing * spacing / c
                              : scheme == Scheme::implicit_euler ? 0.8 * spacing * spacing / c
                                                                 : 0.1 * spacing;
            h.push_back(spacing);
            space_error.push_back(
                sine_mode_run(n, c, scheme, static_cast<int>(std::ceil(t_end / dt - 1e-9)), t_end).error);
        }
        const std::vector<int> step_counts = scheme == Scheme::explicit_euler   ? std::vector<int>{64, 128, 256, 512}
                                             : scheme == Scheme::implicit_euler ? std::vector<int>{16, 32, 64, 128}
                                                                                : std::vector<int>{8, 16, 32, 64};
        std::vector<double> dt, time_error;
        const Eigen::VectorXd mode = sine_mode(fixed, 1, 1);
        for (int steps : step_counts) {
            HeatStepper stepper(fixed, constant_boundary(fixed, 0.0), c, scheme, t_end / steps);
            const HeatRun heat = simulate_heat(stepper, mode, steps);
            dt.push_back(t_end / steps);
            time_error.push_back((heat.u - std::exp(c * lambda * heat.time) * mode).cwiseAbs().maxCoeff());
        }
        table.add_row({scheme_name(scheme), fd::fitted_order(h, space_error),
                       scheme == Scheme::explicit_euler   ? "0.8 h^2/(4c)"
                       : scheme == Scheme::implicit_euler ? "0.8 h^2/c"
                                                          : "h/10",
                       fd::fitted_order(dt, time_error),
                       str(step_counts.front(), "-", step_counts.back(), " on n = 16")});
    }
    table.print(std::cout);
    table.write_csv(run.file("orders_table.csv"));
}

// 3. The matrix-free explicit step in grid-point updates per second, as a fraction of the memory
//    bandwidth measured now (the triad), beside the same step with the sparse matrix.
void throughput_study(const RunContext& run, const Settings& settings)
{
    const std::size_t triad_elements = std::size_t{1} << (run.quick ? 22 : 23);
    const double triad = measure_triad_bandwidth(triad_elements, run.quick ? 0.05 : 0.2);
    // Bytes a kernel must move per update, counted like the triad (no write-allocate):
    // matrix-free: read u_k, write u⁺_k (the neighbours come from cache); sparse: 5 values and 5
    // column indices of L, one row offset, and u_k, b_k, u⁺_k.
    constexpr double matrix_free_bytes = 2 * 8;
    constexpr double sparse_bytes = 5 * (8 + 4) + 4 + 3 * 8;
    Table table(str("Explicit Euler step throughput (one thread): updates per second and effective "
                    "bandwidth, against the triad a = b + s c on 3 x ", triad_elements, " doubles"),
                {{"kernel", Format::text}, {"n", Format::integer}, {"updates per sweep", Format::integer},
                 {"bytes per update", Format::integer}, {"updates [1/s]", Format::scientific, 3},
                 {"bandwidth [GB/s]", Format::fixed, 2}, {"fraction of triad [measured]", Format::fixed, 2}});
    table.add_row({std::string("triad (memory)"), std::string("-"), double(triad_elements), 24.0,
                   triad * 1e9 / 24.0, triad, 1.0});
    const std::vector<int> sizes = run.quick ? std::vector<int>{64, 256} : std::vector<int>{64, 256, 1024, 2048};
    for (int n : sizes) {
        const Grid grid{n};
        const BoundaryValues g = constant_boundary(grid, 0.0);
        const double dt = 0.5 * explicit_stability_limit(grid.h(), settings.c);
        Eigen::VectorXd u = hot_square(grid), next(grid.unknowns());
        const double updates = double(grid.unknowns());
        const double matrix_free = best_time([&] { explicit_euler_step(grid, g, settings.c, dt, u, next); },
                                             run.quick ? 0.03 : 0.1, 200);
        const Eigen::SparseMatrix<double> L = laplacian_matrix(grid);
        const Eigen::VectorXd b = boundary_lift(grid, g);
        const double sparse = best_time(
            [&] { explicit_euler_step_assembled(L, b, settings.c, dt, u, next); }, run.quick ? 0.03 : 0.1, 200);
        for (auto [name, seconds, bytes] : {std::tuple{"matrix-free stencil", matrix_free, matrix_free_bytes},
                                            std::tuple{"sparse matrix L u + b", sparse, sparse_bytes}}) {
            const double rate = updates / seconds;
            table.add_row({std::string(name), double(n), updates, bytes, rate, rate * bytes * 1e-9,
                           rate * bytes * 1e-9 / triad});
        }
    }
    table.print(std::cout);
    table.write_csv(run.file("throughput_table.csv"));
}

// 4. Stability on the hot square: explicit Euler on both sides of h²/(4c), implicit Euler far
//    beyond it, Crank–Nicolson at and beyond its positivity limit h²/(2c).
void stability_study(const RunContext& run, const Settings& settings)
{
    const Grid grid{32};
    const BoundaryValues zero = constant_boundary(grid, 0.0);
    const double limit = explicit_stability_limit(grid.h(), settings.c);
    const int steps = 4000;
    Table table(str("Stability on the hot square, n = 32, ", steps, " steps, explicit limit h^2/(4c) = ",
                    limit),
                {{"scheme", Format::text}, {"dt / limit", Format::fixed, 2}, {"c dt / h^2", Format::fixed, 4},
                 {"g of mode (n,n)", Format::fixed, 4}, {"outcome", Format::text},
                 {"stopped at step", Format::text}, {"first step out of [0,1]", Format::text},
                 {"lowest u", Format::fixed, 4}, {"highest u", Format::fixed, 4}});
    const std::pair<Scheme, std::vector<double>> cases[] = {
        {Scheme::explicit_euler, {0.5, 0.99, 1.01, 2.0}},
        {Scheme::implicit_euler, {1.0, 100.0}},
        {Scheme::crank_nicolson, {1.0, 2.0, 100.0}}};
    for (const auto& [scheme, ratios] : cases)
        for (double ratio : ratios) {
            const double dt = ratio * limit;
            HeatStepper stepper(grid, zero, settings.c, scheme, dt);
            const HeatRun heat = simulate_heat(stepper, hot_square(grid), steps);
            const std::string outcome = heat.blew_up                ? "blew up"
                                        : heat.first_violation > 0 ? "oscillates"
                                                                    : "stable";
            const auto step_or_dash = [](int step) {
                return step > 0 ? Cell(std::to_string(step)) : Cell(std::string("-"));
            };
            table.add_row({scheme_name(scheme), ratio, settings.c * dt / (grid.h() * grid.h()),
                           amplification_factor(scheme, settings.c, dt, laplacian_eigenvalue(grid, grid.n, grid.n)),
                           outcome, step_or_dash(heat.blow_up_step), step_or_dash(heat.first_violation),
                           heat.lowest, heat.highest});
        }
    table.print(std::cout);
    table.write_csv(run.file("stability_table.csv"));
}

fig::RenderOptions heat_map(const std::string& title, double low, double high)
{
    fig::RenderOptions options;
    options.title = title;
    options.field = "temperature";
    options.range = std::pair{low, high};
    options.width = 760;
    options.height = 700;
    return options;
}

// 5. A time series for ParaView: the hot square diffusing into the cold frame.
void hot_square_series(const RunContext& run, const Settings& settings)
{
    const Grid grid{settings.n};
    const BoundaryValues zero = constant_boundary(grid, 0.0);
    const Scheme scheme = parse_scheme(settings.method);
    HeatStepper stepper(grid, zero, settings.c, scheme, settings.dt);
    const int frames = 20, every = std::max(1, settings.steps / frames);
    const int pictures = 4;
    io::PvdSeries series(run.file("hot_square.pvd"));
    int picture = 0;
    const auto observe = [&](int step, double time, const Eigen::VectorXd& u) {
        const io::ImageGrid image = to_image(grid, zero, u);
        series.add(time, image);
        // Heat maps at (about) 0, 1/3, 2/3 and the end of the run, on one colour scale.
        if (run.figures && picture < pictures && step >= settings.steps * picture / (pictures - 1)) {
            fig::render_grid_png(run.file(str("hot_square_", picture, ".png")), image,
                                 heat_map(str(scheme_name(scheme), ", n = ", grid.n, ", t = ", time), 0.0, 1.0));
            ++picture;
        }
    };
    const HeatRun heat = simulate_heat(stepper, hot_square(grid), settings.steps, observe, every);
    std::cout << "\nhot square: " << scheme_name(scheme) << ", n = " << grid.n << ", dt = " << settings.dt
              << " (" << settings.dt / explicit_stability_limit(grid.h(), settings.c)
              << " x the explicit limit), " << heat.steps_taken << " steps to t = " << heat.time << ": "
              << series.frames() << " frames in hot_square.pvd (open it in ParaView)\n";
    if (heat.blew_up)
        std::cout << "the time series blew up at step " << heat.blow_up_step
                  << ": frames stop at the last valid state\n";
    else if (heat.first_violation > 0)
        std::cout << "the time series left [0, 1] first at step " << heat.first_violation
                  << " (lowest u = " << heat.lowest << "): oscillations, not the heat equation\n";
}

// 6. The hard case in pictures: one step of Crank–Nicolson and of implicit Euler at 100× the
//    explicit limit on the hot square.
void large_step_pictures(const RunContext& run, const Settings& settings)
{
    const Grid grid{32};
    const BoundaryValues zero = constant_boundary(grid, 0.0);
    const double dt = 100.0 * explicit_stability_limit(grid.h(), settings.c);
    std::vector<std::pair<Scheme, Eigen::VectorXd>> states;
    for (Scheme scheme : {Scheme::implicit_euler, Scheme::crank_nicolson}) {
        HeatStepper stepper(grid, zero, settings.c, scheme, dt);
        Eigen::VectorXd u;
        stepper.step(hot_square(grid), u);
        states.emplace_back(scheme, u);
    }
    double low = 0.0, high = 0.0;
    for (const auto& [scheme, u] : states) {
        low = std::min(low, u.minCoeff());
        high = std::max(high, u.maxCoeff());
    }
    for (const auto& [scheme, u] : states) {
        const std::string stem = scheme == Scheme::implicit_euler ? "large_dt_implicit_euler" : "large_dt_crank_nicolson";
        const io::ImageGrid image = to_image(grid, zero, u);
        io::write_vti(run.file(stem + ".vti"), image);
        std::cout << scheme_name(scheme) << ", one step of 100 x the explicit limit: u in [" << u.minCoeff()
                  << ", " << u.maxCoeff() << "]\n";
        if (run.figures)
            fig::render_grid_png(run.file(stem + ".png"), image,
                                 heat_map(str(scheme_name(scheme), ": one step of dt = 100 h^2/(4c)"), low, high));
    }
}

}  // namespace

int main(int argc, char** argv)
{
    ChapterCli cli("ch02_heat_equation", "02_heat_equation",
                   "Chapter 02: the 2D heat equation with explicit Euler, implicit Euler and Crank-Nicolson");
    Settings settings;
    cli.app.add_option("--c", settings.c, "Diffusivity c, every study")
        ->check(check::real(0.0, 100.0, check::Ends::open_closed))->capture_default_str();
    auto* n_option = cli.app.add_option("--n", settings.n, "Hot-square series: unknowns per direction")
                         ->check(check::integer(1, 4000))->capture_default_str();
    cli.app.add_option("--dt", settings.dt, "Hot-square series: time step")->check(check::positive())
        ->capture_default_str();
    auto* steps_option = cli.app.add_option("--steps", settings.steps, "Hot-square series: steps")
                             ->check(check::integer(1, 1000000))->capture_default_str();
    cli.app.add_option("--method", settings.method,
                       "Hot-square series: explicit, implicit or crank-nicolson (cn)")
        ->check(check::accepted_by([](const std::string& name) { parse_scheme(name); }))->capture_default_str();
    return cli.run(argc, argv, [&](const RunContext& run) {
        if (run.quick) {  // a small series unless asked otherwise
            if (n_option->count() == 0)
                settings.n = 32;
            if (steps_option->count() == 0)
                settings.steps = 20;
        }
        pareto_study(run, settings);
        orders_study(run, settings);
        stability_study(run, settings);
        throughput_study(run, settings);
        hot_square_series(run, settings);
        large_step_pictures(run, settings);
    });
}
