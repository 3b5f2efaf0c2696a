// The scenes runner: one chapter 10 Simulation per solve (a body, or bodies that can meet), stepped
// together. run_scene is set-up (the output sink, BodyGroups, RunningScene), loop (step_solves,
// take_frame) and output (SceneOutput::finish, scene_output.hpp). docs/scenes.md#the-runner
#include "scenes/runner.hpp"

#include "scene_output.hpp"

#include "scenes/run_outputs.hpp"
#include "scenes/scene_contact.hpp"
#include "scenes/scene_conditions.hpp"
#include "scenes/scene_group.hpp"

#include "15_body_contact/body_contact.hpp"

#include "12_hyperelastic_newton/force_models.hpp"

#include "common/error.hpp"
#include "common/interrupt.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>

namespace fem::scenes {

std::string describe_segments(const std::vector<Segment>& segments)
{
    std::string out;
    for (const Segment& s : segments)
        out += str(out.empty() ? "" : ", ", s.model, " ", s.first_step, "-", s.last_step);
    return out;
}

namespace {

/// The integrator of a body (or a group of bodies stepped as one) whose model may change level:
/// chapter 12's factory makes the one each level needs (on first use) and each step goes to the
/// highest level of its bodies' (a group's joint solve takes the integrator its most demanding body needs).
class LevelIntegrator final : public dynamics::Integrator {
public:
    LevelIntegrator(std::vector<const SceneForces*> forces, const SceneSpec& scene) : forces_(std::move(forces))
    {
        settings_.integrator = scene.integrator;
        settings_.solver = scene.solver;
        settings_.newton_tolerance = scene.newton_tolerance;
    }
    std::string name() const override { return current().name(); }
    int order() const override { return current().order(); }
    bool is_explicit() const override { return current().is_explicit(); }
    dynamics::StepInfo step(dynamics::Body& body, double time_step, dynamics::State& state) override
    {
        return current().step(body, time_step, state);
    }

private:
    /// The body of the highest level (the first of them).
    const SceneForces& leading() const
    {
        return **std::max_element(forces_.begin(), forces_.end(),
                                  [](const SceneForces* a, const SceneForces* b) { return a->level() < b->level(); });
    }
    dynamics::Integrator& current() const
    {
        const SceneForces& lead = leading();
        std::unique_ptr<dynamics::Integrator>& integrator = integrators_[static_cast<int>(lead.level())];
        if (integrator == nullptr) {
            hyper::StepSettings settings = settings_;
            if (lead.level() == Level::hyperelastic)
                settings.integrator = "backward-euler";  // chapter 12's Newton steps backward Euler only
            integrator = hyper::make_integrator_for(lead.level_model(), settings);
        }
        return *integrator;
    }
    std::vector<const SceneForces*> forces_;
    hyper::StepSettings settings_;
    mutable std::array<std::unique_ptr<dynamics::Integrator>, 3> integrators_;
};

struct GroupRun;

/// One body of a running scene. Alone in its group, its Body is the one its group steps; in a group
/// of several (scene_group.hpp), a view of its slice of the joint unknowns: its own mass, loads,
/// pins and force model, which its step hook sets and its frames and energies read.
struct BodyRun {
    const BodySpec* spec = nullptr;
    SceneForces* forces = nullptr;  // owned by body
    std::unique_ptr<dynamics::Body> body;
    bool automatic = false;  // the model is auto's choice of the moment
    std::shared_ptr<Pull> pull = std::make_shared<Pull>();  // what pulls it now (read by its step hook)
    std::vector<Segment> segments;
    std::vector<dynamics::StepRecord> records;
    GroupRun* group = nullptr;
    Eigen::Index offset = 0;  // its first vertex in its group's unknowns

    /// Its slice of its group's state (u, v, forces, time and step; the elastic energy its own).
    dynamics::State state() const;
};

/// The bodies stepped as one solve: one body's own, or a group's joint Body (scene_group.hpp).
struct GroupRun {
    std::vector<BodyRun*> members;
    std::unique_ptr<dynamics::Body> joint;  // null for one body
    dynamics::Body* body = nullptr;         // joint, or the one member's
    std::unique_ptr<LevelIntegrator> integrator;
    std::unique_ptr<ContactIntegrator> contact;  // null: no obstacles and no bodies or self to meet
    std::unique_ptr<dynamics::Simulation> simulation;

