#include "monitor/shaped_tracks.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "collision_response/core/body_shape.h"
#include "collision_response/core/validation.h"
#include "geometry/narrow_phase.h"
#include "monitor/shaped_pairs.h"

namespace collision_response::core::monitor {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// The obstacles as `world` has them placed now.
std::vector<ShapedObstacle> placedObstacles(const World& world) {
  std::vector<ShapedObstacle> placed;
  for (std::size_t o = 0; o < world.obstacles.size(); ++o) {
    if (world.obstacle_tracks[o].known) placed.push_back({o, world.obstacle_tracks[o].placed});
  }
  return placed;
}

/// What the engine needs of `world`'s scene for `body`: gravity, the threshold, and the pair's
/// coefficients with each obstacle (from the monitor's tables, as tuned when it starts).
ShapedScene shapedScene(const World& world, std::size_t body) {
  ShapedScene scene;
  scene.acceleration = world.gravity;
  scene.restitution_threshold = world.restitution_threshold;
  scene.body = body;
  scene.integration_tolerance = world.integration_tolerance;
  if (world.effects.air()) {
    scene.air = world.air[body];
    scene.flight_tolerance = world.flight_tolerance;
  }
  std::vector<double> restitution, friction;
  for (std::size_t o = 0; o < world.obstacles.size(); ++o) {
    const Pair pair{body, world.bodyCount() + o};
    restitution.push_back(world.restitutionOf(pair));
    friction.push_back(world.effects.friction ? world.frictionOf(pair) : 0.0);
  }
  const std::string id = world.bodies[body].id;
  const auto coefficient = [id](std::vector<double> values, const char* what) {
    return [id, values = std::move(values), what](std::size_t o) -> Expected<double> {
      if (!std::isfinite(values[o])) {
        return Error{"materials", std::string("no coefficient of ") + what + " for body '" + id +
                                      "' against obstacle " + std::to_string(o)};
      }
      return values[o];
    };
  };
  scene.restitution = coefficient(std::move(restitution), "restitution");
  scene.friction = coefficient(std::move(friction), "friction");
  return scene;
}

}  // namespace

std::optional<TumblingBody> tumblingAt(const ShapedRoom& room, std::size_t body, double time) {
  const PrincipalBody& principal = *room.principal[body];
  const BodyStateSample state = room.tracks[body]->stateAt(time);
  auto created = TumblingBody::create(principal.shape, principal.moments, time, state.position,
                                      state.velocity, Eigen::Vector3d::Zero(),
                                      state.orientation * principal.body_from_principal,
                                      state.angular_velocity);
  if (!created) return std::nullopt;
  return std::move(created.value());
}

bool touching(const SurfaceGap& gap) {
  return gap.overlapping || gap.gap <= FirstContactOptions{}.manifold_band;
}

Expected<ShapedTrack> ShapedTrack::start(const PrincipalBody& principal,
                                         std::vector<ShapedObstacle> obstacles,
                                         const ShapedScene& scene, const BodyStateSample& state,
                                         std::size_t revision) {
  auto motion = ShapedMotion::create(principal, std::move(obstacles), scene, state);
  if (!motion) return motion.error();
  ShapedTrack track(std::move(motion.value()), revision);
  track.last_orientation = state.orientation;
  return track;
}

