// ch06_assembly: the global stiffness K built three ways (composition S K' Sᵀ, COO triplets through
// Eigen's setFromTriplets, scatter into a precomputed CSR pattern), checked against each other, timed
// from 1k to over 500k tets with the time split into phases; the masses, damping and gravity of a
// clamped beam, its static sag against beam theory, and the files to look at it.
//
// Sample runs:
//   ch06_assembly                      full run (about a minute), files in out/06_assembly
//   ch06_assembly --quick              the small run ctest checks
//   ch06_assembly --largest 200000     stop the throughput study at about 200k tets
//   ch06_assembly --youngs 1e6 --density 1100 --cells 40
//
// Writes: tables checks_table.csv, throughput_table.csv, phases_table.csv, beam_table.csv;
// chart (PNG + CSV) assembly_rate; the beam beam.vtu (masses, gravity forces, displacement),
// beam_masses.png and beam_sag.png.
// docs/06_assembly.md

#include "06_assembly/assembly.hpp"

#include "05_strain_stress/strain_stress.hpp"
#include "common/bandwidth.hpp"
#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/memory.hpp"
#include "common/mesh.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"
#include "common/vtk_io.hpp"

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <optional>
#include <string>

using namespace fem;
using namespace fem::assembly;

namespace {

struct Settings {
    double youngs = 1e7;      // Y [Pa] of the beam and the benchmark material
    double poisson = 0.45;    // ν
    double density = 1000.0;  // ρ [kg/m³]
    int cells = 40;           // cells along the beam of the pictures
    long largest = 510000;    // the throughput study stops at the first mesh with at least this many tets
};

constexpr double mb = 1e-6;  // bytes → MB (10⁶ bytes)

std::size_t sparse_bytes(Eigen::Index nonzeros, Eigen::Index outer)
{
    return static_cast<std::size_t>(nonzeros) * (sizeof(double) + sizeof(int)) +
           static_cast<std::size_t>(outer + 1) * sizeof(int);
}

template <typename Sparse>
std::size_t sparse_bytes(const Sparse& A)
{
    return sparse_bytes(A.nonZeros(), A.outerSize());
}

// The memory a route took, for the table: MB, or "-" where it cannot be measured.
Cell rise_mb(const PeakMemoryRise& peak)
{
    const std::optional<double> rise = peak.rise_bytes();
    return rise ? Cell(*rise * mb) : Cell(std::string("-"));
}

double rel_difference(const SparseMatrix& A, const SparseMatrix& B) { return (A - B).norm() / B.norm(); }

// 1. The routes agree, and the global matrices have the properties the theory says.
void checks(const RunContext& run, const elastic::Lame& material, double density)
{
    TetMesh mesh = beam_mesh(1.0, 0.2, 0.1, run.quick ? 6 : 12);
    // Move the interior vertices a little, so that no check relies on a regular mesh.
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
        const double s = std::sin(12.9898 * v) * 0.5;
        if (mesh.V(v, 0) > 1e-9 && mesh.V(v, 0) < 1.0 - 1e-9)
            mesh.V(v, 0) += 0.1 * s / (run.quick ? 6 : 12);
    }
    validate(mesh);
    const ElementMatrices K_e = element_stiffnesses(mesh, material);
    const SparseMatrix K_a = assemble_by_composition(mesh, K_e);
    const SparseMatrix K_b = assemble_by_triplets(mesh, K_e);
    const SparseMatrix K_c = csc_of_symmetric(AssemblyPattern(mesh).assemble(K_e));

