#pragma once
// The readers of a scene file's parts, the steps of read_scene (solutions/scenes/scene_file.cpp):
// selectors and motions (scene_selectors.cpp), obstacles (scene_obstacles.cpp), the memory budget
// (scene_memory.cpp), a body's mesh (scene_mesh.cpp), a body (scene_body.cpp) and the overrides of
// [quick] and --set (scene_overrides.cpp). Internal to the scene reader. docs/scenes.md#the-scene-file

#include "scenes/scene_fields.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace fem::scenes::detail {

/// A selector table's one of box = [[x0, y0, z0], [x1, y1, z1]], plane = { point, normal, side } or
/// vertices = [...]; its `where` names the table. docs/scenes.md#selecting-vertices
Selector read_selector(const Fields& fields);

/// A pin's motion: fixed, rotate (axis, center, angle in degrees) or translate (displacement) over
/// [start, end] (end defaults to the scene's duration); a field of another motion is refused.
Motion read_motion(const Fields& fields, double duration);

/// One [[obstacle]]: its type's fields only (the others are refused, naming the type they belong to),
/// μ and a velocity, of any speed (chapter 14's contact_step starts each step where the obstacles'
/// motion reaches no vertex, in stages when it must). A mesh's file is read (beside the scene file,
/// then in data/) and placed: its coordinates × scale + translate.
ObstacleSpec read_obstacle(const toml::table& table, const std::string& name, const Source& source,
                           const std::filesystem::path& scene_file);

/// An obstacle may reach this many d̂ from the origin, its motion over the run included: a double
/// resolves a position there to 2·10⁻⁸ d̂, about the barrier's own round-off; a sphere of radius
/// 10⁶ m against a 10 cm block (d̂ = 10⁻³ m) stalled Newton at step 8, one of 10⁵ m ran.
inline constexpr double obstacle_reach_limit = 1e8;

/// A body's vertex may start this many d̂ from a solid obstacle at the least: closer, the barrier's
/// curvature ~ κ d̂²/d² leaves a double's range (a block 10⁻¹⁰⁰ m above the floor: its Newton step
/// could not be solved; 10⁻²⁰ m ran).
inline constexpr double closest_start = 1e-8;

/// Refuses an obstacle (scene.obstacles.back(), read from node, called name) that moves farther
/// than obstacle_reach_limit d̂ in the run (at its velocity field) or reaches farther than that from
/// the origin (at its field of the largest magnitude). docs/scenes.md#obstacles
void check_obstacle_scale(const Fields& top, const toml::node& node, const std::string& name, const SceneSpec& scene);

/// Refuses a scene whose bodies start inside its last obstacle (scene.obstacles.back(), read from
/// node, called name): no vertex may start inside, where its barrier energy would be infinite. A
/// mesh's distance is unsigned (no inside): a body must start beyond d̂ of it, and no edge of its
/// tets may pass through a triangle (a body through a sheet may have every vertex far from it).
/// A solid must start at least closest_start d̂ from every vertex, no surface edge of a body may
/// pass through it, no edge of a box or a mesh through a body's surface triangle, and no obstacle
/// may lie inside a body; and a body meeting obstacles may not be of model linear (at its
/// material.model field). Each refusal names the body, its vertex, edge, triangle or tet.
void check_bodies_clear(const Fields& top, const toml::node& node, const std::string& name, const SceneSpec& scene);

/// Refuses two half-spaces facing each other (antiparallel normals, the bodies between them) whose
/// prescribed motions close the gap between their planes to 2 d̂ or less within the run: the last
/// obstacle (scene.obstacles.back(), read from node, called name) against each one before it, at
/// its velocity field (or its table if it is the other that moves), naming both and the time. A
/// body between them would have to flatten below 2 d̂ or pass through one; a gap that stays wider
/// is left to the run (a body squeezed thin but not flat). The gap of two planes is
/// g(t) = n_b·(x_a + t w_a − p_b − t w_b), linear in t.
void check_half_spaces_apart(const Fields& top, const toml::node& node, const std::string& name, const SceneSpec& scene);

/// Refuses a mesh obstacle of this many triangles when its memory (bytes_per_obstacle_triangle each,
/// scene_memory.cpp) with the bodies' and obstacles' before it passes the scene's budget: at field key.
void check_obstacle_memory(const Fields& fields, const toml::node& node, const std::string& key, long long triangles);

/// Refuses a body whose run would need more memory than the scene may use (see memory_estimate),
/// the bodies read before it included: the error is at field, the field to change.
void check_memory(const Fields& fields, const toml::node& node, const std::string& key, long long vertices,
                  long long tets, const std::string& change);

/// A body's size: the longest edge of its vertices' bounding box [m].
double body_size(const TetMesh& mesh);

/// The rest mesh of a [body.mesh] table (fields), with its spec filled in: a generated box, or a
/// file's tets (.node, .ele, .vtu), a surface's tets (TetGen) or the lattice enclosing a surface,
/// scaled and translated. Refused: a mesh without tets, a body too small or too large, a vertex no
/// tet uses, or one that needs more memory than allowed.
TetMesh build_mesh(const Fields& fields, const std::filesystem::path& scene_file, MeshSpec& spec);

/// One [[body]] (table, called name, the index-th): its name, mesh, material, mass, damping,
/// initial velocity, pins (their vertices selected, none pinned twice) and loads.
BodySpec read_body(const toml::table& table, const std::string& name, const Source& file,
                   const std::filesystem::path& scene_file, double duration, double time_step, int index);

/// Applies the [quick] table's leaves to root (each as an override source records), when root has one.
void apply_quick_table(toml::table& root, Source& source);

/// Applies each "key=value" of settings (the --set options) to root, recorded in source.
void apply_set_options(toml::table& root, const std::vector<std::string>& settings, Source& source);

}  // namespace fem::scenes::detail
