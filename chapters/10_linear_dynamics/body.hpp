#pragma once
// Chapter 10: a scene, the body it builds, and the force model the body moves under.
// docs/10_linear_dynamics.md
//
// The lecture's dynamic equation, written in the displacement u = x − x₀ (3n entries, vertex-major
// like every global vector of the course):
//     M ü + D u̇ + K u = f_ext,      D = α M + β K (Rayleigh),      f_ext = the gravity load.
// Pinned vertices keep u = 0; their dofs are removed from the unknowns (FreeDofs, chapter 06's P).
//
// The pieces chapters 11–13 reuse (docs/10_linear_dynamics.md#the-pieces-of-a-simulation):
//   Scene       plain data: mesh, material, pinned vertices, gravity, damping, mass model, Δt and
//               duration; validate() checks all of it once;
//   ForceModel  the elastic energy U(u), the internal forces f(u) = −∂U/∂u and the tangent
//               stiffness K(u) = ∂²U/∂u²; LinearElasticity is this chapter's (K constant), chapter 11
//               adds the corotational one, chapter 12 the hyperelastic ones;
//   Body        what a scene assembles once: M, f_ext, the free dofs, and its force model.
// The integrators and the time loop that move a Body are in time_integration.hpp.

#include "05_strain_stress/strain_stress.hpp"
#include "06_assembly/assembly.hpp"

#include "common/mesh.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <string>
#include <vector>

