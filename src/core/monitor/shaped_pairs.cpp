#include "monitor/shaped_pairs.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "collision_response/core/rigid_impact.h"
#include "contact/shaped_lasting.h"
#include "geometry/tumbling_contact.h"
#include "monitor/shaped_motion.h"

namespace collision_response::core::monitor {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
/// Passes of one step's watch at most (each moves every pair's watch on by its certified step, or
/// resolves an impact): past it the pairs are left unwatched for the rest of the step, said.
constexpr int kMaxPasses = 1 << 16;

using Pair = std::pair<std::size_t, std::size_t>;

/// m/s: no point of `body`'s track moves faster over a span of `span` seconds from `time`
/// (energySpeedBounds: the centre's speed plus the turning speed times the reach).
double pointSpeedBound(const PrincipalBody& principal, const TumblingBody& body,
                       const Eigen::Vector3d& gravity, double time, double span) {
  const auto [centre, turning] =
      energySpeedBounds(principal, body.velocityAt(time), body.angularVelocityAt(time),
                        body.orientationAt(time), gravity, span);
  return centre + turning * body.reach();
}

/// Track `body` as a tumbling body at `time`: its flight itself where it flies (no rotation made
/// again), else its state there (tumblingAt).
std::optional<TumblingBody> bodyAt(const ShapedRoom& room, std::size_t body, double time) {
  if (const TumblingBody* flight = room.tracks[body]->flight()) return *flight;
  return tumblingAt(room, body, time);
}

/// The state of track `body` at `time` with the velocities `after` (an impact's).
BodyStateSample stateAfter(const ShapedRoom& room, std::size_t body, double time,
                           const SolverBody& after) {
  BodyStateSample state = room.tracks[body]->stateAt(time);
  state.body = body;
  state.time = time;
  state.velocity = after.velocity;
  state.angular_velocity = after.angular_velocity;
  return state;
}

/// One pair's watch over a step.
class PairWatch {
 public:
  PairWatch(const World& world, ShapedRoom& room, std::vector<ImpactRecord>& impacts,
            std::vector<UnmodelledContact>& unmodelled)
      : world_(world), room_(room), impacts_(impacts), unmodelled_(unmodelled) {}

  /// s: how far from `time` the pair (a < b) may go on untouched, up to `end`, where `quiet(i)`
  /// is when track i's present motion ends (ShapedTrack::quietUntil, asked only where both fly or
  /// are still); an impact where it touches closing is resolved (0: look again at `time`); a
  /// lasting touch holds both and leaves the pair unwatched for the rest of the step.
  template <class Quiet>
  double step(const Pair& pair, double time, double end, const Quiet& quiet) {
    if (unwatched_.count(pair)) return end - time;
    const ShapedTrack& track_a = *room_.tracks[pair.first];
    const ShapedTrack& track_b = *room_.tracks[pair.second];
    const auto a = bodyAt(room_, pair.first, time);
    const auto b = bodyAt(room_, pair.second, time);
    if (!a || !b) return end - time;
    const double speed =
        boundOf(track_a, *a, pair.first, time, end) + boundOf(track_b, *b, pair.second, time, end);
    const double distance = (a->positionAt(time) - b->positionAt(time)).norm();
    if (distance > a->reach() + b->reach() + speed * (end - time)) {
      room_.parting.erase(pair);
      return end - time;  // too far apart to meet in the step
    }
    const auto parting = room_.parting.find(pair);
    if (parting != room_.parting.end() && parting->second > time) return parting->second - time;
    // The contact the pair's advancement found ahead, now reached with both motions as they were:
    // taken as found (its gap, normal, approach and manifold), not looked for again (face to face,
    // GJK may see the touching pair as overlapping by its tolerance).
    if (const auto ahead = pending_.find(pair); ahead != pending_.end()) {
      const Pending found = ahead->second;
      pending_.erase(ahead);
      // (t + (t_c - t) is t_c to the instant's rounding.)
      if (std::abs(found.contact.time - time) <= 4 * kEps * std::abs(time) &&
          found.since_a == track_a.since() && found.since_b == track_b.since()) {
        return touch(pair, *a, *b, found.contact, time, end);
      }
    }
    const SurfaceGap gap = gapAt(*a, *b, time);
    if (gap.overlapping) {
      // Just struck, face to face, GJK may see the pair overlap by its tolerance: it parts.
      if (parting != room_.parting.end()) return partOrHold(pair, *a, *b, time, end);
      unwatch(pair, time,
              "found inside each other (an impact missed: a body struck by a moving "
              "obstacle may pass its speed bound)");
      return end - time;
    }
    if (parting != room_.parting.end() && !touching(gap)) room_.parting.erase(parting);
    const double stop = 1e-12 + 4 * kEps * std::abs(time);
    const bool exact =
        (track_a.flight() || track_a.still(end)) && (track_b.flight() || track_b.still(end));
    if (exact) {
      // Both are flights (or still) until the earlier of their own next events: the pair's own
      // certified advancement (tumbling_contact.h: their relative motion) up to there.
      const double until = std::min({quiet(pair.first), quiet(pair.second), end});
      if (!(until > time)) return stop;
      const FirstContactResult found = firstContact(*a, *b, time, until - time);
      if (found.inside_at_start) return touchingNow(pair, *a, *b, time, end);
      if (!found.contact) return std::max(found.clear_until - time, stop);
      if (found.contact->time > time) {
        pending_[pair] = Pending{*found.contact, track_a.since(), track_b.since()};
        return found.contact->time - time;
      }
      return touch(pair, *a, *b, *found.contact, time, end);
    }
    // A body moving in lasting contact: every point's speed bounded by its energy.
    const double ahead = gap.gap / speed;
    if (gap.gap > 0 && ahead > stop) return ahead;
    return touchingNow(pair, *a, *b, time, end);
  }

