// VTK's own error output never reaches the user as its multi-line, coloured log: what VTK reports
// while the course reads or writes is one line inside the fem::Error, and anything else VTK says is
// one line "VTK: <reason>" on stderr (common/vtk_errors.hpp).
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh.hpp"
#include "common/test_support.hpp"
#include "common/vtk_errors.hpp"
#include "common/vtk_io.hpp"

#include <catch2/catch.hpp>

#include <vtkNew.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <cstdio>
#include <functional>
#include <iostream>
#include <sstream>
#include <string>

#include <unistd.h>

using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;

namespace {

/// What the process wrote to its stderr (file descriptor 2, where VTK prints) while call ran.
std::string stderr_of(const std::function<void()>& call)
{
    std::cerr.flush();
    std::fflush(stderr);
    std::FILE* capture = std::tmpfile();
    REQUIRE(capture != nullptr);
    const int saved = ::dup(2);
    ::dup2(::fileno(capture), 2);
    const auto restore = [&] {
        std::cerr.flush();
        std::fflush(stderr);
        ::dup2(saved, 2);
        ::close(saved);
    };
    try {
        call();
    } catch (...) {
        restore();
        std::fclose(capture);
        throw;
    }
    restore();
    std::string text;
    std::rewind(capture);
    for (int c; (c = std::fgetc(capture)) != EOF;)
        text += static_cast<char>(c);
    std::fclose(capture);
    return text;
}

/// The message of the fem::Error that call throws (fails the test if it throws none).
std::string error_of(const std::function<void()>& call)
{
    try {
        call();
    } catch (const fem::Error& e) {
        return e.what();
    }
    FAIL("no fem::Error was thrown");
    return {};
}

}  // namespace

TEST_CASE("a .vtu that VTK refuses is an fem::Error carrying VTK's reason in one line, and VTK prints nothing", "[common][vtk]")
{
    // Its layout passes the course's checks (common/vtu_check.hpp); the zlib stream of its points
    // is damaged, which only VTK's decompressor finds.
    const auto path = std::filesystem::path(FEM_BAD_FILES_DIR) / "zlib_points_corrupt.vtu";
    std::string message;
    const std::string printed = stderr_of([&] { message = error_of([&] { fem::io::read_vtu(path); }); });
    CHECK_THAT(message, Contains("zlib_points_corrupt.vtu") && Contains("as a VTK unstructured grid (.vtu): ") &&
                            Contains("Zlib error while uncompressing data"));
    CHECK(message.find('\n') == std::string::npos);
    CHECK(message.find('\x1b') == std::string::npos);  // no terminal colours
    CHECK(printed.empty());
}

TEST_CASE("a write to a place that cannot hold it is an fem::Error with the reason, and VTK prints nothing", "[common][vtk]")
{
    const auto dir = fem::test::fresh_output_dir("vtk_errors_write");
    fem::write_file(dir / "a_file", "not a folder");
    fem::io::MeshData mesh;
    mesh.points = fem::box_mesh(1, 1, 1).V;
    std::string message;
    const std::string printed =
        stderr_of([&] { message = error_of([&] { fem::io::write_vtu(dir / "a_file" / "mesh.vtu", mesh); }); });
    CHECK_THAT(message, Contains("a_file") && Contains("Not a directory"));
    CHECK(printed.empty());
}

TEST_CASE("what VTK reports outside a read or write is one line 'VTK: <reason>' on stderr, not a log block", "[common][vtk]")
{
    fem::io::detail::route_vtk_output();
    const std::string printed = stderr_of([] {
        vtkNew<vtkXMLUnstructuredGridReader> reader;  // no collector: VTK prints what goes wrong
        reader->SetFileName("/no/such/folder/mesh.vtu");
        reader->Update();
    });
    REQUIRE_FALSE(printed.empty());
    std::istringstream lines(printed);
    for (std::string line; std::getline(lines, line);) {
        CHECK_THAT(line, StartsWith("VTK: "));
        CHECK(line.find('\x1b') == std::string::npos);
    }
    CHECK_THAT(printed, Contains("mesh.vtu"));
}
