// What the studies of ch13_skinning share: the bunny's meshes and the pushed bunny's run.
#include "studies.hpp"

#include "12_hyperelastic_newton/force_models.hpp"

#include "common/files.hpp"
#include "common/mesh_io.hpp"

namespace fem::skin::study {

const std::vector<std::string>& model_names()
{
    static const std::vector<std::string> names{"corotational", "stable-neo-hookean"};
    return names;
}

TriMesh bunny_surface()
{
    return io::read_tri_mesh(data_path("bunny.obj"));
}

TetMesh bunny_tets()
{
    return io::read_tet_mesh(data_path("bunny_coarse.node"));
}

double ground_height(const TriMesh& surface)
{
    const double low = surface.V.col(1).minCoeff(), high = surface.V.col(1).maxCoeff();
    return low + 0.05 * (high - low);
}

Run bunny_run(const TetMesh& mesh, const TriMesh& surface, const Settings& settings, const std::vector<int>* pinned)
{
    const double low = surface.V.col(1).minCoeff(), high = surface.V.col(1).maxCoeff();
    dynamics::Scene scene = dynamics::standing_scene(mesh, settings.rubber, ground_height(surface), settings.duration);
    if (pinned != nullptr) {
        scene.pinned = *pinned;
        dynamics::validate(scene);
    }
    Run run;
    run.body = std::make_unique<dynamics::Body>(scene, hyper::make_force_model(settings.model, scene.mesh, scene.material));
    run.integrator = hyper::make_integrator_for(settings.model);
    run.push = dynamics::sideways_push(scene, low, high, 0.5);
    return run;
}

}  // namespace fem::skin::study
