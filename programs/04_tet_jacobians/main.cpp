// ch04_tet_jacobians: the deformation gradient F of every tet of a beam under stretch, shear, twist
// and a pinch that inverts tets; its error against the analytic F and its cost three ways; point
// location by barycentric coordinates.
//
// Sample runs:
//   ch04_tet_jacobians                      full run, files in out/04_tet_jacobians
//   ch04_tet_jacobians --quick              the small run ctest checks
//   ch04_tet_jacobians --twist 180 --cells 24 --pinch 1.2
//
// Writes: tables deformation_table.csv, twist_convergence_table.csv, locate_table.csv;
// the chart (PNG + CSV) twist_F_error; per field a mesh <field>.vtu (rest positions with point field
// displacement, as every deformed body of the course; cell data det F, |F - I|, F (row-major), F error) and its picture <field>.png.
// docs/04_tet_jacobians.md

#include "04_tet_jacobians/deformation_fields.hpp"
#include "04_tet_jacobians/tet_jacobians.hpp"
#include "01_finite_differences/finite_differences.hpp"

#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/mesh.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"
#include "common/vtk_io.hpp"

#include <Eigen/LU>

#include <cmath>
#include <iostream>
#include <numbers>
#include <random>

using namespace fem;
using namespace fem::tet;

namespace {

struct Settings {
    int cells = 16;          // cells along the beam (the cross-section gets cells of the same size)
    double stretch = 1.5;    // x → stretch · x
    double shear = 0.5;      // x → x + shear · y
    double twist = 90.0;     // total twist of the beam about its axis [degrees]
    double pinch = 1.6;      // z is scaled by 1 − pinch · exp(−((x − L/2)/width)²): > 1 inverts tets
    double pinch_width = 0.1;
};

// The beam: length 1 along x, a 0.25 × 0.25 cross-section centred on (y, z) = (0.125, 0.125).
constexpr double length = 1.0, side = 0.25, centre = side / 2;

std::vector<DeformationField> deformation_fields(const Settings& s)
{
    Eigen::Matrix3d shear = Eigen::Matrix3d::Identity();
    shear(0, 1) = s.shear;
    std::vector<DeformationField> fields{
        affine_field("stretch", str("x -> ", s.stretch, " x"), Eigen::Vector3d(s.stretch, 1.0, 1.0).asDiagonal()),
        affine_field("shear", str("x -> x + ", s.shear, " y"), shear),
        twist_field(s.twist * std::numbers::pi / 180.0 / length, centre, centre),
        pinch_field(s.pinch, s.pinch_width, length / 2, centre)};
    fields[2].description = str(s.twist, " degrees about the axis");
    return fields;
}

TetMesh beam(int cells) { return beam_mesh(length, side, side, cells); }

Eigen::Vector3d centroid(const TetMesh& mesh, int t)
{
    return tet_vertices(mesh, mesh.V, t).colwise().mean().transpose();
}

/// max over tets of ‖F_t − F_exact(centroid of t)‖ (Frobenius).
double max_gradient_error(const TetMesh& mesh, const std::vector<Eigen::Matrix3d>& F,
                          const DeformationField& field)
{
    double error = 0.0;
    for (int t = 0; t < mesh.T.rows(); ++t)
        error = std::max(error, (F[t] - field.gradient(centroid(mesh, t))).norm());
    return error;
}

// 1. Each field on the beam: det F, |F − I|, the error against the analytic F, inverted tets;
//    a .vtu and a picture of the deformed beam.
void field_study(const RunContext& run, const Settings& settings)
{
    const TetMesh mesh = beam(run.quick ? 8 : settings.cells);
    Table table(str("Deformation gradients on a ", length, " x ", side, " x ", side, " beam, ", mesh.T.rows(),
                    " tets: F per tet against the analytic F at its centroid"),
                {{"field", Format::text}, {"deformation", Format::text}, {"min det F", Format::fixed, 4},
                 {"max det F", Format::fixed, 4}, {"max |F - I|", Format::fixed, 4},
                 {"max |F - F_exact|", Format::scientific, 2}, {"inverted tets", Format::integer}});
    for (const DeformationField& field : deformation_fields(settings)) {
        const MatrixX3d x = deform(mesh.V, field);
        const std::vector<Eigen::Matrix3d> F = deformation_gradients(mesh, x);
        const Eigen::Index n = mesh.T.rows();
        Eigen::VectorXd det(n), strain(n), error(n);
        Eigen::MatrixXd F_rows(n, 9);
        int inverted = 0;
        for (Eigen::Index t = 0; t < n; ++t) {
            det[t] = F[t].determinant();
            strain[t] = (F[t] - Eigen::Matrix3d::Identity()).norm();
            error[t] = (F[t] - field.gradient(centroid(mesh, static_cast<int>(t)))).norm();
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b)
                    F_rows(t, 3 * a + b) = F[t](a, b);  // row-major vec(F)
            inverted += det[t] < 0.0;
        }
        table.add_row({field.name, field.description, det.minCoeff(), det.maxCoeff(), strain.maxCoeff(),
                       error.maxCoeff(), double(inverted)});

        io::MeshData data = io::displaced_mesh(mesh.V, mesh.T, x - mesh.V);
        data.cell_data = {{"det F", det}, {"|F - I|", strain}, {"F", F_rows}, {"F error", error}};
        io::write_vtu(run.file(field.name + ".vtu"), data);
        if (run.figures) {
            fig::RenderOptions options;
            const bool by_volume = field.name == "pinch" || field.name == "stretch";
            options.field = by_volume ? "det F" : "|F - I|";
            options.title = str(field.name, " (", field.description, "): ", options.field, " per tet");
            if (field.name == "pinch")
                options.range = std::make_pair(-std::max(1.0, -det.minCoeff()), std::max(1.0, -det.minCoeff()));
            else if (by_volume)
                options.range = std::make_pair(0.0, 2.0);
            else
                options.range = std::make_pair(0.0, std::max(1e-3, strain.maxCoeff()));
            options.view_direction = {-0.45, 0.75, -0.5};
            options.view_up = {0.0, 0.0, 1.0};
            options.height = 520;
            fig::render_mesh_png(run.file(field.name + ".png"), io::warped(data), options);
        }
        if (inverted > 0) {
            TetMesh deformed{x, mesh.T};
            try {
                validate(deformed, field.name);
            } catch (const Error& error) {
                std::cout << "validate() on the " << field.name << "ed mesh: " << error.what() << '\n';
            }
        }
    }
    table.print(std::cout);
    table.write_csv(run.file("deformation_table.csv"));
}

