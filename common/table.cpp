#include "common/table.hpp"

#include "common/error.hpp"
#include "common/files.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <ostream>

namespace fem {
namespace {

std::string format_cell(const Cell& cell, const Column& column)
{
    if (const auto* text = std::get_if<std::string>(&cell))
        return *text;
    const double value = std::get<double>(cell);
    char buffer[64];
    switch (column.format) {
    case Format::integer:
        std::snprintf(buffer, sizeof buffer, "%.0f", value);
        break;
    case Format::fixed:
        std::snprintf(buffer, sizeof buffer, "%.*f", column.precision, value);
        break;
    case Format::scientific:
    case Format::text:
        std::snprintf(buffer, sizeof buffer, "%.*e", column.precision, value);
        break;
    }
    return buffer;
}

}  // namespace

std::string csv_field(const std::string& text)
{
    if (text.find_first_of(",\"\n") == std::string::npos)
        return text;
    std::string quoted = "\"";
    for (char c : text) {
        if (c == '"')
            quoted += '"';
        quoted += c;
    }
    return quoted + "\"";
}

Table::Table(std::string title, std::vector<Column> columns)
    : title_(std::move(title)), columns_(std::move(columns))
{
    if (columns_.empty())
        throw Error(str("table '", title_, "' needs at least one column"));
}

void Table::add_row(std::vector<Cell> cells)
{
    if (cells.size() != columns_.size())
        throw Error(str("table '", title_, "': a row has ", cells.size(), " cells, the table has ",
                        columns_.size(), " columns"));
    rows_.push_back(std::move(cells));
}

std::vector<double> Table::numbers(const std::string& column_name) const
{
    const auto it = std::find_if(columns_.begin(), columns_.end(),
                                 [&](const Column& c) { return c.name == column_name; });
    if (it == columns_.end())
        throw Error(str("table '", title_, "' has no column '", column_name, "'"));
    const auto index = static_cast<std::size_t>(it - columns_.begin());
    std::vector<double> values;
    for (std::size_t r = 0; r < rows_.size(); ++r) {
        const auto* number = std::get_if<double>(&rows_[r][index]);
        if (!number)
            throw Error(str("table '", title_, "', column '", column_name, "', row ", r,
                            " holds text, not a number"));
        values.push_back(*number);
    }
    return values;
}

void Table::print(std::ostream& out) const
{
    std::vector<std::vector<std::string>> text(rows_.size());
    std::vector<std::size_t> width(columns_.size());
    for (std::size_t c = 0; c < columns_.size(); ++c)
        width[c] = columns_[c].name.size();
    for (std::size_t r = 0; r < rows_.size(); ++r)
        for (std::size_t c = 0; c < columns_.size(); ++c) {
            text[r].push_back(format_cell(rows_[r][c], columns_[c]));
            width[c] = std::max(width[c], text[r][c].size());
        }
    auto line = [&](auto&& cell_text) {
        for (std::size_t c = 0; c < columns_.size(); ++c) {
            const std::string s = cell_text(c);
            out << (c ? "  " : "") << std::string(width[c] - s.size(), ' ') << s;
        }
        out << '\n';
    };
    out << '\n' << title_ << '\n';
    line([&](std::size_t c) { return columns_[c].name; });
    line([&](std::size_t c) { return std::string(width[c], '-'); });
    for (std::size_t r = 0; r < rows_.size(); ++r)
        line([&](std::size_t c) { return text[r][c]; });
    out.flush();
}

void Table::write_csv(const std::filesystem::path& path) const
{
    std::ostringstream file;
    for (std::size_t c = 0; c < columns_.size(); ++c)
        file << (c ? "," : "") << csv_field(columns_[c].name);
    file << '\n';
    char buffer[64];
    for (const auto& row : rows_) {
        for (std::size_t c = 0; c < row.size(); ++c) {
            file << (c ? "," : "");
            if (const auto* number = std::get_if<double>(&row[c])) {
                std::snprintf(buffer, sizeof buffer, "%.17g", *number);
                file << buffer;
            } else {
                file << csv_field(std::get<std::string>(row[c]));
            }
        }
        file << '\n';
    }
    write_file(path, file.str());
}

}  // namespace fem