namespace fem::dynamics {

using SparseMatrix = Eigen::SparseMatrix<double>;

/// An isotropic elastic material with a density. Defaults: rubber.
struct Material {
    double youngs_modulus = 1e5;  ///< Y [Pa], finite and > 0
    double poisson_ratio = 0.45;  ///< ν, in (−1, 0.5)
    double density = 1000.0;      ///< ρ [kg/m³], finite and > 0
};

/// Which mass matrix the body uses (chapter 06): the lumped diagonal m_v = Σ ¼ ρ V_t (default:
/// cheap, and the explicit step needs no solve) or the consistent ρ ∫ Φᵀ Φ dV.
enum class MassModel { lumped, consistent };

/// Rayleigh damping D = α M + β K: α [1/s] damps slow motion, β [s] fast motion. For a mode of
/// angular frequency ω the damping ratio is ξ = α/(2ω) + β ω/2. Both in [0, 0.02], the lecture's
/// range (chapter 06's rayleigh_damping checks it).
struct Damping {
    double alpha = 0.0;
    double beta = 0.0;
};

/// A simulation scene: plain data, checked once by validate(). docs/10_linear_dynamics.md#scenes
struct Scene {
    TetMesh mesh;                                ///< rest positions x₀ = mesh.V and tets mesh.T
    Material material;
    std::vector<int> pinned;                     ///< vertices held at their rest position
    Eigen::Vector3d gravity{0.0, 0.0, -9.81};    ///< g [m/s²]; the load is f_v = m_v g
    Damping damping;
    MassModel mass = MassModel::lumped;
    double time_step = 1.0 / 60.0;               ///< Δt [s], finite and > 0
    double duration = 1.0;                       ///< [s], a whole number of steps (see step_count)
    /// ρ_t per tet [kg/m³] (#T entries) for a body of several materials (the scenes runner's bodies
    /// joined into one solve, each with its own density); empty: material.density for every tet.
    std::vector<double> densities;
};

/// The materials the chapters' command lines accept (--youngs, --density): the real solids, from
/// gels (about 10 Pa) to diamond (1.2e12 Pa) and from aerogels (about 1 kg/m³) to osmium (22,590
/// kg/m³), with a margin. validate() itself takes any finite positive value; far outside these
/// ranges the matrices' entries leave the range where their products stay normal doubles (Y = 1e-300
/// failed inside the eigensolver, Y = 1e300 as a zero frequency). docs/10_linear_dynamics.md#scenes
constexpr double lowest_youngs_modulus = 1e-2, highest_youngs_modulus = 1e13;  // [Pa]
constexpr double lowest_density = 1e-2, highest_density = 1e6;                // [kg/m³]

/// The largest Poisson's ratio a body may have: λ/μ = 2ν/(1 − 2ν) ≤ 1e8, i.e. ν ≤ 0.499999995
/// ≈ 0.499999995. The condition number of the stiffness grows like λ/μ (times the mesh's own (L/h)²),
/// and a double has 16 digits: at λ/μ = 1e8 a solve keeps about 8 before the mesh's factor; the sparse
/// Cholesky of a 4×4×4-cell cube broke down (a pivot below n ε |a_jj|) at λ/μ ≈ 5e13. Long before, linear
/// tets lock (they cannot bend without changing volume), so the bound takes away no physics. Below it,
/// Newton may need a smaller Δt (its error says so): the hanging cube converges at ν = 0.49999999 with
/// Δt = 1/600 s. docs/scenes.md#limits
constexpr double largest_lame_ratio = 1e8;
constexpr double highest_poisson_ratio = 0.499999995;  // λ/μ = 2ν/(1 − 2ν) = 1e8 (to 1e-8)

/// fem::Error, naming the field and what is allowed, unless: the mesh is valid (indices, no
/// zero-volume or inverted tet: fem::validate with Inverted::reject), Y > 0, −1 < ν ≤ highest_poisson_ratio, ρ > 0,
/// g finite, 0 ≤ α, β ≤ 0.02, Δt > 0, duration ≥ 0 and a whole number of steps, and every pinned
/// vertex lies in [0, #V) and is listed once, and some vertex is free; densities, when given, has one
/// finite value > 0 per tet. Nothing pinned is allowed
/// (the body falls freely).
/// docs/10_linear_dynamics.md#scenes
void validate(const Scene& scene);

/// Chapter 10's cantilever: 0.2 × 0.02 × 0.02 m along x (beam_mesh with cells_along cubes along
/// it), clamped at x = 0, under gravity −z, undamped, Δt = 1/60 s, lasting `duration` [s]. Chapters
/// 11 and 12 swing a softer one. docs/10_linear_dynamics.md#scenes
Scene cantilever_scene(const Material& material, int cells_along, double duration = 1.0);

/// A body standing on the ground: the mesh as given, every vertex with y ≤ ground pinned, gravity
/// −y (y up), undamped, Δt = 1/60 s, lasting `duration` [s]. Chapter 10's rubber bunny stands on the
/// lowest 5 % of its height; chapter 13 stands a coarse and a fine mesh of it on the same ground.
/// docs/10_linear_dynamics.md#scenes
Scene standing_scene(TetMesh mesh, const Material& material, double ground, double duration = 1.0);

/// A sideways push growing with height: v_x = top_speed · (y − low)/(high − low) at every vertex
/// that is not pinned, zero elsewhere (3n, vertex-major): an initial velocity for initial_state.
/// fem::Error unless high > low.
Eigen::VectorXd sideways_push(const Scene& scene, double low, double high, double top_speed);

/// The vertex with the largest x + y + z: a box's far top corner (a cantilever's tip).
int far_corner(const TetMesh& mesh);

/// The number of steps that cover `duration`: duration / Δt when that is a whole number to within
/// 1e-9 relative (1.0 / (1/60) = 60), fem::Error otherwise (e.g. 1.05 s at Δt = 0.1 s: "10.5
/// steps"), never a silently shortened or lengthened run. fem::Error for Δt ≤ 0 or duration < 0.
int step_count(double duration, double time_step);

// --- Force models ----------------------------------------------------------------------------

/// The elastic response of a body: energy, forces and stiffness at a displacement u (3n).
/// Chapters 11 and 12 add their models; the integrators only see this interface.
/// docs/10_linear_dynamics.md#force-models
class ForceModel {
public:
    virtual ~ForceModel() = default;

    /// A short name for tables, e.g. "linear".
    virtual std::string name() const = 0;

    /// The elastic energy U(u) [J]; writes the internal forces f(u) = −∂U/∂u (3n) into forces
    /// (resized). One call per step: the time loop keeps both for the next step and the energies.
    virtual double evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& forces) = 0;

    /// U(u) alone, for a line search (chapter 12); +∞ where the model is undefined. The default
    /// calls evaluate; a model that can skip the forces overrides it.
    virtual double energy(const Eigen::VectorXd& u)
    {
        Eigen::VectorXd forces;
        return evaluate(u, forces);
    }

    /// The tangent stiffness K(u) = ∂²U/∂u² = −∂f/∂u (3n×3n, both triangles stored).
    virtual const SparseMatrix& stiffness(const Eigen::VectorXd& u) = 0;

    /// A positive semi-definite stand-in for K(u), for a Newton step whose K(u) is indefinite
    /// (chapter 12 projects its element Hessians). The default: stiffness(u), for models whose K
    /// is never indefinite.
    virtual const SparseMatrix& definite_stiffness(const Eigen::VectorXd& u) { return stiffness(u); }

    /// True when K does not depend on u (linear elasticity): an implicit step then factors its
    /// matrix once for the whole run.
    virtual bool constant_stiffness() const = 0;

