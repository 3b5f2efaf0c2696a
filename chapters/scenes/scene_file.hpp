#pragma once
// The scenes capstone: a scene file (TOML) and what it describes. docs/scenes.md#the-scene-file
//
// A scene is plain data, read and checked once, before anything is computed or written: one or
// more bodies (each a mesh, a material and force model, pinned vertices with their prescribed
// motion, loads, damping, an initial velocity), the gravity they share, the time step and duration,
// the thresholds of model "auto", the outputs, and an optional skin (chapter 13). The runner
// (runner.hpp) builds chapter 10's Scene and Body for each body from it.
//
// Every field is checked where it is read: the message names the file, line and column, the field
// (e.g. body[0].material.poisson_ratio) and what is allowed; a field the format does not know is an
// error, never ignored. --set key=value and the scene's own [quick] table edit the file's tree
// before it is read, so an override is checked like the file itself.

#include "14_contact/obstacles.hpp"

#include "10_linear_dynamics/body.hpp"

#include "common/mesh.hpp"
#include "common/tetgen.hpp"

#include <Eigen/Core>

#include <array>
#include <utility>

#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace fem::scenes {

/// A set of vertices of a body's rest mesh. docs/scenes.md#selecting-vertices
struct Selector {
    enum class Kind { box, plane, vertices };
    Kind kind = Kind::box;
    Eigen::Vector3d low = Eigen::Vector3d::Zero(), high = Eigen::Vector3d::Zero();  ///< box corners [m]
    Eigen::Vector3d point = Eigen::Vector3d::Zero();   ///< plane: a point on it [m]
    Eigen::Vector3d normal = Eigen::Vector3d::UnitX(); ///< plane: its normal (unit)
    bool below = false;            ///< plane: every vertex on or behind it (n·(x − p) ≤ tol), not only on it
    std::vector<int> vertices;     ///< an explicit list
    std::string where;             ///< "scenes/x.toml:12:1: body[0].pin[1]", for "selects nothing"
};

/// How pinned vertices move: held (fixed), turned about an axis, or moved by a displacement, with
/// the smooth ramp s(t) = 3τ² − 2τ³, τ = (t − start)/(end − start) clamped to [0, 1] (zero velocity
/// at both ends). docs/scenes.md#pinned-vertices-and-prescribed-motion
struct Motion {
    enum class Kind { fixed, rotate, translate };
    Kind kind = Kind::fixed;
    Eigen::Vector3d axis = Eigen::Vector3d::UnitX();   ///< rotate: the axis direction (unit)
    Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< rotate: a point on the axis [m]
    double angle = 0.0;                                ///< rotate: the total angle [rad]
    /// translate: the total displacement [m]; rotate: the axis's (the turned pins carried along by it)
    Eigen::Vector3d displacement = Eigen::Vector3d::Zero();
    double start = 0.0, end = 0.0;                     ///< the ramp's time window [s], start < end
};

/// One group of pinned vertices and its motion.
struct Pin {
    Selector select;
    Motion motion;
};

/// An applied force beyond gravity: a point load (total force spread equally over the selected
/// vertices) or a surface traction (force per area on the boundary triangles whose three corners are
/// selected, lumped a third of each triangle's force to each corner). Scaled by min(1, t/ramp)
/// (ramp > 0) and zero after `until`. docs/scenes.md#loads
struct Load {
    enum class Kind { point, surface };
    Kind kind = Kind::point;
    Selector select;
    Eigen::Vector3d value = Eigen::Vector3d::Zero();  ///< point: total force [N]; surface: traction [Pa]
    double ramp = 0.0;                                ///< [s], 0: applied at once
    double until = std::numeric_limits<double>::infinity();  ///< [s], released after this time
};

/// Where a body's tets come from.
struct MeshSpec {
    std::filesystem::path file;         ///< .obj/.stl/.ply (tetrahedralised with TetGen), .node/.ele/.vtu
    std::string generator;              ///< "box" (box_mesh) when no file
    Eigen::Vector3d size = Eigen::Vector3d::Ones();   ///< box: edge lengths [m]
    Eigen::Vector3i cells = Eigen::Vector3i::Ones();  ///< box: cubes along x, y, z (6 tets each)
    double scale = 1.0;                 ///< applied to a file's positions first
    Eigen::Vector3d translate = Eigen::Vector3d::Zero();  ///< then this shift [m]
    std::string tetgen = "pq1.5aY";     ///< TetGen's switches for a surface (a max volume may follow a)
    int lattice = 0;                    ///< > 0: instead of TetGen, chapter 13's enclosing_lattice of the
                                        ///< surface with this many cubes along its longest side
};

