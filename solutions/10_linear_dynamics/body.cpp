#include "10_linear_dynamics/body.hpp"

#include "04_tet_jacobians/tet_jacobians.hpp"

#include "common/error.hpp"
#include "common/parallel.hpp"
#include "common/vtk_io.hpp"

#include <algorithm>
#include <utility>
#include <cmath>
#include <iomanip>

namespace fem::dynamics {

void validate(const Scene& scene)
{
    TetMesh mesh = scene.mesh;
    fem::validate(mesh, "scene mesh", Inverted::reject);
    const Material& m = scene.material;
    require_positive(m.youngs_modulus, "Young's modulus Y [Pa]");
    if (!(m.poisson_ratio > -1.0 && m.poisson_ratio <= highest_poisson_ratio))
        throw Error(str(std::setprecision(15), "Poisson's ratio must lie in (-1, ", highest_poisson_ratio, "] (lambda/mu at most ",
                        largest_lame_ratio, ": nearer 0.5 the stiffness's condition number leaves a double no "
                        "digits, and 0.5 is incompressible, which linear tets cannot model), got ",
                        m.poisson_ratio));
    require_positive(m.density, "density rho [kg/m^3]");
    if (!scene.densities.empty()) {
        if (scene.densities.size() != static_cast<std::size_t>(mesh.T.rows()))
            throw Error(str("densities has ", scene.densities.size(), " entries, expected one per tet (", mesh.T.rows(), ")"));
        for (double density : scene.densities)
            require_positive(density, "a tet's density rho [kg/m^3]");
    }
    for (int c = 0; c < 3; ++c)
        require_finite(scene.gravity[c], "gravity g [m/s^2]");
    for (const auto& [value, name] : {std::pair{scene.damping.alpha, "Rayleigh alpha"},
                                      std::pair{scene.damping.beta, "Rayleigh beta"}})
        if (!(value >= 0.0 && value <= assembly::max_rayleigh_coefficient))
            throw Error(str(name, " must lie in [0, ", assembly::max_rayleigh_coefficient,
                            "] (the lecture's range), got ", value));
    step_count(scene.duration, scene.time_step);
    const auto vertices = static_cast<int>(mesh.V.rows());
    std::vector<int> sorted = scene.pinned;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t i = 0; i < sorted.size(); ++i) {
        if (sorted[i] < 0 || sorted[i] >= vertices)
            throw Error(str("pinned vertex ", sorted[i], " is outside the mesh's vertices [0, ", vertices, ")"));
        if (i > 0 && sorted[i] == sorted[i - 1])
            throw Error(str("pinned vertex ", sorted[i], " is listed twice"));
    }
    if (vertices > 0 && sorted.size() == static_cast<std::size_t>(vertices))
        throw Error(str("every one of the mesh's ", vertices, " vertices is pinned: nothing is left to move"));
}

int step_count(double duration, double time_step)
{
    require_positive(time_step, "time step dt [s]");
    if (!(std::isfinite(duration) && duration >= 0.0))
        throw Error(str("duration must be a finite number >= 0 [s], got ", duration));
    const double steps = duration / time_step;
    const double whole = std::round(steps);
    if (std::abs(steps - whole) > 1e-9 * std::max(1.0, steps))
        throw Error(str("duration ", duration, " s is not a whole number of steps of dt = ", time_step, " s (",
                        steps, " steps): choose a duration that is a multiple of dt"));
    if (whole > 1e9)
        throw Error(str("duration / dt = ", whole, " steps: more than 1e9 steps is not a run to start"));
    return static_cast<int>(whole);
}

// --- LinearElasticity --------------------------------------------------------------------------

LinearElasticity::LinearElasticity(const TetMesh& mesh, const Material& material)
    : mesh_(mesh), lame_(elastic::lame_parameters(material.youngs_modulus, material.poisson_ratio)),
      K_(assembly::stiffness_matrix(mesh, lame_))
{
}

double LinearElasticity::evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& forces)
{
    if (u.size() != K_.rows())
        throw Error(str("displacement has ", u.size(), " entries, expected 3n = ", K_.rows()));
    forces = -symmetric_times(K_, u);
    return -0.5 * u.dot(forces);
}