  void unwatch(const Pair& pair, double time, const std::string& why) {
    unwatched_.insert(pair);
    if (why.empty()) return;
    unmodelled_.push_back({pair.first, pair.second, false, time,
                           "a shaped body and another shaped body " + why + ": not resolved"});
  }

 private:
  /// m/s: track `body`'s points' speed bound from `time` to `end` (0 where it is still).
  double boundOf(const ShapedTrack& track, const TumblingBody& body, std::size_t index, double time,
                 double end) const {
    if (track.still(end)) return 0.0;
    return pointSpeedBound(*room_.principal[index], body, world_.gravity, time, end - time);
  }

  /// The pair touching at `time`: closing faster than a settled rebound could lift a point
  /// (ShapedMotion's rule), an impact (0: look again from `time`); not closing (just struck, or a
  /// graze), apart again, looked at from the first instant its gap is open (doubling steps from
  /// the band's passage, up to 1 ms, as ShapedMotion::part); else its contact lasts, which is not
  /// modelled yet: both held where they are, the pair unwatched for the rest of the step
  /// (reported at the step's end).
  double touch(const Pair& pair, const TumblingBody& a, const TumblingBody& b,
               const TumblingContact& contact, double time, double end) {
    const double lift = world_.gravity.norm() * kLastingSettled * std::max(a.reach(), b.reach());
    const double closing = contact.closest.approach_speed;
    if (closing > 0 && closing * closing > 2 * lift) {
      resolve(pair, a, b, contact, time);
      return 0.0;
    }
    if (!(closing > 0)) return partOrHold(pair, a, b, time, end);
    hold(pair, time);
    return end - time;
  }

  /// A pair touching without closing (just struck, a graze): looked at again from the first
  /// instant its gap is past the touching band (doubling steps from the band's passage, up to
  /// 1 ms, as ShapedMotion::part); where it does not open, its contact lasts (hold).
  double partOrHold(const Pair& pair, const TumblingBody& a, const TumblingBody& b, double time,
                    double end) {
    const double speed = (a.velocityAt(time) - b.velocityAt(time)).norm() +
                         a.angularSpeedBound() * a.reach() + b.angularSpeedBound() * b.reach();
    const double band = FirstContactOptions{}.manifold_band;
    for (double step = std::max(band / speed, 1e-12 + 4 * kEps * std::abs(time)); step <= 1e-3;
         step *= 2) {
      // On the two motions as they are at `time` (past the step's end too: the watch of the
      // next step starts from the instant found).
      const SurfaceGap later = gapAt(a, b, time + step);
      if (!later.overlapping && !touching(later)) {
        room_.parting[pair] = time + step;
        return std::min(step, end - time);
      }
    }
    hold(pair, time);
    return end - time;
  }

