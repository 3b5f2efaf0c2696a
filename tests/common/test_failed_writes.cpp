// Writes that fail for real leave what was there before, and nothing half-written: a file size limit
// (RLIMIT_FSIZE in a forked child, SIGXFSZ ignored, so that a write past it fails with EFBIG as on
// a full disk), a folder that cannot be created (its parent is a file, which stops root too);
// files written together (StagedFiles, a TetGen pair) appear together or not at all.
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh.hpp"
#include "common/mesh_io.hpp"
#include "common/table.hpp"
#include "common/test_support.hpp"
#include "common/vtk_io.hpp"

#include <catch2/catch.hpp>

#include <csignal>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <sstream>
#include <string>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;
namespace fs = std::filesystem;

namespace {

/// What `write` did in a child process whose files may grow to `limit` bytes at most: "wrote",
/// "error: <message>" for an fem::Error, or how it failed otherwise ("killed by signal 11").
std::string under_file_size_limit(rlim_t limit, const std::function<void()>& write)
{
    int channel[2];
    REQUIRE(::pipe(channel) == 0);
    std::cout.flush();
    std::cerr.flush();
    const pid_t child = ::fork();
    REQUIRE(child >= 0);
    if (child == 0) {
        ::close(channel[0]);
        std::signal(SIGXFSZ, SIG_IGN);
        const rlimit size_limit{limit, limit};
        std::string report = "setrlimit failed";
        if (::setrlimit(RLIMIT_FSIZE, &size_limit) == 0) {
            try {
                write();
                report = "wrote";
            } catch (const fem::Error& e) {
                report = std::string("error: ") + e.what();
            } catch (const std::exception& e) {
                report = std::string("not an fem::Error: ") + e.what();
            }
        }
        const ssize_t sent = ::write(channel[1], report.data(), report.size());
        ::_exit(sent == static_cast<ssize_t>(report.size()) ? 0 : 3);
    }
    ::close(channel[1]);
    std::string report;
    char buffer[512];
    for (ssize_t n; (n = ::read(channel[0], buffer, sizeof buffer)) > 0;)
        report.append(buffer, static_cast<std::size_t>(n));
    ::close(channel[0]);
    int status = 0;
    ::waitpid(child, &status, 0);
    if (WIFSIGNALED(status))
        return fem::str("killed by signal ", WTERMSIG(status));
    return report;
}

/// Every file under folder (hidden ones too), by relative path, with its bytes.
std::map<std::string, std::string> contents(const fs::path& folder)
{
    std::map<std::string, std::string> files;
    for (const auto& entry : fs::recursive_directory_iterator(folder)) {
        if (!entry.is_regular_file())
            continue;
        std::ifstream file(entry.path(), std::ios::binary);
        std::ostringstream bytes;
        bytes << file.rdbuf();
        files[fs::relative(entry.path(), folder).string()] = bytes.str();
    }
    return files;
}

struct Writer {
    const char* what;
    const char* file;  // the file name it writes
    std::function<void(const fs::path&, int)> write;  // writes a mesh of about n^3 cells
};

}  // namespace

TEST_CASE("a write past a file size limit, as on a full disk, is an fem::Error with the system's reason and leaves the old file", "[common][files]")
{
    const std::vector<Writer> writers = {
        {"write_file", "bytes.bin", [](const fs::path& p, int n) { fem::write_file(p, std::string(n * n * n * 100, 'x')); }},
        {"Table::write_csv", "table.csv",
         [](const fs::path& p, int n) {
             fem::Table table("t", {{"i", fem::Format::integer}, {"x", fem::Format::scientific, 3}});
             for (int i = 0; i < n * n * n; ++i)
                 table.add_row({double(i), 1.0 / (i + 1)});
             table.write_csv(p);
         }},
        {"write_vtu (VTK's XML writer crashed here)", "box.vtu",
         [](const fs::path& p, int n) {
             const fem::TetMesh box = fem::box_mesh(n, n, n);
             fem::io::MeshData data;
             data.points = box.V;
             data.cells = box.T;
             fem::io::write_vtu(p, data);
         }},
        {"write_vti", "grid.vti",
         [](const fs::path& p, int n) {
             fem::io::ImageGrid grid;
             grid.dims = {4 * n, 4 * n, 4 * n};
             grid.spacing = {1.0, 1.0, 1.0};
             grid.point_data = {{"u", Eigen::VectorXd::LinSpaced(64 * n * n * n, 0.0, 1.0)}};
             fem::io::write_vti(p, grid);
         }},
        {"write_tri_mesh .obj", "square.obj",
         [](const fs::path& p, int n) { fem::io::write_tri_mesh(p, fem::square_mesh(2 * n * n)); }},
        {"write_tri_mesh .stl", "square.stl",
         [](const fs::path& p, int n) { fem::io::write_tri_mesh(p, fem::square_mesh(2 * n * n)); }},
        {"write_tri_mesh .ply", "square.ply",
         [](const fs::path& p, int n) { fem::io::write_tri_mesh(p, fem::square_mesh(2 * n * n)); }},
    };
    for (const Writer& writer : writers) {
        DYNAMIC_SECTION(writer.what)
        {
            const fs::path folder = fem::test::fresh_output_dir("file_size_limit");
            writer.write(folder / writer.file, 1);  // the old result, small
            const auto before = contents(folder);
            const std::string report =
                under_file_size_limit(16384, [&] { writer.write(folder / writer.file, 12); });
            CHECK_THAT(report, StartsWith("error: ") && Contains(writer.file) && Contains("File too large"));
            CHECK(contents(folder) == before);  // the old file as it was, and no temporary
        }
    }
}

