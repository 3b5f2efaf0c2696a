// A scene's [[body]]: its name, mesh, material, mass, damping, initial velocity, pins and loads.
// docs/scenes.md#the-scene-file
#include "scene_parts.hpp"

#include "12_hyperelastic_newton/force_models.hpp"

#include <algorithm>
#include <iomanip>
#include <set>
#include <string_view>

namespace fem::scenes::detail {
namespace {

const std::vector<std::string> selector_keys{"box", "plane", "vertices"};

std::vector<std::string> with(std::vector<std::string> keys, const std::vector<std::string>& more)
{
    keys.insert(keys.end(), more.begin(), more.end());
    return keys;
}

}  // namespace

BodySpec read_body(const toml::table& table, const std::string& name, const Source& file,
                   const std::filesystem::path& scene_file, double duration, double time_step, int index)
{
    const Fields fields(table, name, file,
                        {"name", "mesh", "material", "mass", "damping", "pin", "load", "initial_velocity", "self_contact"});
    BodySpec body;
    body.name = fields.text("name", str("body", index));
    // It names files and the rows of steps.csv: printable, and nothing a path or a CSV row would split at.
    const bool plain = std::all_of(body.name.begin(), body.name.end(), [](char c) {
        return static_cast<unsigned char>(c) > ' ' && c != 0x7f && std::string_view("/\\,\"'").find(c) == std::string_view::npos;
    });
    if (body.name.empty() || !plain)
        fields.fail(*fields.get("name"), "name",
                    "must be a non-empty name of printable characters without spaces, slashes, commas or quotes");

    const toml::table* mesh_table = fields.subtable("mesh");
    if (mesh_table == nullptr)
        fields.missing("mesh", "give [body.mesh] with file = \"...\" or generator = \"box\"");
    const Fields mesh(*mesh_table, fields.field("mesh"), file,
                      {"file", "generator", "size", "cells", "scale", "translate", "tetgen", "lattice"});
    body.mesh = build_mesh(mesh, scene_file, body.mesh_spec);

    const toml::table* material_table = fields.subtable("material");
    if (material_table == nullptr)
        fields.missing("material", "give [body.material] with model, youngs_modulus, poisson_ratio, density");
    const Fields material(*material_table, fields.field("material"), file,
                          {"model", "youngs_modulus", "poisson_ratio", "density"});
    body.model = material.text("model", std::string(hyper::linear_model), model_names());
    body.material.youngs_modulus = material.number(
        "youngs_modulus", body.material.youngs_modulus, [](double Y) { return Y > 0.0 && Y <= largest_youngs_modulus; },
        str("a number in (0, ", largest_youngs_modulus, "] Pa (diamond is 1.2e12 Pa; beyond the bound the stresses "
            "of a large strain and the Lame parameters near nu = 0.5 leave a double's range)"));
    body.material.poisson_ratio = material.number(
        "poisson_ratio", body.material.poisson_ratio,
        [](double nu) { return nu > -1.0 && nu <= dynamics::highest_poisson_ratio; },
        str(std::setprecision(15), "a number in (-1, ", dynamics::highest_poisson_ratio, "] (lambda/mu at most ",
            dynamics::largest_lame_ratio, ": nearer 0.5 the stiffness's condition number leaves a double no digits; "
            "0.5 is incompressible, which a displacement model cannot represent)"));
    body.material.density = material.positive("density", body.material.density);
    body.mass = fields.text("mass", "lumped", {"lumped", "consistent"}) == "lumped" ? dynamics::MassModel::lumped
                                                                                   : dynamics::MassModel::consistent;
    if (const toml::table* damping_table = fields.subtable("damping")) {
        const Fields damping(*damping_table, fields.field("damping"), file, {"alpha", "beta"});
        const auto in_range = [](double x) { return x >= 0.0 && x <= 0.02; };
        body.damping.alpha = damping.number("alpha", 0.0, in_range, "a number in [0, 0.02] (1/s)");
        body.damping.beta = damping.number("beta", 0.0, in_range, "a number in [0, 0.02] (s)");
    }
    body.initial_velocity = fields.vector("initial_velocity", Eigen::Vector3d::Zero());
    body.self_contact = fields.flag("self_contact", false);
    // A body that moves farther than its own size in one step leaves the pins' neighbours strained
    // beyond any model's range at the first step (1e6 m/s read as "not positive definite").
    const double extent = body_size(body.mesh);
    if (body.initial_velocity.norm() * time_step > extent)
        fields.fail(*fields.get("initial_velocity"), "initial_velocity",
                    str("moves the body ", body.initial_velocity.norm() * time_step, " m in one step of ", time_step,
                        " s, more than its size ", extent, " m; allowed: a speed up to size / dt = ", extent / time_step,
                        " m/s"));

    const auto each = [&](const std::string& key, const auto& read) {
        const toml::node* node = fields.get(key);
        if (node == nullptr)
            return;
        if (!node->is_array_of_tables())
            fields.fail(*node, key, str("must be an array of tables ([[", name.substr(0, name.find('[')), ".", key,
                                        "]]), got ", Fields::type_name(*node)));
        const toml::array& items = *node->as_array();
        for (std::size_t i = 0; i < items.size(); ++i)
            read(Fields(table_in_array(fields, *items.get(i), key), str(fields.field(key), "[", i, "]"), file,
                        with(selector_keys, key == "pin" ? std::vector<std::string>{"motion", "axis", "center", "angle",
                                                                                   "displacement", "start", "end"}
                                                         : std::vector<std::string>{"type", "force", "traction",
                                                                                    "ramp", "until"})));
    };
    std::set<int> pinned;
    each("pin", [&](const Fields& pin) {
        Pin p{read_selector(pin), read_motion(pin, duration)};
        const std::vector<int> selected = select_vertices(body.mesh, p.select);
        p.select.vertices = selected;  // resolved once: the runner moves exactly these
        p.select.kind = Selector::Kind::vertices;
        for (int v : selected)
            if (!pinned.insert(v).second)
                throw Error(str(p.select.where, ": vertex ", v, " is pinned by an earlier pin too; pins must not overlap"));
        body.pins.push_back(std::move(p));
    });
    body.pinned.assign(pinned.begin(), pinned.end());
    if (!body.pinned.empty() && body.pinned.size() == static_cast<std::size_t>(body.mesh.V.rows()))
        fields.fail(*fields.get("pin"), "pin", str("pins every one of the body's ", body.mesh.V.rows(),
                                                   " vertices: nothing is left to move; pin fewer"));
    each("load", [&](const Fields& load) {
        Load l;
        const std::string type = load.text("type", "point", {"point", "surface"});
        l.kind = type == "point" ? Load::Kind::point : Load::Kind::surface;
        const std::string value_key = type == "point" ? "force" : "traction";
        const std::string other_key = type == "point" ? "traction" : "force";
        if (load.has(other_key))
            load.fail(*load.get(other_key), other_key, str("belongs to the other load type; a ", type, " load has ", value_key));
        if (!load.has(value_key))
            load.missing(value_key, str("a ", type, " load needs ", value_key, " = [x, y, z] (",
                                        type == "point" ? "total force, N" : "force per area, Pa", ")"));
        l.value = load.vector(value_key, Eigen::Vector3d::Zero());
        l.ramp = load.non_negative("ramp", 0.0);
        l.until = load.positive("until", l.until);
        l.select = read_selector(load);
        l.select.vertices = select_vertices(body.mesh, l.select);
        l.select.kind = Selector::Kind::vertices;
        body.loads.push_back(std::move(l));
    });
    return body;
}

}  // namespace fem::scenes::detail