    /// "body 'a'" or "bodies 'a', 'b'" for messages.
    std::string names() const
    {
        std::string out;
        for (const BodyRun* m : members)
            out += str(out.empty() ? "" : ", ", "'", m->spec->name, "'");
        return str(members.size() == 1 ? "body " : "bodies ", out);
    }
};

dynamics::State BodyRun::state() const
{
    const dynamics::State& whole = group->simulation->state();
    if (group->joint == nullptr)
        return whole;
    const Eigen::Index n = 3 * spec->mesh.V.rows(), first = 3 * offset;
    dynamics::State s;
    s.time = whole.time;
    s.step = whole.step;
    s.u = whole.u.segment(first, n);
    s.v = whole.v.segment(first, n);
    if (whole.forces.size() == whole.u.size())
        s.forces = whole.forces.segment(first, n);
    s.elastic_energy = body->model().energy(s.u);
    return s;
}

/// A body of the scene: its force model (auto's levels), its own Body (over its chapter 10 Scene,
/// BodyGroups::body_scene), its segments.
BodyRun start_body(const BodySpec& spec, const dynamics::Scene& body_scene, const SceneSpec& scene,
                   const std::string& model)
{
    BodyRun b;
    b.spec = &spec;
    const std::string chosen = model.empty() ? spec.model : model;
    b.automatic = chosen == "auto";
    const std::string hyperelastic = hyper::is_hyperelastic(chosen) ? chosen : scene.thresholds.hyperelastic;
    auto forces = std::make_unique<SceneForces>(spec.mesh, spec.material, hyperelastic,
                                                b.automatic ? Level::linear : level_of(chosen));
    b.forces = forces.get();
    b.body = std::make_unique<dynamics::Body>(body_scene, std::move(forces));
    b.segments.push_back({0, 0, b.forces->level(), b.forces->level_model()});
    return b;
}

/// The initial velocity of a body (3n): the spec's on every vertex but the pins, which start at rest
/// (their motions ramp up from zero speed).
Eigen::VectorXd initial_velocity(const BodySpec& spec)
{
    Eigen::VectorXd v0 = Eigen::VectorXd::Zero(3 * spec.mesh.V.rows());
    if (spec.initial_velocity.norm() > 0.0) {
        for (Eigen::Index v = 0; v < spec.mesh.V.rows(); ++v)
            v0.segment<3>(3 * v) = spec.initial_velocity;
        for (int v : spec.pinned)
            v0.segment<3>(3 * v).setZero();
    }
    return v0;
}

/// The step hook of a group of several bodies: each body's own (SceneConditions) on its slice and
/// its own Body, their loads and pin velocities then gathered into the joint Body.
class GroupConditions {
public:
    GroupConditions(std::vector<BodyRun*> members, std::vector<SceneConditions> conditions)
        : members_(std::move(members)), conditions_(std::move(conditions))
    {
    }
    bool operator()(dynamics::Body& joint, const dynamics::State&, double step_end)
    {
        bool changed = false;
        Eigen::VectorXd loads(joint.external_forces().size()), pins(loads.size());
        for (std::size_t i = 0; i < members_.size(); ++i) {
            BodyRun& m = *members_[i];
            changed = conditions_[i](*m.body, m.state(), step_end) || changed;
            const Eigen::Index first = 3 * m.offset, n = 3 * m.spec->mesh.V.rows();
            loads.segment(first, n) = m.body->applied_loads();
            pins.segment(first, n) = m.body->pin_velocity();
        }
        joint.set_applied_loads(loads);
        joint.set_pin_velocity(pins);
        return changed;
    }

private:
    std::vector<BodyRun*> members_;
    std::vector<SceneConditions> conditions_;
};

/// The solve of a group of bodies (indices into bodies): its Body (the member's own, or the joint
/// one over joint_scene, BodyGroups::joint_scene), its integrator, contact (obstacles; the bodies
/// against each other and themselves in a group of several; a lone body's self_contact) and step hook.
std::unique_ptr<GroupRun> start_group(std::vector<BodyRun>& bodies, const std::vector<int>& members,
                                      const dynamics::Scene* joint_scene, const SceneSpec& scene,
                                      const std::vector<std::shared_ptr<const contact::Obstacle>>& obstacles)
{
    auto g = std::make_unique<GroupRun>();
    std::vector<SceneForces*> levels;
    Eigen::Index offset = 0;
    for (int i : members) {
        BodyRun& b = bodies[static_cast<std::size_t>(i)];
        b.group = g.get();
        b.offset = offset;
        offset += b.spec->mesh.V.rows();
        g->members.push_back(&b);
        levels.push_back(b.forces);
    }
    const bool joined = members.size() > 1;
    const bool self_contact = joined || bodies[static_cast<std::size_t>(members.front())].spec->self_contact;
    Eigen::VectorXd v0(3 * offset);
    for (BodyRun* b : g->members)
        v0.segment(3 * b->offset, 3 * b->spec->mesh.V.rows()) = initial_velocity(*b->spec);
    if (joined) {
        std::vector<dynamics::ForceModel*> parts;
        std::vector<Eigen::Index> counts;
        for (BodyRun* b : g->members) {
            parts.push_back(b->forces);
            counts.push_back(b->spec->mesh.V.rows());
        }
        g->joint = std::make_unique<dynamics::Body>(*joint_scene, std::make_unique<JointForces>(parts, counts));
        g->body = g->joint.get();
    } else {
        g->body = g->members.front()->body.get();
    }
    for (BodyRun* b : g->members)
        if ((!obstacles.empty() || self_contact) && b->forces->level_model() == hyper::linear_model && !b->automatic)
            throw Error(str("body '", b->spec->name, "': model linear cannot meet obstacles or bodies (its energy of a "
                            "body at rest far from where it started is round-off; docs/scenes.md#obstacles): use auto, "
                            "corotational or a hyperelastic model"));
    g->integrator = std::make_unique<LevelIntegrator>(std::vector<const SceneForces*>(levels.begin(), levels.end()), scene);
    if (!obstacles.empty() || self_contact) {
        // In a group: the member of each vertex, and which members hold themselves off.
        std::vector<int> vertex_body;
        std::vector<bool> self_contacts;
        std::vector<std::string> names;
        for (const BodyRun* m : g->members)
            names.push_back(m->spec->name);
        if (joined)
            for (std::size_t m = 0; m < g->members.size(); ++m) {
                vertex_body.insert(vertex_body.end(), static_cast<std::size_t>(g->members[m]->spec->mesh.V.rows()),
                                   static_cast<int>(m));
                self_contacts.push_back(g->members[m]->spec->self_contact);
            }
        g->contact = std::make_unique<ContactIntegrator>(*g->integrator, levels, *g->body, obstacles, scene, self_contact,
                                                         std::move(vertex_body), std::move(self_contacts), std::move(names));
    }
    std::vector<SceneConditions> conditions;
    for (BodyRun* b : g->members) {
        conditions.emplace_back(*b->spec, scene, b->forces, b->automatic, g->contact.get(), b->pull);
        b->body->set_applied_loads(conditions.back().initial_loads());
    }
    Eigen::VectorXd loads(3 * offset);
    for (std::size_t i = 0; i < g->members.size(); ++i)
        loads.segment(3 * g->members[i]->offset, 3 * g->members[i]->spec->mesh.V.rows()) = conditions[i].initial_loads();
    g->body->set_applied_loads(loads);
    dynamics::Integrator& integrator = g->contact ? static_cast<dynamics::Integrator&>(*g->contact) : *g->integrator;
    g->simulation = std::make_unique<dynamics::Simulation>(*g->body, integrator, dynamics::initial_state(*g->body, {}, v0));
    if (joined)
        g->simulation->set_before_step(GroupConditions(g->members, std::move(conditions)));
    else
        g->simulation->set_before_step(std::move(conditions.front()));
    return g;
}

/// Each member's record of its group's last step (or step 0). Alone: the group's. In a group of
/// several: its own energies (its slice, its masses, loads and model); the group's books (work in,
/// damping and integrator dissipated, iterations, time) on its first body's record, the others'
/// integrator dissipated the energy H they gave to the group's other bodies (H(0) − H(t)), so each
/// record keeps chapter 10's balance H(0) + W_in − H − D − I = 0 and the sums are the group's.
void record_members(GroupRun& g)
{
    const dynamics::StepRecord& whole = g.simulation->last();
    if (g.joint == nullptr) {
        g.members.front()->records.push_back(whole);
        return;
    }
    double given = 0.0;
    for (std::size_t i = 0; i < g.members.size(); ++i) {
        BodyRun& m = *g.members[i];
        dynamics::StepRecord r;
        r.step = whole.step;
        r.time = whole.time;
        r.energies = dynamics::energies(*m.body, m.state());
        const double start = m.records.empty() ? r.energies.total() : m.records.front().energies.total();
        if (i > 0) {
            r.integrator_dissipated = start - r.energies.total();
            given += r.integrator_dissipated;
        }
        m.records.push_back(r);
    }
    dynamics::StepRecord& first = g.members.front()->records.back();
    first.work_in = whole.work_in;
    first.damping_dissipated = whole.damping_dissipated;
    first.integrator_dissipated = whole.integrator_dissipated - given;
    first.newton_iterations = whole.newton_iterations;
    first.solver_iterations = whole.solver_iterations;
    first.seconds = whole.seconds;
}

/// One step of a group, with each member's record and the segment of the model it used.
void step_group(GroupRun& g)
{
    // The path check ([contact] check_path): a contact step's path closed at its end, a step without
    // contact checked as its one straight segment.
    const contact::PathCheckTerm* path = g.contact ? g.contact->potential().term<contact::PathCheckTerm>() : nullptr;
    const Eigen::VectorXd start = path != nullptr ? g.simulation->state().u : Eigen::VectorXd();
    try {
        g.simulation->run(1);
        if (path != nullptr) {
            const dynamics::State& end = g.simulation->state();
            if (g.contact->last_contact())
                path->end_step(end.u);
            else
                path->check_chord(start, end.u, end.step, end.time);
        }
    } catch (const Error& e) {
        throw Error(str(g.names(), ": ", e.what()));
    }
    record_members(g);
    const int step = g.simulation->state().step;
    for (BodyRun* b : g.members) {
        Segment& last = b->segments.back();
        if (last.level == b->forces->level())
            last.last_step = step;
        else
            b->segments.push_back({step, step, b->forces->level(), b->forces->level_model()});
    }
}

/// The record of a group's last step when it has contact (else none): its split from its
/// ContactIntegrator, its pairs at the step's end (counted outside the step's time; none after a
/// step out of contact, whose end ContactPotential::out_of_contact proved d̂ away from every pair).
void record_contact(const GroupRun& g, std::vector<ContactStepRecord>& records)
{
    if (g.contact == nullptr)
        return;
    ContactStepRecord r;
    const dynamics::State& state = g.simulation->state();
    r.step = state.step;
    r.time = state.time;
    for (const BodyRun* m : g.members)
        r.bodies += str(r.bodies.empty() ? "" : "+", m->spec->name);
    r.surface_primitives = g.contact->surface_primitives();
    r.contact = g.contact->last_contact();
    r.seconds = g.simulation->last().seconds;
    r.newton_iterations = g.simulation->last().newton_iterations;
    r.cost = g.contact->last_cost();
    if (r.contact)
        r.pairs = g.contact->pairs(state.u, state.time);
    records.push_back(std::move(r));
}

/// Sets each body's pull from request (stiffness 0: the body's default), printing a line when a
/// pull starts, moves to another vertex or ends.
void update_pulls(std::vector<BodyRun>& bodies, const PullRequest& request, double stiffness)
{
    for (std::size_t i = 0; i < bodies.size(); ++i) {
        BodyRun& b = bodies[i];
        Pull& pull = *b.pull;
        if (request.body == static_cast<int>(i)) {
            if (pull.vertex != request.vertex) {
                pull = make_pull(*b.body, request.vertex, request.target,
                                 stiffness != 0.0 ? stiffness : default_pull_stiffness(*b.body));
                std::cout << "pulling vertex " << pull.vertex << " of body '" << b.spec->name << "' (k = "
                          << pull.stiffness << " N/m on " << pull.vertices.size() << " vertices)" << std::endl;
            }
            pull.target = request.target;
        } else if (pull.vertex >= 0) {
            const Eigen::Vector3d x = b.body->positions(b.state().u).row(pull.vertex).transpose();
            std::cout << "released vertex " << pull.vertex << " of body '" << b.spec->name << "' "
                      << (x - pull.target).norm() << " m from the pointer's point" << std::endl;
            pull = Pull{};
        }
    }
}

/// The frame of every body at its state, merged, with the fields the scene asks for (and "model":
/// each tet's level).
io::MeshData scene_frame(const std::vector<BodyRun>& bodies, const std::vector<dynamics::State>& states,
                         const OutputSpec& output)
{
    std::vector<io::MeshData> parts;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
        io::MeshData frame = dynamics::body_frame(*bodies[i].body, states[i]);
        frame.cell_data.push_back({"model", Eigen::MatrixXd::Constant(frame.cells.rows(), 1,
                                                                      static_cast<double>(bodies[i].forces->level()))});
        parts.push_back(std::move(frame));
    }
    return merged_frame(parts, output);
}

/// The models the bodies use now, for a frame's caption: "stable neo-Hookean", "auto: corotational"
/// for auto's choice, and with several bodies each named ("stiff corotational, soft stable neo-Hookean").
std::string frame_models(const std::vector<BodyRun>& bodies)
{
    std::string out;
    for (const BodyRun& b : bodies) {
        const std::string model = str(b.automatic ? "auto: " : "", model_label(b.forces->level_model()));
        out += bodies.size() == 1 ? model : str(out.empty() ? "" : ", ", b.spec->name, " ", model);
    }
    return out;
}

/// A scene's bodies and the solves that step them, started: the run's set-up. Each body's force
/// model and own Body (over its Scene in groups), the obstacles, and each group's Body, integrator,
/// contact and step hook. The scene and groups must outlive it; it is not copied or moved (each
/// solve points at its bodies).
struct RunningScene {
    RunningScene(const SceneSpec& scene, const BodyGroups& groups, const std::string& model)
    {
        for (std::size_t i = 0; i < scene.bodies.size(); ++i)
            bodies.push_back(start_body(scene.bodies[i], groups.body_scene(i), scene, model));
        const auto obstacles = scene_obstacles(scene);
        for (std::size_t g = 0; g < groups.members().size(); ++g)
            solves.push_back(start_group(bodies, groups.members()[g], groups.joint_scene(g), scene, obstacles));
    }
    RunningScene(const RunningScene&) = delete;
    RunningScene& operator=(const RunningScene&) = delete;

