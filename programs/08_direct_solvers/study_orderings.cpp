// ch08_direct_solvers: 3. fill-reducing orderings (nnz(L) and flops) and the patterns of L.
// docs/08_direct_solvers.md
#include "studies.hpp"

#include "08_direct_solvers/orderings.hpp"

#include "common/figures.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <iostream>
#include <map>

namespace fem::direct::study {

void ordering_study(const RunContext& run, const Settings& settings)
{
    Table table("Fill-reducing orderings: nnz(L) and flops of the factor (symbolic factorization only)",
                {{"matrix", Format::text}, {"grid", Format::text}, {"unknowns", Format::integer},
                 {"ordering", Format::text}, {"nnz(L)", Format::scientific, 3}, {"nnz(L) / nnz(tril A)", Format::fixed, 2},
                 {"flops", Format::scientific, 2}, {"ordering time [s]", Format::scientific, 2}});
    const Ordering orderings[] = {Ordering::natural, Ordering::reverse_cuthill_mckee, Ordering::minimum_degree,
                                  Ordering::eigen_amd, Ordering::nested_dissection};
    std::map<std::string, std::vector<double>> fill_x, fill_y;
    for (const char* family : families)
        for (int size : family_sizes(family, run.quick)) {
            if (family_unknowns(family, size) > settings.max_unknowns)
                continue;
            const Problem p = make_problem(family, size);
            const double tril = static_cast<double>(lower_nonzeros(p.A));
            for (Ordering o : orderings) {
                Timer timer;
                const Permutation perm = fill_reducing_ordering(p.A, o);
                const double seconds = timer.seconds();
                const SymbolicCholesky S = symbolic_cholesky(p.A, perm);
                table.add_row({p.family, size_text(p), double(p.A.rows), ordering_name(o), double(S.nonzeros),
                               S.nonzeros / tril, S.flops, seconds});
                if (p.family == std::string("3D elasticity")) {
                    fill_x[ordering_name(o)].push_back(p.A.rows);
                    fill_y[ordering_name(o)].push_back(double(S.nonzeros));
                }
            }
#ifdef FEM_HAVE_CHOLMOD
            const CholmodResult c = run_cholmod(p.E, Eigen::VectorXd::Zero(p.A.rows), false, true);
            table.add_row({p.family, size_text(p), double(p.A.rows), c.ordering, c.nonzeros, c.nonzeros / tril, c.flops,
                           c.analyse});
#else
            const Cell none = std::string("-");
            table.add_row({p.family, size_text(p), double(p.A.rows), std::string("CHOLMOD not installed"), none, none,
                           none, none});
#endif
        }
    table.print(std::cout);
    table.write_csv(run.file("ordering_table.csv"));
    fig::LineChart chart{"3D elasticity (box, one face pinned): nnz(L) against unknowns", "unknowns", "nnz(L)", true,
                         true, {}};
    for (const auto& [name, x] : fill_x)
        chart.series.push_back({name, x, fill_y[name]});
    chart.legend = fig::Corner::top_left;
    fig::save_chart(chart, run.out_dir / "fill_growth", run.figures);
}

/// The patterns of L (entries of A and fill) of a small 2D Laplacian in four orderings, 2×2 panels.
void pattern_figure(const RunContext& run)
{
    const int grid = 12, n = grid * grid, gap = 6, side = 2 * n + gap;
    const sparse::CscMatrix A = laplacian_2d(grid);
    const Ordering shown[] = {Ordering::natural, Ordering::reverse_cuthill_mckee, Ordering::minimum_degree,
                              Ordering::nested_dissection};
    io::ImageGrid image;
    image.dims = {side, side, 1};
    Eigen::MatrixXd value = Eigen::MatrixXd::Constant(Eigen::Index(side) * side, 1, 0.5);  // the gaps
    std::string title = str("L of a ", grid, "x", grid, " grid Laplacian and nnz(L) in each ordering\n");
    for (int panel = 0; panel < 4; ++panel) {
        const SparseCholesky chol(A, {shown[panel], Factorization::up_looking});
        const sparse::CscMatrix L = chol.factor();
        const sparse::CscMatrix C = symmetric_permutation(A, chol.permutation());  // upper triangle
        Eigen::MatrixXd cells = Eigen::MatrixXd::Zero(n, n);
        for (int j = 0; j < n; ++j)
            for (int k = L.IA[j]; k < L.IA[j + 1]; ++k)
                cells(L.JA[k], j) = 2.0;
        for (int j = 0; j < n; ++j)
            for (int k = C.IA[j]; k < C.IA[j + 1]; ++k)
                cells(j, C.JA[k]) = 1.0;  // C(i, j), i ≤ j, sits at L's position (j, i)
        // panels: natural top left, RCM top right, minimum degree bottom left, nested dissection bottom right
        const int x0 = (panel % 2) * (n + gap), y0 = (panel / 2) * (n + gap);
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j)  // row i at the top of its panel
                value(x0 + j + Eigen::Index(side) * (side - 1 - (y0 + i)), 0) = cells(i, j);
        const char* const short_names[] = {"natural", "RCM", "minimum degree", "nested dissection"};
        const char* const prefixes[] = {"top: ", ", ", "; bottom: ", ", "};
        title += str(prefixes[panel], short_names[panel], " ", L.nonzeros());
    }
    image.point_data = {{"entry", value}};
    io::write_vti(run.file("factor_patterns.vti"), image);
    if (run.figures) {
        fig::RenderOptions options;
        options.title = title;
        options.field = "entry";
        options.categories = {{0.0, "zero", {0.86, 0.86, 0.86}},
                              {1.0, "entry of A", {0.13, 0.40, 0.65}},
                              {2.0, "fill", {0.99, 0.62, 0.10}}};  // the gaps (0.5) are no category: white
        options.width = 1000;
        options.height = 960;
        fig::render_grid_png(run.file("factor_patterns.png"), image, options);
    }
}

}  // namespace fem::direct::study