// 2. Speed against error: the twist on finer beams. F computed three ways (they agree to
//    round-off), its error against the analytic F, and the rate of each way.
void twist_convergence_study(const RunContext& run, const Settings& settings)
{
    const std::vector<int> cells = run.quick ? std::vector<int>{4, 8, 16} : std::vector<int>{4, 8, 16, 32, 64};
    const DeformationField twist = deformation_fields(settings)[2];
    Table table(str("Twist (", settings.twist, " degrees): error of the per-tet F against the analytic F, ",
                    "and F per second computed three ways"),
                {{"cells along", Format::integer}, {"tets", Format::integer}, {"h", Format::scientific, 3},
                 {"max |F - F_exact|", Format::scientific, 3}, {"order", Format::fixed, 2},
                 {"ways differ by", Format::scientific, 1}, {"from vertices [1/s]", Format::scientific, 2},
                 {"precomputed dphi/dX [1/s]", Format::scientific, 2},
                 {"precomputed B [1/s]", Format::scientific, 2}});
    std::vector<double> h, error;
    const double min_seconds = run.quick ? 0.02 : 0.1;
    for (int n : cells) {
        const TetMesh mesh = beam(n);
        const MatrixX3d x = deform(mesh.V, twist);
        const int count = static_cast<int>(mesh.T.rows());
        std::vector<Eigen::Matrix3d> F1(count), F2(count), F3(count);

        // (a) from the vertices every time: T, its inverse, dφ/dX, F.
        const double t1 = best_time([&] {
            for (int t = 0; t < count; ++t)
                F1[t] = deformation_gradient(tet_vertices(mesh, mesh.V, t), tet_vertices(mesh, x, t));
        }, min_seconds, 50);
        // (b) dφ/dX depends on the rest shape only: compute it once, then F = x_eᵀ dφ/dX.
        std::vector<ShapeGradients> G(count);
        for (int t = 0; t < count; ++t)
            G[t] = shape_gradients(tet_vertices(mesh, mesh.V, t));
        const double t2 = best_time([&] {
            for (int t = 0; t < count; ++t) {
                Eigen::Matrix<double, 3, 4> xe;
                for (int i = 0; i < 4; ++i)
                    xe.col(i) = x.row(mesh.T(t, i)).transpose();
                F2[t] = xe * G[t];
            }
        }, min_seconds, 50);
        // (c) the 9×12 B, also once: vec(F) = B q_e (row-major vec, vertex-major q_e).
        std::vector<Jacobian> B(count);
        for (int t = 0; t < count; ++t)
            B[t] = jacobian_matrix(tet_vertices(mesh, mesh.V, t));
        const double t3 = best_time([&] {
            for (int t = 0; t < count; ++t) {
                Eigen::Matrix<double, 12, 1> q;
                for (int i = 0; i < 4; ++i)
                    q.segment<3>(3 * i) = x.row(mesh.T(t, i)).transpose();
                const Eigen::Matrix<double, 9, 1> vec_F = B[t] * q;
                F3[t] = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(vec_F.data());
            }
        }, min_seconds, 50);

        double differ = 0.0;
        for (int t = 0; t < count; ++t)
            differ = std::max({differ, (F1[t] - F2[t]).norm(), (F1[t] - F3[t]).norm()});
        h.push_back(length / n);
        error.push_back(max_gradient_error(mesh, F1, twist));
        const Cell order = h.size() < 2 ? Cell(std::string("-")) : Cell(fd::observed_orders(h, error).back());
        table.add_row({double(n), double(count), h.back(), error.back(), order, differ, count / t1,
                       count / t2, count / t3});
    }
    table.print(std::cout);
    std::cout << "fitted order in h: " << fd::fitted_order(h, error) << '\n';
    table.write_csv(run.file("twist_convergence_table.csv"));
    fig::LineChart chart{str("Twist by ", settings.twist, " degrees: max error of the per-tet F"), "cell size h",
                         "max |F - F_exact| over tets", true, true, {{"linear tets", h, error}}};
    fig::save_chart(chart, run.out_dir / "twist_F_error", run.figures);
}

