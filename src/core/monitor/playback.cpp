#include "collision_response/core/playback.h"

#include <algorithm>
#include <cmath>
#include <limits>

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

Playback::Playback(const Scene& scene, double contact_tolerance, double start)
    : scene_(scene),
      committed_(scene, playbackSettings(contact_tolerance, scene.detection)),
      committed_time_(start),
      horizon_(start) {
  if (scene_.effects.gravity) gravity_ = scene_.gravity;
  std::vector<BodyStateSample> states;
  for (std::size_t i = 0; i < scene_.bodies.size(); ++i) {
    const BodySpec& body = scene_.bodies[i];
    index_[body.id] = i;
    model_index_.push_back(*committed_.bodyIndex(body.id));
    BodyStateSample state;
    state.body = model_index_.back();
    state.time = start;
    state.position = body.position;
    state.velocity = body.velocity;
    state.angular_velocity = body.angular_velocity;
    states.push_back(state);
    flights_.push_back(
        Flight{start, body.position, body.velocity, false, 0, body.angular_velocity});
  }
  committed_.step(start, states);
}

const ImpactMonitor& Playback::at(double time) const {
  if (view_ && view_time_ == time) return *view_;
  if (time > horizon_) {
    // Asking for a later instant makes what was asked for before final.
    if (horizon_ > committed_time_) {
      std::vector<BodyStateSample> final_part;
      while (!pending_.empty() && pending_.front().time <= horizon_) {
        final_part.push_back(pending_.front());
        pending_.erase(pending_.begin());
      }
      if (view_ && view_time_ == horizon_) {
        // The view was worked out to that instant with the same impacts (any impact applied
        // since would have dropped it): it is what advancing would give again.
        committed_ = std::move(*view_);
        view_.reset();
      } else {
        committed_.advance(horizon_, final_part);
      }
      committed_time_ = horizon_;
    }
    horizon_ = time;
  }
  view_ = committed_;
  std::vector<BodyStateSample> ahead;
  for (const BodyStateSample& state : pending_) {
    if (state.time <= time) ahead.push_back(state);
  }
  view_contacts_.clear();
  if (time > committed_time_) view_contacts_ = view_->advance(time, ahead).contacts;
  view_time_ = time;
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

std::vector<ContactRecord> Playback::contacts(double time) const {
  at(time);
  return view_contacts_;
}

bool Playback::applyImpact(std::size_t body, double time, const Eigen::Vector3d& centre,
                           const Eigen::Vector3d& velocity_after,
                           const Eigen::Vector3d& angular_velocity_after) {
  if (time < committed_time_ || time < flights_[body].start) return false;
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
  if (time == committed_time_) {
    // An impact at the instant the model was committed to (two bodies that touch exactly at a
    // sample, found by the next step): taken at that instant.
    committed_.step(time, {state});
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
    const double radius = scene_.bodies[*body].radius;
    const Eigen::Vector3d centre =
        exact_contact ? Eigen::Vector3d(impact.contact_point + side * radius * impact.normal)
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
