// ch08_direct_solvers: dense LU and Cholesky against Eigen; the Hilbert matrices (error against
// condition number); fill-reducing orderings (natural, RCM, minimum degree, nested dissection,
// Eigen's AMD, CHOLMOD's choice) on 2D/3D Laplacians and the stiffness matrix of a box; our sparse
// Cholesky (up-looking and supernodal) against Eigen's SimplicialLLT and CHOLMOD's supernodal
// factorization on the same matrices: analysis, factor and solve times, nnz(L), residual and error;
// the kernels against the hardware: the factorization's rate against the BLAS's dgemm on the
// shapes of its supernodes, our solve against CHOLMOD's, each pair timed in alternation;
// factor once / solve many; the cases where a direct solver must refuse.
//
// Sample runs:
//   ch08_direct_solvers                        full run: about 10k, 50k and 160k unknowns per family
//   ch08_direct_solvers --quick                the small run ctest checks
//   ch08_direct_solvers --max-unknowns 60000   skip the largest matrices
//
// Writes: tables dense_table.csv, hilbert_table.csv, ordering_table.csv, speed_table.csv,
// goals_table.csv, supernodes_table.csv, kernels_table.csv, solve_many_table.csv, failures_table.csv,
// threads_factor_table.csv, threads_phases_table.csv, threads_solve_table.csv;
// charts (PNG + CSV) dense_times, hilbert_errors, fill_growth, factor_times, solve_times;
// the patterns of L for four orderings (factor_patterns.vti/.png) and the box under gravity solved
// with our Cholesky (box_displacement.vtu/.png). docs/08_direct_solvers.md

#include "08_direct_solvers/dense_solvers.hpp"
#include "08_direct_solvers/model_problems.hpp"
#include "08_direct_solvers/orderings.hpp"
#include "08_direct_solvers/sparse_cholesky.hpp"
#include "08_direct_solvers/supernodal.hpp"

#include "06_assembly/assembly.hpp"
#include "07_sparse_storage/sparse_formats.hpp"

#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/mesh.hpp"
#include "common/parallel.hpp"
#include "common/table.hpp"
#include "common/threads_study.hpp"
#include "common/timer.hpp"
#include "common/vtk_io.hpp"
#include "common/random.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>

#ifdef FEM_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif
#if __has_include(<dlfcn.h>)
#include <dlfcn.h>
#define FEM_HAVE_DLSYM 1
#endif

#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <iomanip>

using namespace fem;
using namespace fem::direct;

namespace {

struct Settings {
    long long max_unknowns = 200000;  // matrices above this size are skipped
    double simplicial_flops = 4e9;    // the scalar factorizations run only below this many flops
};

const elastic::Lame rubber = elastic::lame_parameters(1e5, 0.45);
const double eps = std::numeric_limits<double>::epsilon();

/// Best of a few calls for short work, one call for long work.
template <typename Work>
double timed(Work&& work)
{
    return best_time(std::forward<Work>(work), 0.3, 5);
}

/// The best times of two pieces of work run in alternation (a, b, a, b, …), so that the load of
/// the rest of the machine hits both alike: rounds stop after min_seconds or max_rounds. Without
/// b, only a is timed (second = 0).
std::pair<double, double> alternating_best_times(const std::function<void()>& a, const std::function<void()>& b,
                                                 double min_seconds = 0.3, int max_rounds = 5)
{
    double best_a = 1e300, best_b = b ? 1e300 : 0.0;
    Timer total;
    for (int round = 0; round < max_rounds && (round == 0 || total.seconds() < min_seconds); ++round) {
        Timer once;
        a();
        best_a = std::min(best_a, once.seconds());
        if (b) {
            once.restart();
            b();
            best_b = std::min(best_b, once.seconds());
        }
    }
    return {best_a, best_b};
}

// --- One core's dense matrix product, the yardstick of the supernodal factorization -------------

/// C ← C − A Bᵀ in the BLAS's dgemm (column-major, Fortran calling convention).
using Dgemm = void (*)(const char* transa, const char* transb, const int* m, const int* n, const int* k,
                       const double* alpha, const double* a, const int* lda, const double* b, const int* ldb,
                       const double* beta, double* c, const int* ldc);

/// The BLAS's dgemm if the process has one (CHOLMOD links OpenBLAS on Debian, which picks the
/// processor's best kernel at run time), else nullptr: Eigen's own product is compiled for baseline
/// x86-64 (SSE2, no FMA) and would understate what one core can do.
Dgemm blas_dgemm()
{
#ifdef FEM_HAVE_DLSYM
    return reinterpret_cast<Dgemm>(dlsym(RTLD_DEFAULT, "dgemm_"));
#else
    return nullptr;
#endif
}

/// A dense product of a supernode's dimensions: its m rows, ns columns.
struct SupernodeShape {
    int m = 0, ns = 0;
};

/// Three supernodes that stand for the flops of the factorization: the supernodes sorted by their
/// number of rows m, the one at which the running sum of flops (Σ over the supernode's columns j of
/// count_j² = Σ_{i<ns} (m − i)²) passes 1/6, 1/2 and 5/6 of the total. Each represents a third of
/// the flops. perm is the ordering SparseCholesky used (its tree is then postordered).
std::vector<SupernodeShape> flop_weighted_shapes(const sparse::CscMatrix& A, const Permutation& perm)
{
    const SymbolicCholesky symbolic = symbolic_cholesky(A, perm);
    const SupernodalCholesky supernodes(symbolic, symmetric_permutation(A, perm));
    std::vector<std::pair<SupernodeShape, double>> all;
    double total = 0.0;
    for (int s = 0; s < supernodes.supernodes(); ++s) {
        const int ns = supernodes.first(s + 1) - supernodes.first(s);
        const int m = supernodes.rows(s);
        double flops = 0.0;
        for (int i = 0; i < ns; ++i)
            flops += double(m - i) * double(m - i);
        all.push_back({{m, ns}, flops});
        total += flops;
    }
    std::stable_sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.first.m < b.first.m; });
    std::vector<SupernodeShape> shapes;
    double sum = 0.0;
    std::size_t next = 0;
    for (const auto& [shape, flops] : all) {
        sum += flops;
        while (next < 3 && sum >= total * (2.0 * double(next) + 1.0) / 6.0) {
            shapes.push_back(shape);
            ++next;
        }
    }
    return shapes;
}

