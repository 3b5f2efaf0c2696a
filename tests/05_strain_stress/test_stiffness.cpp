// Chapter 05: B_e = D J_e and K_e = V B_eᵀ C B_e, checked against the tensor energy
// ψ = μ ε:ε + (λ/2) tr(ε)² computed here from the 3×3 strain; rigid modes, a patch test on a distorted
// mesh, the lecture's Voigt slip, and conditioning as ν → ½. docs/05_strain_stress.md
#include "05_strain_stress/strain_stress.hpp"
#include "rubber.hpp"

#include "04_tet_jacobians/tet_jacobians.hpp"
#include "common/error.hpp"
#include "common/mesh.hpp"

#include "04_tet_jacobians/tet_fixtures.hpp"
#include <catch2/catch.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <cmath>
#include <random>

using namespace fem::elastic;
using fem::test::skew_tet;
using fem::tet::TetVertices;
using Catch::Matchers::Contains;
using fem::test::rubber;
using Vector12d = Eigen::Matrix<double, 12, 1>;

namespace {

TetVertices rows_of(const Vector12d& q)
{
    TetVertices x;
    for (int i = 0; i < 4; ++i)
        x.row(i) = q.segment<3>(3 * i).transpose();
    return x;
}

Vector12d vertex_major(const TetVertices& x)
{
    Vector12d q;
    for (int i = 0; i < 4; ++i)
        q.segment<3>(3 * i) = x.row(i).transpose();
    return q;
}

Vector12d random_displacement(std::mt19937& random, double scale)
{
    std::uniform_real_distribution<double> u(-scale, scale);
    Vector12d q;
    for (int i = 0; i < 12; ++i)
        q[i] = u(random);
    return q;
}

/// ψ = μ ε:ε + (λ/2) tr(ε)², with ε = ½(∇u + ∇uᵀ) from the 3×3 displacement gradient.
double tensor_energy_density(const Lame& m, const Eigen::Matrix3d& grad_u)
{
    const Eigen::Matrix3d eps = 0.5 * (grad_u + grad_u.transpose());
    double contraction = 0.0;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
            contraction += eps(a, b) * eps(a, b);
    return m.mu * contraction + 0.5 * m.lambda * eps.trace() * eps.trace();
}

/// ∇u of the tet for displacements u (vertex-major), via chapter 04's F = ∂x/∂X.
Eigen::Matrix3d displacement_gradient(const TetVertices& X, const Vector12d& u)
{
    return fem::tet::deformation_gradient(X, X + rows_of(u)) - Eigen::Matrix3d::Identity();
}

/// The six rigid modes of a tet: translations along x, y, z and infinitesimal rotations ω × Xᵢ.
std::vector<Vector12d> rigid_modes(const TetVertices& X)
{
    std::vector<Vector12d> modes;
    for (int a = 0; a < 3; ++a) {
        Vector12d t = Vector12d::Zero();
        for (int i = 0; i < 4; ++i)
            t[3 * i + a] = 1.0;
        modes.push_back(t);
    }
    for (int a = 0; a < 3; ++a) {
        Vector12d r;
        for (int i = 0; i < 4; ++i)
            r.segment<3>(3 * i) = Eigen::Vector3d::Unit(a).cross(X.row(i).transpose());
        modes.push_back(r);
    }
    return modes;
}

/// Eigenvalues of K_e in increasing order.
Eigen::VectorXd eigenvalues(const Matrix12d& K)
{
    return Eigen::SelfAdjointEigenSolver<Matrix12d>(K, Eigen::EigenvaluesOnly).eigenvalues();
}

}  // namespace

