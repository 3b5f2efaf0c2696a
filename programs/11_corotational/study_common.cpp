// What the studies of ch11_corotational share: the beam scene, its tip, the force models, the
// solver options of a changing step matrix, and a body's frame.
#include "11_corotational/frozen_preconditioner.hpp"
#include "studies.hpp"

#include "06_assembly/assembly.hpp"

#include "common/error.hpp"

namespace fem::corot::study {

std::unique_ptr<dynamics::ForceModel> force_model(const std::string& name, const dynamics::Scene& scene)
{
    if (name == "linear")
        return std::make_unique<dynamics::LinearElasticity>(scene.mesh, scene.material);
    if (name == "corotational")
        return std::make_unique<CorotationalElasticity>(scene.mesh, scene.material);
    throw Error(str("unknown force model '", name, "' (linear, corotational)"));
}

const std::vector<std::string>& solver_option_names()
{
    static const std::vector<std::string> names{"refactor", "pcg-ic0 v+ from zero", "pcg-ic0 v+ from v",
                                                "pcg-ic0 dv from last dv", "frozen-factor-pcg",
                                                "rotated-frozen-factor-pcg double", "rotated-frozen-factor-pcg"};
    return names;
}

dynamics::ImplicitOptions solver_option(const std::string& name, double tolerance, dynamics::Body& body)
{
    dynamics::ImplicitOptions options;
    options.solver_options.relative_tolerance = tolerance;
    options.solver = "ours-pcg-ic0";
    if (name == "refactor") {
        options.solver = "ours-cholesky";
    } else if (name == "pcg-ic0 v+ from zero") {
        options.form = dynamics::StepForm::velocity;
        options.warm_start = false;
    } else if (name == "pcg-ic0 v+ from v") {
        options.form = dynamics::StepForm::velocity;
    } else if (name == "pcg-ic0 dv from last dv") {
        // the default form, warm
    } else if (name == "frozen-factor-pcg") {
        options.make_solver = [tolerance] {
            cg::SolverOptions pcg;
            pcg.relative_tolerance = tolerance;
            return std::make_unique<FrozenFactorPcg>(pcg, RefreshRule{.balance_cost = true});
        };
    } else if (name == "rotated-frozen-factor-pcg" || name == "rotated-frozen-factor-pcg double") {
        auto* model = dynamic_cast<CorotationalElasticity*>(&body.model());
        if (model == nullptr)
            throw Error(str(name, ": the body's force model is not corotational"));
        const FactorPrecision precision =
            name == "rotated-frozen-factor-pcg" ? FactorPrecision::single_precision : FactorPrecision::double_precision;
        options.make_solver = [tolerance, model, precision, &dofs = body.dofs()] {
            cg::SolverOptions pcg;
            pcg.relative_tolerance = tolerance;
            return std::make_unique<FrozenFactorPcg>(
                pcg, RefreshRule{.balance_cost = true}, [model, &dofs] { return free_vertex_rotations(*model, dofs); }, precision);
        };
    } else {
        throw Error(str("unknown solver option '", name, "'"));
    }
    return options;
}

}  // namespace fem::corot::study
