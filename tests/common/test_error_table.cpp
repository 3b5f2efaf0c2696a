// Errors, the exercise switch, tables and atomic writes.
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/table.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>

using Catch::Matchers::Contains;

TEST_CASE("NotImplemented names the exercise, the function and the docs, and is no fem::Error",
          "[common]")
{
    const fem::NotImplemented e("05.2", "strain_displacement_matrix", "docs/05_strain_stress.md#b");
    CHECK_THAT(e.what(), Contains("05.2") && Contains("strain_displacement_matrix") &&
                             Contains("docs/05_strain_stress.md#b"));
    // A stub must never satisfy a test that expects an fem::Error for bad input.
    CHECK_THROWS_AS(throw fem::NotImplemented("01.1", "f", "docs"), std::logic_error);
    const bool is_fem_error = std::is_base_of_v<fem::Error, fem::NotImplemented>;
    CHECK_FALSE(is_fem_error);
}

TEST_CASE("require_positive and require_finite reject what they must", "[common]")
{
    CHECK_NOTHROW(fem::require_positive(1e-300, "h"));
    CHECK_THROWS_WITH(fem::require_positive(0.0, "step h"), Contains("step h") && Contains("> 0"));
    CHECK_THROWS_AS(fem::require_positive(-1.0, "h"), fem::Error);
    CHECK_THROWS_AS(fem::require_positive(std::nan(""), "h"), fem::Error);
    CHECK_THROWS_AS(fem::require_positive(std::numeric_limits<double>::infinity(), "h"), fem::Error);
    CHECK_THROWS_AS(fem::require_finite(std::nan(""), "x"), fem::Error);
    CHECK_NOTHROW(fem::require_finite(-3.0, "x"));
}

TEST_CASE("a table prints aligned columns and writes full-precision CSV", "[common]")
{
    fem::Table table("errors", {{"h", fem::Format::scientific, 2},
                                {"method", fem::Format::text},
                                {"steps", fem::Format::integer}});
    table.add_row({0.1, std::string("forward, one-sided"), 10.0});
    table.add_row({1.0 / 3.0, std::string("central"), 20.0});
    CHECK_THROWS_AS(table.add_row({1.0}), fem::Error);
    CHECK(table.numbers("steps") == std::vector<double>{10.0, 20.0});
    CHECK_THROWS_AS(table.numbers("method"), fem::Error);
    CHECK_THROWS_AS(table.numbers("nope"), fem::Error);

    std::ostringstream printed;
    table.print(printed);
    CHECK_THAT(printed.str(), Contains("1.00e-01") && Contains("central") && Contains("20"));

    const auto dir = fem::test::fresh_output_dir("table");
    table.write_csv(dir / "errors.csv");
    std::ifstream file(dir / "errors.csv");
    std::string header, first, second;
    std::getline(file, header);
    std::getline(file, first);
    std::getline(file, second);
    CHECK(header == "h,method,steps");
    CHECK(first == "0.10000000000000001,\"forward, one-sided\",10");
    CHECK(std::stod(second.substr(0, second.find(','))) == 1.0 / 3.0);
}

TEST_CASE("a failed atomic write leaves the old file and no temporary behind", "[common]")
{
    const auto dir = fem::test::fresh_output_dir("atomic");
    const auto path = dir / "result.txt";
    fem::write_atomically(path, [](const std::filesystem::path& tmp) { std::ofstream(tmp) << "old"; });
    CHECK_THROWS_AS(fem::write_atomically(path,
                                          [](const std::filesystem::path& tmp) {
                                              std::ofstream(tmp) << "half";
                                              throw fem::Error("disk full");
                                          }),
                    fem::Error);
    std::ifstream file(path);
    std::string content;
    file >> content;
    CHECK(content == "old");
    int files = 0;
    for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir))
        ++files;
    CHECK(files == 1);
}

TEST_CASE("exercise_stubbed reads the grading switch", "[common]")
{
    // The switch is read once per process; this process was started without it.
    if (std::getenv("FEM_STUB_EXERCISE") == nullptr)
        CHECK_FALSE(fem::exercise_stubbed("01.1"));
}

TEST_CASE("data_path finds shipped data and rejects missing files", "[common]")
{
    CHECK_THROWS_WITH(fem::data_path("no_such_mesh.obj"), Contains("no_such_mesh.obj"));
}

TEST_CASE("data_path finds the shipped bunny from any working folder", "[common]")
{
    const auto previous = std::filesystem::current_path();
    std::filesystem::current_path(std::filesystem::temp_directory_path());
    const auto path = fem::data_path("bunny.obj");
    std::filesystem::current_path(previous);
    CHECK(std::filesystem::is_regular_file(path));
}