TEST_CASE("B_e = D J_e: B_e u_e is the engineering strain of the displacement field", "[ex05.3]")
{
    const TetVertices X = skew_tet();
    const StrainDisplacement B = strain_displacement_matrix(X);
    std::mt19937 random(6);
    for (int k = 0; k < 10; ++k) {
        const Vector12d u = random_displacement(random, 0.1);
        const Eigen::Matrix3d grad_u = displacement_gradient(X, u);
        const Eigen::Matrix3d eps = 0.5 * (grad_u + grad_u.transpose());
        Vector6d want;
        want << eps(0, 0), eps(1, 1), eps(2, 2), 2 * eps(0, 1), 2 * eps(1, 2), 2 * eps(2, 0);
        CHECK((B * u - want).norm() == Approx(0.0).margin(1e-13));
    }
    // Pure shear u = (g y, g x, 0): γ_xy = 2g, every other component zero.
    const double g = 1e-3;
    Vector12d u;
    for (int i = 0; i < 4; ++i)
        u.segment<3>(3 * i) = Eigen::Vector3d(g * X(i, 1), g * X(i, 0), 0.0);
    Vector6d want = Vector6d::Zero();
    want[3] = 2 * g;
    CHECK((B * u - want).norm() == Approx(0.0).margin(1e-16));
}

TEST_CASE("pure shear through the element, B_e then C: sigma_xy = 2 mu eps_xy", "[ex05.8]")
{
    const TetVertices X = skew_tet();
    const double g = 2e-3;  // ε_xy = g
    Vector12d u;
    for (int i = 0; i < 4; ++i)
        u.segment<3>(3 * i) = Eigen::Vector3d(g * X(i, 1), g * X(i, 0), 0.0);
    const Vector6d sigma = stress(rubber, strain_displacement_matrix(X) * u);
    CHECK(sigma[3] == Approx(2.0 * rubber.mu * g).epsilon(1e-12));
    CHECK(sigma.norm() == Approx(2.0 * rubber.mu * g).epsilon(1e-12));
}

TEST_CASE("K_e: half u^T K_e u = V psi(eps) from the tensor formula, for random u", "[ex05.8]")
{
    std::mt19937 random(9);
    for (const Lame& material : {rubber, lame_parameters(2e11, 0.3), lame_parameters(1.0, -0.5)}) {
        for (const TetVertices& X : {skew_tet(), TetVertices(3.0 * skew_tet())}) {
            const Matrix12d K = element_stiffness(X, material);
            const double V = std::abs(fem::tet::signed_volume(X));
            for (int k = 0; k < 10; ++k) {
                const Vector12d u = random_displacement(random, 0.01);
                const double want = V * tensor_energy_density(material, displacement_gradient(X, u));
                CHECK(0.5 * u.dot(K * u) == Approx(want).epsilon(1e-10));
            }
        }
    }
}

TEST_CASE("K_e: symmetric, positive semi-definite, exactly 6 zero eigenvalues, rigid modes in its kernel",
          "[ex05.8]")
{
    const TetVertices X = skew_tet();
    const Matrix12d K = element_stiffness(X, rubber);
    CHECK((K - K.transpose()).norm() <= 1e-12 * K.norm());
    const Eigen::VectorXd values = eigenvalues(K);
    const double largest = values[11];
    for (int i = 0; i < 6; ++i)
        CHECK(std::abs(values[i]) <= 1e-10 * largest);
    for (int i = 6; i < 12; ++i)
        CHECK(values[i] > 1e-4 * largest);
    for (const Vector12d& mode : rigid_modes(X))
        CHECK((K * mode).norm() <= 1e-10 * largest * mode.norm());
    // A large (finite) rotation is NOT in the kernel: linear elasticity sees strain in it.
    const Eigen::Matrix3d R = Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Vector12d rotated = vertex_major(X * R.transpose()) - vertex_major(X);
    CHECK(0.5 * rotated.dot(K * rotated) > 1e-3 * largest * rotated.squaredNorm());
}