  /// A lasting contact: both held where they are (never into each other), the pair unwatched
  /// for the rest of the step, reported at the step's end.
  void hold(const Pair& pair, double time) {
    room_.tracks[pair.first]->holdTouching(time);
    room_.tracks[pair.second]->holdTouching(time);
    room_.parting.erase(pair);
    unwatch(pair, time, "");
  }

  /// The pair touching at `time`, found so by its gap rather than by an advancement to it: its
  /// contact there (touch), or, overlapping by more than the distance's tolerance, reported.
  double touchingNow(const Pair& pair, const TumblingBody& a, const TumblingBody& b, double time,
                     double end) {
    FirstContactOptions at_once;
    at_once.time_tolerance = std::numeric_limits<double>::infinity();
    const FirstContactResult found = firstContact(a, b, time, 0.0, at_once);
    if (!found.contact) {
      unwatch(pair, time, "found inside each other");
      return end - time;
    }
    return touch(pair, a, b, *found.contact, time, end);
  }

  /// The impact of the pair at `time` at `contact`: one point by Chatterjee and Ruina's law with
  /// the pair's friction, several by the same law over all of them; both tracks restarted after.
  void resolve(const Pair& pair, const TumblingBody& a, const TumblingBody& b,
               const TumblingContact& contact, double time) {
    std::vector<SolverBody> bodies{solverBodyOf(*room_.principal[pair.first], a, time),
                                   solverBodyOf(*room_.principal[pair.second], b, time)};
    const std::vector<SolverBody> before = bodies;
    const Pair coefficients{pair.first, pair.second};
    double restitution = world_.restitutionOf(coefficients);
    if (contact.closest.approach_speed < world_.restitution_threshold) restitution = 0.0;
    const double friction = world_.effects.friction ? world_.frictionOf(coefficients) : 0.0;
    std::vector<ClusterContact> points;
    for (const ManifoldPoint& point : contact.manifold) {
      ClusterContact c;
      c.a = 0;
      c.b = 1;
      c.normal = contact.closest.normal;
      c.point = 0.5 * (point.point_a + point.point_b);
      c.lever_a = point.lever_a;
      c.lever_b = point.lever_b;
      c.restitution = restitution;
      points.push_back(c);
    }
    std::vector<ImpactRecord> records;
    const auto record = [&](const ClusterContact& point, double impulse) {
      ImpactRecord r;
      r.time = time;
      r.body_a = pair.first;
      r.other = pair.second;
      r.other_is_obstacle = false;
      r.contact_point = point.point;
      r.normal = point.normal;
      r.restitution = point.restitution;
      r.impulse = impulse;
      return r;
    };
    if (points.size() == 1) {
      auto outcome =
          resolveRigidImpact(bodies[0], bodies[1], points.front(), restitution, friction);
      if (!outcome) {
        unwatch(pair, time, "not resolved (" + outcome.error().message() + ")");
        return;
      }
      ImpactRecord r = record(points.front(), outcome->normal_impulse);
      r.friction_impulse = outcome->tangential_impulse.norm();
      r.energy_lost = outcome->energy_lost;
      records.push_back(r);
    } else {
      auto outcomes =
          resolveRigidSimultaneous(bodies, points, std::vector<double>(points.size(), friction));
      if (!outcomes) {
        unwatch(pair, time, "not resolved (" + outcomes.error().message() + ")");
        return;
      }
      for (std::size_t k = 0; k < points.size(); ++k) {
        const FrictionalOutcome& outcome = (*outcomes)[k];
        ImpactRecord r = record(points[k], outcome.normal.impulse);
        r.friction_impulse = outcome.friction_impulse;
        r.energy_lost = outcome.normal.energy_lost + outcome.friction_energy_lost;
        records.push_back(r);
      }
    }
    for (ImpactRecord& r : records) {
      r.velocity_a_before = before[0].velocity;
      r.angular_velocity_a_before = before[0].angular_velocity;
      r.velocity_b_before = before[1].velocity;
      r.angular_velocity_b_before = before[1].angular_velocity;
      r.velocity_a_after = bodies[0].velocity;
      r.angular_velocity_a_after = bodies[0].angular_velocity;
      r.velocity_b_after = bodies[1].velocity;
      r.angular_velocity_b_after = bodies[1].angular_velocity;
      impacts_.push_back(r);
    }
    const std::size_t sides[2] = {pair.first, pair.second};
    for (int side = 0; side < 2; ++side) {
      const std::size_t body = sides[side];
      const double last_state = room_.tracks[body]->last_state_time;
      const Eigen::Quaterniond orientation = room_.tracks[body]->last_orientation;
      if (!restartShaped(world_, room_, stateAfter(room_, body, time, bodies[side]))) {
        unwatch(pair, time, "not resolved (a state after the impact is refused)");
        continue;
      }
      ShapedTrack& track = *room_.tracks[body];
      track.last_state_time = last_state;
      track.last_orientation = orientation;
      track.last_impact_time = time;
      track.impact_change = bodies[side].velocity - before[side].velocity;
      // Whether it starts inside an obstacle, and its impacts at this instant (a box struck down
      // onto the floor it rests on strikes the floor now).
      track.advanceTo(time, impacts_, unmodelled_);
    }
    room_.parting[pair] = time;  // touching as they part: looked at by touch() from here
  }

