#include "model/candidate_pairs.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <variant>

#include "geometry/narrow_phase.h"
#include "model/motion_model.h"

namespace collision_response::core::monitor {

void allCandidatePairs(const World& world, std::vector<Pair>& pairs) {
  pairs.clear();
  for (std::size_t a = 0; a < world.bodies.size(); ++a) {
    if (!world.tracks[a].known) continue;
    for (std::size_t b = a + 1; b < world.bodies.size(); ++b) {
      if (!world.tracks[b].known || world.inverse_mass[a] + world.inverse_mass[b] == 0.0) continue;
      pairs.emplace_back(a, b);
    }
    if (world.inverse_mass[a] == 0.0) continue;
    for (std::size_t o = 0; o < world.obstacles.size(); ++o) {
      if (world.obstacle_tracks[o].known) pairs.emplace_back(a, world.bodies.size() + o);
    }
  }
}

bool mayReachObstacle(const World& world, const Box& box, std::size_t obstacle, double from,
                      double to) {
  const ObstacleSpec& spec = world.obstacles[obstacle];
  const PlacedShape& placed = world.obstacle_tracks[obstacle].placed;
  // A tf-attached obstacle moves straight on from its last placement (a robot's far links, at
  // rest or not, are no candidates: 2,000 of them cost a step 2,000 narrow phases otherwise).
  return spec.frame.empty() ? mayReach(placed, box) : mayReachMoving(placed, box, from, to);
}

Box obstacleReachBound(const World& world, std::size_t obstacle, double from, double to) {
  const ObstacleSpec& spec = world.obstacles[obstacle];
  const PlacedShape& placed = world.obstacle_tracks[obstacle].placed;
  const RigidPose& pose = placed.pose;
  if (std::holds_alternative<Plane>(placed.shape)) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    return Box{Eigen::Vector3d::Constant(-kInf), Eigen::Vector3d::Constant(kInf)};
  }
  // mayReach's box (a sphere's about its centre, a finite shape's bounding sphere's about its
  // pose's origin), or mayReachMoving's (that of the origin's bounding sphere grown by |v| times
  // the longest time from the placement).
  const bool moves =
      !spec.frame.empty() && !(pose.velocity.isZero() && pose.angular_velocity.isZero());
  Eigen::Vector3d centre = pose.transform.translation();
  double reach = moves ? reachOver(placed, from, to) : boundingRadiusOf(placed.shape);
  if (const Sphere* sphere = std::get_if<Sphere>(&placed.shape); sphere && !moves) {
    centre = sphere->centre;
  }
  reach += 1e-9 * (centre.lpNorm<Eigen::Infinity>() + reach);
  return Box::about(centre, reach);
}

void ObstacleIndex::build(std::vector<Box> bounds, const std::vector<char>& entered, double from,
                          double to) {
  bounds_ = std::move(bounds);
  built_ = true;
  from_ = from;
  to_ = to;
  gridded_.assign(bounds_.size(), 0);
  entered_.clear();
  always_.clear();
  any_gridded_ = false;
  for (std::size_t o = 0; o < bounds_.size(); ++o) {
    if (!entered[o]) continue;
    entered_.push_back(o);
    if (bounds_[o].low.allFinite() && bounds_[o].high.allFinite()) {
      gridded_[o] = 1;
      any_gridded_ = true;
    } else {
      always_.push_back(o);
    }
  }
  if (any_gridded_) grid_.build(bounds_, gridded_);
}

void ObstacleIndex::query(const Box& box, std::vector<std::size_t>& found) const {
  found.clear();
  if (!(box.low.allFinite() && box.high.allFinite())) {
    found = entered_;  // a box the grid cannot place: every obstacle is asked
    return;
  }
  if (any_gridded_) grid_.query(box, found);
  const std::size_t gridded = found.size();
  found.insert(found.end(), always_.begin(), always_.end());
  std::inplace_merge(found.begin(), found.begin() + static_cast<std::ptrdiff_t>(gridded),
                     found.end());
}

