// ch07_sparse_storage: sparse storage by hand. The lecture's 4×6 example in COO, CSR and CSC (with
// the slide's JA corrected); the sparsity pattern of a stiffness matrix; the speed of y = A x from
// COO, CSR, CSC and one stored triangle against Eigen on the stiffness matrices K of chapter 06,
// in nonzeros per second and as a fraction of the memory bandwidth measured in the same run; and
// what the conversions cost against Eigen's setFromTriplets.
//
// Sample runs:
//   ch07_sparse_storage                       full run: box meshes of 14, 31 and 54 cubes a side
//   ch07_sparse_storage --quick               the small run ctest checks
//   ch07_sparse_storage --cells 10 20 40 --convert-max-cells 40 --seconds 0.5
//
// Writes: tables lecture_example_table.csv, lecture_product_table.csv, spmv_table.csv,
// conversion_table.csv; charts (PNG + CSV) spmv_rates, conversion_times; the pattern of a small
// K as stiffness_pattern.vti and .png.
// docs/07_sparse_storage.md

#include "05_strain_stress/strain_stress.hpp"
#include "06_assembly/assembly.hpp"
#include "07_sparse_storage/sparse_formats.hpp"
#include "07_sparse_storage/sparse_products.hpp"

#include "common/bandwidth.hpp"
#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/mesh.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"
#include "common/vtk_io.hpp"

#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <map>
#include <sstream>

using namespace fem;
using namespace fem::sparse;

