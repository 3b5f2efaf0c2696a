// TetGen in a child process (common/tetgen.hpp): a closed surface gives tets; switches that ask too
// much stop at the time or memory limit with an error that names it (issue 23, row 4: they ran
// without end); the temporary folder is gone on every way out.
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh.hpp"
#include "common/mesh_io.hpp"
#include "common/tetgen.hpp"

#include <catch2/catch.hpp>

#include <chrono>
#include <filesystem>
#include <string>

#include <unistd.h>

using Catch::Matchers::Contains;

namespace {

/// The temporary folders of this process's TetGen runs that still exist.
int leftover_folders()
{
    const std::string prefix = "fem-tetgen-" + std::to_string(::getpid()) + "-";
    int count = 0;
    for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::temp_directory_path()))
        count += entry.path().filename().string().starts_with(prefix);
    return count;
}

/// The closed surface of one tetrahedron: four outward triangles.
fem::TriMesh tet_surface()
{
    fem::TriMesh surface;
    surface.V.resize(4, 3);
    surface.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
    surface.F.resize(4, 3);
    surface.F << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
    return surface;
}

}  // namespace

TEST_CASE("TetGen tetrahedralises a closed surface and leaves no temporary folder", "[common][tetgen]")
{
    const fem::TetMesh mesh = fem::tetrahedralize(tet_surface(), "pq1.5aY", "tet");
    CHECK(mesh.T.rows() > 0);
    CHECK(leftover_folders() == 0);
    CHECK_THROWS_WITH(fem::tetrahedralize(tet_surface(), "q1.5; rm -rf", "tet"),
                      Contains("tet: TetGen switches 'q1.5; rm -rf' must include p"));
}

TEST_CASE("TetGen switches that ask too much stop at the time or memory limit, naming it", "[common][tetgen]")
{
    const fem::TriMesh bunny = fem::io::read_tri_mesh(fem::data_path("bunny.obj"));
    fem::TetgenLimits quick;
    quick.seconds = 2.0;
    const auto start = std::chrono::steady_clock::now();
    // A radius-edge bound of 1.0 that TetGen keeps refining towards (issue 23's reproducer).
    CHECK_THROWS_WITH(fem::tetrahedralize(bunny, "pq1.0a0.0000001", "bunny.obj", quick),
                      Contains("bunny.obj: TetGen") && Contains("limit of 2") && Contains("ask for less"));
    CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(10));
    CHECK(leftover_folders() == 0);
    fem::TetgenLimits small;
    small.memory = std::size_t(64) << 20;
    CHECK_THROWS_WITH(fem::tetrahedralize(bunny, "pq1.5a0.0000001", "bunny.obj", small),
                      Contains("bunny.obj: TetGen") && Contains("out of memory within its limit of 64 MB"));
    CHECK(leftover_folders() == 0);
}
