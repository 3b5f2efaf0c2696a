// Best-fit rotations of a tet: the reflection fix, the covariances of the edge and centroid fits,
// the SVD's best-fit rotation and the polar rotation of F (exercises 11.1–11.3), and how that
// rotation changes with F (exercise 11.8).
// docs/11_corotational.md#the-best-fit-rotation
#include "11_corotational/corotational.hpp"

#include "common/error.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>

namespace fem::corot {

Eigen::Matrix3d proper_rotation(Eigen::Matrix3d A, const Eigen::Matrix3d& B)
{
    // BEGIN EXERCISE 11.1 proper_rotation #reflections
    // HINT: If det(A Bᵀ) < 0, negate A's last column (the smallest singular value's); return A Bᵀ.
    if ((A * B.transpose()).determinant() < 0.0)
        A.col(2) = -A.col(2);
    return A * B.transpose();
    // END EXERCISE
}

Eigen::Matrix3d edge_covariance(const tet::TetVertices& X, const tet::TetVertices& x)
{
    Eigen::Matrix3d P, Q;
    for (int i = 0; i < 3; ++i) {
        P.row(i) = X.row(i + 1) - X.row(0);
        Q.row(i) = x.row(i + 1) - x.row(0);
    }
    return P.transpose() * Q;
}

Eigen::Matrix3d centroid_covariance(const tet::TetVertices& X, const tet::TetVertices& x)
{
    const Eigen::RowVector3d X_mean = X.colwise().mean(), x_mean = x.colwise().mean();
    return (X.rowwise() - X_mean).transpose() * (x.rowwise() - x_mean);
}

Eigen::Matrix3d best_fit_rotation(const Eigen::Matrix3d& S)
{
    if (!S.allFinite())
        throw Error("best-fit rotation: the edge covariance S has a non-finite entry");
    if (S.isZero(0.0))
        return Eigen::Matrix3d::Identity();
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(S, Eigen::ComputeFullU | Eigen::ComputeFullV);
    // BEGIN EXERCISE 11.2 best_fit_rotation #the-best-fit-rotation
    // HINT: S = U Σ Vᵀ. The rotation from rest to deformed is R = V Uᵀ (not the slide's U Vᵀ):
    // HINT: proper_rotation of V and U, which also fixes a reflection.
    return proper_rotation(svd.matrixV(), svd.matrixU());
    // END EXERCISE
}

Eigen::Matrix3d polar_rotation(const Eigen::Matrix3d& F)
{
    if (!F.allFinite())
        throw Error("polar rotation: F has a non-finite entry");
    if (F.isZero(0.0))
        return Eigen::Matrix3d::Identity();
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
    // BEGIN EXERCISE 11.3 polar_rotation #edges-centroid-or-polar-decomposition
    // HINT: F = U Σ Vᵀ = (U Vᵀ)(V Σ Vᵀ): the rotation is U Vᵀ, made proper by proper_rotation.
    return proper_rotation(svd.matrixU(), svd.matrixV());
    // END EXERCISE
}

Eigen::Matrix3d polar_rotation_variation(const Eigen::Matrix3d& F, const Eigen::Matrix3d& dF)
{
    if (!dF.allFinite())
        throw Error("polar rotation variation: dF has a non-finite entry");
    const Eigen::Matrix3d R = polar_rotation(F);
    const Eigen::Matrix3d RtF = R.transpose() * F;
    const Eigen::Matrix3d S = 0.5 * (RtF + RtF.transpose());
    const Eigen::Matrix3d T = S.trace() * Eigen::Matrix3d::Identity() - S;
    if (!(std::abs(T.determinant()) > 1e-12 * std::pow(std::max(F.norm(), 1e-300), 3)))
        throw Error("polar rotation variation: (tr S) I - S is singular (F has two zero singular values): "
                    "dR is unbounded");
    Eigen::Matrix3d dR;
    // BEGIN EXERCISE 11.8 polar_rotation_variation #the-derivative-of-r
    // HINT: A = Rᵀ δF; w is the vector of A − Aᵀ: (A₃₂ − A₂₃, A₁₃ − A₃₁, A₂₁ − A₁₂) (0-based: (2,1), (0,2), (1,0)).
    // HINT: Solve ((tr S) I − S) ω = w (T above), then δR = R ω̂ with ω̂ the cross-product matrix of ω.
    const Eigen::Matrix3d A = R.transpose() * dF;
    const Eigen::Vector3d w(A(2, 1) - A(1, 2), A(0, 2) - A(2, 0), A(1, 0) - A(0, 1));
    const Eigen::Vector3d omega = T.partialPivLu().solve(w);
    Eigen::Matrix3d omega_hat;
    omega_hat << 0.0, -omega[2], omega[1],
                 omega[2], 0.0, -omega[0],
                 -omega[1], omega[0], 0.0;
    dR = R * omega_hat;
    // END EXERCISE
    return dR;
}

}  // namespace fem::corot
