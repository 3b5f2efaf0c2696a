// Study 2 of ch11_corotational: a soft cantilever released from the horizontal droops and swings
// through a large angle. Linear elasticity grows (a rotation is a strain to it); the corotational
// body keeps its volume. Speed against error: every model and integrator at several Δt against the
// corotational run at Δt/16; the swing written as a .pvd time series and PNG frames, both models
// side by side. docs/11_corotational.md#a-large-swing
#include "studies.hpp"

#include "10_linear_dynamics/tip_path.hpp"

#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/motion.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <cmath>
#include <iostream>

namespace fem::corot::study {
namespace {

/// One run of the swing: the tip's path (chapter 10's TipPath), and what the tables report.
struct SwingRun {
    std::string model, integrator;
    dynamics::TipPath path;
    double energy_drift = 0.0;           ///< max over the run of (H − H₀) / max (T + U + |W|)
    double lowest_tip_angle = 0.0;       ///< the steepest the tip's chord gets below the horizontal [deg]
    double seconds_per_step = 0.0;
};

/// Runs `model` under the θ-method at Δt (fem::Error if it diverges).
SwingRun swing(const dynamics::Scene& base, const std::string& model, double theta, double time_step)
{
    dynamics::Scene scene = base;
    scene.time_step = time_step;
    dynamics::Body body(scene, force_model(model, scene));
    const auto stepper = std::make_unique<dynamics::ThetaMethod>(theta);
    dynamics::Simulation simulation(body, *stepper, dynamics::initial_state(body));
    const int tip = dynamics::far_corner(scene.mesh);
    SwingRun run{model, stepper->name(), {}, 0.0, 0.0, 0.0};
    run.path.tip = tip;
    run.path.time_step = time_step;
    double h0 = 0.0, scale = 0.0;
    const int steps = dynamics::step_count(scene.duration, time_step);
    Timer clock;
    simulation.run(steps, [&](const dynamics::State& state, const dynamics::StepRecord& record) {
        run.path.record(body, state);
        if (state.step == 0)
            h0 = record.energies.total();
        scale = std::max(scale, record.energies.magnitude());
        run.energy_drift = std::max(run.energy_drift, (record.energies.total() - h0) / std::max(scale, 1e-300));
        const double drop = scene.mesh.V(tip, 2) - run.path.z.back();
        run.lowest_tip_angle = std::max(run.lowest_tip_angle, std::atan2(drop, run.path.x.back()) * 180.0 / M_PI);
    });
    run.seconds_per_step = clock.seconds() / steps;
    return run;
}

/// Both bodies of one step side by side (the corotational one shifted by `offset` along x): one mesh,
/// so that one .pvd and one camera show both. Cell field "model": 0 linear, 1 corotational.
io::MeshData side_by_side(const dynamics::Body& linear, const dynamics::State& linear_state,
                          const dynamics::Body& corotational, const dynamics::State& corotational_state, double offset)
{
    const TetMesh& mesh = linear.mesh();
    const Eigen::Index n = mesh.V.rows(), t = mesh.T.rows();
    MatrixX3d V(2 * n, 3);
    V << mesh.V, mesh.V.rowwise() + Eigen::RowVector3d(offset, 0.0, 0.0);
    Eigen::MatrixX4i T(2 * t, 4);
    T << mesh.T, (mesh.T.array() + static_cast<int>(n)).matrix();
    MatrixX3d u(2 * n, 3);
    u << io::vertex_rows(linear_state.u), io::vertex_rows(corotational_state.u);
    io::MeshData data = io::displaced_mesh(V, T, u);
    Eigen::VectorXd stress(2 * t), model(2 * t);
    stress << linear.model().von_mises_stress(linear_state.u), corotational.model().von_mises_stress(corotational_state.u);
    model << Eigen::VectorXd::Zero(t), Eigen::VectorXd::Ones(t);
    data.cell_data.push_back({"von Mises stress", stress});
    data.cell_data.push_back({"model", model});
    return data;
}

}  // namespace

void swing_study(const RunContext& run, const Settings& settings)
{
    const double base_dt = 1.0 / 60.0;
    const dynamics::Scene scene = dynamics::cantilever_scene(settings.soft, run.quick ? 10 : settings.swing_cells, settings.duration);
    std::cout << "\n== 2. A large swing: the soft cantilever (Y = " << settings.soft.youngs_modulus
              << " Pa) released from the horizontal, " << scene.mesh.T.rows() << " tets, " << settings.duration
              << " s, no damping\n\n";

    // Why: the midpoint rule conserves the energy of a linear body (chapter 10); with the warped
    // stiffness, which leaves out the derivative of R and so underestimates the tangent of the
    // stretched beam, its stiff modes grow a little every step. θ a little above ½ damps them.
    Table thetas("The theta-step with the warped stiffness on the swing: energy gain and loss, or the divergence",
                 {{"theta", Format::fixed, 2}, {"dt (s)", Format::scientific, 3}, {"outcome", Format::text},
                  {"max energy gain / scale", Format::scientific, 2}, {"max energy loss / scale", Format::scientific, 2}});
    for (const double theta : {0.5, 0.52, 0.55, 0.6})
        for (const double dt : {base_dt, base_dt / 4.0}) {
            dynamics::Scene s = scene;
            s.time_step = dt;
            dynamics::Body body(s, force_model("corotational", s));
            dynamics::ThetaMethod stepper(theta);
            dynamics::Simulation simulation(body, stepper, dynamics::initial_state(body));
            double h0 = 0.0, scale = 0.0, gain = 0.0, loss = 0.0;
            try {
                simulation.run(dynamics::step_count(s.duration, dt),
                               [&](const dynamics::State& state, const dynamics::StepRecord& record) {
                                   if (state.step == 0)
                                       h0 = record.energies.total();
                                   scale = std::max(scale, record.energies.magnitude());
                                   gain = std::max(gain, (record.energies.total() - h0) / scale);
                                   loss = std::max(loss, (h0 - record.energies.total()) / scale);
                               });
                thetas.add_row({theta, dt, std::string("bounded"), gain, loss});
            } catch (const Error&) {
                thetas.add_row({theta, dt, str("diverged at t = ", std::lround(1e3 * simulation.state().time) / 1e3, " s"),
                                gain, loss});
            }
        }
    thetas.print(std::cout);
    thetas.write_csv(run.file("theta_table.csv"));

    // Why: speed against error. The reference is the corotational body under backward Euler at
    // 1/16 of the smallest Δt of the table; both integrators converge to it (first order).
    std::vector<double> steps_per_second{30.0, 60.0, 120.0, 240.0};
    if (run.quick)
        steps_per_second = {30.0, 60.0};
    const double reference_dt = 1.0 / (16.0 * steps_per_second.back());
    const SwingRun reference = swing(scene, "corotational", 1.0, reference_dt);
    std::vector<SwingRun> runs;
    Table table(str("Linear against corotational on the swing: the tip against the corotational run at dt = 1/",
                    std::lround(1.0 / reference_dt), " s"),
                {{"model", Format::text}, {"integrator", Format::text}, {"steps per second", Format::integer},
                 {"max tip error [m]", Format::scientific, 2}, {"max |V/V0 - 1|", Format::scientific, 2},
                 {"max energy gain / scale", Format::scientific, 2}, {"tip angle below horizontal [deg]", Format::fixed, 1},
                 {"time per step [s]", Format::scientific, 2}});
    for (const std::string model : {"linear", "corotational"})
        for (const double theta : {1.0, 0.55})
            for (const double rate : steps_per_second) {
                runs.push_back(swing(scene, model, theta, 1.0 / rate));
                const SwingRun& r = runs.back();
                table.add_row({model, r.integrator, rate, dynamics::largest_tip_distance(r.path, reference.path),
                               r.path.largest_volume_change, r.energy_drift, r.lowest_tip_angle, r.seconds_per_step});
            }
    table.add_row({std::string("corotational (reference)"), reference.integrator, 1.0 / reference_dt, 0.0,
                   reference.path.largest_volume_change, reference.energy_drift, reference.lowest_tip_angle,
                   reference.seconds_per_step});
    table.print(std::cout);
    table.write_csv(run.file("swing_table.csv"));

    fig::LineChart pareto;
    pareto.title = "Speed against error on the swing: tip error against the wall time of the run";
    pareto.x_label = "wall time of the swing [s]";
    pareto.y_label = "max tip error [m]";
    pareto.log_x = pareto.log_y = true;
    for (const std::string model : {"linear", "corotational"})
        for (const std::string integrator : {"backward Euler", "theta = 0.55"}) {
            fig::Series series{str(model, ", ", integrator), {}, {}};
            for (const SwingRun& r : runs)
                if (r.model == model && r.integrator == integrator) {
                    series.x.push_back(r.seconds_per_step * double(r.path.times.size() - 1));
                    series.y.push_back(dynamics::largest_tip_distance(r.path, reference.path));
                }
            pareto.series.push_back(series);
        }
    fig::save_chart(pareto, run.file("swing_pareto"), run.figures);

    fig::LineChart tips;
    tips.title = "The tip's height during the swing, dt = 1/60 s";
    tips.x_label = "t [s]";
    tips.y_label = "tip height z [m]";
    tips.series.push_back({str("corotational, dt = 1/", std::lround(1.0 / reference_dt), " s (reference)"),
                           reference.path.times, reference.path.z});
    for (const SwingRun& r : runs)
        if (std::abs(r.path.time_step - base_dt) < 1e-12)
            tips.series.push_back({str(r.model, ", ", r.integrator), r.path.times, r.path.z});
    tips.legend = fig::Corner::bottom_left;
    fig::save_chart(tips, run.file("swing_tips"), run.figures);

    // Why: the picture a lecture needs — both models in one frame, the same camera and colours.
    dynamics::Body linear(scene, force_model("linear", scene)), corotational(scene, force_model("corotational", scene));
    const auto linear_stepper = dynamics::make_integrator("backward-euler");
    const auto corotational_stepper = dynamics::make_integrator("backward-euler");
    dynamics::Simulation linear_run(linear, *linear_stepper, dynamics::initial_state(linear));
    dynamics::Simulation corotational_run(corotational, *corotational_stepper, dynamics::initial_state(corotational));
    io::MotionRecorder recorder(run.file("swing.pvd"), run.figures ? 9 : 0);
    const double offset = 0.3;
    recorder.add(0.0, side_by_side(linear, linear_run.state(), corotational, corotational_run.state(), offset));
    for (int k = 0; k < dynamics::step_count(scene.duration, base_dt); ++k) {
        linear_run.run(1);
        corotational_run.run(1);
        recorder.add(linear_run.state().time,
                     side_by_side(linear, linear_run.state(), corotational, corotational_run.state(), offset));
    }
    fig::RenderOptions view;
    view.title = "Linear (left) and corotational (right) cantilever, backward Euler";
    view.field = "displacement";
    view.unit = "m";
    view.view_direction = {0.0, 1.0, -0.2};
    view.view_up = {0.0, 0.0, 1.0};
    view.height = 560;
    recorder.render_png_frames(run.file("swing"), view);
}

}  // namespace fem::corot::study
