#include "contact/shaped_lasting.h"

namespace collision_response::core {

Eigen::Vector3d LastingMotion::centreAt(double t) const {
  const double s = t - start;
  return centre0 + velocity0 * s + 0.5 * acceleration * s * s;
}

Eigen::Vector3d LastingMotion::velocityAt(double t) const {
  return velocity0 + acceleration * (t - start);
}

Eigen::Vector3d LastingMotion::angularVelocityAt(double t) const {
  return angular_velocity0 + angular_acceleration * (t - start);
}

Eigen::Quaterniond LastingMotion::orientationAt(double t) const {
  const double s = t - start;
  const Eigen::Vector3d turn = angular_velocity0 * s + 0.5 * angular_acceleration * s * s;
  const double angle = turn.norm();
  if (!(angle > 0)) return orientation0;
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, turn / angle)) * orientation0;
}

std::vector<SupportForce> LastingMotion::forcesAt(double) const { return forces; }

Expected<LastingMotion> lastingOnFace(const LastingBody&, const FlatFace&) {
  return Error{"contact", "not yet: a shaped body's lasting contact is not modelled"};
}

std::optional<double> flatBouncesEnd(const LastingBody&, const FlatFace&, double) {
  return std::nullopt;
}

}  // namespace collision_response::core
