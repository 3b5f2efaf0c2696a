// ch05_strain_stress: the Voigt convention checked against the tensor energy, linear against Green
// strain under rotation, the conditioning of K_e as ν → ½, the cost of K_e, and strain and von Mises
// stress on a twisted beam.
//
// Sample runs:
//   ch05_strain_stress                         full run, files in out/05_strain_stress
//   ch05_strain_stress --quick                 the small run ctest checks
//   ch05_strain_stress --twist 120 --poisson 0.3 --cells 24
//
// Writes: tables voigt_table.csv, rotation_table.csv, conditioning_table.csv, stiffness_table.csv,
// twisted_beam_table.csv; charts (PNG + CSV) rotation_strain, conditioning; the mesh
// twisted_beam.vtu (rest positions and displacement; cell data linear and Green strain, von Mises stresses) and
// its pictures twisted_beam_linear.png, twisted_beam_green.png.
// docs/05_strain_stress.md

#include "05_strain_stress/strain_stress.hpp"
#include "04_tet_jacobians/deformation_fields.hpp"
#include "04_tet_jacobians/tet_jacobians.hpp"

#include "common/cli.hpp"
#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/mesh.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"
#include "common/vtk_io.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <cmath>
#include <iostream>
#include <numbers>
#include <random>

using namespace fem;
using namespace fem::elastic;
using tet::TetVertices;
using Vector12d = Eigen::Matrix<double, 12, 1>;

