// mesh_io_speed: how fast a TetGen .node/.ele pair is read, side by side in one run
// (docs/engineering.md, "Reading meshes"). It writes a box mesh of --cells³ cubes (6 tets each)
// with fem::io's writer, then reads it back three ways and prints MB/s (MB = 10^6 bytes of both files):
//   1. the floor: the two files' bytes into memory, nothing parsed;
//   2. the plain route: std::getline per line, std::istringstream >> per value (no checks);
//   3. fem::io::read_tet_mesh: one pass over the file in memory, std::from_chars, every check
//      (columns, numbering, node range) and validate() (finite, non-degenerate, not inverted).
// Routes 2 and 3 must give the same mesh, bit for bit (else: error, exit 1). Each route runs
// --repeats times (the best is shown), timed by the wall clock and by this process's CPU time; the
// files are removed at the end.
//
//   mesh_io_speed                     about 140 MB (--cells 80)
//   mesh_io_speed --cells 100         about 270 MB
//   mesh_io_speed --quick             a 1 MB mesh: the agreement check ctest runs
#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/mesh.hpp"
#include "common/mesh_io.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <algorithm>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

using namespace fem;

namespace {

/// The files' bytes in memory: what any reader must at least do.
std::size_t read_bytes(const std::filesystem::path& node, const std::filesystem::path& ele)
{
    std::size_t total = 0;
    for (const auto& path : {node, ele}) {
        std::ifstream in(path, std::ios::binary);
        std::string bytes(std::filesystem::file_size(path), '\0');
        in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        total += static_cast<std::size_t>(in.gcount());
    }
    return total;
}

/// The obvious reader: std::getline, then std::istringstream >> for each value; '#' comments and
/// blank lines skipped, no other check.
TetMesh read_plain(const std::filesystem::path& node, const std::filesystem::path& ele)
{
    const auto next = [](std::ifstream& in, std::istringstream& line) {
        std::string text;
        while (std::getline(in, text)) {
            text = text.substr(0, text.find('#'));
            if (text.find_first_not_of(" \t\r") != std::string::npos) {
                line.clear();
                line.str(text);
                return;
            }
        }
        throw Error("plain reader: the file ends early");
    };
    TetMesh mesh;
    std::istringstream line;
    std::ifstream nodes(node);
    next(nodes, line);
    long long count = 0, base = 0, number = 0;
    line >> count;
    mesh.V.resize(count, 3);
    for (long long i = 0; i < count; ++i) {
        next(nodes, line);
        line >> number >> mesh.V(i, 0) >> mesh.V(i, 1) >> mesh.V(i, 2);
        if (i == 0)
            base = number;
    }
    std::ifstream elements(ele);
    next(elements, line);
    line >> count;
    mesh.T.resize(count, 4);
    for (long long e = 0; e < count; ++e) {
        next(elements, line);
        line >> number;
        for (int k = 0; k < 4; ++k) {
            line >> number;
            mesh.T(e, k) = static_cast<int>(number - base);
        }
    }
    return mesh;
}

}  // namespace

int main(int argc, char** argv)
{
    ChapterCli cli("mesh_io_speed", "mesh_io_speed",
                   "Reading speed of TetGen .node/.ele files: the floor, the plain per-line route and fem::io's reader");
    int cells = 80, repeats = 2;
    cli.app.add_option("--cells", cells, "Cubes along each side of the box mesh (6 tets each)")
        ->check(check::integer(2, 200))->capture_default_str();
    cli.app.add_option("--repeats", repeats, "Runs of each route (the best is shown)")
        ->check(check::integer(1, 20))->capture_default_str();
    return cli.run(argc, argv, [&](const RunContext& run) {
        if (run.quick)
            cells = std::min(cells, 12);
        const TetMesh box = box_mesh(cells, cells, cells);
        const std::filesystem::path node = run.file("box.node"), ele = run.file("box.ele");
        io::write_tet_mesh(node, box);
        const double megabytes =
            static_cast<double>(std::filesystem::file_size(node) + std::filesystem::file_size(ele)) / 1e6;

        // Wall time, and the CPU time of this process (user + system, std::clock): on a machine
        // shared with other jobs the wall time grows with them, the CPU time much less.
        struct Times {
            double wall = 1e300, cpu = 1e300;
        };
        const auto measure = [&](const auto& work) {
            Times best;
            for (int k = 0; k < repeats; ++k) {
                const std::clock_t cpu_start = std::clock();
                Timer wall;
                work();
                best.wall = std::min(best.wall, wall.seconds());
                best.cpu = std::min(best.cpu, double(std::clock() - cpu_start) / CLOCKS_PER_SEC);
            }
            return best;
        };
        TetMesh plain, ours;
        std::size_t bytes = 0;
        const Times floor_time = measure([&] { bytes = read_bytes(node, ele); });
        const Times plain_time = measure([&] { plain = read_plain(node, ele); });
        const Times ours_time = measure([&] { ours = io::read_tet_mesh(node); });
        if (bytes != static_cast<std::size_t>(megabytes * 1e6 + 0.5))
            throw Error("the floor read fewer bytes than the files hold");
        if (plain.V != ours.V || plain.T != ours.T || ours.V.rows() != box.V.rows() || ours.T.rows() != box.T.rows())
            throw Error("the plain route and read_tet_mesh read different meshes");

        Table table(str("Reading a TetGen pair of ", box.V.rows(), " points and ", box.T.rows(), " tetrahedra (",
                        megabytes, " MB; best of ", repeats, ", files in the page cache)"),
                    {{"route", Format::text}, {"wall time [s]", Format::scientific, 2},
                     {"CPU time [s]", Format::scientific, 2}, {"speed, wall [MB/s]", Format::fixed, 0},
                     {"speed, CPU [MB/s]", Format::fixed, 0}, {"CPU speed / ours [measured]", Format::fixed, 2}});
        const auto add = [&](const std::string& route, const Times& times) {
            table.add_row({route, times.wall, times.cpu, megabytes / times.wall, megabytes / std::max(times.cpu, 1e-9),
                           ours_time.cpu / std::max(times.cpu, 1e-9)});
        };
        add("the bytes into memory (the floor)", floor_time);
        add("std::getline + std::istringstream (plain, unchecked)", plain_time);
        add("fem::io::read_tet_mesh (one pass, from_chars, checked)", ours_time);
        table.print(std::cout);
        table.write_csv(run.file("mesh_io_speed_table.csv"));
        std::filesystem::remove(node);
        std::filesystem::remove(ele);
    });
}
