// Chapter 10: the time integrators and the time loop: the θ-method's step matrix and right-hand
// side (and its reduced, pattern-reusing step matrix), the implicit step, symplectic Euler, the
// energies, the integrators by name, the step hook and Simulation's loop.
// docs/10_linear_dynamics.md#the-implicit-step
#include "10_linear_dynamics/time_integration.hpp"

#include "common/error.hpp"
#include "common/timer.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace fem::dynamics {
namespace {

void require_theta(double theta)
{
    if (!(theta >= 0.5 && theta <= 1.0))
        throw Error(str("theta must lie in [0.5, 1] (0.5: implicit midpoint, 1: backward Euler), got ", theta));
}

void require_fits(const Body& body, const State& state)
{
    const Eigen::Index n = body.dofs().full_size();
    if (state.u.size() != n || state.v.size() != n || state.forces.size() != n)
        throw Error(str("the state does not fit the body: u, v and forces need 3n = ", n, " entries, got ",
                        state.u.size(), ", ", state.v.size(), " and ", state.forces.size()));
}

/// D x = α M x + β K x; Kx is K x when β ≠ 0 (else unused).
Eigen::VectorXd damping_times(const Body& body, const Eigen::VectorXd& x, const Eigen::VectorXd& Kx)
{
    const Damping& d = body.scene().damping;
    Eigen::VectorXd Dx = d.alpha * (body.mass_matrix() * x);
    if (d.beta != 0.0)
        Dx += d.beta * Kx;
    return Dx;
}

/// The velocity the pinned dofs end a θ-step with: v⁺_p = (ṽ_p − (1 − θ) v_p)/θ, so that
/// v_θ = θ v⁺ + (1 − θ) v is the body's pin velocity ṽ_p there (3n, zero on the free dofs).
Eigen::VectorXd pinned_velocity_next(const Body& body, const Eigen::VectorXd& v, double theta)
{
    const Eigen::VectorXd pinned = Eigen::VectorXd::Ones(v.size()) - body.dofs().free_mask();
    return ((body.pin_velocity() - (1.0 - theta) * v) / theta).cwiseProduct(pinned);
}

/// Overwrites the pinned entries of v_next with those of pinned_next (3n each).
void set_pinned(const Body& body, const Eigen::VectorXd& pinned_next, Eigen::VectorXd& v_next)
{
    const Eigen::VectorXd& free = body.dofs().free_mask();
    for (Eigen::Index i = 0; i < v_next.size(); ++i)
        if (free[i] == 0.0)
            v_next[i] = pinned_next[i];
}

/// The work of the pins' reactions over a step, ṽ_pᵀ R_p, where R = M (v⁺ − v) − Δt (f_θ + f_ext − D v_θ)
/// is Δt times the residual r of the step's momentum equation (zero on the free dofs up to the
/// solver's tolerance). momentum_change = M (v⁺ − v), net_force = f_θ + f_ext − D v_θ (3n each).
double boundary_work(const Body& body, const Eigen::VectorXd& momentum_change, const Eigen::VectorXd& net_force,
                     double time_step)
{
    if (!body.pins_move())
        return 0.0;
    const Eigen::VectorXd R = momentum_change - time_step * net_force;
    return body.pin_velocity().cwiseProduct(Eigen::VectorXd::Ones(R.size()) - body.dofs().free_mask()).dot(R);
}

}  // namespace

void commit_step(ForceModel& model, double time_step, Eigen::VectorXd u_next, Eigen::VectorXd v_next, State& state)
{
    Eigen::VectorXd forces;
    const double elastic = model.evaluate(u_next, forces);
    state.u = std::move(u_next);
    state.v = std::move(v_next);
    state.forces = std::move(forces);
    state.elastic_energy = elastic;
    state.time += time_step;
    state.step += 1;
}

io::MeshData body_frame(const Body& body, const State& state)
{
    io::MeshData data = io::displaced_mesh(body.mesh().V, body.mesh().T, io::vertex_rows(state.u));
    data.point_data.push_back({"velocity", io::vertex_rows(state.v)});
    data.cell_data.push_back({"von Mises stress", body.model().von_mises_stress(state.u)});
    return data;
}