/// The GEMM rate in GFLOP/s of C ← C − B Bᵀ (C m×m, B m×ns, 2 m² ns flops) through dgemm, on the
/// shapes in turn, each dimension capped at gemm_cap (one core's rate no longer grows there, and
/// the cap bounds the time and memory of the yardstick), repeated so that each timing covers at
/// least 2·10⁷ flops; one call per shape (the caller alternates it with the factorization and
/// keeps the best). Returns the rate of the mix in which each shape does an equal share of the
/// flops: 1 / mean(1 / rate).
double gemm_mix_rate(Dgemm dgemm, const std::vector<SupernodeShape>& shapes)
{
    constexpr int gemm_cap = 2048;
    double seconds_per_flop = 0.0;
    for (const SupernodeShape& shape : shapes) {
        const int m = std::min(shape.m, gemm_cap), ns = std::min(shape.ns, gemm_cap);
        const Eigen::MatrixXd B = Eigen::MatrixXd::Constant(m, ns, 1e-3);
        Eigen::MatrixXd C = Eigen::MatrixXd::Zero(m, m);
        const double flops = 2.0 * double(m) * m * ns;
        const int calls = static_cast<int>(std::max(1.0, std::ceil(2e7 / flops)));
        const double minus_one = -1.0, one = 1.0;
        Timer timer;
        for (int call = 0; call < calls; ++call)
            dgemm("N", "T", &m, &m, &ns, &minus_one, B.data(), &m, B.data(), &m, &one, C.data(), &m);
        seconds_per_flop += timer.seconds() / (calls * flops) / double(shapes.size());
    }
    return 1e-9 / seconds_per_flop;
}

// --- CHOLMOD, the reference (not course material) ----------------------------------------------

/// One CHOLMOD supernodal factorization and solve through Eigen's CholmodSupport.
struct CholmodResult {
    bool ran = false;
    std::string ordering;  ///< the ordering CHOLMOD used
    double nonzeros = 0.0, flops = 0.0;
    double analyse = 0.0, factor = 0.0, solve = 0.0;
    double other_solve = 0.0;  ///< the solve timed in alternation with CHOLMOD's, if any
    Eigen::VectorXd x;
};

#ifdef FEM_HAVE_CHOLMOD
/// CHOLMOD's BLAS (OpenBLAS on Debian) may start a thread per core; the comparison is one core
/// against one core, so ask it for `threads` (default 1) when the library offers the switch.
void set_blas_threads(int threads)
{
    using SetThreads = void (*)(int);
    if (void* symbol = dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))
        reinterpret_cast<SetThreads>(symbol)(threads);
}

std::string cholmod_ordering_name(int ordering)
{
    switch (ordering) {
    case CHOLMOD_NATURAL: return "natural";
    case CHOLMOD_AMD: return "AMD";
    case CHOLMOD_METIS: return "METIS";
    case CHOLMOD_NESDIS: return "NESDIS";
    default: return str("method ", ordering);
    }
}

/// A (lower triangle read) factored by CHOLMOD with its own ordering choice (natural = false), or
/// in the given numbering (natural = true: A is already permuted). analyse_only skips the
/// numeric work (for the ordering table).
/// With other_solve, the solve is timed in alternation with it (best of each: other_solve_time).
CholmodResult run_cholmod(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b, bool natural,
                          bool analyse_only = false, const std::function<void()>& other_solve = {})
{
    CholmodResult r;
    Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> chol;
    if (natural) {
        chol.cholmod().nmethods = 1;
        chol.cholmod().method[0].ordering = CHOLMOD_NATURAL;
    }
    Timer timer;
    chol.analyzePattern(A);
    r.analyse = timer.seconds();
    const cholmod_common& c = chol.cholmod();
    r.ordering = natural ? "ours (same P)" : "CHOLMOD's: " + cholmod_ordering_name(c.method[c.selected].ordering);
    r.nonzeros = c.lnz;
    r.flops = c.fl;
    r.ran = true;
    if (analyse_only)
        return r;
    r.factor = timed([&] { chol.factorize(A); });
    if (chol.info() != Eigen::Success)
        throw Error("CHOLMOD: the factorization failed (the matrix is not positive definite)");
    std::tie(r.solve, r.other_solve) = alternating_best_times([&] { r.x = chol.solve(b); }, other_solve);
    return r;
}
#endif

// --- 1. Dense LU and Cholesky ----------------------------------------------------------------

