// The plain route of a corotational step (plain_routes.hpp): JacobiSVD per tet, triplet assembly,
// SimplicialLLT refactored every step. docs/11_corotational.md#making-it-fast
#include "11_corotational/plain_routes.hpp"

#include "11_corotational/corotational.hpp"

#include "06_assembly/assembly.hpp"
#include "04_tet_jacobians/tet_jacobians.hpp"

#include "common/error.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <Eigen/SparseCholesky>

namespace fem::corot::plain {

PlainCorotational::PlainCorotational(const TetMesh& mesh, const dynamics::Material& material, PlainRotation rotation)
    : mesh_(mesh), rotation_(rotation),
      K_e_(assembly::element_stiffnesses(mesh, elastic::lame_parameters(material.youngs_modulus, material.poisson_ratio))),
      rest_edges_inverse_(static_cast<std::size_t>(mesh.T.rows()))
{
    for (int t = 0; t < static_cast<int>(mesh.T.rows()); ++t)
        rest_edges_inverse_[static_cast<std::size_t>(t)] = tet::edge_matrix(tet::tet_vertices(mesh, mesh.V, t)).inverse();
}

const std::vector<Eigen::Matrix3d>& PlainCorotational::rotations_at(const Eigen::VectorXd& u)
{
    if (u.size() != 3 * mesh_.V.rows())
        throw Error(str("plain corotational model: the displacement has ", u.size(), " entries, expected 3n = ",
                        3 * mesh_.V.rows()));
    if (!rotations_.empty() && rotated_at_ == u)
        return rotations_;
    const std::size_t tets = static_cast<std::size_t>(mesh_.T.rows());
    std::vector<Eigen::Matrix3d> F(tets);
    for (std::size_t t = 0; t < tets; ++t) {
        Eigen::Matrix3d edges;  // column i: x_{i+1} − x₀, the deformed edges
        const Eigen::Index e = static_cast<Eigen::Index>(t);
        const Eigen::Vector3d x0 = mesh_.V.row(mesh_.T(e, 0)).transpose() + u.segment<3>(3 * mesh_.T(e, 0));
        for (int i = 0; i < 3; ++i)
            edges.col(i) = mesh_.V.row(mesh_.T(e, i + 1)).transpose() + u.segment<3>(3 * mesh_.T(e, i + 1)) - x0;
        F[t] = edges * rest_edges_inverse_[t];
    }
    rotations_.resize(tets);
    if (rotation_ == PlainRotation::polar_newton) {
        polar_rotations_newton(F.data(), rotations_.data(), tets);
    } else {
        for (std::size_t t = 0; t < tets; ++t) {
            const Eigen::JacobiSVD<Eigen::Matrix3d> svd(F[t], Eigen::ComputeFullU | Eigen::ComputeFullV);
            Eigen::Matrix3d U = svd.matrixU();
            if ((U * svd.matrixV().transpose()).determinant() < 0.0)
                U.col(2) = -U.col(2);  // a reflection: flip the direction of the smallest singular value
            rotations_[t] = U * svd.matrixV().transpose();
        }
    }
    rotated_at_ = u;
    return rotations_;
}

double PlainCorotational::evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& forces)
{
    const std::vector<Eigen::Matrix3d>& R = rotations_at(u);
    forces = Eigen::VectorXd::Zero(u.size());
    double energy = 0.0;
    for (Eigen::Index t = 0; t < mesh_.T.rows(); ++t) {
        const Eigen::Matrix3d& Rt = R[static_cast<std::size_t>(t)];
        Eigen::Matrix<double, 12, 1> d;
        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
        for (int i = 0; i < 4; ++i) {
            const Eigen::Vector3d X = mesh_.V.row(mesh_.T(t, i)).transpose();
            d.segment<3>(3 * i) = Rt.transpose() * (X + u.segment<3>(3 * mesh_.T(t, i))) - X;
            mean += 0.25 * d.segment<3>(3 * i);
        }
        for (int i = 0; i < 4; ++i)
            d.segment<3>(3 * i) -= mean;
        const Eigen::Matrix<double, 12, 1> local = K_e_[static_cast<std::size_t>(t)] * d;
        energy += 0.5 * d.dot(local);
        for (int i = 0; i < 4; ++i)
            forces.segment<3>(3 * mesh_.T(t, i)) -= Rt * local.segment<3>(3 * i);
    }
    return energy;
}

const dynamics::SparseMatrix& PlainCorotational::stiffness(const Eigen::VectorXd& u)
{
    const std::vector<Eigen::Matrix3d>& R = rotations_at(u);
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(static_cast<std::size_t>(144 * mesh_.T.rows()));
    for (Eigen::Index t = 0; t < mesh_.T.rows(); ++t) {
        const Eigen::Matrix3d& Rt = R[static_cast<std::size_t>(t)];
        const auto& K_e = K_e_[static_cast<std::size_t>(t)];
        for (int a = 0; a < 4; ++a)
            for (int b = 0; b < 4; ++b) {
                const Eigen::Matrix3d block = Rt * K_e.block<3, 3>(3 * a, 3 * b) * Rt.transpose();
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 3; ++j)
                        triplets.emplace_back(3 * mesh_.T(t, a) + i, 3 * mesh_.T(t, b) + j, block(i, j));
            }
    }
    K_R_.resize(u.size(), u.size());
    K_R_.setFromTriplets(triplets.begin(), triplets.end());
    return K_R_;
}

Eigen::VectorXd PlainCorotational::von_mises_stress(const Eigen::VectorXd&) const
{
    return Eigen::VectorXd::Zero(mesh_.T.rows());
}

namespace {

/// SimplicialLLT::compute on every prepare: nothing of the last factorization is reused.
class PlainCholesky final : public cg::LinearSolver {
public:
    PlainCholesky() : LinearSolver("eigen-llt, refactored") {}
    bool is_direct() const override { return true; }

private:
    void do_prepare(const Eigen::SparseMatrix<double>& A, bool) override
    {
        factor_.compute(A);
        if (factor_.info() != Eigen::Success)
            throw Error(str(name(), ": the Cholesky factorization failed: the matrix is not positive definite"));
    }
    int do_solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override
    {
        x = factor_.solve(b);
        return 0;
    }
    Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> factor_;
};

}  // namespace

std::unique_ptr<cg::LinearSolver> plain_cholesky()
{
    return std::make_unique<PlainCholesky>();
}

dynamics::ImplicitOptions plain_step_options()
{
    dynamics::ImplicitOptions options;
    options.make_solver = [] { return plain_cholesky(); };
    return options;
}

}  // namespace fem::corot::plain
