// The plain route of a hyperelastic Newton step (plain_routes.hpp): dense element products, a
// 9×9 eigensolver for the definite Hessian, triplet assembly, SimplicialLLT refactored every
// iteration. docs/12_hyperelastic_newton.md#making-it-fast
#include "12_hyperelastic_newton/plain_routes.hpp"

#include "11_corotational/plain_routes.hpp"

#include "common/error.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <cmath>

namespace fem::hyper::plain {

namespace {

// fem::Error unless u holds one displacement per vertex of mesh (3n entries).
void require_displacement_of(const TetMesh& mesh, const Eigen::VectorXd& u)
{
    if (u.size() != 3 * mesh.V.rows())
        throw Error(str("plain hyperelastic model: the displacement has ", u.size(), " entries, expected 3n = ",
                        3 * mesh.V.rows()));
}

}  // namespace

PlainHyperelastic::PlainHyperelastic(const TetMesh& mesh, std::unique_ptr<Material> material)
    : mesh_(mesh), material_(std::move(material)), volumes_(mesh.T.rows())
{
    if (!material_)
        throw Error("PlainHyperelastic: no material");
    for (int t = 0; t < static_cast<int>(mesh.T.rows()); ++t) {
        const tet::TetVertices X = tet::tet_vertices(mesh, mesh.V, t);
        B_.push_back(tet::jacobian_matrix(X));  // fem::Error for a zero-volume tet
        rest_edges_inverse_.push_back(tet::edge_matrix(X).inverse());
        volumes_[t] = std::abs(tet::signed_volume(X));
    }
}

Eigen::Matrix3d PlainHyperelastic::displacement_gradient(const Eigen::VectorXd& u, Eigen::Index t) const
{
    Eigen::Matrix3d edges;  // column i: u_{i+1} − u₀
    for (int i = 0; i < 3; ++i)
        edges.col(i) = u.segment<3>(3 * mesh_.T(t, i + 1)) - u.segment<3>(3 * mesh_.T(t, 0));
    return edges * rest_edges_inverse_[static_cast<std::size_t>(t)];
}

double PlainHyperelastic::evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& forces)
{
    require_displacement_of(mesh_, u);
    forces = Eigen::VectorXd::Zero(u.size());
    double energy = 0.0;
    for (Eigen::Index t = 0; t < mesh_.T.rows(); ++t) {
        const Eigen::Matrix3d H = displacement_gradient(u, t);
        energy += volumes_[t] * material_->energy_density(H);
        const Eigen::Matrix<double, 12, 1> f_e =
            -volumes_[t] * (B_[static_cast<std::size_t>(t)].transpose() * flatten(material_->first_piola(H)));
        for (int i = 0; i < 4; ++i)
            forces.segment<3>(3 * mesh_.T(t, i)) += f_e.segment<3>(3 * i);
    }
    return energy;
}

double PlainHyperelastic::energy(const Eigen::VectorXd& u)
{
    require_displacement_of(mesh_, u);
    double energy = 0.0;
    for (Eigen::Index t = 0; t < mesh_.T.rows(); ++t)
        energy += volumes_[t] * material_->energy_density(displacement_gradient(u, t));
    return energy;
}

const dynamics::SparseMatrix& PlainHyperelastic::hessian(const Eigen::VectorXd& u, bool definite)
{
    require_displacement_of(mesh_, u);
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(static_cast<std::size_t>(144 * mesh_.T.rows()));
    for (Eigen::Index t = 0; t < mesh_.T.rows(); ++t) {
        Matrix9d dP = material_->piola_derivative(displacement_gradient(u, t));
        if (definite) {
            const Eigen::SelfAdjointEigenSolver<Matrix9d> eigen(0.5 * (dP + dP.transpose()));
            dP = eigen.eigenvectors() * eigen.eigenvalues().cwiseMax(0.0).asDiagonal() * eigen.eigenvectors().transpose();
        }
        const tet::Jacobian& B = B_[static_cast<std::size_t>(t)];
        const Matrix12d K_e = volumes_[t] * (B.transpose() * dP * B);
        for (int a = 0; a < 4; ++a)
            for (int b = 0; b < 4; ++b)
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 3; ++j)
                        triplets.emplace_back(3 * mesh_.T(t, a) + i, 3 * mesh_.T(t, b) + j, K_e(3 * a + i, 3 * b + j));
    }
    K_.resize(u.size(), u.size());
    K_.setFromTriplets(triplets.begin(), triplets.end());
    return K_;
}

const dynamics::SparseMatrix& PlainHyperelastic::stiffness(const Eigen::VectorXd& u)
{
    return hessian(u, false);
}

const dynamics::SparseMatrix& PlainHyperelastic::definite_stiffness(const Eigen::VectorXd& u)
{
    return hessian(u, true);
}

Eigen::VectorXd PlainHyperelastic::von_mises_stress(const Eigen::VectorXd&) const
{
    return Eigen::VectorXd::Zero(mesh_.T.rows());
}

NewtonOptions plain_newton_options(NewtonOptions options)
{
    options.make_solver = [] { return corot::plain::plain_cholesky(); };
    return options;
}

}  // namespace fem::hyper::plain