void dense_study(const RunContext& run)
{
    const std::vector<int> sizes = run.quick ? std::vector<int>{50, 100} : std::vector<int>{100, 200, 400, 800};
    Table table("Dense direct solvers on random well-conditioned matrices (LU: non-symmetric, Cholesky: SPD)",
                {{"solver", Format::text}, {"n", Format::integer}, {"flops", Format::scientific, 2},
                 {"factor time [s]", Format::scientific, 2}, {"solve time [s]", Format::scientific, 2},
                 {"rate [GFLOP/s]", Format::fixed, 2}, {"residual", Format::scientific, 2}});
    std::map<std::string, std::vector<double>> times;
    std::vector<double> ns;
    for (int n : sizes) {
        ns.push_back(n);
        const Eigen::MatrixXd A = random_matrix(n, n, 1 + n) + 2.0 * std::sqrt(double(n)) * Eigen::MatrixXd::Identity(n, n);
        const Eigen::MatrixXd B = random_matrix(n, n, 2 + n);
        const Eigen::MatrixXd S = B * B.transpose() / n + Eigen::MatrixXd::Identity(n, n);
        const Eigen::VectorXd b = random_vector(n, 3 + n);
        const double lu_flops = 2.0 / 3.0 * n * double(n) * n, llt_flops = lu_flops / 2.0;
        const auto add = [&](const std::string& name, double flops, double factor, double solve,
                             const Eigen::MatrixXd& M, const Eigen::VectorXd& x) {
            table.add_row({name, double(n), flops, factor, solve, flops / factor * 1e-9, (M * x - b).norm() / b.norm()});
            times[name].push_back(factor);
        };
        {
            LuFactorization F;
            Eigen::VectorXd x;
            const double factor = timed([&] { F = lu_factor(A); });
            const double solve = timed([&] { x = lu_solve(F, b); });
            add("ours: LU", lu_flops, factor, solve, A, x);
        }
        {
            Eigen::PartialPivLU<Eigen::MatrixXd> F;
            Eigen::VectorXd x;
            const double factor = timed([&] { F.compute(A); });
            const double solve = timed([&] { x = F.solve(b); });
            add("Eigen PartialPivLU", lu_flops, factor, solve, A, x);
        }
        {
            Eigen::MatrixXd L;
            Eigen::VectorXd x;
            const double factor = timed([&] { L = cholesky_factor(S); });
            const double solve = timed([&] { x = cholesky_solve(L, b); });
            add("ours: Cholesky", llt_flops, factor, solve, S, x);
        }
        {
            Eigen::LLT<Eigen::MatrixXd> F;
            Eigen::VectorXd x;
            const double factor = timed([&] { F.compute(S); });
            const double solve = timed([&] { x = F.solve(b); });
            add("Eigen LLT", llt_flops, factor, solve, S, x);
        }
    }
    table.print(std::cout);
    table.write_csv(run.file("dense_table.csv"));
    fig::LineChart chart{"Dense factorizations: time against n (O(n^3))", "n", "factor time [s]", true, true, {}};
    for (const auto& [name, t] : times)
        chart.series.push_back({name, ns, t});
    chart.legend = fig::Corner::top_left;
    fig::save_chart(chart, run.out_dir / "dense_times", run.figures);
}

// --- 2. Hilbert matrices ---------------------------------------------------------------------

void hilbert_study(const RunContext& run)
{
    Table table("Hilbert matrices: x = (1, ..., 1), b = H x summed in long double; max-norm error of x",
                {{"n", Format::integer}, {"kappa_1 (exact)", Format::scientific, 2},
                 {"kappa_1 (Eigen estimate)", Format::scientific, 2}, {"kappa eps", Format::scientific, 2},
                 {"LU error", Format::text}, {"LU error / (kappa eps)", Format::text},
                 {"Cholesky error", Format::text}, {"Eigen PartialPivLU error", Format::scientific, 2}});
    std::vector<double> kappas, lu_errors, llt_errors, eigen_errors, bound;
    const auto cell = [](double value) { return str(std::scientific, std::setprecision(3), value); };
    for (int n = 2; n <= 14; ++n) {
        const Eigen::MatrixXd H = hilbert_matrix(n);
        const Eigen::VectorXd b = hilbert_row_sums(n);
        const double kappa = hilbert_condition_number(n);
        const Eigen::PartialPivLU<Eigen::MatrixXd> eigen_lu(H);
        const double eigen_error = (eigen_lu.solve(b).array() - 1.0).abs().maxCoeff();
        std::string lu_text, ratio_text, llt_text;
        try {
            const double error = (lu_solve(lu_factor(H), b).array() - 1.0).abs().maxCoeff();
            lu_text = cell(error);
            ratio_text = cell(error / (kappa * eps));
            kappas.push_back(kappa);
            lu_errors.push_back(error);
            eigen_errors.push_back(eigen_error);
            bound.push_back(n * kappa * eps);
        } catch (const Error& e) {
            lu_text = "singular (LU refuses)";
            ratio_text = "-";
        }
        try {
            const double error = (cholesky_solve(cholesky_factor(H), b).array() - 1.0).abs().maxCoeff();
            llt_text = cell(error);
            if (static_cast<int>(llt_errors.size()) < static_cast<int>(kappas.size()))
                llt_errors.push_back(error);
        } catch (const Error& e) {
            llt_text = "not SPD in double";
        }
        table.add_row({double(n), kappa, 1.0 / eigen_lu.rcond(), kappa * eps, lu_text, ratio_text, llt_text, eigen_error});
    }
    table.print(std::cout);
    table.write_csv(run.file("hilbert_table.csv"));
    std::vector<double> llt_kappas(kappas.begin(), kappas.begin() + static_cast<std::ptrdiff_t>(llt_errors.size()));
    fig::LineChart chart{"Hilbert matrices n = 2..13: error of x against the condition number", "kappa_1(H_n)",
                         "max-norm error of x", true, true,
                         {{"ours: LU", kappas, lu_errors},
                          {"ours: Cholesky", llt_kappas, llt_errors},
                          {"Eigen PartialPivLU", kappas, eigen_errors},
                          {"bound n kappa eps", kappas, bound}}};
    chart.legend = fig::Corner::top_left;
    fig::save_chart(chart, run.out_dir / "hilbert_errors", run.figures);
}

// --- The sparse test matrices ------------------------------------------------------------------

struct Problem {
    std::string family;  ///< "2D Laplacian", "3D Laplacian", "3D elasticity"
    int size = 0;        ///< n of the grid, or cubes per side of the box
    sparse::CscMatrix A;
    Eigen::SparseMatrix<double> E;  ///< the same matrix for Eigen and CHOLMOD
};

const char* const families[] = {"2D Laplacian", "3D Laplacian", "3D elasticity"};

std::vector<int> family_sizes(const std::string& family, bool quick)
{
    // about 10k, 50k and 160k unknowns (quick: a few hundred to a few thousand)
    if (family == "2D Laplacian")
        return quick ? std::vector<int>{30, 60} : std::vector<int>{100, 224, 400};
    if (family == "3D Laplacian")
        return quick ? std::vector<int>{8, 14} : std::vector<int>{22, 37, 54};
    return quick ? std::vector<int>{4, 7} : std::vector<int>{14, 25, 37};
}