    Table table(str("Checks on a distorted ", mesh.T.rows(), "-tet beam (", 3 * mesh.V.rows(),
                    " dofs): each value against its bound"),
                {{"check", Format::text}, {"bound", Format::scientific, 0}, {"passed", Format::text},
                 {"value", Format::scientific, 2}});
    const auto add = [&](const std::string& name, double value, double bound) {
        table.add_row({name, bound, std::string(value <= bound ? "yes" : "NO"), value});
    };
    const auto add_outcome = [&](const std::string& name, bool passed) {
        table.add_row({name, std::string("-"), std::string(passed ? "yes" : "NO"), std::string("-")});
    };
    add("(a) composition vs (b) triplets, rel. difference", rel_difference(K_a, K_b), 1e-12);
    add("(c) pattern vs (b) triplets, rel. difference", rel_difference(K_c, K_b), 1e-12);
    add("symmetry |K - K^T| / |K|", rel_difference(SparseMatrix(K_c.transpose()), K_c), 1e-14);
    Eigen::MatrixXd rigid = Eigen::MatrixXd::Zero(K_c.rows(), 6);
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
        for (int c = 0; c < 3; ++c) {
            rigid(3 * v + c, c) = 1.0;
            rigid.block<3, 1>(3 * v, 3 + c) = Eigen::Vector3d::Unit(c).cross(mesh.V.row(v).transpose());
        }
    add("rigid modes |K R| / (|K| |R|)", (K_c * rigid).norm() / (K_c.norm() * rigid.norm()), 1e-12);

    const double mass = density * total_volume(mesh);
    const Eigen::VectorXd lumped = vertex_masses(mesh, density);
    const SparseMatrix M = consistent_mass_matrix(mesh, density);
    add("lumped total / (rho volume) - 1", std::abs(lumped.sum() / mass - 1.0), 1e-12);
    add("consistent total / (rho volume) - 1", std::abs(M.sum() / 3.0 / mass - 1.0), 1e-12);
    Eigen::VectorXd row_error = M * Eigen::VectorXd::Ones(M.rows());
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
        row_error.segment<3>(3 * v) -= Eigen::Vector3d::Constant(lumped[v]);
    add("max |consistent row sum - lumped mass| / max m_v", row_error.cwiseAbs().maxCoeff() / lumped.maxCoeff(),
        1e-12);

    const SparseMatrix P = free_selection_matrix(static_cast<int>(mesh.V.rows()), vertices_on_plane(mesh, 0, 0.0));
    Eigen::SimplicialLLT<SparseMatrix> llt(reduce(K_c, P));
    add_outcome("pinned at x = 0: Cholesky of P^T K P succeeds", llt.info() == Eigen::Success);
    std::string reason;
    try {
        solve_spd(K_c, gravity_load(mesh, density));
    } catch (const Error& error) {
        reason = error.what();
    }
    add_outcome("free-floating K: solve_spd refuses it", !reason.empty());
    table.print(std::cout);
    table.write_csv(run.file("checks_table.csv"));
    std::cout << "the free-floating solve said: " << (reason.empty() ? "(nothing: BUG)" : reason) << "\n\n";
}

// One mesh of the throughput study: times [s] and bytes of each route and phase.
struct Phase {
    std::string route;
    std::string name;
    double seconds;
};

struct Measured {
    long tets = 0;
    Eigen::Index dofs = 0;
    Eigen::Index nonzeros = 0;
    std::size_t scatter_bytes = 0;  // one scatter: K_e and the records read, the values zeroed, read, written
    std::vector<Phase> phases;
};

// Times work(): the best of a few runs for small meshes (noise), a single run for large ones.
template <typename Work>
double time_it(long tets, Work&& work)
{
    return tets < 20000 ? best_time(work, 0.05, 20) : best_time(work, 0.0, 1);
}