TEST_CASE("a TetGen pair appears together: when the .ele cannot be written, the old .node stays too", "[common][files]")
{
    const fs::path folder = fem::test::fresh_output_dir("tetgen_together");
    fem::io::write_tet_mesh(folder / "box.node", fem::box_mesh(1, 1, 1));
    const auto before = contents(folder);
    // A box of 6^3 cubes: its .node (343 points) fits in 20 kB, its .ele (1296 tets) does not.
    const fem::TetMesh box = fem::box_mesh(6, 6, 6);
    const std::string report = under_file_size_limit(20000, [&] { fem::io::write_tet_mesh(folder / "box.node", box); });
    CHECK_THAT(report, StartsWith("error: ") && Contains("box.ele") && Contains("File too large"));
    CHECK(contents(folder) == before);
    // Without the limit both files are replaced.
    fem::io::write_tet_mesh(folder / "box.node", box);
    CHECK(fem::io::read_tet_mesh(folder / "box.node").T.rows() == box.T.rows());
}

TEST_CASE("a folder that cannot be created is an fem::Error naming it, and nothing is written", "[common][files]")
{
    const fs::path folder = fem::test::fresh_output_dir("unwritable");
    fem::write_file(folder / "a_file", "not a folder");
    const auto before = contents(folder);
    fem::io::MeshData mesh;
    mesh.points = fem::box_mesh(1, 1, 1).V;
    CHECK_THROWS_WITH(fem::io::write_vtu(folder / "a_file" / "mesh.vtu", mesh),
                      Contains("a_file") && Contains("cannot create folder"));
    CHECK_THROWS_WITH(fem::StagedFiles(folder / "a_file" / "out"), Contains("cannot create folder"));
    CHECK(contents(folder) == before);
}

TEST_CASE("StagedFiles: files appear together on publish, replace old ones, obsolete ones leave, and without publish nothing changes", "[common][files]")
{
    const fs::path folder = fem::test::fresh_output_dir("staged") / "out";
    {
        fem::StagedFiles first(folder);
        fem::write_file(first.staging() / "a.csv", "a1");
        fem::ensure_directory(first.staging() / "frames");
        fem::write_file(first.staging() / "frames" / "f_0000.vtu", "f1");
        fem::write_file(first.staging() / "frames" / "f_0001.vtu", "f1");
        first.publish();
    }
    fem::write_file(folder / "notes.txt", "a file of the user's");
    const std::map<std::string, std::string> first_run = {
        {"a.csv", "a1"}, {"frames/f_0000.vtu", "f1"}, {"frames/f_0001.vtu", "f1"}, {"notes.txt", "a file of the user's"}};
    CHECK(contents(folder) == first_run);

    {  // a failed run: nothing of it is seen, the staging folder is gone
        fem::StagedFiles failed(folder);
        fem::write_file(failed.staging() / "a.csv", "half");
        fem::write_file(failed.staging() / "b.csv", "half");
    }
    CHECK(contents(folder) == first_run);

    {  // a run with fewer frames and without a.csv: the old frames folder is replaced whole
        fem::StagedFiles second(folder);
        fem::ensure_directory(second.staging() / "frames");
        fem::write_file(second.staging() / "frames" / "f_0000.vtu", "f2");
        fem::write_file(second.staging() / "b.csv", "b2");
        second.publish({"a.csv", "frames", "../notes.txt", "missing.csv"});
    }
    CHECK(contents(folder) == std::map<std::string, std::string>{
                                  {"b.csv", "b2"}, {"frames/f_0000.vtu", "f2"}, {"notes.txt", "a file of the user's"}});

    // A staging folder left by a process that no longer runs (killed mid-write) is removed; one
    // of a running process (this one's) is not.
    fem::ensure_directory(folder / ".staging-999999999-0");  // beyond any pid Linux hands out
    fem::ensure_directory(folder / fem::str(".staging-", ::getpid(), "-999"));
    { fem::StagedFiles third(folder); }
    CHECK_FALSE(fs::exists(folder / ".staging-999999999-0"));
    CHECK(fs::exists(folder / fem::str(".staging-", ::getpid(), "-999")));
    fs::remove(folder / fem::str(".staging-", ::getpid(), "-999"));

    // A folder the failed run created is removed again, with the parents it created.
    const fs::path fresh = fem::test::fresh_output_dir("staged_fresh");
    { fem::StagedFiles unused(fresh / "new" / "out"); }
    CHECK_FALSE(fs::exists(fresh / "new"));
}
