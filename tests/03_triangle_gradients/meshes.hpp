#pragma once
// Meshes and independent reference computations shared by the chapter 03 tests.

#include "common/mesh.hpp"
#include "common/types.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <map>
#include <numbers>
#include <utility>

namespace fem::test {

/// A closed, bumpy, sphere-like surface: a latitude-longitude sphere (two poles, `rings` rings of
/// `segments` vertices) with radius 1 + 0.2 sin(3x) cos(2y), every triangle facing outwards.
inline TriMesh bumpy_sphere(int rings = 12, int segments = 24)
{
    TriMesh mesh;
    const int count = 2 + rings * segments;
    mesh.V.resize(count, 3);
    const auto place = [&](int v, double theta, double phi) {
        Eigen::Vector3d x(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
        x *= 1.0 + 0.2 * std::sin(3 * x.x()) * std::cos(2 * x.y());
        mesh.V.row(v) = x.transpose();
    };
    place(0, 0.0, 0.0);
    place(count - 1, std::numbers::pi, 0.0);
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s)
            place(1 + r * segments + s, std::numbers::pi * (r + 1) / (rings + 1), 2 * std::numbers::pi * s / segments);
    const auto ring = [&](int r, int s) { return 1 + r * segments + (s % segments); };
    std::vector<Eigen::RowVector3i> faces;
    for (int s = 0; s < segments; ++s) {
        faces.emplace_back(0, ring(0, s), ring(0, s + 1));
        faces.emplace_back(count - 1, ring(rings - 1, s + 1), ring(rings - 1, s));
        for (int r = 0; r + 1 < rings; ++r) {
            faces.emplace_back(ring(r, s), ring(r + 1, s), ring(r + 1, s + 1));
            faces.emplace_back(ring(r, s), ring(r + 1, s + 1), ring(r, s + 1));
        }
    }
    mesh.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
    for (std::size_t f = 0; f < faces.size(); ++f) {
        Eigen::RowVector3i face = faces[f];
        const Eigen::Vector3d a = mesh.V.row(face[0]), b = mesh.V.row(face[1]), c = mesh.V.row(face[2]);
        if ((b - a).cross(c - a).dot(a + b + c) < 0.0)  // star-shaped around 0: outward means away from it
            std::swap(face[1], face[2]);
        mesh.F.row(static_cast<Eigen::Index>(f)) = face;
    }
    return mesh;
}

/// The classical cotangent weights w_ij = ½ Σ cot(angle opposite edge ij), keyed by (i < j),
/// computed from angles (acos of normalised dot products), independently of the library.
inline std::map<std::pair<int, int>, double> reference_cotangent_weights(const MatrixX3d& V, const MatrixX3i& F)
{
    std::map<std::pair<int, int>, double> weights;
    for (Eigen::Index f = 0; f < F.rows(); ++f)
        for (int k = 0; k < 3; ++k) {
            const int corner = F(f, k), i = F(f, (k + 1) % 3), j = F(f, (k + 2) % 3);
            const Eigen::Vector3d u = (V.row(i) - V.row(corner)).normalized();
            const Eigen::Vector3d v = (V.row(j) - V.row(corner)).normalized();
            const double angle = std::acos(std::clamp(u.dot(v), -1.0, 1.0));
            weights[{std::min(i, j), std::max(i, j)}] += 0.5 / std::tan(angle);
        }
    return weights;
}

/// The tangential part of vector a on triangle f (a minus its component along the unit normal).
inline Eigen::Vector3d tangential(const MatrixX3d& V, const MatrixX3i& F, Eigen::Index f, const Eigen::Vector3d& a)
{
    const Eigen::Vector3d p = V.row(F(f, 0)), q = V.row(F(f, 1)), r = V.row(F(f, 2));
    const Eigen::Vector3d n = (q - p).cross(r - p).normalized();
    return a - a.dot(n) * n;
}

}  // namespace fem::test