void ShapedTrack::advanceTo(double time, std::vector<ImpactRecord>& impacts,
                            std::vector<UnmodelledContact>& unmodelled) {
  if (fresh_) {
    fresh_ = false;
    // A state inside an obstacle (beyond its touching band) starts no motion there: its first
    // contact would not be found (tumbling_contact.h), and the body would go on through it.
    if (const auto inside = motion_.insideAtStart()) {
      hold(stateAt(since_), *inside,
           "its state is inside the obstacle: a shaped body's motion starts in free space or "
           "touching",
           unmodelled);
      return;
    }
  }
  // Each pass moves on by one event at least (an impact, a graze, a lasting motion's end), and
  // a held body not at all: bounded as the prediction's run is.
  for (;;) {
    if (mode_ == Mode::kHeld) return;
    if (mode_ == Mode::kLasting) {
      // Its lasting motion watches its face alone: another obstacle (a wall it slides into, a
      // robot's link swung at it) is looked for first.
      const double watch_end = std::min(time, lasting_->until);
      if (watched_until_ < watch_end) {
        if (const auto strike =
                motion_.struckWhileLasting(*lasting_, lasting_with_, watched_until_, watch_end)) {
          struck(*strike, unmodelled);
          continue;
        }
        watched_until_ = watch_end;
      }
      if (time <= lasting_->until) return;
      endLasting(unmodelled);
      continue;
    }
    if (leaving_) {
      leaving_ = false;
      // Apart is looked for at once (no horizon): a step shorter than the band's passage would
      // otherwise be taken apart unseen.
      if (!motion_.leave(kInfinity)) {
        enterLasting(motion_.time(), unmodelled);
        continue;
      }
    }
    const std::size_t before = impacts.size();
    const auto found = motion_.next(time, impacts, true);
    if (!found) {
      hold(stateAt(motion_.time()), motion_.lastingWith().empty() ? 0 : motion_.lastingWith()[0],
           found.error().message(), unmodelled);
      return;
    }
    switch (found->event) {
      case ShapedMotion::Event::kFree:
        return;
      case ShapedMotion::Event::kGrazed:
        continue;
      case ShapedMotion::Event::kLasting:
        enterLasting(found->time, unmodelled);
        continue;
      case ShapedMotion::Event::kImpact:
        break;
    }
    since_ = found->time;
    leaving_ = true;
    if (impacts.size() > before) {
      impact_change = impacts.back().velocity_a_after - impacts[before].velocity_a_before;
      last_impact_time = found->time;
    }
    rests_from_ = motion_.flatBouncesEnd();
  }
}

/// Where its lasting motion ends (lasting_->until): asked again from there ("stops"), its events
/// going on from there ("resumes", within ResumeGuard's bounds), or held, saying why.
void ShapedTrack::endLasting(std::vector<UnmodelledContact>& unmodelled) {
  const double until = lasting_->until;
  const std::string ends = lasting_->ends;
  BodyStateSample there = stateAt(until);
  if (ends == "stops") {
    LastingBody body;
    const PrincipalBody& principal = motion_.principal();
    body.shape = principal.shape;
    body.moments = principal.moments;
    body.mass = principal.mass;
    body.time = until;
    body.centre = lasting_->centreAt(until);
    body.velocity = lasting_->velocityAt(until);
    body.angular_velocity = lasting_->angularVelocityAt(until);
    body.orientation = lasting_->orientationAt(until);
    body.gravity = motion_.flight().acceleration();
    startLasting(body, faces_, unmodelled);
    if (mode_ == Mode::kLasting && !(lasting_->until > until)) {
      hold(there, *against_, "its lasting contact ends where it starts", unmodelled);
    }
    return;
  }
  if (ends == "resumes") {
    // Another point reaches the face, or the body leaves it: its events go on from there
    // (within ResumeGuard's bounds; beyond them it is held).
    if (const auto refused = resumes_.refuse(until)) {
      hold(there, *against_, *refused, unmodelled);
      return;
    }
    if (Status status = motion_.restartFrom(there); !status) {
      hold(there, *against_, status.error().message(), unmodelled);
      return;
    }
    if (const auto inside = motion_.insideAtStart()) {  // never through it
      hold(there, *inside, "its tipping ends inside the obstacle", unmodelled);
      return;
    }
    mode_ = Mode::kFlying;
    lasting_.reset();
    since_ = until;
    rests_from_.reset();
    return;
  }
  hold(there, *against_, ends, unmodelled);
}

/// Another obstacle meets the body in its lasting motion: its lasting motion ends there, its
/// events going on from there: a strike's impact with it (the face's points taking part), or a
/// touch that does not close found to last with both (lastingOnFaces).
void ShapedTrack::struck(const ShapedMotion::Strike& strike,
                         std::vector<UnmodelledContact>& unmodelled) {
  const BodyStateSample there = stateAt(strike.time);
  if (const auto refused = resumes_.refuse(strike.time)) {
    hold(there, strike.obstacle, *refused, unmodelled);
    return;
  }
  if (Status status = motion_.restartFrom(there); !status) {
    hold(there, strike.obstacle, status.error().message(), unmodelled);
    return;
  }
  mode_ = Mode::kFlying;
  lasting_.reset();
  since_ = strike.time;
  rests_from_.reset();
}

void ShapedTrack::holdTouching(double time) {
  held_ = stateAt(time);
  held_.velocity.setZero();
  held_.angular_velocity.setZero();
  mode_ = Mode::kHeld;
  since_ = time;
  against_.reset();
  lasting_.reset();
}

