// Chapter 14: the surface of a tet mesh as contact primitives. docs/14_contact.md#the-contact-potential
#include "14_contact/surface.hpp"

#include "13_skinning/skinning.hpp"

#include <algorithm>
#include <map>
#include <utility>

namespace fem::contact {

SurfacePrimitives surface_primitives(const TetMesh& mesh)
{
    SurfacePrimitives surface;
    surface.triangles = skin::boundary_faces(mesh).faces;
    std::map<std::pair<int, int>, int> edges;
    for (Eigen::Index f = 0; f < surface.triangles.rows(); ++f)
        for (int i = 0; i < 3; ++i) {
            const int a = surface.triangles(f, i), b = surface.triangles(f, (i + 1) % 3);
            edges.try_emplace({std::min(a, b), std::max(a, b)}, static_cast<int>(edges.size()));
        }
    surface.edges.resize(static_cast<Eigen::Index>(edges.size()), 2);
    for (const auto& [edge, row] : edges)
        surface.edges.row(row) << edge.first, edge.second;
    std::vector<bool> on_surface(static_cast<std::size_t>(mesh.V.rows()), false);
    for (Eigen::Index f = 0; f < surface.triangles.rows(); ++f)
        for (int c = 0; c < 3; ++c)
            on_surface[static_cast<std::size_t>(surface.triangles(f, c))] = true;
    for (int v = 0; v < static_cast<int>(on_surface.size()); ++v)
        if (on_surface[static_cast<std::size_t>(v)])
            surface.vertices.push_back(v);
    return surface;
}

}  // namespace fem::contact
