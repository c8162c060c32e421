// The monitor's motion-dependent member templates, instantiated once per motion model in
// their own translation units (monitor_straight.cpp, monitor_gravity.cpp): a build without the
// gravity effect compiles the straight-line code exactly as a build with it does.
#pragma once

#include <algorithm>
#include <cmath>
#include <numeric>

#include "collision_response/core/body.h"
#include "collision_response/core/friction.h"
#include "collision_response/core/impact.h"
#include "collision_response/core/monitor.h"
#include "collision_response/core/time_of_impact.h"

namespace collision_response::core {
namespace monitor_detail {

constexpr double kEps = std::numeric_limits<double>::epsilon();
/// A pair approaches when its normal relative velocity is below -64 ulps of the speeds: what a
/// resolved impact leaves behind by rounding (e = 0 gives d' = 0 only up to a few ulps) must not
/// count as a new approach.
constexpr double kApproachTolerance = 64 * kEps;

}  // namespace monitor_detail

using monitor_detail::kApproachTolerance;
using monitor_detail::kEps;

template <class Motion>
Eigen::Vector3d ImpactMonitor::positionAt(std::size_t participant, double time) const {
  if (isObstacle(participant)) {
    const ObstaclePose& pose = obstacle_tracks_[participant - bodies_.size()].pose;
    return pose.position + pose.velocity * (time - pose.time);
  }
  const Track& track = tracks_[participant];
  if constexpr (Motion::kAccelerates) {
    return positionAfter(track.position, track.velocity, track.acceleration, time - track.time);
  } else {
    return track.position + track.velocity * (time - track.time);
  }
}

template <class Motion>
Eigen::Vector3d ImpactMonitor::velocityAt(std::size_t participant, double time) const {
  if (isObstacle(participant)) return obstacle_tracks_[participant - bodies_.size()].pose.velocity;
  const Track& track = tracks_[participant];
  if constexpr (Motion::kAccelerates) {
    return velocityAfter(track.velocity, track.acceleration, time - track.time);
  } else {
    static_cast<void>(time);
    return track.velocity;
  }
}

template <class Motion>
ImpactMonitor::Geometry ImpactMonitor::geometry(const Pair& pair, double time) const {
  const auto [a, other] = pair;
  const Eigen::Vector3d position_a = positionAt<Motion>(a, time);
  Geometry result;
  if (isPlane(other)) {
    const ObstaclePose& plane = obstacle_tracks_[other - bodies_.size()].pose;
    const double offset = plane.offset + plane.normal.dot(plane.velocity) * (time - plane.time);
    result.normal = -plane.normal;  // from the body into the plane
    result.gap = plane.normal.dot(position_a) - offset - radius_[a];
    result.tolerance = touchingBand(radius_[a], settings_.contact_tolerance, position_a, offset);
    result.valid = true;
    return result;
  }
  const Eigen::Vector3d position_other = positionAt<Motion>(other, time);
  const Eigen::Vector3d separation = position_other - position_a;
  const double distance = separation.norm();
  const double contact_distance = radius_[a] + radius_[other];
  if (!(distance > 0)) {
    // Coincident centres (a sample caught one body right through the other): no line of
    // centres; the line of impact is the direction of approach, if there is one.
    const Eigen::Vector3d approach = velocityAt<Motion>(a, time) - velocityAt<Motion>(other, time);
    if (!(approach.norm() > 0)) return result;
    result.normal = approach.normalized();
  } else {
    result.normal = separation / distance;
  }
  result.gap = distance - contact_distance;
  result.tolerance = settings_.contact_tolerance * contact_distance +
                     16 * kEps *
                         (position_a.lpNorm<Eigen::Infinity>() +
                          position_other.lpNorm<Eigen::Infinity>() + contact_distance);
  result.valid = true;
  return result;
}

template <class Motion>
std::optional<double> ImpactMonitor::timeOfImpact(const Pair& pair, double from,
                                                  double horizon) const {
  const auto [a, other] = pair;
  const Eigen::Vector3d relative_velocity =
      velocityAt<Motion>(other, from) - velocityAt<Motion>(a, from);
  if (isPlane(other)) {
    const ObstaclePose& plane = obstacle_tracks_[other - bodies_.size()].pose;
    const Geometry g = geometry<Motion>(pair, from);
    const double rate = -plane.normal.dot(relative_velocity);
    if constexpr (Motion::kAccelerates) {
      return timeOfImpactPlaneBallistic(g.gap, rate, plane.normal.dot(tracks_[a].acceleration),
                                        horizon);
    } else {
      return timeOfImpactPlane(g.gap, rate, horizon);
    }
  }
  const Eigen::Vector3d separation = positionAt<Motion>(other, from) - positionAt<Motion>(a, from);
  const double contact_distance = radius_[a] + radius_[other];
  if constexpr (Motion::kAccelerates) {
    // Two bodies under the same gravity keep the straight-line relative problem.
    const Eigen::Vector3d acceleration_other =
        isObstacle(other) ? Eigen::Vector3d::Zero() : tracks_[other].acceleration;
    return timeOfImpactSpheresAccelerated(separation, relative_velocity,
                                          acceleration_other - tracks_[a].acceleration,
                                          contact_distance, horizon);
  } else {
    return timeOfImpactSpheres<double>(separation, relative_velocity, contact_distance, horizon);
  }
}

template <class Motion>
bool ImpactMonitor::approaching(const Pair& pair, const Eigen::Vector3d& normal,
                                double time) const {
  const Eigen::Vector3d velocity_a = velocityAt<Motion>(pair.first, time);
  const Eigen::Vector3d velocity_other = velocityAt<Motion>(pair.second, time);
  const double relative_normal = (velocity_other - velocity_a).dot(normal);
  const double scale =
      velocity_a.lpNorm<Eigen::Infinity>() + velocity_other.lpNorm<Eigen::Infinity>();
  return relative_normal < -kApproachTolerance * scale;
}

template <class Motion>
bool ImpactMonitor::resolveInstant(double time, const std::vector<Pair>& touching,
                                   StepReport& report, std::vector<std::size_t>& changed) {
  // Positions do not change during an instant: the geometry is computed once.
  std::vector<std::pair<Pair, Geometry>> contacts_at_instant;
  for (const Pair& pair : touching) {
    const Geometry g = geometry<Motion>(pair, time);
    if (g.valid) contacts_at_instant.emplace_back(pair, g);
  }
  for (int round = 0; round < settings_.max_rounds_per_instant; ++round) {
    std::vector<std::size_t> striking;  // indices into contacts_at_instant
    for (std::size_t k = 0; k < contacts_at_instant.size(); ++k) {
      const auto& [pair, g] = contacts_at_instant[k];
      if (approaching<Motion>(pair, g.normal, time)) striking.push_back(k);
    }
    if (striking.empty()) return true;

    // Clusters: contacts that share a movable body are solved together (a union-find over the
    // participants of the striking contacts only, numbered in sorted order).
    std::vector<std::size_t> involved;
    for (const std::size_t k : striking) {
      involved.push_back(contacts_at_instant[k].first.first);
      involved.push_back(contacts_at_instant[k].first.second);
    }
    std::sort(involved.begin(), involved.end());
    involved.erase(std::unique(involved.begin(), involved.end()), involved.end());
    const auto slot_of = [&involved](std::size_t participant) {
      return static_cast<std::size_t>(
          std::lower_bound(involved.begin(), involved.end(), participant) - involved.begin());
    };
    std::vector<std::size_t> parent(involved.size());
    std::iota(parent.begin(), parent.end(), 0);
    const auto find = [&parent](std::size_t x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    for (const std::size_t k : striking) {
      const auto [a, other] = contacts_at_instant[k].first;
      if (inverseMassOf(a) > 0 && inverseMassOf(other) > 0) {
        parent[find(slot_of(a))] = find(slot_of(other));
      }
    }
    const auto cluster_of = [&](std::size_t k) {
      const auto [a, other] = contacts_at_instant[k].first;
      return inverseMassOf(a) > 0 ? find(slot_of(a)) : find(slot_of(other));
    };
    std::vector<std::vector<std::size_t>> clusters;
    std::map<std::size_t, std::size_t> cluster_slot;
    for (const std::size_t k : striking) {
      const auto [slot, inserted] = cluster_slot.emplace(cluster_of(k), clusters.size());
      if (inserted) clusters.emplace_back();
      clusters[slot->second].push_back(k);
    }

    for (const std::vector<std::size_t>& cluster : clusters) {
      std::vector<std::size_t> members;  // participants, local index = position here
      const auto local = [&members](std::size_t participant) {
        const auto found = std::find(members.begin(), members.end(), participant);
        if (found != members.end()) return static_cast<std::size_t>(found - members.begin());
        members.push_back(participant);
        return members.size() - 1;
      };
      std::vector<ClusterContact> cluster_contacts;
      std::vector<FrictionContact> frictions;
      for (const std::size_t k : cluster) {
        const auto& [pair, g] = contacts_at_instant[k];
        ClusterContact contact;
        contact.a = local(pair.first);
        contact.b = local(pair.second);
        contact.normal = g.normal;
        const double approach_speed =
            (velocityAt<Motion>(pair.first, time) - velocityAt<Motion>(pair.second, time))
                .dot(g.normal);
        // Restitution threshold: an approach at or above it bounces; slower ones rest (e = 0).
        contact.restitution = approach_speed >= restitution_threshold_ ? restitutionOf(pair) : 0.0;
        if constexpr (Motion::kAccelerates) {
          // A bounce off a plane too slow to leave the touching band is a rest (restSpeed).
          const double pressing = g.normal.dot(gravity_);  // normal points into the plane
          if (isPlane(pair.second) && pressing > 0 &&
              contact.restitution * approach_speed <= restSpeed(pressing, g.tolerance)) {
            contact.restitution = 0.0;
          }
        }
        cluster_contacts.push_back(contact);
        if (friction_step_ != nullptr) {
          frictions.push_back(
              FrictionContact{friction_[material_[pair.first]][material_[pair.second]], 0.0});
        }
      }
      std::vector<ClusterBody> cluster_bodies;
      for (const std::size_t participant : members) {
        ClusterBody body;
        body.inverse_mass = inverseMassOf(participant);
        body.velocity = velocityAt<Motion>(participant, time);
        body.angular_velocity = angularVelocityOf(participant);
        body.spin_factor = isObstacle(participant) ? 0.0 : spin_factor_[participant];
        body.radius = radius_[participant];
        cluster_bodies.push_back(body);
      }
      const std::vector<ClusterBody> before = cluster_bodies;
      const std::vector<ContactOutcome> outcomes =
          resolveSimultaneous(cluster_bodies, cluster_contacts);
      std::vector<FrictionOutcome> friction_outcomes(cluster_contacts.size());
      if (friction_step_ != nullptr) {
        for (std::size_t c = 0; c < frictions.size(); ++c) {
          frictions[c].normal_impulse = outcomes[c].impulse;
        }
        friction_step_(cluster_bodies, cluster_contacts, frictions, friction_outcomes);
      }

      for (std::size_t m = 0; m < members.size(); ++m) {
        if (isObstacle(members[m]) || inverseMassOf(members[m]) == 0.0) continue;
        Track& track = tracks_[members[m]];
        track.position = positionAt<Motion>(members[m], time);  // before the velocity changes
        track.time = time;
        track.velocity = cluster_bodies[m].velocity;
        track.angular_velocity = cluster_bodies[m].angular_velocity;
        track.last_impact_time = time;
        if constexpr (Motion::kAccelerates) updateResting(members[m]);
        changed.push_back(members[m]);
      }
      for (std::size_t c = 0; c < cluster.size(); ++c) {
        const auto& [pair, g] = contacts_at_instant[cluster[c]];
        const ClusterContact& contact = cluster_contacts[c];
        ImpactRecord record;
        record.time = time;
        record.body_a = pair.first;
        record.other_is_obstacle = isObstacle(pair.second);
        record.other = record.other_is_obstacle ? pair.second - bodies_.size() : pair.second;
        record.normal = g.normal;
        record.contact_point =
            positionAt<Motion>(pair.first, time) + (radius_[pair.first] + 0.5 * g.gap) * g.normal;
        record.restitution = contact.restitution;
        record.impulse = outcomes[c].impulse;
        record.friction_impulse = friction_outcomes[c].impulse;
        record.energy_lost = outcomes[c].energy_lost + friction_outcomes[c].energy_lost;
        record.velocity_a_before = before[contact.a].velocity;
        record.velocity_b_before = before[contact.b].velocity;
        record.velocity_a_after = cluster_bodies[contact.a].velocity;
        record.velocity_b_after = cluster_bodies[contact.b].velocity;
        record.angular_velocity_a_before = before[contact.a].angular_velocity;
        record.angular_velocity_b_before = before[contact.b].angular_velocity;
        record.angular_velocity_a_after = cluster_bodies[contact.a].angular_velocity;
        record.angular_velocity_b_after = cluster_bodies[contact.b].angular_velocity;
        record.oblique = hasObliqueComponent(record.velocity_a_before, g.normal) ||
                         hasObliqueComponent(record.velocity_b_before, g.normal);
        report.impacts.push_back(record);
      }
    }
  }
  return false;
}

template <class Motion>
Box ImpactMonitor::sweptBox(std::size_t body, double from, double to) const {
  const Eigen::Vector3d start = positionAt<Motion>(body, from);
  const Eigen::Vector3d end = positionAt<Motion>(body, to);
  Box box{start.cwiseMin(end), start.cwiseMax(end)};
  if constexpr (Motion::kAccelerates) {
    // A parabola's extreme along an axis, where that axis's velocity turns.
    const Eigen::Vector3d velocity = velocityAt<Motion>(body, from);
    const Eigen::Vector3d& acceleration = tracks_[body].acceleration;
    for (int axis = 0; axis < 3; ++axis) {
      if (acceleration[axis] == 0) continue;
      const double turn = -velocity[axis] / acceleration[axis];
      if (turn > 0 && turn < to - from) {
        const double extreme = positionAt<Motion>(body, from + turn)[axis];
        box.low[axis] = std::min(box.low[axis], extreme);
        box.high[axis] = std::max(box.high[axis], extreme);
      }
    }
  }
  // The body's size, with room for the touching band and the rounding of the positions.
  const double pad = radius_[body] * (1 + 2 * settings_.contact_tolerance) +
                     64 * kEps * (box.low.cwiseAbs().maxCoeff() + box.high.cwiseAbs().maxCoeff());
  box.low.array() -= pad;
  box.high.array() += pad;
  return box;
}

template <class Motion>
bool ImpactMonitor::mayReachObstacle(const Box& box, std::size_t obstacle) const {
  const ObstacleSpec& spec = obstacles_[obstacle];
  if (!spec.frame.empty()) return true;  // a moving obstacle: always a candidate
  const ObstaclePose& pose = obstacle_tracks_[obstacle].pose;
  if (spec.shape == ObstacleShape::kPlane) {
    // The box's lowest point along the normal: does it reach the plane?
    const Eigen::Vector3d centre = 0.5 * (box.low + box.high);
    const Eigen::Vector3d half = 0.5 * (box.high - box.low);
    return pose.normal.dot(centre) - pose.normal.cwiseAbs().dot(half) <= pose.offset;
  }
  const Box post{pose.position.array() - spec.radius, pose.position.array() + spec.radius};
  return post.overlaps(box);
}

template <class Motion>
void ImpactMonitor::broadphasePairs(double from, double to, std::vector<Pair>& pairs) {
  std::vector<Box>& boxes = scratch_.boxes;
  std::vector<char>& active = scratch_.active;
  boxes.resize(bodies_.size());
  active.assign(bodies_.size(), 0);
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    if (!tracks_[i].known) continue;
    active[i] = 1;
    boxes[i] = sweptBox<Motion>(i, from, to);
  }
  scratch_.hash.build(boxes, active);
  scratch_.hash.overlappingPairs(scratch_.body_pairs);
  // Merged in the canonical order: a body's pairs with bodies (sorted), then with obstacles
  // (whose indices follow every body's).
  pairs.clear();
  std::size_t next = 0;
  const std::vector<std::pair<std::size_t, std::size_t>>& body_pairs = scratch_.body_pairs;
  for (std::size_t a = 0; a < bodies_.size(); ++a) {
    for (; next < body_pairs.size() && body_pairs[next].first == a; ++next) {
      if (inverse_mass_[a] + inverse_mass_[body_pairs[next].second] > 0) {
        pairs.push_back(body_pairs[next]);
      }
    }
    if (!active[a] || inverse_mass_[a] == 0.0) continue;
    for (std::size_t o = 0; o < obstacles_.size(); ++o) {
      if (obstacle_tracks_[o].known && mayReachObstacle<Motion>(boxes[a], o)) {
        pairs.emplace_back(a, bodies_.size() + o);
      }
    }
  }
  scratch_.changed_boxes.clear();
}

template <class Motion>
std::vector<std::size_t> ImpactMonitor::addReachablePairs(
    std::size_t body, double from, double to, std::vector<Pair>& pairs,
    const std::vector<std::vector<std::size_t>>& pairs_of) {
  const Box box = sweptBox<Motion>(body, from, to);
  std::vector<std::size_t>& found = scratch_.found;
  scratch_.hash.query(box, found);
  // Bodies changed earlier in the step are in the grid with their old boxes: test their new.
  for (const auto& [other, other_box] : scratch_.changed_boxes) {
    if (other_box.overlaps(box)) found.push_back(other);
  }
  scratch_.changed_boxes.emplace_back(body, box);
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
    if (other == body || !tracks_[other].known ||
        inverse_mass_[body] + inverse_mass_[other] == 0.0) {
      continue;
    }
    add(Pair(std::min(body, other), std::max(body, other)));
  }
  if (inverse_mass_[body] > 0) {
    for (std::size_t o = 0; o < obstacles_.size(); ++o) {
      if (obstacle_tracks_[o].known && mayReachObstacle<Motion>(box, o)) {
        add(Pair(body, bodies_.size() + o));
      }
    }
  }
  return added;
}

