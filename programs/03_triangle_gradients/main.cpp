// ch03_triangle_gradients: gradients of piecewise-linear functions on triangle meshes, the FEM
// (cotangent) Laplacian, and the Poisson and heat equations on unstructured meshes.
//
// Sample runs:
//   ch03_triangle_gradients                     full run, files in out/03_triangle_gradients
//   ch03_triangle_gradients --quick             the small run ctest checks
//   ch03_triangle_gradients --jitter 0.1 --mesh my_surface.stl --heat-time 5
//
// Writes: tables meshes_table.csv, poisson_table.csv, heat_table.csv; charts (PNG + CSV)
// poisson_convergence, poisson_cost, heat_convergence; poisson_solution.vtu/.png (u and its
// gradient per triangle), surface_heat.pvd (+ frames in surface_heat/) and surface_heat.png.
// docs/03_triangle_gradients.md

#include "01_finite_differences/finite_differences.hpp"
#include "03_triangle_gradients/laplacian.hpp"
#include "03_triangle_gradients/poisson_heat.hpp"
#include "03_triangle_gradients/triangle_gradients.hpp"

#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/files.hpp"
#include "common/mesh.hpp"
#include "common/mesh_io.hpp"
#include "common/mesh_quality.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"
#include "common/vtk_io.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <iostream>
#include <numbers>

using namespace fem;
using namespace fem::tri;
using Eigen::Vector3d;

namespace {

constexpr double pi = std::numbers::pi;

struct Settings {
    double jitter = 0.2;         // random displacement of interior vertices, fraction of the cell size
    unsigned seed = 17;          // of the jitter
    double c = 1.0;              // diffusivity of the heat runs on the square
    double t_end = 0.05;         // final time of the heat runs on the square
    std::string mesh;            // the surface of the heat demo (default: data/bunny.obj)
    double heat_time = 10.0;     // final time of the heat demo on the surface
    TriMesh surface;             // read from `mesh` while the options are checked
};

// The manufactured solution on the unit square: u = sin(πx) sin(πy), −Δu = 2π² u, u = 0 on the boundary.
double sine_mode(const Vector3d& x) { return std::sin(pi * x.x()) * std::sin(pi * x.y()); }
Vector3d sine_mode_gradient(const Vector3d& x)
{
    return pi * Vector3d(std::cos(pi * x.x()) * std::sin(pi * x.y()), std::sin(pi * x.x()) * std::cos(pi * x.y()), 0.0);
}

Dirichlet zero_on_boundary(const TriMesh& mesh)
{
    Dirichlet fixed;
    fixed.vertices = boundary_vertices(mesh.F, static_cast<int>(mesh.V.rows()));
    fixed.values = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(fixed.vertices.size()));
    return fixed;
}

Eigen::VectorXd sample(const TriMesh& mesh, const std::function<double(const Vector3d&)>& u)
{
    Eigen::VectorXd values(mesh.V.rows());
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
        values[v] = u(mesh.V.row(v).transpose());
    return values;
}

std::string surface_name(const Settings& settings)
{
    return settings.mesh.empty() ? "bunny" : std::filesystem::path(settings.mesh).stem().string();
}

