#pragma once
// A table of results: printed to the terminal, saved as CSV, and plotted from its columns.
//
// Column naming rule (tools/check_run.py and tools/check_docs.py rely on it): a column whose value
// depends on the machine (a wall time, a rate, a bandwidth) carries its unit in brackets with a
// time in it: "time [s]", "rate [1/s]", "bandwidth [GB/s]", or "[measured]" for a machine-dependent
// ratio ("fraction of triad [measured]"). Those columns are reported but never compared against
// stored numbers; every other column must reproduce. Round-off is held to a bound, not to its
// digits: a stored value ≤ 1e-12 passes while it stays ≤ 1e-10, and a column named "… [round-off]"
// (round-off amplified by a condition number) passes while it grows less than 100×; a column named
// "… [±X]" holds values known to ±X (digits below X are round-off), and an "iterations" column
// agrees within one iteration (see tools/csv_compare.py). A parameter with a unit is written "dt (s)", not "dt [s]".

#include <filesystem>
#include <iosfwd>
#include <string>
#include <variant>
#include <vector>

namespace fem {

/// text as one CSV field: quoted (with inner quotes doubled) when it holds a comma, quote or newline.
std::string csv_field(const std::string& text);

/// How a column's numbers are printed in the terminal (the CSV always keeps full precision).
enum class Format { scientific, fixed, integer, text };

struct Column {
    std::string name;
    Format format = Format::scientific;
    int precision = 3;  ///< digits after the point for scientific and fixed
};

/// One cell: a number or a text (e.g. a method name, "blew up").
using Cell = std::variant<double, std::string>;

class Table {
public:
    /// title is printed above the table; columns fix the order and format of each row's cells.
    Table(std::string title, std::vector<Column> columns);

    /// Appends a row; it must have one cell per column (fem::Error otherwise).
    void add_row(std::vector<Cell> cells);

    const std::string& title() const { return title_; }
    const std::vector<Column>& columns() const { return columns_; }
    std::size_t rows() const { return rows_.size(); }
    const Cell& cell(std::size_t row, std::size_t column) const { return rows_.at(row).at(column); }

    /// The numbers of one column, by name (fem::Error if absent or a cell holds text).
    std::vector<double> numbers(const std::string& column_name) const;

    /// Prints the title and an aligned table.
    void print(std::ostream& out) const;

    /// Writes the table as CSV (header row, then full-precision numbers), atomically.
    void write_csv(const std::filesystem::path& path) const;

private:
    std::string title_;
    std::vector<Column> columns_;
    std::vector<std::vector<Cell>> rows_;
};

}  // namespace fem