State initial_state(Body& body, const Eigen::VectorXd& u0, const Eigen::VectorXd& v0)
{
    const Eigen::Index n = body.dofs().full_size();
    State state;
    state.u = u0.size() == 0 ? Eigen::VectorXd::Zero(n) : u0;
    state.v = v0.size() == 0 ? Eigen::VectorXd::Zero(n) : v0;
    for (const auto& [x, name] : {std::pair{&state.u, "initial displacement u0"}, std::pair{&state.v, "initial velocity v0"}}) {
        if (x->size() != n)
            throw Error(str(name, " has ", x->size(), " entries, expected 3n = ", n));
        for (Eigen::Index i = 0; i < n; ++i)
            if (!std::isfinite((*x)[i]))
                throw Error(str(name, " has the non-finite value ", (*x)[i], " at dof ", i));
    }
    state.elastic_energy = body.model().evaluate(state.u, state.forces);
    return state;
}

Energies energies(const Body& body, const State& state)
{
    Energies e;
    // BEGIN EXERCISE 10.3 energies #energy
    // HINT: The three energies of the state, in joules (docs/10_linear_dynamics.md#energy), into e.kinetic,
    // HINT: e.elastic and e.gravitational. Helpers: kinetic_energy(M, v) and load_potential(f_ext, u), with M and
    // HINT: f_ext on `body`. The elastic energy is not recomputed: the force model's U(u) is kept in the state.
    // HINT: The load potential is zero at rest and negative as the body sags.
    e.kinetic = kinetic_energy(body.mass_matrix(), state.v);
    e.elastic = state.elastic_energy;
    e.gravitational = load_potential(body.external_forces(), state.u);
    // END EXERCISE
    return e;
}

double theta_step_dissipation(const SparseMatrix& M, const SparseMatrix& K, const Eigen::VectorXd& u,
                              const Eigen::VectorXd& u_next, const Eigen::VectorXd& v, const Eigen::VectorXd& v_next,
                              double theta)
{
    require_theta(theta);
    const Eigen::Index n = M.rows();
    if (M.cols() != n || K.rows() != n || K.cols() != n || u.size() != n || u_next.size() != n || v.size() != n ||
        v_next.size() != n)
        throw Error(str("theta_step_dissipation: M (", M.rows(), "x", M.cols(), "), K (", K.rows(), "x", K.cols(),
                        "), u, u+, v, v+ (", u.size(), ", ", u_next.size(), ", ", v.size(), ", ", v_next.size(),
                        ") must be of one size"));
    double dissipated = 0.0;
    // BEGIN EXERCISE 10.10 theta_step_dissipation #energy
    // HINT: A derivation exercise: the energy H − H⁺ one θ-step takes out of an undamped, unloaded linear body by
    // HINT: itself, in `dissipated` (joules), written with M, K and the step's changes of u and v only. Derive it
    // HINT: as docs/10_linear_dynamics.md#energy does for backward Euler, from the θ-step's momentum equation.
    // HINT: Check: positive for θ > ½, zero for the midpoint rule.
    const Eigen::VectorXd du = u_next - u, dv = v_next - v;
    dissipated = (theta - 0.5) * (dv.dot(M * dv) + du.dot(K * du));
    // END EXERCISE
    return dissipated;
}

SparseMatrix step_matrix(const SparseMatrix& M, const SparseMatrix& K, const Damping& damping, double time_step,
                         double theta)
{
    require_positive(time_step, "time step dt [s]");
    require_theta(theta);
    if (M.rows() != K.rows() || M.cols() != K.cols() || M.rows() != M.cols())
        throw Error(str("step matrix: M (", M.rows(), "x", M.cols(), ") and K (", K.rows(), "x", K.cols(),
                        ") must be square and of one size"));
    // BEGIN EXERCISE 10.1 step_matrix #the-implicit-step
    // HINT: A is the matrix of the θ-step's linear system for v⁺ (docs/10_linear_dynamics.md#the-implicit-step),
    // HINT: with Rayleigh damping D = αM + βK (damping.alpha, damping.beta) folded in: one weighted sum of M and
    // HINT: K, returned as a new sparse matrix. Mind which powers of θ and Δt weight each part.
    const double h = theta * time_step;
    return (1.0 + h * damping.alpha) * M + (h * damping.beta + h * h) * K;
    // END EXERCISE
}

// --- ReducedStepMatrix --------------------------------------------------------------------------