void ShapedTrack::placeObstacles(std::vector<ShapedObstacle> placed, double time,
                                 std::size_t revision) {
  motion_.placeObstacles(std::move(placed), std::max(time, motion_.time()));
  revision_ = revision;
}

void ShapedTrack::enterLasting(double time, std::vector<UnmodelledContact>& unmodelled) {
  const std::vector<std::size_t> with = motion_.lastingWith();
  const std::size_t obstacle = with.empty() ? 0 : with.front();
  auto faces = motion_.lastingFaces();
  if (!faces) {
    hold(stateAt(time), obstacle, faces.error().message(), unmodelled);
    return;
  }
  against_ = obstacle;
  lasting_with_ = with;
  startLasting(faces->first, faces->second, unmodelled);
}

void ShapedTrack::startLasting(const LastingBody& body, const std::vector<FlatFace>& faces,
                               std::vector<UnmodelledContact>& unmodelled) {
  const std::size_t obstacle = against_.value_or(0);
  auto motion = lastingOnFaces(body, faces, motion_.integrationTolerance());
  if (!motion && mode_ == Mode::kFlying && motion.error().field == "body.velocity" &&
      motion_.part(kInfinity)) {
    return;  // no lasting contact: its points part from the face, and the flight goes on
  }
  if (!motion) {
    BodyStateSample state;
    state.body = motion_.body();
    state.time = body.time;
    state.position = body.centre;
    state.orientation = body.orientation * motion_.principal().body_from_principal.conjugate();
    hold(state, obstacle, motion.error().message(), unmodelled);
    return;
  }
  const bool resting_again = mode_ == Mode::kLasting;
  mode_ = Mode::kLasting;
  lasting_ = std::move(motion.value());
  faces_ = faces;
  since_ = body.time;
  watched_until_ = body.time;
  against_ = obstacle;
  if (!resting_again) {
    // Where its last impact was a flat landing, whose bounces accumulate at rests_from_
    // (flatBouncesEnd), the contact lasts from there (as a ball's: doc/model.md, "Coming to
    // rest"): a little after the settled bounce that ended the flights.
    lasting_since_ = rests_from_ ? *rests_from_ : body.time;
  }
}

void ShapedTrack::hold(const BodyStateSample& state, std::size_t obstacle, const std::string& what,
                       std::vector<UnmodelledContact>& unmodelled) {
  mode_ = Mode::kHeld;
  held_ = state;
  held_.velocity.setZero();
  held_.angular_velocity.setZero();
  since_ = state.time;
  against_ = obstacle;
  lasting_.reset();
  UnmodelledContact contact;
  contact.body = motion_.body();
  contact.other = obstacle;
  contact.other_is_obstacle = true;
  contact.time = state.time;
  contact.what = what;
  unmodelled.push_back(contact);
}

double ShapedTrack::quietUntil(double horizon) const {
  if (mode_ == Mode::kHeld || still(horizon)) return horizon;
  if (mode_ == Mode::kLasting || fresh_) return since_;
  ShapedMotion peek = motion_;
  if (leaving_ && !peek.leave(kInfinity)) return peek.time();
  std::vector<ImpactRecord> impacts;
  const auto found = peek.next(horizon, impacts, true);
  if (!found) return peek.time();
  return found->event == ShapedMotion::Event::kFree ? horizon : found->time;
}

bool ShapedTrack::still(double horizon) const {
  if (mode_ == Mode::kHeld) return true;
  if (mode_ != Mode::kLasting || lasting_->pivot || !(lasting_->until >= horizon)) return false;
  return lasting_->velocity0.isZero(0.0) && lasting_->acceleration.isZero(0.0) &&
         lasting_->angular_velocity0.isZero(0.0) && lasting_->angular_acceleration.isZero(0.0);
}

BodyStateSample ShapedTrack::stateAt(double time) const {
  if (mode_ == Mode::kHeld) {
    BodyStateSample state = held_;
    state.time = time;
    return state;
  }
  if (mode_ == Mode::kLasting) {
    BodyStateSample state;
    state.body = motion_.body();
    state.time = time;
    state.position = lasting_->centreAt(time);
    state.velocity = lasting_->velocityAt(time);
    state.angular_velocity = lasting_->angularVelocityAt(time);
    state.orientation =
        lasting_->orientationAt(time) * motion_.principal().body_from_principal.conjugate();
    return state;
  }
  return motion_.stateOn(motion_.flight(), time);
}