namespace {

struct Settings {
    std::vector<int> cells{14, 31, 54};  // cubes per side of the box meshes (3 (n+1)³ dofs)
    int convert_max_cells = 31;          // the conversions are timed up to this size (memory)
    double seconds = 0.25;               // measuring time per kernel (the best call counts)
};

/// Rubber-like material; SpMV speed does not depend on the values, only on the pattern.
const elastic::Lame material = elastic::lame_parameters(1e5, 0.45);

template <typename T>
std::string joined(const std::vector<T>& values)
{
    std::ostringstream out;
    for (std::size_t k = 0; k < values.size(); ++k)
        out << (k ? " " : "") << values[k];
    return out.str();
}

// 1. The lecture's 4×6 example: triplets given column by column, sorted into CSR by coo_to_csr,
//    transposed into CSC, and multiplied by x = (1, …, 6) in every format.
void lecture_example(const RunContext& run)
{
    Eigen::MatrixXd D(4, 6);
    D << 10, 20, 0, 0, 0, 0,
         0, 30, 0, 40, 0, 0,
         0, 0, 50, 60, 70, 0,
         0, 0, 0, 0, 0, 80;
    CooMatrix coo;
    coo.rows = 4;
    coo.cols = 6;
    for (int j = 0; j < 6; ++j)  // column by column: not the order CSR needs
        for (int i = 0; i < 4; ++i)
            if (D(i, j) != 0.0)
                coo.add(i, j, D(i, j));
    const CsrMatrix csr = coo_to_csr(coo);
    const CscMatrix csc = csr_to_csc(csr);

    Table table("The lecture's 4x6 example, 0-based: COO as given (column by column), CSR and CSC",
                {{"format", Format::text}, {"array", Format::text}, {"lecture slide", Format::text},
                 {"this code", Format::text}});
    table.add_row({std::string("COO"), std::string("row (row index)"), std::string("-"), joined(coo.row)});
    table.add_row({std::string("COO"), std::string("col (column index)"), std::string("-"), joined(coo.col)});
    table.add_row({std::string("COO"), std::string("value"), std::string("-"), joined(coo.value)});
    table.add_row({std::string("CSR"), std::string("A (values)"), std::string("10 20 30 40 50 60 70 80"),
                   joined(csr.A)});
    table.add_row({std::string("CSR"), std::string("IA (row pointer)"), std::string("0 2 4 7 8"), joined(csr.IA)});
    table.add_row({std::string("CSR"), std::string("JA (column index)"), std::string("0 1 3 2 3 4 5"),
                   joined(csr.JA)});
    table.add_row({std::string("CSC"), std::string("A (values)"), std::string("-"), joined(csc.A)});
    table.add_row({std::string("CSC"), std::string("IA (column pointer)"), std::string("-"), joined(csc.IA)});
    table.add_row({std::string("CSC"), std::string("JA (row index)"), std::string("-"), joined(csc.JA)});
    table.print(std::cout);
    table.write_csv(run.file("lecture_example_table.csv"));
    std::cout << "The slide's JA has 7 entries for 8 values: row 1 (30, 40) must list columns 1 and 3.\n\n";

    const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(6, 1.0, 6.0);
    const Eigen::VectorXd dense = D * x;
    Table products("The lecture's example: y = A x for x = (1, 2, 3, 4, 5, 6) in every format",
                   {{"format and loop", Format::text}, {"y", Format::text}, {"equals dense A x", Format::text}});
    const std::pair<std::string, std::function<void(Eigen::VectorXd&)>> kernels[] = {
        {"COO, y[row] += value x[col]", [&](Eigen::VectorXd& y) { coo_times_vector(coo, x, y); }},
        {"CSR, gather (a dot product per row)", [&](Eigen::VectorXd& y) { csr_times_vector(csr, x, y); }},
        {"CSC, scatter (y += x_j column j)", [&](Eigen::VectorXd& y) { csc_times_vector(csc, x, y); }}};
    for (const auto& [name, kernel] : kernels) {
        Eigen::VectorXd y;
        kernel(y);
        products.add_row({name, joined(std::vector<double>(y.data(), y.data() + y.size())),
                          std::string(y == dense ? "yes" : "no")});
    }
    products.print(std::cout);
    products.write_csv(run.file("lecture_product_table.csv"));
}

// 2. The pattern of K on a small box: 3×3 blocks (a vertex couples to its neighbours in all three
//    coordinates), within a band set by the vertex numbering.
void pattern_figure(const RunContext& run)
{
    const int n = 3;
    const TetMesh mesh = box_mesh(n, n, n);
    const CsrMatrix K = csr_from_eigen(assembly::stiffness_matrix(mesh, material));
    io::ImageGrid image;
    image.dims = {K.cols, K.rows, 1};
    Eigen::MatrixXd stored = Eigen::MatrixXd::Zero(Eigen::Index(K.rows) * K.cols, 1);
    for (int i = 0; i < K.rows; ++i)
        for (int k = K.IA[i]; k < K.IA[i + 1]; ++k)  // row i at the top: image y = rows − 1 − i
            stored(K.JA[k] + Eigen::Index(K.cols) * (K.rows - 1 - i), 0) = 1.0;
    image.point_data = {{"stored", stored}};
    io::write_vti(run.file("stiffness_pattern.vti"), image);
    std::cout << "\nthe pattern of K for a box of " << n << "^3 cubes: " << K.rows << " dofs, " << K.nonzeros()
              << " stored entries (" << 100.0 * K.nonzeros() / (double(K.rows) * K.cols)
              << " % of the dense matrix), in stiffness_pattern.vti\n";
    if (run.figures) {
        fig::RenderOptions options;
        options.title = str("Stored entries of K, box of ", n, "x", n, "x", n, " cubes: ", K.rows, " dofs, ",
                            K.nonzeros(), " nonzeros");
        options.field = "stored";
        options.categories = {{0.0, "zero (not stored)", {0.86, 0.86, 0.86}}, {1.0, "stored", {0.13, 0.40, 0.65}}};
        options.width = 760;
        options.height = 760;
        fig::render_grid_png(run.file("stiffness_pattern.png"), image, options);
    }
}

/// A stiffness matrix of the box with `cells` cubes a side, in every storage the study times.
struct Matrices {
    int cells = 0;
    int dofs = 0;
    int nonzeros = 0;
    Eigen::SparseMatrix<double> K;                       // chapter 06, Eigen's CSC
    Eigen::SparseMatrix<double, Eigen::RowMajor> K_row;  // Eigen's CSR
    Eigen::SparseMatrix<double> K_lower;                 // Eigen's CSC of the lower triangle
    CsrMatrix csr;
    CscMatrix csc;
    CooMatrix coo;    // one triplet per stored entry, in row order
    CsrMatrix lower;  // the lower triangle with the diagonal
};

Matrices stiffness_matrices(int cells)
{
    Matrices m;
    m.cells = cells;
    m.K = assembly::stiffness_matrix(box_mesh(cells, cells, cells), material);
    m.dofs = static_cast<int>(m.K.rows());
    m.nonzeros = static_cast<int>(m.K.nonZeros());
    m.K_row = m.K;
    m.K_lower = m.K.triangularView<Eigen::Lower>();
    m.csr = csr_from_eigen(m.K);
    m.csc = csc_from_eigen(m.K);
    m.coo = csr_to_coo(m.csr);
    m.lower = lower_triangle(m.csr);
    return m;
}

// 3. y = A x in every format against Eigen, as nonzeros per second and as a fraction of the triad.
//    Returns the best time of each kernel per size, for the conversion study and the chart.
//    triad_bandwidth() is called after the products: the triad measured in the same run.
std::map<int, std::map<std::string, double>> spmv_study(const RunContext& run, const Settings& settings,
                                                         const std::vector<Matrices>& matrices,
                                                         const std::function<double()>& triad_bandwidth)
{
    const std::vector<Column> columns{
        {"cubes", Format::integer}, {"dofs", Format::integer}, {"nonzeros", Format::integer},
        {"kernel", Format::text}, {"stored entries", Format::integer}, {"bytes per nonzero", Format::fixed, 2},
        {"matches Eigen", Format::text}, {"time [s]", Format::scientific, 3}, {"rate [GNZ/s]", Format::fixed, 3},
        {"bandwidth [GB/s]", Format::fixed, 2}, {"of triad [GB/s per GB/s]", Format::fixed, 2},
        {"vs best Eigen A x [s/s]", Format::fixed, 2}};
    struct Row {
        int cells, dofs;
        double nnz;
        std::string kernel;
        double stored, bytes, seconds;
        bool matches;
    };
    std::vector<Row> rows;
    std::map<int, std::map<std::string, double>> times;
    std::map<std::string, fig::Series> chart_series;
    fig::Series limit{"memory limit of CSR: its bytes at the triad bandwidth", {}, {}};
    for (const Matrices& m : matrices) {
        const int n = m.dofs;
        Eigen::VectorXd x(n);
        for (int i = 0; i < n; ++i)
            x[i] = 1.0 + 0.5 * std::sin(0.1 * i);
        const Eigen::VectorXd reference = m.K * x;
        const double scale = (m.K.cwiseAbs() * x.cwiseAbs()).maxCoeff();
        Eigen::VectorXd y(n);

        const double nnz = m.nonzeros;
        const double compressed = spmv_bytes(nnz, 4, n + 1, n, n);
        const double coo = spmv_bytes(nnz, 8, 0, n, n);
        const double triangle = spmv_bytes(m.lower.nonzeros(), 4, n + 1, n, n);
        struct Kernel {
            std::string name;
            double stored;
            double bytes;
            std::function<void()> apply;
        };
        const std::vector<Kernel> kernels{
            {"CSR A x (gather)", nnz, compressed, [&] { csr_times_vector(m.csr, x, y); }},
            {"CSC x^T A (gather)", nnz, compressed, [&] { vector_times_csc(x, m.csc, y); }},
            {"CSC A x (scatter)", nnz, compressed, [&] { csc_times_vector(m.csc, x, y); }},
            {"CSR x^T A (scatter)", nnz, compressed, [&] { vector_times_csr(x, m.csr, y); }},
            {"COO A x (row order)", nnz, coo, [&] { coo_times_vector(m.coo, x, y); }},
            {"symmetric, lower triangle in CSR", double(m.lower.nonzeros()), triangle,
             [&] { symmetric_times_vector(m.lower, x, y); }},
            {"Eigen CSC A x", nnz, compressed, [&] { y.noalias() = m.K * x; }},
            {"Eigen CSR A x", nnz, compressed, [&] { y.noalias() = m.K_row * x; }},
            {"Eigen symmetric, lower triangle", double(m.K_lower.nonZeros()), triangle,
             [&] { y.noalias() = m.K_lower.selfadjointView<Eigen::Lower>() * x; }}};
        // Round robin: each kernel is timed in `rounds` short turns spread over the whole study, so
        // that every kernel meets the same mix of quiet and busy moments of a shared machine.
        const int rounds = 5;
        std::vector<std::pair<double, bool>> measured(kernels.size(), {1e300, true});
        for (int round = 0; round < rounds; ++round)
            for (std::size_t k = 0; k < kernels.size(); ++k) {
                measured[k].first = std::min(measured[k].first,
                                             best_time(kernels[k].apply, settings.seconds / rounds, 10000));
                measured[k].second = measured[k].second && y.size() == n &&
                                     (y - reference).cwiseAbs().maxCoeff() <= 1e-12 * scale;
            }
        for (std::size_t k = 0; k < kernels.size(); ++k) {
            times[m.cells][kernels[k].name] = measured[k].first;
            rows.push_back({m.cells, n, nnz, kernels[k].name, kernels[k].stored, kernels[k].bytes,
                            measured[k].first, measured[k].second});
            if (kernels[k].name.find("x^T A") == std::string::npos) {
                fig::Series& series = chart_series[kernels[k].name];
                series.name = kernels[k].name;
                series.x.push_back(nnz);
                series.y.push_back(measured[k].first);
            }
        }
    }

    const double triad = triad_bandwidth();
    Table table(str("y = A x on the stiffness matrix K of a box (chapter 06), one thread, best of repeated "
                    "calls; bytes counted like the triad (", triad, " GB/s in this run)"),
                columns);
    for (const Row& r : rows) {
        const double eigen_best = std::min(times[r.cells]["Eigen CSC A x"], times[r.cells]["Eigen CSR A x"]);
        const double bandwidth = r.bytes / r.seconds * 1e-9;
        table.add_row({double(r.cells), double(r.dofs), r.nnz, r.kernel, r.stored, r.bytes / r.nnz,
                       std::string(r.matches ? "yes" : "no"), r.seconds, r.nnz / r.seconds * 1e-9, bandwidth,
                       bandwidth / triad, eigen_best / r.seconds});
        if (r.kernel == "CSR A x (gather)") {
            limit.x.push_back(r.nnz);
            limit.y.push_back(r.bytes / (triad * 1e9));
        }
    }
    table.print(std::cout);
    table.write_csv(run.file("spmv_table.csv"));

    // Time against size, log-log: the lines rise to the right and leave the bottom-right corner to
    // the legend; the rates are in the table.
    fig::LineChart chart{"y = A x on stiffness matrices: wall time of one product (one thread)",
                         "nonzeros of K", "time [s]", true, true, {}};
    for (const char* name : {"CSR A x (gather)", "CSC A x (scatter)", "COO A x (row order)",
                             "symmetric, lower triangle in CSR", "Eigen CSC A x", "Eigen CSR A x",
                             "Eigen symmetric, lower triangle"})
        chart.series.push_back(chart_series[name]);
    chart.series.push_back(limit);
    fig::save_chart(chart, run.out_dir / "spmv_rates", run.figures);
    return times;
}

/// Whether our CSR arrays and Eigen's hold the same matrix: same pattern, values to round-off.
bool same_matrix(const CsrMatrix& ours, const Eigen::SparseMatrix<double>& eigen)
{
    const CsrMatrix theirs = csr_from_eigen(eigen);
    if (ours.rows != theirs.rows || ours.cols != theirs.cols || ours.IA != theirs.IA || ours.JA != theirs.JA)
        return false;
    double largest = 0.0, difference = 0.0;
    for (std::size_t k = 0; k < ours.A.size(); ++k) {
        largest = std::max(largest, std::abs(theirs.A[k]));
        difference = std::max(difference, std::abs(ours.A[k] - theirs.A[k]));
    }
    return difference <= 1e-13 * largest;
}

// 4. The conversions: assembly triplets (with their duplicates) to CSR by counting sort, against
//    Eigen's setFromTriplets; and the transpose CSR → CSC against Eigen's storage-order copy.
void conversion_study(const RunContext& run, const Settings& settings,
                      const std::map<int, std::map<std::string, double>>& spmv_times)
{
    Table table("Conversions on the stiffness triplets of a box (144 per tet, duplicates summed), one thread",
                {{"cubes", Format::integer}, {"dofs", Format::integer}, {"triplets", Format::integer},
                 {"nonzeros", Format::integer}, {"conversion", Format::text}, {"same matrix as Eigen", Format::text},
                 {"equals S K' S^T (ch. 06)", Format::text},
                 {"time [s]", Format::scientific, 3}, {"entries [1/s]", Format::scientific, 3},
                 {"vs Eigen, same format [s/s]", Format::fixed, 2}, {"in CSR SpMVs [s/s]", Format::fixed, 1}});
    std::map<std::string, fig::Series> series;
    for (int cells : settings.cells) {
        if (cells > settings.convert_max_cells)
            continue;
        const TetMesh mesh = box_mesh(cells, cells, cells);
        const assembly::ElementMatrices K_e = assembly::element_stiffnesses(mesh, material);
        const std::vector<Eigen::Triplet<double>> triplets = assembly::element_triplets(mesh, K_e);
        const int dofs = static_cast<int>(3 * mesh.V.rows());
        CooMatrix coo;
        coo.rows = coo.cols = dofs;
        coo.row.reserve(triplets.size());
        coo.col.reserve(triplets.size());
        coo.value.reserve(triplets.size());
        for (const Eigen::Triplet<double>& t : triplets)
            coo.add(t.row(), t.col(), t.value());

        // The longer conversions run once or twice; best_time stops after settings.seconds.
        CsrMatrix csr;
        const double t_coo = best_time([&] { csr = coo_to_csr(coo); }, settings.seconds, 20);
        Eigen::SparseMatrix<double> K(dofs, dofs);
        const double t_eigen = best_time([&] { K.setFromTriplets(triplets.begin(), triplets.end()); },
                                         settings.seconds, 20);
        Eigen::SparseMatrix<double, Eigen::RowMajor> K_row(dofs, dofs);
        const double t_eigen_row = best_time([&] { K_row.setFromTriplets(triplets.begin(), triplets.end()); },
                                             settings.seconds, 20);
        CscMatrix csc;
        const double t_transpose = best_time([&] { csc = csr_to_csc(csr); }, settings.seconds, 20);
        Eigen::SparseMatrix<double, Eigen::RowMajor> K_copy;
        const double t_eigen_transpose = best_time([&] { K_copy = K; }, settings.seconds, 20);

        const double entries = double(triplets.size());
        const double nnz = double(csr.nonzeros());
        const double spmv = spmv_times.at(cells).at("CSR A x (gather)");
        const bool coo_same = same_matrix(csr, K);
        // Summing the duplicates is the sum over elements of the composition route: K = S K' Sᵀ.
        const bool composed_same = same_matrix(csr, assembly::assemble_by_composition(mesh, K_e));
        const bool csc_same = csc.IA == csc_from_eigen(K).IA && csc.JA == csc_from_eigen(K).JA;
        const bool row_same = same_matrix(csr, K_row);
        const bool copy_same = same_matrix(csr, K_copy);
        const auto yes_no = [](bool yes) { return Cell(std::string(yes ? "yes" : "no")); };
        const Cell none = std::string("-");
        const auto row = [&](const std::string& name, bool same, const Cell& composed, double seconds,
                             double inputs, const Cell& vs) {
            table.add_row({double(cells), double(dofs), entries, nnz, name, yes_no(same), composed, seconds,
                           inputs / seconds, vs, seconds / spmv});
            fig::Series& s = series[name];
            s.name = name;
            s.x.push_back(entries);
            s.y.push_back(seconds);
        };
        row("COO -> CSR, coo_to_csr", coo_same, yes_no(composed_same), t_coo, entries, t_eigen_row / t_coo);
        row("Eigen setFromTriplets, CSR", row_same, none, t_eigen_row, entries, none);
        row("Eigen setFromTriplets, CSC", true, none, t_eigen, entries, none);
        row("CSR -> CSC, csr_to_csc", csc_same, none, t_transpose, nnz, t_eigen_transpose / t_transpose);
        row("Eigen CSC -> CSR (storage-order copy)", copy_same, none, t_eigen_transpose, nnz, none);
    }
    table.print(std::cout);
    table.write_csv(run.file("conversion_table.csv"));

    fig::LineChart chart{"Conversions of stiffness triplets: wall time against the number of triplets",
                         "triplets (144 per tet)", "time [s]", true, true, {}};
    for (const auto& [name, s] : series)
        chart.series.push_back(s);
    fig::save_chart(chart, run.out_dir / "conversion_times", run.figures);
}

}  // namespace

