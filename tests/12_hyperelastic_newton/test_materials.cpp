// Chapter 12: energy densities, stresses and their derivatives against finite differences, the
// rest state, small strains against linear elasticity, and the positive semi-definite projection.
// docs/12_hyperelastic_newton.md
#include "12_hyperelastic_newton/materials.hpp"

#include "common/error.hpp"
#include "common/random.hpp"

#include "../common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

using namespace fem;
using namespace fem::hyper;
using fem::test::EntriesNear;
using fem::test::entries_of;
using Catch::Matchers::Contains;

namespace {

const elastic::Lame steel_like = elastic::lame_parameters(1e6, 0.35);

/// H = F − I: the materials take the displacement gradient.
Eigen::Matrix3d gradient_of(const Eigen::Matrix3d& F)
{
    return F - Eigen::Matrix3d::Identity();
}

/// A random F near I (seeded): I + 0.3 × noise, det > 0.
Eigen::Matrix3d random_deformation(unsigned seed)
{
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + 0.3 * Eigen::Matrix3d(fem::random_matrix(3, 3, seed));
    if (F.determinant() <= 0.0)
        F.row(0) = -F.row(0);
    return F;
}

/// The matrix with entry (a, b) = F(a, b) + h at (row, column) = index (row-major), others F.
Eigen::Matrix3d nudged(const Eigen::Matrix3d& F, int index, double h)
{
    Eigen::Matrix3d G = F;
    G(index / 3, index % 3) += h;
    return G;
}

/// The best relative error of the finite-difference sweep of P against ψ, and of ∂P/∂F against P.
std::pair<double, double> derivative_errors(const Material& material, const Eigen::Matrix3d& F_sample)
{
    const Eigen::Matrix3d F = gradient_of(F_sample);  // H; ∂/∂H = ∂/∂F
    const Vector9d P = flatten(material.first_piola(F));
    const Matrix9d dP = material.piola_derivative(F);
    double best_P = 1e300, best_dP = 1e300;
    const double scale = std::max(1.0, F_sample.norm());
    for (double h = 1e-3 * scale; h > 0.5e-8 * scale; h /= 10.0) {
        Vector9d fd_P;
        Matrix9d fd_dP;
        for (int i = 0; i < 9; ++i) {
            fd_P[i] = (material.energy_density(nudged(F, i, h)) - material.energy_density(nudged(F, i, -h))) / (2.0 * h);
            fd_dP.col(i) = (flatten(material.first_piola(nudged(F, i, h))) -
                            flatten(material.first_piola(nudged(F, i, -h)))) / (2.0 * h);
        }
        best_P = std::min(best_P, (fd_P - P).norm() / P.norm());
        best_dP = std::min(best_dP, (fd_dP - dP).norm() / dP.norm());
    }
    return {best_P, best_dP};
}

}  // namespace

namespace {

/// The finite-difference checks of one material at random F, F with repeated singular values,
/// and (where the material is defined there) inverted and flat F.
void check_derivatives(const std::string& name)
{
    const auto material = make_material(name, 1e6, 0.35);
    std::vector<Eigen::Matrix3d> samples;
    for (unsigned seed = 1; seed <= 8; ++seed)
        samples.push_back(random_deformation(seed));
    // Repeated singular values: a rotated uniform stretch and a rotated uniaxial one.
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    samples.push_back(1.3 * R);
    samples.push_back(R * Eigen::Vector3d(1.4, 0.9, 0.9).asDiagonal());
    if (material->defined_when_inverted()) {
        samples.push_back(R * Eigen::Vector3d(1.1, 0.8, -0.4).asDiagonal());  // inverted
        samples.push_back(R * Eigen::Vector3d(1.2, 0.7, 0.0).asDiagonal());   // flat
    }
    for (const Eigen::Matrix3d& F : samples) {
        const auto [P_error, dP_error] = derivative_errors(*material, F);
        CAPTURE(name, F.determinant(), P_error, dP_error);
        CHECK(P_error < 1e-6);
        CHECK(dP_error < 1e-6);
        const Matrix9d dP = material->piola_derivative(gradient_of(F));
        CHECK_THAT(entries_of(dP), EntriesNear(dP.transpose(), 1e-12 * dP.norm()));
    }
}

}  // namespace

TEST_CASE("StVK: P = dpsi/dF and dP/dF by finite differences, at random, inverted and isotropic F", "[ex12.1]")
{
    check_derivatives("stvk");
}

TEST_CASE("neo-Hookean: P = dpsi/dF and dP/dF by finite differences, at random and isotropic F", "[ex12.2]")
{
    check_derivatives("neo-hookean");
}

TEST_CASE("stable neo-Hookean: P = dpsi/dF and dP/dF by finite differences, inverted and flat F too", "[ex12.3]")
{
    check_derivatives("stable-neo-hookean");
}

