// Studies 3, 4 and 5 of ch10_linear_dynamics: speed against error of the integrators against the
// exact modal solution, statics, and the hard cases. docs/10_linear_dynamics.md#speed-against-error
#include "10_linear_dynamics/modes.hpp"
#include "studies.hpp"

#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <Eigen/SparseCholesky>

#include <cmath>
#include <iostream>
#include <sstream>

namespace fem::dynamics::study {
namespace {

/// Position of a full dof among the free ones (fem::Error if it is pinned).
Eigen::Index free_position(const FreeDofs& dofs, int dof)
{
    const auto& free = dofs.indices();
    const auto it = std::lower_bound(free.begin(), free.end(), dof);
    if (it == free.end() || *it != dof)
        throw Error(str("dof ", dof, " is pinned"));
    return it - free.begin();
}

/// The static displacement K_ff⁻¹ f_ff of a body (full vector), by Eigen's sparse LDLᵀ.
Eigen::VectorXd static_displacement(Body& body)
{
    const FreeDofs& dofs = body.dofs();
    const Eigen::SimplicialLDLT<SparseMatrix> solver(dofs.reduce(body.model().stiffness(Eigen::VectorXd::Zero(dofs.full_size()))));
    Eigen::VectorXd u = Eigen::VectorXd::Zero(dofs.full_size());
    dofs.scatter(solver.solve(dofs.gather(body.external_forces())), u);
    return u;
}

/// One run of the accuracy study.
struct AccuracyRun {
    std::string integrator;
    double time_step = 0.0;
    int steps = 0;
    double tip_error = 0.0;      // |u_tip(T) − reference| / largest |reference tip|
    double max_error = 0.0;      // the largest such error over [0, T] (sampled)
    double energy_drift = 0.0;   // max |H − H(0)| / largest energy magnitude
    double seconds = 0.0;
    std::vector<double> times, tips, totals;  // the trajectory, for the charts
};

/// 2/ω_max of the body's free dofs (chapter 10's explicit limit).
double explicit_limit_of(Body& body)
{
    const FreeDofs& dofs = body.dofs();
    const SparseMatrix K = dofs.reduce(body.model().stiffness(Eigen::VectorXd::Zero(dofs.full_size())));
    return explicit_stability_limit(highest_frequency(K, dofs.reduce(body.mass_matrix())));
}

/// The fewest stable symplectic Euler steps over duration (Δt = 0.9 of the limit).
long long fewest_explicit_steps(double duration, double limit)
{
    return static_cast<long long>(std::ceil(duration / (0.9 * limit)));
}

}  // namespace

long long explicit_steps(const Settings& settings)
{
    Body body(cantilever_scene(settings.beam, settings.accuracy_cells));
    const double limit = explicit_limit_of(body);
    const long long steps = std::isfinite(limit) && limit > 0.0 ? fewest_explicit_steps(settings.duration, limit) : 0;
    const auto given = [](double value) {  // as typed: 0.4999999999 is not 0.5
        std::ostringstream text;
        text.precision(15);
        text << value;
        return text.str();
    };
    if (steps == 0 || 8 * steps > max_explicit_steps)
        throw Error(str("--youngs ", given(settings.beam.youngs_modulus), ", --poisson ", given(settings.beam.poisson_ratio),
                        ", --density ", given(settings.beam.density), ": symplectic Euler would take ", 8 * steps,
                        " steps over --duration ", settings.duration, " s (dt < 2/omega_max = ", limit,
                        " s); at most ", max_explicit_steps, " are run: lower --youngs or --poisson (near 0.5 the ",
                        "volume stiffens without bound), or raise --density"));
    return steps;
}

void accuracy_study(const RunContext& run, const Settings& settings)
{
    std::cout << "\n== 3. Speed against error: the beam released under gravity, against the exact modal solution\n\n";
    // Why: the modal solution is exact in time for the semi-discrete equations, so the tip error
    // below is the integrator's alone (the mesh's own error is the same for every row).
    Scene scene = cantilever_scene(settings.beam, settings.accuracy_cells, settings.duration);
    Body body(scene);
    const FreeDofs& dofs = body.dofs();
    const SparseMatrix K = dofs.reduce(body.model().stiffness(Eigen::VectorXd::Zero(dofs.full_size())));
    const SparseMatrix M = dofs.reduce(body.mass_matrix());
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(K.rows());
    const ModalSolution reference(K, M, dofs.gather(body.external_forces()), scene.damping, zero, zero);
    const int tip_dof = 3 * far_corner(scene.mesh) + 2;
    const Eigen::Index tip_free = free_position(dofs, tip_dof);
    const double T = settings.duration;
    double amplitude = 0.0;
    fig::Series reference_curve{"exact (modal)", {}, {}};
    for (int k = 0; k <= 400; ++k) {
        const double t = T * k / 400.0;
        const double tip = reference.displacement(t, tip_free);
        amplitude = std::max(amplitude, std::abs(tip));
        reference_curve.x.push_back(t);
        reference_curve.y.push_back(tip);
    }
    const double reference_tip = reference.displacement(T, tip_free);
    const double explicit_limit = explicit_limit_of(body);

    const auto simulate = [&](const std::string& name, int steps) {
        AccuracyRun result;
        result.time_step = T / steps;
        result.steps = steps;
        const std::unique_ptr<Integrator> integrator = make_integrator(name);
        result.integrator = integrator->name();
        body.set_time_step(result.time_step);
        Simulation simulation(body, *integrator, initial_state(body));
        double start = 0.0, largest = 0.0;
        const int keep_every = std::max(1, steps / 400), check_every = std::max(1, steps / 2000);
        Timer clock;
        simulation.run(steps, [&](const State& state, const StepRecord& record) {
            if (state.step == 0)
                start = record.energies.total();
            largest = std::max(largest, record.energies.magnitude());
            result.energy_drift = std::max(result.energy_drift, std::abs(record.energies.total() - start));
            if (state.step % check_every == 0)
                result.max_error = std::max(result.max_error,
                                            std::abs(state.u[tip_dof] - reference.displacement(state.time, tip_free)));
            if (state.step % keep_every == 0) {
                result.times.push_back(state.time);
                result.tips.push_back(state.u[tip_dof]);
                result.totals.push_back(record.energies.total());
            }
        });
        result.seconds = clock.seconds();
        result.energy_drift /= largest;
        result.tip_error = std::abs(simulation.state().u[tip_dof] - reference_tip) / amplitude;
        result.max_error /= amplitude;
        return result;
    };

    std::vector<AccuracyRun> runs;
    const std::vector<int> implicit_steps = run.quick ? std::vector<int>{30, 60, 120, 240}
                                                      : std::vector<int>{30, 60, 120, 240, 480, 960, 1920, 3840, 7680};
    for (const std::string name : {"backward-euler", "implicit-midpoint"})
        for (int steps : implicit_steps)
            runs.push_back(simulate(name, static_cast<int>(std::lround(steps * T))));
    const int fewest = static_cast<int>(fewest_explicit_steps(T, explicit_limit));  // main checked the count
    for (int factor : run.quick ? std::vector<int>{1, 2} : std::vector<int>{1, 2, 4, 8})
        runs.push_back(simulate("symplectic-euler", factor * fewest));

    Table table(str("Tip error at t = ", T, " s against the exact modal solution (", K.rows(),
                    " free dofs, undamped; largest tip displacement ", amplitude,
                    " m); symplectic Euler needs dt < 2/omega_max = ", explicit_limit, " s"),
                {{"integrator", Format::text}, {"dt (s)", Format::scientific, 3}, {"steps", Format::integer},
                 {"tip error at T / amplitude", Format::scientific, 2},
                 {"max tip error / amplitude", Format::scientific, 2}, {"energy drift / energy", Format::scientific, 2},
                 {"time [s]", Format::scientific, 2}, {"steps per second [1/s]", Format::scientific, 2}});
    for (const AccuracyRun& r : runs) {
        // The midpoint rule keeps the energy exactly: what is left is round-off (forms_table measures it).
        const Cell drift = r.energy_drift < 1e-10 ? Cell(std::string("< 1e-10 (round-off)")) : Cell(r.energy_drift);
        table.add_row({r.integrator, r.time_step, double(r.steps), r.tip_error, r.max_error, drift, r.seconds,
                       r.steps / std::max(r.seconds, 1e-9)});
    }
    table.print(std::cout);
    table.write_csv(run.file("accuracy_table.csv"));

    // The charts: error against wall time (Pareto), tip trajectories, energies.
    fig::LineChart pareto;
    pareto.title = "Speed against error: largest tip error over the run against wall time";
    pareto.x_label = "wall time [s]";
    pareto.y_label = "max tip error / amplitude";
    pareto.log_x = pareto.log_y = true;
    for (const std::string name : {"backward Euler", "implicit midpoint", "symplectic Euler"}) {
        fig::Series series{name, {}, {}};
        for (const AccuracyRun& r : runs)
            if (r.integrator == name) {
                series.x.push_back(r.seconds);
                series.y.push_back(r.max_error);
            }
        pareto.series.push_back(series);
    }
    pareto.legend = fig::Corner::bottom_left;
    fig::save_chart(pareto, run.file("pareto"), run.figures);

    const auto find = [&](const std::string& name, int steps) -> const AccuracyRun& {
        for (const AccuracyRun& r : runs)
            if (r.integrator == name && r.steps == steps)
                return r;
        throw Error(str("no run of ", name, " with ", steps, " steps"));
    };
    fig::LineChart tips;
    tips.title = "Tip of the beam released under gravity: integrators against the exact modal solution";
    tips.x_label = "t [s]";
    tips.y_label = "tip displacement z [m]";
    tips.series.push_back(reference_curve);
    const int coarse = static_cast<int>(std::lround(30 * T)), fine = static_cast<int>(std::lround(120 * T));
    for (const auto& [name, steps] : {std::pair{std::string("backward Euler"), coarse},
                                      std::pair{std::string("backward Euler"), fine},
                                      std::pair{std::string("implicit midpoint"), coarse}}) {
        const AccuracyRun& r = find(name, steps);
        tips.series.push_back({str(name, ", dt = 1/", std::lround(steps / T), " s"), r.times, r.tips});
    }
    tips.legend = fig::Corner::top_right;
    fig::save_chart(tips, run.file("tip_trajectories"), run.figures);

    // |H − H(0)| on a log axis: the three behaviours (backward Euler losing energy, symplectic Euler
    // oscillating about H(0), the midpoint rule keeping it to round-off) lie decades apart.
    fig::LineChart energy;
    energy.x_label = "t [s]";
    energy.y_label = "|H \u2212 H(0)| [J]";
    energy.log_y = true;
    const auto step_label = [](double dt) {  // dt = 1/120 s, or dt = 6.9e-5 s when 1/dt is no whole number
        const double per_second = 1.0 / dt;
        if (std::abs(per_second - std::round(per_second)) < 1e-6 * per_second)
            return str("dt = 1/", std::lround(per_second), " s");
        const int exponent = static_cast<int>(std::floor(std::log10(dt)));
        return str("dt = ", std::round(dt / std::pow(10.0, exponent - 1)) / 10.0, "e", exponent, " s");
    };
    // The series keep the integrators' names (their colours in the Pareto chart); the steps go in the title.
    const AccuracyRun& implicit = find("backward Euler", fine);
    const AccuracyRun& explicit_run = find("symplectic Euler", fewest);
    energy.title = str("|H(t) \u2212 H(0)|, undamped beam: ", step_label(implicit.time_step), " implicit, ",
                       step_label(explicit_run.time_step).substr(5), " symplectic");
    for (const AccuracyRun* r : {&implicit, &find("implicit midpoint", fine), &explicit_run}) {
        fig::Series change{r->integrator, r->times, {}};
        for (double h : r->totals)
            change.y.push_back(std::abs(h - r->totals.front()));
        energy.series.push_back(change);
    }
    energy.legend = fig::Corner::bottom_right;
    fig::save_chart(energy, run.file("energies"), run.figures);
}

void statics_study(const RunContext& run, const Settings& settings)
{
    std::cout << "\n== 4. Statics: a damped beam under gravity settles to K^-1 f\n\n";
    // Why: at rest the step reduces to K u = f; how fast it gets there depends on dt and damping.
    Scene scene = cantilever_scene(settings.beam, settings.accuracy_cells);
    scene.damping = {0.0, 0.02};
    // The error compares u, the result of many solves, with K^-1 f from another solver: each is exact
    // only to about kappa(K) eps ~ 2e-10 (kappa(K) ~ 9e5 on this beam), so the column says that its
    // digits below 2e-10 are round-off (they change with the processor's SIMD kernels).
    Table table("Steps until |u - K^-1 f| <= 1e-8 |K^-1 f| (beta = 0.02, from rest)",
                {{"integrator", Format::text}, {"dt (s)", Format::scientific, 3}, {"steps to 1e-8", Format::text},
                 {"simulated time (s)", Format::fixed, 3},
                 {"final relative error [±2e-10]", Format::scientific, 2}});
    for (const std::string name : {"backward-euler", "implicit-midpoint"})
        for (const double dt : {1.0 / 60.0, 1.0 / 10.0, 1.0}) {
            scene.time_step = dt;
            scene.duration = 0.0;
            Body body(scene);
            const Eigen::VectorXd expected = static_displacement(body);
            const std::unique_ptr<Integrator> integrator = make_integrator(name);
            Simulation simulation(body, *integrator, initial_state(body));
            int settled = -1;
            const int limit = 2000;
            for (int step = 0; step < limit && settled < 0; ++step) {
                simulation.run(1);
                if ((simulation.state().u - expected).norm() <= 1e-8 * expected.norm())
                    settled = simulation.state().step;
            }
            table.add_row({integrator->name(), dt, settled < 0 ? str("not within ", limit) : str(settled),
                           simulation.state().time,
                           (simulation.state().u - expected).norm() / expected.norm()});
        }
    table.print(std::cout);
    table.write_csv(run.file("statics_table.csv"));
}

void hard_cases_study(const RunContext& run, const Settings& settings)
{
    std::cout << "\n== 5. Hard cases: stability limits, stiffness, free fall, and the two forms of the step\n\n";
    Scene scene = cantilever_scene(settings.beam, run.quick ? 6 : 10);
    Body probe(scene);
    const SparseMatrix K = probe.dofs().reduce(probe.model().stiffness(Eigen::VectorXd::Zero(probe.dofs().full_size())));
    const double limit = explicit_stability_limit(highest_frequency(K, probe.dofs().reduce(probe.mass_matrix())));

    // Why: an integrator is only usable where it is stable; the loop must catch the other case.
    Table table("Stability: each run from rest under gravity; 'diverged' is the time loop's fem::Error",
                {{"case", Format::text}, {"integrator", Format::text}, {"dt (s)", Format::scientific, 3},
                 {"dt / explicit limit", Format::fixed, 2}, {"outcome", Format::text},
                 {"max |u| / static |u|", Format::fixed, 3}, {"energy never rose", Format::text}});
    struct Case {
        std::string label, integrator;
        double youngs, time_step;
        int steps;
    };
    const double Y = settings.beam.youngs_modulus;
    const std::vector<Case> cases = {
        {"explicit just below its limit", "symplectic-euler", Y, 0.99 * limit, 5000},
        {"explicit just above its limit", "symplectic-euler", Y, 1.01 * limit, 5000},
        {"backward Euler far above it", "backward-euler", Y, 100.0 * limit, 500},
        {"midpoint far above it", "implicit-midpoint", Y, 100.0 * limit, 500},
        {"very stiff (Y = 1e9), dt = 1/30 s", "backward-euler", 1e9, 1.0 / 30.0, 90},
    };
    for (const Case& c : cases) {
        Scene s = scene;
        s.material.youngs_modulus = c.youngs;
        s.time_step = c.time_step;
        s.duration = 0.0;
        Body body(s);
        const double static_norm = static_displacement(body).norm();
        const std::unique_ptr<Integrator> integrator = make_integrator(c.integrator);
        Simulation simulation(body, *integrator, initial_state(body));
        double largest = 0.0, previous = 0.0;
        bool never_rose = true;
        std::string outcome = str("bounded over ", c.steps, " steps");
        try {
            simulation.run(c.steps, [&](const State& state, const StepRecord& record) {
                largest = std::max(largest, state.u.norm());
                // A rise above round-off counts: 1e-10 of H's size bounds the error of evaluating H
                // from a solve with condition number up to 10⁶ (the midpoint run's rises are
                // ~1e-12); a real gain is orders larger (the explicit run below its limit: ~1e-5).
                never_rose = never_rose && record.energies.total() <= previous + 1e-10 * record.energies.magnitude();
                previous = record.energies.total();
            });
        } catch (const Error& error) {
            const std::string message = error.what();
            outcome = message.substr(0, message.find(" (t ="));  // "the run diverged at step N"
        }
        table.add_row({c.label, integrator->name(), c.time_step, c.time_step / limit, outcome,
                       largest / static_norm, std::string(never_rose ? "yes" : "no")});
    }
    table.print(std::cout);
    table.write_csv(run.file("stability_table.csv"));

    // Why: with nothing pinned M keeps A positive definite; the body falls rigidly, and backward
    // Euler's centre of mass follows its own discrete parabola dt^2 g n(n+1)/2, not ½ g t².
    Scene falling = scene;
    falling.pinned.clear();
    falling.time_step = 1.0 / 60.0;
    Body body(falling);
    ThetaMethod integrator(1.0);
    Simulation simulation(body, integrator, initial_state(body));
    const Eigen::VectorXd masses = body.dof_masses();
    Table fall("Free fall, nothing pinned: the centre of mass against backward Euler's closed form and 1/2 g t^2",
               {{"step", Format::integer}, {"t (s)", Format::fixed, 4}, {"centre z (m)", Format::scientific, 6},
                {"dt^2 g n(n+1)/2 (m)", Format::scientific, 6}, {"1/2 g t^2 (m)", Format::scientific, 6},
                {"|centre - closed form| / fall [round-off]", Format::scientific, 1},
                {"largest deformation (m) [round-off]", Format::scientific, 1}});
    simulation.run(60, [&](const State& state, const StepRecord&) {
        if (state.step == 0 || state.step % 15 != 0)
            return;
        double centre = 0.0, deformation = 0.0;
        for (Eigen::Index v = 0; v < body.mesh().V.rows(); ++v)
            centre += masses[3 * v] * state.u[3 * v + 2] / (masses.sum() / 3.0);
        for (Eigen::Index v = 0; v < body.mesh().V.rows(); ++v)
            deformation = std::max(deformation, (state.u.segment<3>(3 * v) - Eigen::Vector3d(0, 0, centre)).norm());
        const double n = state.step, dt = falling.time_step;
        const double closed = -9.81 * dt * dt * n * (n + 1.0) / 2.0;
        fall.add_row({n, state.time, centre, closed, -0.5 * 9.81 * state.time * state.time,
                      std::abs(centre - closed) / std::abs(closed), deformation});
    });
    fall.print(std::cout);
    fall.write_csv(run.file("free_fall_table.csv"));

    // Why: the lecture's A v+ = M v + dt (f + f_ext) and A dv = dt (f + f_ext − D v − theta dt K v)
    // are one system; they differ in what round-off does over many steps.
    Scene swinging = scene;
    swinging.gravity.setZero();
    swinging.time_step = 0.01;
    Body loaded(cantilever_scene(settings.beam, run.quick ? 6 : 10));
    const Eigen::VectorXd start = static_displacement(loaded);
    Body free_body(swinging);
    Table forms("The two forms of the implicit midpoint step: energy drift of an undamped swing over 1000 steps",
                {{"form", Format::text}, {"energy drift / energy [round-off]", Format::scientific, 2},
                 {"time per step [s]", Format::scientific, 2}});
    for (const auto& [form, label] : {std::pair{StepForm::velocity_change, "solve for dv (default)"},
                                      std::pair{StepForm::velocity, "solve for v+ (the lecture's)"}}) {
        ImplicitOptions options;
        options.form = form;
        ThetaMethod midpoint(0.5, options);
        Simulation swing(free_body, midpoint, initial_state(free_body, start));
        double h0 = 0.0, drift = 0.0;
        Timer clock;
        swing.run(1000, [&](const State& state, const StepRecord& record) {
            if (state.step == 0)
                h0 = record.energies.total();
            drift = std::max(drift, std::abs(record.energies.total() - h0) / h0);
        });
        forms.add_row({std::string(label), drift, clock.seconds() / 1000.0});
    }
    forms.print(std::cout);
    forms.write_csv(run.file("forms_table.csv"));
}

}  // namespace fem::dynamics::study
