// The scene file: TOML read with toml++, every field checked where it is read.
// docs/scenes.md#the-scene-file
#include "scenes/scene_file.hpp"

#include "13_skinning/skinning.hpp"
#include "14_contact/mesh_obstacle.hpp"

#include "12_hyperelastic_newton/force_models.hpp"
#include "12_hyperelastic_newton/materials.hpp"

#include "10_linear_dynamics/time_integration.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh_io.hpp"
#include "common/tetgen.hpp"

#include <toml++/toml.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <set>
#include <sys/resource.h>
#include <sstream>

namespace fem::scenes {

const std::vector<std::string>& model_names()
{
    static const std::vector<std::string> names = [] {
        std::vector<std::string> all = hyper::force_model_names();  // chapter 12's factory: every model by name
        all.push_back("auto");
        return all;
    }();
    return names;
}

namespace {

// The memory estimate's constants (memory_estimate).
constexpr double fill_per_vertex_block = 1.0;  ///< factor blocks per vertex^(4/3)
constexpr double bytes_per_tet = 3000.0;       ///< the mesh, per-tet matrices and frames
constexpr double bytes_per_vertex = 4000.0;    ///< positions, velocities, the matrices' rows

std::string joined(const std::vector<std::string>& names)
{
    std::string out;
    for (const std::string& name : names)
        out += (out.empty() ? "" : ", ") + name;
    return out;
}

/// text itself, or when longer than 200 characters its start and end with the count between (a
/// name or key of megabytes is not echoed whole).
std::string clipped(const std::string& text)
{
    constexpr std::size_t most = 200;
    if (text.size() <= most)
        return text;
    return str(text.substr(0, 100), "[... ", text.size() - 180, " characters ...]", text.substr(text.size() - 80));
}

/// Refuses TOML text nested deeper than max_nesting levels (tables of headers and dotted keys,
/// arrays and inline tables together) before toml++ parses it: its parser and the tables it builds
/// recurse once per level, and tens of thousands of levels overflow the stack. what names the text
/// (the file, or the --set option), followed by :line:column when with_position.
void check_nesting(std::string_view text, const std::string& what, bool with_position)
{
    int line = 1, column = 0;
    int header = 0;                 // levels of the current [table] header
    std::vector<int> opened;        // '[' or '{' of the open arrays and inline tables
    std::vector<int> key_levels;    // the dotted-key levels at each of them
    int key = 0;                    // dots of the key being read
    bool key_position = true, in_header = false, start_of_line = true;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        ++column;
        if (c == '\n') {
            ++line;
            column = 0;
            if (opened.empty()) {
                key_position = true;
                key = 0;
                start_of_line = true;
            }
            continue;
        }
        if (c == '#') {  // a comment, to the end of the line
            while (i + 1 < text.size() && text[i + 1] != '\n')
                ++i;
            continue;
        }
        if (c == '"' || c == '\'') {  // a string: skipped, escapes and multi-line ones included
            const bool triple = text.substr(i, 3) == std::string(3, c);
            const std::string_view close = triple ? std::string_view(&text[i], 3) : std::string_view(&text[i], 1);
            std::size_t j = i + close.size();
            while (j < text.size() && text.substr(j, close.size()) != close) {
                if (c == '"' && text[j] == '\\')
                    ++j;
                if (j < text.size() && text[j] == '\n') {
                    ++line;
                    column = 0;
                }
                ++j;
            }
            i = std::min(text.size(), j + close.size()) - 1;
            start_of_line = false;
            continue;
        }
        if (c == ' ' || c == '\t' || c == '\r')
            continue;
        if (start_of_line && opened.empty() && c == '[') {  // a header [a.b] or [[a.b]]
            in_header = true;
            header = 1;
            start_of_line = false;
            continue;
        }
        start_of_line = false;
        if (in_header) {
            if (c == '.')
                ++header;
            else if (c == ']' && (i + 1 >= text.size() || text[i + 1] != ']'))
                in_header = false;
        } else if (key_position && c == '.') {
            ++key;
        } else if (c == '=') {
            key_position = false;
        } else if (c == '[' || c == '{') {
            opened.push_back(c);
            key_levels.push_back(key);
            key_position = c == '{';
            key = 0;
        } else if ((c == ']' || c == '}') && !opened.empty()) {
            opened.pop_back();
            key = key_levels.back();
            key_levels.pop_back();
            key_position = false;
        } else if (c == ',' && !opened.empty()) {
            key_position = opened.back() == '{';
            key = 0;
        }
        int levels = header + key + static_cast<int>(opened.size());
        for (int k : key_levels)
            levels += k;
        if (levels > max_nesting)
            throw Error(str(what, with_position ? str(":", line, ":", column) : std::string(), ": nested deeper than ",
                            max_nesting, " levels (tables, dotted keys, arrays and inline tables together); a scene ",
                            "needs fewer than 10"));
    }
}

/// Where the fields being read come from: the scene file, and the overrides that replaced some of
/// them (the field path as given, e.g. "body.material.model", and the option that set it).
struct Source {
    std::string file;
    std::vector<std::pair<std::string, std::string>> overrides;
    ReadLimits limits;
    mutable double estimated_bytes = 0.0;  ///< the memory estimates of the bodies read so far, summed