long long family_unknowns(const std::string& family, int size)
{
    if (family == "2D Laplacian")
        return static_cast<long long>(size) * size;
    if (family == "3D Laplacian")
        return static_cast<long long>(size) * size * size;
    return 3LL * size * (size + 1) * (size + 1);
}

Problem make_problem(const std::string& family, int size)
{
    Problem p{family, size, {}, {}};
    p.A = family == "2D Laplacian" ? laplacian_2d(size)
          : family == "3D Laplacian" ? laplacian_3d(size)
                                     : box_stiffness(size, rubber);
    p.E = sparse::to_eigen(p.A);
    return p;
}

std::string size_text(const Problem& p)
{
    if (p.family == "3D elasticity")
        return str(p.size, "^3 cubes");
    return p.family == "2D Laplacian" ? str(p.size, "^2") : str(p.size, "^3");
}

long long lower_nonzeros(const sparse::CscMatrix& A)
{
    long long count = 0;
    for (int j = 0; j < A.cols; ++j)
        for (int k = A.IA[j]; k < A.IA[j + 1]; ++k)
            count += A.JA[k] >= j;
    return count;
}

// --- 3. Orderings ------------------------------------------------------------------------------

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

// --- 4. Speed against error ------------------------------------------------------------------

/// One row of the speed table.
struct Measured {
    std::string solver, ordering, status = "ok";
    double nonzeros = 0.0, flops = 0.0, analyse = 0.0, factor = 0.0, solve = 0.0, residual = 0.0, error = 0.0;
};

struct SpeedRecord {
    std::string family;
    double unknowns;
    Measured m;
};

/// What else a run of ours reports: the ordering used and the supernodes.
struct OursDetails {
    Permutation perm;
    int supernodes = 0;
    long long stored = 0;
};

/// Our factorization: construct (order, analyse, factor), then refactor while it is quick (best
/// time). after_factor, if given, runs after each factorization (work timed in alternation with
/// it); keep, if given, receives the factorization.
Measured run_ours(const Problem& p, const Eigen::VectorXd& b, const Eigen::VectorXd& x_ref, CholeskyOptions options,
                  const std::string& name, OursDetails* details = nullptr,
                  const std::function<void(const SparseCholesky&)>& after_factor = {},
                  std::optional<SparseCholesky>* keep = nullptr)
{
    Measured m;
    m.solver = name;
    m.ordering = ordering_name(options.ordering);
    SparseCholesky chol(p.A, options);
    m.nonzeros = double(chol.factor_nonzeros());
    m.flops = chol.flops();
    m.analyse = chol.times().ordering + chol.times().symbolic;
    m.factor = chol.times().numeric;
    if (after_factor)
        after_factor(chol);
    for (int repeat = 0; repeat < 4 && m.factor < 0.2; ++repeat) {
        chol.factorize(p.A);
        m.factor = std::min(m.factor, chol.times().numeric);
        if (after_factor)
            after_factor(chol);
    }
    Eigen::VectorXd x;
    m.solve = timed([&] { x = chol.solve(b); });
    m.residual = symmetric_residual(p.A, x, b);
    m.error = (x - x_ref).norm() / x_ref.norm();
    if (details)
        *details = {chol.permutation(), chol.supernodes(), chol.stored_entries()};
    if (keep)
        keep->emplace(std::move(chol));
    return m;
}

/// A CHOLMOD row: with our permutation (the matrix permuted first, CHOLMOD told to keep the order)
/// or with CHOLMOD's own ordering; "CHOLMOD not installed" without it.
/// With other_solve, CHOLMOD's solve is timed in alternation with it; *other_time receives its best.
Measured run_cholmod_row(const Problem& p, const Eigen::VectorXd& b, const Eigen::VectorXd& x_ref,
                         const Permutation* perm, const std::function<void()>& other_solve = {},
                         double* other_time = nullptr)
{
    Measured m;
    m.solver = "CHOLMOD supernodal";
    m.ordering = perm ? "ours (same P)" : "CHOLMOD's own";
#ifdef FEM_HAVE_CHOLMOD
    CholmodResult c;
    Eigen::VectorXd x(p.A.rows);
    if (perm) {
        Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> P(p.A.rows);
        for (int k = 0; k < p.A.rows; ++k)
            P.indices()[(*perm)[k]] = k;  // Eigen's twistedBy maps old → new
        Eigen::SparseMatrix<double> C;
        C = p.E.selfadjointView<Eigen::Lower>().twistedBy(P);
        Eigen::VectorXd Pb(p.A.rows);
        for (int k = 0; k < p.A.rows; ++k)
            Pb[k] = b[(*perm)[k]];
        c = run_cholmod(C, Pb, true, false, other_solve);
        if (other_time)
            *other_time = c.other_solve;
        for (int k = 0; k < p.A.rows; ++k)
            x[(*perm)[k]] = c.x[k];
    } else {
        c = run_cholmod(p.E, b, false);
        x = c.x;
        m.ordering = c.ordering;
    }
    m.nonzeros = c.nonzeros;
    m.flops = c.flops;
    m.analyse = c.analyse;
    m.factor = c.factor;
    m.solve = c.solve;
    m.residual = symmetric_residual(p.A, x, b);
    m.error = (x - x_ref).norm() / x_ref.norm();
#else
    (void)p;
    (void)b;
    (void)x_ref;
    (void)other_solve;
    (void)other_time;
    m.status = "CHOLMOD not installed";
#endif
    return m;
}

