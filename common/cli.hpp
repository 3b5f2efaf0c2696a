#pragma once
// The command line every chapter executable shares (CLI11), and the guard around its main():
// options --out DIR, --quick, --no-figures, --help; fem::Error becomes "error: ..." and exit 1.

#include <CLI/CLI.hpp>

#include <filesystem>
#include <functional>
#include <string>

namespace fem {

/// What a chapter's run needs to know about its invocation.
struct RunContext {
    std::filesystem::path out_dir;  ///< where every file of this run goes (created)
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

    /// Parses argv, creates the output folder and calls body. Returns the process exit code:
    /// 0 on success (and after --help); 1 after printing "error: <message>" for fem::Error, an
    /// unfinished exercise, a bad command line (an unknown option, a value that does not parse)
    /// or any other failure.
    int run(int argc, char** argv, const std::function<void(const RunContext&)>& body);

private:
    RunContext context_;
    std::string out_text_;
    bool no_figures_ = false;
};

}  // namespace fem
