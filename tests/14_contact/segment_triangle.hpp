#pragma once
// Chapter 14's tests: an exact test of whether a segment meets a triangle, in long double, to check
// that no edge has passed through a face (self-contact, an obstacle's edges against a body's faces).
// docs/14_contact.md#checks

#include <Eigen/Core>

namespace fem::test {

/// 6 × the signed volume of (a, b, c, d) in long double: > 0 when d is on the side of (a, b, c) its
/// normal (b − a) × (c − a) points to.
inline long double orient(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                          const Eigen::Vector3d& d)
{
    const auto ld = [](const Eigen::Vector3d& x) { return Eigen::Matrix<long double, 3, 1>(x.cast<long double>()); };
    return (ld(b) - ld(a)).cross(ld(c) - ld(a)).dot(ld(d) - ld(a));
}

/// Whether segment (p, q) meets triangle (a, b, c), touching included: p and q not strictly on one
/// side of the plane, and the segment's line not strictly outside any of the triangle's edges (the
/// three volumes of (p, q) with each edge of one sign or zero). Degenerate, coplanar cases count as
/// meeting (conservative: a test that says "apart" means apart).
inline bool segment_meets_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                                   const Eigen::Vector3d& b, const Eigen::Vector3d& c)
{
    const long double sp = orient(a, b, c, p), sq = orient(a, b, c, q);
    if ((sp > 0 && sq > 0) || (sp < 0 && sq < 0))
        return false;
    const long double e0 = orient(p, q, a, b), e1 = orient(p, q, b, c), e2 = orient(p, q, c, a);
    return !((e0 > 0 || e1 > 0 || e2 > 0) && (e0 < 0 || e1 < 0 || e2 < 0));
}

}  // namespace fem::test
