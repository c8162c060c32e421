// The coefficient of restitution measured the seed's way: drop a ball, measure its bounce.
#pragma once

#include <string>

#include "collision_response/core/expected.h"
#include "collision_response/core/materials.h"

namespace collision_response::core {

/// e = sqrt(h' / h): the seed's v = sqrt(2 g h) before and v' = sqrt(2 g h') after a bounce,
/// |v'| = e |v|. Needs 0 < h finite and 0 <= h' <= h (a higher bounce would mean e > 1).
Expected<double> restitutionFromHeights(double drop_height, double bounce_height);

/// The material whose coefficient against the reference surface is nearest to `restitution`.
struct NearestMaterial {
  std::string name;
  double restitution = 0.0;  ///< the material's coefficient against the reference surface
};
/// Ties go to the name first in alphabetical order. Empty name if the table has no such material.
NearestMaterial nearestMaterial(const MaterialTable& table, double restitution);

}  // namespace collision_response::core