std::vector<ContactRecord> ShapedTrack::contacts(double time) const {
  std::vector<ContactRecord> records;
  if (mode_ != Mode::kLasting) return records;
  const std::size_t body = motion_.body();
  for (const SupportForce& force : lasting_->forcesAt(time)) {
    ContactRecord record;
    record.time = time;
    record.body_a = body;
    record.other =
        force.face < lasting_with_.size() ? lasting_with_[force.face] : against_.value_or(0);
    record.other_is_obstacle = true;
    record.contact_point = force.point;
    // From the body into the face (or into the face's edge, along the body's own face).
    record.normal = force.normal.isZero(0.0) ? Eigen::Vector3d(-faces_.at(force.face).normal)
                                             : Eigen::Vector3d(-force.normal);
    record.normal_force = force.normal_force;
    record.friction_force = -force.friction_force;  // on the face
    record.state = lasting_->stateAt(time);
    record.since = lasting_since_;
    records.push_back(record);
  }
  return records;
}

bool ShapedRoom::any() const {
  return std::any_of(principal.begin(), principal.end(),
                     [](const auto& p) { return p.has_value(); });
}

bool ballsMoveAsShaped(const World& world) {
  const bool any = std::any_of(world.bodies.begin(), world.bodies.end(),
                               [](const BodySpec& body) { return isShapedBody(body); });
  return any && (world.effects.spin || !world.effects.friction);
}

ShapedRoom shapedRoomOf(const World& world) {
  ShapedRoom room;
  room.principal.resize(world.bodies.size());
  room.tracks.resize(world.bodies.size());
  const bool balls_too = ballsMoveAsShaped(world);
  for (std::size_t body = 0; body < world.bodies.size(); ++body) {
    const BodySpec& spec = world.bodies[body];
    if (!isShapedBody(spec) && !(balls_too && std::isfinite(spec.mass))) continue;
    auto principal = principalBody(world.bodies[body], "body");
    if (principal) room.principal[body] = std::move(principal.value());
  }
  return room;
}

bool restartShaped(const World& world, ShapedRoom& room, const BodyStateSample& state) {
  std::optional<ShapedTrack>& track = room.tracks[state.body];
  auto started = ShapedTrack::start(*room.principal[state.body], placedObstacles(world),
                                    shapedScene(world, state.body), state, room.revision);
  if (!started) return false;  // the track kept as it was
  if (track) {
    started.value().last_state_time = track->last_state_time;
    started.value().last_impact_time = track->last_impact_time;
    started.value().impact_change = track->impact_change;
  }
  track = std::move(started.value());
  return true;
}

