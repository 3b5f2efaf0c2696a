// Chapter 12: the line search's volume filter — det(E + s dE) as a cubic, its first crossing of a
// floor, the largest step that keeps every tet's volume, and a Newton step that keeps every tet
// right side out at every iterate where, without the filter, stable neo-Hookean turns them inside out.
// docs/12_hyperelastic_newton.md#the-volume-filter
#include "12_hyperelastic_newton/force_models.hpp"
#include "12_hyperelastic_newton/hyperelastic.hpp"
#include "12_hyperelastic_newton/newton.hpp"
#include "12_hyperelastic_newton/volume_filter.hpp"

#include "09_conjugate_gradient/linear_solver.hpp"
#include "06_assembly/assembly.hpp"
#include "04_tet_jacobians/tet_jacobians.hpp"

#include "common/error.hpp"
#include "common/mesh.hpp"
#include "common/random.hpp"

#include "pinned_cube.hpp"

#include <catch2/catch.hpp>

#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

using namespace fem;
using namespace fem::hyper;
using Catch::Matchers::Contains;

namespace {

/// A StepPotential of zero energy that watches Newton: at every configuration it is asked its
/// gradient at (each iterate), the smallest ratio of a tet's signed volume to its rest volume.
class VolumeWatch final : public StepPotential {
public:
    explicit VolumeWatch(const dynamics::Body& body) : body_(body) {}
    double energy(const Eigen::VectorXd&) const override { return 0.0; }
    Eigen::VectorXd gradient(const Eigen::VectorXd& u) const override
    {
        const TetMesh& mesh = body_.mesh();
        const MatrixX3d x = body_.positions(u);
        for (int t = 0; t < static_cast<int>(mesh.T.rows()); ++t)
            smallest = std::min(smallest, tet::signed_volume(tet::tet_vertices(mesh, x, t)) /
                                              tet::signed_volume(tet::tet_vertices(mesh, mesh.V, t)));
        ++watched;
        return Eigen::VectorXd::Zero(u.size());
    }
    dynamics::SparseMatrix hessian(const Eigen::VectorXd& u) const override
    {
        return dynamics::SparseMatrix(u.size(), u.size());
    }
    mutable double smallest = std::numeric_limits<double>::infinity();
    mutable int watched = 0;

private:
    const dynamics::Body& body_;
};

}  // namespace

TEST_CASE("determinant_cubic: det(E + s dE) at any s from its four coefficients")
{
    for (unsigned trial = 0; trial < 20; ++trial) {
        const Eigen::Matrix3d E = random_matrix(3, 3, 2 * trial), dE = 10.0 * random_matrix(3, 3, 2 * trial + 1);
        const Eigen::Vector4d c = determinant_cubic(E, dE);
        for (double s : {-1.5, -0.3, 0.0, 0.25, 0.7, 1.0, 2.0}) {
            const double direct = (E + s * dE).determinant();
            CHECK(c[0] + s * (c[1] + s * (c[2] + s * c[3])) == Approx(direct).margin(1e-12 * (1.0 + 1e3)));
        }
    }
}