/// The force models a body can use. "auto" starts linear and moves up per step (runner.hpp).
const std::vector<std::string>& model_names();

/// One body of a scene.
struct BodySpec {
    std::string name;                   ///< names its files and table rows (default body0, body1, …)
    MeshSpec mesh_spec;
    TetMesh mesh;                       ///< the rest mesh, built when the scene is read
    std::string model = dynamics::LinearElasticity::model_name;  ///< one of model_names(); "linear" unless given
    dynamics::Material material;
    dynamics::MassModel mass = dynamics::MassModel::lumped;
    dynamics::Damping damping;
    std::vector<Pin> pins;
    std::vector<Load> loads;
    Eigen::Vector3d initial_velocity = Eigen::Vector3d::Zero();  ///< of every free vertex [m/s]
    std::vector<int> pinned;            ///< the union of the pins' vertices, ascending
    /// Whether its surface holds itself off (chapter 14's self-contact: a bar that coils onto itself).
    /// docs/scenes.md#bodies-against-bodies
    bool self_contact = false;
};

/// When model "auto" moves up from linear to corotational to hyperelastic (and back down), measured
/// per step on every tet's deformation gradient F (model_auto.hpp). docs/scenes.md#model-auto
struct AutoThresholds {
    double rotation = 0.0872664625997165;  ///< an unstrained rotation up to this angle [rad] stays linear
                                           ///< (5°: a ghost strain 1 − cos 5° = 0.38 %)
    double ghost_ratio = 0.1;              ///< linear also holds while a tet's ghost strain is at most this
                                           ///< fraction of its real (Green) strain
    double strain = 0.05;                  ///< largest principal Green strain corotational allows
    double volume_ratio = 0.9;             ///< corotational allows det F in [volume_ratio, 2 − volume_ratio]
    double hysteresis = 0.5;               ///< move down only below this fraction of a threshold
    std::string hyperelastic = "stable-neo-hookean";  ///< the model above corotational
};

/// What a run writes. docs/scenes.md#outputs
struct OutputSpec {
    double frame_rate = 30.0;           ///< frames per simulated second (each a .vtu, a PNG, a CSV row)
    bool pvd = true;                    ///< the .pvd time series of .vtu frames
    bool png = true;                    ///< PNG frames (needs a display)
    std::string video = "mp4";          ///< "mp4", "gif" or "none" (ffmpeg, from the PNG frames)
    bool csv = true;                    ///< steps.csv: energies, Newton iterations and time per step
    bool charts = true;                 ///< the charts of steps.csv (PNG + CSV: energies, step_time, newton_iterations)
    bool html = false;                  ///< the web page <scene>.html that plays the run (web_page.hpp)
    std::vector<std::string> fields{"displacement", "velocity", "von Mises stress"};  ///< in the frames
    std::string colour = "von Mises stress";  ///< the field the PNGs are coloured by
    Eigen::Vector3d view_direction{0.3, 1.0, -0.3};   ///< the camera looks along this
    Eigen::Vector3d view_up{0.0, 0.0, 1.0};
    double warp = 1.0;                  ///< displacement scale of the PNGs
    /// The box the camera frames [m] (xmin, xmax, ymin, ymax, zmin, zmax); default: the union of
    /// the frames' bounds, known only at the end, so a live view (--view) frames the rest shape.
    /// Set it (and colour_range) for a live view with exactly the PNGs' camera and colours.
    std::optional<std::array<double, 6>> frame_box;
    std::optional<std::pair<double, double>> colour_range;  ///< default: the run's range
    int width = 900, height = 700;      ///< PNG size [pixels]
};

/// An optional fine surface carried by the tets (chapter 13). docs/scenes.md#skin
struct SkinSpec {
    std::filesystem::path file;         ///< .obj/.stl/.ply surface
    std::string body;                   ///< the body that carries it
};