    std::vector<BodyRun> bodies;  // in the scene's order
    std::vector<std::unique_ptr<GroupRun>> solves;
};

/// One step of every solve in turn (step_group), each one's contact record into records; then, with
/// solves that could meet, that they stayed apart (BodyGroups::check_apart). The Newton iterations
/// the step took, summed over the solves.
int step_solves(RunningScene& running, const BodyGroups& groups, std::vector<ContactStepRecord>& records)
{
    int newton = 0;
    for (std::unique_ptr<GroupRun>& g : running.solves) {
        step_group(*g);
        record_contact(*g, records);
        newton += g->simulation->last().newton_iterations;
    }
    if (groups.checks_apart()) {
        std::vector<MatrixX3d> positions;
        for (const BodyRun& b : running.bodies)
            positions.push_back(b.body->positions(b.state().u));
        groups.check_apart(positions);
    }
    return newton;
}

/// Each body's last record to the output (a row of steps.csv each), with its model's name now.
void log_steps(const std::vector<BodyRun>& bodies, SceneOutput& output)
{
    for (const BodyRun& b : bodies)
        output.add_step(b.spec->name, b.body->model().name(), b.records.back());
}

/// The frame of the bodies' state now, handed to the output; with keep_positions each body's
/// positions kept in result.frames.
void take_frame(const std::vector<BodyRun>& bodies, const OutputSpec& spec, bool keep_positions,
                SceneOutput& output, RunResult& result)
{
    std::vector<dynamics::State> states;
    for (const BodyRun& b : bodies)
        states.push_back(b.state());
    SceneFrame frame;
    frame.step = states.front().step;
    frame.time = states.front().time;
    frame.models = frame_models(bodies);
    if (output.takes_mesh())
        frame.mesh = scene_frame(bodies, states, spec);
    for (std::size_t i = 0; i < bodies.size(); ++i) {
        if (keep_positions)
            result.frames[i].push_back(bodies[i].body->positions(states[i].u));
        frame.displacements.push_back(std::move(states[i].u));
    }
    output.add_frame(frame);
    ++result.frame_count;
}

/// "body a: linear 0-3, corotational 4-120 (steps per model); contact in 80 of 120 steps; one solve
/// with bodies 'a', 'b'" for each body.
void print_models(const std::vector<BodyRun>& bodies, int steps)
{
    for (const BodyRun& b : bodies)
        std::cout << "body " << b.spec->name << ": " << describe_segments(b.segments) << " (steps per model)"
                  << (b.group->contact ? str("; contact in ", b.group->contact->contact_steps(), " of ", steps, " steps") : "")
                  << (b.group->members.size() > 1 ? str("; one solve with ", b.group->names()) : "") << "\n";
}

}  // namespace

