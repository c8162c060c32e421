#include "geometry/motion.h"

namespace collision_response::core {

std::optional<std::size_t> restingPlane(const Eigen::Vector3d& position,
                                        const Eigen::Vector3d& velocity, double radius,
                                        const std::vector<Plane>& planes,
                                        const Eigen::Vector3d& gravity, double contact_tolerance) {
  for (std::size_t i = 0; i < planes.size(); ++i) {
    const Plane& plane = planes[i];
    const double pressing = -gravity.dot(plane.normal);
    if (!(pressing > 0)) continue;
    const double band = touchingBand(radius, contact_tolerance, position, plane.offset);
    const double gap = plane.normal.dot(position) - plane.offset - radius;
    if (std::abs(gap) > band) continue;
    if (std::abs(velocity.dot(plane.normal)) > restSpeed(pressing, band)) continue;
    return i;
  }
  return std::nullopt;
}

}  // namespace collision_response::core
