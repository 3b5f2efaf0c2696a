// Study 4 of ch15_body_contact: what contact between bodies costs — two coarse bunnies thrown at each
// other, stepped as one mesh with self-contact and, side by side, the same two bunnies without
// contact (they pass through each other), and the contact run again with the Hessian's pattern of
// the pairs within d̂ alone (BodyContactOptions::pattern_reach = 0: a new pattern as pairs arrive); per
// step the time in the contact potential (its barrier with the broad phase, and its continuous
// collision check) against the time in the linear solves,
// with the momentum kept and the surface checked for intersections at every step; then the contact
// run again with Newton's tolerance loosened, its iterations against the end state's offset; and
// again (on request) with the barrier's Hessian projected otherwise or tried exact first, κ
// doubled or fixed, and Newton stopped by the length of its step as well (IPC's test).
// docs/15_body_contact.md#the-cost-of-contact
#include "15_body_contact/body_contact.hpp"
#include "15_body_contact/intersections.hpp"
#include "studies.hpp"
#include "15_body_contact/timed_solver.hpp"

#include "12_hyperelastic_newton/force_models.hpp"
#include "12_hyperelastic_newton/newton.hpp"

#include "09_conjugate_gradient/linear_solver.hpp"

#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh.hpp"
#include "common/mesh_io.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <cmath>
#include <iostream>
#include <map>
#include <memory>

