// Chapter 15: the barrier between the surface primitives of one mesh (bodies against bodies and
// a body against itself). docs/15_body_contact.md#bodies-against-bodies-and-self-contact
#include "15_body_contact/self_barrier.hpp"

#include "15_body_contact/ccd.hpp"
#include "15_body_contact/distances.hpp"
#include "15_body_contact/pair_barrier.hpp"

#include "12_hyperelastic_newton/materials.hpp"

#include "common/error.hpp"
#include "common/types.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fem::contact {
SelfContactBarrier::SelfContactBarrier(const TetMesh& mesh, double activation_distance, std::vector<int> vertex_body,
                                       std::vector<bool> body_self_contact)
    : rest_(mesh.V),
      activation_distance_(activation_distance),
      surface_(surface_primitives(mesh)),
      vertex_body_(std::move(vertex_body)),
      body_self_contact_(std::move(body_self_contact))
{
    require_positive(activation_distance, "self-contact activation distance d̂ [m]");
    if (!vertex_body_.empty() && static_cast<Eigen::Index>(vertex_body_.size()) != mesh.V.rows())
        throw Error(str("self-contact: ", vertex_body_.size(), " vertex bodies for ", mesh.V.rows(), " vertices"));
    if (!body_self_contact_.empty())
        for (int body : vertex_body_)
            if (body < 0 || body >= static_cast<int>(body_self_contact_.size()))
                throw Error(str("self-contact: body ", body, " of a vertex has no self-contact setting (",
                                body_self_contact_.size(), " given)"));
}

CandidatePairs SelfContactBarrier::kept(CandidatePairs candidates) const
{
    if (vertex_body_.empty() || body_self_contact_.empty())
        return candidates;
    const auto apart = [&](int a, int b) {  // two bodies, or one that holds itself off
        const int body = vertex_body_[std::size_t(a)];
        return body != vertex_body_[std::size_t(b)] || body_self_contact_[std::size_t(body)];
    };
    std::erase_if(candidates.point_triangle, [&](const std::array<int, 2>& pair) {
        return !apart(pair[0], surface_.triangles(pair[1], 0));
    });
    std::erase_if(candidates.edge_edge, [&](const std::array<int, 2>& pair) {
        return !apart(surface_.edges(pair[0], 0), surface_.edges(pair[1], 0));
    });
    return candidates;
}

MatrixX3d SelfContactBarrier::moved(const MatrixX3d& x, const Eigen::VectorXd& u, const char* what) const
{
    if (u.size() != 3 * x.rows())
        throw Error(str("self-contact: ", what, " needs 3n = ", 3 * x.rows(), " entries, got ", u.size()));
    MatrixX3d moved = x;
    for (Eigen::Index v = 0; v < x.rows(); ++v)
        moved.row(v) += u.segment<3>(3 * v).transpose();
    return moved;
}

const CandidatePairs& SelfContactBarrier::candidates_at(const MatrixX3d& x, double reach, CandidatePairs& fresh) const
{
    if (reach <= activation_distance_ && motion_.low.rows() == x.rows()) {
        const double margin = motion_margin * activation_distance_;
        const bool inside = std::all_of(surface_.vertices.begin(), surface_.vertices.end(), [&](int v) {
            return (x.row(v).array() >= motion_.low.row(v).array() - margin).all() &&
                   (x.row(v).array() <= motion_.high.row(v).array() + margin).all();
        });
        if (inside)
            return motion_.pairs;
    }
    ++broad_phases_;
    fresh = kept(tree_candidates(surface_, x, x, reach));
    return fresh;
}

