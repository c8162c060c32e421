#include "collision_response/core/friction.h"

namespace collision_response::core {

Expected<Inertia> parseInertia(const std::string& name, const std::string& field) {
  if (name.empty() || name == "solid") return Inertia::kSolid;
  if (name == "hollow") return Inertia::kHollow;
  return Error{field,
               "unknown inertia '" + name + "'; known: solid (2/5 m r^2), hollow (2/3 m r^2)"};
}

const char* toString(Inertia inertia) { return inertia == Inertia::kSolid ? "solid" : "hollow"; }

}  // namespace collision_response::core