/// A rigid obstacle every body must stay out of (chapter 14): one of obstacle_types() (a
/// half-space, a sphere, a box, a triangle mesh, …), fixed or moving with a constant velocity, with
/// Coulomb friction μ against every body. docs/scenes.md#obstacles
struct ObstacleSpec {
    std::string type;                                   ///< its [[obstacle]] type, e.g. "sphere"
    std::shared_ptr<const contact::Obstacle> obstacle;  ///< chapter 14's obstacle, placed, with its μ and w
    std::filesystem::path file;                         ///< the file it was read from (a mesh's), else empty
};

/// The constants of contact a scene may set (chapter 14's ContactOptions). docs/scenes.md#obstacles
struct ContactSpec {
    double activation_distance = 1e-3;  ///< d̂ [m]: the barrier acts where a vertex is closer than this
    double friction_velocity = 1e-3;    ///< ε_v [m/s]: slower tangential motion sticks
    /// Whether the bodies hold each other off (chapter 14's barrier between their surfaces, the
    /// bodies that can meet stepped as one solve: scene_group.hpp). docs/scenes.md#bodies-against-bodies
    bool bodies = false;
    /// Coulomb's μ between bodies, and of a body against itself (chapter 14's lagged friction on the
    /// surface pairs, BodyContactOptions::body_friction): with bodies or a body's self_contact; 0: none.
    /// docs/scenes.md#bodies-against-bodies
    double friction = 0.0;
    /// The path check (chapter 15's BodyContactOptions::check_path, fem_scene --check-path): every
    /// segment of every contact step's path between bodies, and every step's chord without contact,
    /// proven free of crossings by a second CCD; a debug mode. docs/scenes.md#bodies-against-bodies
    bool check_path = false;
    /// The solver of every contact step, one of contact_solvers(): "ipc" (chapter 14's barrier, its
    /// Newton's line search cut by the collision check) or "augmented_lagrangian" (chapter 16's
    /// multipliers on d ≥ d̂, no barrier). IPC by default: the augmented Lagrangian takes fewer Newton
    /// iterations on every scene chapter 16 measures, but it has no friction between bodies, does not
    /// stage moving obstacles, and just below the friction threshold its block creeps 5–22 times the
    /// mollifier's bound where IPC's keeps it (docs/16_contact_solvers.md#the-goals-of-issue-49).
    /// docs/scenes.md#the-contact-solver
    std::string solver = "ipc";
};

/// A whole scene, as read from its file.
struct SceneSpec {
    std::filesystem::path file;
    std::string title;
    std::vector<BodySpec> bodies;
    Eigen::Vector3d gravity{0.0, 0.0, -9.81};
    double time_step = 1.0 / 60.0;      ///< Δt [s] ("1/60" allowed in the file)
    double duration = 1.0;              ///< [s], a whole number of steps
    std::string integrator = "backward-euler";
    std::string solver = "default";     ///< chapter 09's solver name
    double newton_tolerance = 1e-6;     ///< chapter 12's relative tolerance
    AutoThresholds thresholds;
    OutputSpec output;
    std::optional<SkinSpec> skin;
    std::vector<ObstacleSpec> obstacles;  ///< none: the bodies float in empty space (no contact)
    ContactSpec contact;
};

/// The deepest nesting a scene file (or a --set value) may have: tables of headers and dotted
/// keys, arrays and inline tables together. Deeper text is refused before it is parsed.
constexpr int max_nesting = 32;

/// The largest scene file read [bytes].
constexpr long long max_scene_bytes = 16ll << 20;

/// A body's size (its bounding box's longest edge) [m]: from a micrometre to a thousand kilometres.
/// Beyond, volumes (products of three edges) and stiffnesses (divided by their squares) leave the
/// range where a double keeps its digits. docs/scenes.md#limits
constexpr double smallest_body_extent = 1e-6, largest_body_extent = 1e6;
/// The stiffest material a scene may have [Pa]: a thousand diamonds (1.2e12 Pa). Beyond, the Lamé
/// parameters near ν = ½ and the stresses of large strains overflow. docs/scenes.md#limits
constexpr double largest_youngs_modulus = 1e15;

