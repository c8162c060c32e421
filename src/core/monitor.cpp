#include "collision_response/core/monitor.h"

#include <algorithm>
#include <cmath>

#include "collision_response/core/body.h"
#include "collision_response/core/friction.h"

namespace collision_response::core {

// The motion-dependent members live in monitor_straight.cpp and monitor_gravity.cpp (see
// monitor_motion.h); here they are only called.
extern template Eigen::Vector3d ImpactMonitor::positionAt<ImpactMonitor::StraightLine>(
    std::size_t, double) const;
extern template Eigen::Vector3d ImpactMonitor::velocityAt<ImpactMonitor::StraightLine>(
    std::size_t, double) const;
extern template ImpactMonitor::Geometry ImpactMonitor::geometry<ImpactMonitor::StraightLine>(
    const Pair&, double) const;
extern template StepReport ImpactMonitor::stepContinuous<ImpactMonitor::StraightLine>(
    double, const std::vector<BodyStateSample>&);
extern template StepReport ImpactMonitor::stepDiscrete<ImpactMonitor::StraightLine>(
    double, const std::vector<BodyStateSample>&);
#ifndef COLLISION_RESPONSE_NO_EFFECTS
extern template Eigen::Vector3d ImpactMonitor::positionAt<ImpactMonitor::UnderGravity>(
    std::size_t, double) const;
extern template Eigen::Vector3d ImpactMonitor::velocityAt<ImpactMonitor::UnderGravity>(
    std::size_t, double) const;
extern template ImpactMonitor::Geometry ImpactMonitor::geometry<ImpactMonitor::UnderGravity>(
    const Pair&, double) const;
extern template StepReport ImpactMonitor::stepContinuous<ImpactMonitor::UnderGravity>(
    double, const std::vector<BodyStateSample>&);
extern template StepReport ImpactMonitor::stepDiscrete<ImpactMonitor::UnderGravity>(
    double, const std::vector<BodyStateSample>&);
#endif

ImpactMonitor::ImpactMonitor(const Scene& scene, const MonitorSettings& settings)
    : settings_(settings),
      detection_(scene.detection),
      restitution_threshold_(scene.restitution_threshold),
      bodies_(scene.bodies),
      obstacles_(scene.obstacles),
      effects_(scene.effects) {
  const auto by_id = [](const auto& x, const auto& y) { return x.id < y.id; };
  std::sort(bodies_.begin(), bodies_.end(), by_id);
  std::sort(obstacles_.begin(), obstacles_.end(), by_id);
#ifdef COLLISION_RESPONSE_NO_EFFECTS
  // The benchmark's reference build: the effects compiled out, to show what "off" costs.
  effects_ = Effects{};
#endif
  if (effects_.gravity) gravity_ = scene.gravity;
  if (effects_.friction) {
#ifndef COLLISION_RESPONSE_NO_EFFECTS
    friction_step_ = effects_.spin ? &applyFrictionToCluster<true> : &applyFrictionToCluster<false>;
#endif
  }

  std::vector<std::string>& material_names = material_names_;
  const auto material_index = [&material_names](const std::string& name) {
    const auto found = std::find(material_names.begin(), material_names.end(), name);
    if (found != material_names.end())
      return static_cast<std::size_t>(found - material_names.begin());
    material_names.push_back(name);
    return material_names.size() - 1;
  };
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    body_index_[bodies_[i].id] = i;
    radius_.push_back(bodies_[i].radius);
    inverse_mass_.push_back(inverseMass(bodies_[i].mass));
    spin_factor_.push_back(
        effects_.spin ? spinFactor(inverse_mass_.back(), bodies_[i].radius, bodies_[i].inertia)
                      : 0.0);
    material_.push_back(material_index(bodies_[i].material));
  }
  for (const ObstacleSpec& obstacle : obstacles_) {
    radius_.push_back(obstacle.shape == ObstacleShape::kSphere ? obstacle.radius : 0.0);
    material_.push_back(material_index(obstacle.material));
  }
  // The pair coefficients, once: impacts look them up by index. Pairs that cannot meet (two
  // obstacles) or have no coefficient (validateScene refuses scenes where such a pair can meet)
  // hold NaN.
  computePairCoefficients(scene.materials);

