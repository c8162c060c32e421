// The benchmark's reference build (collision_response_core_noeffects): no effect can run, so
// the instructions it executes are those of the seed's model alone. scripts/bench_effects.sh
// counts the product's effects-off path against it. Linked instead of effect_selection.cpp.
#include "solver/cluster_solver.h"

namespace collision_response::core {

Effects runnableEffects(const Effects& /*requested*/) { return Effects{}; }

FrictionModel frictionModelFor(const Effects& /*effects*/) { return FrictionModel{}; }

}  // namespace collision_response::core