/// What reading a scene may do and use; the defaults are those of a run.
struct ReadLimits {
    bool tetgen = true;             ///< tetrahedralise a surface mesh file with TetGen (else an error)
    TetgenLimits tetgen_limits;     ///< TetGen's time and memory
    /// The memory a run of the scene may need [bytes] (see memory_estimate); 0: the memory the
    /// machine has available now (and the process's address-space limit, if lower).
    std::size_t memory = 0;
    /// The most winding-number terms (cubes × surface triangles) a mesh.lattice may cost: each
    /// cube of the surface's bounding box is tested against every triangle (chapter 13).
    double lattice_work = 5e9;
};

/// Reads and checks a scene file: first the [quick] table's overrides when quick is set, then
/// each "key=value" of overrides (the --set options; value in TOML syntax, or else a string),
/// then every field. Builds every body's mesh (TetGen for a surface file) and selects its pinned
/// vertices. fem::Error naming the file, line and column, the field and what is allowed, for a
/// missing or unreadable file, a file over max_scene_bytes or nested deeper than max_nesting, a
/// syntax error, an unknown field, a wrong type or value, a mesh without tets, a selection that
/// selects nothing, a surface TetGen cannot tetrahedralise (within limits), or a scene that needs
/// more memory than limits allow (naming the field to change). docs/scenes.md#the-scene-file
SceneSpec read_scene(const std::filesystem::path& path, const std::vector<std::string>& overrides = {},
                     bool quick = false, const ReadLimits& limits = {});

/// What a run of one body needs: its unknowns, the entries of its Cholesky factor, and the memory
/// of the mesh, the matrices, the per-tet data of every model and the factor together.
struct MemoryEstimate {
    long long dofs = 0;           ///< 3 per vertex
    double factor_nonzeros = 0;   ///< entries of the Cholesky factor (a nested-dissection fill estimate)
    double bytes = 0;             ///< the whole run [bytes]
};

/// The memory a run of a body of this many vertices and tets needs (an estimate that errs high):
/// read_scene refuses a scene whose bodies together need more than ReadLimits::memory, before it
/// builds a box mesh and after it reads a file mesh. docs/scenes.md#limits
MemoryEstimate memory_estimate(long long vertices, long long tets);

/// The files a scene reads: the scene file, its bodies' mesh files (a TetGen pair's .node and
/// .ele) and its skin. fem_scene refuses an --out that overlaps one (common/cli.hpp).
std::vector<std::filesystem::path> input_files(const SceneSpec& scene);

/// Chapter 10's Scene of one body of a scene: its mesh, material, pinned vertices, damping and mass,
/// the scene's gravity, Δt and duration.
dynamics::Scene dynamics_scene(const SceneSpec& scene, const BodySpec& body);

/// Whether the scene has bodies that meet: [contact] bodies with two or more bodies, or a body with
/// self_contact (what friction between bodies and the path check need). docs/scenes.md#bodies-against-bodies
bool bodies_meet(const SceneSpec& scene);

/// Whether any step of the scene may need contact: it has obstacles, [contact] bodies with two or
/// more bodies, or a body with self_contact. docs/scenes.md#bodies-against-bodies
bool has_contact(const SceneSpec& scene);

/// The type names of [[obstacle]], in the order the scene reader lists them ("half-space",
/// "sphere", "box", "mesh", …): the registry in solutions/scenes/scene_obstacles.cpp, one entry a
/// type, its own fields and how they are read, checked and built. docs/scenes.md#obstacles
std::vector<std::string> obstacle_types();

/// The names [contact] solver allows: "ipc", "augmented_lagrangian" (ContactSpec::solver).
/// docs/scenes.md#the-contact-solver
std::vector<std::string> contact_solvers();

/// The vertices of mesh a selector selects, ascending. fem::Error (naming selector.where) if none.
std::vector<int> select_vertices(const TetMesh& mesh, const Selector& selector);

/// The prescribed displacement g(X, t) of a rest position X under a motion at time t [m].
Eigen::Vector3d prescribed_displacement(const Motion& motion, const Eigen::Vector3d& X, double t);


}  // namespace fem::scenes