TEST_CASE("first_crossing: the first root of a cubic above its floor, never one past it")
{
    // g(s) = c(s) − floor with roots 0.4, 0.5 and 3 (scaled): it dips below between 0.4 and 0.5 and
    // comes back; the first crossing is 0.4, and the cubic is above the floor before it.
    const auto cubic_with_roots = [](double r1, double r2, double r3, double scale, double floor) {
        // scale (s − r1)(s − r2)(s − r3) + floor, with c₀ = −scale r1 r2 r3 + floor
        return Eigen::Vector4d(-scale * r1 * r2 * r3 + floor, scale * (r1 * r2 + r2 * r3 + r1 * r3),
                               -scale * (r1 + r2 + r3), scale);
    };
    const Eigen::Vector4d dip = cubic_with_roots(0.4, 0.5, 3.0, -1.0, 0.25);
    CHECK(first_crossing(dip, 0.25) == Approx(0.4).epsilon(1e-14));
    CHECK(first_crossing(dip, 0.25) < 0.4);  // from below: the cubic is above the floor there
    // A narrow dip (below the floor on 0.6 < s < 0.6001 only) with the cubic above it again at 1.
    const Eigen::Vector4d narrow = cubic_with_roots(0.6, 0.6001, 5.0, -1.0, 2.0);
    CHECK(first_crossing(narrow, 2.0) == Approx(0.6).epsilon(1e-12));  // g(1) > 0: found by the split
    // No crossing on [0, 1] (roots at 1.5, 2 and −1): 1.
    CHECK(first_crossing(cubic_with_roots(1.5, 2.0, -1.0, 1.0, 0.0), 0.0) == 1.0);
    // A linear and a quadratic: c₀ + c₁ s with c₀ = 1, c₁ = −4, floor 0.2 → s = 0.2;
    // 1 − s² = 0.19 → s = 0.9.
    CHECK(first_crossing(Eigen::Vector4d(1.0, -4.0, 0.0, 0.0), 0.2) == Approx(0.2).epsilon(1e-14));
    CHECK(first_crossing(Eigen::Vector4d(1.0, 0.0, -1.0, 0.0), 0.19) == Approx(0.9).epsilon(1e-14));
    // Brute force on random cubics: no sample before the answer is at or below the floor, and the
    // cubic reaches the floor at it (or the answer is 1).
    for (unsigned trial = 0; trial < 200; ++trial) {
        Eigen::Vector4d c = 4.0 * random_vector(4, 100 + trial);
        c[0] = 1.0;
        const double floor = 0.1, s = first_crossing(c, floor);
        const auto g = [&](double t) { return c[0] + t * (c[1] + t * (c[2] + t * c[3])) - floor; };
        CAPTURE(c.transpose(), s);
        for (int k = 0; k < 1000; ++k)
            CHECK(g(s * k / 1000.0) > 0.0);
        if (s < 1.0)
            CHECK(std::abs(g(s)) < 1e-12);
    }
    CHECK_THROWS_WITH(first_crossing(Eigen::Vector4d(0.1, 1.0, 0.0, 0.0), 0.1), Contains("start above the floor"));
    CHECK_THROWS_WITH(first_crossing(Eigen::Vector4d(1.0, NAN, 0.0, 0.0), 0.1), Contains("finite"));
}

TEST_CASE("largest_volume_keeping_step: a vertex driven through the opposite face stops at the kept fraction")
{
    // The unit corner tet, its apex (0, 0, 1) driven down by 4: the volume falls linearly to 0 at
    // s = 1/4, to 0.1 of itself at s = 0.9/4. A tet already inverted is not held.
    TetMesh tet;
    tet.V.resize(4, 3);
    tet.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
    tet.T.resize(1, 4);
    tet.T << 0, 1, 2, 3;
    MatrixX3d dx = MatrixX3d::Zero(4, 3);
    dx(3, 2) = -4.0;
    CHECK(largest_volume_keeping_step(tet, tet.V, dx, 0.1) == Approx(0.225).epsilon(1e-14));
    CHECK(largest_volume_keeping_step(tet, tet.V, dx, 0.0) == Approx(0.25).epsilon(1e-14));
    CHECK(largest_volume_keeping_step(tet, tet.V, -dx, 0.1) == 1.0);  // moving away: free
    MatrixX3d inverted = tet.V;
    inverted(3, 2) = -1.0;
    CHECK(largest_volume_keeping_step(tet, inverted, dx, 0.1) == 1.0);
    CHECK_THROWS_WITH(largest_volume_keeping_step(tet, tet.V, dx, 1.0), Contains("[0, 1)"));
    CHECK_THROWS_WITH(largest_volume_keeping_step(tet, tet.V, MatrixX3d::Zero(3, 3), 0.1), Contains("one row per vertex"));
}

