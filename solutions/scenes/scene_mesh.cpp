// A scene body's rest mesh: a generated box, a file's tets, a surface tetrahedralised by TetGen or
// the lattice that encloses it (chapter 13), checked for size, memory and unused vertices.
// docs/scenes.md#the-scene-file
#include "scene_parts.hpp"

#include "13_skinning/skinning.hpp"

#include "common/mesh_io.hpp"
#include "common/tetgen.hpp"

#include <algorithm>
#include <cmath>

namespace fem::scenes::detail {

double body_size(const TetMesh& mesh)
{
    return (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).maxCoeff();
}

TetMesh build_mesh(const Fields& fields, const std::filesystem::path& scene_file, MeshSpec& spec)
{
    const bool file = fields.has("file"), generator = fields.has("generator");
    if (file == generator)
        throw Error(str(fields.where(fields.table()), ": ", fields.name(),
                        ": give exactly one of file = \"...\" (.obj, .stl, .ply, .node, .ele, .vtu) or generator = \"box\""));
    spec.scale = fields.positive("scale", 1.0);
    spec.translate = fields.vector("translate", Eigen::Vector3d::Zero());
    TetMesh mesh;
    if (generator) {
        spec.generator = fields.text("generator", "box", {"box"});
        spec.size = fields.vector("size", Eigen::Vector3d::Ones());
        if ((spec.size.array() <= 0.0).any())
            fields.fail(*fields.get("size"), "size", "every edge length must be > 0");
        if (fields.has("cells")) {
            const toml::array& cells = fields.array("cells", 3, "an array of 3 integers in [1, 200]");
            for (int i = 0; i < 3; ++i)
                spec.cells[i] = fields.integer_of(*cells.get(static_cast<std::size_t>(i)), str("cells[", i, "]"), 1, 200);
        }
        for (const std::string key : {"tetgen", "lattice"})
            if (fields.has(key))
                fields.fail(*fields.get(key), key, "belongs to a surface file");
        const Eigen::Vector3<long long> cells = spec.cells.cast<long long>();
        check_memory(fields, fields.has("cells") ? *fields.get("cells") : *fields.get("generator"), "cells",
                     (cells.array() + 1).prod(), 6 * cells.prod(), "use fewer cells");
        mesh = box_mesh(spec.cells.x(), spec.cells.y(), spec.cells.z(), spec.size);
        mesh.V *= spec.scale;  // scale applies to a generated box too (it was ignored)
    } else {
        for (const std::string key : {"size", "cells"})
            if (fields.has(key))
                fields.fail(*fields.get(key), key, "belongs to generator = \"box\"");
        spec.file = existing_file(fields, "file", scene_file);
        const toml::node& node = *fields.get("file");
        const std::string extension = spec.file.extension().string();
        try {
            if (extension == ".obj" || extension == ".stl" || extension == ".ply") {
                if (fields.has("lattice")) {
                    // Chapter 13's coarse mesh: the cubes of a lattice that enclose the surface.
                    if (fields.has("tetgen"))
                        fields.fail(*fields.get("tetgen"), "tetgen", "give either tetgen or lattice, not both");
                    spec.lattice = fields.integer_of(*fields.get("lattice"), "lattice", 1, 100);
                    const TriMesh surface = io::read_tri_mesh(spec.file);
                    // The lattice's cubes are at most those of the surface's bounding box at its
                    // spacing: refused before they are built when their run would not fit in memory
                    // or their winding numbers (each cube against every triangle) are too many.
                    const Eigen::Vector3d extent = surface.V.colwise().maxCoeff() - surface.V.colwise().minCoeff();
                    const double spacing = extent.maxCoeff() / spec.lattice;
                    if (spacing > 0.0) {
                        const Eigen::Vector3<long long> cubes =
                            (extent / spacing).array().ceil().max(1.0).cast<long long>() + 1;
                        check_memory(fields, *fields.get("lattice"), "lattice", (cubes.array() + 1).prod(),
                                     6 * cubes.prod(), "use a smaller lattice");
                        const double work = static_cast<double>(cubes.prod()) * static_cast<double>(surface.F.rows());
                        if (work > fields.source().limits.lattice_work)
                            fields.fail(*fields.get("lattice"), "lattice",
                                        str("up to ", cubes.prod(), " cubes against ", surface.F.rows(),
                                            " triangles are ", work, " winding-number terms; at most ",
                                            fields.source().limits.lattice_work, " are allowed: use a smaller lattice"));
                    }
                    mesh = skin::enclosing_lattice(surface, spec.lattice);
                } else {
                    spec.tetgen = fields.text("tetgen", spec.tetgen);
                    if (!fields.source().limits.tetgen)
                        fields.fail(node, "file", "a surface to tetrahedralise, and TetGen is not allowed here");
                    mesh = tetrahedralize(io::read_tri_mesh(spec.file), spec.tetgen, spec.file.string(),
                                          fields.source().limits.tetgen_limits);
                }
            } else if (extension == ".node" || extension == ".ele" || extension == ".vtu") {
                for (const std::string key : {"tetgen", "lattice"})
                    if (fields.has(key))
                        fields.fail(*fields.get(key), key, "belongs to a surface file (.obj, .stl, .ply)");
                mesh = io::read_tet_mesh(spec.file);
            } else {
                fields.fail(node, "file", str("has the extension '", extension,
                                              "'; allowed: .obj, .stl, .ply (surfaces, TetGen makes the tets), .node, .ele, .vtu"));
            }
        } catch (const Error& e) {
            const std::string text = e.what();
            if (text.rfind(fields.source().file, 0) == 0)
                throw;  // an error of the scene file itself (e.g. lattice), already located
            fields.fail(node, "file", text);
        }
        mesh.V *= spec.scale;
        if (mesh.T.rows() > 0 && !fields.has("lattice"))  // a lattice was counted before it was built
            check_memory(fields, node, "file", mesh.V.rows(), mesh.T.rows(), "use a coarser mesh (or larger TetGen volumes)");
    }
    if (mesh.T.rows() == 0)
        fields.fail(*fields.get(file ? "file" : "generator"), file ? "file" : "generator", "the mesh has no tets");
    // The body's size within what the arithmetic holds: a tet's volume is a product of three edges,
    // its stiffness divides by their squares, so edges of 1e±103 m and beyond leave a double's range
    // (a 1e300 m box read as "zero volume"). The course's bodies are millimetres to metres.
    const double extent = body_size(mesh);
    if (!(extent >= smallest_body_extent && extent <= largest_body_extent)) {
        const std::string key = generator ? "size" : (fields.has("scale") ? "scale" : "file");
        fields.fail(fields.has(key) ? *fields.get(key) : *fields.get(file ? "file" : "generator"), key,
                    str("the body is ", extent, " m across; allowed: ", smallest_body_extent, " m to ",
                        largest_body_extent, " m (change ", generator ? "size" : "scale", ")"));
    }
    // A vertex no tet uses has neither mass nor stiffness: the step's matrix would be singular.
    std::vector<bool> used(static_cast<std::size_t>(mesh.V.rows()), false);
    for (Eigen::Index t = 0; t < mesh.T.rows(); ++t)
        for (int c = 0; c < 4; ++c)
            used[static_cast<std::size_t>(mesh.T(t, c))] = true;
    if (const auto unused = std::find(used.begin(), used.end(), false); unused != used.end())
        fields.fail(*fields.get(file ? "file" : "generator"), file ? "file" : "generator",
                    str("vertex ", unused - used.begin(), " belongs to no tet (", std::count(used.begin(), used.end(), false),
                        " of ", used.size(), " vertices do not); a vertex without a tet has no mass and no stiffness, ",
                        "and the step's matrix would be singular: remove it from the mesh"));
    mesh.V.rowwise() += spec.translate.transpose();
    return mesh;
}

}  // namespace fem::scenes::detail
