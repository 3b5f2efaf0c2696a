// ch01_finite_differences: derivative stencils against h (the truncation/round-off V), and the 1D
// heat equation with FTCS: convergence, cost, and the stability limit.
//
// Sample runs:
//   ch01_finite_differences                  full run, files in out/01_finite_differences
//   ch01_finite_differences --quick          the small run ctest checks
//   ch01_finite_differences --c 0.5 --points 201 --ratio 0.99
//
// Writes: tables derivative_table.csv, stencil_cost_table.csv, heat_convergence_table.csv,
// heat_stability_table.csv;
// charts (PNG + CSV) derivative_errors, heat_convergence, heat_cost, heat_profiles;
// the time series heat_rod.pvd (+ frames in heat_rod/).
// docs/01_finite_differences.md

#include "01_finite_differences/finite_differences.hpp"
#include "01_finite_differences/heat_rod.hpp"

#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"
#include "common/vtk_io.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>

using namespace fem;
using namespace fem::fd;

namespace {

struct Settings {
    double c = 1.0;         // diffusivity of the rod
    int points = 101;       // grid points of the time series
    double ratio = 0.9;     // Δt as a fraction of the stability limit in the time series
    double t_end = 0.05;    // final time of the convergence study and the time series
};

constexpr double max_steps = 1e8;  // of the time series: beyond it the run takes hours

// 1. Stencils: error against h for f = sin at x = 1.
void derivative_study(const RunContext& run)
{
    const ScalarFunction f = [](double x) { return std::sin(x); };
    const double x = 1.0;
    struct Stencil {
        const char* name;
        double (*apply)(const ScalarFunction&, double, double);
        double exact;           // the derivative it approximates, at x
        int evaluations;        // samples of f per call
    };
    const Stencil stencils[4] = {{"forward", forward_difference, std::cos(x), 2},
                                 {"backward", backward_difference, std::cos(x), 2},
                                 {"central", central_difference, std::cos(x), 2},
                                 {"second central", central_second_difference, -std::sin(x), 3}};

    std::vector<double> h;
    std::vector<double> error[4];
    for (int k = 1; k <= 15; ++k) {
        h.push_back(std::pow(10.0, -k));
        for (int s = 0; s < 4; ++s)
            error[s].push_back(std::abs(stencils[s].apply(f, x, h.back()) - stencils[s].exact));
    }

    std::vector<Column> columns{{"h", Format::scientific, 0}};
    for (const Stencil& stencil : stencils) {
        columns.push_back({std::string(stencil.name) + " error", Format::scientific, 2});
        columns.push_back({std::string(stencil.name) + " order", Format::fixed, 2});
    }
    Table table("Derivatives of sin at x = 1: absolute error and observed order against h", columns);
    std::vector<double> orders[4];
    for (int s = 0; s < 4; ++s)
        orders[s] = observed_orders(h, error[s]);
    for (std::size_t i = 0; i < h.size(); ++i) {
        std::vector<Cell> row{h[i]};
        for (int s = 0; s < 4; ++s) {
            row.emplace_back(error[s][i]);
            row.emplace_back(i == 0 ? Cell(std::string("-")) : Cell(orders[s][i - 1]));
        }
        table.add_row(row);
    }
    table.print(std::cout);
    table.write_csv(run.file("derivative_table.csv"));

    // Speed against error: what each stencil costs per call, and the best accuracy it reaches.
    Table cost("Cost and best accuracy of each stencil (sin at x = 1)",
               {{"stencil", Format::text}, {"f evaluations", Format::integer},
                {"time per call [ns]", Format::fixed, 1}, {"best h", Format::scientific, 0},
                {"best error", Format::scientific, 2}});
    for (int s = 0; s < 4; ++s) {
        const int calls = 100000;
        volatile double sink = 0.0;
        const double seconds = best_time([&] {
            for (int c = 0; c < calls; ++c)
                sink = sink + stencils[s].apply(f, x + 1e-9 * c, 1e-4);
        });
        const auto best = std::min_element(error[s].begin(), error[s].end()) - error[s].begin();
        cost.add_row({std::string(stencils[s].name), double(stencils[s].evaluations),
                      1e9 * seconds / calls, h[best], error[s][best]});
    }
    cost.print(std::cout);
    cost.write_csv(run.file("stencil_cost_table.csv"));

    fig::LineChart chart{"Finite differences of sin at x = 1: truncation meets round-off",
                         "step h", "absolute error", true, true, {}};
    for (int s = 0; s < 4; ++s)
        chart.series.push_back({stencils[s].name, h, error[s]});
    fig::save_chart(chart, run.out_dir / "derivative_errors", run.figures);
}

/// Max-norm error against the exact sine-mode solution at t_end, and the wall time of the run.
struct HeatResult {
    double error = 0.0;
    int steps = 0;
    double seconds = 0.0;
};

HeatResult sine_mode_run(const HeatRod& rod, double ratio, double t_end)
{
    const double dt_limit = explicit_stability_limit(rod.h(), rod.c);
    HeatResult result;
    result.steps = static_cast<int>(std::ceil(t_end / (ratio * dt_limit)));
    const double dt = t_end / result.steps;
    const Eigen::VectorXd u0 = sine_mode(rod, 1);
    HeatRun heat;
    result.seconds = best_time([&] { heat = simulate_heat_rod(rod, u0, dt, result.steps); }, 0.1, 5);
    if (heat.blew_up)
        throw Error(str("the convergence run with ", rod.points, " points blew up at step ",
                        heat.blow_up_step, "; Δt must stay below the stability limit"));
    for (int i = 0; i < rod.points; ++i)
        result.error = std::max(result.error,
                                std::abs(heat.u[i] - sine_mode_solution(rod, 1, rod.x(i), heat.time)));
    return result;
}

// 2. FTCS convergence and cost: Δt = 0.9 × limit ∝ h², so the error falls like h².
void heat_convergence_study(const RunContext& run, const Settings& settings)
{
    const std::vector<int> sizes = run.quick ? std::vector<int>{11, 21, 41, 81}
                                             : std::vector<int>{11, 21, 41, 81, 161, 321, 641};
    Table table(str("1D heat, FTCS from sin(pi x), c = ", settings.c, ", dt = 0.9 x limit, t = ",
                    settings.t_end, ": max-norm error against the exact solution"),
                {{"points", Format::integer}, {"h", Format::scientific, 3},
                 {"steps", Format::integer}, {"error", Format::scientific, 3},
                 {"order", Format::fixed, 2}, {"time [s]", Format::scientific, 2},
                 {"updates [1/s]", Format::scientific, 2}});
    std::vector<double> h, error, seconds;
    for (int points : sizes) {
        HeatRod rod;
        rod.points = points;
        rod.c = settings.c;
        const HeatResult result = sine_mode_run(rod, 0.9, settings.t_end);
        h.push_back(rod.h());
        error.push_back(result.error);
        seconds.push_back(result.seconds);
        const Cell order = h.size() < 2 ? Cell(std::string("-"))
                                        : Cell(observed_orders(h, error).back());
        table.add_row({double(points), rod.h(), double(result.steps), result.error, order,
                       result.seconds, double(result.steps) * (points - 2) / result.seconds});
    }
    table.print(std::cout);
    std::cout << "fitted order in h: " << fitted_order(h, error) << '\n';
    table.write_csv(run.file("heat_convergence_table.csv"));

    fig::LineChart convergence{"1D heat with FTCS: error against h (dt = 0.9 h^2/(2c))", "h",
                               "max-norm error at t_end", true, true, {{"FTCS", h, error}}};
    fig::save_chart(convergence, run.out_dir / "heat_convergence", run.figures);
    fig::LineChart cost{"1D heat with FTCS: error against wall time", "wall time [s]",
                        "max-norm error at t_end", true, true, {{"FTCS", seconds, error}}};
    fig::save_chart(cost, run.out_dir / "heat_cost", run.figures);
}

// 3. The stability limit, seen from both sides, on a hot middle third (all modes present).
void stability_study(const RunContext& run, const Settings& settings)
{
    HeatRod rod;
    rod.points = 51;
    rod.c = settings.c;
    const double limit = explicit_stability_limit(rod.h(), rod.c);
    const double t_end = 0.1;
    Table table(str("FTCS stability, 51 points, hot middle third, t = ", t_end, ", limit dt = h^2/(2c) = ",
                    limit),
                {{"dt / limit", Format::fixed, 2}, {"steps asked", Format::integer},
                 {"outcome", Format::text}, {"blow-up step", Format::text},
                 {"max |u| at the end", Format::fixed, 4}});
    for (double ratio : {0.5, 0.9, 0.99, 1.01, 1.1, 2.0}) {
        const double dt = ratio * limit;
        const int steps = static_cast<int>(std::ceil(t_end / dt));
        const HeatRun heat = simulate_heat_rod(rod, hot_middle(rod), dt, steps);
        table.add_row({ratio, double(steps), std::string(heat.blew_up ? "blew up" : "stable"),
                       heat.blew_up ? Cell(std::to_string(heat.blow_up_step)) : Cell(std::string("-")),
                       heat.u.cwiseAbs().maxCoeff()});
    }
    table.print(std::cout);
    table.write_csv(run.file("heat_stability_table.csv"));
}

// 4. A time series for ParaView: the hot middle third diffusing out through the cold ends.
void heat_time_series(const RunContext& run, const Settings& settings)
{
    HeatRod rod;
    rod.points = run.quick ? 21 : settings.points;
    rod.c = settings.c;
    const int steps = static_cast<int>(
        std::ceil(settings.t_end / (settings.ratio * explicit_stability_limit(rod.h(), rod.c))));
    const double dt = settings.t_end / steps;  // at most ratio × the limit, and lands on t_end
    const int frames = run.quick ? 5 : 50;

    io::MeshData mesh;
    mesh.points = MatrixX3d::Zero(rod.points, 3);
    mesh.cells.resize(rod.points - 1, 2);
    for (int i = 0; i < rod.points; ++i)
        mesh.points(i, 0) = rod.x(i);
    for (int i = 0; i + 1 < rod.points; ++i)
        mesh.cells.row(i) << i, i + 1;

    io::PvdSeries series(run.file("heat_rod.pvd"));
    fig::LineChart profiles{"1D heat: the hot middle third diffusing (FTCS)", "x", "u", false, false, {}};
    std::vector<double> x(rod.points);
    for (int i = 0; i < rod.points; ++i)
        x[i] = rod.x(i);
    int profile_count = 0;
    const auto observe = [&](int step, double time, const Eigen::VectorXd& u) {
        mesh.point_data = {{"u", u}};
        series.add(time, mesh);
        if (step == 0 || step == steps || (profile_count < 4 && step >= steps * profile_count / 4)) {
            profiles.series.push_back({str("t = ", std::round(time * 1e5) / 1e5), x,
                                       std::vector<double>(u.data(), u.data() + u.size())});
            ++profile_count;
        }
    };
    const HeatRun heat = simulate_heat_rod(rod, hot_middle(rod), dt, steps, observe,
                                           std::max(1, steps / frames));
    if (heat.blew_up)
        std::cout << "the time series blew up at step " << heat.blow_up_step
                  << ": dt / limit = " << settings.ratio << " > 1; frames stop at the last valid state\n";
    fig::save_chart(profiles, run.out_dir / "heat_profiles", run.figures);
    std::cout << "\ntime series: " << series.frames() << " frames of " << rod.points
              << " points in heat_rod.pvd (open it in ParaView)\n";
}

}  // namespace

