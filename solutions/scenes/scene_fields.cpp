// The scene reader's toolbox: the nesting check of a TOML text, the field checker's helpers and the
// lookup of the files a scene names. docs/scenes.md#the-scene-file
#include "scenes/scene_fields.hpp"

#include "common/files.hpp"

namespace fem::scenes::detail {

std::string joined(const std::vector<std::string>& names)
{
    std::string out;
    for (const std::string& name : names)
        out += (out.empty() ? "" : ", ") + name;
    return out;
}

std::string clipped(const std::string& text)
{
    constexpr std::size_t most = 200;
    if (text.size() <= most)
        return text;
    return str(text.substr(0, 100), "[... ", text.size() - 180, " characters ...]", text.substr(text.size() - 80));
}

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

const toml::table& table_in_array(const Fields& parent, const toml::node& node, const std::string& item)
{
    if (!node.is_table())
        parent.fail(node, item, str("must be a table, got ", Fields::type_name(node)));
    return *node.as_table();
}

bool file_exists(const std::filesystem::path& path)
{
    std::error_code ec;
    return std::filesystem::is_regular_file(path, ec);
}

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

std::filesystem::path existing_file(const Fields& fields, const std::string& key, const std::filesystem::path& scene_file)
{
    const std::filesystem::path path = resolve(scene_file, fields.text(key, ""));
    if (!file_exists(path))
        fields.fail(*fields.get(key), key,
                    str("no such file: ", clipped(path.string()), " (looked beside the scene file, then in the data folder)"));
    return path;
}

}  // namespace fem::scenes::detail