    /// The option that set a field (e.g. "--set body.0.material.poisson_ratio=0.5"), or a table
    /// holding it, or a field inside it, matched on the path without array indices; empty when none did.
    std::string override_of(const std::string& field) const
    {
        const auto plain = [](std::string path) {
            std::string out;
            std::string part;
            std::replace(path.begin(), path.end(), '[', '.');
            path.erase(std::remove(path.begin(), path.end(), ']'), path.end());
            std::istringstream in(path);
            while (std::getline(in, part, '.'))
                if (!part.empty() && !std::all_of(part.begin(), part.end(), ::isdigit))
                    out += (out.empty() ? "" : ".") + part;
            return out;
        };
        // It set the field itself, a table that holds it, or (making tables) a field inside it.
        const auto within = [](const std::string& inner, const std::string& outer) {
            return inner == outer || inner.starts_with(outer + ".");
        };
        std::string found;
        for (const auto& [key, option] : overrides)
            if (within(plain(field), plain(key)) || within(plain(key), plain(field)))
                found = option;  // the last one set it
        return found;
    }
};

/// One table of the scene file being read: its dotted name (body[0].material), the file it came
/// from, and the check that it holds only the allowed fields (no check when none are given).
class Fields {
public:
    Fields(const toml::table& table, std::string name, const Source& source, std::vector<std::string> allowed)
        : table_(table), name_(std::move(name)), source_(source), file_(source.file)
    {
        for (auto&& [key, node] : table_) {
            if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), key.str()) == allowed.end())
                fail(node, std::string(key.str()), str("unknown field; allowed here: ", joined(allowed)));
        }
    }

    /// "file:line:column" of a node; for a node an override put there, "file: <the option>".
    std::string where(const toml::node& node, const std::string& key = "") const
    {
        const toml::source_region& source = node.source();
        if (source.begin.line == 0) {
            const std::string option = source_.override_of(field(key));
            return option.empty() ? file_ : str(file_, ": ", option);
        }
        return str(file_, ":", source.begin.line, ":", source.begin.column);
    }
    std::string field(const std::string& key) const { return name_.empty() ? key : name_ + "." + key; }

    [[noreturn]] void fail(const toml::node& node, const std::string& key, const std::string& message) const
    {
        throw Error(str(where(node, key), ": ", clipped(field(key)), ": ", message));
    }
    [[noreturn]] void missing(const std::string& key, const std::string& message) const
    {
        throw Error(str(where(table_), ": ", field(key), ": missing; ", message));
    }

    const toml::node* get(const std::string& key) const { return table_.get(key); }
    bool has(const std::string& key) const { return get(key) != nullptr; }
    const toml::table& table() const { return table_; }
    const std::string& name() const { return name_; }
    const Source& source() const { return source_; }

    /// A number (an integer is taken as a real) that must satisfy ok, whose failure says allowed.
    template <typename Check>
    double number(const std::string& key, double fallback, Check ok, const std::string& allowed) const
    {
        const toml::node* node = get(key);
        if (node == nullptr)
            return fallback;
        return number_of(*node, key, ok, allowed);
    }
    template <typename Check>
    double number_of(const toml::node& node, const std::string& key, Check ok, const std::string& allowed) const
    {
        if (!node.is_number())
            fail(node, key, str("must be ", allowed, ", got ", type_name(node)));
        const double value = *node.value<double>();
        if (!std::isfinite(value) || !ok(value))
            fail(node, key, str("must be ", allowed, ", got ", value));
        return value;
    }
    double positive(const std::string& key, double fallback) const
    {
        return number(key, fallback, [](double x) { return x > 0.0; }, "a number > 0");
    }
    double non_negative(const std::string& key, double fallback) const
    {
        return number(key, fallback, [](double x) { return x >= 0.0; }, "a number >= 0");
    }
    double finite(const std::string& key, double fallback) const
    {
        return number(key, fallback, [](double) { return true; }, "a finite number");
    }
    int integer(const std::string& key, int fallback, int low, int high) const
    {
        const toml::node* node = get(key);
        if (node == nullptr)
            return fallback;
        return integer_of(*node, key, low, high);
    }
    int integer_of(const toml::node& node, const std::string& key, int low, int high) const
    {
        const std::string allowed = str("an integer in [", low, ", ", high, "]");
        if (!node.is_integer())
            fail(node, key, str("must be ", allowed, ", got ", type_name(node)));
        const std::int64_t value = *node.value<std::int64_t>();
        if (value < low || value > high)
            fail(node, key, str("must be ", allowed, ", got ", value));
        return static_cast<int>(value);
    }
    bool flag(const std::string& key, bool fallback) const
    {
        const toml::node* node = get(key);
        if (node == nullptr)
            return fallback;
        if (!node->is_boolean())
            fail(*node, key, str("must be true or false, got ", type_name(*node)));
        return *node->value<bool>();
    }
    std::string text(const std::string& key, const std::string& fallback, const std::vector<std::string>& allowed = {}) const
    {
        const toml::node* node = get(key);
        if (node == nullptr)
            return fallback;
        const std::string what = allowed.empty() ? "a string" : str("one of ", joined(allowed));
        if (!node->is_string())
            fail(*node, key, str("must be ", what, ", got ", type_name(*node)));
        std::string value = *node->value<std::string>();
        if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), value) == allowed.end())
            fail(*node, key, str("must be ", what, ", got '", value, "'"));
        return value;
    }
    const toml::array& array(const std::string& key, std::size_t size, const std::string& allowed) const
    {
        const toml::node* node = get(key);
        if (!node->is_array() || (size != 0 && node->as_array()->size() != size))
            fail(*node, key, str("must be ", allowed, ", got ", describe(*node)));
        return *node->as_array();
    }
    Eigen::Vector3d vector(const std::string& key, const Eigen::Vector3d& fallback, bool nonzero = false) const
    {
        if (!has(key))
            return fallback;
        const std::string allowed = nonzero ? "an array of 3 finite numbers, not all 0" : "an array of 3 finite numbers";
        const toml::array& values = array(key, 3, allowed);
        Eigen::Vector3d v;
        for (int i = 0; i < 3; ++i) {
            const toml::node& x = *values.get(static_cast<std::size_t>(i));
            if (!x.is_number() || !std::isfinite(*x.value<double>()))
                fail(x, str(key, "[", i, "]"), str("must be a finite number, got ", describe(x)));
            v[i] = *x.value<double>();
        }
        if (nonzero && v.norm() == 0.0)
            fail(*get(key), key, str("must be ", allowed));
        return v;
    }
    std::vector<int> integers(const std::string& key) const
    {
        const toml::array& values = array(key, 0, "an array of vertex indices");
        std::vector<int> out;
        for (std::size_t i = 0; i < values.size(); ++i)
            out.push_back(integer_of(*values.get(i), str(key, "[", i, "]"), 0, std::numeric_limits<int>::max()));
        return out;
    }
    std::vector<std::string> texts(const std::string& key, const std::vector<std::string>& fallback,
                                   const std::vector<std::string>& allowed) const
    {
        if (!has(key))
            return fallback;
        const toml::array& values = array(key, 0, str("an array of strings from: ", joined(allowed)));
        std::vector<std::string> out;
        for (std::size_t i = 0; i < values.size(); ++i) {
            const toml::node& x = *values.get(i);
            const std::string item = str(key, "[", i, "]");
            if (!x.is_string() || std::find(allowed.begin(), allowed.end(), *x.value<std::string>()) == allowed.end())
                fail(x, item, str("must be one of ", joined(allowed), ", got ", describe(x)));
            out.push_back(*x.value<std::string>());
        }
        return out;
    }
    /// A sub-table (empty Fields if absent).
    const toml::table* subtable(const std::string& key) const
    {
        const toml::node* node = get(key);
        if (node == nullptr)
            return nullptr;
        if (!node->is_table())
            fail(*node, key, str("must be a table, got ", type_name(*node)));
        return node->as_table();
    }

    static std::string type_name(const toml::node& node)
    {
        std::ostringstream out;
        out << node.type();
        return out.str();
    }
    static std::string describe(const toml::node& node)
    {
        std::ostringstream out;
        if (node.is_string())
            out << "'" << clipped(*node.value<std::string>()) << "'";
        else if (node.is_boolean())
            out << (*node.value<bool>() ? "true" : "false");
        else if (node.is_number())
            out << *node.value<double>();
        else
            out << (node.is_array() ? "an " : "a ") << node.type();
        return out.str();
    }

