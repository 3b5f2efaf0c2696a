#pragma once
// The studies of ch08_direct_solvers, one file each (study_*.cpp), called in order by main.cpp, and
// what several of them share (study_support.cpp): the sparse test matrices, the timers and
// CHOLMOD, the reference. Not part of the chapter's library: only the executable uses them.

#include "08_direct_solvers/model_problems.hpp"
#include "08_direct_solvers/sparse_cholesky.hpp"

#include "05_strain_stress/strain_stress.hpp"
#include "07_sparse_storage/sparse_formats.hpp"

#include "common/cli.hpp"
#include "common/timer.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace fem::direct::study {

/// The executable's options (main.cpp checks them before any study runs).
struct Settings {
    long long max_unknowns = 200000;  // matrices above this size are skipped
    double simplicial_flops = 4e9;    // the scalar factorizations run only below this many flops
};

/// The material of the elasticity matrices: Y = 10⁵ Pa, ν = 0.45.
inline const elastic::Lame rubber = elastic::lame_parameters(1e5, 0.45);
/// The unit round-off of a double.
inline constexpr double eps = std::numeric_limits<double>::epsilon();

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
                                                 double min_seconds = 0.3, int max_rounds = 5);

// --- The sparse test matrices ------------------------------------------------------------------

/// One sparse test matrix of a family, in our format and Eigen's.
struct Problem {
    std::string family;  ///< "2D Laplacian", "3D Laplacian", "3D elasticity"
    int size = 0;        ///< n of the grid, or cubes per side of the box
    sparse::CscMatrix A;
    Eigen::SparseMatrix<double> E;  ///< the same matrix for Eigen and CHOLMOD
};

/// The families of test matrices, in the tables' order.
inline const char* const families[] = {"2D Laplacian", "3D Laplacian", "3D elasticity"};

/// The sizes of a family's matrices: about 10k, 50k and 160k unknowns (quick: a few hundred to a
/// few thousand).
std::vector<int> family_sizes(const std::string& family, bool quick);
/// The unknowns of a family's matrix of this size: n², n³, or 3 n (n+1)² (the box without its pinned face).
long long family_unknowns(const std::string& family, int size);
/// The family's matrix of this size: laplacian_2d, laplacian_3d or box_stiffness of rubber.
Problem make_problem(const std::string& family, int size);
/// The size as the tables write it: "100^2", "22^3" or "14^3 cubes".
std::string size_text(const Problem& p);
/// The entries of A's lower triangle, the diagonal included.
long long lower_nonzeros(const sparse::CscMatrix& A);

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
/// A (lower triangle read) factored by CHOLMOD with its own ordering choice (natural = false), or
/// in the given numbering (natural = true: A is already permuted). analyse_only skips the
/// numeric work (for the ordering table).
/// With other_solve, the solve is timed in alternation with it (best of each: other_solve_time).
CholmodResult run_cholmod(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b, bool natural,
                          bool analyse_only = false, const std::function<void()>& other_solve = {});
#endif

// --- The studies, in the order main.cpp runs them ------------------------------------------------

/// One row of the speed table.
struct Measured {
    std::string solver, ordering, status = "ok";
    double nonzeros = 0.0, flops = 0.0, analyse = 0.0, factor = 0.0, solve = 0.0, residual = 0.0, error = 0.0;
};

/// A row of the speed table with the matrix it was measured on.
struct SpeedRecord {
    std::string family;
    double unknowns;
    Measured m;
};

/// 1. Dense LU and Cholesky on random matrices against Eigen: times, rates, residuals.
void dense_study(const RunContext& run);
/// 2. The Hilbert matrices: each solver's error against the condition number.
void hilbert_study(const RunContext& run);
/// 3. Fill-reducing orderings: nnz(L) and flops of each ordering on every test matrix.
void ordering_study(const RunContext& run, const Settings& settings);
/// 3b. The patterns of L (entries of A and fill) of a small 2D Laplacian in four orderings.
void pattern_figure(const RunContext& run);
/// 4. Speed against error: our Cholesky, Eigen's SimplicialLLT and CHOLMOD on every test matrix.
std::vector<SpeedRecord> speed_study(const RunContext& run, const Settings& settings);
/// 4b. The performance goals of the chapter, side by side (never asserted).
void goals_table(const RunContext& run, const std::vector<SpeedRecord>& records);
/// 5. Factor once, solve many: the factorization against the solves it pays for.
void solve_many_study(const RunContext& run);
/// 5b. The supernodal factorization and a solve on 1 and 2 threads.
void threads_study(const RunContext& run);
/// 6. Singular and indefinite matrices: every solver refuses with the column it failed at.
void failures_study(const RunContext& run);
/// 7. The box under gravity, solved with our Cholesky (box_displacement.vtu/.png).
void box_under_gravity(const RunContext& run);

}  // namespace fem::direct::study