namespace {

template <class Motion>
void broadphasePairs(World& world, double from, double to, std::vector<Pair>& pairs) {
  std::vector<Box>& boxes = world.scratch.boxes;
  std::vector<char>& active = world.scratch.active;
  boxes.resize(world.bodies.size());
  active.assign(world.bodies.size(), 0);
  for (std::size_t i = 0; i < world.bodies.size(); ++i) {
    if (!world.tracks[i].known) continue;
    active[i] = 1;
    boxes[i] = sweptBox<Motion>(world, i, from, to);
  }
  world.scratch.hash.build(boxes, active);
  world.scratch.hash.overlappingPairs(world.scratch.body_pairs);
  // Each body asks the obstacles its box may reach through their grid, not each of them (a
  // robot's 2,000 links beside a cluster of 1,728 balls: 3.5 million tests a step otherwise).
  std::vector<Box> bounds(world.obstacles.size());
  std::vector<char> entered(world.obstacles.size(), 0);
  for (std::size_t o = 0; o < world.obstacles.size(); ++o) {
    if (!world.obstacle_tracks[o].known) continue;
    entered[o] = 1;
    bounds[o] = obstacleReachBound(world, o, from, to);
  }
  ObstacleIndex& obstacles = world.scratch.obstacles;
  obstacles.build(std::move(bounds), entered, from, to);
  std::vector<std::size_t>& near = world.scratch.found;
  pairs.clear();
  std::size_t next = 0;
  const std::vector<std::pair<std::size_t, std::size_t>>& body_pairs = world.scratch.body_pairs;
  for (std::size_t a = 0; a < world.bodies.size(); ++a) {
    for (; next < body_pairs.size() && body_pairs[next].first == a; ++next) {
      if (world.inverse_mass[a] + world.inverse_mass[body_pairs[next].second] > 0) {
        pairs.push_back(body_pairs[next]);
      }
    }
    if (!active[a] || world.inverse_mass[a] == 0.0) continue;
    obstacles.query(boxes[a], near);
    for (const std::size_t o : near) {
      if (mayReachObstacle(world, boxes[a], o, from, to)) {
        pairs.emplace_back(a, world.bodies.size() + o);
      }
    }
  }
  world.scratch.changed_boxes.clear();
}

}  // namespace

template <class Motion>
void candidatePairs(World& world, double from, double to, std::vector<Pair>& pairs) {
  if (world.settings.broadphase) {
    broadphasePairs<Motion>(world, from, to, pairs);
  } else {
    allCandidatePairs(world, pairs);
  }
}

template <class Motion>
std::vector<std::size_t> addReachablePairs(World& world, std::size_t body, double from, double to,
                                           std::vector<Pair>& pairs,
                                           const std::vector<std::vector<std::size_t>>& pairs_of) {
  const Box box = sweptBox<Motion>(world, body, from, to);
  std::vector<Box>& start_boxes = world.scratch.boxes;
  if (world.settings.broadphase && body < start_boxes.size() && world.scratch.active[body] &&
      (start_boxes[body].low.array() <= box.low.array()).all() &&
      (box.high.array() <= start_boxes[body].high.array()).all()) {
    return {};  // within the box it swept at the step's start: its pairs are candidates already
  }
  std::vector<std::size_t>& found = world.scratch.found;
  world.scratch.hash.query(box, found);
  // Bodies changed earlier in the step are in the grid with their old boxes: test their new.
  // One entry a body, its latest box: a body struck thousands of times in a step (a chain at a
  // mass ratio of 1e6) would otherwise make each query walk all its earlier boxes.
  bool listed = false;
  for (auto& [other, other_box] : world.scratch.changed_boxes) {
    if (other == body) {
      other_box = box;
      listed = true;
    } else if (other_box.overlaps(box)) {
      found.push_back(other);
    }
  }
  if (!listed) world.scratch.changed_boxes.emplace_back(body, box);
  const auto known_pair = [&](const Pair& pair) {
    for (const std::size_t k : pairs_of[body]) {
      if (pairs[k] == pair) return true;
    }
    return false;
  };
  std::vector<std::size_t> added;
  const auto add = [&](const Pair& pair) {
    if (known_pair(pair)) return;
    pairs.push_back(pair);
    added.push_back(pairs.size() - 1);
  };
  for (const std::size_t other : found) {
    if (other == body || !world.tracks[other].known ||
        world.inverse_mass[body] + world.inverse_mass[other] == 0.0) {
      continue;
    }
    add(Pair(std::min(body, other), std::max(body, other)));
  }
  if (world.inverse_mass[body] > 0) {
    // The obstacles the step's candidatePairs entered for a span that holds [from, to] (a
    // stepped cluster's 1,728 balls each changed, beside a robot's 2,000 links), or each.
    if (world.settings.broadphase &&
        world.scratch.obstacles.covers(world.obstacles.size(), from, to)) {
      world.scratch.obstacles.query(box, found);
      for (const std::size_t o : found) {
        if (mayReachObstacle(world, box, o, from, to)) add(Pair(body, world.bodies.size() + o));
      }
    } else {
      for (std::size_t o = 0; o < world.obstacles.size(); ++o) {
        if (world.obstacle_tracks[o].known && mayReachObstacle(world, box, o, from, to)) {
          add(Pair(body, world.bodies.size() + o));
        }
      }
    }
  }
  return added;
}

template void candidatePairs<StraightLine>(World&, double, double, std::vector<Pair>&);
template void candidatePairs<UnderGravity>(World&, double, double, std::vector<Pair>&);
template std::vector<std::size_t> addReachablePairs<StraightLine>(
    World&, std::size_t, double, double, std::vector<Pair>&,
    const std::vector<std::vector<std::size_t>>&);
template std::vector<std::size_t> addReachablePairs<UnderGravity>(
    World&, std::size_t, double, double, std::vector<Pair>&,
    const std::vector<std::vector<std::size_t>>&);

}  // namespace collision_response::core::monitor
