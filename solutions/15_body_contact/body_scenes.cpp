// Chapter 15: the stack of three blocks and the obstacles the fired block meets.
// docs/15_body_contact.md#a-stack-at-rest
#include "15_body_contact/body_scenes.hpp"

#include "15_body_contact/mesh_obstacle.hpp"

#include "common/error.hpp"

#include <algorithm>

namespace fem::contact {

BlockStack block_stack(double reach)
{
    if (!(reach > 0.0 && reach <= 0.01))
        throw Error(str("block_stack: the reach must lie in (0, 0.01] m, got ", reach));
    const double sizes[3] = {0.3, 0.2, 0.1};
    const Eigen::Vector3d corners[3] = {{0.0, 0.0, 0.5 * reach}, {0.05, 0.045, 0.3 + 1.7 * reach},
                                        {0.1, 0.08, 0.5 + 2.9 * reach}};
    BlockStack stack;
    stack.mesh.V.resize(24, 3);
    stack.mesh.T.resize(18, 4);
    for (int k = 0; k < 3; ++k) {
        const TetMesh block = box_mesh(1, 1, 1, Eigen::Vector3d::Constant(sizes[k]));
        stack.mesh.V.middleRows(8 * k, 8) = block.V.rowwise() + corners[k].transpose();
        stack.mesh.T.middleRows(6 * k, 6) = block.T.array() + 8 * k;
    }
    stack.start = Eigen::VectorXd::Zero(3 * 24);
    for (int v = 0; v < 24; ++v)
        stack.start[3 * v + 2] = -0.7 * reach * stack_block(v);
    return stack;
}

std::shared_ptr<const Obstacle> box_under_block(const Eigen::Matrix3d& turn)
{
    const Eigen::Vector3d half = Eigen::Vector3d::Constant(0.03);
    double top = 0.0;  // the highest corner's height above the centre
    for (int k = 0; k < 8; ++k)
        top = std::max(top, (turn * Eigen::Vector3d((k & 1) ? 1 : -1, (k & 2) ? 1 : -1, (k & 4) ? 1 : -1).cwiseProduct(half)).z());
    return std::make_shared<Box>(Eigen::Vector3d(0.05, 0.05, -top), half, turn);
}

std::shared_ptr<const Obstacle> triangle_under_block()
{
    TriMesh triangle;
    triangle.V.resize(3, 3);
    triangle.V << 0.05, 0.05, 0.0, 0.6, -0.2, -0.1, -0.2, 0.6, -0.1;
    triangle.F.resize(1, 3);
    triangle.F << 0, 1, 2;
    return std::make_shared<MeshObstacle>(triangle);
}

}  // namespace fem::contact
