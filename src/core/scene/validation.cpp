#include "collision_response/core/validation.h"

#include <array>
#include <charconv>
#include <cmath>
#include <limits>

namespace collision_response::core {

std::string formatNumber(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return std::string(buffer.data(), result.ptr);
}

std::string formatVector(const Eigen::Vector3d& value) {
  return "[" + formatNumber(value.x()) + ", " + formatNumber(value.y()) + ", " +
         formatNumber(value.z()) + "]";
}

Status checkFinite(double value, const std::string& field) {
  if (!std::isfinite(value))
    return Error{field, "must be a finite number, got " + formatNumber(value)};
  return Ok{};
}

Status checkFinite(const Eigen::Vector3d& value, const std::string& field) {
  static const std::array<const char*, 3> kAxes = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    if (!std::isfinite(value[axis])) {
      return Error{field + "." + kAxes[axis],
                   "must be a finite number, got " + formatNumber(value[axis])};
    }
  }
  return Ok{};
}

Status checkRestitution(double restitution, const std::string& field) {
  if (!(restitution >= 0.0 && restitution <= 1.0)) {
    return Error{field,
                 "coefficient of restitution must be in [0, 1] (0 plastic, 1 elastic), got " +
                     formatNumber(restitution)};
  }
  return Ok{};
}

Status checkMass(double mass, const std::string& field) {
  if (std::isnan(mass) || !(mass > 0.0)) {
    return Error{field, "must be > 0 kg, or .inf for an immovable body, got " + formatNumber(mass)};
  }
  if (!std::isfinite(inverseMass(mass))) {
    return Error{field, "is too small: 1/mass overflows (got " + formatNumber(mass) + " kg)"};
  }
  return Ok{};
}

Status checkRadius(double radius, const std::string& field) {
  if (!std::isfinite(radius) || radius < 0.0) {
    return Error{field, "must be a finite number >= 0 m, got " + formatNumber(radius)};
  }
  return Ok{};
}

Status checkName(const std::string& name, const std::string& field) {
  if (name.empty()) return Error{field, "must not be empty"};
  for (const char c : name) {
    if (static_cast<unsigned char>(c) <= ' ' || c == 0x7f) {
      return Error{field, "'" + name + "' contains whitespace or a control character"};
    }
  }
  return Ok{};
}

Status checkFrameId(const std::string& frame, const std::string& field) {
  if (!frame.empty() && frame.front() == '/') {
    const std::size_t name = frame.find_first_not_of('/');
    return Error{field, "'" + frame + "' starts with '/': tf2 frame ids have none (use '" +
                            (name == std::string::npos ? std::string() : frame.substr(name)) +
                            "')"};
  }
  return checkName(frame, field);
}

Status checkFriction(double friction, const std::string& field) {
  if (!std::isfinite(friction) || friction < 0.0) {
    return Error{field,
                 "Coulomb coefficient must be a finite number >= 0, got " + formatNumber(friction)};
  }
  return Ok{};
}

Status checkRestitutionThreshold(double threshold, const std::string& field) {
  if (!std::isfinite(threshold) || threshold < 0.0) {
    return Error{field, "must be a finite number >= 0 m/s, got " + formatNumber(threshold)};
  }
  return Ok{};
}

Status checkAirCoefficient(double coefficient, const std::string& field) {
  if (!std::isfinite(coefficient) || coefficient < 0.0) {
    return Error{field, "must be a finite coefficient >= 0, got " + formatNumber(coefficient)};
  }
  return Ok{};
}

Status checkContactTolerance(double tolerance, const std::string& field) {
  if (!std::isfinite(tolerance) || tolerance < 0.0 || tolerance >= 1.0) {
    return Error{field,
                 "must be a fraction of the contact distance in [0, 1) (surfaces closer than it "
                 "touch), got " +
                     formatNumber(tolerance)};
  }
  return Ok{};
}

Status checkRepresentable(std::initializer_list<NamedResult> results) {
  for (const NamedResult& result : results) {
    if (!result.finite) return Error{result.field, kBeyondDoubles};
  }
  return Ok{};
}

Status checkResolvablePosition(const Eigen::Vector3d& position, const std::string& field) {
  if (auto status = checkFinite(position, field); !status) return status;
  static const std::array<const char*, 3> kAxes = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(position[axis]) < kMaxResolvedCoordinate) continue;
    const std::string axis_name = kAxes[axis];
    return Error{field + "." + axis_name,
                 formatNumber(position[axis]) +
                     " m is beyond where the monitor can resolve a contact (|" + axis_name +
                     "| must be below 2^1022 = " + formatNumber(kMaxResolvedCoordinate) +
                     " m: past 2^1023 the sum of two bodies' coordinates overflows)"};
  }
  return Ok{};
}