// 1. Meshes: shape quality, negative cotangent weights, GᵀAG against the cotangent formula.
void mesh_study(const RunContext& run, const Settings& settings)
{
    Table table("Meshes: shape, cotangent weights, and GᵀAG against the cotangent formula",
                {{"mesh", Format::text}, {"vertices", Format::integer}, {"triangles", Format::integer},
                 {"min angle (deg)", Format::fixed, 2}, {"max angle (deg)", Format::fixed, 2},
                 {"obtuse triangles", Format::integer}, {"negative weights", Format::integer},
                 {"max |GtAG - cot| / max L_ii", Format::scientific, 2},
                 {"max |row sum| / max L_ii", Format::scientific, 2},
                 {"max gradient error", Format::scientific, 2},
                 {"GtAG time [s]", Format::scientific, 2}, {"cotangent time [s]", Format::scientific, 2}});
    const int n = run.quick ? 16 : 64;
    const std::vector<std::pair<std::string, TriMesh>> meshes = {
        {str("square ", n, "x", n), square_mesh(n)},
        {str("square ", n, "x", n, " jittered"), square_mesh(n, settings.jitter, settings.seed)},
        {surface_name(settings), settings.surface}};
    for (const auto& [name, mesh] : meshes) {
        const TriQuality quality = mesh_quality(mesh);
        SparseMatrix L, L_cot;
        const double fem_seconds = best_time([&, &mesh = mesh] { L = fem_laplacian(mesh.V, mesh.F); }, 0.1, 20);
        const double cot_seconds = best_time([&, &mesh = mesh] { L_cot = cotangent_laplacian(mesh.V, mesh.F); }, 0.1, 20);
        const double scale = L.diagonal().cwiseAbs().maxCoeff();
        const double difference = SparseMatrix(L - L_cot).coeffs().cwiseAbs().maxCoeff() / scale;
        const double row_sums = (L * Eigen::VectorXd::Ones(L.cols())).cwiseAbs().maxCoeff() / scale;
        // The gradient of a linear function is exact: its tangential part on every triangle.
        const Vector3d g(0.3, -1.2, 0.7);
        const MatrixX3d gradients = face_gradients(mesh.V, mesh.F, mesh.V * g);
        double gradient_error = 0.0;
        for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
            const Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
            const Vector3d normal = (b - a).cross(c - a).normalized();
            gradient_error = std::max(gradient_error,
                                      (gradients.row(f).transpose() - (g - g.dot(normal) * normal)).norm() / g.norm());
        }
        table.add_row({name, double(mesh.V.rows()), double(mesh.F.rows()), quality.min_angle_deg,
                       quality.max_angle_deg, double(quality.obtuse_triangles), double(negative_weight_edges(L)),
                       difference, row_sums, gradient_error, fem_seconds, cot_seconds});
    }
    table.print(std::cout);
    table.write_csv(run.file("meshes_table.csv"));
}

/// One manufactured Poisson solve: errors, timings, and the solution (for the VTK output).
struct PoissonRun {
    ErrorNorms error;
    double assembly_seconds = 0.0;
    double solve_seconds = 0.0;
    TriMesh mesh;
    Eigen::VectorXd u;
};

PoissonRun poisson_run(int n, double jitter, unsigned seed)
{
    PoissonRun result;
    result.mesh = square_mesh(n, jitter, seed);
    const TriMesh& mesh = result.mesh;
    SparseMatrix L;
    Eigen::VectorXd mass;
    result.assembly_seconds = best_time([&] {
        L = fem_laplacian(mesh.V, mesh.F);
        mass = lumped_mass(mesh.V, mesh.F);
    }, 0.1, 10);
    const Eigen::VectorXd f = 2 * pi * pi * sample(mesh, sine_mode);
    const Dirichlet fixed = zero_on_boundary(mesh);
    result.solve_seconds = best_time([&] { result.u = solve_poisson(L, mass, f, fixed); }, 0.1, 10);
    result.error = error_norms(mesh.V, mesh.F, result.u, sine_mode, sine_mode_gradient);
    return result;
}

