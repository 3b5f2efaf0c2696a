// Chapter 15: the self-contact Hessian's anticipated pattern (BodyContactOptions::pattern_reach,
// SelfContactBarrier::anticipate): the same values as the Hessian of the pairs within d̂ alone, in a
// pattern that holds that one's, and one pattern over a step's Newton iterations while pairs arrive
// (also where the exact barrier Hessian fails to factor); Newton's step-length test in the impact;
// the contact potential's clocks (ContactClocks) that split such a step's time.
// docs/15_body_contact.md#the-cost-of-contact
#include "15_body_contact/body_contact.hpp"
#include "15_body_contact/intersections.hpp"
#include "15_body_contact/timed_solver.hpp"

#include "contact_bodies.hpp"

#include "12_hyperelastic_newton/force_models.hpp"
#include "12_hyperelastic_newton/newton.hpp"

#include "09_conjugate_gradient/linear_solver.hpp"

#include "common/timer.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Core>
#include <Eigen/Sparse>

#include <limits>
#include <memory>
#include <set>
#include <utility>
#include <vector>

using namespace fem;
using namespace fem::contact;
using fem::test::box_at;
using fem::test::two_bodies;

namespace {

/// The (row, column) of every stored entry of A, explicit zeros included.
std::set<std::pair<Eigen::Index, Eigen::Index>> pattern(const Eigen::SparseMatrix<double>& A)
{
    std::set<std::pair<Eigen::Index, Eigen::Index>> entries;
    for (Eigen::Index j = 0; j < A.outerSize(); ++j)
        for (Eigen::SparseMatrix<double>::InnerIterator it(A, j); it; ++it)
            entries.emplace(it.row(), it.col());
    return entries;
}

/// Two blocks of 2³ cells of 1 cm, 1.5 mm apart along x and offset in y and z, thrown at each other
/// at ±0.5 m/s (2.5 mm closer a step of 1/400 s: pairs come within d̂ = 1 mm during the first
/// step's Newton iterations), with self-contact, the Hessian's pattern reaching reach × d̂, and
/// Newton's solver counting new patterns; Newton also stopped by its step's length at step_fraction
/// × d̂ (0: the gradient's test alone), the barrier's Hessian tried exact first when exact.
struct Approach : test::ContactRun {
    TimedSolver* solver = nullptr;  // counts the matrices with a new pattern

    explicit Approach(double reach, double step_fraction = 0.0, bool exact = false)
        : ContactRun(test::free_scene(mesh()), options(reach, exact), {}, {}, thrown())
    {
        hyper::NewtonOptions newton_options;
        newton_options.relative_tolerance = 1e-9;
        newton_options.max_iterations = 200;
        newton_options.step_tolerance = step_fraction * contact->options().activation_distance / time_step;
        newton_options.make_solver = [this] {
            auto counting = std::make_unique<TimedSolver>(cg::make_solver("default"));
            solver = counting.get();
            return counting;
        };
        newton = std::make_unique<hyper::NewtonBackwardEuler>(newton_options);
        newton->set_potential(contact.get());
    }
    static TetMesh mesh()
    {
        return two_bodies(box_at(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(0.01), 2),
                          box_at(Eigen::Vector3d(0.0115, 0.002, -0.003), Eigen::Vector3d::Constant(0.01), 2));
    }
    static BodyContactOptions options(double reach, bool exact = false)
    {
        BodyContactOptions options;
        options.self_contact = true;
        options.pattern_reach = reach;
        options.exact_barrier_hessian = exact;
        return options;
    }
    static Eigen::VectorXd thrown()
    {
        const Eigen::Index n = mesh().V.rows();
        Eigen::VectorXd velocity = Eigen::VectorXd::Zero(3 * n);
        for (Eigen::Index v = 0; v < n; ++v)
            velocity[3 * v] = v < n / 2 ? 0.5 : -0.5;
        return velocity;
    }
};

}  // namespace