TEST_CASE("K_e and B_e reject flat tets and unstable materials with fem::Error", "[ex05.8]")
{
    TetVertices flat = skew_tet();
    flat.row(3) = 0.5 * (flat.row(0) + flat.row(1));
    CHECK_THROWS_AS(strain_displacement_matrix(flat), fem::Error);
    CHECK_THROWS_WITH(element_stiffness(flat, rubber), Contains("flat"));
    CHECK_THROWS_AS(element_stiffness(skew_tet(), Lame{1.0, -1.0}), fem::Error);
    // An inverted rest tet (vertices listed the other way) has the same stiffness: V = |signed volume|.
    TetVertices inverted = skew_tet();
    inverted.row(2).swap(inverted.row(3));
    const Matrix12d K = element_stiffness(skew_tet(), rubber);
    Eigen::Matrix<double, 12, 12> swap = Eigen::Matrix<double, 12, 12>::Identity();
    swap.block<3, 3>(6, 6).setZero();
    swap.block<3, 3>(9, 9).setZero();
    swap.block<3, 3>(6, 9).setIdentity();
    swap.block<3, 3>(9, 6).setIdentity();
    CHECK((element_stiffness(inverted, rubber) - swap * K * swap).norm() <= 1e-10 * K.norm());
}

TEST_CASE("the lecture's Voigt slip: 1/2 in D with mu on C's diagonal gives a quarter of the shear energy",
          "[ex05.8]")
{
    const TetVertices X = skew_tet();
    const double g = 1e-3, V = std::abs(fem::tet::signed_volume(X));
    Vector12d u;
    for (int i = 0; i < 4; ++i)
        u.segment<3>(3 * i) = Eigen::Vector3d(g * X(i, 1), g * X(i, 0), 0.0);  // ε_xy = g
    const double exact = V * tensor_energy_density(rubber, displacement_gradient(X, u));
    CHECK(exact == Approx(V * 2.0 * rubber.mu * g * g).epsilon(1e-12));
    CHECK(0.5 * u.dot(element_stiffness(X, rubber) * u) == Approx(exact).epsilon(1e-10));
    // The lecture's matrices, built here: D with ½ on the shear rows, C with μ on the shear diagonal.
    Eigen::Matrix<double, 6, 9> D_lecture = Eigen::Matrix<double, 6, 9>::Zero();
    D_lecture(0, 0) = D_lecture(1, 4) = D_lecture(2, 8) = 1.0;
    D_lecture(3, 1) = D_lecture(3, 3) = D_lecture(4, 5) = D_lecture(4, 7) = D_lecture(5, 6) = D_lecture(5, 2) = 0.5;
    Matrix6d C_lecture = Matrix6d::Zero();
    C_lecture.topLeftCorner<3, 3>().setConstant(rubber.lambda);
    C_lecture.topLeftCorner<3, 3>().diagonal().array() += 2 * rubber.mu;
    C_lecture.bottomRightCorner<3, 3>().diagonal().setConstant(rubber.mu);
    const Eigen::Matrix<double, 6, 12> B_lecture = D_lecture * fem::tet::jacobian_matrix(X);
    const double lecture = 0.5 * V * (B_lecture * u).dot(C_lecture * (B_lecture * u));
    CHECK(lecture / exact == Approx(0.25).epsilon(1e-12));
}