template <class Visit>
bool SelfContactBarrier::for_each_pair(const Eigen::VectorXd& u, double reach, bool with_derivatives,
                                       Visit visit) const
{
    const MatrixX3d x = moved(rest_, u, "the displacement u");
    const auto at = [&](int v) -> Eigen::Vector3d { return x.row(v).transpose(); };
    const auto rest = [&](int v) -> Eigen::Vector3d { return rest_.row(v).transpose(); };
    CandidatePairs fresh;
    const CandidatePairs& candidates = candidates_at(x, reach, fresh);
    SurfacePair pair;
    const auto offer = [&](const PrimitiveFunction& squared, const PrimitiveFunction& mollifier) {
        if (!(squared.value < reach * reach))
            return true;
        if (!(squared.value > 0.0))
            return false;
        pair.distance = std::sqrt(squared.value);
        pair.mollifier = mollifier.value;
        pair.barrier = mollified_barrier(squared, mollifier, activation_distance_, with_derivatives);
        visit(pair);
        return true;
    };
    pair.kind = PrimitivePair::point_triangle;
    for (const auto& [vertex, triangle] : candidates.point_triangle) {
        pair.vertices[0] = vertex;
        for (int c = 0; c < 3; ++c)
            pair.vertices[c + 1] = surface_.triangles(triangle, c);
        const Eigen::Vector3d p = at(vertex), a = at(pair.vertices[1]), b = at(pair.vertices[2]),
                              c = at(pair.vertices[3]);
        if (!offer(point_triangle_squared_distance(p, a, b, c, point_triangle_type(p, a, b, c)), unit_mollifier()))
            return false;
    }
    pair.kind = PrimitivePair::edge_edge;
    for (const auto& [first, second] : candidates.edge_edge) {
        const int v[4] = {surface_.edges(first, 0), surface_.edges(first, 1), surface_.edges(second, 0),
                          surface_.edges(second, 1)};
        std::copy(v, v + 4, pair.vertices);
        const Eigen::Vector3d a0 = at(v[0]), a1 = at(v[1]), b0 = at(v[2]), b1 = at(v[3]);
        const PrimitiveFunction squared = edge_edge_squared_distance(a0, a1, b0, b1, edge_edge_type(a0, a1, b0, b1));
        if (!(squared.value < reach * reach))
            continue;  // the mollifier only for the pairs within reach
        const double threshold = edge_edge_mollifier_threshold(rest(v[0]), rest(v[1]), rest(v[2]), rest(v[3]));
        if (!offer(squared, edge_edge_mollifier(a0, a1, b0, b1, threshold)))
            return false;
    }
    return true;
}

double SelfContactBarrier::energy(const Eigen::VectorXd& u, double stiffness) const
{
    double total = 0.0;
    if (!for_each_pair(u, activation_distance_, false, [&](const SurfacePair& pair) { total += pair.barrier.value; }))
        return infinity;
    return stiffness * total;
}

void SelfContactBarrier::add_gradient(const Eigen::VectorXd& u, double stiffness, Eigen::VectorXd& gradient) const
{
    if (gradient.size() != u.size())
        throw Error(str("self-contact: the gradient needs ", u.size(), " entries, got ", gradient.size()));
    const bool apart = for_each_pair(u, activation_distance_, true, [&](const SurfacePair& pair) {
        for (int k = 0; k < 4; ++k)
            gradient.segment<3>(3 * pair.vertices[k]) += stiffness * pair.barrier.gradient.segment<3>(3 * k);
    });
    if (!apart)
        throw Error("self-contact: the gradient of the barrier was asked where two surface primitives touch (d = 0)");
}

void SelfContactBarrier::add_hessian(const Eigen::VectorXd& u, double stiffness,
                                     std::vector<Eigen::Triplet<double>>& triplets,
                                     std::optional<hyper::Projection> projection) const
{
    const bool apart = for_each_pair(u, activation_distance_, true, [&](const SurfacePair& pair) {
        // Each pair's block is made PSD on its own (a sum of PSD blocks is PSD), or left as it is.
        add_pair_block(pair.vertices,
                       stiffness * (projection ? hyper::project_to_psd<12>(pair.barrier.hessian, *projection)
                                               : pair.barrier.hessian),
                       triplets);
    });
    if (!apart)
        throw Error("self-contact: the Hessian of the barrier was asked where two surface primitives touch (d = 0)");
}