private:
    const toml::table& table_;
    std::string name_;
    const Source& source_;
    const std::string& file_;
};

/// Δt: a number > 0 or a fraction "1/60".
double time_step_field(const Fields& fields, const std::string& key, double fallback)
{
    const toml::node* node = fields.get(key);
    if (node == nullptr)
        return fallback;
    const std::string allowed = "a number > 0 or a fraction like \"1/60\"";
    double value = 0.0;
    if (node->is_string()) {
        const std::string text = *node->value<std::string>();
        double a = 0.0, b = 0.0;
        char slash = 0, rest = 0;
        std::istringstream in(text);
        if (!(in >> a >> slash >> b) || slash != '/' || (in >> rest) || b == 0.0)
            fields.fail(*node, key, str("must be ", allowed, ", got '", text, "'"));
        value = a / b;
    } else {
        if (!node->is_number())
            fields.fail(*node, key, str("must be ", allowed, ", got ", Fields::type_name(*node)));
        value = *node->value<double>();
    }
    if (!std::isfinite(value) || value <= 0.0)
        fields.fail(*node, key, str("must be ", allowed, ", got ", value));
    return value;
}

/// The table of an array of tables, checked to be one.
const toml::table& table_in_array(const Fields& parent, const toml::node& node, const std::string& item)
{
    if (!node.is_table())
        parent.fail(node, item, str("must be a table, got ", Fields::type_name(node)));
    return *node.as_table();
}

Selector read_selector(const Fields& fields)
{
    Selector s;
    s.where = str(fields.where(fields.table()), ": ", fields.name());
    const int given = int(fields.has("box")) + int(fields.has("plane")) + int(fields.has("vertices"));
    if (given != 1)
        throw Error(str(s.where, ": give exactly one of box = [[x0, y0, z0], [x1, y1, z1]], ",
                        "plane = { point = [...], normal = [...] } or vertices = [...]"));
    if (fields.has("box")) {
        s.kind = Selector::Kind::box;
        const toml::array& corners = fields.array("box", 2, "two corners [[x0, y0, z0], [x1, y1, z1]]");
        const toml::table corner_table{{"low", *corners.get(0)}, {"high", *corners.get(1)}};
        const Fields corner(corner_table, fields.field("box"), fields.source(), {"low", "high"});
        s.low = corner.vector("low", Eigen::Vector3d::Zero());
        s.high = corner.vector("high", Eigen::Vector3d::Zero());
        if ((s.low.array() > s.high.array()).any())
            fields.fail(*fields.get("box"), "box", "the first corner must be below the second in x, y and z");
    } else if (fields.has("plane")) {
        s.kind = Selector::Kind::plane;
        const Fields plane(*fields.subtable("plane"), fields.field("plane"), fields.source(), {"point", "normal", "side"});
        s.point = plane.vector("point", Eigen::Vector3d::Zero());
        s.normal = plane.vector("normal", Eigen::Vector3d::UnitX(), true).normalized();
        s.below = plane.text("side", "on", {"on", "below"}) == "below";
    } else {
        s.kind = Selector::Kind::vertices;
        s.vertices = fields.integers("vertices");
    }
    return s;
}

Motion read_motion(const Fields& fields, double duration)
{
    Motion m;
    const std::string kind = fields.text("motion", "fixed", {"fixed", "rotate", "translate"});
    m.start = fields.non_negative("start", 0.0);
    m.end = fields.positive("end", std::max(duration, m.start + 1e-9));
    if (m.end <= m.start)
        fields.fail(*fields.get("end"), "end", str("must be after start = ", m.start, " s"));
    const bool rotate = kind == "rotate", translate = kind == "translate";
    for (const std::string key : {"axis", "center", "angle"})
        if (!rotate && fields.has(key))
            fields.fail(*fields.get(key), key, "belongs to motion = \"rotate\"");
    if (!translate && fields.has("displacement"))
        fields.fail(*fields.get("displacement"), "displacement", "belongs to motion = \"translate\"");
    if (kind == "fixed") {
        for (const std::string key : {"start", "end"})
            if (fields.has(key))
                fields.fail(*fields.get(key), key, "belongs to a moving pin (motion = \"rotate\" or \"translate\")");
        return m;
    }
    if (rotate) {
        m.kind = Motion::Kind::rotate;
        m.axis = fields.vector("axis", Eigen::Vector3d::UnitX(), true).normalized();
        m.center = fields.vector("center", Eigen::Vector3d::Zero());
        m.angle = fields.finite("angle", 0.0) * std::acos(-1.0) / 180.0;
    } else {
        m.kind = Motion::Kind::translate;
        m.displacement = fields.vector("displacement", Eigen::Vector3d::Zero());
    }
    return m;
}

/// Whether path exists as a regular file; false, not an exception, for a name the system refuses
/// (too long). A folder, a device or a pipe is no mesh (reading a pipe could wait for ever).
bool file_exists(const std::filesystem::path& path)
{
    std::error_code ec;
    return std::filesystem::is_regular_file(path, ec);
}