Eigen::VectorXd LinearElasticity::von_mises_stress(const Eigen::VectorXd& u) const
{
    if (u.size() != K_.rows())
        throw Error(str("displacement has ", u.size(), " entries, expected 3n = ", K_.rows()));
    const elastic::Matrix6d C = elastic::elasticity_matrix(lame_);
    Eigen::VectorXd stress(mesh_.T.rows());
    for (Eigen::Index t = 0; t < mesh_.T.rows(); ++t) {
        tet::TetVertices X;
        Eigen::Matrix<double, 12, 1> u_e;
        for (int i = 0; i < 4; ++i) {
            X.row(i) = mesh_.V.row(mesh_.T(t, i));
            u_e.segment<3>(3 * i) = u.segment<3>(3 * mesh_.T(t, i));
        }
        stress[t] = elastic::von_mises(C * (elastic::strain_displacement_matrix(X) * u_e));
    }
    return stress;
}

// --- FreeDofs ----------------------------------------------------------------------------------

FreeDofs::FreeDofs(int vertex_count, const std::vector<int>& pinned_vertices)
    : full_size_(3 * static_cast<Eigen::Index>(vertex_count)),
      P_(assembly::free_selection_matrix(vertex_count, pinned_vertices)),
      mask_(Eigen::VectorXd::Ones(3 * static_cast<Eigen::Index>(vertex_count)))
{
    for (int v : pinned_vertices)
        mask_.segment<3>(3 * v).setZero();
    free_.reserve(static_cast<std::size_t>(P_.cols()));
    for (Eigen::Index dof = 0; dof < full_size_; ++dof)
        if (mask_[dof] != 0.0)
            free_.push_back(static_cast<int>(dof));
}

Eigen::VectorXd FreeDofs::gather(const Eigen::VectorXd& full) const
{
    if (full.size() != full_size_)
        throw Error(str("a full vector has 3n = ", full_size_, " entries, got ", full.size()));
    Eigen::VectorXd free(size());
    for (Eigen::Index i = 0; i < size(); ++i)
        free[i] = full[free_[static_cast<std::size_t>(i)]];
    return free;
}

void FreeDofs::scatter(const Eigen::VectorXd& free, Eigen::VectorXd& full) const
{
    if (free.size() != size() || full.size() != full_size_)
        throw Error(str("scatter: expected ", size(), " free and ", full_size_, " full entries, got ", free.size(),
                        " and ", full.size()));
    for (Eigen::Index i = 0; i < size(); ++i)
        full[free_[static_cast<std::size_t>(i)]] = free[i];
}

SparseMatrix FreeDofs::reduce(const SparseMatrix& A) const
{
    // Pᵀ A P (chapter 06's reduce) by selection: keep the columns of free dofs and, in them, the
    // rows of free dofs, renumbered. One pass over A, no sparse products: a changing step matrix
    // (chapters 11 and 12) is reduced every step.
    if (A.rows() != full_size_ || A.cols() != full_size_)
        throw Error(str("reduce: A must be ", full_size_, "x", full_size_, ", got ", A.rows(), "x", A.cols()));
    std::vector<int> renumbered(static_cast<std::size_t>(full_size_), -1);
    for (std::size_t i = 0; i < free_.size(); ++i)
        renumbered[static_cast<std::size_t>(free_[i])] = static_cast<int>(i);
    SparseMatrix reduced(size(), size());
    reduced.reserve(A.nonZeros());
    for (Eigen::Index column = 0; column < size(); ++column) {
        reduced.startVec(column);
        for (SparseMatrix::InnerIterator it(A, free_[static_cast<std::size_t>(column)]); it; ++it)
            if (const int row = renumbered[static_cast<std::size_t>(it.row())]; row >= 0)
                reduced.insertBack(row, column) = it.value();
    }
    reduced.finalize();
    return reduced;
}

SparseMatrix FreeDofs::project(const SparseMatrix& A) const
{
    if (A.rows() != full_size_ || A.cols() != full_size_)
        throw Error(str("project: A must be ", full_size_, "x", full_size_, ", got ", A.rows(), "x", A.cols()));
    SparseMatrix projected = A;
    for (Eigen::Index col = 0; col < projected.outerSize(); ++col)
        for (SparseMatrix::InnerIterator it(projected, col); it; ++it) {
            const bool pinned_row = mask_[it.row()] == 0.0, pinned_col = mask_[it.col()] == 0.0;
            if (pinned_row || pinned_col)
                it.valueRef() = it.row() == it.col() ? 1.0 : 0.0;
        }
    projected.prune(0.0);  // the zeroed couplings go; the unit diagonal of a pinned dof stays
    return projected;
}

