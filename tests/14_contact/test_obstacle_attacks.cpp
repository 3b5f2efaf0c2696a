// Chapter 14: obstacles given with extreme numbers (issue 48, item 6e) — a half-space whose point
// lies far along its plane is that plane, to the last digit of its distance, and a block slides on it
// as on the plane given by the origin. docs/14_contact.md#obstacles
#include "14_contact/contact_scenes.hpp"
#include "14_contact/obstacles.hpp"
#include "one_thread.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

using namespace fem;
using namespace fem::contact;

TEST_CASE("obstacle attacks: a half-space whose point lies far along its plane has that plane's distance, shifted by "
          "a constant at most", "[obstacles]")
{
    // Points of the planes 0.01 y + z = 0 and y + z = 0, 10⁹ m and 10¹² m along them.
    for (const auto& [point, normal] : std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>{
             {{0.0, 1e9, -1e7}, {0.0, 0.01, 1.0}}, {{0.0, 1e12, -1e12}, {0.0, 1.0, 1.0}}, {{3e9, 1e9, -1e9}, {0.0, 1.0, 1.0}}}) {
        const HalfSpace far(point, normal), near(Eigen::Vector3d::Zero(), normal);
        double low = INFINITY, high = -INFINITY;
        for (int k = 0; k < 1000; ++k) {
            const Eigen::Vector3d x(0.1 * std::sin(1.3 * k), 0.1 * std::cos(0.7 * k), 0.05 + 0.01 * std::sin(0.3 * k));
            const double shift = far.distance(x, 0.0) - near.distance(x, 0.0);
            low = std::min(low, shift);
            high = std::max(high, shift);
        }
        INFO("point " << point.transpose() << ": the far plane's distance minus the near one's in [" << low << ", "
                      << high << "] m");
        CHECK(high - low == 0.0);          // a constant: no digit of x lost
        CHECK(std::abs(high) <= 1e-8);     // the offset n·p's own round-off
    }
}

TEST_CASE("obstacle attacks: a block slides on a 45° plane given by a point 10⁹ m along it exactly as on the plane "
          "given by the origin", "[obstacles][ex14.2]")
{
    BlockSettings settings;
    const Eigen::Vector3d normal(0.0, 1.0, 1.0);
    const auto run = [&](const Eigen::Vector3d& point) {
        BlockSettings these = settings;
        these.obstacles = {std::make_shared<HalfSpace>(point, normal)};
        BlockScene block = block_scene(these);
        std::vector<Eigen::VectorXd> states;
        for (int step = 0; step < 20; ++step) {
            block.step();
            states.push_back(block.state.u);
        }
        return states;
    };
    const std::vector<Eigen::VectorXd> near = run(Eigen::Vector3d::Zero());
    std::vector<Eigen::VectorXd> far;
    REQUIRE_NOTHROW(far = run(Eigen::Vector3d(0.0, 1e9, -1e9)));
    for (std::size_t step = 0; step < near.size(); ++step)
        CHECK((far[step] - near[step]).lpNorm<Eigen::Infinity>() == 0.0);
    CHECK(near.back().segment<3>(0).norm() > 1e-3);  // it slid: the plane held it along the slope
}