/// The file a scene names: an absolute path as given, else beside the scene file, else in data/.
std::filesystem::path resolve(const std::filesystem::path& scene_file, const std::string& name)
{
    const std::filesystem::path given(name);
    if (given.is_absolute())
        return given;
    const std::filesystem::path beside = scene_file.parent_path() / given;
    if (file_exists(beside))
        return beside;
    try {
        return data_path(name);
    } catch (const Error&) {
        return beside;  // in neither place: the error names the first tried
    }
}

/// One [[obstacle]]: its type's fields only (the others are refused, naming the type they belong to),
/// μ, and a velocity that moves it (towards a vertex) less than d̂ per step: faster, it could reach
/// a vertex from beyond d̂ within one step, where no barrier force has yet pushed back. A mesh's file
/// is read (beside the scene file, then in data/) and placed: its coordinates × scale + translate.
ObstacleSpec read_obstacle(const toml::table& table, const std::string& name, const Source& source,
                           const std::filesystem::path& scene_file, double time_step, double activation_distance)
{
    const std::vector<std::string> types{"half-space", "sphere", "box", "mesh"};
    const std::vector<std::vector<std::string>> own{
        {"point", "normal"}, {"center", "radius"}, {"center", "size", "axis", "angle"}, {"file", "scale", "translate"}};
    const Fields fields(table, name, source, {"type", "point", "normal", "center", "radius", "size", "axis", "angle",
                                              "file", "scale", "translate", "velocity", "friction"});
    if (!fields.has("type"))
        fields.missing("type", "one of half-space, sphere, box, mesh");
    const std::string type = fields.text("type", "", types);
    const std::size_t index = static_cast<std::size_t>(std::find(types.begin(), types.end(), type) - types.begin());
    for (std::size_t other = 0; other < types.size(); ++other)
        for (const std::string& key : own[other])
            if (fields.has(key) && std::find(own[index].begin(), own[index].end(), key) == own[index].end())
                fields.fail(*fields.get(key), key, str("belongs to type = \"", types[other], "\", not to type = \"", type, "\""));
    ObstacleSpec o;
    o.kind = static_cast<ObstacleSpec::Kind>(index);
    if (o.kind == ObstacleSpec::Kind::half_space) {
        o.point = fields.vector("point", o.point);
        o.normal = fields.vector("normal", o.normal, true).normalized();
    } else if (o.kind != ObstacleSpec::Kind::mesh) {
        o.center = fields.vector("center", o.center);
    }
    if (o.kind == ObstacleSpec::Kind::sphere) {
        if (!fields.has("radius"))
            fields.missing("radius", "a sphere needs radius = r (m)");
        o.radius = fields.positive("radius", o.radius);
    }
    if (o.kind == ObstacleSpec::Kind::box) {
        if (!fields.has("size"))
            fields.missing("size", "a box needs size = [x, y, z] (its edge lengths, m)");
        o.size = fields.vector("size", o.size);
        if ((o.size.array() <= 0.0).any())
            fields.fail(*fields.get("size"), "size", "must be three edge lengths > 0 (m)");
        o.axis = fields.vector("axis", o.axis, true).normalized();
        o.angle = fields.finite("angle", 0.0) * std::acos(-1.0) / 180.0;
    }
    if (o.kind == ObstacleSpec::Kind::mesh) {
        if (!fields.has("file"))
            fields.missing("file", "a mesh needs file = \"….obj\" (a triangle surface: .obj, .stl, .ply or .vtu)");
        const toml::node& node = *fields.get("file");
        o.file = resolve(scene_file, fields.text("file", ""));
        if (!file_exists(o.file))
            fields.fail(node, "file", str("no such file: ", clipped(o.file.string()), " (looked beside the scene file, then in the data folder)"));
        const std::string extension = o.file.extension().string();
        if (extension != ".obj" && extension != ".stl" && extension != ".ply" && extension != ".vtu")
            fields.fail(node, "file", str("has the extension '", extension, "'; a mesh obstacle is a triangle surface: .obj, .stl, .ply or .vtu"));
        try {
            o.surface = io::read_tri_mesh(o.file);
        } catch (const Error& e) {
            fields.fail(node, "file", str("must be a surface of triangles, none degenerate: ", e.what()));
        }
        o.scale = fields.positive("scale", o.scale);
        o.translate = fields.vector("translate", o.translate);
        o.surface.V = ((o.surface.V * o.scale).rowwise() + o.translate.transpose()).eval();
    }
    o.friction = fields.number("friction", 0.0, [](double mu) { return mu >= 0.0 && mu <= 10.0; }, "a number in [0, 10]");
    o.velocity = fields.vector("velocity", o.velocity);
    // A half-space moves towards the bodies only along its normal; a sphere or a box in every direction.
    const double approach = o.kind == ObstacleSpec::Kind::half_space ? std::abs(o.normal.dot(o.velocity)) : o.velocity.norm();
    if (approach * time_step >= activation_distance)
        fields.fail(*fields.get("velocity"), "velocity",
                    str("moves the obstacle ", approach * time_step, " m towards the bodies in one step of ", time_step,
                        " s, not less than contact.activation_distance = ", activation_distance,
                        " m; allowed: a speed below ", activation_distance / time_step, " m/s (or a smaller time.step)"));
    return o;
}

const std::vector<std::string> selector_keys{"box", "plane", "vertices"};

std::vector<std::string> with(std::vector<std::string> keys, const std::vector<std::string>& more)
{
    keys.insert(keys.end(), more.begin(), more.end());
    return keys;
}


