#pragma once
// The studies of ch09_conjugate_gradient, one file each (study_*.cpp), called in order by main.cpp,
// and what several of them share (study_support.cpp): the test problems and our iterative methods.
// Not part of the chapter's library: only the executable uses them.

#include "09_conjugate_gradient/conjugate_gradient.hpp"
#include "09_conjugate_gradient/linear_operator.hpp"
#include "09_conjugate_gradient/linear_solver.hpp"
#include "09_conjugate_gradient/model_problems.hpp"
#include "09_conjugate_gradient/preconditioners.hpp"

#include "05_strain_stress/strain_stress.hpp"
#include "07_sparse_storage/sparse_formats.hpp"

#include "common/cli.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <string>
#include <vector>

namespace fem::cg::study {

/// The executable's options (main.cpp checks them before any study runs).
struct Settings {
    std::vector<int> lap2{32, 100, 224, 388};   // 2D Laplacians: n² unknowns (1k … 150k)
    std::vector<int> lap3{10, 22, 37, 54};      // 3D Laplacians: n³ unknowns (1k … 157k)
    std::vector<int> cells{4, 8, 14, 25, 37};   // elastic boxes: 3 c (c+1)² unknowns (300 … 160k)
    std::vector<double> tolerances{1e-2, 1e-4, 1e-6, 1e-8, 1e-10};
    int llt_max_3d = 12000;   // Eigen's SimplicialLLT on 3D problems up to this many unknowns
    int ours_max_3d = 60000;  // our sparse Cholesky on 3D problems up to this many (with CHOLMOD there)
    int eigen_sweep_max = 100000;  // Eigen's CG at every tolerance up to this many unknowns
    double youngs = 1e5;      // Y [Pa] of the box (rubber)
    double poisson = 0.45;    // ν of the box
    double density = 1000.0;  // ρ [kg/m³]
    double seconds = 0.3;     // measuring time per timed run (the best run counts)
};

/// The tolerance of the crossover and of the PCG-against-Eigen comparison: the interface's default.
constexpr double comparison_tolerance = default_relative_tolerance;

/// What each study solves: A x = b with A symmetric positive definite.
struct Problem {
    std::string key;    // lap2, lap3, box
    std::string label;  // for tables
    bool three_d = false;
    Eigen::SparseMatrix<double> A;
    Eigen::VectorXd b;
};

/// The problem of a key and size: "lap2" (laplacian_2d(size), a uniform source), "lap3"
/// (laplacian_3d(size), a uniform source) or "box" (clamped_box of size cubes a side, of the
/// settings' material, under its weight).
Problem make_problem(const std::string& key, int size, const Settings& settings);

/// value in scientific notation without digits after the point: "1e-06".
std::string scientific(double value);

/// ‖x − reference‖₂ / ‖reference‖₂.
double relative_error(const Eigen::VectorXd& x, const Eigen::VectorXd& reference);

// --- our iterative methods, one place that builds them --------------------------------------------

/// Our CG variants on the stored lower triangle (the fastest product, section 2).
struct OurMethod {
    std::string name;  // CG, PCG-Jacobi, PCG-IC0
    std::unique_ptr<LinearOperator> preconditioner;
    double setup_seconds = 0.0;
};

/// The names make_method knows, in the tables' order.
inline const std::vector<std::string> our_methods{"CG", "PCG-Jacobi", "PCG-IC0"};

/// What a figure calls a solver: the tables name the direct ones by make_solver's keys
/// ("eigen-llt"), which a legend beside "ours CG" and "Eigen CG (diagonal)" should not.
std::string figure_label(const std::string& solver);

/// The method of a name of our_methods for the matrix csr: its preconditioner built (and timed).
OurMethod make_method(const std::string& name, const sparse::CsrMatrix& csr);

/// CG, or PCG with the method's preconditioner, on A x = b from x.
CgResult run_method(const LinearOperator& A, const OurMethod& method, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                    const CgSettings& settings);

// --- The studies, in the order main.cpp runs them ------------------------------------------------

/// 1. Convergence against conditioning: CG iterations against κ on Laplacians of growing size.
void conditioning_study(const RunContext& run);
/// 2. The operator: one product y = A x through each representation.
void operator_study(const RunContext& run, const Settings& settings);
/// 3. Preconditioners on the elastic box and a Laplacian: iterations, κ(M⁻¹A), times, histories.
void preconditioner_study(const RunContext& run, const Settings& settings);
/// 3b. Kershaw's matrix and boxes of rising Poisson ratio: when IC(0) breaks down, and the shift.
void ic0_shift_study(const RunContext& run, const Settings& settings);
/// 4. Speed against error: every solver on every problem; the crossover; ours against Eigen's CG.
void speed_against_error_study(const RunContext& run, const Settings& settings);
/// 5. Hard cases: indefinite and singular matrices through every solver.
void hard_cases_study(const RunContext& run, const Settings& settings);
/// 6. CG smooths the error: the error on a grid after k iterations (VTK image + PNGs).
void error_snapshots(const RunContext& run);
/// 6b. The box sagging under its weight, solved by the default solver (VTK + PNG).
void box_picture(const RunContext& run, const Settings& settings);

}  // namespace fem::cg::study
