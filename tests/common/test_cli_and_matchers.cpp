// The shared command line of the chapter executables (a bad option is "error: …" and exit 1) and
// the entry-by-entry matrix matcher of test_support.hpp (it names the entry that differs).
#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/test_support.hpp"

#include <catch2/catch.hpp>

#include <Eigen/SparseCore>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <new>
#include <sstream>
#include <stdexcept>
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

/// check_options: the chapter's check of options together (none when empty); setup: what the
/// chapter tells the command line before it runs (its inputs, its entries); body: the run's work.
CliRun run_cli(std::vector<std::string> args, const std::function<void()>& check_options = {},
               const std::function<void(fem::ChapterCli&)>& setup = {},
               const std::function<void(const fem::RunContext&)>& body = {})
{
    fem::ChapterCli cli("ch00_test", "00_test", "A test of the shared command line");
    if (setup)
        setup(cli);
    double c = 1.0;
    int n = 3;
    cli.app.add_option("--c", c, "A chapter option")->capture_default_str();
    cli.app.add_option("--n", n, "A checked chapter option")->check(fem::check::integer(1, 10));
    if (check_options)
        cli.check_options(check_options);
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
        if (body)
            body(context);
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

namespace {

/// The message of `check` for `text`: empty when it accepts it.
std::string refusal(const CLI::Validator& check, std::string text) { return check(text); }

}  // namespace

TEST_CASE("the option checks refuse non-numbers, NaN, infinity and values out of range, saying what is allowed", "[cli]")
{
    using namespace fem::check;
    constexpr double unbounded = std::numeric_limits<double>::infinity();
    CHECK(refusal(positive(), "0.5").empty());
    CHECK(refusal(positive(), "1e-300").empty());
    for (const char* bad : {"0", "-1", "nan", "inf", "1e999", "hot", "", " 1", "1x"})
        CHECK_THAT(refusal(positive(), bad), Contains("must be a finite number > 0, got '" + std::string(bad) + "'"));
    CHECK(refusal(non_negative(), "0").empty());
    CHECK_FALSE(refusal(non_negative(), "-0.1").empty());
    CHECK(refusal(finite(), "-1e300").empty());
    CHECK_THAT(refusal(finite(), "-inf"), Contains("must be a finite number, got '-inf'"));

    const CLI::Validator poisson = real(-1.0, 0.5, Ends::open);
    CHECK(refusal(poisson, "0.49").empty());
    CHECK_THAT(refusal(poisson, "0.5"), Contains("must be a number in (-1, 0.5)"));
    CHECK_FALSE(refusal(poisson, "-1").empty());
    CHECK(refusal(real(0.0, 0.24, Ends::open_closed), "0.24").empty());
    CHECK_THAT(refusal(real(0.0, 0.24, Ends::open_closed), "0"), Contains("a number in (0, 0.24]"));
    CHECK(refusal(real(0.0, unbounded, Ends::closed_open), "0").empty());
    CHECK(refusal(real(-unbounded, 2.0, Ends::closed), "2").empty());
    CHECK_THAT(refusal(real(-unbounded, 2.0, Ends::closed), "3"), Contains("a finite number <= 2"));

    CHECK(refusal(integer(3, 10), "3").empty());
    CHECK(refusal(integer(3, 10), "+10").empty());
    for (const char* bad : {"2", "11", "-1", "3.0", "1e1", "three", "", "99999999999999999999"})
        CHECK_THAT(refusal(integer(3, 10), bad), Contains("must be an integer in [3, 10], got"));
    CHECK_THAT(refusal(at_least(0u), "-1"), Contains("must be an integer >= 0 (at most 4294967295)"));
    CHECK_FALSE(refusal(at_least(0u), "4294967296").empty());
    CHECK(refusal(at_least(0u), "4294967295").empty());

    const CLI::Validator word = accepted_by([](const std::string& text) {
        if (text != "cn")
            throw fem::Error("use cn");
    });
    CHECK(refusal(word, "cn").empty());
    CHECK(refusal(word, "rk4") == "use cn");
}

TEST_CASE("a checked option out of range is 'error: …' naming it, and nothing runs", "[cli]")
{
    const CliRun run = run_cli({"--n", "0"});
    CHECK(run.code == 1);
    CHECK_FALSE(run.body_ran);
    CHECK_THAT(run.err, Contains("error: --n: must be an integer in [1, 10], got '0'"));
    CHECK(run.out.empty());
}

TEST_CASE("an fem::Error of the chapter's check_options is 'error: …' and exit 1, before the body runs", "[cli]")
{
    const std::string out_dir = fem::test::fresh_output_dir("cli_check_options").string();
    const CliRun refused = run_cli({"--no-figures", "--out", out_dir + "/out"},
                                   [] { throw fem::Error("--c and --n do not go together"); });
    CHECK(refused.code == 1);
    CHECK_FALSE(refused.body_ran);
    CHECK_THAT(refused.err, Contains("error: --c and --n do not go together"));
    CHECK_FALSE(std::filesystem::exists(out_dir + "/out"));  // the output folder was not created
    bool checked = false;
    const CliRun accepted = run_cli({"--no-figures", "--out", out_dir + "/out"}, [&] { checked = true; });
    CHECK(accepted.code == 0);
    CHECK(checked);
    CHECK(accepted.body_ran);
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

TEST_CASE("an empty --out is refused before anything is written (issue 23, row 7)", "[cli]")
{
    const std::filesystem::path here = std::filesystem::current_path();
    const bool had_manifest = std::filesystem::exists(here / ".fem-run-files");
    const CliRun run = run_cli({"--no-figures", "--out", ""});
    CHECK(run.code == 1);
    CHECK_FALSE(run.body_ran);
    CHECK_THAT(run.err, Contains("error: --out: must name a folder, got an empty text"));
    CHECK(std::filesystem::exists(here / ".fem-run-files") == had_manifest);  // nothing published here
}

TEST_CASE("any exception is one line 'error: …' and exit 1, and one that is not an fem::Error is an internal error to report", "[cli]")
{
    const std::string out_dir = fem::test::fresh_output_dir("cli_internal_error").string();
    // In the options' check (it was std::terminate there) and in the run itself.
    const CliRun in_check = run_cli({"--no-figures", "--out", out_dir + "/out"},
                                    [] { throw std::out_of_range("stoul"); });
    const CliRun in_body = run_cli({"--no-figures", "--out", out_dir + "/out"}, {}, {},
                                   [](const fem::RunContext&) { throw std::out_of_range("stoul"); });
    for (const CliRun& run : {in_check, in_body}) {
        CHECK(run.code == 1);
        CHECK_THAT(run.err, Contains("error: internal error: stoul") && Contains("please report it"));
        CHECK(std::count(run.err.begin(), run.err.end(), '\n') == 1);  // one line
    }
    CHECK_FALSE(in_check.body_ran);
    CHECK_FALSE(std::filesystem::exists(out_dir + "/out"));
    const CliRun memory = run_cli({"--no-figures", "--out", out_dir + "/out"}, {}, {},
                                  [](const fem::RunContext&) { throw std::bad_alloc(); });
    CHECK(memory.code == 1);
    CHECK_THAT(memory.err, Contains("error: out of memory"));
}

TEST_CASE("an --out that is, lies inside or holds an input is refused before anything runs (issue 23, rows 3 and 10)", "[cli]")
{
    const std::filesystem::path dir = fem::test::fresh_output_dir("cli_inputs");
    const std::filesystem::path scene = dir / "proj" / "mybar.toml";
    fem::write_file(scene, "title = 'mine'\n");
    const auto inputs = [&](fem::ChapterCli& cli) { cli.protect_inputs({scene}); };
    for (const std::filesystem::path& out : {dir / "proj", dir, scene, dir / "proj" / "." / "mybar.toml" / "x"}) {
        INFO(out);
        const CliRun run = run_cli({"--no-figures", "--out", out.string()}, {}, inputs);
        CHECK(run.code == 1);
        CHECK_FALSE(run.body_ran);
        CHECK_THAT(run.err, Contains("error: --out: '" + out.string() + "'") && Contains("the input '" + scene.string()));
    }
    CHECK(std::filesystem::exists(scene));
    CHECK(run_cli({"--no-figures", "--out", (dir / "elsewhere").string()}, {}, inputs).code == 0);
}

TEST_CASE("an entry the run writes does not replace one of the same name that no earlier run wrote (issue 23, row 3)", "[cli]")
{
    const std::filesystem::path out = fem::test::fresh_output_dir("cli_entries");
    fem::write_file(out / "mybar" / "mesh.node", "the user's mesh");
    const auto frames = [](fem::ChapterCli& cli) { cli.writes_entry("mybar"); };
    const auto write_frames = [](const fem::RunContext& run) { fem::write_file(run.file("mybar") / "f.vtu", "frame"); };
    const CliRun refused = run_cli({"--no-figures", "--out", out.string()}, {}, frames, write_frames);
    CHECK(refused.code == 1);
    CHECK_FALSE(refused.body_ran);
    CHECK_THAT(refused.err, Contains("mybar' exists and was not written by an earlier run"));
    CHECK(std::filesystem::exists(out / "mybar" / "mesh.node"));
    // A folder an earlier run wrote (listed in .fem-run-files) is the run's to replace.
    std::filesystem::remove_all(out / "mybar");
    CHECK(run_cli({"--no-figures", "--out", out.string()}, {}, frames, write_frames).code == 0);
    CHECK(run_cli({"--no-figures", "--out", out.string()}, {}, frames, write_frames).code == 0);
    CHECK(std::filesystem::exists(out / "mybar" / "f.vtu"));
}

TEST_CASE("a .fem-run-files that names anything but plain entries of --out is ignored with a warning (issue 23, row 10)", "[cli]")
{
    const std::filesystem::path out = fem::test::fresh_output_dir("cli_forged_list");
    fem::write_file(out / "keep.csv", "not this run's");
    fem::write_file(out / ".fem-run-files", "keep.csv\n../victim\n");
    const CliRun run = run_cli({"--no-figures", "--out", out.string()});
    CHECK(run.code == 0);
    CHECK_THAT(run.err, Contains("warning: ") && Contains(".fem-run-files:2: '../victim' is not a file name of this folder"));
    CHECK(std::filesystem::exists(out / "keep.csv"));  // the list was not followed
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
