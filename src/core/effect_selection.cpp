// The effects of the product build: every effect a scene or a request names runs.
#include "collision_response/core/cluster_solver.h"

namespace collision_response::core {

Effects runnableEffects(const Effects& requested) { return requested; }

FrictionModel frictionModelFor(const Effects& effects) {
  if (!effects.friction) return FrictionModel{};
  if (effects.spin) return FrictionModel{&applyFriction<true>, &applyFrictionToCluster<true>};
  return FrictionModel{&applyFriction<false>, &applyFrictionToCluster<false>};
}

}  // namespace collision_response::core
