// What the studies of ch12_hyperelastic_newton share: the beam scene, its tip, the force models by
// name, and a body's frame.
#include "12_hyperelastic_newton/studies.hpp"

#include "11_corotational/corotational.hpp"

#include "06_assembly/assembly.hpp"

#include "common/error.hpp"

namespace fem::hyper::study {

dynamics::Scene beam_scene(const dynamics::Material& material, int cells_along, double duration)
{
    dynamics::Scene scene;
    scene.mesh = beam_mesh(0.2, 0.02, 0.02, cells_along);
    scene.material = material;
    scene.pinned = assembly::vertices_on_plane(scene.mesh, 0, 0.0);
    scene.gravity = Eigen::Vector3d(0.0, 0.0, -9.81);
    scene.time_step = 1.0 / 60.0;
    scene.duration = duration;
    return scene;
}

int beam_tip(const TetMesh& mesh)
{
    Eigen::Index tip = 0;
    mesh.V.rowwise().sum().maxCoeff(&tip);
    return static_cast<int>(tip);
}

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

io::MeshData frame(const dynamics::Body& body, const dynamics::State& state)
{
    io::MeshData data = io::displaced_mesh(body.mesh().V, body.mesh().T, io::vertex_rows(state.u));
    data.point_data.push_back({"velocity", io::vertex_rows(state.v)});
    data.cell_data.push_back({"von Mises stress", body.model().von_mises_stress(state.u)});
    return data;
}

}  // namespace fem::hyper::study
