// The monitor's members for straight-line motion (no gravity): see monitor_motion.h.
#include "monitor_motion.h"

namespace collision_response::core {
COLLISION_RESPONSE_INSTANTIATE_MONITOR(StraightLine)
}  // namespace collision_response::core
