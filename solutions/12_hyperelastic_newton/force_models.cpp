#include "12_hyperelastic_newton/force_models.hpp"

#include "12_hyperelastic_newton/hyperelastic.hpp"
#include "12_hyperelastic_newton/materials.hpp"
#include "12_hyperelastic_newton/newton.hpp"

#include "11_corotational/corotational.hpp"
#include "11_corotational/frozen_preconditioner.hpp"

#include "common/error.hpp"

#include <algorithm>

namespace fem::hyper {
namespace {

/// The error for a model name that is not one of force_model_names(), listing them.
Error unknown_model(std::string_view name)
{
    std::string names;
    for (const std::string& known : force_model_names())
        names += str(names.empty() ? "" : ", ", known);
    return Error(str("unknown force model '", name, "'; choose one of: ", names));
}

/// Chapter 11's frozen factor as the solver of every step matrix (frozen_factor_solver).
std::unique_ptr<cg::LinearSolver> make_frozen_factor_solver()
{
    return std::make_unique<corot::FrozenFactorPcg>(cg::SolverOptions{1e-8, 0}, corot::RefreshRule{.iterations_above = 10});
}

}  // namespace

std::vector<std::string> force_model_names()
{
    std::vector<std::string> names{std::string(linear_model), std::string(corotational_model)};
    for (std::string& material : material_names())
        names.push_back(std::move(material));
    return names;
}

bool is_hyperelastic(std::string_view name)
{
    const std::vector<std::string> materials = material_names();
    return std::find(materials.begin(), materials.end(), name) != materials.end();
}

std::unique_ptr<dynamics::ForceModel> make_force_model(std::string_view name, const TetMesh& mesh,
                                                       const dynamics::Material& material)
{
    if (name == linear_model)
        return std::make_unique<dynamics::LinearElasticity>(mesh, material);
    if (name == corotational_model)
        return std::make_unique<corot::CorotationalElasticity>(mesh, material, corot::RotationFit::polar,
                                                               corot::PolarAlgorithm::newton,
                                                               corot::ForceForm::shape_gradients);
    if (is_hyperelastic(name))
        return std::make_unique<HyperelasticElasticity>(
            mesh, make_material(name, material.youngs_modulus, material.poisson_ratio));
    throw unknown_model(name);
}

NewtonOptions newton_options_for(const StepSettings& settings)
{
    NewtonOptions options;
    options.relative_tolerance = settings.newton_tolerance;
    if (settings.solver == "default" || settings.solver == frozen_factor_solver)
        options.make_solver = make_frozen_factor_solver;
    else
        options.solver = settings.solver;
    return options;
}

std::unique_ptr<dynamics::Integrator> make_integrator_for(std::string_view model, const StepSettings& settings)
{
    if (is_hyperelastic(model)) {
        if (settings.integrator != "backward-euler")
            throw Error(str("integrator '", settings.integrator, "' for the hyperelastic model '", model,
                            "': chapter 12's Newton steps backward Euler only; use backward-euler"));
        return std::make_unique<NewtonBackwardEuler>(newton_options_for(settings));
    }
    if (model != linear_model && model != corotational_model)
        throw unknown_model(model);
    dynamics::ImplicitOptions options;
    if (settings.solver == frozen_factor_solver)
        options.make_solver = make_frozen_factor_solver;
    else
        options.solver = settings.solver;
    return dynamics::make_integrator(settings.integrator, options);
}

}  // namespace fem::hyper
