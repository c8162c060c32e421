#include "collision_response/core/restitution.h"

#include <cmath>

#include "collision_response/core/validation.h"

namespace collision_response::core {

Expected<double> restitutionFromHeights(double drop_height, double bounce_height) {
  if (!std::isfinite(drop_height) || !(drop_height > 0.0)) {
    return Error{"drop_height", "must be a finite number > 0 m, got " + formatNumber(drop_height)};
  }
  if (!std::isfinite(bounce_height) || bounce_height < 0.0) {
    return Error{"bounce_height",
                 "must be a finite number >= 0 m, got " + formatNumber(bounce_height)};
  }
  if (bounce_height > drop_height) {
    return Error{"bounce_height", "must not exceed drop_height (" + formatNumber(drop_height) +
                                      " m): a higher bounce means e > 1, got " +
                                      formatNumber(bounce_height)};
  }
  if (bounce_height == 0.0) return 0.0;  // a dead drop; and -0 is not a coefficient
  // h' / h can underflow (1e-300 / 1e300) or overflow where e does not: the ratio is taken of
  // the two mantissas (h = m 2^k with m in [0.5, 1)) and the power of two, made even, halved.
  // Where the ratio is a normal double this is the same correctly rounded division and square
  // root as sqrt(h' / h), bit for bit: scaling by a power of two is exact.
  int bounce_exponent = 0;
  int drop_exponent = 0;
  double bounce_mantissa = std::frexp(bounce_height, &bounce_exponent);
  const double drop_mantissa = std::frexp(drop_height, &drop_exponent);
  int exponent = bounce_exponent - drop_exponent;
  if (exponent % 2 != 0) {
    bounce_mantissa *= 2.0;
    exponent -= 1;
  }
  return std::ldexp(std::sqrt(bounce_mantissa / drop_mantissa), exponent / 2);
}

NearestMaterial nearestMaterial(const MaterialTable& table, double restitution) {
  NearestMaterial nearest;
  double best_distance = INFINITY;
  for (const auto& [name, value] : table.againstReferenceSurface()) {  // sorted by name
    const double distance = std::abs(value - restitution);
    if (distance < best_distance) {
      best_distance = distance;
      nearest = NearestMaterial{name, value};
    }
  }
  return nearest;
}

}  // namespace collision_response::core
