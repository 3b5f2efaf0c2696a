// ch08_direct_solvers: 7. the box under gravity, solved with our Cholesky.
// docs/08_direct_solvers.md
#include "studies.hpp"

#include "06_assembly/assembly.hpp"

#include "common/figures.hpp"
#include "common/mesh.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"
#include "common/vtk_io.hpp"

#include <iostream>

namespace fem::direct::study {

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

}  // namespace fem::direct::study