namespace fem::contact::study {
namespace {

/// What one run of the two bunnies measured.
struct BunnyRun {
    int steps = 0, newton_iterations = 0, orderings = 0;
    double nonzeros = 0.0;       ///< of the matrices Newton solved with, on average
    long long broad_phases = 0;  ///< trees the self-contact barrier built (ContactClocks::broad_phases)
    double seconds = 0.0, solve_seconds = 0.0, barrier_seconds = 0.0, collision_seconds = 0.0;
    double momentum_drift = 0.0;  ///< the largest |Σ m v| over the run, relative to Σ m |v₀|
    bool intersection_free = true;
    double smallest_distance = 0.0;  ///< between the bunnies' surfaces over the run (contact only) [m]
    Eigen::VectorXd u;               ///< the displacements after the last step (3n) [m]
    int most_iterations = 0;   ///< of one step
    int fallbacks = 0;         ///< Newton iterations whose exact Hessian failed (HessianChoice::exact_then_definite)
    int factorizations = 0;    ///< the matrices the linear solver prepared, failed ones included
    double stiffness = 0.0;    ///< κ of the last step [N/m]
};

}  // namespace

void bodies_study(const RunContext& run, bool hessian_variants)
{
    std::cout << "\n== 4. Bodies against bodies: two coarse bunnies thrown at each other, one mesh with self-contact,\n"
                 "   beside the same two bunnies without contact; where a step's time goes\n\n";
    // The coarse bunny (data/bunny_coarse: 2,199 vertices) scaled to 20 cm, and a copy of it along x,
    // placed where moving it along x would first reach the first one's vertices after `gap` (the
    // vertices' largest and smallest x over 5 mm cells of (y, z)). Each spins about its own vertical
    // axis at ±5 rad/s (so that its step is a real elastic solve with contact or without, not a
    // rigid translation Newton finishes at once) and they close at 1 m/s: rubber (Y = 10⁵ Pa,
    // ν = 0.4, ρ = 1000 kg/m³), no gravity, Δt = 1/400 s, d̂ = 1 mm.
    // --quick: two 10 cm blocks of 3³ cells stand in for the bunnies (the same code, seconds less).
    TetMesh bunny = run.quick ? box_mesh(3, 3, 3, Eigen::Vector3d::Constant(0.1))
                              : io::read_tet_mesh(data_path("bunny_coarse.node"));
    const Eigen::RowVector3d low = bunny.V.colwise().minCoeff(), high = bunny.V.colwise().maxCoeff();
    bunny.V = ((bunny.V.rowwise() - low) * ((run.quick ? 0.1 : 0.2) / (high - low).maxCoeff())).eval();
    const double cell = 5e-3, gap = 5e-3, speed = 0.5, spin = 5.0;
    std::map<std::pair<int, int>, std::pair<double, double>> columns;  // (y, z) cell → (largest x, smallest x)
    for (Eigen::Index v = 0; v < bunny.V.rows(); ++v) {
        const std::pair<int, int> key{int(std::floor(bunny.V(v, 1) / cell)), int(std::floor(bunny.V(v, 2) / cell))};
        auto [it, added] = columns.try_emplace(key, bunny.V(v, 0), bunny.V(v, 0));
        it->second = {std::max(it->second.first, bunny.V(v, 0)), std::min(it->second.second, bunny.V(v, 0))};
    }
    double shift = 0.0;  // the copy at x + shift meets the first one's vertices in no column
    for (const auto& [key, extent] : columns)
        shift = std::max(shift, extent.first - extent.second);
    const Eigen::Index n = bunny.V.rows();
    dynamics::Scene scene;
    scene.mesh.V.resize(2 * n, 3);
    scene.mesh.V << bunny.V, bunny.V.rowwise() + Eigen::RowVector3d(shift + gap, 0.0, 0.0);
    scene.mesh.T.resize(2 * bunny.T.rows(), 4);
    scene.mesh.T << bunny.T, (bunny.T.array() + static_cast<int>(n)).matrix();
    scene.material = {1e5, 0.4, 1000.0};
    scene.gravity.setZero();
    scene.time_step = 1.0 / 400.0;
    const int steps = run.quick ? 4 : 8;
    Eigen::VectorXd v0 = Eigen::VectorXd::Zero(6 * n);
    const Eigen::RowVector3d centre = bunny.V.colwise().mean();
    for (Eigen::Index v = 0; v < 2 * n; ++v) {
        const double sign = v < n ? 1.0 : -1.0;
        const Eigen::RowVector3d arm = scene.mesh.V.row(v) - centre - (v < n ? 0.0 : shift + gap) * Eigen::RowVector3d::UnitX();
        v0.segment<3>(3 * v) = sign * (speed * Eigen::Vector3d::UnitX() + spin * Eigen::Vector3d(-arm.y(), arm.x(), 0.0));
    }
    BodyContactOptions options;
    options.self_contact = true;
    options.activation_distance = 1e-3;

    // step_fraction > 0: Newton also stops when its direction moves no vertex coordinate by more than
    // step_fraction × d̂ (NewtonOptions::step_tolerance = step_fraction d̂ / Δt).
    const auto one_run = [&](bool with_contact, double tolerance, const BodyContactOptions& run_options, double step_fraction = 0.0) {
        dynamics::Body body(scene, hyper::make_force_model("stable-neo-hookean", scene.mesh, scene.material));
        TimedSolver* solver = nullptr;
        hyper::NewtonOptions newton_options;
        newton_options.max_iterations = 200;
        newton_options.relative_tolerance = tolerance;
        newton_options.step_tolerance = step_fraction * options.activation_distance / scene.time_step;
        newton_options.make_solver = [&solver] {
            auto timed = std::make_unique<TimedSolver>(cg::make_solver("default"));
            solver = timed.get();
            return timed;
        };
        hyper::NewtonBackwardEuler newton(newton_options);
        std::unique_ptr<ContactPotential> contact;
        if (with_contact) {
            contact = std::make_unique<ContactPotential>(body_contact_potential(body, {}, run_options));
            newton.set_potential(contact.get());
        }
        dynamics::State state = dynamics::initial_state(body, {}, v0);
        const SurfacePrimitives surface = surface_primitives(scene.mesh);
        double scale = 0.0;
        for (Eigen::Index k = 0; k < v0.size(); ++k)
            scale += body.dof_masses()[k] * std::abs(v0[k]);
        BunnyRun result;
        result.smallest_distance = std::numeric_limits<double>::infinity();
        for (int step = 0; step < steps; ++step) {
            const Timer timer;
            const dynamics::StepInfo info =
                with_contact ? contact_step(newton, *contact, body, scene.time_step, state) : newton.step(body, scene.time_step, state);
            result.seconds += timer.seconds();
            result.newton_iterations += info.newton_iterations;
            result.most_iterations = std::max(result.most_iterations, info.newton_iterations);
            result.fallbacks += newton.last().definite_fallbacks;
            if (with_contact)
                result.stiffness = contact->stiffness();
            ++result.steps;
            Eigen::Vector3d momentum = Eigen::Vector3d::Zero();
            for (Eigen::Index k = 0; k < state.v.size(); ++k)
                momentum[k % 3] += body.dof_masses()[k] * state.v[k];
            result.momentum_drift = std::max(result.momentum_drift, momentum.norm() / scale);
            if (with_contact) {
                result.intersection_free = result.intersection_free &&
                    !first_edge_through_triangle(body.positions(state.u), surface.edges, surface.triangles).found();
                result.smallest_distance = std::min(result.smallest_distance, contact->smallest_distance(state.u));
            }
        }
        result.u = state.u;
        result.solve_seconds = solver ? solver->seconds : 0.0;
        result.orderings = solver ? solver->new_patterns : 0;
        result.factorizations = solver ? static_cast<int>(solver->prepares) : 0;
        result.nonzeros = solver && solver->prepares > 0 ? solver->nonzeros / solver->prepares : 0.0;
        if (contact) {
            const ContactClocks clocks = contact->clocks();
            result.broad_phases = clocks.broad_phases;
            result.barrier_seconds = clocks.barrier_seconds;
            result.collision_seconds = clocks.collision_seconds;
        }
        return result;
    };
    const double tolerance = hyper::NewtonOptions{}.relative_tolerance;  // 10⁻⁶, every other table's
    BodyContactOptions unanticipated = options;
    unanticipated.pattern_reach = 0.0;
    const BunnyRun contact_run = one_run(true, tolerance, options), unanticipated_run = one_run(true, tolerance, unanticipated),
                   free_run = one_run(false, tolerance, options);

    Table table(str(run.quick ? "Two blocks (2 x 64 vertices)" : "Two coarse bunnies (2 x 2,199 vertices)",
                    " thrown at each other at 1 m/s, spinning: per step, with self-contact and without"),
                {{"run", Format::text}, {"steps", Format::integer}, {"Newton iterations", Format::integer},
                 {"new matrix patterns", Format::integer}, {"matrix nonzeros", Format::scientific, 2},
                 {"broad phases", Format::integer},
                 {"time per step [ms]", Format::fixed, 1}, {"linear solves [ms]", Format::fixed, 1},
                 {"barrier and broad phase [ms]", Format::fixed, 1}, {"collision check [ms]", Format::fixed, 1},
                 {"step time / without contact [measured]", Format::fixed, 2},
                 {"momentum drift [round-off]", Format::scientific, 1},
                 {"intersection-free", Format::text}});
    const auto row = [&](const char* name, const BunnyRun& r) {
        const double per = 1e3 / r.steps;
        table.add_row({std::string(name), double(r.steps), double(r.newton_iterations), double(r.orderings),
                       r.nonzeros, double(r.broad_phases), per * r.seconds,
                       per * r.solve_seconds, per * r.barrier_seconds, per * r.collision_seconds,
                       r.seconds / free_run.seconds, r.momentum_drift,
                       std::string(&r == &free_run ? "(passes through)" : r.intersection_free ? "yes" : "NO")});
    };
    row("self-contact", contact_run);
    row("self-contact, pattern of the pairs within dhat", unanticipated_run);
    row("no contact", free_run);
    table.print(std::cout);
    table.write_csv(run.file("two_bunnies_table.csv"));
    std::cout << "closest the two bodies came: " << contact_run.smallest_distance << " m (d-hat " << options.activation_distance
              << " m)\n";

    // Newton's tolerance loosened to 10⁻³ (one run: each costs about as much as the default's):
    // what the contact step saves in iterations against how far the bunnies end from the default
    // tolerance's run (the largest vertex offset, against d̂).
    Table loose(str(run.quick ? "Two blocks" : "Two coarse bunnies",
                    " with self-contact: Newton's relative tolerance against the iterations and the end state"),
                {{"Newton tolerance", Format::scientific, 0}, {"Newton iterations", Format::integer},
                 {"new matrix patterns", Format::integer}, {"time per step [ms]", Format::fixed, 1},
                 {"linear solves [ms]", Format::fixed, 1}, {"step time / without contact [measured]", Format::fixed, 2},
                 {"largest offset from tolerance 1e-6 / dhat", Format::scientific, 1},
                 {"closest distance / dhat", Format::scientific, 1}, {"momentum drift [round-off]", Format::scientific, 1},
                 {"intersection-free", Format::text}});
    for (double loose_tolerance : {tolerance, 1e-3}) {
        const BunnyRun r = loose_tolerance == tolerance ? contact_run : one_run(true, loose_tolerance, options);
        loose.add_row({loose_tolerance, double(r.newton_iterations), double(r.orderings), 1e3 * r.seconds / r.steps,
                       1e3 * r.solve_seconds / r.steps, r.seconds / free_run.seconds,
                       (r.u - contact_run.u).lpNorm<Eigen::Infinity>() / options.activation_distance,
                       r.smallest_distance / options.activation_distance, r.momentum_drift,
                       std::string(r.intersection_free ? "yes" : "NO")});
    }
    loose.print(std::cout);
    loose.write_csv(run.file("two_bunnies_tolerance_table.csv"));
    if (!hessian_variants)
        return;

    // What cuts the impact steps' iterations at the same tolerance: the barrier blocks' projection
    // (ContactOptions::barrier_projection), the exact barrier Hessian tried first
    // (ContactOptions::exact_barrier_hessian, under chapter 12's HessianChoice::exact_then_definite),
    // and κ: doubled at a step's start while the bunnies are within 0.1 d̂ and closing (the adaptive
    // rule with ε_d = 0.1 d̂ over the bounding-box diagonal), or fixed at 100 times the adaptive run's;
    // and Newton also stopped once its direction moves no coordinate by more than 10⁻² or 10⁻³ d̂
    // (NewtonOptions::step_tolerance), which ends the linear tail of an impact step early.
    const double diagonal = (scene.mesh.V.colwise().maxCoeff() - scene.mesh.V.colwise().minCoeff()).norm();
    const double kappa = contact_run.stiffness;
    struct Variant {
        const char* name;
        hyper::Projection projection;
        bool exact;
        double stiffness, doubling_distance;
        double step_fraction;  ///< Newton's step test at this × d̂ (0: the gradient's test alone)
    };
    const double ipc = ContactOptions{}.doubling_distance;
    Table variants(str(run.quick ? "Two blocks" : "Two coarse bunnies",
                       " with self-contact at Newton tolerance 1e-6: the barrier's Hessian and kappa against the iterations"),
                   {{"barrier Hessian", Format::text}, {"kappa", Format::text}, {"Newton stops", Format::text},
                    {"Newton iterations", Format::integer},
                    {"most in a step", Format::integer}, {"exact Hessian failed", Format::integer},
                    {"factorizations", Format::integer}, {"new matrix patterns", Format::integer},
                    {"time per step [ms]", Format::fixed, 1},
                    {"linear solves [ms]", Format::fixed, 1}, {"step time / without contact [measured]", Format::fixed, 2},
                    {"closest distance / dhat", Format::scientific, 1},
                    {"largest offset from the first row / dhat", Format::scientific, 1},
                    {"momentum drift [round-off]", Format::scientific, 1}, {"intersection-free", Format::text}});
    for (const Variant& variant :
         {Variant{"clamp", hyper::Projection::clamp, false, 0.0, ipc, 0.0},
          Variant{"absolute values", hyper::Projection::absolute, false, 0.0, ipc, 0.0},
          Variant{"exact, else clamp", hyper::Projection::clamp, true, 0.0, ipc, 0.0},
          Variant{"clamp", hyper::Projection::clamp, false, 0.0, 0.1 * options.activation_distance / diagonal, 0.0},
          Variant{"clamp", hyper::Projection::clamp, false, 100.0 * kappa, ipc, 0.0},
          Variant{"exact, else clamp", hyper::Projection::clamp, true, 100.0 * kappa, ipc, 0.0},
          Variant{"clamp", hyper::Projection::clamp, false, 0.0, ipc, 1e-2},
          Variant{"clamp", hyper::Projection::clamp, false, 0.0, ipc, 1e-3},
          Variant{"exact, else clamp", hyper::Projection::clamp, true, 0.0, ipc, 1e-3}}) {
        BodyContactOptions variant_options = options;
        variant_options.barrier_projection = variant.projection;
        variant_options.exact_barrier_hessian = variant.exact;
        variant_options.stiffness = variant.stiffness;
        variant_options.doubling_distance = variant.doubling_distance;
        const bool as_default = variant.projection == options.barrier_projection && variant.exact == options.exact_barrier_hessian &&
                                variant.stiffness == options.stiffness && variant.doubling_distance == ipc &&
                                variant.step_fraction == 0.0;
        const BunnyRun r = as_default ? contact_run : one_run(true, tolerance, variant_options, variant.step_fraction);
        variants.add_row({std::string(variant.name),
                          std::string(variant.stiffness > 0.0           ? "fixed, 100 x adaptive"
                                      : variant.doubling_distance != ipc ? "adaptive, doubled below 0.1 dhat"
                                                                         : "adaptive"),
                          variant.step_fraction > 0.0 ? str("gradient, or step < ", variant.step_fraction, " dhat")
                                                      : std::string("gradient"),
                          double(r.newton_iterations), double(r.most_iterations), double(r.fallbacks),
                          double(r.factorizations), double(r.orderings), 1e3 * r.seconds / r.steps, 1e3 * r.solve_seconds / r.steps,
                          r.seconds / free_run.seconds, r.smallest_distance / options.activation_distance,
                          (r.u - contact_run.u).lpNorm<Eigen::Infinity>() / options.activation_distance, r.momentum_drift,
                          std::string(r.intersection_free ? "yes" : "NO")});
    }
    variants.print(std::cout);
    variants.write_csv(run.file("two_bunnies_hessian_table.csv"));
}

}  // namespace fem::contact::study