Measured run_eigen_simplicial(const Problem& p, const Eigen::VectorXd& b, const Eigen::VectorXd& x_ref)
{
    Measured m;
    m.solver = "Eigen SimplicialLLT";
    m.ordering = "Eigen AMD";
    Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> llt;
    Timer timer;
    llt.analyzePattern(p.E);
    m.analyse = timer.seconds();
    m.factor = timed([&] { llt.factorize(p.E); });
    if (llt.info() != Eigen::Success)
        throw Error("Eigen SimplicialLLT: the factorization failed");
    m.nonzeros = double(llt.matrixL().nestedExpression().nonZeros());
    Eigen::VectorXd x;
    m.solve = timed([&] { x = llt.solve(b); });
    m.residual = symmetric_residual(p.A, x, b);
    m.error = (x - x_ref).norm() / x_ref.norm();
    return m;
}

std::vector<SpeedRecord> speed_study(const RunContext& run, const Settings& settings)
{
    Table table("Sparse Cholesky: speed against error (b = A x_ref, x_ref random; one core)",
                {{"matrix", Format::text}, {"unknowns", Format::integer}, {"solver", Format::text},
                 {"ordering", Format::text}, {"status", Format::text}, {"nnz(L)", Format::scientific, 3},
                 {"flops", Format::scientific, 2}, {"analyse time [s]", Format::scientific, 2},
                 {"factor time [s]", Format::scientific, 2}, {"solve time [s]", Format::scientific, 2},
                 {"rate [GFLOP/s]", Format::fixed, 2}, {"residual", Format::scientific, 2},
                 {"error", Format::scientific, 2}});
    Table supernodes("Supernodes of our factorization (nested dissection)",
                     {{"matrix", Format::text}, {"unknowns", Format::integer}, {"supernodes", Format::integer},
                      {"mean columns per supernode", Format::fixed, 2}, {"stored / nnz(L)", Format::fixed, 3},
                      {"flops per stored entry", Format::fixed, 1}});
    Table kernels("Kernels against the hardware (one core): our supernodal factorization against dgemm on the "
                  "supernodes' shapes, our solve against CHOLMOD's (same P); each pair timed in alternation",
                  {{"matrix", Format::text}, {"unknowns", Format::integer},
                   {"shapes m x ns at 1/6, 1/2, 5/6 of the flops", Format::text},
                   {"factor rate [GFLOP/s]", Format::fixed, 2}, {"dgemm rate, those shapes [GFLOP/s]", Format::fixed, 2},
                   {"factor / dgemm rate [measured]", Format::fixed, 3}, {"ours solve [s]", Format::scientific, 2},
                   {"CHOLMOD solve [s]", Format::scientific, 2}, {"solve / CHOLMOD [measured]", Format::fixed, 3}});
    const Dgemm dgemm = blas_dgemm();
    std::vector<SpeedRecord> records;
    for (const char* family : families)
        for (int size : family_sizes(family, run.quick)) {
            if (family_unknowns(family, size) > settings.max_unknowns)
                continue;
            const Problem p = make_problem(family, size);
            const Eigen::VectorXd x_ref = random_vector(p.A.rows, 7);
            const Eigen::VectorXd b = p.E * x_ref;
            std::vector<Measured> rows;
            const CholeskyOptions fast{Ordering::nested_dissection, Factorization::supernodal};
            OursDetails details;
            // The factorization alternates with dgemm on the shapes of its supernodes (best rate of
            // each); the factor is kept for the solve's race against CHOLMOD's below.
            std::vector<SupernodeShape> shapes;
            double gemm_rate = 0.0;
            const auto gemm_after = [&](const SparseCholesky& chol) {
                if (shapes.empty())
                    shapes = flop_weighted_shapes(p.A, chol.permutation());
                if (dgemm)
                    gemm_rate = std::max(gemm_rate, gemm_mix_rate(dgemm, shapes));
            };
            std::optional<SparseCholesky> kept;
            rows.push_back(run_ours(p, b, x_ref, fast, "ours: supernodal", &details, gemm_after, &kept));
            const Measured ours = rows.back();
            const Permutation& perm = details.perm;
            supernodes.add_row({p.family, double(p.A.rows), double(details.supernodes),
                                double(p.A.rows) / details.supernodes, double(details.stored) / ours.nonzeros,
                                ours.flops / double(details.stored)});
            if (ours.flops <= settings.simplicial_flops) {
                rows.push_back(run_ours(p, b, x_ref, {Ordering::nested_dissection, Factorization::up_looking},
                                        "ours: up-looking"));
            } else {
                Measured skipped{"ours: up-looking", ordering_name(Ordering::nested_dissection), "skipped: flops > budget"};
                skipped.nonzeros = ours.nonzeros;
                skipped.flops = ours.flops;
                rows.push_back(skipped);
            }
            const SymbolicCholesky amd = symbolic_cholesky(p.A, eigen_amd(p.A));
            if (amd.flops <= settings.simplicial_flops) {
                rows.push_back(run_eigen_simplicial(p, b, x_ref));
                rows.back().flops = amd.flops;
            } else {
                Measured skipped{"Eigen SimplicialLLT", "Eigen AMD", "skipped: flops > budget"};
                skipped.nonzeros = double(amd.nonzeros);
                skipped.flops = amd.flops;
                rows.push_back(skipped);
            }
            double ours_solve = 0.0;
            Eigen::VectorXd x_ours;
            rows.push_back(run_cholmod_row(p, b, x_ref, &perm, [&] { x_ours = kept->solve(b); }, &ours_solve));
            kept.reset();
            const Measured same = rows.back();
            if (ours_solve > 0.0)
                rows.front().solve = ours_solve;  // the time of the race, in every table
            rows.push_back(run_cholmod_row(p, b, x_ref, nullptr));
            std::string shapes_text;
            for (const SupernodeShape& shape : shapes)
                shapes_text += str(shapes_text.empty() ? "" : ", ", shape.m, "x", shape.ns);
            const double rate = ours.flops / ours.factor * 1e-9;
            const bool raced = same.status == "ok";
            const Cell none = std::string("-");
            kernels.add_row({p.family, double(p.A.rows), shapes_text, rate, dgemm ? Cell(gemm_rate) : none,
                             dgemm ? Cell(rate / gemm_rate) : none, rows.front().solve,
                             raced ? Cell(same.solve) : none, raced ? Cell(rows.front().solve / same.solve) : none});
            for (const Measured& m : rows) {
                const bool ran = m.status == "ok";
                const auto measured = [&](double value) { return ran ? Cell(value) : Cell(std::string("-")); };
                table.add_row({p.family, double(p.A.rows), m.solver, m.ordering, m.status,
                               m.nonzeros > 0.0 ? Cell(m.nonzeros) : Cell(std::string("-")),
                               m.flops > 0.0 ? Cell(m.flops) : Cell(std::string("-")), measured(m.analyse),
                               measured(m.factor), measured(m.solve), measured(m.flops / m.factor * 1e-9),
                               measured(m.residual), measured(m.error)});
                records.push_back({p.family, double(p.A.rows), m});
            }
        }
    table.print(std::cout);
    table.write_csv(run.file("speed_table.csv"));
    supernodes.print(std::cout);
    supernodes.write_csv(run.file("supernodes_table.csv"));
    kernels.print(std::cout);
    std::cout << "goals (measured, never asserted): factor rate >= 0.8 x dgemm's on the same shapes; solve <= 1.0 x "
                 "CHOLMOD's\n";
    kernels.write_csv(run.file("kernels_table.csv"));
    return records;
}

