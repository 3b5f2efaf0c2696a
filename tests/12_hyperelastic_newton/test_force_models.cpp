// Chapter 12: every model by name (force_models.hpp), the material registry, and stable
// neo-Hookean in the paper's form against the paper's formula written out from F.
// docs/12_hyperelastic_newton.md#every-model-by-name, docs/12_hyperelastic_newton.md#stable-neo-hookean
#include "12_hyperelastic_newton/force_models.hpp"
#include "12_hyperelastic_newton/materials.hpp"
#include "12_hyperelastic_newton/newton.hpp"

#include "11_corotational/corotational.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"
#include "common/random.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <cmath>

using namespace fem;
using namespace fem::hyper;
using Catch::Matchers::Contains;

TEST_CASE("the model names: linear, corotational, then every registered material, each built by its name", "[ch12]")
{
    const std::vector<std::string> names = force_model_names(), materials = material_names();
    REQUIRE(names.size() == materials.size() + 2);
    CHECK(names[0] == "linear");
    CHECK(names[1] == "corotational");
    CHECK(std::equal(materials.begin(), materials.end(), names.begin() + 2));
    const TetMesh mesh = box_mesh(1, 1, 1, Eigen::Vector3d(0.1, 0.1, 0.1));
    const dynamics::Material rubber{1e5, 0.45, 1000.0};
    for (const std::string& name : names) {
        CAPTURE(name);
        CHECK(is_hyperelastic(name) == (name != "linear" && name != "corotational"));
        CHECK(make_force_model(name, mesh, rubber)->name() == name);
        const auto integrator = make_integrator_for(name);
        CHECK(integrator->name() == (is_hyperelastic(name) ? "Newton backward Euler" : "backward Euler"));
    }
    for (const std::string& name : materials)  // the registry's name is the material's own
        CHECK(make_material(name, 1e5, 0.3)->name() == name);
    CHECK_FALSE(is_hyperelastic("rubber"));
    CHECK(make_integrator_for("corotational", {.integrator = "implicit-midpoint"})->order() == 2);
}

TEST_CASE("the material registry's names: each material's own, in words and as a label, in the registry's order", "[ch12]")
{
    const std::vector<MaterialNames> descriptions = material_descriptions();
    const std::vector<std::string> names = material_names();
    REQUIRE(descriptions.size() == names.size());
    for (std::size_t i = 0; i < names.size(); ++i) {
        CAPTURE(names[i]);
        CHECK(descriptions[i].name == names[i]);
        CHECK_FALSE(descriptions[i].in_words.empty());
        CHECK_FALSE(descriptions[i].label.empty());
    }
    CHECK(descriptions[0].in_words == "St. Venant-Kirchhoff");
    CHECK(descriptions[0].label == "StVK");
    // The course's stable neo-Hookean is compared; the paper's form of it is not (a variant).
    CHECK(descriptions[2].compared);
    CHECK_FALSE(descriptions[3].compared);
}

TEST_CASE("the model names: unknown names and a hyperelastic model with another integrator are refused", "[ch12]")
{
    const TetMesh mesh = box_mesh(1, 1, 1, Eigen::Vector3d(0.1, 0.1, 0.1));
    CHECK_THROWS_WITH(make_force_model("rubber", mesh, {}), Contains("unknown force model 'rubber'") &&
                                                                Contains("corotational") && Contains("stable-neo-hookean-paper"));
    CHECK_THROWS_WITH(make_integrator_for("rubber"), Contains("unknown force model 'rubber'"));
    CHECK_THROWS_WITH(make_integrator_for("neo-hookean", {.integrator = "implicit-midpoint"}),
                      Contains("backward Euler only"));
    CHECK_THROWS_WITH(make_integrator_for("linear", {.integrator = "leapfrog"}), Contains("leapfrog"));
    CHECK_THROWS_AS(make_integrator_for("stvk", {.newton_tolerance = 0.0}), Error);
    CHECK_THROWS_WITH(make_material("rubber", 1e6, 0.3), Contains("stable-neo-hookean-paper"));
}

