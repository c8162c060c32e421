// The monitor's members for motion under gravity (the gravity effect): see monitor_motion.h.
// The build without effects (COLLISION_RESPONSE_NO_EFFECTS) leaves them out.
#ifndef COLLISION_RESPONSE_NO_EFFECTS
#include "monitor_motion.h"

namespace collision_response::core {
COLLISION_RESPONSE_INSTANTIATE_MONITOR(UnderGravity)
}  // namespace collision_response::core
#endif
