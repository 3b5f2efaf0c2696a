// ch08_direct_solvers: 4. speed against error: our sparse Cholesky against Eigen's SimplicialLLT
// and CHOLMOD, the factorization's rate against one core's dgemm on the shapes of its supernodes,
// and the chapter's goals side by side. docs/08_direct_solvers.md
#include "studies.hpp"

#include "08_direct_solvers/supernodal.hpp"

#include "common/figures.hpp"
#include "common/random.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <Eigen/SparseCholesky>

#if __has_include(<dlfcn.h>)
#include <dlfcn.h>
#define FEM_HAVE_DLSYM 1
#endif

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <optional>

namespace fem::direct::study {
namespace {

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

}  // namespace

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

}  // namespace fem::direct::study