namespace {

struct Settings {
    double youngs = 1e5;   // Young's modulus Y [Pa] (rubber)
    double poisson = 0.45; // Poisson's ratio ν
    double twist = 60.0;   // total twist of the beam [degrees]
    int cells = 16;        // cells along the beam
};

constexpr double length = 1.0, side = 0.25, centre = side / 2;
constexpr double degree = std::numbers::pi / 180.0;

/// A tet with no symmetry, so no component of a test deformation vanishes by accident.
TetVertices skew_tet()
{
    TetVertices X;
    X << 0.1, -0.2, 0.3,
         1.3, 0.1, -0.1,
         0.4, 1.1, 0.2,
         0.2, 0.3, 0.9;
    return X;
}

/// Vertex-major displacements u_e of the field u(X) = A X at the tet's vertices.
Vector12d linear_displacement(const TetVertices& X, const Eigen::Matrix3d& A)
{
    Vector12d u;
    for (int i = 0; i < 4; ++i)
        u.segment<3>(3 * i) = A * X.row(i).transpose();
    return u;
}

// 1. The Voigt convention: four ways to write D and C, checked on pure shear and uniaxial strain
//    against the tensor energy V ψ = V (μ ε:ε + λ/2 tr(ε)²).
void voigt_study(const RunContext& run, const Lame& material)
{
    const TetVertices X = skew_tet();
    const double V = std::abs(tet::signed_volume(X)), g = 1e-3;
    Eigen::Matrix3d shear = Eigen::Matrix3d::Zero(), uniaxial = Eigen::Matrix3d::Zero();
    shear(0, 1) = shear(1, 0) = g;  // u = (g y, g x, 0): ε_xy = g
    uniaxial(0, 0) = g;
    struct Convention {
        std::string name, d_text, c_text;
        double d, c, stress_scale;  // D's shear factor, C's shear diagonal / μ, shear entry / σ_xy
    };
    const double r = std::sqrt(2.0);
    const std::vector<Convention> conventions{
        {"lecture (tensor strain, mu)", "1/2", "mu", 0.5, 1.0, 1.0},
        {"tensor strain, 2 mu", "1/2", "2 mu", 0.5, 2.0, 1.0},
        {"engineering strain, mu (ours)", "1", "mu", 1.0, 1.0, 1.0},
        {"Mandel (sqrt 2), 2 mu", "1/sqrt2", "2 mu", 1.0 / r, 2.0, r}};
    Table table("Voigt conventions against the tensor formulas (pure shear eps_xy = 1e-3, uniaxial eps_xx = 1e-3)",
                {{"convention", Format::text}, {"D shear entries", Format::text}, {"C shear diagonal", Format::text},
                 {"sigma_xy / (2 mu eps_xy)", Format::fixed, 4}, {"shear energy / exact", Format::fixed, 4},
                 {"uniaxial energy / exact", Format::fixed, 4}});
    const tet::Jacobian J = tet::jacobian_matrix(X);
    for (const Convention& k : conventions) {
        StrainSelection D = strain_selection_matrix();
        D.bottomRows<3>() *= k.d;
        Matrix6d C = elasticity_matrix(material);
        C.bottomRightCorner<3, 3>() *= k.c;
        const StrainDisplacement B = D * J;
        const auto energy = [&](const Eigen::Matrix3d& A) {
            const Vector6d e = B * linear_displacement(X, A);
            return 0.5 * V * e.dot(C * e);
        };
        const Vector6d s = C * (B * linear_displacement(X, shear));
        table.add_row({k.name, k.d_text, k.c_text, s[3] / k.stress_scale / (2 * material.mu * g),
                       energy(shear) / (V * energy_density(material, shear)),
                       energy(uniaxial) / (V * energy_density(material, uniaxial))});
    }
    table.print(std::cout);
    table.write_csv(run.file("voigt_table.csv"));
}

// 2. A rigid rotation: Green strain stays zero, linear strain grows like θ²/√2, and so does the
//    energy K_e assigns to the rotated tet (the reason for corotation, chapter 11).
void rotation_study(const RunContext& run, const Lame& material)
{
    const TetVertices X = skew_tet();
    const double V = std::abs(tet::signed_volume(X));
    const Matrix12d K = element_stiffness(X, material);
    const Eigen::Vector3d axis = Eigen::Vector3d(1.0, 1.0, 1.0).normalized();
    Table table("A tet rotated rigidly by an angle about (1,1,1): the strain each measure sees",
                {{"angle [deg]", Format::fixed, 1}, {"|linear strain|", Format::scientific, 3},
                 {"sqrt2 (1 - cos)", Format::scientific, 3}, {"|Green strain|", Format::scientific, 2},
                 {"K_e energy / V [J/m^3]", Format::scientific, 3}, {"von Mises, linear [Pa]", Format::scientific, 3},
                 {"von Mises, Green [Pa]", Format::scientific, 2}});
    std::vector<double> angles, linear, green, predicted, small_angle;
    for (double a : {0.1, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 45.0, 90.0, 180.0}) {
        const Eigen::Matrix3d R = Eigen::AngleAxisd(a * degree, axis).toRotationMatrix();
        const Eigen::Matrix3d F = tet::deformation_gradient(X, X * R.transpose());
        const Eigen::Matrix3d eps = small_strain(F), E = green_strain(F);
        const Vector12d u = linear_displacement(X, R - Eigen::Matrix3d::Identity());
        angles.push_back(a);
        linear.push_back(eps.norm());
        green.push_back(E.norm());
        predicted.push_back(std::sqrt(2.0) * (1.0 - std::cos(a * degree)));
        small_angle.push_back(std::pow(a * degree, 2) / std::sqrt(2.0));
        table.add_row({a, linear.back(), predicted.back(), green.back(), 0.5 * u.dot(K * u) / V,
                       von_mises(stress(material, strain_to_voigt(eps))),
                       von_mises(stress(material, strain_to_voigt(E)))});
    }
    table.print(std::cout);
    table.write_csv(run.file("rotation_table.csv"));
    fig::LineChart chart{"Strain of a rigidly rotated tet", "rotation angle [degrees]", "|strain| (Frobenius)", true,
                         true, {{"linear strain", angles, linear},
                                // dashed: up to 45 degrees it lies on the linear strain
                                {"theta^2 / sqrt2 (small angles)", angles, small_angle, false, true},
                                {"Green strain (round-off)", angles, green}}};
    fig::save_chart(chart, run.out_dir / "rotation_strain", run.figures);
}

// 3. ν → ½: the condition number of K_e (largest over smallest non-zero eigenvalue) against λ/μ.
void conditioning_study(const RunContext& run, const Settings& settings)
{
    TetVertices regular;
    regular << 1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1;
    Table table("Conditioning of K_e of a regular tet as nu -> 1/2 (rigid modes excluded)",
                {{"nu", Format::fixed, 5}, {"lambda/mu", Format::scientific, 3}, {"cond(K_e)", Format::scientific, 3},
                 {"cond / (lambda/mu)", Format::fixed, 4}, {"smallest non-zero / (mu V)", Format::fixed, 4}});
    std::vector<double> ratio, condition;
    for (double nu : {0.1, 0.3, 0.45, 0.49, 0.499, 0.4999, 0.49999}) {
        const Lame m = lame_parameters(settings.youngs, nu);
        const Eigen::VectorXd values =
            Eigen::SelfAdjointEigenSolver<Matrix12d>(element_stiffness(regular, m), Eigen::EigenvaluesOnly).eigenvalues();
        ratio.push_back(m.lambda / m.mu);
        condition.push_back(values[11] / values[6]);
        table.add_row({nu, ratio.back(), condition.back(), condition.back() / ratio.back(),
                       values[6] / (m.mu * std::abs(tet::signed_volume(regular)))});
    }
    table.print(std::cout);
    table.write_csv(run.file("conditioning_table.csv"));
    fig::LineChart chart{"Condition number of K_e as nu -> 1/2", "lambda / mu", "cond(K_e)", true, true,
                         {{"regular tet", ratio, condition}}};
    fig::save_chart(chart, run.out_dir / "conditioning", run.figures);
}

/// K_e block by block from dφ/dX, without B_e: K_ij = V (λ ∇φᵢ∇φⱼᵀ + μ ∇φⱼ∇φᵢᵀ + μ (∇φᵢ·∇φⱼ) I).
Matrix12d closed_form_stiffness(const TetVertices& X, const Lame& m)
{
    const tet::ShapeGradients G = tet::shape_gradients(X);
    const double V = std::abs(tet::signed_volume(X));
    Matrix12d K;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            const Eigen::Vector3d gi = G.row(i).transpose(), gj = G.row(j).transpose();
            K.block<3, 3>(3 * i, 3 * j) = V * (m.lambda * gi * gj.transpose() + m.mu * gj * gi.transpose() +
                                                m.mu * gi.dot(gj) * Eigen::Matrix3d::Identity());
        }
    return K;
}