// 2. Throughput of the three routes, with the time of each phase.
void throughput(const RunContext& run, const elastic::Lame& material, const Settings& settings,
                std::vector<Measured>& measured)
{
    const std::vector<std::array<int, 3>> all = {{6, 6, 5}, {12, 12, 10}, {22, 22, 22}, {32, 32, 32}, {48, 48, 37}};
    const std::vector<std::array<int, 3>> quick = {{6, 6, 5}, {12, 12, 10}};
    const long composition_limit = 100000;  // route (a) runs up to this many tets (seconds beyond)

    Table table("Assembly of K: one-off setup and per-assembly time of each route (K_e given), "
                "memory computed from the arrays each route holds at its peak",
                {{"tets", Format::integer}, {"dofs", Format::integer}, {"nonzeros", Format::integer},
                 {"route", Format::text}, {"one-off time [s]", Format::scientific, 2},
                 {"assembly time [s]", Format::scientific, 2}, {"rate [tets/s]", Format::scientific, 2},
                 {"speed-up over triplets [measured]", Format::fixed, 1}, {"memory (MB)", Format::fixed, 1},
                 {"peak RSS rise (MB) [measured]", Format::fixed, 0}});
    for (const auto& dims : run.quick ? quick : all) {
        const TetMesh mesh = box_mesh(dims[0], dims[1], dims[2]);
        Measured m;
        m.tets = static_cast<long>(mesh.T.rows());
        m.dofs = 3 * mesh.V.rows();
        const auto add_phase = [&](const std::string& route, const std::string& name, double seconds) {
            m.phases.push_back({route, name, seconds});
            return seconds;
        };

        ElementMatrices K_e;
        const double t_ke = add_phase("K_e", "K_e = V B^T C B (chapter 05)", time_it(m.tets, [&] {
            K_e = element_stiffnesses(mesh, material);
        }));
        const std::size_t ke_bytes = K_e.size() * sizeof(Matrix12d);

        // (b) triplets + setFromTriplets: the reference.
        double t_fill = 0.0, t_convert = 0.0;
        std::size_t b_bytes = 0;
        Cell b_rss;
        SparseMatrix K_b;
        {
            const PeakMemoryRise peak;
            t_fill = time_it(m.tets, [&] {
                const auto triplets = element_triplets(mesh, K_e);
                b_bytes = triplets.capacity() * sizeof(Eigen::Triplet<double>);
            });
            const auto triplets = element_triplets(mesh, K_e);
            t_convert = time_it(m.tets, [&] {
                K_b = SparseMatrix(m.dofs, m.dofs);
                K_b.setFromTriplets(triplets.begin(), triplets.end());
            });
            b_bytes += sparse_bytes(K_b);
            b_rss = rise_mb(peak);
        }
        add_phase("(b) triplets", "fill 144 triplets per tet", t_fill);
        add_phase("(b) triplets", "setFromTriplets (sort, sum, compress)", t_convert);
        m.nonzeros = K_b.nonZeros();
        const double t_b = t_fill + t_convert;

        // (c) the pattern: built once, then a pure scatter.
        std::optional<AssemblyPattern> pattern;
        CsrMatrix K_c;
        double t_build = 0.0, t_scatter = 0.0;
        Cell c_rss;
        {
            const PeakMemoryRise peak;
            t_build = time_it(m.tets, [&] { pattern.emplace(mesh); });
            K_c = pattern->zero_matrix();
            t_scatter = best_time([&] { pattern->assemble(K_e, K_c); }, m.tets < 20000 ? 0.05 : 0.3, 20);
            c_rss = rise_mb(peak);
        }
        add_phase("(c) pattern", "build the pattern (once)", t_build);
        add_phase("(c) pattern", "scatter into the values", t_scatter);
        const std::size_t c_bytes = pattern->memory_bytes() + sparse_bytes(K_c);
        m.scatter_bytes = ke_bytes + 20 * sizeof(int) * static_cast<std::size_t>(m.tets) +
                          3 * sizeof(double) * static_cast<std::size_t>(m.nonzeros);
        if (rel_difference(csc_of_symmetric(K_c), K_b) > 1e-12)
            throw Error(str("route (c) disagrees with route (b) on the ", m.tets, "-tet mesh"));

        table.add_row({double(m.tets), double(m.dofs), double(m.nonzeros), std::string("K_e (chapter 05)"),
                       std::string("-"), t_ke, m.tets / t_ke, std::string("-"), ke_bytes * mb,
                       std::string("-")});

        // (a) composition: S once; K' and the two products per assembly.
        if (m.tets <= composition_limit) {
            double t_s = 0.0, t_blocks = 0.0, t_left = 0.0, t_right = 0.0;
            std::size_t a_bytes = 0;
            Cell a_rss;
            SparseMatrix K_a;
            {
                const PeakMemoryRise peak;
                SparseMatrix S, blocks, SK, St;
                t_s = time_it(m.tets, [&] {
                    S = scatter_matrix(mesh);
                    St = S.transpose();
                });
                t_blocks = time_it(m.tets, [&] { blocks = block_diagonal(K_e); });
                t_left = time_it(m.tets, [&] { SK = S * blocks; });
                t_right = time_it(m.tets, [&] { K_a = SK * St; });
                a_bytes = sparse_bytes(S) + sparse_bytes(St) + sparse_bytes(blocks) + sparse_bytes(SK) +
                          sparse_bytes(K_a);
                a_rss = rise_mb(peak);
            }
            if (rel_difference(K_a, K_b) > 1e-12)
                throw Error(str("route (a) disagrees with route (b) on the ", m.tets, "-tet mesh"));
            add_phase("(a) composition", "build S and S^T (once)", t_s);
            add_phase("(a) composition", "build K' = diag(K_e)", t_blocks);
            add_phase("(a) composition", "product S K'", t_left);
            add_phase("(a) composition", "product (S K') S^T", t_right);
            const double t_a = t_blocks + t_left + t_right;
            table.add_row({double(m.tets), double(m.dofs), double(m.nonzeros), std::string("(a) composition"), t_s,
                           t_a, m.tets / t_a, t_b / t_a, a_bytes * mb, a_rss});
        } else {
            table.add_row({double(m.tets), double(m.dofs), double(m.nonzeros), std::string("(a) composition"),
                           std::string("skipped"), std::string("skipped"), std::string("skipped"),
                           std::string("-"), std::string("skipped"), std::string("-")});
        }
        table.add_row({double(m.tets), double(m.dofs), double(m.nonzeros),
                       std::string("(b) triplets, setFromTriplets"), std::string("-"), t_b, m.tets / t_b, 1.0,
                       b_bytes * mb, b_rss});
        table.add_row({double(m.tets), double(m.dofs), double(m.nonzeros), std::string("(c) pattern scatter"),
                       t_build, t_scatter, m.tets / t_scatter, t_b / t_scatter, c_bytes * mb, c_rss});
        measured.push_back(std::move(m));
        if (measured.back().tets >= settings.largest)
            break;
    }
    table.print(std::cout);
    table.write_csv(run.file("throughput_table.csv"));
    std::cout << "route (a) runs up to " << composition_limit << " tets; beyond, its products take many seconds\n\n";
}