    /// The von Mises stress of every tet at u (#T entries) [Pa], for the frames.
    virtual Eigen::VectorXd von_mises_stress(const Eigen::VectorXd& u) const = 0;
};

/// Linear elasticity (chapters 05–06): U(u) = ½ uᵀ K u, f(u) = −K u, K assembled once from the rest
/// shape. evaluate() costs one sparse product. docs/10_linear_dynamics.md#force-models
class LinearElasticity final : public ForceModel {
public:
    /// K = assembly::stiffness_matrix(mesh, Lamé(Y, ν)). fem::Error as that function.
    LinearElasticity(const TetMesh& mesh, const Material& material);

    /// Its name, as tables and chapter 12's registry of models by name (force_models.hpp) write it.
    static constexpr const char* model_name = "linear";
    std::string name() const override { return model_name; }
    double evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& forces) override;
    const SparseMatrix& stiffness(const Eigen::VectorXd&) override { return K_; }
    bool constant_stiffness() const override { return true; }
    /// σ = C B_e u_e per tet (chapter 05), then von Mises.
    Eigen::VectorXd von_mises_stress(const Eigen::VectorXd& u) const override;

    const SparseMatrix& K() const { return K_; }

private:
    TetMesh mesh_;
    elastic::Lame lame_;
    SparseMatrix K_;
};

// --- Free dofs -------------------------------------------------------------------------------

/// The free degrees of freedom: every dof 3v + c whose vertex v is not pinned, ascending. The
/// reduced unknowns are u_f = Pᵀ u and u = P u_f with P = assembly::free_selection_matrix; gather and
/// scatter do the same by index, without a product. docs/10_linear_dynamics.md#pinned-vertices
class FreeDofs {
public:
    /// fem::Error for a pinned index outside [0, vertex_count) or listed twice.
    FreeDofs(int vertex_count, const std::vector<int>& pinned_vertices);

    Eigen::Index size() const { return static_cast<Eigen::Index>(free_.size()); }  ///< 3n − 3·#pinned
    Eigen::Index full_size() const { return full_size_; }                          ///< 3n
    const std::vector<int>& indices() const { return free_; }
    /// P (3n × size()), chapter 06's selection matrix.
    const SparseMatrix& P() const { return P_; }
    /// The diagonal projection of the kept-dofs route: 1 on free dofs, 0 on pinned ones (3n).
    const Eigen::VectorXd& free_mask() const { return mask_; }

    /// u_f = Pᵀ u (size()). fem::Error if u has not full_size() entries.
    Eigen::VectorXd gather(const Eigen::VectorXd& full) const;
    /// u(free dofs) = u_f, other entries untouched. fem::Error on sizes.
    void scatter(const Eigen::VectorXd& free, Eigen::VectorXd& full) const;
    /// A_ff = Pᵀ A P (size() × size()).
    SparseMatrix reduce(const SparseMatrix& A) const;
    /// The kept-dofs alternative: P̂ A P̂ + (I − P̂) with P̂ = diag(free_mask()) (3n×3n): the rows and
    /// columns of pinned dofs replaced by those of the identity. Solving it with a right-hand side
    /// that is zero on the pinned dofs gives the same free values as A_ff and zeros elsewhere.
    SparseMatrix project(const SparseMatrix& A) const;

private:
    Eigen::Index full_size_ = 0;
    std::vector<int> free_;
    SparseMatrix P_;
    Eigen::VectorXd mask_;
};

// --- The body --------------------------------------------------------------------------------

/// What a scene assembles once: the mass matrix, the gravity load, the free dofs and the force
/// model. Integrators read it. Two things may change between steps, set by a step hook
/// (Simulation::set_before_step) for scenes whose boundary conditions move: the applied loads
/// (f_ext = gravity load + applied loads) and the velocity of the pinned vertices over the next step.
/// docs/10_linear_dynamics.md#the-step-hook
class Body {
public:
    /// validate(scene), then M (lumped or consistent, chapter 06), f_ext = gravity_load and the
    /// free dofs; with Scene::densities, each summed over the tets of each density (block diagonal
    /// for bodies that share no vertex). model: the force model (default: LinearElasticity of the scene's mesh and material).
    explicit Body(const Scene& scene, std::unique_ptr<ForceModel> model = nullptr);

    const Scene& scene() const { return scene_; }
    const TetMesh& mesh() const { return scene_.mesh; }

