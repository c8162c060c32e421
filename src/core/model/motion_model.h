// The motion models of the monitor and the small kernels that depend on them: where a
// participant is at an instant and how fast it moves, where two participants are relative to
// each other, when they first touch, and the box a body sweeps. The model is a template
// parameter chosen once per step (monitor.cpp, withMotionModel): no per-pair branch on gravity.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <optional>

#include "collision_response/core/time_of_impact.h"
#include "geometry/broadphase.h"
#include "geometry/motion.h"
#include "model/monitor_world.h"

namespace collision_response::core::monitor {

/// Free flight in a straight line: no effect moves the bodies between impacts.
struct StraightLine {
  static constexpr bool kAccelerates = false;
  static Eigen::Vector3d position(const Track& track, double time) {
    return track.position + track.velocity * (time - track.time);
  }
  static Eigen::Vector3d velocity(const Track& track, double /*time*/) { return track.velocity; }
  static Eigen::Vector3d angularVelocity(const Track& track, double /*time*/) {
    return track.angular_velocity;
  }
};

/// Parabolas under the track's acceleration (gravity, or its part along the plane a body rests
/// on): the gravity effect.
/// In curved lasting contact the motion is the integrated step's instead.
struct UnderGravity {
  static constexpr bool kAccelerates = true;
  static Eigen::Vector3d position(const Track& track, double time) {
    if (track.constrained) return track.constrained->position(track.slot, time);
    return positionAfter(track.position, track.velocity, track.acceleration, time - track.time);
  }
  static Eigen::Vector3d velocity(const Track& track, double time) {
    if (track.constrained) return track.constrained->velocity(track.slot, time);
    return velocityAfter(track.velocity, track.acceleration, time - track.time);
  }
  static Eigen::Vector3d angularVelocity(const Track& track, double time) {
    if (track.constrained) return track.constrained->angularVelocity(track.slot, time);
    return velocityAfter(track.angular_velocity, track.angular_acceleration, time - track.time);
  }
};

/// The participant moves along an integrated step (curved lasting contact, flight through air).
inline bool constrained(const World& world, std::size_t participant) {
  return !world.isObstacle(participant) && world.tracks[participant].constrained != nullptr;
}

/// The participant flies through air (drag, Magnus): an AirFlight.
inline bool freeFlight(const World& world, std::size_t participant) {
  return constrained(world, participant) && world.tracks[participant].constrained->free();
}

/// A participant's position at `time`: a body along its track, an obstacle along its pose.
template <class Motion>
Eigen::Vector3d positionAt(const World& world, std::size_t participant, double time) {
  if (world.isObstacle(participant)) {
    return originAt(world.obstaclePose(participant), time);
  }
  return Motion::position(world.tracks[participant], time);
}

template <class Motion>
Eigen::Vector3d velocityAt(const World& world, std::size_t participant, double time) {
  if (world.isObstacle(participant)) return world.obstaclePose(participant).velocity;
  return Motion::velocity(world.tracks[participant], time);
}

template <class Motion>
Eigen::Vector3d angularVelocityAt(const World& world, std::size_t participant, double time) {
  if (world.isObstacle(participant)) return world.obstaclePose(participant).angular_velocity;
  return Motion::angularVelocity(world.tracks[participant], time);
}

/// The acceleration the model gives a participant (obstacles move in straight lines).
template <class Motion>
Eigen::Vector3d accelerationOf(const World& world, std::size_t participant) {
  if (!Motion::kAccelerates || world.isObstacle(participant)) return Eigen::Vector3d::Zero();
  return world.tracks[participant].acceleration;
}

/// A participant's shape at `time`: a body's sphere on its track, an obstacle's placed shape
/// moved on along its pose.
template <class Motion>
PlacedShape shapeAt(const World& world, std::size_t participant, double time) {
  if (world.isObstacle(participant)) return shapeAt(world.placedShape(participant), time);
  PlacedShape placed;
  const Eigen::Vector3d centre = positionAt<Motion>(world, participant, time);
  placed.shape = Sphere{centre, world.radius[participant]};
  placed.pose.time = time;
  placed.pose.transform.translation() = centre;
  placed.pose.velocity = velocityAt<Motion>(world, participant, time);
  placed.pose.angular_velocity = angularVelocityAt<Motion>(world, participant, time);
  return placed;
}

/// Where the two participants of `pair` are relative to each other at `time` (the narrow
/// phase's contactGeometry). Coincident centres (a sample caught one body right through the
/// other) have no line of centres; the line of impact is the direction of approach, if any.
template <class Motion>
Geometry geometry(const World& world, const Pair& pair, double time) {
  // Named copies rather than a structured binding: the lambda below captures them (C++17, and
  // clang, allow no capture of a binding).
  const std::size_t a = pair.first, other = pair.second;
  return contactGeometry(positionAt<Motion>(world, a, time), world.radius[a],
                         shapeAt<Motion>(world, other, time), world.settings.contact_tolerance,
                         [&] {
                           return Eigen::Vector3d(velocityAt<Motion>(world, a, time) -
                                                  velocityAt<Motion>(world, other, time));
                         });
}

template <class Motion>
Geometry geometry(const World& world, const Pair& pair, double time);

/// A bound on a participant's acceleration over [from, to]: a free body's own; along an
/// integrated motion, that motion's bound (IntegratedMotion::accelerationBound).
template <class Motion>
double accelerationBound(const World& world, std::size_t participant, double from, double to) {
  if (world.isObstacle(participant)) return 0.0;
  const Track& track = world.tracks[participant];
  if (track.constrained) {
    return track.constrained->accelerationBound(track.slot, world.gravity.norm(), from, to);
  }
  return track.acceleration.norm();
}

/// The first contact of a pair one of whose bodies follows an integrated step, within it, by
/// conservative advancement (Mirtich, "Impulse-based dynamic simulation of rigid body systems",
/// 1996): from each sample the next is as far as the gap cannot close, at the closing speed and
/// the acceleration bounds (with the line of centres' turning, |v|^2 / d); the first sample at
/// or past contact is bisected. A pair touching at `from` (just resolved) is looked at as it
/// separates and comes back: its contact is where its gap falls half-way from its start to the
/// touching band's edge, inside the band, so the instant's resolver sees it touch.
///
/// A free flight through air (AirFlight) bounces again and again off what it left: half-way to
/// the band's edge each time would drift its contacts to that edge and, one rounding later, past
/// it (a ball bouncing on a floor for seconds, then through it). Its contact is where its gap
/// comes back to 0, or to its start where it started inside, never deeper; the instant returned
/// is the last one before it, bisected until the gap there is within half the band of it, so
/// the next bounce starts no deeper than this one.
template <class Motion>
std::optional<double> timeOfImpactAlongPaths(const World& world, const Pair& pair, double from,
                                             double horizon) {
  double end = from + horizon;
  for (const std::size_t p : {pair.first, pair.second}) {
    if (constrained(world, p)) end = std::min(end, world.tracks[p].constrained->end());
  }
  if (!(end > from)) return std::nullopt;
  const Geometry start = geometry<Motion>(world, pair, from);
  if (start.gap < -start.tolerance) return std::nullopt;  // overlapping already: not an impact
  const bool flying = freeFlight(world, pair.first) || freeFlight(world, pair.second);
  const double contact_at = flying          ? std::min(0.0, start.gap)
                            : start.gap > 0 ? 0.0
                                            : 0.5 * (start.gap - start.tolerance);
  // A finite shape's next feature may curve where this one is flat.
  const bool curved = !start.flat() || start.bounded;
  const double contact_distance = world.radius[pair.first] + world.radius[pair.second];
  const double accelerations = accelerationBound<Motion>(world, pair.first, from, end) +
                               accelerationBound<Motion>(world, pair.second, from, end);
  const double span = end - from;
  const double shortest = 1e-12 * span + 4 * kEps * std::abs(end);
  constexpr int kMaxSamples = 4096;
  double previous_time = from, step = shortest, previous_gap = start.gap;
  Geometry g = start;
  for (int samples = 0; samples < kMaxSamples && previous_time < end; ++samples) {
    const Eigen::Vector3d relative = velocityAt<Motion>(world, pair.second, previous_time) -
                                     velocityAt<Motion>(world, pair.first, previous_time);
    const double closing = std::max(0.0, -g.normal.dot(relative));
    const double bound = accelerations + (curved ? relative.squaredNorm() / contact_distance : 0.0);
    const double room = g.gap - contact_at;
    // Far enough that closing at `closing`, accelerating at `bound`, leaves half the room; near
    // the start (no room yet) twice the last step.
    double advance =
        room > 0 ? room / (closing + std::sqrt(closing * closing + bound * room)) : 2 * step;
    advance = std::clamp(advance, shortest, span / 16);
    step = advance;
    const double t = std::min(previous_time + advance, end);
    g = geometry<Motion>(world, pair, t);
    if (g.gap <= contact_at) {
      double open = previous_time, closed = t, open_gap = previous_gap;
      while (closed - open > 1e-13 * span + 4e-16 * std::abs(closed) ||
             (flying && open_gap - contact_at > 0.5 * start.tolerance)) {
        const double middle = 0.5 * (open + closed);
        if (!(middle > open && middle < closed)) break;  // no double between them
        const double gap = geometry<Motion>(world, pair, middle).gap;
        if (gap > contact_at) {
          open = middle;
          open_gap = gap;
        } else {
          closed = middle;
        }
      }
      return (flying ? open : closed) - from;
    }
    previous_time = t;
    previous_gap = g.gap;
  }
  return std::nullopt;
}

/// The first contact of `pair` within `horizon` after `from` (time_of_impact.h's stable roots).
template <class Motion>
std::optional<double> timeOfImpact(const World& world, const Pair& pair, double from,
                                   double horizon) {
  const auto [a, other] = pair;
  if constexpr (Motion::kAccelerates) {
    if (constrained(world, a) || constrained(world, other)) {
      return timeOfImpactAlongPaths<Motion>(world, pair, from, horizon);
    }
  }
  BallMotion ball;
  ball.centre = positionAt<Motion>(world, a, from);
  ball.radius = world.radius[a];
  ball.velocity = velocityAt<Motion>(world, a, from);
  if constexpr (Motion::kAccelerates) ball.acceleration = world.tracks[a].acceleration;
  const PlacedShape shape = shapeAt<Motion>(world, other, from);
  return firstContact(ball, shape, velocityAt<Motion>(world, other, from),
                      accelerationOf<Motion>(world, other), Motion::kAccelerates, horizon);
}

/// How far apart the pair's surfaces can close within `horizon` from `from`, head-on and
/// accelerating all the way: a gap larger than this needs no root.
template <class Motion>
double reach(const World& world, const Pair& pair, double from, double horizon) {
  if constexpr (Motion::kAccelerates) {
    // An integrated step's accelerations vary: no bound, the root is looked for.
    if (constrained(world, pair.first) || constrained(world, pair.second)) return INFINITY;
  }
  const Eigen::Vector3d own = velocityAt<Motion>(world, pair.first, from);
  const Eigen::Vector3d other = velocityAt<Motion>(world, pair.second, from);
  double distance = (other - own).norm() * horizon;
  // A finite obstacle that turns (shapeAt): its origin's velocity turns with it, and its
  // surface's points move up to |w| R faster.
  if (world.isObstacle(pair.second)) {
    const PlacedShape& placed = world.placedShape(pair.second);
    const double turning = placed.pose.angular_velocity.norm() * turningReach(placed.shape);
    if (turning > 0) distance = (own.norm() + other.norm() + turning) * horizon;
  }
  if constexpr (Motion::kAccelerates) {
    distance += 0.5 *
                (accelerationOf<Motion>(world, pair.second) - world.tracks[pair.first].acceleration)
                    .norm() *
                horizon * horizon;
  }
  return distance;
}

/// The velocity at `time` of the pair's second participant where the pair touches (`g`): a
/// body's, a plane's or a sphere's own (a sphere's turning is carried by its radius), and a
/// finite shape's surface's at the contact point, v + w x r (its centre's unless it turns).
template <class Motion>
Eigen::Vector3d touchingVelocity(const World& world, const Pair& pair, const Geometry& g,
                                 double time) {
  if (g.bounded && world.isObstacle(pair.second)) return g.surface_velocity;
  return velocityAt<Motion>(world, pair.second, time);
}

/// The pair's relative velocity along the normal of `g` at `time` (> 0: opening) and what
/// rounding explains of it (kApproachTolerance of the speeds).
struct NormalMotion {
  double speed = 0.0, rounding = 0.0;
};
template <class Motion>
NormalMotion normalMotion(const World& world, const Pair& pair, const Geometry& g, double time) {
  const Eigen::Vector3d velocity_a = velocityAt<Motion>(world, pair.first, time);
  const Eigen::Vector3d velocity_other = touchingVelocity<Motion>(world, pair, g, time);
  return NormalMotion{(velocity_other - velocity_a).dot(g.normal),
                      kApproachTolerance * (velocity_a.lpNorm<Eigen::Infinity>() +
                                            velocity_other.lpNorm<Eigen::Infinity>())};
}

/// The pair closes along the normal of `g` at `time` faster than rounding explains.
template <class Motion>
bool approaching(const World& world, const Pair& pair, const Geometry& g, double time) {
  const NormalMotion motion = normalMotion<Motion>(world, pair, g, time);
  return motion.speed < -motion.rounding;
}

/// The pair opens along the normal of `g` at `time` faster than rounding explains.
template <class Motion>
bool separating(const World& world, const Pair& pair, const Geometry& g, double time) {
  const NormalMotion motion = normalMotion<Motion>(world, pair, g, time);
  return motion.speed > motion.rounding;
}

/// The box a body sweeps over [from, to], padded by its radius.
template <class Motion>
Box sweptBox(const World& world, std::size_t body, double from, double to) {
  const Eigen::Vector3d start = positionAt<Motion>(world, body, from);
  Box box{start, start};
  bool integrated = false;
  if constexpr (Motion::kAccelerates) integrated = constrained(world, body);
  if (!integrated) {
    // Its position at `to` only when its motion is not integrated: asking an integrated one
    // would integrate it on to `to` (ConstrainedStep integrates only as far as it is looked at).
    const Eigen::Vector3d end = positionAt<Motion>(world, body, to);
    box = Box{start.cwiseMin(end), start.cwiseMax(end)};
  }
  if constexpr (Motion::kAccelerates) {
    if (integrated) {
      // Along the integrated motion, sampled; beyond its end, as far as its speed and its
      // acceleration's bound could carry it.
      const IntegratedMotion& motion = *world.tracks[body].constrained;
      const std::size_t slot = world.tracks[body].slot;
      const double inside = std::clamp(to, from, motion.end());
      for (int i = 1; i <= 16; ++i) {
        const Eigen::Vector3d point =
            positionAt<Motion>(world, body, from + (inside - from) * i / 16);
        box.low = box.low.cwiseMin(point);
        box.high = box.high.cwiseMax(point);
      }
      const double bound = motion.accelerationBound(slot, world.gravity.norm(), from, to);
      const double beyond = to - inside;
      double distance =
          velocityAt<Motion>(world, body, inside).norm() * beyond + 0.5 * bound * beyond * beyond;
      if (motion.free()) {
        // A flight bends between the samples by at most a chord's sagitta, bound h^2 / 8.
        const double h = (inside - from) / 16;
        distance += bound * h * h / 8;
      }
      box.low.array() -= distance;
      box.high.array() += distance;
    } else {
      // A parabola's extreme along an axis, where that axis's velocity turns.
      const Eigen::Vector3d velocity = velocityAt<Motion>(world, body, from);
      const Eigen::Vector3d& acceleration = world.tracks[body].acceleration;
      for (int axis = 0; axis < 3; ++axis) {
        if (acceleration[axis] == 0) continue;
        const double turn = -velocity[axis] / acceleration[axis];
        if (turn > 0 && turn < to - from) {
          const double extreme = positionAt<Motion>(world, body, from + turn)[axis];
          box.low[axis] = std::min(box.low[axis], extreme);
          box.high[axis] = std::max(box.high[axis], extreme);
        }
      }
    }
  }
  // The body's size, with room for the touching band and the rounding of the positions.
  const double pad = world.radius[body] * (1 + 2 * world.settings.contact_tolerance) +
                     64 * kEps * (box.low.cwiseAbs().maxCoeff() + box.high.cwiseAbs().maxCoeff());
  box.low.array() -= pad;
  box.high.array() += pad;
  return box;
}

}  // namespace collision_response::core::monitor