TEST_CASE("stable neo-Hookean, the paper's form: P and dP/dF by finite differences, inverted and flat F too", "[ex12.3]")
{
    check_derivatives("stable-neo-hookean-paper");
}

TEST_CASE("materials: stress free at rest, zero stress energy under rotation, linear elasticity for small strains",
          "[ex12.2]")
{
    const Eigen::Matrix3d G = Eigen::Matrix3d(fem::random_matrix(3, 3, 41));
    const Eigen::Matrix3d R = Eigen::AngleAxisd(2.5, Eigen::Vector3d(-1, 2, 0.5).normalized()).toRotationMatrix();
    for (const std::string& name : material_names()) {
        const auto material = make_material(name, 1e6, 0.35);
        const elastic::Lame lame = material->lame();
        CAPTURE(name);
        CHECK(material->first_piola(Eigen::Matrix3d::Zero()).norm() == 0.0);
        CHECK(material->energy_density(Eigen::Matrix3d::Zero()) == 0.0);
        CHECK(std::abs(material->energy_density(gradient_of(R))) <= 1e-9 * lame.mu);  // rotations cost nothing
        CHECK(material->first_piola(gradient_of(R)).norm() <= 1e-9 * lame.mu);
        // P(I + εG) − σ_linear(ε) = O(ε²): the gap falls 4× when ε halves.
        std::vector<double> gaps;
        for (const double eps : {1e-2, 5e-3, 2.5e-3}) {
            const Eigen::Matrix3d grad = eps * G, strain = 0.5 * (grad + grad.transpose());
            const Eigen::Matrix3d linear = 2.0 * lame.mu * strain + lame.lambda * strain.trace() * Eigen::Matrix3d::Identity();
            gaps.push_back((material->first_piola(grad) - linear).norm());
        }
        for (std::size_t k = 1; k < gaps.size(); ++k)
            CHECK(std::log2(gaps[k - 1] / gaps[k]) == Approx(2.0).margin(0.1));
    }
}

TEST_CASE("neo-Hookean: infinite energy and a clear error for det F <= 0, stable neo-Hookean pushes back", "[ch12]")
{
    const Eigen::Matrix3d inverted = gradient_of(Eigen::Vector3d(1.0, 1.0, -0.2).asDiagonal());
    const NeoHookean neo(steel_like);
    CHECK(std::isinf(neo.energy_density(inverted)));
    CHECK_THROWS_WITH(neo.first_piola(inverted), Contains("det F"));
    CHECK_THROWS_AS(neo.piola_derivative(inverted), Error);
    // The stable one: the stress of an inverted element points back toward det F > 0.
    const StableNeoHookean stable(steel_like);
    const Eigen::Matrix3d P = stable.first_piola(inverted);
    CHECK(P(2, 2) < 0.0);  // dψ/dF₂₂ < 0: increasing F₂₂ (un-inverting) lowers the energy
    CHECK(std::isfinite(stable.energy_density(inverted)));
    CHECK_THROWS_WITH(make_material("rubber", 1e6, 0.3), Contains("stable-neo-hookean"));
    CHECK_THROWS_AS(make_material("stvk", 1e6, 0.5), Error);
    CHECK_THROWS_AS(make_material("stvk", -1.0, 0.3), Error);
    CHECK_THROWS_AS(stable.first_piola(Eigen::Matrix3d::Constant(NAN)), Error);
}

TEST_CASE("materials: tiny strains keep their relative accuracy (written in H, nothing of size mu cancels)", "[ex12.2]")
{
    const Eigen::Matrix3d G = Eigen::Matrix3d(fem::random_matrix(3, 3, 43));
    for (const std::string& name : material_names()) {
        const auto material = make_material(name, 1e6, 0.35);
        const elastic::Lame lame = material->lame();
        for (const double eps : {1e-9, 1e-12}) {
            const Eigen::Matrix3d grad = eps * G, strain = 0.5 * (grad + grad.transpose());
            const Eigen::Matrix3d linear = 2.0 * lame.mu * strain + lame.lambda * strain.trace() * Eigen::Matrix3d::Identity();
            const double energy = lame.mu * strain.squaredNorm() + 0.5 * lame.lambda * strain.trace() * strain.trace();
            CAPTURE(name, eps);
            CHECK_THAT(test::entries_of(material->first_piola(grad)), test::EntriesNear(linear, 1e-6 * linear.norm()));
            CHECK(material->energy_density(grad) == Approx(energy).epsilon(1e-6));
        }
    }
}

TEST_CASE("volume_change and cofactor_change: det(I + H) - 1 and cof(I + H) - I without cancellation", "[ch12]")
{
    const Eigen::Matrix3d H = 0.3 * Eigen::Matrix3d(fem::random_matrix(3, 3, 44));
    const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + H;
    CHECK(volume_change(H) == Approx(F.determinant() - 1.0).epsilon(1e-12));
    CHECK_THAT(entries_of(cofactor_change(H)), EntriesNear((cofactor(F) - Eigen::Matrix3d::Identity()), 1e-12));
    const Eigen::Matrix3d tiny = 1e-12 * H;
    CHECK(volume_change(tiny) == Approx(tiny.trace()).epsilon(1e-9));  // det F − 1 would be round-off
}

