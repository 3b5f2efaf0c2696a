#include "common/cli.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/memory.hpp"
#include "common/parallel.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <iostream>
#include <iterator>
#include <new>
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

/// The shortest decimal text that reads back as x (std::to_chars): 1e+13, 0.499999995, 0.02.
std::string shortest_text(double x)
{
    std::array<char, 32> text{};
    const auto [end, error] = std::to_chars(text.data(), text.data() + text.size(), x);
    return error == std::errc() ? std::string(text.data(), end) : str(x);
}

std::string interval_text(double low, double high, Ends ends)
{
    const bool low_in = ends == Ends::closed || ends == Ends::closed_open;
    const bool high_in = ends == Ends::closed || ends == Ends::open_closed;
    if (std::isinf(low) && std::isinf(high))
        return "a finite number";
    // Every digit of a bound: 0.499999995 must not print as 0.5.
    const std::string low_text = shortest_text(low), high_text = shortest_text(high);
    if (std::isinf(high))
        return str("a finite number ", low_in ? ">= " : "> ", low_text);
    if (std::isinf(low))
        return str("a finite number ", high_in ? "<= " : "< ", high_text);
    return str("a number in ", low_in ? "[" : "(", low_text, ", ", high_text, high_in ? "]" : ")");
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
        ->capture_default_str()
        ->check(CLI::Validator(
            [](std::string& text) { return text.empty() ? std::string("must name a folder, got an empty text") : std::string(); },
            ""));
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

/// The names the previous run in `out` wrote (none when there was none). Every line must be a plain
/// entry name of out (no folder part, not the list itself, not a staging folder): a list that holds
/// anything else was not written by a run, and is ignored with a warning (nothing is removed).
std::vector<std::string> previous_run_files(const std::filesystem::path& out)
{
    std::vector<std::string> names;
    std::ifstream file(out / run_manifest);
    int line = 0;
    for (std::string name; std::getline(file, name);) {
        ++line;
        const bool plain = !name.empty() && name != "." && name != ".." && name != run_manifest &&
                           name.find('/') == std::string::npos && !name.starts_with(".staging-");
        if (!plain) {
            std::cerr << "warning: " << (out / run_manifest).string() << ":" << line << ": '" << name.substr(0, 200)
                      << "' is not a file name of this folder; the list is ignored (no earlier result is removed)\n";
            return {};
        }
        names.push_back(name);
    }
    return names;
}

/// path made absolute, with symbolic links and "..", "." resolved as far as it exists.
std::filesystem::path resolved(const std::filesystem::path& path)
{
    std::error_code ec;
    const std::filesystem::path absolute = std::filesystem::absolute(path, ec);
    const std::filesystem::path canonical = std::filesystem::weakly_canonical(absolute, ec);
    return (ec ? absolute : canonical).lexically_normal();
}

/// True when inner is outer or lies inside it (both resolved).
bool within(const std::filesystem::path& inner, const std::filesystem::path& outer)
{
    const auto o = std::mismatch(outer.begin(), outer.end(), inner.begin(), inner.end()).first;
    return o == outer.end() || (o->empty() && std::next(o) == outer.end());  // or a trailing separator
}

/// The message of a failure caught at the top of a run: an fem::Error's or an unfinished exercise's
/// own; a lack of memory said so; anything else is a bug of the course.
std::string failure_message(const std::exception_ptr& failure)
{
    constexpr const char* report = " (a bug of the course: please report it with the command line)";
    try {
        std::rethrow_exception(failure);
    } catch (const Error& e) {
        return e.what();
    } catch (const NotImplemented& e) {
        return e.what();
    } catch (const std::bad_alloc&) {
        return "out of memory (std::bad_alloc): the run needs more memory than the system gives it";
    } catch (const std::exception& e) {
        return str("internal error: ", e.what(), report);
    } catch (...) {
        return str("internal error: an exception of an unknown type", report);
    }
}

}  // namespace

void ChapterCli::check_options(std::function<void()> check) { check_ = std::move(check); }

void ChapterCli::protect_inputs(const std::vector<std::filesystem::path>& inputs)
{
    inputs_.insert(inputs_.end(), inputs.begin(), inputs.end());
}

void ChapterCli::writes_entry(const std::string& name) { written_entries_.push_back(name); }

void ChapterCli::check_command_line()
{
    if (check_)
        check_();
    const std::filesystem::path out = resolved(out_text_);
    for (const std::filesystem::path& input : inputs_) {
        const std::filesystem::path in = resolved(input);
        if (within(in, out) || within(out, in))
            throw Error(str("--out: '", out_text_, "' ", within(out, in) ? "is or lies inside" : "holds",
                            " the input '", input.string(), "'; the run's files would replace or remove it: ",
                            "choose a folder apart from the inputs"));
    }
    std::error_code ec;
    if (written_entries_.empty() || !std::filesystem::is_directory(out, ec))
        return;
    const std::vector<std::string> previous = previous_run_files(out);
    for (const std::string& name : written_entries_)
        if (std::filesystem::exists(std::filesystem::symlink_status(out / name, ec)) &&
            std::find(previous.begin(), previous.end(), name) == previous.end())
            throw Error(str("--out: '", (std::filesystem::path(out_text_) / name).string(),
                            "' exists and was not written by an earlier run (", run_manifest,
                            " does not list it); this run would replace it: move it or choose another --out"));
}

int ChapterCli::run(int argc, char** argv, const std::function<void(const RunContext&)>& body)
{
    wait_passively(argv);  // may start the program again, with OMP_WAIT_POLICY=passive
    // Every exception ends here, as one line: none reaches std::terminate.
    try {
        try {
            app.parse(argc, argv);
        } catch (const CLI::ParseError& e) {
            // --help prints the options and exits with 0; anything else is a bad command line.
            return app.exit(e) == 0 ? 0 : 1;
        }
        try {
            check_command_line();
        } catch (const Error& e) {
            std::cerr << "error: " << e.what() << "\nrun with --help to see the options\n";
            return 1;
        }
    } catch (...) {
        std::cerr << "error: " << failure_message(std::current_exception()) << '\n';
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
        // The number varies by machine and library version: check_run.py compares files, never stdout.
        std::cout << "peak memory: " << (peak_resident_bytes() + 500'000) / 1'000'000
                  << " MB (resident, getrusage; 1 MB = 10^6 bytes)\n";
        return 0;
    } catch (...) {
        message = failure_message(std::current_exception());
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