ReducedStepMatrix::Pattern::Pattern(const SparseMatrix& A)
{
    if (!A.isCompressed())
        throw Error("ReducedStepMatrix: the matrices must be compressed");
    outer.assign(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1);
    inner.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
}

bool ReducedStepMatrix::Pattern::matches(const SparseMatrix& A) const
{
    return A.isCompressed() && static_cast<std::size_t>(A.outerSize()) + 1 == outer.size() &&
           static_cast<std::size_t>(A.nonZeros()) == inner.size() &&
           std::equal(outer.begin(), outer.end(), A.outerIndexPtr()) &&
           std::equal(inner.begin(), inner.end(), A.innerIndexPtr());
}

ReducedStepMatrix::ReducedStepMatrix(const SparseMatrix& M, const SparseMatrix& K, const FreeDofs& dofs)
    : M_pattern_(M), K_pattern_(K)
{
    const Eigen::Index n = dofs.full_size();
    if (M.rows() != n || M.cols() != n || K.rows() != n || K.cols() != n)
        throw Error(str("ReducedStepMatrix: M (", M.rows(), "x", M.cols(), ") and K (", K.rows(), "x", K.cols(),
                        ") must both be ", n, "x", n));
    // The pattern: reduce the pattern of M + K (ones, so that no entry cancels).
    SparseMatrix ones_M = M, ones_K = K;
    ones_M.coeffs().setOnes();
    ones_K.coeffs().setOnes();
    A_ = dofs.reduce(SparseMatrix(ones_M + ones_K));
    A_.makeCompressed();
    // Where each entry of M and K lands: column j of the input is free column renumbered[j], and
    // its row i lands in that column at row renumbered[i] (found by binary search once).
    std::vector<int> renumbered(static_cast<std::size_t>(n), -1);
    for (std::size_t f = 0; f < dofs.indices().size(); ++f)
        renumbered[static_cast<std::size_t>(dofs.indices()[f])] = static_cast<int>(f);
    const auto slots = [&](const SparseMatrix& B) {
        std::vector<int> slot(static_cast<std::size_t>(B.nonZeros()), -1);  // Eigen's own index type
        for (Eigen::Index j = 0; j < n; ++j) {
            const int column = renumbered[static_cast<std::size_t>(j)];
            if (column < 0)
                continue;
            const int* first = A_.innerIndexPtr() + A_.outerIndexPtr()[column];
            const int* last = A_.innerIndexPtr() + A_.outerIndexPtr()[column + 1];
            for (Eigen::Index k = B.outerIndexPtr()[j]; k < B.outerIndexPtr()[j + 1]; ++k)
                if (const int row = renumbered[static_cast<std::size_t>(B.innerIndexPtr()[k])]; row >= 0)
                    slot[static_cast<std::size_t>(k)] = static_cast<int>(std::lower_bound(first, last, row) - A_.innerIndexPtr());
        }
        return slot;
    };
    M_slot_ = slots(M);
    K_slot_ = slots(K);
}

bool ReducedStepMatrix::fits(const SparseMatrix& M, const SparseMatrix& K) const
{
    return M_pattern_.matches(M) && K_pattern_.matches(K);
}

const SparseMatrix& ReducedStepMatrix::assemble(const SparseMatrix& M, const SparseMatrix& K, double a, double k)
{
    if (!fits(M, K))
        throw Error("ReducedStepMatrix: M or K no longer has the pattern the step matrix was built for");
    double* values = A_.valuePtr();
    std::fill(values, values + A_.nonZeros(), 0.0);
    const auto add = [values](const SparseMatrix& B, const std::vector<int>& slot, double weight) {
        const double* b = B.valuePtr();
        for (std::size_t e = 0; e < slot.size(); ++e)
            if (slot[e] >= 0)
                values[slot[e]] += weight * b[e];
    };
    add(M, M_slot_, a);
    add(K, K_slot_, k);
    return A_;
}

const SparseMatrix& ReducedStepMatrix::assemble(const SparseMatrix& M, const SparseMatrix& K, const Damping& damping,
                                                double time_step, double theta)
{
    require_positive(time_step, "time step dt [s]");
    require_theta(theta);
    const double h = theta * time_step;
    return assemble(M, K, 1.0 + h * damping.alpha, h * damping.beta + h * h);
}