/// The performance goals of the chapter, side by side (never asserted): per matrix, our supernodal
/// factorization against Eigen's SimplicialLLT and against CHOLMOD with the same ordering.
void goals_table(const RunContext& run, const std::vector<SpeedRecord>& records)
{
    Table table("Goals: our supernodal Cholesky against Eigen's SimplicialLLT and CHOLMOD (same matrix, one core)",
                {{"matrix", Format::text}, {"unknowns", Format::integer},
                 {"factor / SimplicialLLT [measured]", Format::fixed, 3},
                 {"factor / CHOLMOD same P [measured]", Format::fixed, 3},
                 {"solve / CHOLMOD same P [measured]", Format::fixed, 3},
                 {"factor / CHOLMOD own ordering [measured]", Format::fixed, 3}});
    std::map<std::pair<std::string, double>, std::map<std::string, Measured>> by_matrix;
    std::vector<std::pair<std::string, double>> order;
    for (const SpeedRecord& r : records) {
        const auto key = std::pair{r.family, r.unknowns};
        if (by_matrix.find(key) == by_matrix.end())
            order.push_back(key);
        by_matrix[key][r.m.solver + " / " + (r.m.ordering.rfind("CHOLMOD", 0) == 0 ? "own" : r.m.ordering)] = r.m;
    }
    const auto ratio = [](const Measured* a, const Measured* b, double Measured::*field) -> Cell {
        if (!a || !b || a->status != "ok" || b->status != "ok" || !(b->*field > 0.0))
            return std::string("-");
        return a->*field / b->*field;
    };
    for (const auto& key : order) {
        const auto& rows = by_matrix[key];
        const auto find = [&](const std::string& name) -> const Measured* {
            const auto it = rows.find(name);
            return it == rows.end() ? nullptr : &it->second;
        };
        const Measured* ours = find("ours: supernodal / nested dissection");
        const Measured* simplicial = find("Eigen SimplicialLLT / Eigen AMD");
        const Measured* same = find("CHOLMOD supernodal / ours (same P)");
        const Measured* own = find("CHOLMOD supernodal / own");
        table.add_row({key.first, key.second, ratio(ours, simplicial, &Measured::factor),
                       ratio(ours, same, &Measured::factor), ratio(ours, same, &Measured::solve),
                       ratio(ours, own, &Measured::factor)});
    }
    table.print(std::cout);
    std::cout << "goals (measured, never asserted): factor <= 0.5 x SimplicialLLT; factor <= 2 x CHOLMOD and "
                 "solve <= 1.2 x CHOLMOD on 3D elasticity with >= 100k unknowns\n";
    table.write_csv(run.file("goals_table.csv"));

    // Charts over all matrices: factor time against flops (the slope is the rate), solve time
    // against nnz(L) (a solve reads L twice). One point per matrix, as markers: a line joining
    // different matrices would suggest a trend between them that is not there.
    fig::LineChart factor{"Numeric factorization: time against flops, all matrices", "flops of the factorization",
                          "factor time [s]", true, true, {}};
    fig::LineChart solve{"Solve (one right-hand side): time against nnz(L), all matrices", "nnz(L)",
                         "solve time [s]", true, true, {}};
    std::map<std::string, std::vector<std::pair<double, double>>> factor_points, solve_points;
    std::vector<std::string> names;
    for (const SpeedRecord& r : records) {
        if (r.m.status != "ok")
            continue;
        const std::string name = r.m.solver + (r.m.ordering.rfind("CHOLMOD", 0) == 0 ? " (own ordering)"
                                              : r.m.solver.rfind("CHOLMOD", 0) == 0 ? " (same P)" : "");
        if (factor_points.find(name) == factor_points.end())
            names.push_back(name);
        factor_points[name].push_back({r.m.flops, r.m.factor});
        solve_points[name].push_back({r.m.nonzeros, r.m.solve});
    }
    const auto series = [](const std::string& name, std::vector<std::pair<double, double>> points) {
        std::sort(points.begin(), points.end());
        fig::Series line{name, {}, {}, true};
        for (const auto& [x, y] : points) {
            line.x.push_back(x);
            line.y.push_back(y);
        }
        return line;
    };
    for (const std::string& name : names) {
        factor.series.push_back(series(name, factor_points[name]));
        solve.series.push_back(series(name, solve_points[name]));
    }
    factor.legend = solve.legend = fig::Corner::top_left;
    fig::save_chart(factor, run.out_dir / "factor_times", run.figures);
    fig::save_chart(solve, run.out_dir / "solve_times", run.figures);
}

// --- 5. Factor once, solve many ----------------------------------------------------------------

