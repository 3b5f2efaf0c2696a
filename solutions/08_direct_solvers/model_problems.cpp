// Chapter 08: the test matrices: 2D and 3D Laplacians and the stiffness matrix of a box.
// docs/08_direct_solvers.md#the-test-matrices
#include "08_direct_solvers/model_problems.hpp"

#include "02_heat_equation/heat_grid.hpp"
#include "06_assembly/assembly.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"

namespace fem::direct {

sparse::CscMatrix laplacian_2d(int n)
{
    heat::Grid grid;
    grid.n = n;
    heat::validate(grid);
    const Eigen::SparseMatrix<double> L = heat::laplacian_matrix(grid);
    return sparse::csc_from_eigen(-L);
}

sparse::CscMatrix laplacian_3d(int n)
{
    if (n < 1 || n > 1000)
        throw Error(str("laplacian_3d: n = ", n, "; allowed 1 ≤ n ≤ 1000"));
    const double h = 1.0 / (n + 1);
    const double scale = 1.0 / (h * h);
    const int unknowns = n * n * n;
    sparse::CooMatrix coo;
    coo.rows = coo.cols = unknowns;
    const auto index = [n](int i, int j, int l) { return i + n * (j + n * l); };
    for (int l = 0; l < n; ++l)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const int k = index(i, j, l);
                coo.add(k, k, 6.0 * scale);
                if (i > 0) coo.add(k, index(i - 1, j, l), -scale);
                if (i + 1 < n) coo.add(k, index(i + 1, j, l), -scale);
                if (j > 0) coo.add(k, index(i, j - 1, l), -scale);
                if (j + 1 < n) coo.add(k, index(i, j + 1, l), -scale);
                if (l > 0) coo.add(k, index(i, j, l - 1), -scale);
                if (l + 1 < n) coo.add(k, index(i, j, l + 1), -scale);
            }
    return sparse::csr_to_csc(sparse::coo_to_csr(coo));
}

sparse::CscMatrix box_stiffness(int cells, const elastic::Lame& material)
{
    if (cells < 1 || cells > 200)
        throw Error(str("box_stiffness: cells = ", cells, "; allowed 1 ≤ cells ≤ 200"));
    const TetMesh mesh = box_mesh(cells, cells, cells);
    const assembly::SparseMatrix K = assembly::stiffness_matrix(mesh, material);
    const assembly::SparseMatrix P = assembly::free_selection_matrix(
        static_cast<int>(mesh.V.rows()), assembly::vertices_on_plane(mesh, 0, 0.0));
    return sparse::csc_from_eigen(assembly::reduce(K, P));
}

}  // namespace fem::direct