// --- Body ------------------------------------------------------------------------------------

namespace {

const Scene& validated(const Scene& scene)
{
    validate(scene);
    return scene;
}

}  // namespace

namespace {

/// The mesh's tets of each density: (ρ, the mesh with only those tets, every vertex kept), one
/// entry per distinct value of Scene::densities, or (material.density, the mesh) without them.
std::vector<std::pair<double, TetMesh>> tets_by_density(const Scene& scene)
{
    if (scene.densities.empty())
        return {{scene.material.density, scene.mesh}};
    std::vector<double> values = scene.densities;
    std::sort(values.begin(), values.end());
    values.erase(std::unique(values.begin(), values.end()), values.end());
    std::vector<std::pair<double, TetMesh>> parts;
    for (double density : values) {
        std::vector<Eigen::Index> rows;
        for (Eigen::Index t = 0; t < scene.mesh.T.rows(); ++t)
            if (scene.densities[static_cast<std::size_t>(t)] == density)
                rows.push_back(t);
        TetMesh part;
        part.V = scene.mesh.V;
        part.T = scene.mesh.T(rows, Eigen::all);
        parts.emplace_back(density, std::move(part));
    }
    return parts;
}

}  // namespace

Body::Body(const Scene& scene, std::unique_ptr<ForceModel> model)
    : scene_(validated(scene)),
      model_(model ? std::move(model) : std::make_unique<LinearElasticity>(scene.mesh, scene.material)),
      dofs_(static_cast<int>(scene.mesh.V.rows()), scene.pinned)
{
    const Eigen::Index n = scene.mesh.V.rows();
    M_.resize(3 * n, 3 * n);
    Eigen::VectorXd masses = Eigen::VectorXd::Zero(n);
    gravity_load_ = Eigen::VectorXd::Zero(3 * n);
    for (const auto& [density, tets] : tets_by_density(scene)) {
        M_ += scene.mass == MassModel::lumped ? assembly::lumped_mass_matrix(tets, density)
                                              : assembly::consistent_mass_matrix(tets, density);
        masses += assembly::vertex_masses(tets, density);
        gravity_load_ += assembly::gravity_load(tets, density, scene.gravity);
    }
    M_.makeCompressed();
    dof_masses_.resize(3 * masses.size());
    for (Eigen::Index v = 0; v < masses.size(); ++v)
        dof_masses_.segment<3>(3 * v).setConstant(masses[v]);
    f_ext_ = gravity_load_;
    applied_ = Eigen::VectorXd::Zero(f_ext_.size());
    pin_velocity_ = Eigen::VectorXd::Zero(f_ext_.size());
}

void Body::set_time_step(double time_step)
{
    step_count(scene_.duration, time_step);
    scene_.time_step = time_step;
}

namespace {

/// fem::Error unless x has n entries, all finite (what: the quantity, for the message).
void require_finite_dofs(const Eigen::VectorXd& x, Eigen::Index n, const char* what)
{
    if (x.size() != n)
        throw Error(str(what, " has ", x.size(), " entries, expected 3n = ", n));
    for (Eigen::Index i = 0; i < n; ++i)
        if (!std::isfinite(x[i]))
            throw Error(str(what, " has the non-finite value ", x[i], " at dof ", i, " (vertex ", i / 3, ")"));
}

}  // namespace

void Body::set_applied_loads(const Eigen::VectorXd& loads)
{
    if (loads.size() == 0) {
        applied_.setZero();
    } else {
        require_finite_dofs(loads, dofs_.full_size(), "the applied loads");
        applied_ = loads;
    }
    f_ext_ = gravity_load_ + applied_;
}