namespace {

/// A known flying track started before the room's latest revision (an obstacle placed, the
/// coefficients tuned) starts again from where it is (its motion since then, among the obstacles
/// and with the coefficients as they are now).
void followRevisions(const World& world, ShapedRoom& room, double from) {
  for (std::size_t body = 0; body < room.tracks.size(); ++body) {
    std::optional<ShapedTrack>& track = room.tracks[body];
    if (!track || track->revision() == room.revision || track->mode() == ShapedTrack::Mode::kHeld) {
      continue;
    }
    if (track->mode() == ShapedTrack::Mode::kLasting) {
      // Its lasting motion goes on; the other obstacles it watches are as placed now.
      track->placeObstacles(placedObstacles(world), from, room.revision);
      continue;
    }
    const double since = std::max(track->since(), from);
    BodyStateSample state = track->stateAt(since);
    state.body = body;
    const double last_state = track->last_state_time;
    const Eigen::Quaterniond orientation = track->last_orientation;
    restartShaped(world, room, state);
    if (room.tracks[body]) {
      room.tracks[body]->last_state_time = last_state;
      room.tracks[body]->last_orientation = orientation;
    }
  }
}

/// The shaped states, oldest first, taken as the balls' are (applyStates in monitor.cpp): a state
/// not newer than its body's last one is stale; one older than its track's motion is set aside;
/// one lacking more than half of the velocity change of an impact since the body's previous state
/// is reported as contradicting it (but at the impact's own instant, where the monitor keeps its
/// motion after). Each taken is advanced to `time`.
void takeStates(const World& world, ShapedRoom& room, double time,
                const std::vector<BodyStateSample>& states, std::vector<UnmodelledContact>& held,
                StepReport& report) {
  std::vector<BodyStateSample> ordered;
  for (const BodyStateSample& state : states) {
    if (room.shaped(state.body)) ordered.push_back(state);
  }
  std::stable_sort(ordered.begin(), ordered.end(),
                   [](const BodyStateSample& x, const BodyStateSample& y) {
                     return x.time < y.time || (x.time == y.time && x.body < y.body);
                   });
  for (const BodyStateSample& state : ordered) {
    std::optional<ShapedTrack>& track = room.tracks[state.body];
    const double previous = track ? track->last_state_time : -kInfinity;
    if (state.time <= previous) {
      ++report.stale_states;
      continue;
    }
    if (!checkOrientation(state.orientation, "orientation") ||
        !ShapedTrack::start(*room.principal[state.body], {}, shapedScene(world, state.body), state,
                            0)) {
      ++report.refused_states;  // the node's intake refuses them first, by name
      continue;
    }
    if (track) track->last_state_time = state.time;
    if (track && state.time < track->since()) {
      ++report.states_set_aside;
      continue;
    }
    if (track && track->last_impact_time >= previous && track->last_impact_time <= state.time &&
        track->impact_change != Eigen::Vector3d::Zero()) {
      const Eigen::Vector3d predicted = track->stateAt(state.time).velocity;
      const double change = track->impact_change.norm();
      const double missing = -(state.velocity - predicted).dot(track->impact_change) / change;
      if (missing > 0.5 * change) {
        if (state.time - track->last_impact_time <= kSameInstant) continue;
        report.contradicted.push_back({state.body, track->last_impact_time, state.time, missing});
      }
    }
    if (!restartShaped(world, room, state)) continue;
    room.tracks[state.body]->last_state_time = state.time;
    room.tracks[state.body]->advanceTo(std::max(time, state.time), report.impacts, held);
  }
}

/// The contacts not modelled at `time`: each held track's with its obstacle, each pair the watch
/// of shaped pairs could not resolve, and each shaped body touching a ball or another shaped body
/// (its gap at `time`, overlapping or within the band);
/// those that did not hold at the last step's end are reported, beginning at `time` (a held
/// track's when it was held).
void reportUnmodelled(const World& world, ShapedRoom& room, double time,
                      const std::vector<UnmodelledContact>& held, const BallPositions& balls,
                      StepReport& report) {
  std::set<std::tuple<std::size_t, std::size_t, bool>> now;
  std::vector<UnmodelledContact> found;
  for (std::size_t body = 0; body < room.tracks.size(); ++body) {
    const std::optional<ShapedTrack>& track = room.tracks[body];
    if (!track || track->mode() != ShapedTrack::Mode::kHeld || !track->against()) continue;
    const auto key = std::make_tuple(body, *track->against(), true);
    if (!now.insert(key).second) continue;
    UnmodelledContact contact{body, *track->against(), true, track->since(),
                              "its contact with the obstacle is not modelled yet"};
    for (const UnmodelledContact& h : held) {
      if (h.body == body && h.other == contact.other) contact = h;
    }
    found.push_back(contact);
  }
  // What the watch of shaped pairs could not resolve (a pair found inside each other, an impact
  // the solver refused): reported as it comes.
  for (const UnmodelledContact& h : held) {
    if (h.other_is_obstacle) continue;
    if (now.insert(std::make_tuple(h.body, h.other, false)).second) found.push_back(h);
  }
  for (std::size_t body = 0; body < room.tracks.size(); ++body) {
    if (!room.tracks[body]) continue;
    const auto tumbling = tumblingAt(room, body, time);
    if (!tumbling) continue;
    const double reach = tumbling->reach();
    const Eigen::Vector3d centre = tumbling->positionAt(time);
    for (std::size_t other = 0; other < world.bodies.size(); ++other) {
      if (other == body) continue;
      std::optional<SurfaceGap> gap;
      if (room.shaped(other)) {
        if (other < body || !room.tracks[other]) continue;  // each pair once
        const auto second = tumblingAt(room, other, time);
        if (!second) continue;
        if ((second->positionAt(time) - centre).norm() > reach + second->reach() + 1e-9) continue;
        gap = gapAt(*tumbling, *second, time);
      } else {
        const std::optional<Eigen::Vector3d> at = balls(other);
        if (!at) continue;
        const Eigen::Vector3d ball = *at;
        const double radius = std::max(world.radius[other], 1e-12);
        if ((ball - centre).norm() > reach + radius + 1e-9) continue;
        PlacedShape sphere;
        sphere.shape = Sphere{ball, radius};
        sphere.pose.time = time;
        sphere.pose.transform.translation() = ball;
        gap = gapAt(*tumbling, sphere, time);
      }
      if (!touching(*gap)) continue;
      // A pair of shaped bodies just struck is parting (shaped_pairs.h), not in lasting contact.
      if (room.shaped(other) && room.parting.count({body, other})) continue;
      const auto key = std::make_tuple(body, other, false);
      if (!now.insert(key).second) continue;  // said above, by the watch of shaped pairs
      found.push_back({body, other, false, time,
                       room.shaped(other)
                           ? std::string("two shaped bodies in lasting contact (at rest on each "
                                         "other, pushing) are not modelled yet: both are held "
                                         "where they are until their next states (their impacts "
                                         "are resolved)")
                           : std::string("a shaped body touching a ball is not modelled yet: it "
                                         "is not resolved (no impulse, no force)")});
    }
  }
  for (const UnmodelledContact& contact : found) {
    const auto key = std::make_tuple(contact.body, contact.other, contact.other_is_obstacle);
    if (room.unmodelled_now.count(key) == 0) report.unmodelled.push_back(contact);
  }
  room.unmodelled_now = std::move(now);
}

void finishStep(const World& world, ShapedRoom& room, double time,
                const std::vector<UnmodelledContact>& held, const BallPositions& balls,
                std::size_t ball_impacts, StepReport& report) {
  reportUnmodelled(world, room, time, held, balls, report);
  for (std::size_t body = 0; body < room.tracks.size(); ++body) {
    if (!room.tracks[body]) continue;
    // A flight through air that stalled (held where it got to: AirFlight), said once.
    ShapedTrack& track = *room.tracks[body];
    if (const double stalled = track.stalledAt();
        stalled <= time && stalled != track.stall_reported) {
      track.stall_reported = stalled;
      report.stalled.push_back({body, stalled});
    }
    const std::vector<ContactRecord> contacts = room.tracks[body]->contacts(time);
    report.contacts.insert(report.contacts.end(), contacts.begin(), contacts.end());
  }
  if (report.impacts.size() > ball_impacts) {
    std::stable_sort(report.impacts.begin(), report.impacts.end(),
                     [](const ImpactRecord& x, const ImpactRecord& y) { return x.time < y.time; });
  }
}

}  // namespace