  const World& world_;
  ShapedRoom& room_;
  std::vector<ImpactRecord>& impacts_;
  std::vector<UnmodelledContact>& unmodelled_;
  std::set<Pair> unwatched_;  // lasting or not resolved: not watched for the rest of the step
  /// A contact found ahead by a pair's advancement, and the instants the two motions it was found
  /// on hold from (ShapedTrack::since): valid at its instant while they are unchanged.
  struct Pending {
    TumblingContact contact;
    double since_a = 0.0;
    double since_b = 0.0;
  };
  std::map<Pair, Pending> pending_;
};

}  // namespace

void advanceShapedTogether(const World& world, ShapedRoom& room, double from, double time,
                           std::vector<ImpactRecord>& impacts,
                           std::vector<UnmodelledContact>& unmodelled) {
  std::vector<std::size_t> known;
  for (std::size_t body = 0; body < room.tracks.size(); ++body) {
    if (room.tracks[body]) known.push_back(body);
  }
  const auto advanceAll = [&](double to) {
    for (const std::size_t body : known) {
      if (room.tracks[body]) room.tracks[body]->advanceTo(to, impacts, unmodelled);
    }
  };
  if (known.size() < 2) {
    advanceAll(time);
    return;
  }
  PairWatch watch(world, room, impacts, unmodelled);
  double t = from;
  advanceAll(t);
  std::vector<std::optional<double>> quiet(room.tracks.size());  // this pass's, where asked
  const auto quietOf = [&](std::size_t body) {
    if (!quiet[body]) quiet[body] = room.tracks[body]->quietUntil(time);
    return *quiet[body];
  };
  for (int pass = 0; t < time; ++pass) {
    if (pass == kMaxPasses) {
      for (std::size_t i = 0; i < known.size(); ++i) {
        for (std::size_t j = i + 1; j < known.size(); ++j) {
          watch.unwatch({known[i], known[j]}, t, "passed the watch's steps (65,536 in a step)");
        }
      }
    }
    std::fill(quiet.begin(), quiet.end(), std::nullopt);
    double next = time;
    bool struck = false;
    for (std::size_t i = 0; i < known.size() && !struck; ++i) {
      for (std::size_t j = i + 1; j < known.size(); ++j) {
        const std::size_t a = known[i], b = known[j];
        if (!room.tracks[a] || !room.tracks[b]) continue;
        const double step = watch.step({a, b}, t, time, quietOf);
        if (step == 0.0) {
          struck = true;  // an impact: every pair looked at again from here
          break;
        }
        next = std::min(next, t + step);
      }
    }
    if (struck) continue;
    advanceAll(next);
    t = next;
  }
}

}  // namespace collision_response::core::monitor