RunResult run_scene(const SceneSpec& scene, const RunOptions& options)
{
    // The set-up. The output first: it binds the skin (chapter 13), so that a bad one is refused
    // before anything runs or is written; then the groups (the start check), then the bodies.
    SceneOutput output(scene, options.run, options.skin, options.on_frame);
    const BodyGroups groups(scene);
    RunningScene running(scene, groups, options.model);
    const int steps = dynamics::step_count(scene.duration, scene.time_step);
    const int frame_every = steps_per_frame(scene);

    // The loop: every solve steps in turn; each step's records and every frame go to the output.
    RunResult result;
    result.frames.resize(running.bodies.size());
    for (std::unique_ptr<GroupRun>& g : running.solves) {
        g->simulation->run(0);  // step 0's record: the energies at the start
        record_members(*g);
    }
    log_steps(running.bodies, output);
    take_frame(running.bodies, scene.output, options.keep_positions, output, result);
    Progress progress(steps, options.progress);
    Timer clock;
    for (int k = 1; options.forever || k <= steps; ++k) {
        if (stop_requested()) {
            result.interrupted = true;
            break;
        }
        if (options.pull)
            update_pulls(running.bodies, options.pull(), options.pull_stiffness);
        const int newton = step_solves(running, groups, result.contact_records);
        result.newton_iterations += newton;
        result.steps = k;
        log_steps(running.bodies, output);
        if (k % frame_every == 0 || k == steps)
            take_frame(running.bodies, scene.output, options.keep_positions, output, result);
        if (!options.forever)
            progress.update(k, newton);
    }
    result.seconds = clock.seconds();
    if (result.interrupted)
        progress.finish();

    // The output: each body's books into the result, the models printed, the files of the whole run.
    for (BodyRun& b : running.bodies) {
        result.segments.push_back(b.segments);
        result.contact_steps.push_back(b.group->contact ? b.group->contact->contact_steps() : 0);
        if (const auto* path = b.group->contact ? b.group->contact->potential().term<contact::PathCheckTerm>() : nullptr;
            path != nullptr && b.group->members.front() == &b) {
            result.path_segments += path->segments();
            result.path_pair_tests += path->pair_tests();
        }
        result.records.push_back(std::move(b.records));
    }
    if (options.print_models)
        print_models(running.bodies, result.steps);
    output.finish(result.records, result.contact_records, result.steps, result.interrupted);
    return result;
}

RunResult run_positions(const SceneSpec& scene, const std::string& model)
{
    RunOptions options;
    options.model = model;
    options.keep_positions = true;
    options.print_models = false;
    return run_scene(scene, options);
}

}  // namespace fem::scenes