void solve_many_study(const RunContext& run)
{
    const int cells = run.quick ? 5 : 20;
    const int steps = 100, block = 20;
    const sparse::CscMatrix K = box_stiffness(cells, rubber);
    const Eigen::MatrixXd B = random_matrix(K.rows, steps, 11);
    Timer timer;
    SparseCholesky chol(K);
    const double construct = timer.seconds();
    const double analyse = chol.times().ordering + chol.times().symbolic, numeric = chol.times().numeric;
    Eigen::MatrixXd X(K.rows, steps);
    const double one_at_a_time = timed([&] {
        for (int c = 0; c < steps; ++c)
            X.col(c) = chol.solve(Eigen::VectorXd(B.col(c)));
    });
    Eigen::MatrixXd Y(K.rows, steps);
    const double blocked = timed([&] {
        for (int c = 0; c < steps; c += block)
            Y.middleCols(c, block) = chol.solve_many(B.middleCols(c, block));
    });
    double worst = 0.0;
    for (int c = 0; c < steps; ++c)
        worst = std::max(worst, symmetric_residual(K, Y.col(c), B.col(c)));
    Table table(str("Factor once, solve many: ", steps, " right-hand sides, 3D elasticity, ", cells, "^3 cubes, ",
                    K.rows, " unknowns (largest residual ", std::scientific, std::setprecision(2), worst, ")"),
                {{"work", Format::text}, {"right-hand sides", Format::integer}, {"time [s]", Format::scientific, 3},
                 {"per right-hand side [s]", Format::scientific, 3}});
    const Cell none = std::string("-");
    table.add_row({std::string("analyse: ordering + symbolic (once)"), none, analyse, none});
    table.add_row({std::string("numeric factorization (once)"), none, numeric, none});
    table.add_row({std::string("solve, one right-hand side at a time"), double(steps), one_at_a_time, one_at_a_time / steps});
    table.add_row({str("solve_many, ", block, " right-hand sides at a time"), double(steps), blocked, blocked / steps});
    table.add_row({std::string("factor once + solve each"), double(steps), construct + one_at_a_time,
                   (construct + one_at_a_time) / steps});
    table.add_row({std::string("factor every step (from one factorization's time)"), double(steps),
                   steps * (construct + one_at_a_time / steps), construct + one_at_a_time / steps});
    table.print(std::cout);
    table.write_csv(run.file("solve_many_table.csv"));
}

// --- 5b. Threads ------------------------------------------------------------------------------

/// The supernodal factorization and a solve on 1 and 2 threads (threads_table: quiet and beside a
/// busy core, the bits compared), on the stiffness matrix of a box of 25³ cubes (50,700 unknowns;
/// quick: 5³). docs/08_direct_solvers.md#threads
void threads_study(const RunContext& run)
{
    const int cells = run.quick ? 5 : 25;
    const double seconds = run.quick ? 0.2 : 3.0;
    const sparse::CscMatrix K = box_stiffness(cells, rubber);
    const Eigen::VectorXd b = random_vector(K.rows, 12);
    SparseCholesky chol(K);
    const Table factor = threads_table(
        str("Supernodal numeric factorization (+ one solve, whose x is compared) on 1 and 2 threads, 3D elasticity, ",
            cells, "^3 cubes, ", K.rows, " unknowns"),
        [&] {
            chol.factorize(K);
            return chol.solve(b);
        },
        seconds);
    factor.print(std::cout);
    factor.write_csv(run.file("threads_factor_table.csv"));

    // Where the two threads gain: the factorization's phases (CholeskyTimes), medians of the calls
    // made in `seconds` on each count.
    Table phases(str("The factorization's two phases on 1 and 2 threads (medians), same matrix: the subtrees side by "
                     "side, then the top supernodes one after another"),
                 {{"threads", Format::integer},
                  {"factorization [s]", Format::scientific, 3},
                  {"subtrees [s]", Format::scientific, 3},
                  {"top supernodes [s]", Format::scientific, 3},
                  {"subtrees: speed-up [measured]", Format::fixed, 2},
                  {"top: speed-up [measured]", Format::fixed, 2},
                  {"top: share of the time [measured]", Format::fixed, 2}});
    double one_thread_subtrees = 0.0, one_thread_top = 0.0;
    for (const int threads : {1, 2}) {
        const ScopedThreadCount scope(threads);
        std::vector<double> numeric, subtrees, top;
        const Timer measuring;
        while (numeric.size() < 3 || measuring.seconds() < seconds) {
            chol.factorize(K);
            numeric.push_back(chol.times().numeric);
            subtrees.push_back(chol.times().numeric_subtrees);
            top.push_back(chol.times().numeric_top);
        }
        const double subtree_time = median(subtrees), top_time = median(top), numeric_time = median(numeric);
        if (threads == 1) {
            one_thread_subtrees = subtree_time;
            one_thread_top = top_time;
        }
        phases.add_row({double(threads), numeric_time, subtree_time, top_time, one_thread_subtrees / subtree_time,
                        one_thread_top / top_time, top_time / numeric_time});
    }
    phases.print(std::cout);
    phases.write_csv(run.file("threads_phases_table.csv"));
    const Table solve = threads_table(
        str("Supernodal solve (forward and back substitution, one right-hand side) on 1 and 2 threads, same matrix"),
        [&] { return chol.solve(b); }, seconds);
    solve.print(std::cout);
    solve.write_csv(run.file("threads_solve_table.csv"));
}

// --- 6. When a direct solver must refuse -------------------------------------------------------