Eigen::VectorXd step_right_hand_side(const SparseMatrix& M, const Eigen::VectorXd& v, const Eigen::VectorXd& forces,
                                     const Eigen::VectorXd& external_forces, double time_step)
{
    require_positive(time_step, "time step dt [s]");
    if (M.rows() != v.size() || forces.size() != v.size() || external_forces.size() != v.size())
        throw Error(str("step right-hand side: M is ", M.rows(), "x", M.cols(), ", v, f and f_ext have ", v.size(),
                        ", ", forces.size(), " and ", external_forces.size(), " entries"));
    // BEGIN EXERCISE 10.2 step_right_hand_side #the-implicit-step
    // HINT: The lecture's right-hand side b of backward Euler solved for v⁺ (docs/10_linear_dynamics.md#the-implicit-step).
    // HINT: K is not an argument: `forces` holds the internal forces f(u) = −K u, sign included.
    return M * v + time_step * (forces + external_forces);
    // END EXERCISE
}

Eigen::VectorXd velocity_change_right_hand_side(const SparseMatrix& M, const Eigen::VectorXd& v,
                                                const Eigen::VectorXd& Kv, const Eigen::VectorXd& forces,
                                                const Eigen::VectorXd& external_forces, const Damping& damping,
                                                double time_step, double theta)
{
    require_positive(time_step, "time step dt [s]");
    require_theta(theta);
    if (M.rows() != v.size() || Kv.size() != v.size() || forces.size() != v.size() ||
        external_forces.size() != v.size())
        throw Error(str("velocity-change right-hand side: M is ", M.rows(), "x", M.cols(), ", v, K v, f and f_ext have ",
                        v.size(), ", ", Kv.size(), ", ", forces.size(), " and ", external_forces.size(), " entries"));
    const Eigen::VectorXd Dv = damping.alpha == 0.0 ? Eigen::VectorXd(damping.beta * Kv)
                                                    : Eigen::VectorXd(damping.alpha * symmetric_times(M, v) + damping.beta * Kv);
    return time_step * (forces + external_forces - Dv - (theta * time_step) * Kv);
}

// --- ThetaMethod ------------------------------------------------------------------------------

ThetaMethod::ThetaMethod(double theta, ImplicitOptions options)
    : theta_((require_theta(theta), theta)), options_(std::move(options)),
      solver_(options_.make_solver ? options_.make_solver() : cg::make_solver(options_.solver, options_.solver_options))
{
    if (!solver_)
        throw Error("ThetaMethod: the solver factory of the options returned no solver");
}

std::string ThetaMethod::name() const
{
    if (theta_ == 1.0)
        return "backward Euler";
    if (theta_ == 0.5)
        return "implicit midpoint";
    return str("theta = ", theta_);
}

