// The obstacle index (monitor/candidate_pairs.h): a filter before the exact tests of a body
// against the obstacles (a robot's thousands of links), so it must find every obstacle whose
// bound a box overlaps, whatever the boxes: the answer of testing every obstacle, sorted.
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <vector>

#include "monitor/candidate_pairs.h"

namespace collision_response::core::monitor {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

Box around(const Eigen::Vector3d& centre, double half) {
  return Box{centre.array() - half, centre.array() + half};
}

bool finite(const Box& box) { return box.low.allFinite() && box.high.allFinite(); }

/// What testing every obstacle finds: each entered one whose bound overlaps the box, or that has
/// no finite bound, or all entered ones for a box that is not finite.
std::vector<std::size_t> everyObstacle(const std::vector<Box>& bounds,
                                       const std::vector<char>& entered, const Box& box) {
  std::vector<std::size_t> found;
  for (std::size_t o = 0; o < bounds.size(); ++o) {
    if (entered[o] && (!finite(box) || !finite(bounds[o]) || bounds[o].overlaps(box))) {
      found.push_back(o);
    }
  }
  return found;
}

// 2,000 links of a robot's size along an arm, a few not entered (their tf unknown), planes and
// a bound with a NaN (found always), one huge mesh; queries of balls' sizes, near and far, and
// boxes that are huge, infinite or NaN.
TEST(ObstacleIndex, FindsWhatTestingEveryObstacleFinds) {
  std::mt19937 random(41);
  std::uniform_real_distribution<double> along(-5.0, 5.0), size(0.01, 0.3);
  std::vector<Box> bounds;
  std::vector<char> entered;
  for (int i = 0; i < 2000; ++i) {
    bounds.push_back(
        around(Eigen::Vector3d(along(random), 0.1 * along(random), 1 + 0.1 * along(random)),
               size(random)));
    entered.push_back(i % 97 == 0 ? 0 : 1);
  }
  bounds[5] = Box{Eigen::Vector3d::Constant(-kInf), Eigen::Vector3d::Constant(kInf)};  // a plane
  bounds[1500] = Box{Eigen::Vector3d::Constant(-kInf), Eigen::Vector3d::Constant(kInf)};
  bounds[700] = around(Eigen::Vector3d(kNan, 0, 0), 1.0);
  bounds[900] = around(Eigen::Vector3d::Zero(), 400.0);  // a floor's mesh
  ObstacleIndex index;
  index.build(bounds, entered);

  std::vector<Box> queries;
  for (int i = 0; i < 3000; ++i) {
    queries.push_back(around(
        Eigen::Vector3d(2 * along(random), 0.3 * along(random), 1 + 0.3 * along(random)), 0.05));
  }
  queries.push_back(around(Eigen::Vector3d::Zero(), 1e6));
  queries.push_back(around(Eigen::Vector3d(1e300, 0, 0), 1.0));
  queries.push_back(around(Eigen::Vector3d::Zero(), kInf));
  queries.push_back(around(Eigen::Vector3d(kNan, 0, 0), 0.1));
  std::vector<std::size_t> found;
  std::size_t asked = 0;
  for (const Box& box : queries) {
    index.query(box, found);
    ASSERT_EQ(found, everyObstacle(bounds, entered, box));
    asked += found.size();
  }
  // A ball's box asks a few links, not 2,000 (the filter filters): at most the 4 found always
  // and the links within its reach, on average far fewer than a tenth of them.
  EXPECT_LT(asked, queries.size() * 200);
}

// Nothing entered, or only planes: every query finds just those.
TEST(ObstacleIndex, OnlyPlanesOrNothing) {
  ObstacleIndex index;
  std::vector<std::size_t> found;
  index.build({}, {});
  index.query(around(Eigen::Vector3d::Zero(), 1.0), found);
  EXPECT_TRUE(found.empty());
  const Box plane{Eigen::Vector3d::Constant(-kInf), Eigen::Vector3d::Constant(kInf)};
  index.build({plane, plane, plane}, {1, 0, 1});
  index.query(around(Eigen::Vector3d::Zero(), 1.0), found);
  EXPECT_EQ(found, (std::vector<std::size_t>{0, 2}));
}

}  // namespace
}  // namespace collision_response::core::monitor