TEST_CASE("the corotational model by name is chapter 11's polar fit with shape-gradient forces", "[ch12]")
{
    const TetMesh mesh = box_mesh(2, 1, 1, Eigen::Vector3d(0.2, 0.1, 0.1));
    const dynamics::Material rubber{1e5, 0.45, 1000.0};
    const auto by_name = make_force_model("corotational", mesh, rubber);
    corot::CorotationalElasticity lecture(mesh, rubber);  // the lecture's force form: the same forces
    const Eigen::VectorXd u = 0.02 * fem::random_vector(3 * mesh.V.rows(), 71);
    Eigen::VectorXd f, g;
    CHECK(by_name->evaluate(u, f) == Approx(lecture.evaluate(u, g)).epsilon(1e-12));
    CHECK((f - g).norm() <= 1e-10 * g.norm());
}

TEST_CASE("stable neo-Hookean in the paper's form: the paper's energy from F, linear elasticity for small strains",
          "[ch12]")
{
    // Smith, de Goes, Kim 2018, written out from F with their μ' = 4μ/3, λ' = λ + 5μ/6 and
    // α = 1 + 3μ'/(4λ'); the course's material subtracts its rest value.
    const double youngs = 1e6, poisson = 0.35;
    const auto paper = make_material("stable-neo-hookean-paper", youngs, poisson);
    const elastic::Lame lame = paper->lame();
    const double mu = 4.0 * lame.mu / 3.0, lambda = lame.lambda + 5.0 * lame.mu / 6.0, alpha = 1.0 + 0.75 * mu / lambda;
    const auto written_out = [&](const Eigen::Matrix3d& F) {
        const double I_C = F.squaredNorm(), J = F.determinant();
        return 0.5 * mu * (I_C - 3.0) - 0.5 * mu * std::log(I_C + 1.0) + 0.5 * lambda * (J - alpha) * (J - alpha);
    };
    const double rest = written_out(Eigen::Matrix3d::Identity());
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, -1, 2).normalized()).toRotationMatrix();
    for (const Eigen::Matrix3d& F : {Eigen::Matrix3d(Eigen::Matrix3d::Identity() + 0.3 * fem::random_matrix(3, 3, 73)),
                                     Eigen::Matrix3d(R * Eigen::Vector3d(1.5, 0.6, -0.3).asDiagonal()),  // inverted
                                     Eigen::Matrix3d(Eigen::Matrix3d::Zero())}) {                         // a point
        const double expected = written_out(F) - rest;
        CAPTURE(F.determinant(), expected);
        CHECK(paper->energy_density(F - Eigen::Matrix3d::Identity()) ==
              Approx(expected).epsilon(1e-12).margin(1e-12 * lame.mu));
    }
    // Its stress agrees with linear elasticity of (λ, μ) to first order: the gap falls 4× when ε halves
    // (also checked for every material in test_materials.cpp); the course's variant reaches the
    // same limit through λ̂ = λ + μ without the log term.
    const Eigen::Matrix3d G = fem::random_matrix(3, 3, 75);
    const auto course = make_material("stable-neo-hookean", youngs, poisson);
    const double eps = 1e-4;
    const Eigen::Matrix3d strain = 0.5 * eps * (G + G.transpose());
    const Eigen::Matrix3d linear = 2.0 * lame.mu * strain + lame.lambda * strain.trace() * Eigen::Matrix3d::Identity();
    CHECK((paper->first_piola(eps * G) - linear).norm() <= 1e-3 * linear.norm());
    CHECK((paper->first_piola(eps * G) - course->first_piola(eps * G)).norm() <= 1e-3 * linear.norm());
    // Far from rest the two part: the paper's log term holds a tet squeezed to a point at a higher energy.
    const Eigen::Matrix3d point = -Eigen::Matrix3d::Identity();
    CHECK(paper->energy_density(point) != Approx(course->energy_density(point)).epsilon(1e-3));
}
