#include "collision_response/core/playback.h"

#include <cmath>

namespace collision_response::core {

Playback::Playback(const Scene& scene, double contact_tolerance, double start)
    : scene_(scene), contact_tolerance_(contact_tolerance) {
  if (scene_.effects.gravity) gravity_ = scene_.gravity;
  for (const ObstacleSpec& obstacle : scene_.obstacles) {
    if (obstacle.shape == ObstacleShape::kPlane && obstacle.frame.empty()) {
      fixed_planes_.push_back(Plane{obstacle.normal.normalized(), obstacle.offset});
    }
  }
  for (std::size_t i = 0; i < scene_.bodies.size(); ++i) {
    index_[scene_.bodies[i].id] = i;
    segments_.push_back(
        makeSegment(i, start, scene_.bodies[i].position, scene_.bodies[i].velocity, 0));
  }
}

Playback::Segment Playback::makeSegment(std::size_t body, double start,
                                        const Eigen::Vector3d& position,
                                        const Eigen::Vector3d& velocity, int impacts_before) const {
  Segment segment{start, position, velocity, Eigen::Vector3d::Zero(), false, impacts_before};
  const BodySpec& spec = scene_.bodies[body];
  if (std::isinf(spec.mass) || gravity_ == Eigen::Vector3d::Zero()) return segment;
  segment.acceleration = gravity_;
  const auto plane =
      restingPlane(position, velocity, spec.radius, fixed_planes_, gravity_, contact_tolerance_);
  if (plane) {
    const Eigen::Vector3d& normal = fixed_planes_[*plane].normal;
    segment.velocity -= segment.velocity.dot(normal) * normal;
    segment.acceleration = restingAcceleration(gravity_, normal);
    segment.apex_reported = true;  // a slide has no apex
  }
  return segment;
}

Eigen::Vector3d Playback::position(std::size_t body, double time) const {
  const Segment& s = segments_[body];
  return positionAfter(s.position, s.velocity, s.acceleration, time - s.start);
}

Eigen::Vector3d Playback::velocity(std::size_t body, double time) const {
  const Segment& s = segments_[body];
  return velocityAfter(s.velocity, s.acceleration, time - s.start);
}

bool Playback::applyImpact(std::size_t body, double time, const Eigen::Vector3d& centre,
                           const Eigen::Vector3d& velocity_after) {
  Segment& segment = segments_[body];
  if (time < segment.start) return false;
  segment = makeSegment(body, time, centre, velocity_after, segment.impacts_before + 1);
  return true;
}

void Playback::applyImpact(const ImpactMonitor& monitor, const ImpactRecord& impact,
                           bool exact_contact) {
  const auto apply = [&](std::size_t monitor_body, double side, const Eigen::Vector3d& after) {
    const auto body = bodyIndex(monitor.body(monitor_body).id);
    if (!body) return;
    const double radius = scene_.bodies[*body].radius;
    const Eigen::Vector3d centre =
        exact_contact ? Eigen::Vector3d(impact.contact_point + side * radius * impact.normal)
                      : position(*body, impact.time);
    applyImpact(*body, impact.time, centre, after);
  };
  apply(impact.body_a, -1.0, impact.velocity_a_after);
  if (!impact.other_is_obstacle) apply(impact.other, +1.0, impact.velocity_b_after);
}

std::vector<Apex> Playback::apexesUntil(double time) {
  std::vector<Apex> apexes;
  const double g = gravity_.norm();
  if (!(g > 0)) return apexes;
  const Eigen::Vector3d up = -gravity_ / g;
  for (std::size_t i = 0; i < segments_.size(); ++i) {
    Segment& segment = segments_[i];
    const double rising = segment.velocity.dot(up);
    if (segment.apex_reported || !(rising > 0)) continue;
    const double apex_time = segment.start + rising / g;
    if (apex_time > time) continue;
    segment.apex_reported = true;
    apexes.push_back(
        Apex{i, apex_time, position(i, apex_time), velocity(i, apex_time), segment.impacts_before});
  }
  return apexes;
}

std::optional<std::size_t> Playback::bodyIndex(const std::string& id) const {
  const auto found = index_.find(id);
  if (found == index_.end()) return std::nullopt;
  return found->second;
}

}  // namespace collision_response::core