// 3. Where the time goes: the phases of each route on the largest mesh it ran on.
void phases(const RunContext& run, const std::vector<Measured>& measured)
{
    Table table("Where the time goes: phases of each route on the largest mesh it ran on",
                {{"tets", Format::integer}, {"route", Format::text}, {"phase", Format::text},
                 {"time [s]", Format::scientific, 2}, {"per tet [ns]", Format::fixed, 1},
                 {"share of route [measured]", Format::fixed, 3}});
    for (const std::string route : {"K_e", "(a) composition", "(b) triplets", "(c) pattern"}) {
        const Measured* last = nullptr;
        for (const Measured& m : measured)
            for (const Phase& p : m.phases)
                if (p.route == route)
                    last = &m;
        if (!last)
            continue;
        double total = 0.0;
        for (const Phase& p : last->phases)
            if (p.route == route)
                total += p.seconds;
        for (const Phase& p : last->phases)
            if (p.route == route)
                table.add_row({double(last->tets), route, p.name, p.seconds, 1e9 * p.seconds / last->tets,
                               p.seconds / total});
    }
    table.print(std::cout);
    table.write_csv(run.file("phases_table.csv"));

    // The scatter against what the memory delivers: it streams every K_e once (1152 bytes per tet),
    // 20 ints of offsets per tet, and the values (zeroed, then read and written: 3 × 8 bytes each).
    const Measured& last = measured.back();
    double scatter_seconds = 0.0;
    for (const Phase& p : last.phases)
        if (p.name == "scatter into the values")
            scatter_seconds = p.seconds;
    const double triad = measure_triad_bandwidth(std::size_t{1} << 23, run.quick ? 0.05 : 0.2);
    std::cout << "scatter on " << last.tets << " tets streams " << last.scatter_bytes * mb << " MB: "
              << last.scatter_bytes / scatter_seconds * 1e-9 << " GB/s against a triad bandwidth of " << triad
              << " GB/s on this machine\n\n";
}