void write_poisson_solution(const RunContext& run, const PoissonRun& result)
{
    const TriMesh& mesh = result.mesh;
    const Eigen::VectorXd exact = sample(mesh, sine_mode);
    const MatrixX3d gradients = face_gradients(mesh.V, mesh.F, result.u);
    Eigen::MatrixXd exact_gradients(mesh.F.rows(), 3), gradient_error(mesh.F.rows(), 1);
    for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
        const Vector3d centroid = (mesh.V.row(mesh.F(f, 0)) + mesh.V.row(mesh.F(f, 1)) + mesh.V.row(mesh.F(f, 2))) / 3.0;
        exact_gradients.row(f) = sine_mode_gradient(centroid).transpose();
        gradient_error(f, 0) = (gradients.row(f) - exact_gradients.row(f)).norm();
    }
    io::MeshData data;
    data.points = mesh.V;
    data.cells = mesh.F;
    data.point_data = {{"u", result.u}, {"u exact", exact}, {"error", result.u - exact}};
    data.cell_data = {{"gradient", gradients}, {"exact gradient", exact_gradients},
                      {"gradient error", gradient_error}};
    io::write_vtu(run.file("poisson_solution.vtu"), data);
    fig::RenderOptions options;
    options.title = str("Poisson on a jittered mesh: u_h, ", mesh.F.rows(), " triangles");
    options.field = "u";
    if (run.figures) {
        fig::render_mesh_png(run.file("poisson_solution.png"), data, options);
        options.title = "Gradient error |grad u_h - grad u| at the centroids (constant per triangle)";
        options.field = "gradient error";
        fig::render_mesh_png(run.file("poisson_gradient_error.png"), data, options);
    }
}

// 2. Manufactured Poisson: error against h and wall time, regular and jittered meshes.
void poisson_study(const RunContext& run, const Settings& settings)
{
    const std::vector<int> sizes = run.quick ? std::vector<int>{8, 16, 32, 64}
                                             : std::vector<int>{8, 16, 32, 64, 128, 256};
    Table table("Poisson -Δu = 2π² sin(πx) sin(πy) on the unit square, u = 0 on the boundary: L u = M f",
                {{"mesh", Format::text}, {"n", Format::integer}, {"h", Format::scientific, 3},
                 {"vertices", Format::integer}, {"L2 error", Format::scientific, 3}, {"L2 order", Format::fixed, 2},
                 {"gradient error", Format::scientific, 3}, {"gradient order", Format::fixed, 2},
                 {"assembly time [s]", Format::scientific, 2}, {"solve time [s]", Format::scientific, 2}});
    fig::LineChart convergence{"Poisson on the unit square: error against h", "h", "L2 norm of the error",
                               true, true, {}};
    fig::LineChart cost{"Poisson on the unit square: L2 error against wall time (assembly + solve)",
                        "wall time [s]", "L2 error", true, true, {}};
    for (const double jitter : {0.0, settings.jitter}) {
        const std::string name = jitter == 0.0 ? "regular" : str("jittered ", jitter);
        std::vector<double> h, l2, gradient, seconds;
        for (int n : sizes) {
            const PoissonRun result = poisson_run(n, jitter, settings.seed);
            h.push_back(1.0 / n);
            l2.push_back(result.error.l2);
            gradient.push_back(result.error.gradient_l2);
            seconds.push_back(result.assembly_seconds + result.solve_seconds);
            const bool first = h.size() < 2;
            table.add_row({name, double(n), h.back(), double(result.mesh.V.rows()), l2.back(),
                           first ? Cell(std::string("-")) : Cell(fd::observed_orders(h, l2).back()), gradient.back(),
                           first ? Cell(std::string("-")) : Cell(fd::observed_orders(h, gradient).back()),
                           result.assembly_seconds, result.solve_seconds});
            if (jitter > 0.0 && n == (run.quick ? 16 : 32))
                write_poisson_solution(run, result);
        }
        std::cout << name << ": fitted orders " << fd::fitted_order(h, l2) << " (L2), "
                  << fd::fitted_order(h, gradient) << " (gradient)\n";
        convergence.series.push_back({name + ": u", h, l2});
        convergence.series.push_back({name + ": gradient", h, gradient});
        cost.series.push_back({name, seconds, l2});
    }
    table.print(std::cout);
    table.write_csv(run.file("poisson_table.csv"));
    fig::save_chart(convergence, run.out_dir / "poisson_convergence", run.figures);
    fig::save_chart(cost, run.out_dir / "poisson_cost", run.figures);
}

