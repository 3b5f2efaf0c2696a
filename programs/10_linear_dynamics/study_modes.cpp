// Studies 1 and 2 of ch10_linear_dynamics: the beam's modes, and the modal recurrence every
// integrator must follow. docs/10_linear_dynamics.md#modes
#include "10_linear_dynamics/modes.hpp"
#include "studies.hpp"

#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <cmath>
#include <complex>
#include <iostream>

namespace fem::dynamics::study {
namespace {

constexpr double pi = 3.14159265358979323846;

struct FreeSystem {
    SparseMatrix K, M;
};

FreeSystem free_system(Body& body)
{
    const Eigen::VectorXd rest = Eigen::VectorXd::Zero(body.dofs().full_size());
    return {body.dofs().reduce(body.model().stiffness(rest)), body.dofs().reduce(body.mass_matrix())};
}

}  // namespace

void modes_study(const RunContext& run, const Settings& settings)
{
    std::cout << "== 1. Modes: K phi = omega^2 M phi on the free dofs of the cantilever\n\n";
    // Why: every check of this chapter is measured against the body's own modes.
    const Scene scene = cantilever_scene(settings.beam, settings.accuracy_cells);
    Body body(scene);
    const FreeSystem free = free_system(body);
    Timer dense_clock;
    const Modes dense = lowest_modes_dense(free.K, free.M, 6);
    const double dense_time = dense_clock.seconds();
    Timer lanczos_clock;
    const Modes lanczos = lowest_modes(free.K, free.M, 6);
    const double lanczos_time = lanczos_clock.seconds();
    Table modes(str("The six lowest modes of the ", scene.mesh.T.rows(), "-tet beam (", free.K.rows(),
                    " free dofs): dense eigensolver (", dense_time, " s) and shift-invert Lanczos on our Cholesky (",
                    lanczos_time, " s)"),
                {{"mode", Format::integer}, {"dense f (Hz)", Format::fixed, 4}, {"Lanczos f (Hz)", Format::fixed, 4},
                 {"relative difference [round-off]", Format::scientific, 1}});
    for (int k = 0; k < 6; ++k)
        modes.add_row({double(k + 1), dense.omega[k] / (2 * pi), lanczos.omega[k] / (2 * pi),
                       std::abs(lanczos.omega[k] - dense.omega[k]) / dense.omega[k]});
    modes.print(std::cout);
    modes.write_csv(run.file("modes_table.csv"));

    // Why: linear tets are too stiff in bending (shear locking); the frequency shows by how much.
    const Material& m = settings.beam;
    const double f_beam = euler_bernoulli_first_frequency(m.youngs_modulus, m.density, 0.2, 0.02 * 0.02,
                                                          std::pow(0.02, 4) / 12.0);
    Table theory(str("First bending frequency against Euler-Bernoulli f1 = (1.8751^2/2 pi) sqrt(EI/(rho A L^4)) = ",
                     f_beam, " Hz"),
                 {{"cells along", Format::integer}, {"free dofs", Format::integer}, {"f1 (Hz)", Format::fixed, 4},
                  {"f1 / Euler-Bernoulli", Format::fixed, 4}});
    fig::Series ratio_series{"f1 of linear tets / Euler-Bernoulli", {}, {}};
    for (int cells : run.quick ? std::vector<int>{10, 20} : std::vector<int>{10, 20, 40, 80}) {
        Body refined(cantilever_scene(settings.beam, cells));
        const FreeSystem system = free_system(refined);
        const double f1 = lowest_modes(system.K, system.M, 1).omega[0] / (2 * pi);
        theory.add_row({double(cells), double(system.K.rows()), f1, f1 / f_beam});
        ratio_series.x.push_back(double(system.K.rows()));
        ratio_series.y.push_back(f1 / f_beam);
    }
    theory.print(std::cout);
    theory.write_csv(run.file("beam_theory_table.csv"));
    fig::LineChart chart;
    chart.title = "Cantilever: first frequency of linear tets over Euler-Bernoulli's";
    chart.x_label = "free dofs";
    chart.y_label = "f1 / f1 (Euler-Bernoulli)";
    chart.log_x = true;
    chart.series = {ratio_series, {"Euler-Bernoulli", {ratio_series.x.front(), ratio_series.x.back()}, {1.0, 1.0}}};
    chart.legend = fig::Corner::top_right;
    fig::save_chart(chart, run.file("beam_frequency"), run.figures);

    // Why: explicit Euler is stable only below 2/omega_max; Lanczos finds omega_max in a few dozen
    // products, power iteration converges like (omega_2/omega_1)^(2k).
    Table limit("The explicit stability limit dt < 2/omega_max: omega_max by Lanczos and by power iteration",
                {{"cells along", Format::integer}, {"free dofs", Format::integer},
                 {"omega_max Lanczos (rad/s)", Format::scientific, 6}, {"omega_max power (rad/s)", Format::scientific, 6},
                 {"power iterations", Format::integer}, {"power converged", Format::text},
                 {"dt limit (s)", Format::scientific, 4}, {"steps per simulated second", Format::integer}});
    for (int cells : run.quick ? std::vector<int>{10, 20} : std::vector<int>{10, 20, 40}) {
        Body refined(cantilever_scene(settings.beam, cells));
        const FreeSystem system = free_system(refined);
        const double omega_max = highest_frequency(system.K, system.M);
        const PowerIteration power =
            power_iteration(system.K, refined.dofs().gather(refined.dof_masses()), 1e-10, 20000);
        const double dt = explicit_stability_limit(omega_max);
        limit.add_row({double(cells), double(system.K.rows()), omega_max, power.omega, double(power.iterations),
                       std::string(power.converged ? "yes" : "no"), dt, std::ceil(1.0 / dt)});
    }
    limit.print(std::cout);
    limit.write_csv(run.file("stability_limit_table.csv"));
}

void recurrence_study(const RunContext& run, const Settings& settings)
{
    std::cout << "\n== 2. One mode, one oscillator: the body started in mode 1 against the 2x2 recurrence\n\n";
    // Why: D = alpha M + beta K is diagonal in the modal basis, so each step acts on mode 1 as the
    // scalar oscillator's step matrix G. The whole body must follow G^n to round-off.
    Scene scene = cantilever_scene(settings.beam, 6);
    scene.gravity.setZero();
    Body probe(scene);
    const FreeSystem free = free_system(probe);
    const Modes modes = lowest_modes_dense(free.K, free.M, 1);
    const double omega = modes.omega[0];
    const int tip_dof = 3 * far_corner(scene.mesh) + 2;
    Eigen::VectorXd phi = Eigen::VectorXd::Zero(probe.dofs().full_size());
    probe.dofs().scatter(modes.shapes.col(0), phi);
    phi *= 1e-3 / std::abs(phi[tip_dof]);
    const double omega_max = highest_frequency(free.K, free.M);

    Table table(str("Tip of the body started in mode 1 (omega_1 = ", omega, " rad/s) against the modal recurrence, "
                    "100 steps"),
                {{"integrator", Format::text}, {"damping", Format::text}, {"omega_1 dt", Format::fixed, 4},
                 {"xi", Format::scientific, 3}, {"max deviation / max tip [round-off]", Format::scientific, 1}});
    for (const auto& [damping, label] : {std::pair{Damping{}, "none"}, std::pair{Damping{0.02, 0.0}, "alpha = 0.02"},
                                         std::pair{Damping{0.0, 0.02}, "beta = 0.02"}}) {
        scene.damping = damping;
        const double xi = damping_ratio(damping, omega);
        for (const std::string& name : integrator_names()) {
            const bool explicit_step = name == "symplectic-euler";
            // Symplectic Euler at half its limit, which damping lowers (beta most: xi grows with omega).
            scene.time_step = explicit_step
                                  ? 0.5 * explicit_stability_limit(omega_max, damping_ratio(damping, omega_max))
                                  : 0.01;
            scene.duration = 0.0;
            Body body(scene);
            const std::unique_ptr<Integrator> integrator = make_integrator(name);
            const Eigen::Matrix2d G =
                explicit_step ? symplectic_oscillator_step_matrix(omega, xi, scene.time_step)
                              : oscillator_step_matrix(omega, xi, scene.time_step, name == "backward-euler" ? 1.0 : 0.5);
            table.add_row({integrator->name(), std::string(label), omega * scene.time_step, xi,
                           modal_recurrence_deviation(body, *integrator, phi, tip_dof, G, 100)});
        }
    }
    table.print(std::cout);
    table.write_csv(run.file("recurrence_table.csv"));

    // Why: the amplitude factor and the phase per step are what an animator sees: backward Euler
    // damps mode 1 by 1/sqrt(1 + w^2 dt^2) per step and turns it by atan(w dt) instead of w dt.
    Table decay("Backward Euler on mode 1, undamped: amplitude factor and phase per step, measured and by formula",
                {{"omega_1 dt", Format::fixed, 2}, {"|lambda| measured", Format::fixed, 10},
                 {"1/sqrt(1 + w^2 dt^2)", Format::fixed, 10}, {"phase measured", Format::fixed, 10},
                 {"atan(w dt)", Format::fixed, 10}, {"exact phase w dt", Format::fixed, 4},
                 {"amplitude after one period", Format::scientific, 3}});
    scene.damping = {};
    for (const double omega_dt : {0.05, 0.2, 0.5, 1.0, 2.0, 5.0}) {
        scene.time_step = omega_dt / omega;
        Body body(scene);
        ThetaMethod integrator(1.0);
        Simulation simulation(body, integrator, initial_state(body, phi));
        const Eigen::VectorXd Mphi = body.mass_matrix() * phi;
        const double phi_norm = phi.dot(Mphi);
        std::complex<double> first, previous, last_ratio;
        simulation.run(10, [&](const State& state, const StepRecord&) {
            // w = p + i omega q with q = phiᵀMu/phiᵀMphi, p = phiᵀMv/phiᵀMphi: multiplied by lambda per step.
            const std::complex<double> w(Mphi.dot(state.v) / phi_norm, omega * Mphi.dot(state.u) / phi_norm);
            if (state.step == 0)
                first = w;
            else
                last_ratio = w / previous;
            previous = w;
        });
        const double modulus = std::abs(last_ratio);
        decay.add_row({omega_dt, modulus, 1.0 / std::sqrt(1.0 + omega_dt * omega_dt), std::abs(std::arg(last_ratio)),
                       std::atan(omega_dt), omega_dt, std::pow(modulus, 2 * pi / std::atan(omega_dt))});
    }
    decay.print(std::cout);
    decay.write_csv(run.file("decay_table.csv"));
}

}  // namespace fem::dynamics::study