TEST_CASE("self-contact's anticipated pattern: the same Hessian values in a pattern that holds the plain one's",
          "[self][ex15.5]")
{
    Approach plain(0.0), anticipated(1.0);
    plain.contact->begin_step(*plain.body, plain.state, plain.time_step);
    anticipated.contact->begin_step(*anticipated.body, anticipated.state, anticipated.time_step);
    REQUIRE(plain.contact->stiffness() == anticipated.contact->stiffness());
    CHECK(plain.contact->term<BodyContactTerm>()->barrier().anticipated_pattern().nonZeros() == 0);
    // Along the predicted motion, from no pair within d̂ to several (at full speed the 1.5 mm gap
    // closes by 2.5 mm over the step: 1 mm, 0.625 mm and 0.25 mm are left at 0.2, 0.35 and 0.5 of it).
    std::size_t most_pairs = 0;
    for (double fraction : {0.0, 0.2, 0.35, 0.5}) {
        INFO("fraction " << fraction << " of the step's predicted motion");
        const Eigen::VectorXd u = plain.state.u + fraction * plain.time_step * plain.state.v;
        const std::size_t within = plain.contact->term<BodyContactTerm>()->barrier().pairs(u, false).size();
        most_pairs = std::max(most_pairs, within);
        const Eigen::SparseMatrix<double> H = plain.contact->hessian(u), G = anticipated.contact->hessian(u);
        CHECK(Eigen::MatrixXd(G) == Eigen::MatrixXd(H));  // bit for bit: only zeros were added
        const auto plain_pattern = pattern(H), anticipated_pattern = pattern(G);
        CHECK(std::includes(anticipated_pattern.begin(), anticipated_pattern.end(), plain_pattern.begin(),
                            plain_pattern.end()));
        CHECK(anticipated_pattern.size() > plain_pattern.size());
        // The same pattern at every point of the motion: the one anticipate fixed.
        CHECK(anticipated_pattern == pattern(anticipated.contact->term<BodyContactTerm>()->barrier().anticipated_pattern()));
    }
    CHECK(most_pairs > 10);  // the blocks' pairs arrive along the motion
}

TEST_CASE("self-contact's anticipated pattern: one matrix pattern a step while pairs arrive, the same steps",
          "[self][ex15.5]")
{
    Approach plain(0.0), anticipated(1.0);
    int plain_most = 0, anticipated_most = 0;
    for (int step = 0; step < 3; ++step) {
        const int plain_before = plain.solver ? plain.solver->new_patterns : 0;
        const int anticipated_before = anticipated.solver ? anticipated.solver->new_patterns : 0;
        plain.step();
        anticipated.step();
        plain_most = std::max(plain_most, plain.solver->new_patterns - plain_before);
        anticipated_most = std::max(anticipated_most, anticipated.solver->new_patterns - anticipated_before);
        INFO("step " << step);
        // The same Newton iterates up to the round-off of another elimination order.
        CHECK((anticipated.state.u - plain.state.u).lpNorm<Eigen::Infinity>() <= 1e-9 * 1e-3);
    }
    INFO("most new patterns in one step: " << plain_most << " plain, " << anticipated_most << " anticipated");
    CHECK(plain_most > 1);         // pairs arrived within a step: the plain Hessian changed its pattern
    CHECK(anticipated_most == 1);  // the anticipated one kept the step's first
    CHECK(anticipated.contact->smallest_distance(anticipated.state.u) < 1e-3);  // they met, within d̂
}

TEST_CASE("Newton's step-length test in an impact: fewer iterations, the end state within a fraction of dhat",
          "[self][ex15.5]")
{
    // The two blocks meet over 4 steps, solved to Newton's gradient tolerance (10⁻⁹) and again
    // stopped once a Newton direction moves no coordinate by more than 10⁻³ d̂: the same contact
    // (no surface crossed), momentum kept to round-off (internal forces only), and every vertex
    // within 5·10⁻³ d̂ of the tight run's.
    const double dhat = ContactOptions{}.activation_distance;
    Approach tight(1.0), stopped(1.0, 1e-3);
    const SurfacePrimitives surface = surface_primitives(Approach::mesh());
    const Eigen::Index n = tight.state.v.size() / 3;
    const Eigen::Vector3d start = test::momentum(*tight.body, tight.state.v, 0, n);
    double scale = 0.0;
    for (Eigen::Index k = 0; k < tight.state.v.size(); ++k)
        scale += tight.body->dof_masses()[k] * std::abs(tight.state.v[k]);
    int tight_iterations = 0, stopped_iterations = 0;
    for (int step = 0; step < 4; ++step) {
        INFO("step " << step);
        tight.step();
        stopped.step();
        tight_iterations += tight.newton->last().iterations;
        stopped_iterations += stopped.newton->last().iterations;
        CHECK((stopped.state.u - tight.state.u).lpNorm<Eigen::Infinity>() <= 5e-3 * dhat);
        CHECK((test::momentum(*stopped.body, stopped.state.v, 0, n) - start).norm() <= 1e-12 * scale);
        CHECK_FALSE(first_edge_through_triangle(stopped.body->positions(stopped.state.u), surface.edges,
                                                surface.triangles)
                        .found());
    }
    CHECK(stopped.contact->smallest_distance(stopped.state.u) < dhat);  // they met
    INFO(tight_iterations << " Newton iterations to the gradient's tolerance, " << stopped_iterations
                          << " with the step test");
    CHECK(stopped_iterations < tight_iterations);
}