// 3. Heat on the square: implicit Euler with Δt = h² against the exact decay of the sine mode.
void heat_study(const RunContext& run, const Settings& settings)
{
    const std::vector<int> sizes = run.quick ? std::vector<int>{8, 16, 32} : std::vector<int>{8, 16, 32, 64, 128};
    const double decay = std::exp(-2 * pi * pi * settings.c * settings.t_end);
    Table table(str("Heat u_t = c Δu, c = ", settings.c, ", from sin(πx) sin(πy), implicit Euler with dt = h^2, ",
                    "jittered meshes: L2 error at t = ", settings.t_end),
                {{"n", Format::integer}, {"h", Format::scientific, 3}, {"dt", Format::scientific, 3},
                 {"steps", Format::integer}, {"L2 error", Format::scientific, 3}, {"order", Format::fixed, 2},
                 {"factor time [s]", Format::scientific, 2}, {"steps time [s]", Format::scientific, 2}});
    std::vector<double> h, error;
    for (int n : sizes) {
        const TriMesh mesh = square_mesh(n, settings.jitter, settings.seed);
        const int steps = static_cast<int>(std::ceil(settings.t_end * n * n));
        const double dt = settings.t_end / steps;
        const SparseMatrix L = fem_laplacian(mesh.V, mesh.F);
        const Eigen::VectorXd mass = lumped_mass(mesh.V, mesh.F);
        Timer factor_timer;
        const ImplicitHeat heat(L, mass, settings.c, dt, zero_on_boundary(mesh).vertices);
        const double factor_seconds = factor_timer.seconds();
        Eigen::VectorXd u = sample(mesh, sine_mode);
        Timer step_timer;
        for (int s = 0; s < steps; ++s)
            heat.step(u);
        const double step_seconds = step_timer.seconds();
        h.push_back(1.0 / n);
        error.push_back(error_norms(mesh.V, mesh.F, u, [&](const Vector3d& x) { return decay * sine_mode(x); },
                                    [&](const Vector3d& x) { return Vector3d(decay * sine_mode_gradient(x)); })
                            .l2);
        table.add_row({double(n), h.back(), dt, double(steps), error.back(),
                       h.size() < 2 ? Cell(std::string("-")) : Cell(fd::observed_orders(h, error).back()),
                       factor_seconds, step_seconds});
    }
    table.print(std::cout);
    table.write_csv(run.file("heat_table.csv"));
    fig::LineChart chart{"Heat on jittered meshes, implicit Euler with dt = h^2: L2 error at t_end", "h",
                         "L2 error", true, true, {{"implicit Euler", h, error}}};
    fig::save_chart(chart, run.out_dir / "heat_convergence", run.figures);
}