void failures_study(const RunContext& run)
{
    Table table("Singular and indefinite matrices: every solver refuses with the column it failed at",
                {{"matrix", Format::text}, {"solver", Format::text}, {"outcome", Format::text}});
    const auto outcome = [](const std::function<void()>& work) -> std::string {
        try {
            work();
        } catch (const Error& e) {
            return str("fem::Error: ", e.what());
        }
        return "solved";
    };
    Eigen::MatrixXd rank_two(3, 3);
    rank_two << 1, 2, 3, 4, 5, 6, 7, 8, 9;
    table.add_row({std::string("[1 2 3; 4 5 6; 7 8 9] (rank 2)"), std::string("dense LU"),
                   outcome([&] { lu_factor(rank_two); })});
    table.add_row({std::string("Hilbert, n = 14 (kappa eps = 1e4)"), std::string("dense LU"),
                   outcome([&] { lu_factor(hilbert_matrix(14)); })});
    table.add_row({std::string("Hilbert, n = 13"), std::string("dense Cholesky"),
                   outcome([&] { cholesky_factor(hilbert_matrix(13)); })});
    Eigen::MatrixXd indefinite(2, 2);
    indefinite << 1, 2, 2, 1;
    table.add_row({std::string("[1 2; 2 1] (eigenvalues 3, -1)"), std::string("dense Cholesky"),
                   outcome([&] { cholesky_factor(indefinite); })});
    sparse::CscMatrix negative = laplacian_2d(8);
    for (int k = negative.IA[17]; k < negative.IA[18]; ++k)
        if (negative.JA[k] == 17)
            negative.A[k] = -1.0;
    for (Ordering o : {Ordering::natural, Ordering::nested_dissection})
        table.add_row({std::string("2D Laplacian 8x8 with a_17,17 = -1"), str("sparse up-looking, ", ordering_name(o)),
                       outcome([&] { SparseCholesky(negative, {o, Factorization::up_looking}); })});
    const TetMesh free_box = box_mesh(3, 3, 3);
    const sparse::CscMatrix K_free = sparse::csc_from_eigen(assembly::stiffness_matrix(free_box, rubber));
    table.add_row({std::string("K of a free box (nothing pinned: 6 rigid modes)"),
                   std::string("sparse up-looking, minimum degree"),
                   outcome([&] { SparseCholesky(K_free, {Ordering::minimum_degree, Factorization::up_looking}); })});
    {
        // Eigen checks only for pivots ≤ 0: on a singular matrix it may go on and return a huge x.
        const Eigen::SparseMatrix<double> E = sparse::to_eigen(K_free);
        Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> llt(E);
        std::string text = "NumericalIssue (a pivot <= 0)";
        if (llt.info() == Eigen::Success) {
            const Eigen::VectorXd b = Eigen::VectorXd::Ones(E.rows());
            text = str("factored; x for b = (1, ..., 1) has |x| = ", std::scientific, std::setprecision(1),
                       llt.solve(b).norm(), " (a silent wrong answer)");
        }
        table.add_row({std::string("K of a free box (nothing pinned: 6 rigid modes)"),
                       std::string("Eigen SimplicialLLT"), text});
    }
    table.print(std::cout);
    table.write_csv(run.file("failures_table.csv"));
}

// --- 7. The box under gravity, solved with our Cholesky ------------------------------------------

void box_under_gravity(const RunContext& run)
{
    const int cells = run.quick ? 4 : 16;
    const double density = 1000.0;
    const TetMesh mesh = box_mesh(cells, cells, cells);
    const assembly::SparseMatrix K = assembly::stiffness_matrix(mesh, rubber);
    const assembly::SparseMatrix P =
        assembly::free_selection_matrix(static_cast<int>(mesh.V.rows()), assembly::vertices_on_plane(mesh, 0, 0.0));
    const assembly::SparseMatrix K_free = assembly::reduce(K, P);
    const Eigen::VectorXd f_free = P.transpose() * assembly::gravity_load(mesh, density);
    const SparseCholesky chol(K_free);
    const Eigen::VectorXd u = assembly::expand(P, chol.solve(f_free));
    const MatrixX3d displacement = io::vertex_rows(u);
    const io::MeshData data = io::displaced_mesh(mesh.V, mesh.T, displacement);
    io::write_vtu(run.file("box_displacement.vtu"), data);
    std::cout << "\nbox_displacement.vtu: a rubber cube of " << cells << "^3 cubes clamped at x = 0 under gravity, "
              << K_free.rows() << " unknowns, solved with SparseCholesky (nnz(L) = " << chol.factor_nonzeros()
              << "); largest |u| = " << displacement.rowwise().norm().maxCoeff() << " m\n";
    if (run.figures) {
        fig::RenderOptions options;
        options.view_direction = {0.4, 1.0, -0.3};
        options.view_up = {0.0, 0.0, 1.0};
        options.field = "displacement";
        options.unit = "m";
        options.title = "rubber cube clamped at x = 0, sagging under gravity (true scale): |u| [m]";
        options.height = 620;
        fig::render_mesh_png(run.file("box_displacement.png"), io::warped(data), options);
    }
}

}  // namespace

int main(int argc, char** argv)
{
    ChapterCli cli("ch08_direct_solvers", "08_direct_solvers",
                   "Chapter 08: dense LU and Cholesky, orderings, sparse Cholesky against Eigen and CHOLMOD");
    Settings settings;
    cli.app.add_option("--max-unknowns", settings.max_unknowns, "Skip sparse matrices with more unknowns")
        ->check(check::integer(1, 100000000))->capture_default_str();
    cli.app.add_option("--simplicial-flops", settings.simplicial_flops,
                       "Run the scalar factorizations (ours up-looking, Eigen SimplicialLLT) only below this many flops")
        ->check(check::non_negative())->capture_default_str();
    int blas_threads = 1;
    cli.app.add_option("--blas-threads", blas_threads,
                       "Threads of CHOLMOD's BLAS (1: one core against our one core)")
        ->check(check::integer(1, 256))->capture_default_str();
    return cli.run(argc, argv, [&](const RunContext& run) {
#ifdef FEM_HAVE_CHOLMOD
        set_blas_threads(blas_threads);
#else
        (void)blas_threads;
#endif
        dense_study(run);
        hilbert_study(run);
        ordering_study(run, settings);
        pattern_figure(run);
        {
            const ScopedThreadCount one_core(1);  // the speed tables compare one core with one core
            goals_table(run, speed_study(run, settings));
            solve_many_study(run);
        }
        threads_study(run);
        failures_study(run);
        box_under_gravity(run);
    });
}
