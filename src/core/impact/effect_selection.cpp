// The effects of the product build: every effect a scene or a request names runs.
#include "solver/cluster_solver.h"

namespace collision_response::core {

Effects runnableEffects(const Effects& requested) { return requested; }

FrictionModel frictionModelFor(const Effects& effects) {
  if (!effects.friction) return FrictionModel{};
  if (effects.spin) {
    return FrictionModel{&applyFriction<true>, &applyFrictionJointly<true>,
                         &applyFrictionBySweeps<true>};
  }
  return FrictionModel{&applyFriction<false>, &applyFrictionJointly<false>,
                       &applyFrictionBySweeps<false>};
}

}  // namespace collision_response::core
