#pragma once
// The command line every chapter executable shares (CLI11), and the guard around its main():
// options --out DIR, --quick, --no-figures, --help; any exception becomes one line "error: ..." and
// exit 1 (one that is not an fem::Error is a bug: "error: internal error: ... please report it").
// Every option is checked before anything is computed or written: its values by a check of
// fem::check (given to CLI11's ->check()), what depends on several options by
// ChapterCli::check_options.

#include <CLI/CLI.hpp>

#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace fem {

/// Checks of an option's values for CLI11's Option::check(), run while the command line is parsed.
/// Each one refuses text that is not a number, NaN and ±inf, and says what is allowed; CLI11 puts
/// the option's name in front: "error: --points: must be an integer >= 3, got '2'".
namespace check {

/// Which ends of an interval belong to it.
enum class Ends { open, closed, open_closed, closed_open };

/// A finite real number in the interval from low to high (±infinity: unbounded on that side),
/// with the ends given: real(-1, 0.5, Ends::open) is "a number in (-1, 0.5)".
CLI::Validator real(double low, double high, Ends ends);

/// A finite real number > 0.
CLI::Validator positive();

/// A finite real number >= 0.
CLI::Validator non_negative();

/// A finite real number (any sign).
CLI::Validator finite();

/// An integer in [low, high] (both included), written in decimal digits with an optional sign.
CLI::Validator integer(long long low, long long high);

/// An integer >= low that fits the option's type T (e.g. int): at_least<int>(3).
template <typename T>
CLI::Validator at_least(T low)
{
    return integer(static_cast<long long>(low), static_cast<long long>(std::numeric_limits<T>::max()));
}

/// A text that parse accepts: parse throws fem::Error for any other, and its message becomes the
/// option's error (e.g. check::accepted_by([](const std::string& s) { parse_scheme(s); })).
CLI::Validator accepted_by(std::function<void(const std::string&)> parse);

}  // namespace check

/// What a chapter's run needs to know about its invocation.
struct RunContext {
    /// Where every file of this run goes: a staging folder inside --out, whose files appear in
    /// --out together when the run succeeds (see ChapterCli::run).
    std::filesystem::path out_dir;
    bool quick = false;             ///< a small, fast run (ctest uses it)
    bool figures = true;            ///< write PNG figures (needs a display; see figures.hpp)

    /// out_dir / file_name
    std::filesystem::path file(const std::string& file_name) const { return out_dir / file_name; }
};

/// One chapter executable's command line. Add chapter options to app, then call run().
class ChapterCli {
public:
    /// executable "ch01_finite_differences", chapter "01_finite_differences" (default output
    /// folder out/01_finite_differences), description: one line for --help.
    ChapterCli(const std::string& executable, const std::string& chapter,
               const std::string& description);

    CLI::App app;

    /// Sets the check of what no single option's check can see (options that depend on each other, a
    /// file an option names): run() calls it after parsing, before the output folder is touched,
    /// and an fem::Error it throws is a bad command line (exit 1, nothing written).
    void check_options(std::function<void()> check);

    /// Names the files the run reads (a scene, its meshes, its skin); the check of check_options() may
    /// call it. run() refuses, before anything is written, an --out that is one of them, lies inside
    /// one, or holds one at any depth: publishing the run's files could replace or delete it.
    void protect_inputs(const std::vector<std::filesystem::path>& inputs);

    /// Names an entry (a file or folder name) the run writes directly into --out, which replaces
    /// an entry of that name there; the check of check_options() may call it. run() refuses, before
    /// anything is written, an --out that already holds such an entry that the previous run into it
    /// did not write (its .fem-run-files does not list it): it is someone else's.
    void writes_entry(const std::string& name);

    /// First calls wait_passively(argv) (common/parallel.hpp: the program may start again, with
    /// OMP_WAIT_POLICY=passive). Parses argv (running every option's check), runs the check of
    /// check_options(), and calls
    /// body, which writes into a staging folder (fem::StagedFiles) inside --out. Only when body
    /// returns do its files appear in --out, together, replacing the previous run's (whose files
    /// this run did not write again are removed; other files are left alone), and run() prints
    /// "wrote <--out>" and the run's peak resident memory ("peak memory: 312 MB", from
    /// peak_resident_bytes() of common/memory.hpp; not printed after a failure). A run that fails
    /// leaves --out as it was. The list of the files written (.fem-run-files in --out) names the
    /// files the next run may remove; a list that names anything but plain entries of --out is
    /// ignored with a warning. Returns the process exit code: 0 on success (and after --help); 1
    /// after printing one line "error: <message>" for fem::Error, an unfinished exercise, a bad
    /// command line (an unknown option, a value that does not parse, an empty --out, an --out
    /// that overlaps an input) or any other exception ("internal error: ... please report it"):
    /// nothing escapes to std::terminate.
    int run(int argc, char** argv, const std::function<void(const RunContext&)>& body);

private:
    /// The options' checks, the inputs' and the output folder's: fem::Error for a bad command line.
    void check_command_line();

    std::function<void()> check_;
    std::vector<std::filesystem::path> inputs_;
    std::vector<std::string> written_entries_;
    RunContext context_;
    std::string out_text_;
    bool no_figures_ = false;
};

}  // namespace fem