  tracks_.resize(bodies_.size());
  obstacle_tracks_.resize(obstacles_.size());
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    const ObstacleSpec& obstacle = obstacles_[i];
    if (!obstacle.frame.empty()) continue;  // placed by setObstaclePose from tf
    ObstaclePose pose;
    pose.position = obstacle.position;
    pose.normal = obstacle.normal.normalized();
    pose.offset = obstacle.offset;
    obstacle_tracks_[i] = ObstacleTrack{true, pose};
    if (obstacle.shape == ObstacleShape::kPlane) {
      fixed_planes_.push_back(Plane{pose.normal, pose.offset});
      fixed_plane_obstacle_.push_back(i);
    }
  }
}

void ImpactMonitor::computePairCoefficients(const MaterialTable& materials) {
  const std::size_t count = material_names_.size();
  restitution_.assign(count, std::vector<double>(count, NAN));
  friction_.assign(count, std::vector<double>(count, NAN));
  for (std::size_t i = 0; i < count; ++i) {
    for (std::size_t j = 0; j < count; ++j) {
      if (const auto value = materials.restitution(material_names_[i], material_names_[j])) {
        restitution_[i][j] = *value;
      }
      if (const auto value = materials.friction(material_names_[i], material_names_[j])) {
        friction_[i][j] = *value;
      }
    }
  }
}

void ImpactMonitor::tune(Detection detection, double restitution_threshold,
                         const MaterialTable& materials) {
  if (detection != detection_) overlapping_.clear();
  detection_ = detection;
  restitution_threshold_ = restitution_threshold;
  computePairCoefficients(materials);
}

std::optional<ObstaclePose> ImpactMonitor::obstaclePose(std::size_t obstacle) const {
  if (!obstacle_tracks_[obstacle].known) return std::nullopt;
  return obstacle_tracks_[obstacle].pose;
}

std::optional<std::size_t> ImpactMonitor::bodyIndex(const std::string& id) const {
  const auto found = body_index_.find(id);
  if (found == body_index_.end()) return std::nullopt;
  return found->second;
}

void ImpactMonitor::setObstaclePose(std::size_t obstacle, const ObstaclePose& pose) {
  obstacle_tracks_[obstacle] = ObstacleTrack{true, pose};
}

void ImpactMonitor::reset() {
  for (Track& track : tracks_) track = Track{};
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    if (!obstacles_[i].frame.empty()) obstacle_tracks_[i] = ObstacleTrack{};
  }
  overlapping_.clear();
  started_ = false;
  now_ = 0.0;
}

std::size_t ImpactMonitor::trackedBodies() const {
  return static_cast<std::size_t>(
      std::count_if(tracks_.begin(), tracks_.end(), [](const Track& t) { return t.known; }));
}

std::optional<std::size_t> ImpactMonitor::restingOn(std::size_t body) const {
  if (!tracks_[body].known || tracks_[body].resting_on < 0) return std::nullopt;
  return static_cast<std::size_t>(tracks_[body].resting_on);
}

std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> ImpactMonitor::predictedState(
    std::size_t body, double time) const {
  if (!tracks_[body].known) return std::nullopt;
#ifndef COLLISION_RESPONSE_NO_EFFECTS
  if (effects_.gravity) {
    return std::make_pair(positionAt<UnderGravity>(body, time),
                          velocityAt<UnderGravity>(body, time));
  }
#endif
  return std::make_pair(positionAt<StraightLine>(body, time), velocityAt<StraightLine>(body, time));
}

bool ImpactMonitor::isPlane(std::size_t participant) const {
  return isObstacle(participant) &&
         obstacles_[participant - bodies_.size()].shape == ObstacleShape::kPlane;
}

bool ImpactMonitor::known(std::size_t participant) const {
  return isObstacle(participant) ? obstacle_tracks_[participant - bodies_.size()].known
                                 : tracks_[participant].known;
}

double ImpactMonitor::inverseMassOf(std::size_t participant) const {
  return isObstacle(participant) ? 0.0 : inverse_mass_[participant];
}

Eigen::Vector3d ImpactMonitor::angularVelocityOf(std::size_t participant) const {
  return isObstacle(participant)
             ? obstacle_tracks_[participant - bodies_.size()].pose.angular_velocity
             : tracks_[participant].angular_velocity;
}

double ImpactMonitor::restitutionOf(const Pair& pair) const {
  return restitution_[material_[pair.first]][material_[pair.second]];
}

bool ImpactMonitor::resting(const Pair& pair) const {
  return isObstacle(pair.second) &&
         tracks_[pair.first].resting_on == static_cast<int>(pair.second - bodies_.size());
}

