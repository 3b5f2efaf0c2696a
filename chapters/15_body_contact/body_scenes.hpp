#pragma once
// Chapter 15: the scenes its tests and chapter 16's side-by-side study both build — the stack of
// three blocks (three one-cell cubes in one mesh, each on the one below, the lowest on the floor
// z = 0; docs/15_body_contact.md#a-stack-at-rest) and the obstacles with corners that the 10 cm block
// [0, 0.1]² × [0.2, 0.3] is fired down at (docs/15_body_contact.md#never-an-intersection).

#include "14_contact/obstacles.hpp"

#include "common/mesh.hpp"

#include <Eigen/Core>

#include <memory>

namespace fem::contact {

/// The stack's mesh and where it starts.
struct BlockStack {
    /// 24 vertices, 18 tets: block k (0, 1, 2: bottom to top) is vertices 8k … 8k + 7 and tets
    /// 6k … 6k + 5, a cube of edge 0.3, 0.2, 0.1 m (27, 8 and 1 kg at ρ = 1000 kg/m³) with its lowest
    /// corner at (0, 0, 0.5 r), (0.05, 0.045, 0.3 + 1.7 r), (0.1, 0.08, 0.5 + 2.9 r): off the centre of
    /// the one below (no vertex over a diagonal), each 1.2 r above the one below and the lowest 0.5 r
    /// above the floor at rest.
    TetMesh mesh;
    /// The start u₀ (3 × 24) [m]: block k moved down by 0.7 k r, so that every block starts 0.5 r
    /// above the one below (self-contact asks for more than r between bodies at rest, and the
    /// barrier's push at 0.5 r is what sets them down).
    Eigen::VectorXd start;
};

/// The stack of BlockStack for the reach r [m] (IPC's d̂, the augmented Lagrangian's δ): fem::Error
/// for r not in (0, 0.01] m (the blocks must stay stacked). docs/15_body_contact.md#a-stack-at-rest
BlockStack block_stack(double reach);

/// The block (0, 1, 2: bottom to top) of each of block_stack's 24 vertices: vertex / 8.
inline int stack_block(int vertex) { return vertex / 8; }

/// A box of half extent 3 cm turned by turn (a rotation), its highest point at z = 0 under the fired
/// block's centre (0.05, 0.05): its corners and edges meet the block's lower face between its vertices.
std::shared_ptr<const Obstacle> box_under_block(const Eigen::Matrix3d& turn);

/// A mesh obstacle of one triangle, (0.05, 0.05, 0), (0.6, −0.2, −0.1), (−0.2, 0.6, −0.1): its corner
/// points up under the fired block's centre.
std::shared_ptr<const Obstacle> triangle_under_block();

}  // namespace fem::contact