/// The same V B_eᵀ C B_e with dynamic-size matrices (a heap allocation per temporary).
Eigen::MatrixXd dynamic_stiffness(const TetVertices& X, const Lame& m)
{
    const Eigen::MatrixXd B = strain_displacement_matrix(X);
    const Eigen::MatrixXd C = elasticity_matrix(m);
    return std::abs(tet::signed_volume(X)) * B.transpose() * C * B;
}

// 4. Speed against error: K_e for every tet of the beam, three ways; each checked against the
//    tensor energy V ψ(ε) for a random displacement per tet.
void stiffness_study(const RunContext& run, const Settings& settings, const Lame& material)
{
    const TetMesh mesh = beam_mesh(length, side, side, run.quick ? 8 : settings.cells);
    const int count = static_cast<int>(mesh.T.rows());
    std::vector<TetVertices> X(count);
    std::vector<Vector12d> u(count);
    std::vector<double> exact(count);
    std::mt19937 random(5);
    std::uniform_real_distribution<double> entry(-1e-3, 1e-3);
    for (int t = 0; t < count; ++t) {
        X[t] = tet::tet_vertices(mesh, mesh.V, t);
        for (int k = 0; k < 12; ++k)
            u[t][k] = entry(random);
        // ∇u = Σ uᵢ ∇φᵢᵀ: the "deformation gradient" of the map X → u(X), without forming X + u.
        TetVertices u_rows;
        for (int i = 0; i < 4; ++i)
            u_rows.row(i) = u[t].segment<3>(3 * i).transpose();
        const Eigen::Matrix3d grad_u = tet::deformation_gradient(X[t], u_rows);
        exact[t] = std::abs(tet::signed_volume(X[t])) * energy_density(material, 0.5 * (grad_u + grad_u.transpose()));
    }
    std::vector<Matrix12d> reference(count);
    for (int t = 0; t < count; ++t)
        reference[t] = element_stiffness(X[t], material);

    Table table(str("K_e for the ", count, " tets of the beam: energy error against V psi(eps) for a random u per tet, "
                    "and the rate"),
                {{"method", Format::text}, {"max energy error (relative)", Format::scientific, 2},
                 {"max |K_e - element_stiffness| / |K_e|", Format::scientific, 2}, {"rate [1/s]", Format::scientific, 2}});
    const double min_seconds = run.quick ? 0.02 : 0.1;
    const auto report = [&](const std::string& name, const auto& compute) {
        std::vector<Matrix12d> K(count);
        const double seconds = best_time([&] {
            for (int t = 0; t < count; ++t)
                K[t] = compute(X[t]);
        }, min_seconds, 50);
        double energy_error = 0.0, difference = 0.0;
        for (int t = 0; t < count; ++t) {
            energy_error = std::max(energy_error, std::abs(0.5 * u[t].dot(K[t] * u[t]) - exact[t]) / exact[t]);
            difference = std::max(difference, (K[t] - reference[t]).norm() / reference[t].norm());
        }
        table.add_row({name, energy_error, difference, count / seconds});
    };
    report("V B_e^T C B_e, fixed-size (element_stiffness)",
           [&](const TetVertices& Xt) { return element_stiffness(Xt, material); });
    report("V B_e^T C B_e, dynamic-size", [&](const TetVertices& Xt) -> Matrix12d { return dynamic_stiffness(Xt, material); });
    report("closed form from dphi/dX", [&](const TetVertices& Xt) { return closed_form_stiffness(Xt, material); });
    table.print(std::cout);
    table.write_csv(run.file("stiffness_table.csv"));
}