void SelfContactBarrier::anticipate(const Eigen::VectorXd& u, const Eigen::VectorXd& motion, double reach)
{
    if (!(std::isfinite(reach) && reach >= 0.0))
        throw Error(str("self-contact: the reach of the anticipated pattern must be a finite number >= 0 [m], got ", reach));
    const MatrixX3d start = moved(rest_, u, "the displacement u");
    const MatrixX3d end = moved(start, motion, "the predicted motion");
    anticipated_ = Eigen::SparseMatrix<double>(u.size(), u.size());
    if (reach == 0.0)
        return;
    ++broad_phases_;
    const CandidatePairs candidates = kept(tree_candidates(surface_, start, end, reach));
    std::vector<std::array<int, 2>> blocks;  // (a, b) for every two vertices of a candidate pair
    const auto add = [&](const int (&v)[4]) {
        for (int a : v)
            for (int b : v)
                blocks.push_back({a, b});
    };
    for (const auto& [vertex, triangle] : candidates.point_triangle)
        add({vertex, surface_.triangles(triangle, 0), surface_.triangles(triangle, 1), surface_.triangles(triangle, 2)});
    for (const auto& [first, second] : candidates.edge_edge)
        add({surface_.edges(first, 0), surface_.edges(first, 1), surface_.edges(second, 0), surface_.edges(second, 1)});
    std::sort(blocks.begin(), blocks.end());
    blocks.erase(std::unique(blocks.begin(), blocks.end()), blocks.end());
    std::vector<Eigen::Triplet<double>> zeros;
    zeros.reserve(9 * blocks.size());
    for (const auto& [a, b] : blocks)
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                zeros.emplace_back(3 * a + i, 3 * b + j, 0.0);
    anticipated_.setFromTriplets(zeros.begin(), zeros.end());
}

std::vector<SurfacePair> SelfContactBarrier::pairs(const Eigen::VectorXd& u, bool with_derivatives) const
{
    std::vector<SurfacePair> within;
    if (!for_each_pair(u, activation_distance_, with_derivatives,
                       [&](const SurfacePair& pair) { within.push_back(pair); }))
        throw Error("self-contact: the pairs of the barrier were asked where two surface primitives touch (d = 0)");
    return within;
}

double SelfContactBarrier::smallest_distance(const Eigen::VectorXd& u, double reach) const
{
    double smallest = infinity;
    if (!for_each_pair(u, reach, false, [&](const SurfacePair& pair) { smallest = std::min(smallest, pair.distance); }))
        return 0.0;
    return smallest;
}

double SelfContactBarrier::time_of_impact(const Eigen::VectorXd& u, const Eigen::VectorXd& du) const
{
    const MatrixX3d x0 = moved(rest_, u, "the displacement u");
    const MatrixX3d x1 = moved(x0, du, "the step du");
    // The motion's candidates within d̂ + 2δ, kept for the evaluations that follow (header); the
    // time of impact needs only those whose swept boxes meet.
    motion_ = {};
    ++broad_phases_;
    CandidatePairs candidates =
        kept(tree_candidates(surface_, x0, x1, activation_distance_ * (1.0 + 2.0 * motion_margin)));
    const MatrixX3d low = x0.cwiseMin(x1), high = x0.cwiseMax(x1);
    double earliest = infinity;
    PrimitiveMotion motion;
    const auto add = [&](PrimitivePair kind, const int (&v)[4]) {
        const int split = kind == PrimitivePair::point_triangle ? 1 : 2;  // the first primitive's vertices
        Eigen::RowVector3d first_low = low.row(v[0]), first_high = high.row(v[0]);
        Eigen::RowVector3d second_low = low.row(v[split]), second_high = high.row(v[split]);
        for (int k = 1; k < 4; ++k) {
            Eigen::RowVector3d& side_low = k < split ? first_low : second_low;
            Eigen::RowVector3d& side_high = k < split ? first_high : second_high;
            side_low = side_low.cwiseMin(low.row(v[k]));
            side_high = side_high.cwiseMax(high.row(v[k]));
        }
        // Swept boxes more than the smallest gap apart (line_search_time_of_impact): no impact, and
        // no end nearer than the gap.
        const double gap = 0.1 * activation_distance_;
        if ((first_low.array() > second_high.array() + gap).any() || (second_low.array() > first_high.array() + gap).any())
            return;
        for (int k = 0; k < 4; ++k) {
            motion.start.col(k) = x0.row(v[k]).transpose();
            motion.end.col(k) = x1.row(v[k]).transpose();
        }
        earliest = std::min(earliest, line_search_time_of_impact(kind, motion, activation_distance_));
    };
    for (const auto& [vertex, triangle] : candidates.point_triangle) {
        const auto corners = surface_.triangles.row(triangle);
        add(PrimitivePair::point_triangle, {vertex, corners(0), corners(1), corners(2)});
    }
    for (const auto& [first, second] : candidates.edge_edge)
        add(PrimitivePair::edge_edge, {surface_.edges(first, 0), surface_.edges(first, 1), surface_.edges(second, 0),
                                       surface_.edges(second, 1)});
    motion_ = {low, high, std::move(candidates)};
    return earliest;
}

}  // namespace fem::contact