StepInfo ThetaMethod::step(Body& body, double time_step, State& state)
{
    require_positive(time_step, "time step dt [s]");
    require_fits(body, state);
    ForceModel& model = body.model();
    const FreeDofs& dofs = body.dofs();
    const SparseMatrix& M = body.mass_matrix();
    const bool eliminate = options_.pinned == PinnedRoute::eliminate;
    const SparseMatrix& K = model.stiffness(state.u);
    StepInfo info;

    if (solver_->size() == 0 || options_.refactor_every_step || !model.constant_stiffness() ||
        time_step != prepared_time_step_ || &body != prepared_body_) {
        if (eliminate) {
            if (!reduced_ || prepared_body_ != &body || !reduced_->fits(M, K))
                reduced_.emplace(M, K, dofs);
            solver_->prepare(reduced_->assemble(M, K, body.scene().damping, time_step, theta_));
        } else {
            solver_->prepare(dofs.project(step_matrix(M, K, body.scene().damping, time_step, theta_)));
        }
        prepared_time_step_ = time_step;
        prepared_body_ = &body;
        info.prepared = true;
    }

    if (!options_.warm_start)  // a cold start: from zero, not from the last answer
        solution_ = Eigen::VectorXd::Zero(eliminate ? dofs.size() : dofs.full_size());
    Eigen::VectorXd v_next, v_theta, u_next;
    // BEGIN EXERCISE 10.4 theta_step #the-implicit-step
    // HINT: One θ-step of a linear body (docs/10_linear_dynamics.md#the-implicit-step): solve A x = rhs with the
    // HINT: prepared solver_, x being v⁺ (StepForm::velocity, the lecture's b) or Δv = v⁺ − v
    // HINT: (StepForm::velocity_change, #two-forms-of-one-step), as options_.form says. A is ready: the free dofs
    // HINT: only when `eliminate` (dofs.gather / dofs.scatter), else all 3n with the pinned rows and columns made
    // HINT: the identity's (then the right-hand side's pinned entries must be zero). Helpers above:
    // HINT: velocity_change_right_hand_side, step_right_hand_side (the lecture's b, whole at θ = 1 only: for θ < 1 the docs'
    // HINT: b has a correction with a damping part and a stiffness part; damping_times gives D v),
    // HINT: pinned_velocity_next and set_pinned. Moving pins (#moving-pins): the pinned part of x is known, not
    // HINT: zero (in the Δv form it is a change from v_p); take what A does with it off the right-hand side.
    // HINT: rhs_ and solution_ are the solver's vectors: solution_ keeps the last answer, the warm start (start it
    // HINT: afresh when its size does not fit). End with v_next, v_theta (the θ-weighted velocity) and u_next
    // HINT: (moved with v_theta) filled, 3n each.
    const bool change = options_.form == StepForm::velocity_change;
    Eigen::VectorXd Kv;
    if (change || theta_ < 1.0)
        Kv = symmetric_times(K, state.v);
    Eigen::VectorXd b;
    if (change) {
        b = velocity_change_right_hand_side(M, state.v, Kv, state.forces, body.external_forces(),
                                            body.scene().damping, time_step, theta_);
    } else {
        b = step_right_hand_side(M, state.v, state.forces, body.external_forces(), time_step);
        if (theta_ < 1.0)
            b -= ((1.0 - theta_) * time_step) * (damping_times(body, state.v, Kv) + (theta_ * time_step) * Kv);
    }
    const Eigen::VectorXd pinned_next = pinned_velocity_next(body, state.v, theta_);
    const Eigen::VectorXd pinned_part = change ? Eigen::VectorXd(pinned_next - state.v.cwiseProduct(
                                                     Eigen::VectorXd::Ones(b.size()) - dofs.free_mask()))
                                               : pinned_next;
    if (pinned_part.cwiseAbs().maxCoeff() > 0.0) {
        const double h = theta_ * time_step;
        const Damping& d = body.scene().damping;
        b -= (1.0 + h * d.alpha) * (M * pinned_part) + (h * d.beta + h * h) * (K * pinned_part);
    }
    // solution_ still holds the previous answer: the warm start of an iterative solver.
    v_next = Eigen::VectorXd::Zero(state.v.size());
    if (eliminate) {
        rhs_ = dofs.gather(b);
        if (solution_.size() != rhs_.size())
            solution_ = change ? Eigen::VectorXd::Zero(rhs_.size()) : dofs.gather(state.v);
        solver_->solve(rhs_, solution_);
        dofs.scatter(solution_, v_next);
    } else {
        rhs_ = b.cwiseProduct(dofs.free_mask());
        if (solution_.size() != rhs_.size())
            solution_ = change ? Eigen::VectorXd::Zero(rhs_.size()) : Eigen::VectorXd(state.v);
        solver_->solve(rhs_, solution_);
        v_next = solution_.cwiseProduct(dofs.free_mask());  // exactly zero on the pinned dofs
    }
    if (change)
        v_next += state.v;
    set_pinned(body, pinned_next, v_next);
    v_theta = theta_ * v_next + (1.0 - theta_) * state.v;
    u_next = state.u + time_step * v_theta;
    // END EXERCISE

    info.solver_iterations = solver_->stats().iterations;
    const Damping& d = body.scene().damping;
    Eigen::VectorXd damping_force = Eigen::VectorXd::Zero(v_theta.size());
    if (d.alpha != 0.0 || d.beta != 0.0) {
        const Eigen::VectorXd Kv = d.beta != 0.0 ? Eigen::VectorXd(K * v_theta) : Eigen::VectorXd();
        damping_force = damping_times(body, v_theta, Kv);
        info.damping_work = time_step * v_theta.dot(damping_force);
    }
    if (body.pins_move()) {  // f_θ = f(u) − θΔt K v_θ: the step's linearised force at u_θ
        const Eigen::VectorXd net =
            state.forces - (theta_ * time_step) * (K * v_theta) + body.external_forces() - damping_force;
        info.boundary_work = boundary_work(body, M * (v_next - state.v), net, time_step);
    }
    commit_step(model, time_step, std::move(u_next), std::move(v_next), state);
    return info;
}

