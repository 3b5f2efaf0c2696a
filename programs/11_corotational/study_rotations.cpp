// Study 1 of ch11_corotational: which rotation an element gets. The lecture's edge fit against the
// centroid fit and the polar decomposition of F, on single tets and on every tet of the TetGen
// bunny; the slide's U Vᵀ against R = V Uᵀ. docs/11_corotational.md#edges-centroid-or-polar-decomposition
#include "studies.hpp"

#include "04_tet_jacobians/tet_jacobians.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh_io.hpp"
#include "common/random.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <iostream>

namespace fem::corot::study {
namespace {

/// The angle of the rotation R₁ᵀ R₂ [degrees]: how far apart two rotations are. From
/// ‖R₁ − R₂‖_F = 2√2 sin(θ/2), which unlike acos((tr R₁ᵀR₂ − 1)/2) keeps small angles accurate.
double angle_between(const Eigen::Matrix3d& R1, const Eigen::Matrix3d& R2)
{
    const double half_sine = std::min(1.0, (R1 - R2).norm() / (2.0 * std::sqrt(2.0)));
    return 2.0 * std::asin(half_sine) * 180.0 / M_PI;
}

/// The three fits of one tet deformed by x = A X, and the edge fit with the corners rotated by
/// one (1, 2, 0, 3: the same tet, another first corner).
struct Fits {
    Eigen::Matrix3d polar, centroid, edges, edges_other_corner;
};

Fits fits(const tet::TetVertices& X, const Eigen::Matrix3d& A)
{
    const tet::TetVertices x = X * A.transpose();
    tet::TetVertices X1, x1;
    X1 << X.row(1), X.row(2), X.row(0), X.row(3);
    x1 << x.row(1), x.row(2), x.row(0), x.row(3);
    return {polar_rotation(tet::deformation_gradient(X, x)), best_fit_rotation(centroid_covariance(X, x)),
            best_fit_rotation(edge_covariance(X, x)), best_fit_rotation(edge_covariance(X1, x1))};
}

}  // namespace

void rotation_study(const RunContext& run, const Settings& settings)
{
    std::cout << "\n== 1. Which rotation: the lecture's edge fit, the centroid fit, the polar decomposition of F\n\n";
    // Why: the slide takes U Vᵀ of S = Pᵀ Q; rotating a tet by a known R shows that is Rᵀ.
    Table slide("A tet rotated by a known R: the error of R = V U^T and of the slide's U V^T",
                {{"rotation angle (deg)", Format::fixed, 1}, {"V U^T error (deg) [round-off]", Format::scientific, 1},
                 {"U V^T error (deg)", Format::fixed, 1}});
    tet::TetVertices corner;
    corner << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
    for (const double degrees : {10.0, 45.0, 90.0, 170.0}) {
        const Eigen::Matrix3d R =
            Eigen::AngleAxisd(degrees * M_PI / 180.0, Eigen::Vector3d(1.0, 2.0, 2.0).normalized()).toRotationMatrix();
        const Eigen::Matrix3d S = edge_covariance(corner, corner * R.transpose());
        const Eigen::JacobiSVD<Eigen::Matrix3d> svd(S, Eigen::ComputeFullU | Eigen::ComputeFullV);
        slide.add_row({degrees, angle_between(best_fit_rotation(S), R),
                       angle_between(svd.matrixU() * svd.matrixV().transpose(), R)});
    }
    slide.print(std::cout);
    slide.write_csv(run.file("slide_table.csv"));

    // Why: the three fits agree for the tets they are exact for and part ways for skewed ones; on a
    // real mesh the edge fit also depends on which corner is listed first.
    Eigen::Matrix3d shear;
    shear << 1.0, 0.4, 0.0, 0.0, 1.0, 0.0, 0.1, 0.0, 0.9;
    const Eigen::Matrix3d A =
        Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix() * shear;
    tet::TetVertices regular, skewed;
    regular << 1, 1, 1, 1, -1, -1, -1, -1, 1, -1, 1, -1;
    skewed << 0, 0, 0, 1, 0, 0, 0.9, 0.1, 0, 0.3, 0.2, 0.05;
    Table table("One deformation x = A X (a 0.7 rad rotation of a shear), each tet's rotation by the three fits",
                {{"tets", Format::text}, {"edges vs polar (deg)", Format::fixed, 2},
                 {"centroid vs polar (deg)", Format::fixed, 2},
                 {"edges, corner 0 vs corner 1 first (deg)", Format::fixed, 2}});
    const auto add = [&](const std::string& name, const Fits& f) {
        table.add_row({name, angle_between(f.edges, f.polar), angle_between(f.centroid, f.polar),
                       angle_between(f.edges, f.edges_other_corner)});
    };
    add("corner tet (edges from corner 0 orthonormal)", fits(corner, A));
    add("regular tet", fits(regular, A));
    add("skewed tet (a sliver)", fits(skewed, A));
    const TetMesh bunny = io::read_tet_mesh(data_path("bunny_coarse.node"));
    std::vector<double> edges, centroid, order;
    for (int t = 0; t < static_cast<int>(bunny.T.rows()); ++t) {
        const Fits f = fits(tet::tet_vertices(bunny, bunny.V, t), A);
        edges.push_back(angle_between(f.edges, f.polar));
        centroid.push_back(angle_between(f.centroid, f.polar));
        order.push_back(angle_between(f.edges, f.edges_other_corner));
    }
    const auto quantile = [](std::vector<double> values, double q) {
        std::sort(values.begin(), values.end());
        return values[static_cast<std::size_t>(q * double(values.size() - 1))];
    };
    table.add_row({str("TetGen bunny, median of ", bunny.T.rows()), quantile(edges, 0.5), quantile(centroid, 0.5),
                   quantile(order, 0.5)});
    table.add_row({str("TetGen bunny, largest of ", bunny.T.rows()), quantile(edges, 1.0), quantile(centroid, 1.0),
                   quantile(order, 1.0)});
    table.print(std::cout);
    table.write_csv(run.file("fits_table.csv"));

    // Why: one polar decomposition per tet per step is the price of corotation; the hand-written
    // Newton iteration is measured against Eigen's SVD, the reference, on the F of real elements.
    Table speed("The polar rotation of 10,000 deformation gradients (a random rotation of a stretch within 20 %), "
                "SVD against Newton, one and four at a time",
                {{"algorithm", Format::text}, {"rotations per second [measured]", Format::scientific, 2},
                 {"max |R^T R - I| [round-off]", Format::scientific, 1}, {"max |R - R_svd| [round-off]", Format::scientific, 1}});
    std::vector<Eigen::Matrix3d> gradients;
    for (unsigned seed = 1; seed <= 10000; ++seed) {
        const Eigen::Matrix3d stretch = Eigen::Matrix3d::Identity() + 0.2 * Eigen::Matrix3d(fem::random_matrix(3, 3, seed));
        const Eigen::Vector3d axis = Eigen::Vector3d(fem::random_vector(3, seed + 20000)).normalized();
        gradients.push_back(Eigen::AngleAxisd(0.001 * seed, axis).toRotationMatrix() * stretch);
    }
    std::vector<Eigen::Matrix3d> reference(gradients.size());
    const std::vector<std::string> algorithms{"Eigen's JacobiSVD (polar_rotation)", "Newton (polar_rotation_newton)",
                                              "Newton, four at a time (polar_rotations_newton)"};
    for (std::size_t a = 0; a < algorithms.size(); ++a) {
        std::vector<Eigen::Matrix3d> rotations(gradients.size());
        const double seconds = best_time([&] {
            if (a == 2) {
                polar_rotations_newton(gradients.data(), rotations.data(), gradients.size());
                return;
            }
            for (std::size_t i = 0; i < gradients.size(); ++i)
                rotations[i] = a == 1 ? polar_rotation_newton(gradients[i]) : polar_rotation(gradients[i]);
        }, settings.seconds);
        if (a == 0)
            reference = rotations;
        double orthogonality = 0.0, difference = 0.0;
        for (std::size_t i = 0; i < gradients.size(); ++i) {
            orthogonality = std::max(orthogonality, (rotations[i].transpose() * rotations[i] -
                                                     Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff());
            difference = std::max(difference, (rotations[i] - reference[i]).cwiseAbs().maxCoeff());
        }
        speed.add_row({algorithms[a], double(gradients.size()) / seconds, orthogonality, difference});
    }
    speed.print(std::cout);
    speed.write_csv(run.file("polar_table.csv"));
}

}  // namespace fem::corot::study