void rate_chart(const RunContext& run, const std::vector<Measured>& measured)
{
    fig::LineChart chart{"Assembly rate of K against mesh size (K_e given)", "tets", "rate [tets/s]",
                         true, true, {}};
    chart.legend = fig::Corner::bottom_left;
    const std::vector<std::pair<std::string, std::vector<std::string>>> routes = {
        {"(a) composition S K' S^T", {"build K' = diag(K_e)", "product S K'", "product (S K') S^T"}},
        {"(b) triplets + setFromTriplets", {"fill 144 triplets per tet", "setFromTriplets (sort, sum, compress)"}},
        {"(c) scatter into the pattern", {"scatter into the values"}},
        {"K_e computation (chapter 05)", {"K_e = V B^T C B (chapter 05)"}}};
    for (const auto& [name, phase_names] : routes) {
        fig::Series series{name, {}, {}};
        for (const Measured& m : measured) {
            double seconds = 0.0;
            for (const Phase& p : m.phases)
                if (std::find(phase_names.begin(), phase_names.end(), p.name) != phase_names.end())
                    seconds += p.seconds;
            if (seconds > 0.0) {
                series.x.push_back(double(m.tets));
                series.y.push_back(m.tets / seconds);
            }
        }
        chart.series.push_back(series);
    }
    fig::save_chart(chart, run.out_dir / "assembly_rate", run.figures);
}

// 4. A clamped beam under gravity: masses, forces, the reduced system, the sag against beam theory.
void beam(const RunContext& run, const elastic::Lame& material, const Settings& settings)
{
    const double length = 1.0, side = 0.1, g = 9.81;
    // Timoshenko's tip deflection of a cantilever under its weight q = ρ g A per length:
    // q L⁴ / (8 E I) (bending) + q L² / (2 κ G A) (shear, κ = 5/6 for a square section).
    const double area = side * side, inertia = side * side * side * side / 12.0;
    const double q = settings.density * g * area;
    const double bending = q * std::pow(length, 4) / (8.0 * settings.youngs * inertia);
    const double shear = q * length * length / (2.0 * 5.0 / 6.0 * material.mu * area);
    const double reference = bending + shear;

    Table table(str("Cantilever ", length, " x ", side, " x ", side, " m under gravity, clamped at x = 0: ",
                    "tip sag against Timoshenko beam theory (", reference, " m)"),
                {{"cells along", Format::integer}, {"tets", Format::integer}, {"free dofs", Format::integer},
                 {"tip sag (m)", Format::scientific, 4}, {"sag / theory", Format::fixed, 4},
                 {"assemble time [s]", Format::scientific, 2}, {"solve time [s]", Format::scientific, 2}});
    const std::vector<int> cell_counts = run.quick ? std::vector<int>{10, 20} : std::vector<int>{10, 20, 40, 80};
    for (int cells : cell_counts) {
        const TetMesh mesh = beam_mesh(length, side, side, cells);
        Timer assemble_timer;
        const SparseMatrix K = stiffness_matrix(mesh, material);
        const Eigen::VectorXd f = gravity_load(mesh, settings.density);
        const std::vector<int> clamped = vertices_on_plane(mesh, 0, 0.0);
        const SparseMatrix P = free_selection_matrix(static_cast<int>(mesh.V.rows()), clamped);
        const SparseMatrix K_free = reduce(K, P);
        const Eigen::VectorXd f_free = P.transpose() * f;
        const double t_assemble = assemble_timer.seconds();
        Timer solve_timer;
        const Eigen::VectorXd u = expand(P, solve_spd(K_free, f_free));
        const double t_solve = solve_timer.seconds();
        double sag = 0.0;  // the mean vertical displacement of the free end x = L
        const std::vector<int> tip = vertices_on_plane(mesh, 0, length);
        for (int v : tip)
            sag -= u[3 * v + 2] / static_cast<double>(tip.size());
        table.add_row({double(cells), double(mesh.T.rows()), double(K_free.rows()), sag, sag / reference,
                       t_assemble, t_solve});
    }
    table.print(std::cout);
    table.write_csv(run.file("beam_table.csv"));

    // The files: the beam of the pictures with its masses, forces and displacement.
    const TetMesh mesh = beam_mesh(length, side, side, run.quick ? 10 : settings.cells);
    const SparseMatrix K = stiffness_matrix(mesh, material);
    const Eigen::VectorXd masses = vertex_masses(mesh, settings.density);
    const Eigen::VectorXd f = gravity_load(mesh, settings.density);
    const std::vector<int> clamped = vertices_on_plane(mesh, 0, 0.0);
    const SparseMatrix P = free_selection_matrix(static_cast<int>(mesh.V.rows()), clamped);
    const Eigen::VectorXd u = expand(P, solve_spd(reduce(K, P), P.transpose() * f));
    const SparseMatrix M = consistent_mass_matrix(mesh, settings.density);
    const Eigen::VectorXd consistent_rows = M * Eigen::VectorXd::Ones(M.rows());

    io::MeshData data = io::displaced_mesh(mesh.V, mesh.T, io::vertex_rows(u));
    Eigen::MatrixXd consistent_diagonal(mesh.V.rows(), 1), pinned = Eigen::MatrixXd::Zero(mesh.V.rows(), 1);
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
        consistent_diagonal(v, 0) = M.coeff(3 * v, 3 * v);
    for (int v : clamped)
        pinned(v, 0) = 1.0;
    Eigen::MatrixXd row_sums(mesh.V.rows(), 1);
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
        row_sums(v, 0) = consistent_rows[3 * v];
    data.point_data.insert(data.point_data.end(), {{"lumped mass", masses},
                                                   {"consistent mass diagonal", consistent_diagonal},
                                                   {"consistent mass row sum", row_sums},
                                                   {"gravity force", io::vertex_rows(f)},
                                                   {"pinned", pinned}});
    Eigen::MatrixXd volume(mesh.T.rows(), 1);
    for (int t = 0; t < static_cast<int>(mesh.T.rows()); ++t)
        volume(t, 0) = std::abs(tet_signed_volume6(mesh, t)) / 6.0;
    data.cell_data = {{"volume", volume}};
    io::write_vtu(run.file("beam.vtu"), data);

    // The pictures: the lumped masses on the rest shape, the displacement on the deformed shape (true scale).
    // The masses are cut open along the middle (y = side/2): the inner vertices, which share the
    // most tets and so carry the most mass, show on the cut.
    fig::RenderOptions options;
    options.view_direction = {0.35, 1.0, -0.25};
    options.view_up = {0.0, 0.0, 1.0};
    options.height = 520;
    options.field = "lumped mass";
    options.unit = "kg";
    options.title = "lumped vertex masses m_v = sum of rho V / 4 over the tets at v [kg],\ncut open at y = "
                    + str(side / 2) + " m";
    options.cut = fig::CutPlane{{0.0, side / 2, 0.0}, {0.0, -1.0, 0.0}};
    fig::render_mesh_png(run.file("beam_masses.png"), data, options);
    options.cut.reset();
    options.field = "displacement";
    options.unit = "m";
    options.title = "clamped beam sagging under gravity (true scale): |u| [m]";
    fig::render_mesh_png(run.file("beam_sag.png"), io::warped(data), options);
    std::cout << "\nbeam.vtu: " << mesh.T.rows() << " tets with lumped and consistent masses, gravity forces "
              << "and the static displacement (total mass " << masses.sum() << " kg, weight "
              << -f.sum() << " N)\n";
}

}  // namespace

