#pragma once
// Chapter 12: every force model of chapters 10–12 by name, and the integrator each one steps with —
// the one place the studies of chapters 12 and 13 and the scenes runner build a model from a name.
// docs/12_hyperelastic_newton.md#every-model-by-name
//
// The names: "linear" (chapter 10's LinearElasticity), "corotational" (chapter 11, the fast
// configuration: polar fit by Newton's polar iteration, shape-gradient forces), then every
// hyperelastic material of material_names() (HyperelasticElasticity). A new material registered in
// materials.cpp is a new name here without any edit.

#include "12_hyperelastic_newton/newton.hpp"

#include "11_corotational/corotational.hpp"

#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include "common/mesh.hpp"

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace fem::hyper {

/// The name of chapter 10's LinearElasticity ("linear"), the first of force_model_names(): the one
/// definition every chapter and the scenes runner compare a model's name with.
inline constexpr std::string_view linear_model = dynamics::LinearElasticity::model_name;

/// The name of chapter 11's CorotationalElasticity ("corotational"), the second of force_model_names().
inline constexpr std::string_view corotational_model = corot::CorotationalElasticity::model_name;

/// linear_model, corotational_model, then material_names() in the registry's order.
std::vector<std::string> force_model_names();

/// True for a name of material_names() (a model stepped by NewtonBackwardEuler), false for
/// "linear", "corotational" and any other name.
bool is_hyperelastic(std::string_view name);

/// The force model called `name` (one of force_model_names()) for a mesh and material (Y, ν; the
/// density is the Body's business). fem::Error for another name (the message lists the known ones),
/// or as the model's constructor (a bad mesh or material).
std::unique_ptr<dynamics::ForceModel> make_force_model(std::string_view name, const TetMesh& mesh,
                                                       const dynamics::Material& material);

/// How a model is stepped: chapter 10's integrator name, the solver's name, and the relative
/// tolerance of chapter 12's Newton iteration (hyperelastic models only). The solver: any name of
/// chapter 09's make_solver, or frozen_factor_solver; "default" means chapter 09's default solver
/// (the supernodal Cholesky) for "linear" and "corotational", and frozen_factor_solver for Newton.
struct StepSettings {
    std::string integrator = "backward-euler";
    std::string solver = "default";
    double newton_tolerance = 1e-6;
};

/// The name of chapter 11's FrozenFactorPcg as a Newton solver: one supernodal factor kept across
/// Newton iterations and steps, applied in single precision as CG's preconditioner and refactored
/// when a solve needs more than 10 CG iterations; with NewtonOptions::forcing each Newton system is
/// solved only as tightly as the gradient needs (inexact Newton). The fastest converged step of
/// docs/12_hyperelastic_newton.md#the-plain-route-and-hobaks-step, so the default of Newton steps.
inline constexpr std::string_view frozen_factor_solver = "frozen-factor-pcg";

/// The Newton options of a hyperelastic step: settings.newton_tolerance as the relative tolerance,
/// and settings.solver ("default" or frozen_factor_solver: FrozenFactorPcg made by
/// NewtonOptions::make_solver; any other name: chapter 09's solver of that name, checked when the
/// Newton step makes it). The rest are NewtonOptions' defaults.
NewtonOptions newton_options_for(const StepSettings& settings);

/// The integrator for the force model called `model`: chapter 10's make_integrator(settings.integrator)
/// with settings.solver for "linear" and "corotational" (frozen_factor_solver through
/// ImplicitOptions::make_solver); NewtonBackwardEuler with
/// newton_options_for(settings) for a hyperelastic one. fem::Error for an unknown model, integrator or
/// solver, a hyperelastic model with an integrator other than "backward-euler" (Newton steps backward
/// Euler only), or a tolerance outside (0, 1).
std::unique_ptr<dynamics::Integrator> make_integrator_for(std::string_view model, const StepSettings& settings = {});

}  // namespace fem::hyper
