// Chapter 11: best-fit rotations, corotated forces and the warped stiffness, against known
// rotations, rigid motions, rotation covariance and the small-deformation limit.
// docs/11_corotational.md
#include "11_corotational/corotational.hpp"
#include "11_corotational/frozen_preconditioner.hpp"

#include "10_linear_dynamics/time_integration.hpp"

#include "06_assembly/assembly.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"
#include "common/random.hpp"
#include "common/vtk_io.hpp"

#include "../common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include <array>
#include <cmath>

using namespace fem;
using namespace fem::corot;
using fem::test::EntriesNear;
using fem::test::entries_of;
using Catch::Matchers::Contains;

namespace {

const dynamics::Material rubber{1e5, 0.45, 1000.0};

/// A rotation by `angle` about a random axis (seeded).
Eigen::Matrix3d rotation(double angle, unsigned seed)
{
    return Eigen::AngleAxisd(angle, Eigen::Vector3d(fem::random_vector(3, seed)).normalized()).toRotationMatrix();
}

/// A random positively oriented tet (seeded): the unit corner tet plus jitter.
tet::TetVertices random_tet(unsigned seed)
{
    tet::TetVertices X;
    X << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
    X += 0.3 * Eigen::Matrix<double, 4, 3>(fem::random_matrix(4, 3, seed));
    if (tet::signed_volume(X) < 0.0)
        X.row(2).swap(X.row(3));
    return X;
}

/// Every vertex moved by x = Q X + c.
MatrixX3d rigidly_moved(const MatrixX3d& V, const Eigen::Matrix3d& Q, const Eigen::Vector3d& c)
{
    return (V * Q.transpose()).rowwise() + c.transpose();
}

Eigen::VectorXd displacement(const MatrixX3d& x, const MatrixX3d& V)
{
    const MatrixX3d u = x - V;
    return Eigen::Map<const Eigen::VectorXd>(u.data(), u.size());
}

double orthogonality_error(const Eigen::Matrix3d& R)
{
    return (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
}

/// A 4×2×2-cell rubber beam whose backward-Euler step matrix M + Δt² K_R(u) (Δt = 1/60 s) is taken
/// after a rigid turn by `angle` about a random axis (axis_seed): what a frozen factor meets when the
/// body turns under it.
class TurningBeam {
public:
    explicit TurningBeam(unsigned axis_seed) : axis_seed_(axis_seed) {}

    dynamics::SparseMatrix step_matrix(double angle)
    {
        const Eigen::VectorXd u =
            displacement(rigidly_moved(mesh.V, rotation(angle, axis_seed_), Eigen::Vector3d::Zero()), mesh.V);
        return dynamics::SparseMatrix(mass_ + time_step_ * time_step_ * model_.stiffness(u));
    }

    const TetMesh mesh = box_mesh(4, 2, 2, Eigen::Vector3d(0.4, 0.2, 0.2));

private:
    unsigned axis_seed_;
    CorotationalElasticity model_{mesh, rubber};
    dynamics::SparseMatrix mass_ = assembly::lumped_mass_matrix(mesh, rubber.density);
    double time_step_ = 1.0 / 60.0;
};

}  // namespace

TEST_CASE("reflection fix: A B^T, with A's last column negated when det(A B^T) = -1", "[ex11.1]")
{
    for (unsigned seed = 1; seed <= 10; ++seed) {
        const Eigen::Matrix3d A = rotation(0.5 * seed, seed), B = rotation(0.3 * seed, seed + 50);
        CHECK_THAT(entries_of(proper_rotation(A, B)), EntriesNear(A * B.transpose(), 1e-14));  // already proper
        const Eigen::Matrix3d flip = Eigen::Vector3d(1.0, 1.0, -1.0).asDiagonal();
        const Eigen::Matrix3d reflected = A * flip;  // det(reflected Bᵀ) = −1
        const Eigen::Matrix3d R = proper_rotation(reflected, B);
        CAPTURE(seed);
        CHECK(R.determinant() == Approx(1.0).epsilon(1e-13));
        CHECK_THAT(entries_of(R), EntriesNear(A * B.transpose(), 1e-14));  // the last column flipped back, not another
    }
}

TEST_CASE("best-fit rotation: R = V U^T recovers known rotations, the slide's U V^T is its inverse", "[ex11.2]")
{
    for (unsigned seed = 1; seed <= 40; ++seed) {
        const double angle = 0.16 * seed;  // up to 6.4 rad: beyond pi
        const Eigen::Matrix3d Q = rotation(angle, seed);
        const tet::TetVertices X = random_tet(seed + 100);
        const Eigen::Vector3d c = Eigen::Vector3d(fem::random_vector(3, seed + 200)) * 5.0;
        const tet::TetVertices x = (X * Q.transpose()).rowwise() + c.transpose();
        const Eigen::Matrix3d S = edge_covariance(X, x);
        const Eigen::Matrix3d R = best_fit_rotation(S);
        CAPTURE(seed, angle);
        CHECK((R - Q).cwiseAbs().maxCoeff() <= 1e-12);
        CHECK(R.determinant() == Approx(1.0).epsilon(1e-13));
        // The slide's U Vᵀ is the transpose: the inverse rotation.
        const Eigen::JacobiSVD<Eigen::Matrix3d> svd(S, Eigen::ComputeFullU | Eigen::ComputeFullV);
        const Eigen::Matrix3d slide = svd.matrixU() * svd.matrixV().transpose();
        CHECK((slide - Q.transpose()).cwiseAbs().maxCoeff() <= 1e-12);
    }
}

TEST_CASE("best-fit rotation: reflections, flat, collapsed and uniformly scaled tets give proper rotations",
          "[ex11.2]")
{
    const tet::TetVertices X = random_tet(7);
    // Inverted: vertex 3 pushed through the opposite face (a reflection of the edges).
    tet::TetVertices inverted = X;
    const Eigen::RowVector3d n = (X.row(1) - X.row(0)).cross(X.row(2) - X.row(0)).normalized();
    inverted.row(3) -= 2.0 * n.dot(X.row(3) - X.row(0)) * n;
    // Flat: vertex 3 in the plane of the others (one singular value 0).
    tet::TetVertices flat = X;
    flat.row(3) -= n.dot(X.row(3) - X.row(0)) * n;
    // A mirror image of the whole tet (det of the best orthogonal map is −1).
    tet::TetVertices mirrored = X;
    mirrored.col(0) = -mirrored.col(0);
    for (const auto& [x, name] : {std::pair{inverted, "inverted"}, std::pair{flat, "flat"},
                                  std::pair{mirrored, "mirrored"}, std::pair{tet::TetVertices(3.0 * X), "scaled"},
                                  std::pair{tet::TetVertices(tet::TetVertices::Zero()), "collapsed"}}) {
        const Eigen::Matrix3d R = best_fit_rotation(edge_covariance(X, x));
        CAPTURE(name);
        CHECK(R.allFinite());
        CHECK(orthogonality_error(R) <= 1e-12);
        CHECK(R.determinant() == Approx(1.0).epsilon(1e-12));
    }
    // Uniform scaling has repeated singular values; its rotation is still the identity.
    CHECK_THAT(entries_of(best_fit_rotation(edge_covariance(X, tet::TetVertices(3.0 * X)))),
               EntriesNear(Eigen::Matrix3d::Identity(), 1e-12));
    CHECK_THROWS_AS(best_fit_rotation(Eigen::Matrix3d::Constant(std::nan(""))), Error);
}

TEST_CASE("polar rotation: F = R S with S symmetric positive semi-definite, a proper R for any F", "[ex11.3]")
{
    for (unsigned seed = 1; seed <= 20; ++seed) {
        const Eigen::Matrix3d Q = rotation(0.3 * seed, seed);
        Eigen::Matrix3d stretch = Eigen::Matrix3d(fem::random_matrix(3, 3, seed + 10));
        stretch = stretch * stretch.transpose() + 0.1 * Eigen::Matrix3d::Identity();  // SPD
        const Eigen::Matrix3d R = polar_rotation(Q * stretch);
        CAPTURE(seed);
        CHECK_THAT(entries_of(R), EntriesNear(Q, 1e-12));
    }
    // Inverted (det F < 0), flat (rank 2), a line (rank 1), zero: proper rotations, no NaN.
    Eigen::Matrix3d inverted = rotation(1.0, 3) * Eigen::Vector3d(1.2, 0.9, -0.3).asDiagonal();
    Eigen::Matrix3d flat = rotation(2.0, 4) * Eigen::Vector3d(1.0, 0.5, 0.0).asDiagonal();
    Eigen::Matrix3d line = Eigen::Vector3d(1, 2, 3) * Eigen::RowVector3d(0.5, -1, 0.2);
    for (const Eigen::Matrix3d& F : {inverted, flat, line, Eigen::Matrix3d(Eigen::Matrix3d::Zero())}) {
        const Eigen::Matrix3d R = polar_rotation(F);
        CHECK(R.allFinite());
        CHECK(orthogonality_error(R) <= 1e-12);
        CHECK(R.determinant() == Approx(1.0).epsilon(1e-12));
    }
    // The inverted F: R^T F is symmetric with one negative eigenvalue (the smallest stretch).
    const Eigen::Matrix3d S = polar_rotation(inverted).transpose() * inverted;
    CHECK_THAT(entries_of(S), EntriesNear(S.transpose(), 1e-12));
    CHECK(S.determinant() < 0.0);
    CHECK_THROWS_AS(polar_rotation(Eigen::Matrix3d::Constant(INFINITY)), Error);
}

TEST_CASE("polar rotation by Newton's iteration: the SVD's rotation to round-off, the SVD for hard cases", "[ex11.3]")
{
    double largest_difference = 0.0, largest_orthogonality = 0.0;
    for (unsigned seed = 1; seed <= 2000; ++seed) {
        // Rotations up to 2π of stretches within 40 % (σ from about 0.3 to 1.7).
        const Eigen::Matrix3d F = rotation(0.003 * seed, seed) *
                                  (Eigen::Matrix3d::Identity() + 0.4 * Eigen::Matrix3d(fem::random_matrix(3, 3, seed + 7)));
        if (F.determinant() <= 0.0)
            continue;
        const Eigen::Matrix3d R = polar_rotation_newton(F);
        largest_difference = std::max(largest_difference, (R - polar_rotation(F)).cwiseAbs().maxCoeff());
        largest_orthogonality = std::max(largest_orthogonality, orthogonality_error(R));
    }
    CAPTURE(largest_difference, largest_orthogonality);
    CHECK(largest_difference <= 1e-12);
    CHECK(largest_orthogonality <= 1e-14);
    // Inverted, flat and zero F go to the SVD: a proper rotation, never a reflection.
    const Eigen::Matrix3d inverted = rotation(1.0, 3) * Eigen::Vector3d(1.2, 0.9, -0.3).asDiagonal();
    const Eigen::Matrix3d flat = rotation(2.0, 4) * Eigen::Vector3d(1.0, 0.5, 0.0).asDiagonal();
    for (const Eigen::Matrix3d& F : {inverted, flat, Eigen::Matrix3d(Eigen::Matrix3d::Zero())}) {
        const Eigen::Matrix3d R = polar_rotation_newton(F);
        CHECK_THAT(entries_of(R), EntriesNear(polar_rotation(F), 1e-12));
        CHECK(R.determinant() == Approx(1.0).epsilon(1e-12));
    }
}

TEST_CASE("polar rotations four at a time: the bits of one at a time, for easy and hard F mixed", "[ex11.3]")
{
    // Small strains (the lanes' case), large ones (a scaled first step), inverted and flat F (the
    // SVD), in groups of four where each kind sits next to the others, and a count that is not a
    // multiple of four. With AVX2 the groups of easy F run in the lanes; either way every R must
    // equal polar_rotation_newton's exactly (ctest also runs this with FEM_NO_AVX2=1).
    std::vector<Eigen::Matrix3d> F;
    for (unsigned seed = 0; seed < 203; ++seed) {
        const double strain = seed % 5 == 0 ? 0.3 : seed % 7 == 0 ? 1e-6 : 1e-3;
        Eigen::Matrix3d G = rotation(0.05 * seed, 500 + seed) *
                            (Eigen::Matrix3d::Identity() + strain * Eigen::Matrix3d(fem::random_matrix(3, 3, 900 + seed)));
        if (seed % 31 == 0)
            G.col(2) = -G.col(2);  // inverted
        if (seed % 37 == 0)
            G.col(1) = 0.5 * G.col(0);  // flat
        F.push_back(G);
    }
    std::vector<Eigen::Matrix3d> R(F.size());
    polar_rotations_newton(F.data(), R.data(), F.size());
    int differing = 0;
    for (std::size_t k = 0; k < F.size(); ++k)
        differing += R[k] != polar_rotation_newton(F[k]);
    CHECK(differing == 0);
    F[101](1, 1) = std::nan("");
    CHECK_THROWS_WITH(polar_rotations_newton(F.data(), R.data(), F.size()), Contains("F[101] of 203 has a non-finite"));
}

TEST_CASE("edges, centroid or polar: equal for the tets they were made for, different for skewed ones", "[ex11.3]")
{
    tet::TetVertices corner;  // edges from vertex 0 orthonormal: PᵀP = I
    corner << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
    tet::TetVertices regular;  // the corners' covariance ∝ I
    regular << 1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1;
    if (tet::signed_volume(regular) < 0.0)
        regular.row(2).swap(regular.row(3));
    tet::TetVertices skewed;
    skewed << 0, 0, 0, 1, 0, 0, 0.9, 0.1, 0, 0.3, 0.2, 0.05;
    Eigen::Matrix3d G;  // a shear and a squash, then a rotation
    G << 1.0, 0.4, 0.0, 0.0, 1.0, 0.0, 0.1, 0.0, 0.9;
    const Eigen::Matrix3d A = rotation(0.7, 3) * G;
    const auto fits = [&](const tet::TetVertices& X) {
        const tet::TetVertices x = X * A.transpose();
        return std::array<Eigen::Matrix3d, 3>{polar_rotation(tet::deformation_gradient(X, x)),
                                             best_fit_rotation(centroid_covariance(X, x)),
                                             best_fit_rotation(edge_covariance(X, x))};
    };
    const auto c = fits(corner), r = fits(regular), k = fits(skewed);
    CHECK_THAT(entries_of(c[0]), EntriesNear(c[2], 1e-12));   // corner tet: polar = edges
    CHECK_THAT(entries_of(r[0]), EntriesNear(r[1], 1e-12));   // regular tet: polar = centroid
    CHECK((k[0] - k[1]).norm() > 1e-3);     // skewed: all three differ
    CHECK((k[0] - k[2]).norm() > 1e-3);
    CHECK((k[1] - k[2]).norm() > 1e-3);
    for (const auto* set : {&c, &r, &k})
        for (const Eigen::Matrix3d& R : *set)
            CHECK(orthogonality_error(R) <= 1e-12);
    // The polar rotation leaves RᵀF symmetric: no rotation is left in the corotated strain.
    const Eigen::Matrix3d F = tet::deformation_gradient(skewed, skewed * A.transpose());
    const Eigen::Matrix3d stretch = k[0].transpose() * F;
    CHECK_THAT(entries_of(stretch), EntriesNear(stretch.transpose(), 1e-12 * stretch.norm()));
}

TEST_CASE("rotated stiffness: every 3x3 block becomes R K_ab R^T", "[ex11.4]")
{
    const Matrix12d K_e = elastic::element_stiffness(random_tet(5), elastic::lame_parameters(1e5, 0.3));
    const Eigen::Matrix3d R = rotation(2.0, 9);
    Matrix12d R_hat = Matrix12d::Zero();
    for (int i = 0; i < 4; ++i)
        R_hat.block<3, 3>(3 * i, 3 * i) = R;
    const Matrix12d expected = R_hat * K_e * R_hat.transpose();
    CHECK((rotated_stiffness(K_e, R) - expected).cwiseAbs().maxCoeff() <= 1e-12 * K_e.cwiseAbs().maxCoeff());
    // K_e is symmetric up to its own round-off, which a computed block's transpose may carry over.
    CHECK((rotated_stiffness(K_e, Eigen::Matrix3d::Identity()) - K_e).cwiseAbs().maxCoeff() <=
          1e-14 * K_e.cwiseAbs().maxCoeff());
}

TEST_CASE("corotated force: -R K_e (R^T x - X), zero for rigid motions, the linear force at R = I", "[ex11.5]")
{
    const tet::TetVertices X = random_tet(11);
    const Matrix12d K_e = elastic::element_stiffness(X, elastic::lame_parameters(1e5, 0.3));
    Vector12d X_e, x_e;
    for (int i = 0; i < 4; ++i)
        X_e.segment<3>(3 * i) = X.row(i).transpose();
    const Eigen::Matrix3d Q = rotation(2.5, 4);
    for (int i = 0; i < 4; ++i)
        x_e.segment<3>(3 * i) = Q * X.row(i).transpose() + Eigen::Vector3d(1, 2, 3);
    CHECK(corotated_force(K_e, Q, x_e, X_e).norm() <= 1e-10 * K_e.norm());
    // With R = I it is the linear force −K_e (x_e − X_e).
    const Vector12d stretched = X_e + 0.01 * Vector12d(fem::random_vector(12, 8));
    CHECK((corotated_force(K_e, Eigen::Matrix3d::Identity(), stretched, X_e) + K_e * (stretched - X_e)).norm() <=
          1e-12 * (K_e * (stretched - X_e)).norm());
    // A rotated deformation gives the rotated force.
    Vector12d rotated;
    for (int i = 0; i < 4; ++i)
        rotated.segment<3>(3 * i) = Q * stretched.segment<3>(3 * i);
    const Vector12d f = corotated_force(K_e, Q, rotated, X_e), f0 = -(K_e * (stretched - X_e));
    for (int i = 0; i < 4; ++i)
        CHECK_THAT(entries_of(f.segment<3>(3 * i)), EntriesNear(Q * f0.segment<3>(3 * i), 1e-10 * f0.norm()));
}

TEST_CASE("corotational body: no force under rigid motion, rotation covariance of f and K_R", "[ex11.6]")
{
    const TetMesh mesh = box_mesh(3, 2, 2, Eigen::Vector3d(0.3, 0.2, 0.2));
    CorotationalElasticity corotational(mesh, rubber);
    dynamics::LinearElasticity linear(mesh, rubber);
    Eigen::VectorXd stretch(3 * mesh.V.rows()), f_stretch, f;
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
        stretch.segment<3>(3 * v) = Eigen::Vector3d(0.01 * mesh.V(v, 0), 0.0, 0.0);  // 1 % stretch
    linear.evaluate(stretch, f_stretch);
    const double scale = f_stretch.norm();
    for (const double angle : {0.5, 2.0, 3.1, 4.5}) {
        const Eigen::Matrix3d Q = rotation(angle, 21);
        const Eigen::VectorXd rigid = displacement(rigidly_moved(mesh.V, Q, Eigen::Vector3d(0.3, -1, 2)), mesh.V);
        const double energy = corotational.evaluate(rigid, f);
        CAPTURE(angle);
        CHECK(f.norm() <= 1e-10 * scale);
        CHECK(std::abs(energy) <= 1e-10 * 0.5 * stretch.dot(-f_stretch));
        linear.evaluate(rigid, f);
        CHECK(f.norm() > 10.0 * scale);  // linear elasticity resists a rotation
    }
    // f(Q x) = Q f(x) and K_R(Q x) = Q K_R(x) Qᵀ for a deformed state x.
    const Eigen::VectorXd u = 0.02 * fem::random_vector(3 * mesh.V.rows(), 31);
    const MatrixX3d x = mesh.V + io::vertex_rows(u);
    const Eigen::Matrix3d Q = rotation(1.3, 41);
    const Eigen::VectorXd u_rotated = displacement(rigidly_moved(x, Q, Eigen::Vector3d::Zero()), mesh.V);
    Eigen::VectorXd f_x, f_Qx;
    corotational.evaluate(u, f_x);
    corotational.evaluate(u_rotated, f_Qx);
    const MatrixX3d rotated_forces = io::vertex_rows(f_x) * Q.transpose();
    CHECK_THAT(entries_of(io::vertex_rows(f_Qx)), EntriesNear(rotated_forces, 1e-10 * f_x.norm()));
    const Eigen::MatrixXd K_x(corotational.stiffness(u)), K_Qx(corotational.stiffness(u_rotated));
    Eigen::MatrixXd Q_hat = Eigen::MatrixXd::Zero(K_x.rows(), K_x.cols());
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
        Q_hat.block<3, 3>(3 * v, 3 * v) = Q;
    CHECK((K_Qx - Q_hat * K_x * Q_hat.transpose()).cwiseAbs().maxCoeff() <= 1e-10 * K_x.cwiseAbs().maxCoeff());
    // At rest K_R is the linear K, symmetric.
    const Eigen::MatrixXd K_rest(corotational.stiffness(Eigen::VectorXd::Zero(u.size())));
    CHECK((K_rest - Eigen::MatrixXd(linear.K())).cwiseAbs().maxCoeff() <= 1e-12 * K_rest.cwiseAbs().maxCoeff());
    CHECK((K_x - K_x.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * K_x.cwiseAbs().maxCoeff());
    // The polar rotations by Newton's iteration (the default) or by the SVD: the same forces.
    CorotationalElasticity by_svd(mesh, rubber, RotationFit::polar, PolarAlgorithm::svd);
    Eigen::VectorXd f_svd;
    by_svd.evaluate(u, f_svd);
    CHECK_THAT(entries_of(f_x), EntriesNear(f_svd, 1e-12 * f_svd.norm()));
}

TEST_CASE("shape-gradient form: the forces and energy of the stiffness-matrix form, to round-off",
          "[ex11.6]")
{
    const elastic::Lame lame = elastic::lame_parameters(1e5, 0.3);
    for (unsigned seed = 0; seed < 20; ++seed) {
        const tet::TetVertices X = random_tet(100 + seed);
        const Matrix12d K_e = elastic::element_stiffness(X, lame);
        const Eigen::Matrix3d rest_inverse = tet::edge_matrix(X).inverse();
        const double volume = std::abs(tet::signed_volume(X));
        // A deformed tet: rotated by up to 3 rad and strained by up to 20 %, far from the origin.
        tet::TetVertices x = X;
        x += 0.2 * Eigen::Matrix<double, 4, 3>(fem::random_matrix(4, 3, 200 + seed));
        const Eigen::Matrix3d Q = rotation(0.15 * seed, 300 + seed);
        x = ((x * Q.transpose()).rowwise() + Eigen::RowVector3d(50.0, -20.0, 7.0)).eval();
        const Eigen::Matrix3d F = tet::edge_matrix(x) * rest_inverse;
        const Eigen::Matrix3d R = polar_rotation(F);
        Vector12d x_e, X_e;
        for (int i = 0; i < 4; ++i) {
            x_e.segment<3>(3 * i) = x.row(i).transpose();
            X_e.segment<3>(3 * i) = X.row(i).transpose();
        }
        CAPTURE(seed);
        const Vector12d expected = corotated_force(K_e, R, x_e, X_e);
        const Vector12d d = corotated_displacement(R, x_e, X_e);
        const GradientFormElement element = gradient_form_forces(F, R, rest_inverse, volume, lame);
        const Vector12d forces = element.forces.reshaped();
        // x is 50 m from the origin: its round-off (1e-14) over the edges, times K_e, bounds both forms
        CHECK_THAT(entries_of(forces), EntriesNear(expected, 1e-11 * K_e.norm() * d.norm() + 1e-13 * K_e.norm()));
        CHECK(element.energy == Approx(0.5 * d.dot(K_e * d)).epsilon(1e-10));
    }
    // As a body's force model: the same forces and energy as the default form, and the same K_R.
    const TetMesh mesh = box_mesh(3, 2, 2, Eigen::Vector3d(0.3, 0.2, 0.2));
    CorotationalElasticity matrices(mesh, rubber);
    CorotationalElasticity gradients(mesh, rubber, RotationFit::polar, PolarAlgorithm::newton,
                                     ForceForm::shape_gradients);
    const Eigen::VectorXd u = 0.05 * fem::random_vector(3 * mesh.V.rows(), 77);
    Eigen::VectorXd f_matrices, f_gradients;
    const double energy = matrices.evaluate(u, f_matrices);
    CHECK(gradients.evaluate(u, f_gradients) == Approx(energy).epsilon(1e-12));
    CHECK_THAT(entries_of(f_gradients), EntriesNear(f_matrices, 1e-12 * f_matrices.norm()));
    const Eigen::MatrixXd K_matrices(matrices.stiffness(u)), K_gradients(gradients.stiffness(u));
    CHECK(K_gradients == K_matrices);  // K_R is R K_ab Rᵀ in both: the same rotations, the same bits
    // and after a step to another u (the kept F must follow u)
    const Eigen::VectorXd v = u + 0.01 * fem::random_vector(u.size(), 78);
    CHECK(gradients.evaluate(v, f_gradients) == Approx(matrices.evaluate(v, f_matrices)).epsilon(1e-12));
    CHECK_THAT(entries_of(f_gradients), EntriesNear(f_matrices, 1e-12 * f_matrices.norm()));
}

TEST_CASE("warped stiffness of one strained, rotated tet: every 3x3 block of K_R is R K_ab R^T", "[ex11.6]")
{
    // One tet, so K_R is the element's own block matrix: a wrong rotation (none, Rᵀ K R, R on one
    // side only) or a block added at the wrong vertices shows in a named block.
    TetMesh mesh;
    mesh.V = random_tet(7);
    mesh.T.resize(1, 4);
    mesh.T << 0, 1, 2, 3;
    CorotationalElasticity model(mesh, rubber);
    Eigen::Matrix3d stretch;
    stretch << 1.1, 0.05, 0.0, 0.02, 0.95, 0.03, 0.0, 0.04, 1.05;
    const MatrixX3d x = rigidly_moved(MatrixX3d(mesh.V * stretch.transpose()), rotation(0.8, 17), Eigen::Vector3d(0.1, -0.2, 0.3));
    const Eigen::VectorXd u = displacement(x, mesh.V);
    const Eigen::MatrixXd K_R = Eigen::MatrixXd(model.stiffness(u));
    const Eigen::Matrix3d R = model.rotations(u)[0];
    const Matrix12d K_e = assembly::element_stiffnesses(mesh, elastic::lame_parameters(rubber.youngs_modulus, rubber.poisson_ratio))[0];
    REQUIRE(K_R.rows() == 12);
    for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
            const Eigen::Matrix3d expected = R * K_e.block<3, 3>(3 * a, 3 * b) * R.transpose();
            const double deviation = (K_R.block<3, 3>(3 * a, 3 * b) - expected).cwiseAbs().maxCoeff();
            CAPTURE(a, b, deviation);
            CHECK(deviation <= 1e-12 * K_e.cwiseAbs().maxCoeff());
        }
}

TEST_CASE("small deformations: corotational and linear forces differ by O(eps^2)", "[ex11.6]")
{
    const TetMesh mesh = box_mesh(2, 2, 2);
    CorotationalElasticity corotational(mesh, rubber);
    dynamics::LinearElasticity linear(mesh, rubber);
    const Eigen::VectorXd direction = fem::random_vector(3 * mesh.V.rows(), 51);
    std::vector<double> gaps;
    for (const double eps : {1e-2, 5e-3, 2.5e-3, 1.25e-3}) {
        Eigen::VectorXd f_c, f_l;
        corotational.evaluate(eps * direction, f_c);
        linear.evaluate(eps * direction, f_l);
        gaps.push_back((f_c - f_l).norm());
    }
    for (std::size_t k = 1; k < gaps.size(); ++k) {
        const double order = std::log2(gaps[k - 1] / gaps[k]);
        CAPTURE(k, order);
        CHECK(order == Approx(2.0).margin(0.1));
    }
}

TEST_CASE("vertex order: corners permuted or the mesh renumbered change nothing, except the lecture's edge fit",
          "[ex11.6]")
{
    const TetMesh mesh = box_mesh(2, 1, 1);
    const Eigen::VectorXd u = 0.05 * fem::random_vector(3 * mesh.V.rows(), 61);
    // Even permutations of every tet's corners keep the orientation.
    TetMesh permuted = mesh;
    for (Eigen::Index t = 0; t < mesh.T.rows(); ++t)
        permuted.T.row(t) << mesh.T(t, 1), mesh.T(t, 2), mesh.T(t, 0), mesh.T(t, 3);
    // The vertices renumbered in reverse.
    const Eigen::Index n = mesh.V.rows();
    TetMesh renumbered{mesh.V.colwise().reverse(), mesh.T};
    for (Eigen::Index t = 0; t < mesh.T.rows(); ++t)
        for (int i = 0; i < 4; ++i)
            renumbered.T(t, i) = static_cast<int>(n - 1 - mesh.T(t, i));
    Eigen::VectorXd u_renumbered(u.size());
    for (Eigen::Index v = 0; v < n; ++v)
        u_renumbered.segment<3>(3 * (n - 1 - v)) = u.segment<3>(3 * v);

    for (const RotationFit fit : {RotationFit::polar, RotationFit::centroid, RotationFit::edges}) {
        CorotationalElasticity reference(mesh, rubber, fit), corners(permuted, rubber, fit),
            reversed(renumbered, rubber, fit);
        Eigen::VectorXd f_ref, f_corners, f_reversed;
        const double energy = reference.evaluate(u, f_ref);
        const double energy_corners = corners.evaluate(u, f_corners);
        const double energy_reversed = reversed.evaluate(u_renumbered, f_reversed);
        double reversed_gap = 0.0;
        for (Eigen::Index v = 0; v < n; ++v)
            reversed_gap = std::max(reversed_gap, (f_reversed.segment<3>(3 * (n - 1 - v)) - f_ref.segment<3>(3 * v)).norm());
        CAPTURE(int(fit));
        CHECK(energy_reversed == Approx(energy).epsilon(1e-12));  // renumbering never matters
        CHECK(reversed_gap <= 1e-12 * f_ref.norm());
        if (fit == RotationFit::edges) {
            // The slide's fit uses the edges from corner 0: another first corner, another rotation.
            CHECK(std::abs(energy_corners - energy) > 1e-4 * energy);
        } else {
            CHECK(energy_corners == Approx(energy).epsilon(1e-12));
            CHECK_THAT(entries_of(f_corners), EntriesNear(f_ref, 1e-12 * f_ref.norm()));
        }
    }
}

// A free cube spun at 6 rad/s, no gravity. Linear elasticity swells (a rotation is a strain to
// it); the corotational body keeps its volume. The linearly implicit step moves every point along
// its velocity, a tangent to its circle, which stretches the spinning body a little each step; the
// warped stiffness K_R (no derivative of R) does not see that coming, so both integrators GAIN
// energy here, backward Euler too, by an amount that shrinks with dt (a discretisation error that
// a Newton-converged step, chapter 12, removes).
TEST_CASE("a spinning body: linear elasticity swells, corotational keeps its volume, energy gain shrinks with dt",
          "[ex11.6]")
{
    dynamics::Scene scene;
    scene.mesh = box_mesh(2, 2, 2, Eigen::Vector3d(0.1, 0.1, 0.1));
    scene.material = rubber;
    scene.gravity.setZero();
    scene.duration = 0.0;
    const Eigen::Vector3d centre(0.05, 0.05, 0.05), spin(0.0, 0.0, 6.0);
    Eigen::VectorXd v0(3 * scene.mesh.V.rows());
    for (Eigen::Index v = 0; v < scene.mesh.V.rows(); ++v)
        v0.segment<3>(3 * v) = spin.cross(Eigen::Vector3d(scene.mesh.V.row(v).transpose()) - centre);
    const double volume = total_volume(scene.mesh), horizon = 0.5;
    struct Outcome {
        double growth = 0.0, energy_gain = 0.0;
    };
    const auto run = [&](std::unique_ptr<dynamics::ForceModel> model, const std::string& integrator, double dt) {
        scene.time_step = dt;
        dynamics::Body body(scene, std::move(model));
        const auto stepper = dynamics::make_integrator(integrator);
        dynamics::Simulation simulation(body, *stepper, dynamics::initial_state(body, {}, v0));
        Outcome outcome;
        double h0 = 0.0;
        simulation.run(static_cast<int>(std::lround(horizon / dt)),
                       [&](const dynamics::State& state, const dynamics::StepRecord& record) {
                           if (state.step == 0)
                               h0 = record.energies.total();
                       });
        outcome.energy_gain = simulation.last().energies.total() / h0 - 1.0;
        TetMesh moved{body.positions(simulation.state().u), scene.mesh.T};
        outcome.growth = total_volume(moved) / volume - 1.0;
        return outcome;
    };
    const Outcome linear = run(std::make_unique<dynamics::LinearElasticity>(scene.mesh, rubber), "implicit-midpoint", 0.01);
    const Outcome coarse = run(std::make_unique<CorotationalElasticity>(scene.mesh, rubber), "implicit-midpoint", 0.01);
    const Outcome fine = run(std::make_unique<CorotationalElasticity>(scene.mesh, rubber), "implicit-midpoint", 0.0025);
    const Outcome backward = run(std::make_unique<CorotationalElasticity>(scene.mesh, rubber), "backward-euler", 0.01);
    const Outcome backward_fine =
        run(std::make_unique<CorotationalElasticity>(scene.mesh, rubber), "backward-euler", 0.0025);
    CAPTURE(linear.growth, coarse.growth, coarse.energy_gain, fine.energy_gain, backward.energy_gain,
            backward_fine.energy_gain);
    CHECK(linear.growth > 1.0);                        // three radians: the linear body doubles its volume
    CHECK(std::abs(coarse.growth) < 0.01);             // the centrifugal stretch only
    CHECK(std::abs(linear.energy_gain) < 1e-9);        // linear forces: the midpoint rule conserves
    CHECK(coarse.energy_gain > 0.0);
    CHECK(fine.energy_gain < coarse.energy_gain / 3.0);  // 4x smaller dt: the gain shrinks
    CHECK(backward.energy_gain > 0.0);
    CHECK(backward_fine.energy_gain < backward.energy_gain / 2.0);
}

TEST_CASE("finite differences: the polar fit's force is -dU/du, the edge fit's is not, K_R misses the dR term",
          "[ex11.6]")
{
    const TetMesh mesh = box_mesh(2, 1, 1, Eigen::Vector3d(0.2, 0.1, 0.1));
    const Eigen::VectorXd direction = fem::random_vector(3 * mesh.V.rows(), 91);
    // A bent and turned state: a rotation by 0.8 rad plus a 3 % random strain.
    const Eigen::VectorXd turned = displacement(rigidly_moved(mesh.V, rotation(0.8, 93), Eigen::Vector3d::Zero()), mesh.V);
    const Eigen::VectorXd u = turned + 0.003 * fem::random_vector(turned.size(), 92);
    for (const RotationFit fit : {RotationFit::polar, RotationFit::edges}) {
        CorotationalElasticity model(mesh, rubber, fit);
        Eigen::VectorXd f;
        model.evaluate(u, f);
        const Eigen::VectorXd slope = Eigen::VectorXd::Constant(1, -f.dot(direction));  // dU/dh = −f·d
        const std::vector<double> errors = test::central_difference_errors(
            [&](double h) {
                Eigen::VectorXd g;
                return Eigen::VectorXd::Constant(1, model.evaluate(u + h * direction, g));
            },
            slope, 0.1);
        const double best = *std::min_element(errors.begin(), errors.end());
        CAPTURE(int(fit), errors[0], errors[1], errors[2], best);
        if (fit == RotationFit::polar) {
            CHECK(best <= 1e-6);
            CHECK(errors[1] < errors[0]);
        } else {
            CHECK(best > 1e-4);  // the edge fit leaves a rotation in R^T F: its force is no gradient
        }
    }
    // The warped stiffness against the derivative of the force: exact at rest and for a rigid
    // rotation, off by a gap that grows in proportion to the strain otherwise.
    CorotationalElasticity model(mesh, rubber);
    const auto tangent_gap = [&](const Eigen::VectorXd& state) {
        const Eigen::VectorXd K_d = model.stiffness(state) * direction;
        const std::vector<double> errors = test::central_difference_errors(
            [&](double h) {
                Eigen::VectorXd g;
                model.evaluate(state + h * direction, g);
                return Eigen::VectorXd(-g);
            },
            K_d, 0.1);
        return *std::min_element(errors.begin(), errors.end());
    };
    const Eigen::VectorXd strain = 0.01 * fem::random_vector(turned.size(), 94);
    const double at_rest = tangent_gap(Eigen::VectorXd::Zero(turned.size())), rigid = tangent_gap(turned);
    const double strained = tangent_gap(turned + strain), twice = tangent_gap(turned + 2.0 * strain);
    CAPTURE(at_rest, rigid, strained, twice);
    CHECK(at_rest <= 1e-7);
    CHECK(rigid <= 1e-7);
    CHECK(strained > 1e-4);
    CHECK(twice / strained == Approx(2.0).margin(0.3));
}

// The midpoint rule conserves a linear body's energy; with the warped stiffness, which is smaller
// than the true tangent of a stretched body (above), its stiff modes grow by about 1 + 2|δ| a step
// (δ the relative gap), and the run diverges. θ a little above ½ damps them.
TEST_CASE("the midpoint rule with the warped stiffness diverges on a large swing, theta = 0.55 stays bounded",
          "[ex11.6]")
{
    dynamics::Scene scene;
    scene.mesh = beam_mesh(0.2, 0.02, 0.02, 20);  // 480 tets: stiff modes far above 1/dt
    scene.material = {2e5, 0.45, 1100.0};
    scene.pinned = assembly::vertices_on_plane(scene.mesh, 0, 0.0);
    scene.time_step = 1.0 / 60.0;
    const auto run = [&](double theta, double& gain) {
        dynamics::Body body(scene, std::make_unique<CorotationalElasticity>(scene.mesh, scene.material));
        dynamics::ThetaMethod stepper(theta);
        dynamics::Simulation simulation(body, stepper, dynamics::initial_state(body));
        double h0 = 0.0, scale = 0.0;
        simulation.run(90, [&](const dynamics::State& state, const dynamics::StepRecord& record) {
            if (state.step == 0)
                h0 = record.energies.total();
            scale = std::max(scale, record.energies.magnitude());
            gain = std::max(gain, (record.energies.total() - h0) / scale);
        });
    };
    double gain = 0.0;
    // The loop's message names the cause of a nonlinear model's implicit step, not an explicit limit.
    CHECK_THROWS_WITH(run(0.5, gain), Contains("diverged") && Contains("nonlinear force model") &&
                                          Contains("theta above 1/2") && !Contains("stability limit"));
    double damped_gain = 0.0;
    CHECK_NOTHROW(run(0.55, damped_gain));
    CHECK(damped_gain < 0.1);
}

TEST_CASE("bad input: a zero-volume rest tet is named", "[ch11]")
{
    TetMesh mesh = box_mesh(1, 1, 1);
    mesh.V.row(mesh.T(2, 3)) = mesh.V.row(mesh.T(2, 0));
    CHECK_THROWS_AS(CorotationalElasticity(mesh, rubber), Error);
    CorotationalElasticity good(box_mesh(1, 1, 1), rubber);
    const Eigen::Index good_vertices = box_mesh(1, 1, 1).V.rows();
    Eigen::VectorXd f;
    CHECK_THROWS_WITH(good.evaluate(Eigen::VectorXd::Zero(5), f), Contains("3n"));
    Eigen::VectorXd broken = Eigen::VectorXd::Zero(3 * good_vertices);
    broken[7] = std::nan("");
    CHECK_THROWS_WITH(good.evaluate(broken, f), Contains("entry 7 (vertex 2)"));
}

TEST_CASE("frozen-factor PCG: exact at rest, more iterations as the body turns, the same answer", "[ex11.7]")
{
    const TetMesh mesh = box_mesh(3, 2, 2, Eigen::Vector3d(0.3, 0.2, 0.2));
    CorotationalElasticity model(mesh, rubber);
    const Eigen::VectorXd rest = Eigen::VectorXd::Zero(3 * mesh.V.rows());
    const auto M = assembly::lumped_mass_matrix(mesh, rubber.density);
    const double dt = 1.0 / 60.0;
    const auto step_matrix = [&](const Eigen::VectorXd& u) {
        return dynamics::SparseMatrix(M + dt * dt * model.stiffness(u));
    };
    const auto exact = FactorPrecision::double_precision;
    FrozenFactorPcg frozen({}, {}, {}, exact);
    frozen.prepare(step_matrix(rest));
    const Eigen::VectorXd b = fem::random_vector(rest.size(), 71);
    Eigen::VectorXd x = frozen.solve(b);
    CHECK(frozen.stats().iterations <= 1);  // its own factor: one iteration
    // In single precision the factor is its own matrix's inverse only to float's rounding (about
    // 1e-7): one more iteration takes the residual below the default 1e-8, to the same answer.
    FrozenFactorPcg rounded;
    rounded.prepare(step_matrix(rest));
    CHECK_THAT(entries_of(rounded.solve(b)), EntriesNear(x, 1e-7 * x.norm()));
    CHECK(rounded.stats().iterations == 2);
    std::vector<int> iterations;
    for (const double angle : {0.3, 1.0, 2.0}) {
        const Eigen::VectorXd turned = displacement(rigidly_moved(mesh.V, rotation(angle, 81), Eigen::Vector3d::Zero()), mesh.V);
        const dynamics::SparseMatrix A = step_matrix(turned);
        frozen.prepare(A);
        x = frozen.solve(b);
        iterations.push_back(frozen.stats().iterations);
        const auto direct = cg::make_solver("default");
        direct->prepare(A);
        CHECK_THAT(entries_of(x), EntriesNear(direct->solve(b), 1e-7 * x.norm()));
    }
    CAPTURE(iterations[0], iterations[1], iterations[2]);
    CHECK(iterations[0] < iterations[2]);
    CHECK(frozen.factorizations() == 1);
    FrozenFactorPcg refreshing({}, RefreshRule{.iterations_above = 3}, {}, exact);
    refreshing.prepare(step_matrix(rest));
    refreshing.solve(b);
    const dynamics::SparseMatrix turned_A =
        step_matrix(displacement(rigidly_moved(mesh.V, rotation(2.0, 81), Eigen::Vector3d::Zero()), mesh.V));
    refreshing.prepare(turned_A);
    refreshing.solve(b);          // many iterations: the next prepare refactors
    refreshing.prepare(turned_A);
    CHECK(refreshing.factorizations() == 2);

    // Turned with the body: a rigidly rotated body's matrix is Q A₀ Qᵀ, so the rotated frozen factor
    // stays exact (one iteration) at any angle, where the plain one needs more and more.
    const dynamics::FreeDofs all(static_cast<int>(mesh.V.rows()), {});
    FrozenFactorPcg turning({}, {}, [&] { return free_vertex_rotations(model, all); }, exact);
    (void)model.stiffness(rest);
    turning.prepare(step_matrix(rest));
    for (const double angle : {0.3, 1.0, 2.0}) {
        const Eigen::VectorXd turned = displacement(rigidly_moved(mesh.V, rotation(angle, 81), Eigen::Vector3d::Zero()), mesh.V);
        const dynamics::SparseMatrix A = step_matrix(turned);  // evaluates the model at `turned`
        turning.prepare(A);
        x = turning.solve(b);
        CAPTURE(angle);
        CHECK(turning.stats().iterations <= 1);
        const auto direct = cg::make_solver("default");
        direct->prepare(A);
        CHECK_THAT(entries_of(x), EntriesNear(direct->solve(b), 1e-7 * x.norm()));
    }
    CHECK(turning.factorizations() == 1);
    FrozenFactorPcg wrong_size({}, {}, [] { return std::vector<Eigen::Matrix3d>(2, Eigen::Matrix3d::Identity()); });
    CHECK_THROWS_WITH(wrong_size.prepare(step_matrix(rest)), Contains("block rotations"));
}

TEST_CASE("frozen-factor PCG in single precision: the true residual |b - A x| / |b| reaches the tolerance",
          "[ex11.7]")
{
    // The float copy of the factor is neither exactly linear nor exactly symmetric, so plain PCG's
    // theory does not cover it: check the true residual of the answer, recomputed here, on a stale
    // factor (the body turned under it), against the double-precision factor's iteration count.
    TurningBeam beam(93);
    const auto step_matrix = [&](double angle) { return beam.step_matrix(angle); };
    const TetMesh& mesh = beam.mesh;
    const Eigen::VectorXd b = fem::random_vector(3 * mesh.V.rows(), 94);
    const double tolerance = 1e-10;
    FrozenFactorPcg single({tolerance}, {}, {}, FactorPrecision::single_precision);
    FrozenFactorPcg exact({tolerance}, {}, {}, FactorPrecision::double_precision);
    single.prepare(step_matrix(0.0));
    exact.prepare(step_matrix(0.0));
    for (const double angle : {0.1, 0.5, 1.5}) {
        const dynamics::SparseMatrix A = step_matrix(angle);
        single.prepare(A);
        exact.prepare(A);
        const Eigen::VectorXd x = single.solve(b);
        (void)exact.solve(b);
        const double true_residual = (b - A * x).norm() / b.norm();
        CAPTURE(angle, true_residual, single.stats().iterations, exact.stats().iterations);
        CHECK(true_residual <= tolerance);
        CHECK(single.stats().iterations > 2);  // the factor is stale: CG has work to do
        // Measured: 15 and 15 at 0.1 rad, 53 and 50 at 0.5, 158 and 130 at 1.5: over many
        // iterations the float rounding costs CG some of its conjugacy, a fifth more iterations at most.
        CHECK(single.stats().iterations <= 1.25 * exact.stats().iterations + 1);
        // Flexible PCG (Polak–Ribière β) with the same float factor: its true residual reaches the
        // tolerance too.
        direct::CholeskyOptions factor_options;
        factor_options.single_precision_copy = true;
        const direct::SparseCholesky factor(step_matrix(0.0), factor_options);
        const cg::FunctionOperator product(A.rows(), [&](const Eigen::VectorXd& v, Eigen::VectorXd& Av) { Av = A * v; });
        const cg::FunctionOperator preconditioner(A.rows(), [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
            z = factor.solve_single_precision(r);
        });
        cg::CgSettings settings;
        settings.relative_tolerance = tolerance;
        settings.beta = cg::CgBeta::polak_ribiere;
        Eigen::VectorXd y;
        const cg::CgResult flexible = cg::preconditioned_conjugate_gradient(product, preconditioner, b, y, settings);
        CAPTURE(flexible.iterations);
        CHECK(flexible.converged);
        CHECK((b - A * y).norm() / b.norm() <= tolerance);
        CHECK(flexible.relative_residual <= tolerance);
    }
    CHECK(single.factorizations() == 1);
}

TEST_CASE("frozen-factor PCG: the balanced refresh refactors once the extra iterations have cost a factorization",
          "[ex11.7]")
{
    TurningBeam beam(91);
    const auto step_matrix = [&](double angle) { return beam.step_matrix(angle); };
    const TetMesh& mesh = beam.mesh;
    const Eigen::VectorXd b = fem::random_vector(3 * mesh.V.rows(), 92);
    // The same matrix again and again: no solve needs more than the first, so it never refactors.
    FrozenFactorPcg steady({}, RefreshRule{.balance_cost = true});
    const dynamics::SparseMatrix A0 = step_matrix(0.0);
    for (int k = 0; k < 20; ++k) {
        steady.prepare(A0);
        steady.solve(b);
    }
    CHECK(steady.factorizations() == 1);
    // A body turning 0.002 rad a step under a factor that does not turn with it: the iterations grow.
    // The costs the rule compares, from the same factorization of A0 (flops, stored entries, nnz(A)).
    direct::CholeskyOptions factor_options;
    factor_options.single_precision_copy = true;
    const direct::SparseCholesky factor(A0, factor_options);
    const double factorization = factor.flops();
    const double iteration = 4.0 * double(factor.stored_entries()) + 2.0 * double(A0.nonZeros());
    FrozenFactorPcg turning({}, RefreshRule{.balance_cost = true});
    std::vector<int> iterations;
    double extra = 0.0;
    int refreshed_after = -1;  // the solve after which the account first reached a factorization
    for (int k = 0; k < 40 && turning.factorizations() < 2; ++k) {
        turning.prepare(step_matrix(0.002 * k));
        turning.solve(b);
        iterations.push_back(turning.stats().iterations);
        if (k > 0)
            extra += std::max(0, iterations.back() - iterations.front()) * iteration;
        if (refreshed_after < 0 && extra >= factorization)
            refreshed_after = k;
    }
    CAPTURE(iterations, factorization / iteration);
    REQUIRE(refreshed_after > 0);
    CHECK(refreshed_after > 1);  // the account took several solves to fill
    CHECK(iterations[static_cast<std::size_t>(refreshed_after)] > iterations.front());
    // It refactored at the prepare right after that solve, not before and not later.
    CHECK(turning.factorizations() == 2);
    CHECK(static_cast<int>(iterations.size()) == refreshed_after + 2);
    // The same with a cap on the iterations instead: refactors after the first solve above it.
    FrozenFactorPcg capped({}, RefreshRule{.iterations_above = iterations.front() + 1});
    for (int k = 0; k < 40 && capped.factorizations() < 2; ++k) {
        capped.prepare(step_matrix(0.002 * k));
        capped.solve(b);
    }
    CHECK(capped.factorizations() == 2);
    CHECK_THROWS_WITH(FrozenFactorPcg({}, RefreshRule{.iterations_above = -1}), Contains(">= 0"));
}