template <class Motion>
StepReport ImpactMonitor::stepContinuous(double time, const std::vector<BodyStateSample>& states) {
  StepReport report;
  // Buffers reused from step to step: a step allocates nothing once they have grown.
  std::vector<Pair>& pairs = scratch_.pairs;
  if (settings_.broadphase) {
    broadphasePairs<Motion>(now_, time, pairs);
  } else {
    candidatePairs(pairs);
  }
  // Each body's pairs, so that after an impact only the pairs of the bodies it changed are
  // looked at again: the others' next contact has not moved.
  std::vector<std::vector<std::size_t>>& pairs_of = scratch_.pairs_of;
  pairs_of.resize(bodies_.size());
  for (std::vector<std::size_t>& list : pairs_of) list.clear();
  const auto index_pair = [&](std::size_t k) {
    pairs_of[pairs[k].first].push_back(k);
    if (!isObstacle(pairs[k].second)) pairs_of[pairs[k].second].push_back(k);
  };
  for (std::size_t k = 0; k < pairs.size(); ++k) index_pair(k);
  const std::size_t count = pairs.size();
  std::vector<double>& next_contact = scratch_.next_contact;
  next_contact.assign(count, INFINITY);
  // The pending first contacts, earliest on top; an entry whose time no longer matches its
  // pair's (rescheduled since) is stale and skipped.
  using Event = std::pair<double, std::size_t>;
  std::vector<Event>& events = scratch_.events;
  events.clear();
  const auto later = [](const Event& x, const Event& y) { return x.first > y.first; };

  // The next first contact of a pair from `from`, given its geometry then. A touching pair
  // that does not approach (it was just resolved, or slides) never comes back in a straight
  // line; under gravity it may (a ball that bounced falls back), so its next entry is looked
  // for, except on the plane it rests on.
  const auto schedule = [&](std::size_t k, double from, const Geometry& g) {
    next_contact[k] = INFINITY;
    const Pair& pair = pairs[k];
    if (!g.valid || resting(pair)) return;
    const bool touching_now = std::abs(g.gap) <= g.tolerance;
    if (!Motion::kAccelerates && touching_now) return;
    // Out of reach within the step even head-on (and accelerating all the way): no root needed.
    const double horizon = time - from;
    const double speed =
        (velocityAt<Motion>(pair.second, from) - velocityAt<Motion>(pair.first, from)).norm();
    double reach = speed * horizon;
    if constexpr (Motion::kAccelerates) {
      const Eigen::Vector3d acceleration_other =
          isObstacle(pair.second) ? Eigen::Vector3d::Zero() : tracks_[pair.second].acceleration;
      reach +=
          0.5 * (acceleration_other - tracks_[pair.first].acceleration).norm() * horizon * horizon;
    }
    if (g.gap > reach) return;
    const auto delay = timeOfImpact<Motion>(pair, from, horizon);
    if (!delay) return;
    const double when = std::min(from + *delay, time);
    // No progress on a pair already handled at this instant would loop for ever.
    if (touching_now && !(when > from)) return;
    next_contact[k] = when;
    events.emplace_back(when, k);
    std::push_heap(events.begin(), events.end(), later);
  };

  // At the start every pair may touch (the states were just taken); later only the pairs
  // reached from the struck ones through touching contacts (a chain, a rack).
  double instant = now_;
  std::vector<Geometry>& start_geometry = scratch_.geometry;
  start_geometry.resize(count);
  std::vector<std::size_t> touching;
  for (std::size_t k = 0; k < count; ++k) {
    start_geometry[k] = geometry<Motion>(pairs[k], instant);
    const Geometry& g = start_geometry[k];
    if (g.valid && std::abs(g.gap) <= g.tolerance) touching.push_back(k);
  }
  bool first = true;
  std::vector<Pair> touching_pairs;
  std::vector<std::size_t> changed;
  std::vector<char>& queued = scratch_.queued;
  queued.assign(bodies_.size(), 0);
  std::vector<std::size_t> frontier, frontier_seen;
  for (int instants = 0;; ++instants) {
    if (instants >= settings_.max_instants_per_step) {
      report.truncated = true;
      break;
    }
    touching_pairs.clear();
    for (const std::size_t k : touching) touching_pairs.push_back(pairs[k]);
    changed.clear();
    if (!touching_pairs.empty() &&
        !resolveInstant<Motion>(instant, touching_pairs, report, changed)) {
      report.truncated = true;
      break;
    }
    if (first) {
      // Geometry is unchanged by an impact: positions do not jump.
      for (std::size_t k = 0; k < count; ++k) schedule(k, instant, start_geometry[k]);
      first = false;
    } else {
      for (const std::size_t body : changed) {
        // Its new motion may reach bodies its swept box did not: new candidate pairs.
        if (settings_.broadphase) {
          for (const std::size_t k :
               addReachablePairs<Motion>(body, instant, time, pairs, pairs_of)) {
            next_contact.push_back(INFINITY);
            index_pair(k);
          }
        }
        for (const std::size_t k : pairs_of[body]) {
          schedule(k, instant, geometry<Motion>(pairs[k], instant));
        }
      }
    }

    while (!events.empty() && events.front().first != next_contact[events.front().second]) {
      std::pop_heap(events.begin(), events.end(), later);  // stale
      events.pop_back();
    }
    if (events.empty()) break;
    instant = events.front().first;
    // The struck pairs, and every contact touching their bodies, transitively.
    for (const std::size_t body : frontier_seen) queued[body] = 0;
    frontier_seen.clear();
    touching.clear();
    frontier.clear();
    while (!events.empty() && events.front().first == instant) {
      const std::size_t k = events.front().second;
      const bool current = next_contact[k] == instant;
      std::pop_heap(events.begin(), events.end(), later);
      events.pop_back();
      if (!current || std::find(touching.begin(), touching.end(), k) != touching.end()) continue;
      next_contact[k] = INFINITY;
      touching.push_back(k);
      for (const std::size_t participant : {pairs[k].first, pairs[k].second}) {
        if (!isObstacle(participant) && !queued[participant]) {
          queued[participant] = 1;
          frontier_seen.push_back(participant);
          frontier.push_back(participant);
        }
      }
    }
    while (!frontier.empty()) {
      const std::size_t body = frontier.back();
      frontier.pop_back();
      for (const std::size_t k : pairs_of[body]) {
        if (std::find(touching.begin(), touching.end(), k) != touching.end()) continue;
        const Geometry g = geometry<Motion>(pairs[k], instant);
        if (!g.valid || std::abs(g.gap) > g.tolerance) continue;
        touching.push_back(k);
        const std::size_t other = pairs[k].first == body ? pairs[k].second : pairs[k].first;
        if (!isObstacle(other) && !queued[other]) {
          queued[other] = 1;
          frontier_seen.push_back(other);
          frontier.push_back(other);
        }
      }
    }
    // The canonical order of the pairs (by their bodies' sorted ids, not by when the
    // broadphase found them).
    std::sort(touching.begin(), touching.end(),
              [&pairs](std::size_t x, std::size_t y) { return pairs[x] < pairs[y]; });
  }
  applyStates(states, report);
  now_ = time;
  return report;
}

