#include "common/cli.hpp"

#include "common/error.hpp"
#include "common/files.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <optional>

namespace fem {

namespace check {
namespace {

/// A number as C++ writes it: "0.5", "-1e-3", "inf" and "nan" included (refused by the checks).
bool parse_real(const std::string& text, double& value)
{
    if (text.empty() || std::isspace(static_cast<unsigned char>(text.front())))
        return false;
    char* end = nullptr;
    errno = 0;
    value = std::strtod(text.c_str(), &end);
    return end == text.c_str() + text.size() && errno != ERANGE;
}

std::string interval_text(double low, double high, Ends ends)
{
    const bool low_in = ends == Ends::closed || ends == Ends::closed_open;
    const bool high_in = ends == Ends::closed || ends == Ends::open_closed;
    if (std::isinf(low) && std::isinf(high))
        return "a finite number";
    if (std::isinf(high))
        return str("a finite number ", low_in ? ">= " : "> ", low);
    if (std::isinf(low))
        return str("a finite number ", high_in ? "<= " : "< ", high);
    return str("a number in ", low_in ? "[" : "(", low, ", ", high, high_in ? "]" : ")");
}

}  // namespace

CLI::Validator real(double low, double high, Ends ends)
{
    const std::string allowed = interval_text(low, high, ends);
    const bool low_in = ends == Ends::closed || ends == Ends::closed_open;
    const bool high_in = ends == Ends::closed || ends == Ends::open_closed;
    return CLI::Validator(
        [=](std::string& text) {
            double x = 0.0;
            const bool inside = parse_real(text, x) && std::isfinite(x) && (low_in ? x >= low : x > low) &&
                                (high_in ? x <= high : x < high);
            return inside ? std::string() : str("must be ", allowed, ", got '", text, "'");
        },
        "(" + allowed + ")");
}

CLI::Validator positive() { return real(0.0, std::numeric_limits<double>::infinity(), Ends::open); }

CLI::Validator non_negative() { return real(0.0, std::numeric_limits<double>::infinity(), Ends::closed_open); }

CLI::Validator finite()
{
    constexpr double unbounded = std::numeric_limits<double>::infinity();
    return real(-unbounded, unbounded, Ends::open);
}

CLI::Validator integer(long long low, long long high)
{
    // The upper end of an option's type (at_least) is named after the lower one.
    const std::string allowed = high >= std::numeric_limits<int>::max()
                                    ? str("an integer >= ", low, " (at most ", high, ")")
                                    : str("an integer in [", low, ", ", high, "]");
    return CLI::Validator(
        [=](std::string& text) {
            const char* begin = text.c_str();
            char* end = nullptr;
            errno = 0;
            const long long n = std::strtoll(begin, &end, 10);
            const bool digits = !text.empty() && !std::isspace(static_cast<unsigned char>(text.front())) &&
                                end == begin + text.size() && errno != ERANGE;
            return digits && n >= low && n <= high ? std::string() : str("must be ", allowed, ", got '", text, "'");
        },
        "(" + allowed + ")");
}

CLI::Validator accepted_by(std::function<void(const std::string&)> parse)
{
    return CLI::Validator(
        [parse = std::move(parse)](std::string& text) {
            try {
                parse(text);
                return std::string();
            } catch (const Error& e) {
                return std::string(e.what());
            }
        },
        "");
}

}  // namespace check


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

namespace {

/// The list of the files a run wrote, kept in its output folder for the next run.
constexpr const char* run_manifest = ".fem-run-files";

/// The names the previous run in `out` wrote (none when there was none).
std::vector<std::string> previous_run_files(const std::filesystem::path& out)
{
    std::vector<std::string> names;
    std::ifstream file(out / run_manifest);
    for (std::string name; std::getline(file, name);)
        names.push_back(name);
    return names;
}

}  // namespace

void ChapterCli::check_options(std::function<void()> check) { check_ = std::move(check); }

int ChapterCli::run(int argc, char** argv, const std::function<void(const RunContext&)>& body)
{
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help prints the options and exits with 0; anything else is a bad command line.
        return app.exit(e) == 0 ? 0 : 1;
    }
    try {
        if (check_)
            check_();
    } catch (const Error& e) {
        std::cerr << "error: " << e.what() << "\nrun with --help to see the options\n";
        return 1;
    }
    const std::filesystem::path out = out_text_;
    std::string message;
    try {
        // A file size limit (ulimit -f) makes a write fail with EFBIG, like a full disk, instead
        // of killing the run before it can clean up.
        std::signal(SIGXFSZ, SIG_IGN);
        std::optional<StagedFiles> staged;
        try {
            staged.emplace(out);
        } catch (const Error& e) {
            throw Error(str("--out: ", e.what()));
        }
        context_.out_dir = staged->staging();
        context_.figures = !no_figures_;
        body(context_);
        // The run's files appear together; those of the previous run that this one did not
        // write again leave in the same step (a run's folder never mixes two runs).
        std::vector<std::string> written;
        for (const auto& entry : std::filesystem::directory_iterator(context_.out_dir))
            written.push_back(entry.path().filename().string());
        std::sort(written.begin(), written.end());
        std::string manifest;
        for (const std::string& name : written)
            manifest += name + '\n';
        write_file(context_.file(run_manifest), manifest);
        staged->publish(previous_run_files(out));
        std::cout << "\nwrote " << std::filesystem::absolute(out).lexically_normal().string() << '\n';
        return 0;
    } catch (const Error& e) {
        message = e.what();
    } catch (const NotImplemented& e) {
        message = e.what();
    } catch (const std::exception& e) {
        message = str("unexpected failure: ", e.what());
    }
    // The staging folder is gone: name the files where they would have appeared.
    const std::string staging = context_.out_dir.string();
    for (std::size_t at = staging.empty() ? std::string::npos : message.find(staging); at != std::string::npos;
         at = message.find(staging, at))
        message.replace(at, staging.size(), out.string());
    std::cerr << "error: " << message << '\n';
    return 1;
}

}  // namespace fem