TEST_CASE("the cofactor is dJ/dF, J F^-T where F is invertible, and defined where it is not", "[ch12]")
{
    const Eigen::Matrix3d F = random_deformation(5);
    CHECK_THAT(entries_of(cofactor(F)), EntriesNear(F.determinant() * F.inverse().transpose(), 1e-12 * F.norm()));
    const Eigen::Matrix3d flat = Eigen::Vector3d(1.0, 2.0, 0.0).asDiagonal();
    CHECK((cofactor(flat) - Eigen::Matrix3d(Eigen::Vector3d(0.0, 0.0, 2.0).asDiagonal())).norm() == 0.0);
}

TEST_CASE("PSD projection: clamp or mirror the negative eigenvalues, leave a PSD matrix alone", "[ex12.6]")
{
    const Eigen::Matrix3d compressed = gradient_of(Eigen::Vector3d(0.6, 0.7, 0.8).asDiagonal());
    const Matrix9d dP = StVenantKirchhoff(steel_like).piola_derivative(compressed);
    const Eigen::SelfAdjointEigenSolver<Matrix9d> before(dP);
    CHECK(before.eigenvalues().minCoeff() < 0.0);  // StVK under compression: indefinite
    for (const Projection projection : {Projection::clamp, Projection::absolute}) {
        const Matrix9d projected = project_to_psd<9>(dP, projection);
        const Eigen::SelfAdjointEigenSolver<Matrix9d> after(projected);
        CHECK(after.eigenvalues().minCoeff() >= -1e-9 * dP.norm());
        Eigen::Matrix<double, 9, 1> expected = before.eigenvalues();
        for (int i = 0; i < 9; ++i)
            if (expected[i] < 0.0)
                expected[i] = projection == Projection::clamp ? 0.0 : -expected[i];
        std::sort(expected.data(), expected.data() + 9);
        CHECK_THAT(entries_of(after.eigenvalues()), EntriesNear(expected, 1e-9 * dP.norm()));
    }
    const Matrix9d positive = StableNeoHookean(steel_like).piola_derivative(Eigen::Matrix3d::Zero());
    CHECK_THAT(entries_of(project_to_psd<9>(positive, Projection::clamp)), EntriesNear(positive, 1e-9 * positive.norm()));
}

TEST_CASE("neo_hookean_stress_change: dP along dF against finite differences of P written out", "[ex12.10]")
{
    // The independent answer: P = μ(F − F⁻ᵀ) + λ ln J F⁻ᵀ written here from F with Eigen's inverse
    // (not the chapter's first_piola), differenced centrally along δF over a sweep of steps.
    const elastic::Lame lame = steel_like;
    const auto piola = [&](const Eigen::Matrix3d& F) -> Eigen::Matrix3d {
        const Eigen::Matrix3d G = F.inverse().transpose();
        return lame.mu * (F - G) + lame.lambda * std::log(F.determinant()) * G;
    };
    std::vector<Eigen::Matrix3d> samples;
    for (unsigned seed = 1; seed <= 8; ++seed)
        samples.push_back(random_deformation(seed));
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    samples.push_back(1.3 * R);                                           // ln J ≠ 0, μ − λ ln J < 0
    samples.push_back(R * Eigen::Vector3d(1.4, 0.9, 0.2).asDiagonal());  // strongly compressed
    for (std::size_t k = 0; k < samples.size(); ++k) {
        const Eigen::Matrix3d& F = samples[k];
        const Eigen::Matrix3d dF = random_matrix(3, 3, 50 + static_cast<unsigned>(k));
        const Eigen::Matrix3d dP = neo_hookean_stress_change(lame, F, dF);
        double best = 1e300;
        for (double h = 1e-3; h > 1e-9; h /= 10.0) {
            const Eigen::Matrix3d fd = (piola(F + h * dF) - piola(F - h * dF)) / (2.0 * h);
            best = std::min(best, (fd - dP).norm() / fd.norm());
        }
        CAPTURE(k, F.determinant(), best);
        CHECK(best < 1e-7);
    }
    // Linear in δF, zero for δF = 0; refused where neo-Hookean is undefined.
    const Eigen::Matrix3d F = random_deformation(3), dF = random_matrix(3, 3, 7);
    CHECK(neo_hookean_stress_change(lame, F, 2.0 * dF).isApprox(2.0 * neo_hookean_stress_change(lame, F, dF), 1e-14));
    CHECK(neo_hookean_stress_change(lame, F, Eigen::Matrix3d::Zero()).isZero(0.0));
    CHECK_THROWS_AS(neo_hookean_stress_change(lame, Eigen::Vector3d(1.0, 1.0, -0.5).asDiagonal(), dF), Error);
}
