// ch08_direct_solvers: 6. the singular and indefinite matrices a direct solver must refuse.
// docs/08_direct_solvers.md
#include "studies.hpp"

#include "08_direct_solvers/dense_solvers.hpp"

#include "06_assembly/assembly.hpp"

#include "common/error.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>

#include <iomanip>
#include <iostream>

namespace fem::direct::study {

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

}  // namespace fem::direct::study
