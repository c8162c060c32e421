#include "collision_response/core/monitor.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "collision_response/core/body.h"
#include "collision_response/core/friction.h"
#include "collision_response/core/impact.h"
#include "collision_response/core/time_of_impact.h"

namespace collision_response::core {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
/// A pair approaches when its normal relative velocity is below -64 ulps of the speeds: what a
/// resolved impact leaves behind by rounding (e = 0 gives d' = 0 only up to a few ulps) must not
/// count as a new approach.
constexpr double kApproachTolerance = 64 * kEps;

}  // namespace

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
  if (effects_.gravity) gravity_ = scene.gravity;
  if (effects_.friction) {
    friction_step_ = effects_.spin ? &applyFrictionToCluster<true> : &applyFrictionToCluster<false>;
  }

  std::vector<std::string> material_names;
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
    inverse_inertia_.push_back(
        effects_.spin ? inverseInertia(inverse_mass_.back(), bodies_[i].radius, bodies_[i].inertia)
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
  const std::size_t count = material_names.size();
  restitution_.assign(count, std::vector<double>(count, NAN));
  friction_.assign(count, std::vector<double>(count, NAN));
  for (std::size_t i = 0; i < count; ++i) {
    for (std::size_t j = 0; j < count; ++j) {
      if (const auto value = scene.materials.restitution(material_names[i], material_names[j])) {
        restitution_[i][j] = *value;
      }
      if (const auto value = scene.materials.friction(material_names[i], material_names[j])) {
        friction_[i][j] = *value;
      }
    }
  }

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
  if (effects_.gravity) {
    return std::make_pair(positionAt<UnderGravity>(body, time),
                          velocityAt<UnderGravity>(body, time));
  }
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

Eigen::Vector3d ImpactMonitor::angularVelocityOf(std::size_t participant) const {
  return isObstacle(participant)
             ? obstacle_tracks_[participant - bodies_.size()].pose.angular_velocity
             : tracks_[participant].angular_velocity;
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
  if (!(distance > 0)) return result;  // coincident centres: no line of impact
  const double contact_distance = radius_[a] + radius_[other];
  result.normal = separation / distance;
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

std::vector<ImpactMonitor::Pair> ImpactMonitor::candidatePairs() const {
  std::vector<Pair> pairs;
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
  return pairs;
}

template <class Motion>
bool ImpactMonitor::resolveInstant(double time, const std::vector<Pair>& touching,
                                   StepReport& report) {
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

    // Clusters: contacts that share a movable body are solved together.
    const std::size_t participants = bodies_.size() + obstacles_.size();
    std::vector<std::size_t> parent(participants);
    std::iota(parent.begin(), parent.end(), 0);
    const auto find = [&parent](std::size_t x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    for (const std::size_t k : striking) {
      const auto [a, other] = contacts_at_instant[k].first;
      if (inverseMassOf(a) > 0 && inverseMassOf(other) > 0) parent[find(a)] = find(other);
    }
    const auto cluster_of = [&](std::size_t k) {
      const auto [a, other] = contacts_at_instant[k].first;
      return inverseMassOf(a) > 0 ? find(a) : find(other);
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
        frictions.push_back(
            FrictionContact{radius_[pair.first], radius_[pair.second],
                            friction_[material_[pair.first]][material_[pair.second]], 0.0});
      }
      std::vector<ClusterBody> cluster_bodies;
      for (const std::size_t participant : members) {
        ClusterBody body;
        body.inverse_mass = inverseMassOf(participant);
        body.velocity = velocityAt<Motion>(participant, time);
        body.angular_velocity = angularVelocityOf(participant);
        body.inverse_inertia = isObstacle(participant) ? 0.0 : inverse_inertia_[participant];
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

void ImpactMonitor::applyStates(const std::vector<BodyStateSample>& states, StepReport& report) {
  std::vector<BodyStateSample> ordered = states;
  std::stable_sort(ordered.begin(), ordered.end(), [](const auto& x, const auto& y) {
    return x.time < y.time || (x.time == y.time && x.body < y.body);
  });
  for (const BodyStateSample& state : ordered) {
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
    updateResting(state.body);
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
        for (const Pair& pair : candidatePairs()) {
          const Geometry g = effects_.gravity ? geometry<UnderGravity>(pair, time)
                                              : geometry<StraightLine>(pair, time);
          if (g.valid && g.gap < -g.tolerance) overlapping_.insert(pair);
        }
      }
    }
    return report;
  }
  forgetStaleBodies(time);
  // The motion model is chosen here, once per step, not in the per-pair loops.
  if (detection_ == Detection::kContinuous) {
    return effects_.gravity ? stepContinuous<UnderGravity>(time, states)
                            : stepContinuous<StraightLine>(time, states);
  }
  return effects_.gravity ? stepDiscrete<UnderGravity>(time, states)
                          : stepDiscrete<StraightLine>(time, states);
}

template <class Motion>
StepReport ImpactMonitor::stepContinuous(double time, const std::vector<BodyStateSample>& states) {
  StepReport report;
  const std::vector<Pair> pairs = candidatePairs();
  double instant = now_;
  std::vector<Pair> struck;  // the pairs whose first contact is `instant`
  for (int count = 0;; ++count) {
    if (count >= settings_.max_instants_per_step) {
      report.truncated = true;
      break;
    }
    std::vector<Pair> touching = struck;
    for (const Pair& pair : pairs) {
      const Geometry g = geometry<Motion>(pair, instant);
      if (g.valid && std::abs(g.gap) <= g.tolerance &&
          std::find(struck.begin(), struck.end(), pair) == struck.end()) {
        touching.push_back(pair);
      }
    }
    if (!resolveInstant<Motion>(instant, touching, report)) {
      report.truncated = true;
      break;
    }
    // The next first contact. A touching pair that does not approach (it was just resolved, or
    // slides) never comes back in a straight line; under gravity it may (a ball that bounced
    // falls back), so its next entry is looked for, except on the plane it rests on.
    double next = INFINITY;
    struck.clear();
    for (const Pair& pair : pairs) {
      if (resting(pair)) continue;
      const Geometry g = geometry<Motion>(pair, instant);
      if (!g.valid) continue;
      const bool touching_now = std::abs(g.gap) <= g.tolerance;
      if (!Motion::kAccelerates && touching_now) continue;
      const auto delay = timeOfImpact<Motion>(pair, instant, time - instant);
      if (!delay) continue;
      const double when = std::min(instant + *delay, time);
      // No progress on a pair already handled at this instant would loop for ever.
      if (touching_now && !(when > instant)) continue;
      if (when < next) {
        next = when;
        struck.assign(1, pair);
      } else if (when == next) {
        struck.push_back(pair);
      }
    }
    if (struck.empty()) break;
    instant = next;
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
  const std::vector<Pair> pairs = candidatePairs();
  std::vector<Pair> touching;
  for (const Pair& pair : pairs) {
    const Geometry g = geometry<Motion>(pair, time);
    if (g.valid && g.gap <= g.tolerance && overlapping_.count(pair) == 0) touching.push_back(pair);
  }
  if (!resolveInstant<Motion>(time, touching, report)) report.truncated = true;
  overlapping_.clear();
  for (const Pair& pair : pairs) {
    const Geometry g = geometry<Motion>(pair, time);
    if (g.valid && g.gap < -g.tolerance) overlapping_.insert(pair);
  }
  return report;
}

}  // namespace collision_response::core
