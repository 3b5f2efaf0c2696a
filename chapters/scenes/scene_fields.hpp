#pragma once
// The scene reader's toolbox (solutions/scenes/scene_fields.cpp), internal to the reader
// (solutions/scenes/scene_*.cpp): the check of a TOML text's nesting before it is parsed, where the
// fields come from (the file, the overrides), the checked reading of one table's fields (Fields),
// and the lookup of the files a scene names. docs/scenes.md#the-scene-file

#include "scenes/scene_file.hpp"

#include "common/error.hpp"

#include <toml++/toml.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace fem::scenes::detail {

/// The names separated by ", ".
std::string joined(const std::vector<std::string>& names);

/// text itself, or when longer than 200 characters its start and end with the count between (a
/// name or key of megabytes is not echoed whole).
std::string clipped(const std::string& text);

/// Refuses TOML text nested deeper than max_nesting levels (tables of headers and dotted keys,
/// arrays and inline tables together) before toml++ parses it: its parser and the tables it builds
/// recurse once per level, and tens of thousands of levels overflow the stack. what names the text
/// (the file, or the --set option), followed by :line:column when with_position.
void check_nesting(std::string_view text, const std::string& what, bool with_position);

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
double time_step_field(const Fields& fields, const std::string& key, double fallback);

/// The table of an array of tables, checked to be one.
const toml::table& table_in_array(const Fields& parent, const toml::node& node, const std::string& item);

/// Whether path exists as a regular file; false, not an exception, for a name the system refuses
/// (too long). A folder, a device or a pipe is no mesh (reading a pipe could wait for ever).
bool file_exists(const std::filesystem::path& path);

/// The file a scene names: an absolute path as given, else beside the scene file, else in data/.
std::filesystem::path resolve(const std::filesystem::path& scene_file, const std::string& name);

/// The file the string field key names (resolve), which must exist: else an error at the field,
/// "no such file: <path> (looked beside the scene file, then in the data folder)".
std::filesystem::path existing_file(const Fields& fields, const std::string& key, const std::filesystem::path& scene_file);

}  // namespace fem::scenes::detail
