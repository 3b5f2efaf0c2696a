// ch09_conjugate_gradient: 5. hard cases: indefinite and singular matrices through every solver.
// docs/09_conjugate_gradient.md
#include "studies.hpp"

#include "06_assembly/assembly.hpp"

#include "common/error.hpp"
#include "common/table.hpp"

#include <algorithm>
#include <iostream>
#include <tuple>

namespace fem::cg::study {
namespace {

/// The message of an fem::Error up to its second ": " or first "; " (what failed and where, without
/// the advice that follows).
std::string short_message(const std::string& message)
{
    const auto first = message.find(": ");
    const auto second = first == std::string::npos ? first : message.find(": ", first + 2);
    return message.substr(0, std::min(second, message.find("; ")));
}

}  // namespace

void hard_cases_study(const RunContext& run, const Settings& settings)
{
    const int cells = 3;
    const elastic::Lame material = elastic::lame_parameters(settings.youngs, settings.poisson);
    const ElasticBox box = clamped_box(cells, material, settings.density);
    // Indefinite: K − σ I with σ = 10 λ_min, between the smallest eigenvalues (estimated by CG).
    Eigen::VectorXd probe;
    const CgResult estimate = conjugate_gradient(EigenOperator(box.K), box.f, probe);
    const double sigma = 10.0 * lanczos_extreme_eigenvalues(estimate).lambda_min;
    Eigen::SparseMatrix<double> identity(box.K.rows(), box.K.rows());
    identity.setIdentity();
    const Eigen::SparseMatrix<double> shifted = box.K - sigma * identity;
    // Singular: K of the free box (nothing pinned): six rigid motions, and a load with a net force.
    const Eigen::SparseMatrix<double> free_K = assembly::stiffness_matrix(box.mesh, material);
    const Eigen::VectorXd free_f = assembly::gravity_load(box.mesh, settings.density);

    Table table("Hard cases: what every solver says about a matrix that is not positive definite",
                {{"matrix", Format::text}, {"solver", Format::text}, {"outcome", Format::text}});
    const std::vector<std::tuple<std::string, const Eigen::SparseMatrix<double>*, const Eigen::VectorXd*>> cases{
        {str("K - sigma I, indefinite (", cells, " cells)"), &shifted, &box.f},
        {str("K without pinned vertices, singular (", cells, " cells)"), &free_K, &free_f}};
    for (const auto& [name, A, b] : cases) {
        for (const std::string& solver_name : solver_names()) {
            const std::unique_ptr<LinearSolver> solver = make_solver(solver_name);
            std::string outcome;
            try {
                solver->prepare(*A);
                const Eigen::VectorXd x = solver->solve(*b);
                outcome = str("no error: relative residual ", scientific(solver->relative_residual()),
                              ", |x| = ", scientific(x.norm()));
            } catch (const Error& e) {
                std::cout << solver_name << " on " << name << ": " << e.what() << '\n';
                outcome = "fem::Error: " + short_message(e.what());
            }
            table.add_row({name, solver_name, outcome});
        }
    }
    table.print(std::cout);
    table.write_csv(run.file("hard_cases_table.csv"));
}

}  // namespace fem::cg::study
