// Chapter 13's skin as an observer of a scene body's frames. docs/scenes.md#skin
#include "scenes/skin_observer.hpp"

#include "13_skinning/skinning.hpp"

#include "common/error.hpp"
#include "common/mesh_io.hpp"

namespace fem::scenes {
namespace {

/// Chapter 13's skin: W bound once to the body's rest tets (point location, barycentric weights,
/// the outside rule), and each frame the surface at x = W (X + u) with its normals.
class ChapterSkin final : public SkinObserver {
public:
    ChapterSkin(const SkinSpec& spec, const BodySpec& body) : rest_(body.mesh.V)
    {
        try {
            // The skin's file is in the coordinates of its body's mesh file: the same scale and shift.
            TriMesh surface = io::read_tri_mesh(spec.file);
            surface.V *= body.mesh_spec.scale;
            surface.V.rowwise() += body.mesh_spec.translate.transpose();
            skin_ = skin::build_skin(body.mesh, surface);
        } catch (const Error& e) {
            throw Error(str("skin '", spec.file.string(), "' of body '", spec.body, "': ", e.what()));
        }
    }
    io::MeshData frame(const Eigen::VectorXd& u) const override
    {
        return skin::skin_frame(skin_, rest_ + io::vertex_rows(u));
    }

private:
    MatrixX3d rest_;
    skin::Skin skin_;
};

}  // namespace

std::unique_ptr<SkinObserver> make_skin_observer(const SkinSpec& skin, const BodySpec& body)
{
    return std::make_unique<ChapterSkin>(skin, body);
}

std::size_t skin_body(const SceneSpec& scene)
{
    if (!scene.skin)
        throw Error("skin_body: the scene has no skin");
    for (std::size_t i = 0; i < scene.bodies.size(); ++i)
        if (scene.bodies[i].name == scene.skin->body)
            return i;
    throw Error(str("skin: no body is called '", scene.skin->body, "'"));
}

}  // namespace fem::scenes
