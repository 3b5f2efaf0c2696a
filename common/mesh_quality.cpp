#include "common/mesh_quality.hpp"

#include "common/error.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace fem {
namespace {

constexpr double degrees = 180.0 / std::numbers::pi;

/// The angle between u and v in [0, π], accurate also near 0 and π (atan2 of |u×v| and u·v).
double angle_between(const Eigen::Vector3d& u, const Eigen::Vector3d& v)
{
    return std::atan2(u.cross(v).norm(), u.dot(v));
}

}  // namespace

std::array<double, 3> triangle_angles(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                      const Eigen::Vector3d& c)
{
    if ((b - a).norm() == 0.0 || (c - b).norm() == 0.0 || (a - c).norm() == 0.0)
        throw Error("triangle_angles: the triangle has a zero-length edge; its angles are undefined");
    return {angle_between(b - a, c - a), angle_between(c - b, a - b), angle_between(a - c, b - c)};
}

double triangle_aspect_ratio(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c)
{
    const double ab = (b - a).norm(), bc = (c - b).norm(), ca = (a - c).norm();
    const double area = 0.5 * (b - a).cross(c - a).norm();
    if (!(area > 0.0))
        return std::numeric_limits<double>::infinity();
    const double inradius = area / (0.5 * (ab + bc + ca));
    return std::max({ab, bc, ca}) / (2.0 * std::sqrt(3.0) * inradius);
}

std::array<double, 6> tet_dihedral_angles(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c, const Eigen::Vector3d& d)
{
    const Eigen::Vector3d p[4] = {a, b, c, d};
    // Outward normal of the face opposite corner k: orient (face normal) away from corner k.
    Eigen::Vector3d normal[4];
    for (int k = 0; k < 4; ++k) {
        const Eigen::Vector3d& x = p[(k + 1) % 4];
        const Eigen::Vector3d& y = p[(k + 2) % 4];
        const Eigen::Vector3d& z = p[(k + 3) % 4];
        normal[k] = (y - x).cross(z - x);
        if (normal[k].norm() == 0.0)
            throw Error(str("tet_dihedral_angles: the face opposite corner ", k,
                            " has zero area; the dihedral angles are undefined"));
        if (normal[k].dot(p[k] - x) > 0.0)
            normal[k] = -normal[k];
    }
    // Edge (i, j) is shared by the faces opposite the other two corners k and l.
    constexpr int edges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    std::array<double, 6> angles{};
    for (int e = 0; e < 6; ++e) {
        int other[2], n = 0;
        for (int k = 0; k < 4; ++k)
            if (k != edges[e][0] && k != edges[e][1])
                other[n++] = k;
        angles[e] = std::numbers::pi - angle_between(normal[other[0]], normal[other[1]]);
    }
    return angles;
}

double tet_aspect_ratio(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                        const Eigen::Vector3d& d)
{
    const double volume = std::abs((b - a).dot((c - a).cross(d - a))) / 6.0;
    if (!(volume > 0.0))
        return std::numeric_limits<double>::infinity();
    const double faces = 0.5 * ((c - b).cross(d - b).norm() + (c - a).cross(d - a).norm() +
                                (b - a).cross(d - a).norm() + (b - a).cross(c - a).norm());
    const double longest = std::max({(b - a).norm(), (c - a).norm(), (d - a).norm(), (c - b).norm(),
                                     (d - b).norm(), (d - c).norm()});
    const double inradius = 3.0 * volume / faces;
    return longest / (2.0 * std::sqrt(6.0) * inradius);
}

TriQuality mesh_quality(const TriMesh& mesh)
{
    validate(mesh);
    TriQuality q;
    q.min_angle_deg = q.min_area = std::numeric_limits<double>::infinity();
    for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
        const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                              c = mesh.V.row(mesh.F(f, 2));
        const auto angles = triangle_angles(a, b, c);
        const double smallest = *std::min_element(angles.begin(), angles.end()) * degrees;
        const double largest = *std::max_element(angles.begin(), angles.end()) * degrees;
        q.min_angle_deg = std::min(q.min_angle_deg, smallest);
        q.max_angle_deg = std::max(q.max_angle_deg, largest);
        if (largest > 90.0)
            ++q.obtuse_triangles;
        const double area = 0.5 * (b - a).cross(c - a).norm();
        q.min_area = std::min(q.min_area, area);
        q.max_area = std::max(q.max_area, area);
        const double aspect = triangle_aspect_ratio(a, b, c);
        if (aspect > q.max_aspect_ratio) {
            q.max_aspect_ratio = aspect;
            q.worst_triangle = static_cast<int>(f);
        }
    }
    return q;
}

TetQuality mesh_quality(const TetMesh& mesh)
{
    TetMesh checked = mesh;
    validate(checked, "mesh", Inverted::reorient);  // inverted tets are measured, not refused
    TetQuality q;
    q.min_dihedral_deg = q.min_volume = std::numeric_limits<double>::infinity();
    q.max_volume = -std::numeric_limits<double>::infinity();
    for (Eigen::Index t = 0; t < mesh.T.rows(); ++t) {
        const Eigen::Vector3d a = mesh.V.row(mesh.T(t, 0)), b = mesh.V.row(mesh.T(t, 1)),
                              c = mesh.V.row(mesh.T(t, 2)), d = mesh.V.row(mesh.T(t, 3));
        for (double angle : tet_dihedral_angles(a, b, c, d)) {
            q.min_dihedral_deg = std::min(q.min_dihedral_deg, angle * degrees);
            q.max_dihedral_deg = std::max(q.max_dihedral_deg, angle * degrees);
        }
        const double volume = tet_signed_volume6(mesh, static_cast<int>(t)) / 6.0;
        q.min_volume = std::min(q.min_volume, volume);
        q.max_volume = std::max(q.max_volume, volume);
        const double aspect = tet_aspect_ratio(a, b, c, d);
        if (aspect > q.max_aspect_ratio) {
            q.max_aspect_ratio = aspect;
            q.worst_tet = static_cast<int>(t);
        }
    }
    return q;
}

}  // namespace fem
