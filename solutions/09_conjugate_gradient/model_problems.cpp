// Chapter 09: the test matrices. docs/09_conjugate_gradient.md#the-test-problems
#include "09_conjugate_gradient/model_problems.hpp"

#include "06_assembly/assembly.hpp"
#include "07_sparse_storage/sparse_formats.hpp"
#include "08_direct_solvers/model_problems.hpp"
#include "common/error.hpp"

#include <cmath>
#include <numbers>

namespace fem::cg {

double laplacian_condition_number(int n)
{
    if (n < 1)
        throw Error(str("laplacian_condition_number: needs n ≥ 1, got ", n));
    const double half_angle = std::numbers::pi / (2.0 * (n + 1));
    const double cotangent = std::cos(half_angle) / std::sin(half_angle);
    return cotangent * cotangent;
}

ElasticBox clamped_box(int cells, const elastic::Lame& material, double density)
{
    if (cells < 1 || cells > 200)
        throw Error(str("clamped_box: cells = ", cells, "; allowed 1 ≤ cells ≤ 200"));
    require_positive(density, "clamped_box: the density");
    elastic::require_stable(material);
    ElasticBox box;
    box.mesh = box_mesh(cells, cells, cells);
    box.pinned = assembly::vertices_on_plane(box.mesh, 0, 0.0);
    box.P = assembly::free_selection_matrix(static_cast<int>(box.mesh.V.rows()), box.pinned);
    box.K = sparse::to_eigen(direct::box_stiffness(cells, material));  // Pᵀ K P, the same P
    box.K.makeCompressed();
    box.f = box.P.transpose() * assembly::gravity_load(box.mesh, density);
    return box;
}

}  // namespace fem::cg
