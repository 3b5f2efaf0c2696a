// What the studies of ch10_linear_dynamics share: the beam scene, its tip, and a body's frame.
#include "10_linear_dynamics/studies.hpp"

#include "06_assembly/assembly.hpp"

namespace fem::dynamics::study {

Scene beam_scene(const Material& material, int cells_along)
{
    Scene scene;
    scene.mesh = beam_mesh(0.2, 0.02, 0.02, cells_along);
    scene.material = material;
    scene.pinned = assembly::vertices_on_plane(scene.mesh, 0, 0.0);
    scene.gravity = Eigen::Vector3d(0.0, 0.0, -9.81);
    scene.time_step = 1.0 / 60.0;
    scene.duration = 1.0;
    return scene;
}

int beam_tip(const TetMesh& mesh)
{
    Eigen::Index tip = 0;
    mesh.V.rowwise().sum().maxCoeff(&tip);
    return static_cast<int>(tip);
}

io::MeshData frame(const Body& body, const State& state)
{
    io::MeshData data = io::displaced_mesh(body.mesh().V, body.mesh().T, io::vertex_rows(state.u));
    data.point_data.push_back({"velocity", io::vertex_rows(state.v)});
    data.cell_data.push_back({"von Mises stress", body.model().von_mises_stress(state.u)});
    return data;
}

}  // namespace fem::dynamics::study
