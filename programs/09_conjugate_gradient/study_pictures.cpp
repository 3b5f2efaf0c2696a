// ch09_conjugate_gradient: 6. pictures: the CG error on a grid after k iterations, the sagging box.
// docs/09_conjugate_gradient.md
#include "studies.hpp"

#include "02_heat_equation/heat_grid.hpp"
#include "06_assembly/assembly.hpp"
#include "08_direct_solvers/model_problems.hpp"

#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/random.hpp"
#include "common/table.hpp"
#include "common/vtk_io.hpp"

#include <iostream>

namespace fem::cg::study {

/// CG smooths the error: start from the solution plus noise, and look at the error after k steps.
void error_snapshots(const RunContext& run)
{
    heat::Grid grid;
    grid.n = run.quick ? 31 : 63;
    const int n = grid.n;
    const EigenOperator A(sparse::to_eigen(direct::laplacian_2d(n)));
    const Eigen::VectorXd solution = heat::sample(grid, [](double x, double y) { return x * (1 - x) * y * y * (1 - y); });
    Eigen::VectorXd b;
    A.apply(solution, b);
    Eigen::VectorXd start = solution + 0.02 * random_vector(solution.size(), 2);  // CG overwrites it
    const std::vector<int> snapshots{0, 5, 30};
    std::vector<Eigen::VectorXd> errors;
    CgSettings settings;
    settings.max_iterations = snapshots.back();
    settings.observer = [&](int k, const Eigen::VectorXd& x, double) {
        if (std::find(snapshots.begin(), snapshots.end(), k) != snapshots.end())
            errors.push_back(x - solution);
    };
    conjugate_gradient(A, b, start, settings);

    // One grid with a field per snapshot (the interior unknowns; ParaView shows them side by side),
    // and a picture of each, scaled to its largest error.
    io::ImageGrid image;
    image.dims = {n, n, 1};
    image.spacing = {grid.h(), grid.h(), 1.0};
    image.origin = {grid.h(), grid.h(), 0.0};
    Table table("CG error e_k = x_k - x* on the 2D grid: it is smoothed long before it is small",
                {{"iteration k", Format::integer}, {"max |e_k|", Format::scientific, 3},
                 {"max |e_k| / max |e_0|", Format::scientific, 3}});
    for (std::size_t s = 0; s < errors.size(); ++s) {
        const double largest = errors[s].cwiseAbs().maxCoeff();
        table.add_row({double(snapshots[s]), largest, largest / errors[0].cwiseAbs().maxCoeff()});
        image.point_data.push_back({str("error after ", snapshots[s], " iterations"), errors[s]});
    }
    io::write_vti(run.file("cg_error_snapshots.vti"), image);
    table.print(std::cout);
    table.write_csv(run.file("error_snapshot_table.csv"));
    for (std::size_t s = 0; s < errors.size(); ++s) {
        io::ImageGrid scaled = image;
        scaled.point_data = {{"scaled error", errors[s] / errors[s].cwiseAbs().maxCoeff()}};
        fig::RenderOptions options;
        options.title = str("CG error after ", snapshots[s], " iterations, e_k / max |e_k|");
        options.field = "scaled error";
        options.range = std::pair{-1.0, 1.0};
        options.width = 620;
        options.height = 520;
        fig::render_grid_png(run.file(str("cg_error_", snapshots[s], ".png")), scaled, options);
    }
}

/// The box sagging under its weight, solved by the default solver.
void box_picture(const RunContext& run, const Settings& settings)
{
    const int cells = run.quick ? 6 : 14;
    const ElasticBox box = clamped_box(cells, elastic::lame_parameters(settings.youngs, settings.poisson),
                                       settings.density);
    const std::unique_ptr<LinearSolver> solver = make_solver("default");
    solver->prepare(box.K);
    const Eigen::VectorXd u = assembly::expand(box.P, solver->solve(box.f));
    const MatrixX3d displacement = io::vertex_rows(u);
    const io::MeshData data = io::displaced_mesh(box.mesh.V, box.mesh.T, displacement);
    io::write_vtu(run.file("box_displacement.vtu"), data);
    fig::RenderOptions options;
    options.title =
        str("clamped box sagging under its weight (true scale, ", figure_label(solver->name()), "): |u| [m]");
    options.field = "displacement";
    options.unit = "m";
    options.view_direction = {0.5, 1.0, -0.6};
    options.view_up = {0.0, 0.0, 1.0};
    options.height = 560;
    fig::render_mesh_png(run.file("box_displacement.png"), io::warped(data), options);
    std::cout << "\nbox_displacement.vtu: " << box.mesh.T.rows() << " tets, " << box.K.rows()
              << " unknowns solved by " << solver->name() << " in " << solver->stats().prepare_seconds +
                                                                       solver->stats().solve_seconds
              << " s; largest |u| = " << displacement.rowwise().norm().maxCoeff() << " m\n";
}

}  // namespace fem::cg::study
