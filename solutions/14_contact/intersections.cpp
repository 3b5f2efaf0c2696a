// Chapter 14: the intersection check (intersections.hpp). docs/14_contact.md#never-an-intersection
#include "14_contact/intersections.hpp"

#include "13_skinning/skinning.hpp"

#include "common/error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace fem::contact {

int certified_orientation(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                          const Eigen::Vector3d& d)
{
    // Shewchuk's orient3d, its first (a-priori) stage: the determinant of the differences from d and
    // the permanent of their magnitudes, which bounds the round-off of the whole computation.
    const Eigen::Vector3d ad = a - d, bd = b - d, cd = c - d;
    const double bc_x = bd.y() * cd.z() - bd.z() * cd.y(), ca_x = cd.y() * ad.z() - cd.z() * ad.y(),
                 ab_x = ad.y() * bd.z() - ad.z() * bd.y();
    const double determinant = ad.x() * bc_x + bd.x() * ca_x + cd.x() * ab_x;
    const double permanent = (std::abs(bd.y() * cd.z()) + std::abs(bd.z() * cd.y())) * std::abs(ad.x()) +
                             (std::abs(cd.y() * ad.z()) + std::abs(cd.z() * ad.y())) * std::abs(bd.x()) +
                             (std::abs(ad.y() * bd.z()) + std::abs(ad.z() * bd.y())) * std::abs(cd.x());
    constexpr double epsilon = std::numeric_limits<double>::epsilon() / 2.0;  // 2⁻⁵³
    const double bound = (7.0 + 56.0 * epsilon) * epsilon * permanent;
    // orient3d(a, b, c, d) in Shewchuk's convention is positive when d is below the plane of a, b, c
    // seen counter-clockwise: the opposite of (b − a) × (c − a) · (d − a).
    if (determinant > bound)
        return -1;
    if (determinant < -bound)
        return 1;
    return 0;
}

bool segment_meets_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b, const Eigen::Vector3d& c)
{
    const int sp = certified_orientation(a, b, c, p), sq = certified_orientation(a, b, c, q);
    if (sp != 0 && sp == sq)
        return false;  // both strictly on one side of the plane
    const int e0 = certified_orientation(p, q, a, b), e1 = certified_orientation(p, q, b, c),
              e2 = certified_orientation(p, q, c, a);
    const bool some_positive = e0 > 0 || e1 > 0 || e2 > 0, some_negative = e0 < 0 || e1 < 0 || e2 < 0;
    return !(some_positive && some_negative);  // the line strictly outside an edge: apart
}

EdgeThroughTriangle first_edge_through_triangle(const MatrixX3d& x, const Eigen::MatrixX2i& edges,
                                                const MatrixX3i& triangles)
{
    const Eigen::Index n = x.rows();
    if (!x.allFinite())
        throw Error("first_edge_through_triangle: a position is not finite");
    if (edges.size() > 0 && (edges.minCoeff() < 0 || edges.maxCoeff() >= n))
        throw Error(str("first_edge_through_triangle: an edge's vertex is outside the ", n, " positions"));
    if (triangles.size() > 0 && (triangles.minCoeff() < 0 || triangles.maxCoeff() >= n))
        throw Error(str("first_edge_through_triangle: a triangle's vertex is outside the ", n, " positions"));
    EdgeThroughTriangle crossing;
    if (edges.rows() == 0 || triangles.rows() == 0)
        return crossing;
    std::vector<Eigen::Matrix<double, 2, 3>> boxes(static_cast<std::size_t>(triangles.rows()));
    for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
        Eigen::Matrix<double, 2, 3>& box = boxes[static_cast<std::size_t>(t)];
        box.row(0) = box.row(1) = x.row(triangles(t, 0));
        for (int k = 1; k < 3; ++k) {
            box.row(0) = box.row(0).cwiseMin(x.row(triangles(t, k)));
            box.row(1) = box.row(1).cwiseMax(x.row(triangles(t, k)));
        }
    }
    const skin::BoxHierarchy tree = skin::box_hierarchy(boxes, 4);
    for (Eigen::Index e = 0; e < edges.rows(); ++e) {
        const int i = edges(e, 0), j = edges(e, 1);
        const Eigen::Vector3d p = x.row(i).transpose(), q = x.row(j).transpose();
        std::vector<int> found = skin::boxes_meeting(tree, boxes, p.cwiseMin(q), p.cwiseMax(q));
        std::sort(found.begin(), found.end());
        for (int t : found) {
            const auto triangle = triangles.row(t);
            if ((triangle.array() == i).any() || (triangle.array() == j).any())
                continue;  // an edge of the triangle, or one meeting it at a corner
            if (segment_meets_triangle(p, q, x.row(triangle(0)).transpose(), x.row(triangle(1)).transpose(),
                                       x.row(triangle(2)).transpose()))
                return {static_cast<int>(e), t};
        }
    }
    return crossing;
}

std::string describe(const EdgeThroughTriangle& crossing, const Eigen::MatrixX2i& edges, const MatrixX3i& triangles)
{
    if (!crossing.found())
        return {};
    const auto t = triangles.row(crossing.triangle);
    return str("edge (", edges(crossing.edge, 0), ", ", edges(crossing.edge, 1), ") meets triangle (", t(0), ", ",
               t(1), ", ", t(2), ")");
}

}  // namespace fem::contact