/// Per-tet strains and stresses of the beam under a twist.
struct BeamStrains {
    MatrixX3d x;
    Eigen::MatrixXd linear, green;               // Voigt (engineering shear), one row per tet
    Eigen::VectorXd mises_linear, mises_green;   // von Mises of C ε and of C E [Pa]
    double max_green_exact = 0, max_green_error = 0, max_linear_error = 0;
};

BeamStrains twisted_beam(const TetMesh& mesh, double twist_degrees, const Lame& material)
{
    const tet::DeformationField twist = tet::twist_field(twist_degrees * degree / length, centre, centre);
    BeamStrains out;
    out.x = tet::deform(mesh.V, twist);
    const std::vector<Eigen::Matrix3d> F = tet::deformation_gradients(mesh, out.x);
    const Eigen::Index n = mesh.T.rows();
    out.linear.resize(n, 6);
    out.green.resize(n, 6);
    out.mises_linear.resize(n);
    out.mises_green.resize(n);
    for (Eigen::Index t = 0; t < n; ++t) {
        const Eigen::Matrix3d eps = small_strain(F[t]), E = green_strain(F[t]);
        const Eigen::Vector3d centroid =
            tet::tet_vertices(mesh, mesh.V, static_cast<int>(t)).colwise().mean().transpose();
        const Eigen::Matrix3d E_exact = green_strain(twist.gradient(centroid));
        out.linear.row(t) = strain_to_voigt(eps).transpose();
        out.green.row(t) = strain_to_voigt(E).transpose();
        out.mises_linear[t] = von_mises(stress(material, strain_to_voigt(eps)));
        out.mises_green[t] = von_mises(stress(material, strain_to_voigt(E)));
        out.max_green_exact = std::max(out.max_green_exact, E_exact.norm());
        out.max_green_error = std::max(out.max_green_error, (E - E_exact).norm());
        out.max_linear_error = std::max(out.max_linear_error, (eps - E_exact).norm());
    }
    return out;
}