/// Shaped tracks with no state for longer than the body timeout are forgotten.
void forgetStale(const World& world, ShapedRoom& room, double time) {
  for (std::optional<ShapedTrack>& track : room.tracks) {
    if (track && time - track->last_state_time > world.settings.body_timeout) track.reset();
  }
}

void stepShaped(const World& world, ShapedRoom& room, double from, double time,
                const std::vector<BodyStateSample>& states, const BallPositions& balls,
                StepReport& report) {
  const std::size_t ball_impacts = report.impacts.size();
  forgetStale(world, room, time);
  followRevisions(world, room, from);
  std::vector<UnmodelledContact> held;
  advanceShapedTogether(world, room, from, time, report.impacts, held);
  takeStates(world, room, time, states, held, report);
  finishStep(world, room, time, held, balls, ball_impacts, report);
}

void advanceShaped(const World& world, ShapedRoom& room, double from, double time,
                   const std::vector<BodyStateSample>& imposed, const BallPositions& balls,
                   StepReport& report) {
  const std::size_t ball_impacts = report.impacts.size();
  forgetStale(world, room, time);
  followRevisions(world, room, from);
  std::vector<UnmodelledContact> held;
  double now = from;
  for (const BodyStateSample& state : imposed) {
    std::optional<ShapedTrack>& track = room.tracks[state.body];
    if (!room.shaped(state.body) || !track) continue;
    if (state.time > now) {
      advanceShapedTogether(world, room, now, state.time, report.impacts, held);
      now = state.time;
    }
    track->advanceTo(state.time, report.impacts, held);
    // The motion just after an impact, which turns no body at its instant: the orientation the
    // track has there is kept.
    BodyStateSample after = state;
    after.orientation = track->stateAt(state.time).orientation;
    const double last_state = std::max(track->last_state_time, state.time);
    const Eigen::Quaterniond orientation = track->last_orientation;
    if (!restartShaped(world, room, after)) continue;
    room.tracks[state.body]->last_state_time = last_state;
    room.tracks[state.body]->last_orientation = orientation;
    room.tracks[state.body]->last_impact_time = state.time;
    room.tracks[state.body]->impact_change.setZero();
  }
  advanceShapedTogether(world, room, std::max(now, from), time, report.impacts, held);
  finishStep(world, room, time, held, balls, ball_impacts, report);
}

}  // namespace collision_response::core::monitor