void ImpactMonitor::updateResting(std::size_t body) {
  Track& track = tracks_[body];
  track.resting_on = -1;
  track.acceleration = inverse_mass_[body] > 0 ? gravity_ : Eigen::Vector3d::Zero();
  if (!effects_.gravity || inverse_mass_[body] == 0.0) return;
  const auto plane = restingPlane(track.position, track.velocity, radius_[body], fixed_planes_,
                                  gravity_, settings_.contact_tolerance);
  if (!plane) return;
  const Eigen::Vector3d& normal = fixed_planes_[*plane].normal;
  track.resting_on = static_cast<int>(fixed_plane_obstacle_[*plane]);
  track.velocity -= track.velocity.dot(normal) * normal;  // along the plane
  track.acceleration = restingAcceleration(gravity_, normal);
}

void ImpactMonitor::candidatePairs(std::vector<Pair>& pairs) const {
  pairs.clear();
  for (std::size_t a = 0; a < bodies_.size(); ++a) {
    if (!tracks_[a].known) continue;
    for (std::size_t b = a + 1; b < bodies_.size(); ++b) {
      if (!tracks_[b].known || inverse_mass_[a] + inverse_mass_[b] == 0.0) continue;
      pairs.emplace_back(a, b);
    }
    if (inverse_mass_[a] == 0.0) continue;
    for (std::size_t o = 0; o < obstacles_.size(); ++o) {
      if (obstacle_tracks_[o].known) pairs.emplace_back(a, bodies_.size() + o);
    }
  }
}

void ImpactMonitor::applyStates(const std::vector<BodyStateSample>& states, StepReport& report) {
  const auto earlier = [](const BodyStateSample& x, const BodyStateSample& y) {
    return x.time < y.time || (x.time == y.time && x.body < y.body);
  };
  // Sources usually send their bodies in one order, and the states of one array share a stamp:
  // the copy and sort are paid only when the states are not in order already.
  const std::vector<BodyStateSample>* ordered = &states;
  std::vector<BodyStateSample> sorted;
  if (!std::is_sorted(states.begin(), states.end(), earlier)) {
    sorted = states;
    std::stable_sort(sorted.begin(), sorted.end(), earlier);
    ordered = &sorted;
  }
  for (const BodyStateSample& state : *ordered) {
    Track& track = tracks_[state.body];
    if (state.time <= track.last_state_time) {
      ++report.stale_states;
      continue;
    }
    const double previous_state_time = track.last_state_time;
    track.last_state_time = state.time;
    const bool impact_since_previous_state =
        track.last_impact_time > previous_state_time && track.last_impact_time <= state.time;
    if (track.known && (state.time < track.time || impact_since_previous_state)) continue;
    track.known = true;
    track.time = state.time;
    track.position = state.position;
    track.velocity = state.velocity;
    track.angular_velocity = state.angular_velocity;
    if (effects_.gravity) updateResting(state.body);
  }
}

void ImpactMonitor::forgetStaleBodies(double time) {
  for (Track& track : tracks_) {
    if (track.known && time - track.last_state_time > settings_.body_timeout) track.known = false;
  }
}

StepReport ImpactMonitor::step(double time, const std::vector<BodyStateSample>& states) {
  if (!started_ || time <= now_) {
    StepReport report;
    applyStates(states, report);
    if (!started_) {
      started_ = true;
      now_ = time;
      if (detection_ == Detection::kDiscrete) {
        candidatePairs(scratch_.pairs);
        for (const Pair& pair : scratch_.pairs) {
#ifndef COLLISION_RESPONSE_NO_EFFECTS
          const Geometry g = effects_.gravity ? geometry<UnderGravity>(pair, time)
                                              : geometry<StraightLine>(pair, time);
#else
          const Geometry g = geometry<StraightLine>(pair, time);
#endif
          if (g.valid && g.gap < -g.tolerance) overlapping_.insert(pair);
        }
      }
    }
    return report;
  }
  forgetStaleBodies(time);
  // The motion model is chosen here, once per step, not in the per-pair loops.
#ifdef COLLISION_RESPONSE_NO_EFFECTS
  return detection_ == Detection::kContinuous ? stepContinuous<StraightLine>(time, states)
                                              : stepDiscrete<StraightLine>(time, states);
#else
  if (detection_ == Detection::kContinuous) {
    return effects_.gravity ? stepContinuous<UnderGravity>(time, states)
                            : stepContinuous<StraightLine>(time, states);
  }
  return effects_.gravity ? stepDiscrete<UnderGravity>(time, states)
                          : stepDiscrete<StraightLine>(time, states);
#endif
}

}  // namespace collision_response::core
