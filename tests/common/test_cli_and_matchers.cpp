// The shared command line of the chapter executables (a bad option is "error: …" and exit 1) and
// the entry-by-entry matrix matcher of test_support.hpp (it names the entry that differs).
#include "common/cli.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/SparseCore>

#include <iostream>
#include <sstream>
#include <string>
#include <vector>

using Catch::Matchers::Contains;
using fem::test::EntriesNear;
using fem::test::entries_of;

namespace {

/// What ChapterCli::run returns and prints for the arguments `args` (after the program name).
struct CliRun {
    int code = -1;
    std::string out, err;
    bool body_ran = false;
};

CliRun run_cli(std::vector<std::string> args)
{
    fem::ChapterCli cli("ch00_test", "00_test", "A test of the shared command line");
    double c = 1.0;
    cli.app.add_option("--c", c, "A chapter option")->capture_default_str();
    args.insert(args.begin(), "ch00_test");
    std::vector<char*> argv;
    for (std::string& arg : args)
        argv.push_back(arg.data());
    std::ostringstream out, err;
    std::streambuf* const old_out = std::cout.rdbuf(out.rdbuf());
    std::streambuf* const old_err = std::cerr.rdbuf(err.rdbuf());
    CliRun run;
    run.code = cli.run(static_cast<int>(argv.size()), argv.data(), [&](const fem::RunContext& context) {
        run.body_ran = true;
        CHECK_FALSE(context.figures);  // every call below that gets here passes --no-figures
    });
    std::cout.rdbuf(old_out);
    std::cerr.rdbuf(old_err);
    run.out = out.str();
    run.err = err.str();
    return run;
}

}  // namespace

TEST_CASE("an unknown option is 'error: …' naming it, and exit code 1", "[cli]")
{
    const CliRun run = run_cli({"--colour", "red"});
    CHECK(run.code == 1);
    CHECK_FALSE(run.body_ran);
    CHECK_THAT(run.err, Contains("error: ") && Contains("--colour") && Contains("--help"));
    const CliRun bad_value = run_cli({"--c", "hot"});
    CHECK(bad_value.code == 1);
    CHECK_THAT(bad_value.err, Contains("error: ") && Contains("--c"));
}

TEST_CASE("the option --help lists the options without CLI11's default-value markup, and exits with 0", "[cli]")
{
    const CliRun run = run_cli({"--help"});
    CHECK(run.code == 0);
    CHECK_FALSE(run.body_ran);
    CHECK_THAT(run.out, Contains("--no-figures") && Contains("--quick") && Contains("--out"));
    CHECK_THAT(run.out, !Contains("{false}"));
}

TEST_CASE("the flag --no-figures turns the figures off", "[cli]")
{
    const std::string out_dir = fem::test::fresh_output_dir("cli").string();
    const CliRun run = run_cli({"--no-figures", "--out", out_dir});
    CHECK(run.code == 0);
    CHECK(run.body_ran);
}

TEST_CASE("EntriesNear passes within its tolerance and names the first entry that differs", "[matchers]")
{
    Eigen::MatrixXd expected(2, 3);
    expected << 1, 2, 3,
                4, 5, 6;
    Eigen::MatrixXd actual = expected;
    actual(1, 2) += 1e-10;
    CHECK(EntriesNear(expected, 1e-9).match(entries_of(actual)));
    CHECK(EntriesNear(expected, 0.0, 1e-10).match(entries_of(actual)));  // relative: 6e-10 allowed
    CHECK(EntriesNear(Eigen::SparseMatrix<double>(expected.sparseView()), 1e-9).match(entries_of(actual)));

    const EntriesNear exact(expected, 0.0);
    actual(0, 1) = 2.5;
    CHECK_FALSE(exact.match(entries_of(actual)));
    CHECK_THAT(exact.describe(), Contains("differs at (0, 1): expected 2, got 2.5") && Contains("1 more"));

    const EntriesNear vector(Eigen::Vector3d(1, 2, 3), 0.0);
    CHECK_FALSE(vector.match(entries_of(Eigen::Vector3d(1, 2, 4))));
    CHECK_THAT(vector.describe(), Contains("differs at entry 2: expected 3, got 4"));

    CHECK_FALSE(vector.match(entries_of(Eigen::Vector2d(1, 2))));
    CHECK_THAT(vector.describe(), Contains("is not 3×1"));
    CHECK_FALSE(vector.match(entries_of(Eigen::Vector3d(1, 2, std::nan("")))));
    CHECK(Catch::Detail::stringify(entries_of(expected)) == "a 2×3 matrix");
}