int main(int argc, char** argv)
{
    ChapterCli cli("ch06_assembly", "06_assembly",
                   "Chapter 06: assembling K three ways, masses, damping, gravity, pinned vertices");
    Settings settings;
    cli.app.add_option("--youngs", settings.youngs, "Young's modulus Y [Pa]")->check(check::positive())
        ->capture_default_str();
    cli.app.add_option("--poisson", settings.poisson, "Poisson's ratio nu")
        ->check(check::real(-1.0, 0.5, check::Ends::open))->capture_default_str();
    cli.app.add_option("--density", settings.density, "Density rho [kg/m^3]")->check(check::positive())
        ->capture_default_str();
    cli.app.add_option("--cells", settings.cells, "Cells along the beam of the files")
        ->check(check::integer(1, 400))->capture_default_str();
    cli.app.add_option("--largest", settings.largest,
                       "The throughput study stops at the first mesh with at least this many tets")
        ->check(check::integer(1, 100000000))->capture_default_str();
    return cli.run(argc, argv, [&](const RunContext& run) {
        const elastic::Lame material = elastic::lame_parameters(settings.youngs, settings.poisson);
        checks(run, material, settings.density);
        std::vector<Measured> measured;
        throughput(run, material, settings, measured);
        phases(run, measured);
        rate_chart(run, measured);
        beam(run, material, settings);
    });
}
