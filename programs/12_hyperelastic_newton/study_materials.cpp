// Study 1 of ch12_hyperelastic_newton: the three energy densities — their derivatives against
// finite differences, and the uniaxial stress–stretch curve of each, against the closed form for
// St. Venant–Kirchhoff and against linear elasticity. docs/12_hyperelastic_newton.md#energy-densities
#include "studies.hpp"

#include "common/error.hpp"
#include "common/figures.hpp"
#include "common/random.hpp"
#include "common/table.hpp"

#include <cmath>
#include <iostream>

namespace fem::hyper::study {
namespace {

/// The best relative error over h = 10⁻³ … 10⁻⁸ of central differences of ψ against P and of P
/// against ∂P/∂F, at the displacement gradient H.
std::pair<double, double> finite_difference_errors(const Material& material, const Eigen::Matrix3d& H)
{
    const Vector9d P = flatten(material.first_piola(H));
    const Matrix9d dP = material.piola_derivative(H);
    double best_P = 1e300, best_dP = 1e300;
    for (double h = 1e-3; h > 0.5e-8; h /= 10.0) {
        Vector9d fd_P;
        Matrix9d fd_dP;
        for (int i = 0; i < 9; ++i) {
            Eigen::Matrix3d plus = H, minus = H;
            plus(i / 3, i % 3) += h;
            minus(i / 3, i % 3) -= h;
            fd_P[i] = (material.energy_density(plus) - material.energy_density(minus)) / (2.0 * h);
            fd_dP.col(i) = (flatten(material.first_piola(plus)) - flatten(material.first_piola(minus))) / (2.0 * h);
        }
        best_P = std::min(best_P, (fd_P - P).norm() / P.norm());
        best_dP = std::min(best_dP, (fd_dP - dP).norm() / dP.norm());
    }
    return {best_P, best_dP};
}

/// The lateral stretch l at which a bar stretched by λ along x is free of lateral stress:
/// P₂₂(diag(λ, l, l)) = 0, by bisection on [0.05, 3].
double lateral_stretch(const Material& material, double stretch)
{
    const auto lateral_stress = [&](double l) {
        return material.first_piola(Eigen::Vector3d(stretch - 1.0, l - 1.0, l - 1.0).asDiagonal().toDenseMatrix())(1, 1);
    };
    double low = 0.05, high = 3.0;
    for (int k = 0; k < 200; ++k) {
        const double mid = 0.5 * (low + high);
        ((lateral_stress(low) < 0.0) == (lateral_stress(mid) < 0.0) ? low : high) = mid;
    }
    return 0.5 * (low + high);
}

}  // namespace

std::string model_in_words(const std::string& name)
{
    for (const MaterialNames& material : material_descriptions())
        if (material.name == name)
            return material.in_words;
    return name;
}

void materials_study(const RunContext& run, const Settings& settings)
{
    std::cout << "\n== 1. Energy densities: derivatives by finite differences, uniaxial stretch\n\n";
    const double youngs = settings.soft.youngs_modulus, poisson = settings.soft.poisson_ratio;
    // Why: P and ∂P/∂F are checked against ψ and P at random F, as HOBAK does for every material.
    Table derivatives("Best relative error of central differences (h = 1e-3 ... 1e-8) over 20 random F",
                      {{"material", Format::text}, {"P against psi [round-off]", Format::scientific, 1},
                       {"dP/dF against P [round-off]", Format::scientific, 1}});
    for (const std::string& name : material_names()) {
        const auto material = make_material(name, youngs, poisson);
        double worst_P = 0.0, worst_dP = 0.0;
        for (unsigned seed = 1; seed <= 20; ++seed) {
            const Eigen::Matrix3d H = 0.3 * Eigen::Matrix3d(fem::random_matrix(3, 3, seed));
            if (!material->defined_when_inverted() && volume_change(H) <= -1.0)
                continue;
            const auto [P, dP] = finite_difference_errors(*material, H);
            worst_P = std::max(worst_P, P);
            worst_dP = std::max(worst_dP, dP);
        }
        derivatives.add_row({name, worst_P, worst_dP});
    }
    derivatives.print(std::cout);
    derivatives.write_csv(run.file("derivatives_table.csv"));

    // Why: the materials agree for small strains and part ways for large ones; StVK softens under
    // compression (its force returns to zero as the bar flattens), neo-Hookean stiffens.
    fig::LineChart curves;
    curves.title = str("Uniaxial stretch (Y = ", youngs, " Pa, \u03BD = ", poisson, "): nominal stress P\u2081\u2081, laterally free");
    curves.x_label = "stretch \u03BB = l / L";
    curves.y_label = "P\u2081\u2081 [Pa]";
    std::vector<Column> columns{{"stretch", Format::fixed, 2}, {"linear (Pa)", Format::scientific, 4}};
    fig::Series linear{"linear", {}, {}};
    std::vector<fig::Series> series;
    for (const std::string& name : material_names()) {  // stvk, the registry's first, is P11[0] below
        series.push_back({name, {}, {}});
        columns.push_back({name + " (Pa)", Format::scientific, 4});
    }
    columns.push_back({"stvk against closed form [round-off]", Format::scientific, 1});
    Table uniaxial("Uniaxial stretch: P11 of each material, and StVK against its closed form lambda Y (lambda^2 - 1) / 2",
                   columns);
    for (int k = 0; k <= 25; ++k) {  // stretches 0.5 … 1.75: StVK collapses laterally past √(1 + 1/ν) ≈ 1.8
        const double stretch = (10 + k) / 20.0;
        linear.x.push_back(stretch);
        linear.y.push_back(youngs * (stretch - 1.0));
        std::vector<double> P11;
        for (std::size_t m = 0; m < series.size(); ++m) {
            const auto material = make_material(series[m].name, youngs, poisson);
            const double l = lateral_stretch(*material, stretch);
            P11.push_back(material->first_piola(Eigen::Vector3d(stretch - 1.0, l - 1.0, l - 1.0).asDiagonal().toDenseMatrix())(0, 0));
            series[m].x.push_back(stretch);
            series[m].y.push_back(P11.back());
        }
        const double closed = stretch * youngs * 0.5 * (stretch * stretch - 1.0);
        if (k % 5 == 0) {  // every 0.25 in the table
            std::vector<Cell> row{stretch, youngs * (stretch - 1.0)};
            row.insert(row.end(), P11.begin(), P11.end());
            row.push_back(std::abs(P11[0] - closed) / std::max(std::abs(closed), youngs));
            uniaxial.add_row(row);
        }
    }
    // The legend names the materials in words; the two stable neo-Hookean variants are dashed, as
    // neo-Hookean lies under them up to the largest stretches.
    curves.series.push_back(linear);
    for (fig::Series s : series) {
        s.dashed = s.name.rfind("stable-", 0) == 0;
        s.name = model_in_words(s.name);
        curves.series.push_back(s);
    }
    curves.legend = fig::Corner::top_left;
    uniaxial.print(std::cout);
    uniaxial.write_csv(run.file("uniaxial_table.csv"));
    fig::save_chart(curves, run.file("uniaxial"), run.figures);
}

}  // namespace fem::hyper::study