int main(int argc, char** argv)
{
    ChapterCli cli("ch07_sparse_storage", "07_sparse_storage",
                   "Chapter 07: COO, CSR and CSC by hand; SpMV and conversions against Eigen");
    Settings settings;
    cli.app.add_option("--cells", settings.cells, "Cubes per side of the box meshes whose K is timed")
        ->check(check::integer(1, 120))->capture_default_str();
    cli.app.add_option("--convert-max-cells", settings.convert_max_cells,
                       "Time the conversions only for boxes up to this many cubes a side (their triplets "
                       "take 2.3 kB per cube)")
        ->check(check::integer(1, 120))->capture_default_str();
    cli.app.add_option("--seconds", settings.seconds, "Measuring time per kernel in seconds")
        ->check(check::real(0.0, 60.0, check::Ends::open_closed))->capture_default_str();
    return cli.run(argc, argv, [&](const RunContext& run) {
        if (run.quick) {
            settings.cells = {3, 6};
            settings.convert_max_cells = 6;
            settings.seconds = 0.02;
        }
        lecture_example(run);
        pattern_figure(run);

        // The triad before the matrices are built; measured again after the products, and the
        // better of the two is what the memory delivered in this run.
        const std::size_t triad_elements = std::size_t{1} << (run.quick ? 22 : 23);
        const double triad_seconds = run.quick ? 0.05 : 0.2;
        const double triad_before = measure_triad_bandwidth(triad_elements, triad_seconds);

        std::vector<Matrices> matrices;
        for (int cells : settings.cells) {
            Timer timer;
            matrices.push_back(stiffness_matrices(cells));
            std::cout << "box of " << cells << "^3 cubes: K has " << matrices.back().dofs << " dofs and "
                      << matrices.back().nonzeros << " nonzeros (assembled and converted in " << timer.seconds()
                      << " s)\n";
        }
        const auto spmv_times = spmv_study(run, settings, matrices, [&] {
            const double triad = std::max(triad_before, measure_triad_bandwidth(triad_elements, triad_seconds));
            std::cout << "\ntriad a = b + s c on 3 x " << triad_elements << " doubles: " << triad
                      << " GB/s (the better of before and after the products)\n";
            return triad;
        });
        matrices.clear();
        conversion_study(run, settings, spmv_times);
    });
}
