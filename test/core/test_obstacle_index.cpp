// The obstacle index (monitor/candidate_pairs.h): a filter before the exact tests of a body
// against the obstacles (a robot's thousands of links), so it must find every obstacle whose
// bound a box overlaps, whatever the boxes: the answer of testing every obstacle, sorted.
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <utility>
#include <variant>
#include <vector>

#include "contact/stepped_clusters.h"
#include "geometry/narrow_phase.h"
#include "model/candidate_pairs.h"

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

/// 400 obstacles: spheres, boxes, cylinders, capsules and planes, fixed or on a frame, at rest,
/// moving and turning, placed at times about 0.
World obstacles(std::mt19937& random) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0), size(0.01, 0.5);
  World world;
  for (int i = 0; i < 400; ++i) {
    ObstacleSpec spec;
    spec.frame = i % 3 == 0 ? "" : "link";
    PlacedShape placed;
    switch (i % 5) {
      case 0:
        placed.shape = Plane{Eigen::Vector3d(unit(random), unit(random), 1).normalized(), 0.1};
        break;
      case 1:
        placed.shape = Cuboid{Eigen::Vector3d(size(random), size(random), size(random))};
        break;
      case 2:
        placed.shape = Cylinder{size(random), size(random)};
        break;
      case 3:
        placed.shape = Capsule{size(random), size(random)};
        break;
      default:
        break;
    }
    placed.pose.time = 0.1 * unit(random);
    placed.pose.transform.translation() = Eigen::Vector3d(unit(random), unit(random), unit(random));
    placed.pose.transform.linear() =
        Eigen::AngleAxisd(3 * unit(random),
                          Eigen::Vector3d(unit(random), unit(random), 1).normalized())
            .toRotationMatrix();
    if (i % 4 == 0) placed.shape = Sphere{placed.pose.transform.translation(), size(random)};
    if (i % 7 != 0)
      placed.pose.velocity = 3 * Eigen::Vector3d(unit(random), unit(random), unit(random));
    if (i % 2 == 0)
      placed.pose.angular_velocity = 5 * Eigen::Vector3d(unit(random), 0, unit(random));
    world.obstacles.push_back(spec);
    world.obstacle_tracks.push_back(ObstacleTrack{true, placed});
  }
  return world;
}

// The bound candidatePairs enters an obstacle with holds every box its exact test accepts
// (mayReachObstacle), over the span it was built for and any span within it (addReachablePairs
// asks it for a body changed within the step): spheres, boxes, cylinders and capsules, fixed or
// on a tf frame, at rest, moving, turning, placed before, within or after the span; planes have
// none (found always).
TEST(ObstacleIndex, BoundHoldsWhatTheExactTestAccepts) {
  std::mt19937 random(8);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), size(0.01, 0.5);
  const World world = obstacles(random);
  const double from = 0.0, to = 0.05;
  std::size_t accepted = 0;
  for (std::size_t o = 0; o < world.obstacles.size(); ++o) {
    const Box bound = obstacleReachBound(world, o, from, to);
    const bool plane = std::holds_alternative<Plane>(world.obstacle_tracks[o].placed.shape);
    EXPECT_EQ(finite(bound), !plane) << o;
    for (int q = 0; q < 200; ++q) {
      const Box box = around(1.5 * Eigen::Vector3d(unit(random), unit(random), unit(random)),
                             0.1 * size(random));
      const double start = from + (to - from) * 0.5 * (1 + unit(random));
      const double end = start + (to - start) * 0.5 * (1 + unit(random));
      for (const auto& [a, b] : {std::pair(from, to), std::pair(start, end)}) {
        if (!mayReachObstacle(world, box, o, a, b)) continue;
        ++accepted;
        EXPECT_TRUE(!finite(bound) || bound.overlaps(box)) << o << " " << a << " " << b;
      }
    }
  }
  EXPECT_GT(accepted, 1000u);  // the boxes reach some obstacles
}

// nearPairs' filter (a stepped cluster's bodies with the obstacles) holds every pair its exact
// test accepts: a ball whose surface is within its reach, the obstacle's motion over the span
// and the touching band of the obstacle's (contactGeometry of the obstacle moved on to the
// instant: shapeAt) has its box overlap the obstacle's, at instants before and after the
// obstacle's placement, with touching bands of 0 and of a tenth.
TEST(ObstacleIndex, SteppedNearBoxesHoldWhatTheGeometryAccepts) {
  std::mt19937 random(9);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), size(0.01, 0.2);
  World world = obstacles(random);
  const double span = 0.01;
  std::size_t accepted = 0;
  for (const double tolerance : {0.0, 0.1}) {
    world.settings.contact_tolerance = tolerance;
    for (std::size_t o = 0; o < world.obstacles.size(); ++o) {
      const PlacedShape& placed = world.obstacle_tracks[o].placed;
      const double moving = placed.pose.velocity.norm() * span;
      for (int q = 0; q < 200; ++q) {
        const double time = 0.2 * unit(random);
        const Eigen::Vector3d centre =
            1.5 * Eigen::Vector3d(unit(random), unit(random), unit(random));
        const double radius = size(random), reach = 0.5 * size(random);
        const ContactGeometry g =
            contactGeometry(centre, radius, shapeAt(placed, time), tolerance,
                            [] { return Eigen::Vector3d(Eigen::Vector3d::UnitX()); });
        if (!g.valid || !(g.gap <= reach + moving + g.tolerance)) continue;
        ++accepted;
        const Box bound = nearObstacleBox(world, o, time, moving);
        EXPECT_TRUE(!finite(bound) || bound.overlaps(nearBodyBox(world, radius, centre, reach)))
            << o << " at " << time << ", gap " << g.gap;
      }
    }
  }
  EXPECT_GT(accepted, 1000u);
  // At the edge: a ball of 0.1 m beside a sphere of 0.3 m along x, its gap its reach (0.05 m)
  // plus the whole touching band of a tenth (0.04 m): near, so the boxes meet.
  world.settings.contact_tolerance = 0.1;
  world.obstacles.assign(1, ObstacleSpec{});
  PlacedShape sphere;
  sphere.shape = Sphere{Eigen::Vector3d::Zero(), 0.3};
  world.obstacle_tracks.assign(1, ObstacleTrack{true, sphere});
  const Eigen::Vector3d centre(0.1 + 0.3 + 0.05 + 0.04, 0, 0);
  const ContactGeometry g = contactGeometry(
      centre, 0.1, sphere, 0.1, [] { return Eigen::Vector3d(Eigen::Vector3d::UnitX()); });
  ASSERT_LE(g.gap, 0.05 + g.tolerance);
  EXPECT_TRUE(nearObstacleBox(world, 0, 0.0, 0.0).overlaps(nearBodyBox(world, 0.1, centre, 0.05)));
}

}  // namespace
}  // namespace collision_response::core::monitor