int main(int argc, char** argv)
{
    ChapterCli cli("ch01_finite_differences", "01_finite_differences",
                   "Chapter 01: finite difference stencils and the 1D heat equation (FTCS)");
    Settings settings;
    cli.app.add_option("--c", settings.c, "Diffusivity c of the rod")->check(check::positive())->capture_default_str();
    cli.app.add_option("--points", settings.points, "Grid points of the time series")
        ->check(check::integer(3, 100000))->capture_default_str();
    cli.app.add_option("--ratio", settings.ratio,
                       "Time step of the time series as a fraction of the stability limit")
        ->check(check::positive())->capture_default_str();
    cli.app.add_option("--t-end", settings.t_end, "Final time")->check(check::positive())->capture_default_str();
    cli.check_options([&] {
        // The longest runs: the time series, the finest grid of the convergence study (641 points at
        // 0.9 × the limit) and the slowest of the stability study (51 points, 0.5 × the limit, t = 0.1).
        const auto steps = [&](int points, double ratio, double t_end) {
            HeatRod rod;
            rod.points = points;
            rod.c = settings.c;
            return t_end / (ratio * explicit_stability_limit(rod.h(), rod.c));
        };
        const double most = std::max({steps(settings.points, settings.ratio, settings.t_end),
                                      steps(641, 0.9, settings.t_end), steps(51, 0.5, 0.1)});
        if (!(most <= max_steps))
            throw Error(str("--c ", settings.c, ", --t-end ", settings.t_end, ", --ratio ", settings.ratio,
                            " and --points ", settings.points, " ask for ", most, " time steps in one run; at most ",
                            max_steps, " are allowed (a smaller --c or --t-end, or a larger --ratio, take fewer)"));
    });
    return cli.run(argc, argv, [&](const RunContext& run) {
        derivative_study(run);
        heat_convergence_study(run, settings);
        stability_study(run, settings);
        heat_time_series(run, settings);
    });
}