TEST_CASE("patch test: a linear displacement on a distorted mesh gives the exact stress everywhere",
          "[ex05.8]")
{
    // A 3×3×3 box with its interior vertices moved at random (still valid).
    fem::TetMesh mesh = fem::box_mesh(3, 3, 3);
    std::mt19937 random(31);
    std::uniform_real_distribution<double> jitter(-0.1 / 3, 0.1 / 3);
    std::vector<bool> boundary(mesh.V.rows());
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
        const Eigen::RowVector3d p = mesh.V.row(v);
        boundary[v] = (p.array() < 1e-12).any() || (p.array() > 1 - 1e-12).any();
        if (!boundary[v])
            mesh.V.row(v) += Eigen::RowVector3d(jitter(random), jitter(random), jitter(random));
    }
    REQUIRE(fem::validate(mesh) == 0);

    Eigen::Matrix3d A;  // ∇u: a stretch, a shear and a small rotation part
    A << 2e-3, 5e-4, -1e-4, 3e-4, -1e-3, 2e-4, 0.0, 6e-4, 1.5e-3;
    const Eigen::Vector3d b(1e-3, -2e-3, 5e-4);
    const Eigen::Matrix3d eps = 0.5 * (A + A.transpose());
    const Eigen::Matrix3d sigma_exact = rubber.lambda * eps.trace() * Eigen::Matrix3d::Identity() + 2 * rubber.mu * eps;
    const Eigen::Index n = mesh.V.rows();
    Eigen::VectorXd u_exact(3 * n);
    for (Eigen::Index v = 0; v < n; ++v)
        u_exact.segment<3>(3 * v) = A * mesh.V.row(v).transpose() + b;

    // Assemble K with a plain loop (chapter 06 teaches assembly), fix the boundary to the linear
    // field, solve for the interior: the linear field must come back, and so must the stress.
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(3 * n, 3 * n);
    for (int t = 0; t < mesh.T.rows(); ++t) {
        const Matrix12d Ke = element_stiffness(fem::tet::tet_vertices(mesh, mesh.V, t), rubber);
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j)
                K.block<3, 3>(3 * mesh.T(t, i), 3 * mesh.T(t, j)) += Ke.block<3, 3>(3 * i, 3 * j);
    }
    std::vector<int> free, fixed;
    for (Eigen::Index v = 0; v < n; ++v)
        for (int a = 0; a < 3; ++a)
            (boundary[v] ? fixed : free).push_back(static_cast<int>(3 * v + a));
    REQUIRE(free.size() == 3 * 8);
    Eigen::MatrixXd K_ff(free.size(), free.size()), K_fc(free.size(), fixed.size());
    Eigen::VectorXd u_c(fixed.size());
    for (std::size_t i = 0; i < free.size(); ++i) {
        for (std::size_t j = 0; j < free.size(); ++j)
            K_ff(i, j) = K(free[i], free[j]);
        for (std::size_t j = 0; j < fixed.size(); ++j)
            K_fc(i, j) = K(free[i], fixed[j]);
    }
    for (std::size_t j = 0; j < fixed.size(); ++j)
        u_c[j] = u_exact[fixed[j]];
    const Eigen::LLT<Eigen::MatrixXd> factor(K_ff);
    REQUIRE(factor.info() == Eigen::Success);
    const Eigen::VectorXd u_f = factor.solve(-K_fc * u_c);
    Eigen::VectorXd u = u_exact;
    for (std::size_t i = 0; i < free.size(); ++i) {
        CHECK(u_f[i] == Approx(u_exact[free[i]]).margin(1e-12));
        u[free[i]] = u_f[i];
    }
    for (int t = 0; t < mesh.T.rows(); ++t) {
        Vector12d ue;
        for (int i = 0; i < 4; ++i)
            ue.segment<3>(3 * i) = u.segment<3>(3 * mesh.T(t, i));
        const Eigen::Matrix3d sigma =
            stress_to_tensor(stress(rubber, strain_displacement_matrix(fem::tet::tet_vertices(mesh, mesh.V, t)) * ue));
        CHECK((sigma - sigma_exact).norm() <= 1e-9 * sigma_exact.norm());
    }
}

TEST_CASE("nu -> 1/2: the condition number of K_e (on its non-rigid part) grows like lambda/mu",
          "[ex05.8]")
{
    TetVertices regular;  // a regular tet: its conditioning is the material's, not the shape's
    regular << 1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1;
    std::vector<double> ratio, condition;
    for (double nu : {0.49, 0.499, 0.4999}) {
        const Lame m = lame_parameters(1e5, nu);
        const Eigen::VectorXd values = eigenvalues(element_stiffness(regular, m));
        ratio.push_back(m.lambda / m.mu);
        condition.push_back(values[11] / values[6]);  // largest over smallest non-zero
    }
    INFO("lambda/mu = " << ratio[0] << ", " << ratio[1] << ", " << ratio[2] << "; cond(K_e) = " << condition[0]
                        << ", " << condition[1] << ", " << condition[2]);
    for (std::size_t k = 1; k < ratio.size(); ++k) {
        CHECK(condition[k] > condition[k - 1]);
        // Growth by the same factor as λ/μ (about 10 per step), within 10 %.
        CHECK(condition[k] / condition[k - 1] == Approx(ratio[k] / ratio[k - 1]).epsilon(0.1));
    }
    // cond / (λ/μ) settles to a constant.
    CHECK(condition[2] / ratio[2] == Approx(condition[1] / ratio[1]).epsilon(0.02));
}
