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
  // One division and one square root, each correctly rounded.
  return std::sqrt(bounce_height / drop_height);
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