TEST_CASE("Newton backward Euler with the volume filter: stable neo-Hookean keeps every tet right side out at "
          "every iterate where, without it, the step inverts them", "[ex12.9]")
{
    // A soft cube of 2³ cells pinned at its base, its top slammed down at 40 m/s: one step of 1/24 s
    // would move the top by sixteen times the cube's height. Stable neo-Hookean is finite at J ≤ 0,
    // so without the filter nothing stops Newton's iterates from turning tets inside out.
    dynamics::Scene scene = test::pinned_cube(1e5, 0.4, 1.0 / 24.0);
    scene.gravity.setZero();
    Eigen::VectorXd v0 = Eigen::VectorXd::Zero(3 * scene.mesh.V.rows());
    for (Eigen::Index v = 0; v < scene.mesh.V.rows(); ++v)
        v0[3 * v + 2] = -400.0 * scene.mesh.V(v, 2);
    const auto run = [&](double kept_volume) {
        dynamics::Body body(scene, make_force_model("stable-neo-hookean", scene.mesh, scene.material));
        NewtonOptions options;
        options.kept_volume = kept_volume;
        options.max_iterations = 200;
        NewtonBackwardEuler newton(options);
        VolumeWatch watch(body);
        newton.set_potential(&watch);
        dynamics::State state = dynamics::initial_state(body, {}, v0);
        for (int step = 0; step < 5; ++step)
            newton.step(body, scene.time_step, state);
        return watch.smallest;
    };
    const double unfiltered = run(0.0), filtered = run(0.1);
    CAPTURE(unfiltered, filtered);
    CHECK(unfiltered < 0.0);  // the test's scene does invert tets without the filter
    CHECK(filtered > 0.0);
    CHECK_THROWS_WITH(NewtonBackwardEuler([] {
                          NewtonOptions options;
                          options.kept_volume = -0.1;
                          return options;
                      }()),
                      Contains("kept volume"));
}

TEST_CASE("Newton's definite system: one that does not factor, by round-off or by a planted indefinite block, stops "
          "in the course's words", "[ex12.9]")
{
    // E(x) = ½ xᵀ A x − bᵀ x with A = 10²⁰ n nᵀ + 10⁻³ I, n = (1, 1)/√2: positive definite, but the
    // second pivot of its Cholesky factor (10⁻³ beside a diagonal of 5·10¹⁹) is below the pivot test
    // n ε |a_jj| of chapter 08's factorization: the 10⁻³ is lost in the sum (a contact pair a hair
    // apart beside a vertex's mass, which chapter 15's minimum separation prevents).
    const Eigen::Vector2d n = Eigen::Vector2d(1.0, 1.0).normalized();
    const auto sparse = [](const Eigen::Matrix2d& dense) {
        dynamics::SparseMatrix matrix = dense.sparseView();
        return matrix;
    };
    dynamics::SparseMatrix A = sparse(1e20 * n * n.transpose() + 1e-3 * Eigen::Matrix2d::Identity());
    const Eigen::Vector2d b = 1e20 * n;
    const auto solver = cg::make_solver("ours-cholesky");
    CHECK_THROWS_WITH(solver->prepare(A), Contains("pivot"));  // the factorization alone fails
    NewtonProblem problem;
    problem.objective = [&](const Eigen::VectorXd& x, double* magnitude) {
        const double quadratic = 0.5 * x.dot(A * x), work = b.dot(x);
        if (magnitude != nullptr)
            *magnitude = std::abs(quadratic) + std::abs(work);
        return quadratic - work;
    };
    problem.gradient = [&](const Eigen::VectorXd& x) { return Eigen::VectorXd(A * x - b); };
    problem.hessian = [&](const Eigen::VectorXd&, bool) -> const dynamics::SparseMatrix& { return A; };
    problem.scale = b.norm();
    problem.what = "the planted problem";
    NewtonOptions options;
    options.hessian = HessianChoice::definite;
    const auto message = [&] {
        try {
            (void)newton_minimize(problem, Eigen::VectorXd::Zero(2), options, *solver);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    // The round-off failure, and a "definite" Hessian that is not (diag(1, −1), a bug planted in a
    // potential): each names the problem and what to change, not the factorization.
    for (const dynamics::SparseMatrix& planted : {A, sparse(Eigen::Vector2d(1.0, -1.0).asDiagonal())}) {
        A = planted;
        const std::string error = message();
        CAPTURE(error);
        CHECK_THAT(error, Contains("Newton: the planted problem: the system of the Newton step") &&
                              Contains("is not positive definite to working precision") && Contains("use a smaller dt"));
        CHECK_THAT(error, !Contains("Cholesky") && !Contains("pivot"));
    }
}
