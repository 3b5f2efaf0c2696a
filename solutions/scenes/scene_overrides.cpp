// The overrides of a scene file: the [quick] table's fields and each --set key=value, applied to
// the file's tree before it is read, so an override is checked like the file itself.
// docs/scenes.md#the-scene-file
#include "scene_parts.hpp"

#include <algorithm>
#include <sstream>

namespace fem::scenes::detail {
namespace {

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

void apply_quick_table(toml::table& root, Source& source)
{
    const toml::node* node = root.get("quick");
    if (node == nullptr)
        return;
    if (!node->is_table())
        Fields(root, "", source, {}).fail(*node, "quick", "must be a table of overrides (field = value)");
    std::vector<std::pair<std::string, const toml::node*>> leaves;
    flatten(*node->as_table(), "", leaves);
    toml::table copy = root;
    for (const auto& [key, value] : leaves) {
        const std::string option = str("[quick] ", key, " (line ", value->source().begin.line, ")");
        assign(copy, split_path(key), 0, *value, str(source.file, ": ", option));
        source.overrides.emplace_back(key, option);
    }
    root = std::move(copy);
}

void apply_set_options(toml::table& root, const std::vector<std::string>& settings, Source& source)
{
    for (const std::string& setting : settings) {
        apply_override(root, setting, str(clipped(source.file), ": --set ", clipped(setting)));
        source.overrides.emplace_back(setting.substr(0, setting.find('=')), "--set " + setting);
    }
}

}  // namespace fem::scenes::detail