/// The memory this process may still use [bytes]: the system's available memory (MemAvailable of
/// /proc/meminfo), or the address-space limit (ulimit -v) when it is lower.
double available_memory()
{
    double available = std::numeric_limits<double>::infinity();
    std::ifstream meminfo("/proc/meminfo");
    for (std::string key; meminfo >> key;) {
        double kilobytes = 0.0;
        meminfo >> kilobytes;
        if (key == "MemAvailable:")
            available = kilobytes * 1024.0;
        meminfo.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
    }
    rlimit limit{};
    if (::getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
        available = std::min(available, static_cast<double>(limit.rlim_cur));
    return available;
}

/// Refuses a body whose run would need more memory than the scene may use (see memory_estimate),
/// the bodies read before it included: the error is at field, the field to change.
void check_memory(const Fields& fields, const toml::node& node, const std::string& key, long long vertices,
                  long long tets, const std::string& change)
{
    const MemoryEstimate need = memory_estimate(vertices, tets);
    const Source& source = fields.source();
    const double budget = source.limits.memory > 0 ? static_cast<double>(source.limits.memory) : available_memory();
    if (source.estimated_bytes + need.bytes > budget)
        fields.fail(node, key, str("a run of this mesh needs about ", std::ceil(need.bytes / 1e6), " MB (", tets, " tets, ",
                                   need.dofs, " unknowns, about ", need.factor_nonzeros, " factor entries)",
                                   source.estimated_bytes > 0 ? str(" besides ", std::ceil(source.estimated_bytes / 1e6),
                                                                    " MB for the bodies before it")
                                                              : std::string(),
                                   ", more than the ", std::floor(budget / 1e6), " MB available: ", change));
    source.estimated_bytes += need.bytes;
}

/// A body's size: the longest edge of its vertices' bounding box [m].
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
        const std::string name = fields.text("file", "");
        spec.file = resolve(scene_file, name);
        const toml::node& node = *fields.get("file");
        if (!file_exists(spec.file))
            fields.fail(node, "file", str("no such file: ", clipped(spec.file.string()), " (looked beside the scene file, then in the data folder)"));
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

BodySpec read_body(const toml::table& table, const std::string& name, const Source& file,
                   const std::filesystem::path& scene_file, double duration, double time_step, int index)
{
    const Fields fields(table, name, file,
                        {"name", "mesh", "material", "mass", "damping", "pin", "load", "initial_velocity"});
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
    body.model = material.text("model", "linear", model_names());
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

/// Splits "a.b.c" into its parts.
std::vector<std::string> split_path(const std::string& path)
{
    std::vector<std::string> parts;
    std::string part;
    std::istringstream in(path);
    while (std::getline(in, part, '.'))
        parts.push_back(part);
    return parts;
}

bool all_digits(const std::string& s)
{
    return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

/// Sets the field at parts[at..] below node to value; an array of tables without an index takes
/// the value in every element.
void assign(toml::table& table, const std::vector<std::string>& parts, std::size_t at, const toml::node& value,
            const std::string& option)
{
    const std::string& key = parts[at];
    if (at + 1 == parts.size()) {
        value.visit([&](auto&& v) { table.insert_or_assign(key, v); });
        return;
    }
    toml::node* child = table.get(key);
    if (child == nullptr) {
        table.insert_or_assign(key, toml::table{});
        child = table.get(key);
    }
    if (child->is_table()) {
        assign(*child->as_table(), parts, at + 1, value, option);
    } else if (child->is_array_of_tables()) {
        toml::array& items = *child->as_array();
        if (all_digits(parts[at + 1])) {
            const std::size_t index = parts[at + 1].size() > 9 ? items.size() : std::stoul(parts[at + 1]);
            if (index >= items.size())
                throw Error(str(option, ": ", key, " has ", items.size(), " entries, no ", clipped(parts[at + 1])));
            if (at + 2 == parts.size())
                throw Error(str(option, ": name a field of ", key, "[", index, "]"));
            assign(*items.get(index)->as_table(), parts, at + 2, value, option);
        } else {
            for (std::size_t i = 0; i < items.size(); ++i)
                assign(*items.get(i)->as_table(), parts, at + 1, value, option);
        }
    } else {
        throw Error(str(option, ": ", key, " is not a table, so it has no field ", parts[at + 1]));
    }
}

/// Applies one "key=value" override to the tree.
void apply_override(toml::table& root, const std::string& setting, const std::string& option)
{
    const std::size_t equals = setting.find('=');
    if (equals == std::string::npos || equals == 0)
        throw Error(str(option, ": expected key=value (e.g. body.material.model=auto or time.step=1/120)"));
    const std::string key = setting.substr(0, equals), text = setting.substr(equals + 1);
    const std::vector<std::string> parts = split_path(key);
    for (const std::string& part : parts)
        if (part.empty())
            throw Error(str(option, ": the key '", clipped(key), "' has an empty part"));
    if (parts.size() > static_cast<std::size_t>(max_nesting))
        throw Error(str(option, ": the key has ", parts.size(), " parts; at most ", max_nesting, " are allowed"));
    check_nesting("value = " + text, option, false);
    // The value in TOML syntax (a number, true, [1, 2, 3], "text"); anything else is a string.
    toml::table parsed;
    try {
        parsed = toml::parse("value = " + text, option);
    } catch (const toml::parse_error&) {
        std::string quoted = "\"";
        for (char c : text) {
            if (c == '"' || c == '\\')
                quoted += '\\';
            quoted += c;
        }
        try {
            parsed = toml::parse("value = " + quoted + "\"", option);
        } catch (const toml::parse_error& e) {
            throw Error(str(option, ": the value is neither TOML nor a plain string: ", e.description()));
        }
    }
    assign(root, parts, 0, *parsed.get("value"), option);
}

/// Adds the leaves of a [quick] table as "a.b.c" paths.
void flatten(const toml::table& table, const std::string& prefix, std::vector<std::pair<std::string, const toml::node*>>& out)
{
    for (auto&& [key, node] : table) {
        const std::string path = prefix.empty() ? std::string(key.str()) : prefix + "." + std::string(key.str());
        if (node.is_table())
            flatten(*node.as_table(), path, out);
        else
            out.emplace_back(path, &node);
    }
}

}  // namespace

SceneSpec read_scene(const std::filesystem::path& path, const std::vector<std::string>& overrides, bool quick,
                     const ReadLimits& limits)
{
    const std::string file = path.string();
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(path, ec);
    if (!std::filesystem::is_regular_file(status))
        throw Error(str("scene file '", clipped(file), "': ",
                        ec && ec != std::errc::no_such_file_or_directory ? ec.message()
                        : std::filesystem::exists(status)                 ? "not a regular file"
                                                                          : "no such file"));
    std::ifstream in(path, std::ios::binary);
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (!in || size > max_scene_bytes)
        throw Error(str("scene file '", clipped(file), "': ", !in ? "cannot be read" : str("holds ", size, " bytes; at most "),
                        !in ? "" : str(max_scene_bytes, " are allowed (a scene is a few kilobytes)")));
    std::string text(static_cast<std::size_t>(size), '\0');
    in.seekg(0);
    if (!in.read(text.data(), size))
        throw Error(str("scene file '", clipped(file), "': cannot be read"));
    check_nesting(text, file, true);
    toml::table root;
    try {
        root = toml::parse(text, file);
    } catch (const toml::parse_error& e) {
        throw Error(str(file, ":", e.source().begin.line, ":", e.source().begin.column, ": TOML syntax error: ",
                        e.description()));
    }
    Source source{file, {}, limits};
    if (quick) {
        if (const toml::node* node = root.get("quick")) {
            if (!node->is_table())
                Fields(root, "", source, {}).fail(*node, "quick", "must be a table of overrides (field = value)");
            std::vector<std::pair<std::string, const toml::node*>> leaves;
            flatten(*node->as_table(), "", leaves);
            toml::table copy = root;
            for (const auto& [key, value] : leaves) {
                const std::string option = str("[quick] ", key, " (line ", value->source().begin.line, ")");
                assign(copy, split_path(key), 0, *value, str(file, ": ", option));
                source.overrides.emplace_back(key, option);
            }
            root = std::move(copy);
        }
    }
    for (const std::string& setting : overrides) {
        apply_override(root, setting, str(clipped(file), ": --set ", clipped(setting)));
        source.overrides.emplace_back(setting.substr(0, setting.find('=')), "--set " + setting);
    }

    const Fields top(root, "", source, {"title", "gravity", "body", "time", "solver", "auto", "output", "skin", "obstacle",
                                        "contact", "quick"});
    SceneSpec scene;
    scene.file = path;
    scene.title = top.text("title", path.stem().string());
    scene.gravity = top.vector("gravity", scene.gravity);

    if (const toml::table* time_table = top.subtable("time")) {
        const Fields time(*time_table, "time", source, {"step", "duration", "integrator"});
        scene.time_step = time_step_field(time, "step", scene.time_step);
        scene.duration = time.number("duration", scene.duration, [](double d) { return d > 0.0 && d <= 3600.0; },
                                     "a number in (0, 3600] (seconds)");
        scene.integrator = time.text("integrator", scene.integrator, dynamics::integrator_names());
        try {
            dynamics::step_count(scene.duration, scene.time_step);
        } catch (const Error& e) {
            time.fail(time.has("duration") ? *time.get("duration") : *time_table, "duration", e.what());
        }
    }
    if (const toml::table* solver_table = top.subtable("solver")) {
        const Fields solver(*solver_table, "solver", source, {"name", "newton_tolerance"});
        scene.solver = solver.text("name", scene.solver);
        scene.newton_tolerance = solver.number("newton_tolerance", scene.newton_tolerance,
                                               [](double t) { return t > 0.0 && t < 1.0; }, "a number in (0, 1)");
    }
    if (const toml::table* auto_table = top.subtable("auto")) {
        const Fields a(*auto_table, "auto", source,
                       {"rotation", "ghost_ratio", "strain", "volume_ratio", "hysteresis", "hyperelastic"});
        const double degrees = std::acos(-1.0) / 180.0;
        scene.thresholds.rotation =
            a.number("rotation", scene.thresholds.rotation / degrees, [](double x) { return x > 0.0 && x < 90.0; },
                     "a number in (0, 90) (degrees)") * degrees;
        scene.thresholds.ghost_ratio = a.number("ghost_ratio", scene.thresholds.ghost_ratio,
                                                [](double x) { return x > 0.0 && x <= 1.0; }, "a number in (0, 1]");
        scene.thresholds.strain = a.number("strain", scene.thresholds.strain, [](double x) { return x > 0.0 && x < 1.0; },
                                           "a number in (0, 1)");
        scene.thresholds.volume_ratio = a.number("volume_ratio", scene.thresholds.volume_ratio,
                                                 [](double x) { return x > 0.0 && x < 1.0; }, "a number in (0, 1)");
        scene.thresholds.hysteresis = a.number("hysteresis", scene.thresholds.hysteresis,
                                               [](double x) { return x > 0.0 && x <= 1.0; }, "a number in (0, 1]");
        scene.thresholds.hyperelastic =
            a.text("hyperelastic", scene.thresholds.hyperelastic, hyper::material_names());
    }
    if (const toml::table* output_table = top.subtable("output")) {
        const Fields o(*output_table, "output", source,
                       {"frame_rate", "pvd", "png", "video", "csv", "charts", "frame_box", "colour_range", "fields", "colour", "view_direction", "view_up",
                        "warp", "width", "height"});
        OutputSpec& out = scene.output;
        out.frame_rate = o.number("frame_rate", out.frame_rate, [](double f) { return f > 0.0 && f <= 1000.0; },
                                  "a number in (0, 1000] (frames per simulated second)");
        out.pvd = o.flag("pvd", out.pvd);
        out.png = o.flag("png", out.png);
        out.video = o.text("video", out.video, {"mp4", "gif", "none"});
        out.csv = o.flag("csv", out.csv);
        out.charts = o.flag("charts", out.charts);
        if (out.charts && !out.csv)
            o.fail(*o.get(o.has("charts") ? "charts" : "csv"), "charts", "are drawn from steps.csv: set csv = true or charts = false");
        if (out.png && !out.pvd)
            o.fail(*o.get(o.has("png") ? "png" : "pvd"), "png", "frames are rendered from the .pvd frames: set pvd = true or png = false");
        const std::vector<std::string> fields{"displacement", "velocity", "von Mises stress", "model"};
        out.fields = o.texts("fields", out.fields, fields);
        out.colour = o.text("colour", out.colour, fields);
        out.view_direction = o.vector("view_direction", out.view_direction, true);
        out.view_up = o.vector("view_up", out.view_up, true);
        out.warp = o.positive("warp", out.warp);
        if (o.has("frame_box")) {
            const toml::array& corners = o.array("frame_box", 2, "two corners [[x0, y0, z0], [x1, y1, z1]]");
            const toml::table corner_table{{"low", *corners.get(0)}, {"high", *corners.get(1)}};
            const Fields corner(corner_table, o.field("frame_box"), o.source(), {"low", "high"});
            const Eigen::Vector3d low = corner.vector("low", Eigen::Vector3d::Zero());
            const Eigen::Vector3d high = corner.vector("high", Eigen::Vector3d::Zero());
            if ((low.array() >= high.array()).any())
                o.fail(*o.get("frame_box"), "frame_box", "the first corner must be below the second in x, y and z");
            out.frame_box = std::array<double, 6>{low.x(), high.x(), low.y(), high.y(), low.z(), high.z()};
        }
        if (o.has("colour_range")) {
            const toml::array& range = o.array("colour_range", 2, "[low, high] with low < high");
            const double low = o.number_of(*range.get(0), "colour_range[0]", [](double) { return true; }, "a finite number");
            const double high = o.number_of(*range.get(1), "colour_range[1]", [low](double h) { return h > low; },
                                            "a finite number above colour_range[0]");
            out.colour_range = std::make_pair(low, high);
        }
        out.width = o.integer("width", out.width, 64, 4096);
        out.height = o.integer("height", out.height, 64, 4096);
        if (out.colour != "displacement" && std::find(out.fields.begin(), out.fields.end(), out.colour) == out.fields.end())
            o.fail(*output_table, "colour", str("'", out.colour, "' must be one of the fields written (output.fields)"));
        if (!out.png && !o.has("video"))
            out.video = "none";  // the default video is made from the PNG frames: none without them
        if (out.video != "none" && !out.png)
            o.fail(*o.get("video"), "video", "is made from the PNG frames: set png = true or video = \"none\"");
    }

    const toml::node* bodies = top.get("body");
    if (bodies == nullptr)
        top.missing("body", "give at least one [[body]] with its mesh and material");
    if (!bodies->is_array_of_tables())
        top.fail(*bodies, "body", str("must be an array of tables ([[body]]), got ", Fields::type_name(*bodies)));
    const toml::array& items = *bodies->as_array();
    std::set<std::string> names;
    for (std::size_t i = 0; i < items.size(); ++i) {
        const std::string name = str("body[", i, "]");
        scene.bodies.push_back(
            read_body(table_in_array(top, *items.get(i), "body"), name, source, path, scene.duration, scene.time_step,
                      static_cast<int>(i)));
        if (!names.insert(scene.bodies.back().name).second)
            top.fail(*items.get(i), name + ".name", str("'", scene.bodies.back().name, "' is the name of an earlier body"));
    }

    if (const toml::table* contact_table = top.subtable("contact")) {
        const Fields c(*contact_table, "contact", source, {"activation_distance", "friction_velocity"});
        scene.contact.activation_distance = c.positive("activation_distance", scene.contact.activation_distance);
        scene.contact.friction_velocity = c.positive("friction_velocity", scene.contact.friction_velocity);
    }
    if (const toml::node* obstacles = top.get("obstacle")) {
        if (!obstacles->is_array_of_tables())
            top.fail(*obstacles, "obstacle", str("must be an array of tables ([[obstacle]]), got ", Fields::type_name(*obstacles)));
        const toml::array& list = *obstacles->as_array();
        for (std::size_t i = 0; i < list.size(); ++i) {
            const std::string name = str("obstacle[", i, "]");
            scene.obstacles.push_back(read_obstacle(table_in_array(top, *list.get(i), "obstacle"), name, source, path,
                                                    scene.time_step, scene.contact.activation_distance));
            // No vertex may start inside: its barrier energy would be infinite. A mesh's distance is
            // unsigned (no inside): a body must start beyond d̂ of it, and no edge of its tets may
            // pass through a triangle (a body through a sheet may have every vertex far from it).
            const auto obstacle = make_obstacle(scene.obstacles.back());
            const auto* mesh = dynamic_cast<const contact::MeshObstacle*>(obstacle.get());
            const double clearance = mesh ? scene.contact.activation_distance : 0.0;
            for (const BodySpec& body : scene.bodies) {
                for (Eigen::Index v = 0; v < body.mesh.V.rows(); ++v) {
                    const double d = obstacle->distance(body.mesh.V.row(v).transpose(), 0.0);
                    if (!(d > clearance))
                        top.fail(*list.get(i), name,
                                 mesh ? str("body '", body.name, "' starts within contact.activation_distance = ", clearance,
                                            " m of it (vertex ", v, " at ", d, " m from its triangles; a mesh's distance ",
                                            "is unsigned, so a body must start clear of it): move the body or the obstacle")
                                      : str("body '", body.name, "' starts inside it (vertex ", v, " at ", d,
                                            " m from its surface): move the body or the obstacle"));
                }
                for (Eigen::Index t = 0; mesh && t < body.mesh.T.rows(); ++t)
                    for (int j = 0; j < 4; ++j)
                        for (int k = j + 1; k < 4; ++k)
                            if (mesh->crosses(body.mesh.V.row(body.mesh.T(t, j)).transpose(),
                                              body.mesh.V.row(body.mesh.T(t, k)).transpose()))
                                top.fail(*list.get(i), name,
                                         str("body '", body.name, "' starts through it (the edge of tet ", t, " from vertex ",
                                             body.mesh.T(t, j), " to ", body.mesh.T(t, k), " crosses a triangle): ",
                                             "move the body or the obstacle"));
            }
        }
        if (scene.integrator != "backward-euler") {
            const toml::table& time_table = *top.subtable("time");  // where a non-default integrator was set
            Fields(time_table, "time", source, {})
                .fail(*time_table.get("integrator"), "integrator",
                      str("'", scene.integrator, "' is not for a scene with obstacles, whose contact steps are ",
                          "Newton backward Euler (chapter 14): use backward-euler"));
        }
    }
    if (const toml::table* skin_table = top.subtable("skin")) {
        const Fields s(*skin_table, "skin", source, {"file", "body"});
        SkinSpec skin;
        if (!s.has("file"))
            s.missing("file", "the fine surface (.obj, .stl, .ply) the tets carry");
        skin.file = resolve(path, s.text("file", ""));
        if (!file_exists(skin.file))
            s.fail(*s.get("file"), "file", str("no such file: ", clipped(skin.file.string()), " (looked beside the scene file, then in the data folder)"));
        skin.body = s.text("body", scene.bodies.front().name);
        if (!names.count(skin.body))
            s.fail(*s.get("body"), "body", str("no body is called '", skin.body, "'"));
        scene.skin = skin;
    }
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
        const BodySpec& body = scene.bodies[i];
        const bool hyper = body.model != "linear" && body.model != "corotational";
        if (hyper && scene.integrator != "backward-euler")
            throw Error(str(file, ": time.integrator: '", scene.integrator, "' is not for body[", i, "].material.model = '",
                            body.model, "', which steps with Newton backward Euler only: use backward-euler"));
        try {
            dynamics::validate(dynamics_scene(scene, body));
        } catch (const Error& e) {
            throw Error(str(file, ": ", body.name, ": ", e.what()));
        }
    }
    return scene;
}

MemoryEstimate memory_estimate(long long vertices, long long tets)
{
    MemoryEstimate e;
    e.dofs = 3 * vertices;
    // A fill-reducing ordering of a 3D mesh of n vertices leaves about n^(4/3) nonzero 3x3 blocks in
    // the Cholesky factor (nested dissection's bound, George 1973); the per-tet and per-vertex bytes
    // cover the mesh, the matrices, every model's per-tet data and the frames, chosen to err high.
    e.factor_nonzeros = 9.0 * fill_per_vertex_block * std::pow(static_cast<double>(vertices), 4.0 / 3.0);
    e.bytes = bytes_per_tet * static_cast<double>(tets) + bytes_per_vertex * static_cast<double>(vertices) +
              12.0 * e.factor_nonzeros;
    return e;
}

std::vector<std::filesystem::path> input_files(const SceneSpec& scene)
{
    std::vector<std::filesystem::path> files{scene.file};
    for (const BodySpec& body : scene.bodies) {
        const std::filesystem::path& mesh = body.mesh_spec.file;
        if (mesh.empty())
            continue;
        files.push_back(mesh);
        if (mesh.extension() == ".node" || mesh.extension() == ".ele")
            files.push_back(std::filesystem::path(mesh).replace_extension(mesh.extension() == ".node" ? ".ele" : ".node"));
    }
    if (scene.skin)
        files.push_back(scene.skin->file);
    for (const ObstacleSpec& obstacle : scene.obstacles)
        if (!obstacle.file.empty())
            files.push_back(obstacle.file);
    return files;
}

dynamics::Scene dynamics_scene(const SceneSpec& scene, const BodySpec& body)
{
    return dynamics::Scene{.mesh = body.mesh, .material = body.material, .pinned = body.pinned,
                           .gravity = scene.gravity, .damping = body.damping, .mass = body.mass,
                           .time_step = scene.time_step, .duration = scene.duration};
}

std::shared_ptr<const contact::Obstacle> make_obstacle(const ObstacleSpec& spec)
{
    switch (spec.kind) {
    case ObstacleSpec::Kind::half_space:
        return std::make_shared<contact::HalfSpace>(spec.point, spec.normal, spec.friction, spec.velocity);
    case ObstacleSpec::Kind::sphere:
        return std::make_shared<contact::Sphere>(spec.center, spec.radius, spec.friction, spec.velocity);
    case ObstacleSpec::Kind::mesh:
        return std::make_shared<contact::MeshObstacle>(spec.surface, spec.friction, spec.velocity, spec.file.string());
    case ObstacleSpec::Kind::box:
        break;
    }
    const Eigen::Matrix3d rotation = Eigen::AngleAxisd(spec.angle, spec.axis).toRotationMatrix();
    return std::make_shared<contact::Box>(spec.center, 0.5 * spec.size, rotation, spec.friction, spec.velocity);
}

std::vector<int> select_vertices(const TetMesh& mesh, const Selector& selector)
{
    std::vector<int> out;
    const Eigen::Index n = mesh.V.rows();
    const double diagonal = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm();
    const double tolerance = 1e-6 * diagonal;
    if (selector.kind == Selector::Kind::vertices) {
        std::set<int> unique;
        for (int v : selector.vertices) {
            if (v < 0 || v >= n)
                throw Error(str(selector.where, ": vertex ", v, " does not exist (the mesh has ", n, " vertices)"));
            unique.insert(v);
        }
        out.assign(unique.begin(), unique.end());
    }
    for (Eigen::Index v = 0; v < n && selector.kind != Selector::Kind::vertices; ++v) {
        const Eigen::Vector3d x = mesh.V.row(v).transpose();
        bool in = false;
        if (selector.kind == Selector::Kind::box) {
            in = ((x.array() >= selector.low.array() - tolerance) && (x.array() <= selector.high.array() + tolerance)).all();
        } else {
            const double distance = selector.normal.dot(x - selector.point);
            in = selector.below ? distance <= tolerance : std::abs(distance) <= tolerance;
        }
        if (in)
            out.push_back(static_cast<int>(v));
    }
    if (out.empty()) {
        const Eigen::RowVector3d low = mesh.V.colwise().minCoeff(), high = mesh.V.colwise().maxCoeff();
        throw Error(str(selector.where, ": selects no vertex of the mesh, which spans [", low.x(), ", ", high.x(),
                        "] x [", low.y(), ", ", high.y(), "] x [", low.z(), ", ", high.z(), "] m"));
    }
    return out;
}

Eigen::Vector3d prescribed_displacement(const Motion& motion, const Eigen::Vector3d& X, double t)
{
    if (motion.kind == Motion::Kind::fixed)
        return Eigen::Vector3d::Zero();
    const double tau = std::clamp((t - motion.start) / (motion.end - motion.start), 0.0, 1.0);
    const double s = tau * tau * (3.0 - 2.0 * tau);
    if (motion.kind == Motion::Kind::translate)
        return s * motion.displacement;
    const Eigen::Matrix3d R = Eigen::AngleAxisd(s * motion.angle, motion.axis).toRotationMatrix();
    return R * (X - motion.center) + motion.center - X;
}

}  // namespace fem::scenes