template <class Motion>
StepReport ImpactMonitor::stepDiscrete(double time, const std::vector<BodyStateSample>& states) {
  StepReport report;
  applyStates(states, report);
  now_ = time;
  std::vector<Pair>& pairs = scratch_.pairs;
  if (settings_.broadphase) {
    broadphasePairs<Motion>(time, time, pairs);
  } else {
    candidatePairs(pairs);
  }
  std::vector<Pair> touching;
  for (const Pair& pair : pairs) {
    const Geometry g = geometry<Motion>(pair, time);
    if (g.valid && g.gap <= g.tolerance && overlapping_.count(pair) == 0) touching.push_back(pair);
  }
  std::vector<std::size_t> changed;
  if (!resolveInstant<Motion>(time, touching, report, changed)) report.truncated = true;
  overlapping_.clear();
  for (const Pair& pair : pairs) {
    const Geometry g = geometry<Motion>(pair, time);
    if (g.valid && g.gap < -g.tolerance) overlapping_.insert(pair);
  }
  return report;
}

/// Every member template for one motion model, instantiated where this is expanded.
#define COLLISION_RESPONSE_INSTANTIATE_MONITOR(Motion)                                           \
  template Eigen::Vector3d ImpactMonitor::positionAt<ImpactMonitor::Motion>(std::size_t, double) \
      const;                                                                                     \
  template Eigen::Vector3d ImpactMonitor::velocityAt<ImpactMonitor::Motion>(std::size_t, double) \
      const;                                                                                     \
  template ImpactMonitor::Geometry ImpactMonitor::geometry<ImpactMonitor::Motion>(const Pair&,   \
                                                                                  double) const; \
  template StepReport ImpactMonitor::stepContinuous<ImpactMonitor::Motion>(                      \
      double, const std::vector<BodyStateSample>&);                                              \
  template StepReport ImpactMonitor::stepDiscrete<ImpactMonitor::Motion>(                        \
      double, const std::vector<BodyStateSample>&);

}  // namespace collision_response::core
