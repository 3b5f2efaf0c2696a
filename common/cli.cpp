#include "common/cli.hpp"

#include "common/error.hpp"
#include "common/files.hpp"

#include <iostream>

namespace fem {

ChapterCli::ChapterCli(const std::string& executable, const std::string& chapter,
                       const std::string& description)
    : app(description, executable), out_text_("out/" + chapter)
{
    app.add_option("--out", out_text_, "Folder for the VTK files, CSV tables and PNG figures")
        ->capture_default_str();
    app.add_flag("--quick", context_.quick, "A small, fast run (what ctest runs)");
    app.add_flag("--no-figures", no_figures_, "Skip the PNG figures");
    // A bad command line reads like every other bad input: "error: ..." (naming the option), and
    // exit code 1 (see run()), instead of CLI11's bare message and its own exit codes.
    app.failure_message([](const CLI::App*, const CLI::Error& e) {
        return str("error: ", e.what(), "\nrun with --help to see the options\n");
    });
}

int ChapterCli::run(int argc, char** argv, const std::function<void(const RunContext&)>& body)
{
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help prints the options and exits with 0; anything else is a bad command line.
        return app.exit(e) == 0 ? 0 : 1;
    }
    try {
        context_.out_dir = out_text_;
        context_.figures = !no_figures_;
        ensure_directory(context_.out_dir);
        body(context_);
        std::cout << "\nwrote " << std::filesystem::absolute(context_.out_dir).lexically_normal().string()
                  << '\n';
        return 0;
    } catch (const Error& e) {
        std::cerr << "error: " << e.what() << '\n';
    } catch (const NotImplemented& e) {
        std::cerr << "error: " << e.what() << '\n';
    } catch (const std::exception& e) {
        std::cerr << "error: unexpected failure: " << e.what() << '\n';
    }
    return 1;
}

}  // namespace fem
