#pragma once
// The one place chapter 13 plugs into the scenes: a fine surface carried by a body's tets, written
// beside the tets' frames. docs/scenes.md#skin

#include "scenes/scene_file.hpp"

#include "common/vtk_io.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <memory>

namespace fem::scenes {

/// An observer of a body's frames that carries a fine surface (its .vtp series is written beside
/// the tets' frames). docs/scenes.md#skin
class SkinObserver {
public:
    virtual ~SkinObserver() = default;
    /// The skin's surface at the body's displacement u (3n), for the frame's .vtp.
    virtual io::MeshData frame(const Eigen::VectorXd& u) const = 0;
};

/// The skin of a scene, bound to the rest tets of its body by chapter 13's build_skin; the skin's
/// file is read in its body's mesh coordinates (the body's scale and translate apply). fem::Error
/// naming the skin's file and body for a surface chapter 13 refuses (empty, degenerate, or a vertex
/// farther outside the tets than its limit).
std::unique_ptr<SkinObserver> make_skin_observer(const SkinSpec& skin, const BodySpec& body);

/// The index of the body the scene's skin names (the scene must have a skin; read_scene checked
/// the name).
std::size_t skin_body(const SceneSpec& scene);

}  // namespace fem::scenes