// 3. Locating points: random points in and around the beam.
void locate_study(const RunContext& run, const Settings& settings)
{
    const TetMesh mesh = beam(run.quick ? 8 : settings.cells);
    const int points = run.quick ? 200 : 2000;
    std::mt19937 random(2024);
    std::uniform_real_distribution<double> along(-0.05 * length, 1.05 * length), across(-0.05 * side, 1.05 * side);
    std::vector<Eigen::Vector3d> p(points);
    for (auto& point : p)
        point = Eigen::Vector3d(along(random), across(random), across(random));
    std::vector<PointLocation> found(points);
    const double seconds = best_time([&] {
        for (int k = 0; k < points; ++k)
            found[k] = locate_point(mesh, p[k]);
    }, 0.0, 1);
    int inside = 0;
    double reproduction = 0.0, outside_expected = 0;
    for (int k = 0; k < points; ++k) {
        inside += found[k].inside;
        const bool in_box = p[k].x() >= 0 && p[k].x() <= length && p[k].y() >= 0 && p[k].y() <= side &&
                            p[k].z() >= 0 && p[k].z() <= side;
        outside_expected += !in_box;
        if (found[k].inside != in_box)
            throw Error(str("locate_point disagrees with the box test for point ", k));
        reproduction = std::max(reproduction,
                                (tet_vertices(mesh, mesh.V, found[k].tet).transpose() * found[k].phi - p[k]).norm());
    }
    Table table(str("Locating random points in and around the beam (", mesh.T.rows(), " tets, brute force)"),
                {{"points", Format::integer}, {"inside", Format::integer}, {"outside", Format::integer},
                 {"outside the box", Format::integer}, {"max |sum phi_i X_i - p|", Format::scientific, 2},
                 {"rate [1/s]", Format::scientific, 2}});
    table.add_row({double(points), double(inside), double(points - inside), outside_expected, reproduction,
                   points / seconds});
    table.print(std::cout);
    table.write_csv(run.file("locate_table.csv"));
}

}  // namespace

int main(int argc, char** argv)
{
    ChapterCli cli("ch04_tet_jacobians", "04_tet_jacobians",
                   "Chapter 04: tet shape functions, the deformation gradient F, J_e and B");
    Settings settings;
    cli.app.add_option("--cells", settings.cells, "Cells along the beam")->check(check::integer(1, 400))
        ->capture_default_str();
    cli.app.add_option("--stretch", settings.stretch, "Stretch factor along x")->check(check::positive())
        ->capture_default_str();
    cli.app.add_option("--shear", settings.shear, "Shear x += shear * y")->check(check::finite())->capture_default_str();
    cli.app.add_option("--twist", settings.twist, "Total twist of the beam [degrees]")->check(check::finite())
        ->capture_default_str();
    cli.app.add_option("--pinch", settings.pinch, "Pinch depth (> 1 inverts tets near the middle)")
        ->check(check::finite())->capture_default_str();
    return cli.run(argc, argv, [&](const RunContext& run) {
        field_study(run, settings);
        twist_convergence_study(run, settings);
        locate_study(run, settings);
    });
}