    /// Δt [s] of every step taken on this body: the scene's, the one place it lives (Simulation
    /// reads it here at each step).
    double time_step() const { return scene_.time_step; }
    /// Changes Δt, for a study that sweeps it on one body (M, the loads and the model do not depend
    /// on it). fem::Error unless Δt is finite and > 0 and the scene's duration is a whole number of
    /// steps of it (step_count).
    void set_time_step(double time_step);
    ForceModel& model() { return *model_; }
    const ForceModel& model() const { return *model_; }
    const FreeDofs& dofs() const { return dofs_; }

    /// M (3n×3n): diagonal for the lumped model.
    const SparseMatrix& mass_matrix() const { return M_; }
    /// The lumped masses repeated per dof (3n): m_v at 3v, 3v+1, 3v+2 (also for consistent M,
    /// whose rows sum to them).
    const Eigen::VectorXd& dof_masses() const { return dof_masses_; }
    /// f_ext (3n): m_v g per vertex plus the applied loads (pinned vertices included: their entries
    /// do work only when the pins move, and that work is the pins' reactions', see StepInfo).
    const Eigen::VectorXd& external_forces() const { return f_ext_; }
    /// The gravity load m_v g per vertex (3n), constant.
    const Eigen::VectorXd& gravity_load() const { return gravity_load_; }

    /// Replaces the applied loads f_a (3n; empty: none): from now on f_ext = gravity_load() + f_a.
    /// fem::Error for a size other than 3n or a non-finite entry (naming the dof).
    void set_applied_loads(const Eigen::VectorXd& loads);
    /// The applied loads f_a (3n; zero unless set).
    const Eigen::VectorXd& applied_loads() const { return applied_; }

    /// Sets how the pinned vertices move over the next step: their mean velocity
    /// ṽ_p = (g(t + Δt) − u_p(t)) / Δt (3n; entries of free dofs must be 0; empty: pins at rest).
    /// An integrator then ends the step with u_p⁺ = u_p + Δt ṽ_p exactly, and its free dofs feel
    /// the pins' motion through the coupling of the step matrix. fem::Error for a size other than
    /// 3n, a non-finite entry or a non-zero entry on a free dof. docs/10_linear_dynamics.md#moving-pins
    void set_pin_velocity(const Eigen::VectorXd& velocity);
    /// ṽ_p (3n, zero on free dofs; all zero unless set).
    const Eigen::VectorXd& pin_velocity() const { return pin_velocity_; }
    /// True when some pinned dof has ṽ_p ≠ 0.
    bool pins_move() const { return pins_move_; }

    /// x = x₀ + u as #V×3 rows.
    MatrixX3d positions(const Eigen::VectorXd& u) const;

private:
    Scene scene_;
    std::unique_ptr<ForceModel> model_;
    FreeDofs dofs_;
    SparseMatrix M_;
    Eigen::VectorXd dof_masses_;
    Eigen::VectorXd gravity_load_, applied_, f_ext_;
    Eigen::VectorXd pin_velocity_;
    bool pins_move_ = false;
};

/// The energies of a state (u, v) of a body [J]:
///   kinetic T = ½ vᵀ M v,  elastic U(u) (from the force model),  gravitational W = −f_extᵀ u
///   (the potential of the constant load, zero at rest), total H = T + U + W.
/// For an undamped body the exact motion keeps H constant. docs/10_linear_dynamics.md#energy
struct Energies {
    double kinetic = 0.0;
    double elastic = 0.0;
    double gravitational = 0.0;
    double total() const { return kinetic + elastic + gravitational; }
    /// T + U + |W|: the size of the energies in play, the scale of the divergence check.
    double magnitude() const;
};

/// The kinetic energy ½ vᵀ M v (v: 3n, M: 3n×3n). fem::Error on sizes.
/// docs/10_linear_dynamics.md#energy
double kinetic_energy(const SparseMatrix& M, const Eigen::VectorXd& v);

/// y = A x for a symmetric sparse A stored whole (both triangles, column-major, n×n; x: n), on every
/// core, row by row: y_i = Σ_j A_ji x_j over column i of A (row i, A being symmetric), j ascending.
/// Each y_i is one thread's sum in a fixed order, so the bits do not depend on the number of
/// threads (they equal Eigen's serial A * x when A is exactly symmetric). fem::Error on sizes.
Eigen::VectorXd symmetric_times(const SparseMatrix& A, const Eigen::VectorXd& x);

/// The potential of a constant load, W = −f_extᵀ u (both 3n): the work the load did is −W.
/// docs/10_linear_dynamics.md#energy
double load_potential(const Eigen::VectorXd& f_ext, const Eigen::VectorXd& u);

}  // namespace fem::dynamics