// --- SymplecticEuler ----------------------------------------------------------------------------

StepInfo SymplecticEuler::step(Body& body, double time_step, State& state)
{
    require_positive(time_step, "time step dt [s]");
    require_fits(body, state);
    ForceModel& model = body.model();
    const FreeDofs& dofs = body.dofs();
    const Damping& d = body.scene().damping;
    const bool lumped = body.scene().mass == MassModel::lumped;
    StepInfo info;
    if (!lumped && (mass_solver_ == nullptr || prepared_body_ != &body)) {
        mass_solver_ = cg::make_solver("default");
        mass_solver_->prepare(dofs.reduce(body.mass_matrix()));
        prepared_body_ = &body;
        info.prepared = true;
    }
    Eigen::VectorXd Kv;
    if (d.beta != 0.0)
        Kv = model.stiffness(state.u) * state.v;
    const Eigen::VectorXd damping_force = damping_times(body, state.v, Kv);

    Eigen::VectorXd v_next, u_next;
    // BEGIN EXERCISE 10.5 symplectic_euler_step #explicit-euler
    // HINT: Symplectic Euler (docs/10_linear_dynamics.md#explicit-euler): forces at the old state (state.forces,
    // HINT: body.external_forces(), and damping_force, already D v), positions moved with the NEW velocity (that
    // HINT: is what makes it symplectic). Work on the free dofs (dofs.gather / dofs.scatter): lumped, M⁻¹ is a
    // HINT: division by body.dof_masses(); consistent, mass_solver_ is already prepared with M_ff. The pinned dofs
    // HINT: end the step at the body's pin velocity (#moving-pins); with a consistent M their acceleration over the
    // HINT: step reaches the free rows through M_fp (the lumped M has none). Fill v_next and u_next, 3n each.
    const Eigen::VectorXd pin_change = body.pin_velocity() - state.v.cwiseProduct(Eigen::VectorXd::Ones(state.v.size()) - dofs.free_mask());
    Eigen::VectorXd net = dofs.gather(state.forces + body.external_forces() - damping_force);
    if (!lumped && pin_change.cwiseAbs().maxCoeff() > 0.0)
        net -= dofs.gather(body.mass_matrix() * pin_change) / time_step;
    Eigen::VectorXd acceleration;
    if (lumped)
        acceleration = net.cwiseQuotient(dofs.gather(body.dof_masses()));
    else
        acceleration = mass_solver_->solve(net);
    v_next = body.pin_velocity();
    dofs.scatter(dofs.gather(state.v) + time_step * acceleration, v_next);
    u_next = state.u + time_step * v_next;
    // END EXERCISE

    info.damping_work = time_step * v_next.dot(damping_force);
    info.boundary_work = boundary_work(body, body.mass_matrix() * (v_next - state.v),
                                       state.forces + body.external_forces() - damping_force, time_step);
    commit_step(model, time_step, std::move(u_next), std::move(v_next), state);
    return info;
}

std::unique_ptr<Integrator> make_integrator(std::string_view name, const ImplicitOptions& options)
{
    if (name == "backward-euler")
        return std::make_unique<ThetaMethod>(1.0, options);
    if (name == "implicit-midpoint")
        return std::make_unique<ThetaMethod>(0.5, options);
    if (name == "symplectic-euler")
        return std::make_unique<SymplecticEuler>();
    std::string names;
    for (const std::string& known : integrator_names())
        names += (names.empty() ? "" : ", ") + known;
    throw Error(str("unknown integrator '", name, "'; choose one of: ", names));
}

std::vector<std::string> integrator_names()
{
    return {"backward-euler", "implicit-midpoint", "symplectic-euler"};
}

// --- The time loop -------------------------------------------------------------------------------