void Body::set_pin_velocity(const Eigen::VectorXd& velocity)
{
    if (velocity.size() == 0) {
        pin_velocity_.setZero();
        pins_move_ = false;
        return;
    }
    require_finite_dofs(velocity, dofs_.full_size(), "the pin velocity");
    const Eigen::VectorXd& free = dofs_.free_mask();
    for (Eigen::Index i = 0; i < velocity.size(); ++i)
        if (free[i] != 0.0 && velocity[i] != 0.0)
            throw Error(str("the pin velocity is ", velocity[i], " at dof ", i, " of vertex ", i / 3,
                            ", which is not pinned; only pinned dofs have a prescribed velocity"));
    pin_velocity_ = velocity;
    pins_move_ = velocity.cwiseAbs().maxCoeff() > 0.0;
}

MatrixX3d Body::positions(const Eigen::VectorXd& u) const
{
    return scene_.mesh.V + io::vertex_rows(u);
}

double Energies::magnitude() const
{
    return kinetic + elastic + std::abs(gravitational);
}

double kinetic_energy(const SparseMatrix& M, const Eigen::VectorXd& v)
{
    if (M.rows() != v.size() || M.cols() != v.size())
        throw Error(str("kinetic energy: M is ", M.rows(), "x", M.cols(), " but v has ", v.size(), " entries"));
    return 0.5 * v.dot(M * v);
}

Eigen::VectorXd symmetric_times(const SparseMatrix& A, const Eigen::VectorXd& x)
{
    if (A.rows() != A.cols() || A.cols() != x.size())
        throw Error(str("symmetric product: A is ", A.rows(), "x", A.cols(), " but x has ", x.size(), " entries"));
    Eigen::VectorXd y(x.size());
    const int* outer = A.outerIndexPtr();
    const int* nonzeros = A.innerNonZeroPtr();  // null when A is compressed
    const int* inner = A.innerIndexPtr();
    const double* values = A.valuePtr();
    parallel_for(A.cols(), [&](Eigen::Index i) {
        const int first = outer[i], last = nonzeros == nullptr ? outer[i + 1] : first + nonzeros[i];
        double sum = 0.0;
        for (int k = first; k < last; ++k)
            sum += values[k] * x[inner[k]];
        y[i] = sum;
    });
    return y;
}

double load_potential(const Eigen::VectorXd& f_ext, const Eigen::VectorXd& u)
{
    if (f_ext.size() != u.size())
        throw Error(str("load potential: f_ext has ", f_ext.size(), " entries but u has ", u.size()));
    return -f_ext.dot(u);
}

Scene cantilever_scene(const Material& material, int cells_along, double duration)
{
    Scene scene;
    scene.mesh = beam_mesh(0.2, 0.02, 0.02, cells_along);
    scene.material = material;
    scene.pinned = assembly::vertices_on_plane(scene.mesh, 0, 0.0);
    scene.gravity = Eigen::Vector3d(0.0, 0.0, -9.81);
    scene.time_step = 1.0 / 60.0;
    scene.duration = duration;
    return scene;
}

Scene standing_scene(TetMesh mesh, const Material& material, double ground, double duration)
{
    Scene scene;
    scene.mesh = std::move(mesh);
    scene.material = material;
    for (Eigen::Index v = 0; v < scene.mesh.V.rows(); ++v)
        if (scene.mesh.V(v, 1) <= ground)
            scene.pinned.push_back(static_cast<int>(v));
    scene.gravity = Eigen::Vector3d(0.0, -9.81, 0.0);
    scene.time_step = 1.0 / 60.0;
    scene.duration = duration;
    return scene;
}

Eigen::VectorXd sideways_push(const Scene& scene, double low, double high, double top_speed)
{
    if (!(high > low))
        throw Error(str("sideways_push: the top ", high, " must lie above the bottom ", low));
    Eigen::VectorXd push = Eigen::VectorXd::Zero(3 * scene.mesh.V.rows());
    for (Eigen::Index v = 0; v < scene.mesh.V.rows(); ++v)
        push[3 * v] = top_speed * (scene.mesh.V(v, 1) - low) / (high - low);
    for (int v : scene.pinned)
        push[3 * v] = 0.0;
    return push;
}

int far_corner(const TetMesh& mesh)
{
    Eigen::Index corner = 0;
    mesh.V.rowwise().sum().maxCoeff(&corner);
    return static_cast<int>(corner);
}

}  // namespace fem::dynamics