TEST_CASE("the exact barrier Hessian that fails to factor costs no new matrix pattern (the solver keeps it)",
          "[self][ex15.5]")
{
    // Newton tries M + Δt² (K + ∇²P) first and, where it fails to factor, factors the clamped one of
    // the same anticipated pattern: chapter 09's solver keeps the failed one's ordering for it.
    Approach exact(1.0, 0.0, true);
    int fallbacks = 0;
    for (int step = 0; step < 4; ++step) {
        const int before = exact.solver ? exact.solver->new_patterns : 0;
        exact.step();
        fallbacks += exact.newton->last().definite_fallbacks;
        INFO("step " << step);
        CHECK(exact.solver->new_patterns - before <= 1);  // the step's pattern, once
    }
    CHECK(fallbacks > 0);  // some exact Hessians did fail
}

TEST_CASE("the contact potential's clocks: parts of its steps' time, its broad phases, zero after a reset",
          "[self][ex15.5]")
{
    Approach run(1.0);
    const SelfContactBarrier& self = run.contact->term<BodyContactTerm>()->barrier();
    ContactClocks clocks = run.contact->clocks();
    CHECK(clocks.barrier_seconds == 0.0);
    CHECK(clocks.collision_seconds == 0.0);
    CHECK(clocks.broad_phases == self.broad_phases());  // the constructor's check at rest among them
    CHECK(clocks.broad_phases > 0);
    for (int step = 0; step < 2; ++step) {
        run.contact->reset_clocks();
        const long long before = self.broad_phases();
        const Timer timer;
        run.step();
        const double seconds = timer.seconds();
        clocks = run.contact->clocks();
        INFO("step " << step << ": " << seconds << " s, barrier " << clocks.barrier_seconds << " s, collision check "
                     << clocks.collision_seconds << " s");
        CHECK(clocks.barrier_seconds > 0.0);    // begin_step, the energies, gradients and Hessians
        CHECK(clocks.collision_seconds > 0.0);  // the start velocity, the line searches' times of impact
        CHECK(clocks.barrier_seconds + clocks.collision_seconds <= seconds);  // parts of the step, none twice
        CHECK(clocks.broad_phases == self.broad_phases() - before);
    }
    // Reset, and asked only what neither clock covers: the clocks stay at zero.
    run.contact->reset_clocks();
    const long long at_reset = self.broad_phases();
    run.contact->smallest_distance(run.state.u);
    run.contact->barrier_energy(run.state.u, run.state.time);
    clocks = run.contact->clocks();
    CHECK(clocks.barrier_seconds == 0.0);
    CHECK(clocks.collision_seconds == 0.0);
    CHECK(clocks.broad_phases == self.broad_phases() - at_reset);  // the trees they built, if any
}

TEST_CASE("self-contact's anticipated pattern refuses a negative or non-finite reach", "[self][ex15.5]")
{
    const TetMesh mesh = Approach::mesh();
    const dynamics::Body body(test::free_scene(mesh), hyper::make_force_model("stable-neo-hookean", mesh, {1e5, 0.3, 1000.0}));
    for (double reach : {-1.0, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
        INFO("pattern reach " << reach);
        CHECK_THROWS_WITH(body_contact_potential(body, {}, Approach::options(reach)),
                          Catch::Contains("anticipated Hessian pattern must be >= 0"));
    }
    SelfContactBarrier barrier(mesh, 1e-3);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(3 * mesh.V.rows());
    CHECK_THROWS_WITH(barrier.anticipate(zero, zero, -1e-3), Catch::Contains("must be a finite number >= 0"));
    CHECK_THROWS_WITH(barrier.anticipate(zero, Eigen::VectorXd::Zero(3), 1e-3), Catch::Contains("the predicted motion"));
}