double apply_step_hook(const Simulation::BeforeStep& hook, Body& body, State& state, double step_end)
{
    double work = 0.0;
    // BEGIN EXERCISE 10.9 apply_step_hook #the-step-hook
    // HINT: Book in `work` the energy a hook puts in (docs/10_linear_dynamics.md#the-step-hook), in joules: the
    // HINT: jump of H = energies(body, state).total() across the hook, at the same (u, v). The hook is called as
    // HINT: hook(body, state, step_end), the state read-only, and returns whether it changed the loads or the
    // HINT: model; only then is anything booked, and then the state's forces and elastic energy are stale until
    // HINT: the model is evaluated again at u (body.model().evaluate(u, forces) fills the forces and returns U).
    const double before = energies(body, state).total();
    if (hook(body, std::as_const(state), step_end)) {
        state.elastic_energy = body.model().evaluate(state.u, state.forces);
        work = energies(body, state).total() - before;
    }
    // END EXERCISE
    return work;
}

// --- Simulation ----------------------------------------------------------------------------------

Simulation::Simulation(Body& body, Integrator& integrator, State initial)
    : body_(body), integrator_(integrator), state_(std::move(initial))
{
    require_fits(body, state_);
    const Material& material = body.scene().material;
    const double volume = body.dof_masses().sum() / 3.0 / material.density;
    roundoff_energy_ = material.youngs_modulus * volume * divergence_roundoff_strain * divergence_roundoff_strain;
}

void Simulation::run(int steps, const Observer& observer)
{
    if (steps < 0)
        throw Error(str("the number of steps must be >= 0, got ", steps));
    if (!started_) {
        last_ = StepRecord{};
        last_.step = state_.step;
        last_.time = state_.time;
        last_.energies = energies(body_, state_);
        initial_total_ = last_.energies.total();
        largest_magnitude_ = last_.energies.magnitude();
        started_ = true;
        if (observer)
            observer(state_, last_);
    }
    for (int k = 0; k < steps; ++k) {
        Timer clock;
        const double time_step = body_.time_step();
        StepRecord record;
        record.work_in = last_.work_in;
        if (before_step_)
            record.work_in += apply_step_hook(before_step_, body_, state_, state_.time + time_step);
        const StepInfo info = integrator_.step(body_, time_step, state_);
        record.work_in += info.boundary_work;
        record.seconds = clock.seconds();
        record.step = state_.step;
        record.time = state_.time;
        record.energies = energies(body_, state_);
        record.solver_iterations = info.solver_iterations;
        record.newton_iterations = info.newton_iterations;
        record.damping_dissipated = last_.damping_dissipated + info.damping_work;
        const double total = record.energies.total();
        const auto where = [&] {
            return str("step ", record.step, " (t = ", record.time, " s, dt = ", time_step, " s, ",
                       integrator_.name(), ", ", body_.model().name(), " model)");
        };
        // What makes this integrator gain energy, and what to change (built only for the message).
        const auto cause = [&] {
            if (integrator_.is_explicit())
                return std::string("an explicit step above its stability limit 2/omega_max does this: use a "
                                   "smaller dt (below explicit_stability_limit) or an implicit integrator");
            if (body_.model().constant_stiffness())
                return str("an implicit step (", integrator_.name(), ") of a linear body cannot gain energy at "
                           "any dt: look for a wrong term in the step (its matrix or right-hand side), or a load "
                           "or pin motion the step hook changed without its work booked");
            return str("an implicit step (", integrator_.name(), ") of a nonlinear force model can gain energy "
                       "where the step does not hold the motion (a midpoint step, a linearised stiffness far "
                       "from the tangent): use a smaller dt or a more dissipative step (a theta above 1/2, "
                       "backward Euler)");
        };
        if (!std::isfinite(total) || !std::isfinite(record.work_in) || !state_.u.allFinite() || !state_.v.allFinite())
            throw Error(str("the run diverged at ", where(), ": the state is no longer finite (energy ", total,
                            " J); ", cause()));
        largest_magnitude_ = std::max(largest_magnitude_, record.energies.magnitude());
        const double rise = total - record.work_in - initial_total_;
        if (rise > divergence_energy_fraction * largest_magnitude_ && rise > roundoff_energy_)
            throw Error(str("the run diverged at ", where(), ": H - W_in (the total energy less the ", record.work_in,
                            " J the scene put in) rose from ", initial_total_, " J to ", total - record.work_in,
                            " J, by ", rise / std::max(largest_magnitude_, 1e-300),
                            " of the largest energy in play (the limit is ", divergence_energy_fraction,
                            "); ", cause()));
        record.integrator_dissipated = initial_total_ + record.work_in - total - record.damping_dissipated;
        last_ = record;
        if (observer)
            observer(state_, last_);
    }
}

}  // namespace fem::dynamics