// 4. Heat on a closed surface (no boundary: nothing is fixed, heat is conserved), as a time series.
void surface_heat(const RunContext& run, const Settings& settings)
{
    const TriMesh& mesh = settings.surface;
    const SparseMatrix L = fem_laplacian(mesh.V, mesh.F);
    const Eigen::VectorXd mass = lumped_mass(mesh.V, mesh.F);
    const std::vector<int> boundary = boundary_vertices(mesh.F, static_cast<int>(mesh.V.rows()));
    // Hot: the vertices within 10% of the mesh size from its highest vertex (largest y).
    Eigen::Index top = 0;
    mesh.V.col(1).maxCoeff(&top);
    const double size = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm();
    Eigen::VectorXd u(mesh.V.rows());
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
        u[v] = (mesh.V.row(v) - mesh.V.row(top)).norm() < 0.1 * size ? 1.0 : 0.0;
    const int steps = run.quick ? 10 : 100, frames = run.quick ? 2 : 10;
    const double dt = settings.heat_time / steps;
    const ImplicitHeat heat(L, mass, settings.c, dt, boundary);  // an open surface keeps its rim at u0
    const double heat_before = mass.dot(u);

    io::MeshData data;
    data.points = mesh.V;
    data.cells = mesh.F;
    io::PvdSeries series(run.file("surface_heat.pvd"));
    const auto record = [&](double time) {
        data.point_data = {{"u", u}};
        data.cell_data = {{"gradient", face_gradients(mesh.V, mesh.F, u)}};
        series.add(time, data);
    };
    record(0.0);
    for (int s = 1; s <= steps; ++s) {
        heat.step(u);
        if (s % (steps / frames) == 0)
            record(s * dt);
    }
    std::cout << "\nheat on " << surface_name(settings) << " (" << mesh.V.rows() << " vertices, "
              << boundary.size() << " on a boundary): " << steps << " implicit steps of dt = " << dt
              << ", total heat sum(m u) " << heat_before << " -> " << mass.dot(u) << ", u in [" << u.minCoeff()
              << ", " << u.maxCoeff() << "]; " << series.frames() << " frames in surface_heat.pvd\n";
    fig::RenderOptions options;
    options.title = str("Heat on the ", surface_name(settings), " at t = ", settings.heat_time,
                        " (implicit Euler, cotangent Laplacian)");
    options.field = "u";
    if (run.figures)
        fig::render_mesh_png(run.file("surface_heat.png"), data, options);
}

}  // namespace

int main(int argc, char** argv)
{
    ChapterCli cli("ch03_triangle_gradients", "03_triangle_gradients",
                   "Chapter 03: gradients on triangle meshes, the cotangent Laplacian, Poisson and heat");
    Settings settings;
    cli.app.add_option("--jitter", settings.jitter, "Jitter of the unstructured meshes, a fraction of a cell "
                       "(the regular mesh is always run beside the jittered one)")
        ->check(check::real(0.0, 0.24, check::Ends::open_closed))->capture_default_str();
    cli.app.add_option("--seed", settings.seed, "Random seed of the jitter")->check(check::at_least(0u))
        ->capture_default_str();
    cli.app.add_option("--c", settings.c, "Diffusivity of the heat runs")
        ->check(check::real(0.0, 100.0, check::Ends::open_closed))->capture_default_str();
    cli.app.add_option("--t-end", settings.t_end, "Final time of the heat runs on the square")
        ->check(check::real(0.0, 10.0, check::Ends::open_closed))->capture_default_str();
    cli.app.add_option("--mesh", settings.mesh, "Surface of the heat demo: .obj, .stl, .ply or .vtu (default: the bunny)");
    cli.app.add_option("--heat-time", settings.heat_time, "Final time of the heat demo on the surface")
        ->check(check::positive())->capture_default_str();
    cli.check_options([&] {  // the surface is read (and checked) once, before any study runs
        const std::filesystem::path surface = settings.mesh.empty() ? data_path("bunny.obj")
                                                                    : std::filesystem::path(settings.mesh);
        try {
            settings.surface = io::read_tri_mesh(surface);
        } catch (const Error& e) {
            throw Error(str("--mesh: ", e.what()));
        }
        // The demo keeps an open surface's rim at its start value: a surface that is all rim (loose
        // triangles) would leave nothing to heat.
        const auto vertices = static_cast<int>(settings.surface.V.rows());
        if (boundary_vertices(settings.surface.F, vertices).size() == static_cast<std::size_t>(vertices))
            throw Error(str("--mesh: ", surface.string(), ": every one of its ", vertices,
                            " vertices lies on its boundary, which the heat demo holds fixed: nothing is left ",
                            "to heat; give a surface with interior vertices (a closed one has no boundary)"));
    });
    return cli.run(argc, argv, [&](const RunContext& run) {
        mesh_study(run, settings);
        poisson_study(run, settings);
        heat_study(run, settings);
        surface_heat(run, settings);
    });
}
