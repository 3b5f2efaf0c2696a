// Every model and auto against a converged reference. docs/scenes.md#what-each-model-costs
#include "scenes/compare.hpp"

#include "13_skinning/skinning.hpp"

#include "12_hyperelastic_newton/force_models.hpp"
#include "12_hyperelastic_newton/materials.hpp"

#include "common/error.hpp"
#include "common/table.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>

namespace fem::scenes {
namespace {

/// The scene with its time step divided by `refinement` and its frames at the same times (every
/// refinement × steps_per_frame(scene) of its steps).
SceneSpec refined(const SceneSpec& scene, int refinement)
{
    SceneSpec fine = scene;
    fine.output.frame_rate = 1.0 / (steps_per_frame(scene) * scene.time_step);
    fine.time_step = scene.time_step / refinement;
    return fine;
}


/// The largest vertex distance between two runs over all frames [m].
double largest_difference(const RunResult& a, const RunResult& b)
{
    double largest = 0.0;
    for (std::size_t body = 0; body < a.frames.size(); ++body)
        for (std::size_t f = 0; f < std::min(a.frames[body].size(), b.frames[body].size()); ++f)
            largest = std::max(largest, (a.frames[body][f] - b.frames[body][f]).rowwise().norm().maxCoeff());
    return largest;
}

}  // namespace

ModelComparison compare_models(const SceneSpec& scene, const RunContext* run)
{
    ModelComparison comparison;
    comparison.reference_time_step = scene.time_step / reference_refinement;
    const std::string reference_model = "stable-neo-hookean";
    RunResult reference, coarser;
    try {
        reference = run_positions(refined(scene, reference_refinement), reference_model);
        coarser = run_positions(refined(scene, reference_refinement / 2), reference_model);
    } catch (const Error& e) {
        throw Error(str("--compare: the reference runs (", reference_model, " at dt = ", comparison.reference_time_step,
                        " s and twice that) failed: ", e.what()));
    }
    if (reference.interrupted || coarser.interrupted) {
        std::cout << "interrupted: the comparison stops before its reference is complete\n";
        return comparison;
    }
    for (std::size_t b = 0; b < scene.bodies.size(); ++b)
        if (coarser.frames[b].size() != reference.frames[b].size())
            throw Error("--compare: the reference runs wrote different frame counts");
    comparison.reference_change = largest_difference(reference, coarser);

    std::vector<std::vector<char>> on_surface;
    double largest_displacement = 0.0;
    for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
        const MatrixX3i faces = skin::boundary_faces(scene.bodies[b].mesh).faces;
        on_surface.emplace_back(static_cast<std::size_t>(scene.bodies[b].mesh.V.rows()), 0);
        for (Eigen::Index i = 0; i < faces.size(); ++i)
            on_surface.back()[static_cast<std::size_t>(faces(i / 3, i % 3))] = 1;
        for (const MatrixX3d& x : reference.frames[b])
            largest_displacement = std::max(largest_displacement, (x - scene.bodies[b].mesh.V).rowwise().norm().maxCoeff());
    }

    // The reference's model at the scene's Δt, then every other model the comparison runs, then auto.
    std::vector<std::string> models{reference_model, std::string(hyper::linear_model),
                                    std::string(hyper::corotational_model)};
    for (const hyper::MaterialNames& material : hyper::material_descriptions())
        if (material.compared && material.name != reference_model)
            models.push_back(material.name);
    models.push_back("auto");
    for (const std::string& model : models) {
        ModelError row;
        row.model = model;
        RunResult result;
        try {
            result = run_positions(scene, model);
        } catch (const Error& e) {
            std::cout << "model " << model << " failed: " << e.what() << '\n';
            row.failed = true;
            comparison.rows.push_back(row);
            continue;
        }
        if (result.interrupted) {
            std::cout << "interrupted: the comparison stops after " << comparison.rows.size() << " models\n";
            break;
        }
        double tet_sum = 0.0, surface_sum = 0.0;
        long tet_count = 0, surface_count = 0;
        for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
            if (result.frames[b].size() != reference.frames[b].size())
                throw Error(str("--compare: model ", model, " wrote ", result.frames[b].size(), " frames, the reference ",
                                reference.frames[b].size(), " (the frame times differ at dt/", reference_refinement, ")"));
            for (std::size_t f = 0; f < reference.frames[b].size(); ++f) {
                const Eigen::VectorXd error = (result.frames[b][f] - reference.frames[b][f]).rowwise().norm();
                for (Eigen::Index v = 0; v < error.size(); ++v) {
                    tet_sum += error[v] * error[v];
                    row.tet_max = std::max(row.tet_max, error[v]);
                    ++tet_count;
                    if (on_surface[b][static_cast<std::size_t>(v)]) {
                        surface_sum += error[v] * error[v];
                        row.surface_max = std::max(row.surface_max, error[v]);
                        ++surface_count;
                    }
                }
            }
        }
        row.tet_rms = std::sqrt(tet_sum / std::max(tet_count, 1L));
        row.surface_rms = std::sqrt(surface_sum / std::max(surface_count, 1L));
        row.relative_max = largest_displacement > 0.0 ? row.tet_max / largest_displacement : 0.0;
        row.newton_iterations = result.newton_iterations;
        row.seconds = result.seconds;
        row.seconds_per_step = result.seconds / std::max(result.steps, 1);
        for (std::size_t b = 0; b < result.segments.size(); ++b)
            row.models_used += (b ? "; " : "") + describe_segments(result.segments[b]);
        comparison.rows.push_back(row);
    }
    if (run == nullptr)
        return comparison;

    Table table(str("Each model at dt = ", scene.time_step, " s against stable neo-Hookean at dt/", reference_refinement,
                    " (", scene.title, ")"),
                {{"model", Format::text}, {"tet RMS error (m)", Format::scientific, 2},
                 {"tet max error (m)", Format::scientific, 2}, {"surface RMS error (m)", Format::scientific, 2},
                 {"surface max error (m)", Format::scientific, 2}, {"max error / max |u|", Format::scientific, 2},
                 {"Newton iterations", Format::integer}, {"time per step [ms]", Format::scientific, 2},
                 {"total [s]", Format::scientific, 2}, {"models used (steps)", Format::text}});
    for (const ModelError& row : comparison.rows) {
        if (row.failed)
            table.add_row({row.model, "failed", "failed", "failed", "failed", "failed", "-", "-", "-", "-"});
        else
            table.add_row({row.model, row.tet_rms, row.tet_max, row.surface_rms, row.surface_max, row.relative_max,
                           double(row.newton_iterations), 1e3 * row.seconds_per_step, row.seconds, row.models_used});
    }
    table.print(std::cout);
    std::cout << "reference: stable-neo-hookean at dt = " << comparison.reference_time_step
              << " s; doubling its dt moves it by at most " << comparison.reference_change << " m\n";
    table.write_csv(run->file("models_" + scene.file.stem().string() + ".csv"));
    double smallest = std::numeric_limits<double>::infinity();
    for (const ModelError& row : comparison.rows)
        if (!row.failed)
            smallest = std::min(smallest, row.tet_max);
    Table converged(str("The reference converged (", scene.title, ")"),
                    {{"scene", Format::text}, {"reference dt (s)", Format::scientific, 3},
                     {"change when its dt doubles (m)", Format::scientific, 2}, {"smallest model error (m)", Format::scientific, 2}});
    converged.add_row({scene.file.stem().string(), comparison.reference_time_step, comparison.reference_change, smallest});
    converged.write_csv(run->file("reference_" + scene.file.stem().string() + ".csv"));
    return comparison;
}

}  // namespace fem::scenes