// 5. The twisted beam: linear against Green strain per tet, for growing twist; files for one twist.
void twisted_beam_study(const RunContext& run, const Settings& settings, const Lame& material)
{
    const TetMesh mesh = beam_mesh(length, side, side, run.quick ? 8 : settings.cells);
    Table table(str("Twisted ", length, " x ", side, " x ", side, " beam, ", mesh.T.rows(),
                    " tets: per-tet strain against the exact Green strain at the centroid"),
                {{"twist [deg]", Format::fixed, 1}, {"max |E exact|", Format::scientific, 3},
                 {"max |E - E exact|", Format::scientific, 3}, {"max |eps linear - E exact|", Format::scientific, 3},
                 {"max von Mises, linear [Pa]", Format::scientific, 3},
                 {"max von Mises, Green [Pa]", Format::scientific, 3}});
    for (double twist : {5.0, 15.0, 30.0, 60.0, 90.0, 180.0}) {
        const BeamStrains s = twisted_beam(mesh, twist, material);
        table.add_row({twist, s.max_green_exact, s.max_green_error, s.max_linear_error, s.mises_linear.maxCoeff(),
                       s.mises_green.maxCoeff()});
    }
    table.print(std::cout);
    table.write_csv(run.file("twisted_beam_table.csv"));

    const BeamStrains s = twisted_beam(mesh, settings.twist, material);
    io::MeshData data = io::displaced_mesh(mesh.V, mesh.T, s.x - mesh.V);
    data.cell_data = {{"linear strain", s.linear}, {"Green strain", s.green},
                      {"vM linear", s.mises_linear}, {"vM Green", s.mises_green}};
    io::write_vtu(run.file("twisted_beam.vtu"), data);
    if (run.figures) {
        const double top = std::max(s.mises_linear.maxCoeff(), s.mises_green.maxCoeff());
        for (const auto& [field, file, what] :
             {std::tuple{"vM linear", "twisted_beam_linear.png", "linear strain"},
              std::tuple{"vM Green", "twisted_beam_green.png", "Green strain"}}) {
            fig::RenderOptions options;
            options.field = field;
            options.unit = "Pa";
            options.title = str("beam twisted by ", settings.twist, " degrees: von Mises stress [Pa] from ", what);
            options.range = std::make_pair(0.0, top);
            options.view_direction = {-0.45, 0.75, -0.5};
            options.view_up = {0.0, 0.0, 1.0};
            options.height = 520;
            fig::render_mesh_png(run.file(file), io::warped(data), options);
        }
    }
}

}  // namespace

int main(int argc, char** argv)
{
    ChapterCli cli("ch05_strain_stress", "05_strain_stress",
                   "Chapter 05: strain, stress, Lame parameters and the element stiffness K_e");
    Settings settings;
    cli.app.add_option("--youngs", settings.youngs, "Young's modulus Y [Pa]")->check(check::positive())
        ->capture_default_str();
    cli.app.add_option("--poisson", settings.poisson, "Poisson's ratio nu")
        ->check(check::real(-1.0, 0.5, check::Ends::open))->capture_default_str();
    cli.app.add_option("--twist", settings.twist, "Twist of the beam in the pictures [degrees]")
        ->check(check::finite())->capture_default_str();
    cli.app.add_option("--cells", settings.cells, "Cells along the beam")->check(check::integer(1, 400))
        ->capture_default_str();
    return cli.run(argc, argv, [&](const RunContext& run) {
        const Lame material = lame_parameters(settings.youngs, settings.poisson);
        std::cout << "material: Y = " << settings.youngs << " Pa, nu = " << settings.poisson
                  << ": lambda = " << material.lambda << " Pa, mu = " << material.mu << " Pa\n\n";
        voigt_study(run, material);
        rotation_study(run, material);
        conditioning_study(run, settings);
        stiffness_study(run, settings, material);
        twisted_beam_study(run, settings, material);
    });
}