Status checkResolvableLength(double length, const std::string& field) {
  if (auto status = checkFinite(length, field); !status) return status;
  if (std::abs(length) < kMaxResolvedCoordinate) return Ok{};
  return Error{field, formatNumber(length) +
                          " m is beyond where the monitor can resolve a contact (its magnitude "
                          "must be below 2^1022 = " +
                          formatNumber(kMaxResolvedCoordinate) +
                          " m: past 2^1023 the sum of two coordinates overflows)"};
}

Status checkResolvableObstaclePosition(const Eigen::Vector3d& position, double reach,
                                       const std::string& field) {
  if (auto status = checkResolvablePosition(position, field); !status) return status;
  if (!(reach > 0)) return Ok{};
  constexpr double kBandsPerReach = 0x1p47;  // 2^-48 (|x| + |x|) = reach at |x| = 2^47 reach
  const double bound = kBandsPerReach * reach;
  static const std::array<const char*, 3> kAxes = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(position[axis]) < bound) continue;
    const std::string axis_name = kAxes[axis];
    return Error{field + "." + axis_name,
                 formatNumber(position[axis]) +
                     " m is beyond where a contact with this obstacle resolves (|" + axis_name +
                     "| must be below 2^47 times its bounding radius " + formatNumber(reach) +
                     " m, " + formatNumber(bound) +
                     " m: from there the touching band of a body near it, 2^-48 (|x_body| + |" +
                     axis_name + "| + ...), is as wide as the whole obstacle)"};
  }
  return Ok{};
}

Status checkBody(const Body& body, const std::string& prefix) {
  // Checked first without the fields' names, which are built only to say what failed: a valid
  // body (every request's; a ball's collision the most frequent) builds no string.
  static const std::string kUnnamed;
  if (checkMass(body.mass, kUnnamed) && checkRadius(body.radius, kUnnamed) &&
      checkFinite(body.position, kUnnamed) && checkFinite(body.velocity, kUnnamed) &&
      checkFinite(body.angular_velocity, kUnnamed)) {
    return Ok{};
  }
  if (auto status = checkMass(body.mass, prefix + ".mass"); !status) return status;
  if (auto status = checkRadius(body.radius, prefix + ".radius"); !status) return status;
  if (auto status = checkFinite(body.position, prefix + ".position"); !status) return status;
  if (auto status = checkFinite(body.velocity, prefix + ".velocity"); !status) return status;
  return checkFinite(body.angular_velocity, prefix + ".angular_velocity");
}

Expected<Eigen::Vector3d> lineOfImpact(const Eigen::Vector3d& normal,
                                       const Eigen::Vector3d& position_a,
                                       const Eigen::Vector3d& position_b,
                                       const std::string& field) {
  if (auto status = checkFinite(normal, field); !status) return status.error();
  if (normal != Eigen::Vector3d::Zero()) return unitVector(normal);
  const Eigen::Vector3d centre_to_centre = position_b - position_a;
  if (!centre_to_centre.allFinite()) {
    return Error{field,
                 "is zero and the centres are too far apart to derive it (b.position - "
                 "a.position overflows); give the normal"};
  }
  if (centre_to_centre == Eigen::Vector3d::Zero()) {
    return Error{field, "is zero and a.position equals b.position " + formatVector(position_a) +
                            ": no line of impact; give a nonzero normal"};
  }
  return unitVector(centre_to_centre);
}

Eigen::Vector3d unitVector(const Eigen::Vector3d& v) {
  const Eigen::Vector3d scaled = v / v.cwiseAbs().maxCoeff();
  return scaled / scaled.norm();
}

bool isRotation(const Eigen::Quaterniond& orientation) {
  const Eigen::Vector4d& q = orientation.coeffs();
  if (!q.allFinite() || q.isZero(0.0)) return false;
  const double length = q.stableNorm();
  return std::abs(length * length - 1.0) < kQuaternionNormTolerance;
}

Status checkOrientation(const Eigen::Quaterniond& orientation, const std::string& field) {
  if (isRotation(orientation)) return Ok{};
  static const std::array<const char*, 4> kComponents = {"x", "y", "z", "w"};
  const Eigen::Vector4d& q = orientation.coeffs();  // x, y, z, w
  for (int k = 0; k < 4; ++k) {
    if (!std::isfinite(q[k])) {
      return Error{field + "." + kComponents[k],
                   "must be a finite number, got " + formatNumber(q[k])};
    }
  }
  if (q.isZero(0.0)) {
    return Error{field,
                 "is zero: no rotation has it (a rotation's quaternion has length 1; the "
                 "identity is [0, 0, 0, 1] as [x, y, z, w])"};
  }
  const double length = q.stableNorm();
  if (!(std::abs(length * length - 1.0) < kQuaternionNormTolerance)) {
    return Error{field,
                 "must have length 1 (a rotation's quaternion: x^2 + y^2 + z^2 + w^2 within " +
                     formatNumber(kQuaternionNormTolerance) + " of 1), got length " +
                     formatNumber(length)};
  }
  return Ok{};
}

}  // namespace collision_response::core
