#pragma once
// Helpers shared by the tests of every chapter.

#include "common/files.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace fem::test {

/// A fresh, empty folder for the files one test writes: <build>/test_output/<chapter>/<name>.
inline std::filesystem::path fresh_output_dir(const std::string& name)
{
    const std::filesystem::path dir = std::filesystem::path(FEM_TEST_OUTPUT_DIR) / name;
    std::filesystem::remove_all(dir);
    fem::ensure_directory(dir);
    return dir;
}

/// A table of bad inputs and their errors (tests/common/bad_files/errors.txt,
/// tests/scenes/bad_scenes/errors.txt): one line "file  text", where text is what the file's error
/// must contain; a file may have several lines, one per text; '#' starts a comment line.
inline std::map<std::string, std::vector<std::string>> error_table(const std::filesystem::path& table)
{
    std::ifstream in(table);
    REQUIRE(in);
    std::map<std::string, std::vector<std::string>> expected;
    for (std::string line; std::getline(in, line);) {
        if (line.empty() || line.front() == '#')
            continue;
        std::istringstream fields(line);
        std::string name, text;
        fields >> name >> std::ws;
        std::getline(fields, text);
        REQUIRE_FALSE(text.empty());
        expected[name].push_back(text);
    }
    return expected;
}

/// The finite-difference sweep (HOBAK's habit): the relative errors ‖(g(h) − g(−h))/(2h) − exact‖ /
/// ‖exact‖ of central differences of g (any vector-valued function of a step h along one direction)
/// for h = scale·10⁻³, scale·10⁻⁴, …, scale·10⁻⁸. A correct derivative has a best error far below
/// 1e-6 and errors that first fall with h (as h², until round-off takes over); a wrong one stalls.
inline std::vector<double> central_difference_errors(const std::function<Eigen::VectorXd(double)>& g,
                                                     const Eigen::VectorXd& exact, double scale = 1.0)
{
    std::vector<double> errors;
    for (double h = 1e-3 * scale; h > 0.5e-8 * scale; h /= 10.0)
        errors.push_back(((g(h) - g(-h)) / (2.0 * h) - exact).norm() / exact.norm());
    return errors;
}

/// The smallest error of a sweep of central_difference_errors: what a correct derivative has far
/// below 1e-6.
inline double best_error(const std::vector<double>& errors)
{
    return *std::min_element(errors.begin(), errors.end());
}

/// Central differences of a potential (anything with energy(u) and gradient(u), u of n entries) at
/// u with step h along each coordinate eᵢ: gradient[i] = (E(u + h eᵢ) − E(u − h eᵢ))/(2h) (n) and
/// hessian's column i = (∇E(u + h eᵢ) − ∇E(u − h eᵢ))/(2h) (n×n, not symmetrised).
struct CentralDifferences {
    Eigen::VectorXd gradient;
    Eigen::MatrixXd hessian;
};
template <typename Potential>
CentralDifferences central_differences(const Potential& potential, const Eigen::VectorXd& u, double h)
{
    const Eigen::Index n = u.size();
    CentralDifferences differences{Eigen::VectorXd(n), Eigen::MatrixXd(n, n)};
    for (Eigen::Index i = 0; i < n; ++i) {
        Eigen::VectorXd e = Eigen::VectorXd::Zero(n);
        e[i] = h;
        differences.gradient[i] = (potential.energy(u + e) - potential.energy(u - e)) / (2.0 * h);
        differences.hessian.col(i) = (potential.gradient(u + e) - potential.gradient(u - e)) / (2.0 * h);
    }
    return differences;
}

/// The entries of a matrix or vector, dense or sparse, as compared by EntriesNear. Catch2 prints
/// it as its shape only ("a 12×12 matrix"): the matcher names the entries that matter.
struct MatrixEntries {
    Eigen::MatrixXd values;
};

/// What CHECK_THAT(entries_of(actual), EntriesNear(expected, ...)) compares: any Eigen matrix,
/// vector or sparse matrix, or an expression of them.
template <typename Matrix>
MatrixEntries entries_of(const Matrix& matrix)
{
    return {Eigen::MatrixXd(matrix)};
}

/// Catch2 matcher for a matrix compared entry by entry, as Catch's Approx compares one number:
/// |actual_ij − expected_ij| ≤ max(absolute, relative · |expected_ij|) for every entry, and the
/// same shape. On failure it says which entry
/// differs first (row, column, expected, got) and how many differ:
///
///     CHECK_THAT(entries_of(K), EntriesNear(K_expected, 1e-12 * scale));
class EntriesNear : public Catch::MatcherBase<MatrixEntries> {
public:
    /// expected: any Eigen matrix, vector or sparse matrix; absolute and relative: the tolerance.
    template <typename Matrix>
    explicit EntriesNear(const Matrix& expected, double absolute, double relative = 0.0)
        : expected_(expected), absolute_(absolute), relative_(relative)
    {
    }

    bool match(const MatrixEntries& actual) const override
    {
        const Eigen::MatrixXd& a = actual.values;
        std::ostringstream out;
        if (a.rows() != expected_.rows() || a.cols() != expected_.cols()) {
            out << "is not " << expected_.rows() << "×" << expected_.cols() << " like the expected matrix";
            report_ = out.str();
            return false;
        }
        Eigen::Index differing = 0;
        for (Eigen::Index j = 0; j < a.cols(); ++j)
            for (Eigen::Index i = 0; i < a.rows(); ++i) {
                const double want = expected_(i, j), got = a(i, j);
                if (std::abs(got - want) <= std::max(absolute_, relative_ * std::abs(want)))
                    continue;  // (a NaN on either side never passes)
                if (differing++ == 0) {
                    out.precision(17);
                    out << "differs at " << (a.cols() == 1 ? "entry " + std::to_string(i)
                                                            : "(" + std::to_string(i) + ", " + std::to_string(j) + ")")
                        << ": expected " << want << ", got " << got;
                }
            }
        if (differing > 1)
            out << " (and " << differing - 1 << " more of its " << a.size() << " entries)";
        report_ = out.str();
        return differing == 0;
    }

    std::string describe() const override
    {
        std::ostringstream out;
        out << "is within ";
        if (relative_ > 0.0)
            out << "max(" << absolute_ << ", " << relative_ << "·|expected|)";
        else
            out << absolute_;
        out << " of the expected matrix entry by entry";
        if (!report_.empty())
            out << ", but " << report_;
        return out.str();
    }

private:
    Eigen::MatrixXd expected_;
    double absolute_;
    double relative_;
    mutable std::string report_;  // what match() found, for describe()
};

}  // namespace fem::test

namespace Catch {

/// Prints the compared matrix as its shape; EntriesNear names the entries that differ.
template <>
struct StringMaker<fem::test::MatrixEntries> {
    static std::string convert(const fem::test::MatrixEntries& entries)
    {
        return "a " + std::to_string(entries.values.rows()) + "×" + std::to_string(entries.values.cols()) +
               " matrix";
    }
};

}  // namespace Catch
