#include "collision_response/core/playback.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "collision_response/core/body_shape.h"
#include "geometry/motion.h"

namespace collision_response::core {
namespace {

/// Under continuous detection the played motion finds and resolves its own impacts, so that no
/// body is shown inside another before the watcher's impact is heard, or where the replay of the
/// watcher's impacts drifts from the watcher's own motion by its solves' residuals. Under discrete
/// detection the watcher finds impacts as overlaps at its samples: the played bodies must reach
/// them.
MonitorSettings playbackSettings(double contact_tolerance, Detection detection) {
  MonitorSettings settings;
  settings.contact_tolerance = contact_tolerance;
  settings.body_timeout = std::numeric_limits<double>::infinity();
  settings.detect_impacts = detection == Detection::kContinuous;
  return settings;
}

}  // namespace

Playback::Playback(const Scene& scene, double contact_tolerance, double start, double replay_window)
    : scene_(scene), replay_window_(replay_window > 0 ? replay_window : 0.0) {
  if (scene_.effects.gravity) gravity_ = scene_.gravity;
  ImpactMonitor model(scene, playbackSettings(contact_tolerance, scene.detection));
  std::vector<BodyStateSample> states;
  for (std::size_t i = 0; i < scene_.bodies.size(); ++i) {
    const BodySpec& body = scene_.bodies[i];
    index_[body.id] = i;
    model_index_.push_back(*model.bodyIndex(body.id));
    BodyStateSample state;
    state.body = model_index_.back();
    state.time = start;
    state.position = body.position;
    state.velocity = body.velocity;
    state.angular_velocity = body.angular_velocity;
    state.orientation = body.orientation;
    states.push_back(state);
    flights_.push_back(
        Flight{start, body.position, body.velocity, false, 0, body.angular_velocity});
  }
  model.step(start, states);
  played_.push_back(Played{start, std::move(model), {}});
}

std::vector<BodyStateSample> Playback::impactsIn(double from, double to) const {
  std::vector<BodyStateSample> impacts;
  for (const BodyStateSample& state : pending_) {
    if (state.time > from && state.time <= to) impacts.push_back(state);
  }
  return impacts;
}

void Playback::playFromPrevious(std::size_t k) const {
  Played& played = played_[k];
  const Played& before = played_[k - 1];
  played.model = *before.model;
  played.contacts =
      played.model->advance(played.time, impactsIn(before.time, played.time)).contacts;
}

void Playback::replay() const {
  for (std::size_t k = 1; k < played_.size(); ++k) {
    if (!played_[k].model) playFromPrevious(k);
  }
}

const ImpactMonitor& Playback::at(double time) const {
  if (view_ && view_time_ == time) {
    at_contacts_ = &view_contacts_;
    return *view_;
  }
  replay();
  if (time > played_.back().time) {
    played_.push_back(Played{time, std::nullopt, {}});
    playFromPrevious(played_.size() - 1);
    // What is final: the latest instant asked for more than the window before this one (window
    // 0: the one before it). The impacts up to it are in its model.
    std::size_t final_index = 0;
    while (final_index + 2 <= played_.size() - 1 &&
           played_[final_index + 1].time < time - replay_window_) {
      ++final_index;
    }
    played_.erase(played_.begin(), played_.begin() + static_cast<std::ptrdiff_t>(final_index));
    const double final_time = played_.front().time;
    pending_.erase(std::remove_if(pending_.begin(), pending_.end(),
                                  [&](const BodyStateSample& s) { return s.time <= final_time; }),
                   pending_.end());
    at_contacts_ = &played_.back().contacts;
    return *played_.back().model;
  }
  // An instant at or before the last one asked for: the latest played at or before it.
  std::size_t k = played_.size() - 1;
  while (k > 0 && played_[k].time > time) --k;
  if (played_[k].time >= time) {
    at_contacts_ = &played_[k].contacts;
    return *played_[k].model;
  }
  view_ = *played_[k].model;
  view_contacts_ = view_->advance(time, impactsIn(played_[k].time, time)).contacts;
  view_time_ = time;
  at_contacts_ = &view_contacts_;
  return *view_;
}

Eigen::Vector3d Playback::position(std::size_t body, double time) const {
  return at(time).predictedState(model_index_[body], time)->first;
}

Eigen::Vector3d Playback::velocity(std::size_t body, double time) const {
  return at(time).predictedState(model_index_[body], time)->second;
}

Eigen::Vector3d Playback::angularVelocity(std::size_t body, double time) const {
  return at(time).predictedAngularVelocity(model_index_[body], time);
}

Eigen::Quaterniond Playback::orientation(std::size_t body, double time) const {
  return at(time).predictedOrientation(model_index_[body], time);
}

std::vector<ContactRecord> Playback::contacts(double time) const {
  at(time);
  return *at_contacts_;
}

bool Playback::applyImpact(std::size_t body, double time, const Eigen::Vector3d& centre,
                           const Eigen::Vector3d& velocity_after,
                           const Eigen::Vector3d& angular_velocity_after) {
  if (time < played_.front().time || time < flights_[body].start) return false;
  BodyStateSample state;
  state.body = model_index_[body];
  state.time = time;
  state.position = centre;
  state.velocity = velocity_after;
  state.angular_velocity = angular_velocity_after;
  view_.reset();
  flights_[body] = Flight{time,
                          centre,
                          velocity_after,
                          false,
                          flights_[body].impacts_before + 1,
                          angular_velocity_after};
  // Every instant asked for at or after the impact is played again from the one before it.
  for (std::size_t k = 1; k < played_.size(); ++k) {
    if (played_[k].time >= time) played_[k].model.reset();
  }
  if (time == played_.front().time) {
    // An impact at the instant that is final (two bodies that touch exactly at a sample, found
    // by the next step): taken at that instant.
    played_.front().model->step(time, {state});
    return true;
  }
  const auto later = std::upper_bound(
      pending_.begin(), pending_.end(), state,
      [](const BodyStateSample& x, const BodyStateSample& y) { return x.time < y.time; });
  pending_.insert(later, state);
  return true;
}

bool Playback::applyImpact(const ImpactMonitor& monitor, const ImpactRecord& impact,
                           bool exact_contact) {
  const auto apply = [&](std::size_t monitor_body, double side, const Eigen::Vector3d& after,
                         const Eigen::Vector3d& angular_after) {
    const auto body = bodyIndex(monitor.body(monitor_body).id);
    if (!body) return true;  // not one of this scene's bodies: nothing to move
    // A ball's centre from the contact (its radius along the normal); a body the monitor moves
    // as a rigid body (a shaped body, or a ball among shaped bodies) where its motion has it at
    // the instant (a shaped body's centre is no radius from the contact).
    const double radius = scene_.bodies[*body].radius;
    const bool from_contact = exact_contact && !monitor.shaped(monitor_body);
    const Eigen::Vector3d centre =
        from_contact ? Eigen::Vector3d(impact.contact_point + side * radius * impact.normal)
                     : position(*body, impact.time);
    return applyImpact(*body, impact.time, centre, after, angular_after);
  };
  bool applied =
      apply(impact.body_a, -1.0, impact.velocity_a_after, impact.angular_velocity_a_after);
  if (!impact.other_is_obstacle) {
    applied = apply(impact.other, +1.0, impact.velocity_b_after, impact.angular_velocity_b_after) &&
              applied;
  }
  return applied;
}

std::vector<std::size_t> Playback::applyImpacts(const ImpactMonitor& monitor,
                                                const std::vector<ImpactRecord>& impacts,
                                                bool exact_contact) {
  std::vector<std::size_t> refused;
  if (exact_contact) {
    for (std::size_t k = 0; k < impacts.size(); ++k) {
      if (!applyImpact(monitor, impacts[k], true)) refused.push_back(k);
    }
    return refused;
  }
  struct Placed {
    std::size_t record, body;
    double time;
    Eigen::Vector3d centre, velocity, angular_velocity;
  };
  std::vector<Placed> placed;
  for (std::size_t k = 0; k < impacts.size(); ++k) {
    const ImpactRecord& impact = impacts[k];
    const auto place = [&](std::size_t monitor_body, const Eigen::Vector3d& after,
                           const Eigen::Vector3d& angular_after) {
      const auto body = bodyIndex(monitor.body(monitor_body).id);
      if (body) {
        placed.push_back(
            {k, *body, impact.time, position(*body, impact.time), after, angular_after});
      }
    };
    place(impact.body_a, impact.velocity_a_after, impact.angular_velocity_a_after);
    if (!impact.other_is_obstacle) {
      place(impact.other, impact.velocity_b_after, impact.angular_velocity_b_after);
    }
  }
  for (const Placed& p : placed) {
    const bool applied = applyImpact(p.body, p.time, p.centre, p.velocity, p.angular_velocity);
    if (!applied && (refused.empty() || refused.back() != p.record)) refused.push_back(p.record);
  }
  return refused;
}

std::vector<Apex> Playback::apexesUntil(double time) {
  std::vector<Apex> apexes;
  const double g = gravity_.norm();
  // The apex of a parabola: through air (drag, Magnus) a flight's is not (and e from its
  // heights would not be the coefficient of restitution), so none is reported.
  if (!(g > 0) || scene_.effects.air()) return apexes;
  const Eigen::Vector3d up = -gravity_ / g;
  for (std::size_t i = 0; i < flights_.size(); ++i) {
    Flight& flight = flights_[i];
    const double rising = flight.velocity.dot(up);
    if (flight.apex_reported || !(rising > 0)) continue;
    const double apex_time = flight.start + rising / g;
    if (apex_time > time) continue;
    flight.apex_reported = true;
    const double dt = apex_time - flight.start;
    apexes.push_back(Apex{i, apex_time,
                          positionAfter(flight.position, flight.velocity, gravity_, dt),
                          velocityAfter(flight.velocity, gravity_, dt), flight.impacts_before,
                          flight.angular_velocity});
  }
  return apexes;
}

std::optional<std::size_t> Playback::bodyIndex(const std::string& id) const {
  const auto found = index_.find(id);
  if (found == index_.end()) return std::nullopt;
  return found->second;
}

}  // namespace collision_response::core
