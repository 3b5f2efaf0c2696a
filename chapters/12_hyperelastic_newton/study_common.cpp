// What the studies of ch12_hyperelastic_newton share: the beam scene, its tip, the force models by
// name, and a body's frame.
#include "12_hyperelastic_newton/studies.hpp"

#include "11_corotational/corotational.hpp"

#include "06_assembly/assembly.hpp"

#include "common/error.hpp"

namespace fem::hyper::study {

const std::vector<std::string>& model_names()
{
    static const std::vector<std::string> names{"linear", "corotational", "stvk", "neo-hookean", "stable-neo-hookean"};
    return names;
}

std::unique_ptr<dynamics::ForceModel> force_model(const std::string& name, const dynamics::Scene& scene)
{
    if (name == "linear")
        return std::make_unique<dynamics::LinearElasticity>(scene.mesh, scene.material);
    if (name == "corotational")
        return std::make_unique<corot::CorotationalElasticity>(scene.mesh, scene.material);
    return std::make_unique<HyperelasticElasticity>(
        scene.mesh, make_material(name, scene.material.youngs_modulus, scene.material.poisson_ratio));
}

}  // namespace fem::hyper::study
