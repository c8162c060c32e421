// Impacts between the monitor's shaped bodies (issue 42, step 6: "their impacts are found and
// resolved"): every known shaped track advanced over a step together, each pair of shaped bodies
// watched for its first contact, and the impact there resolved on both.
//
// The watch: where both bodies fly (or one is still: held, or resting with no velocity), the
// pair's own certified advancement on their two flights (firstContact of two tumbling bodies,
// tumbling_contact.h: their relative motion), up to the earlier of their own next events
// (ShapedTrack::quietUntil, found on a copy of each engine). Where one moves in lasting contact,
// conservative advancement on the pair's certified gap g at t: no point of either body moves
// faster than its bound over the step's rest T, so they do not touch before t + g / (V_a + V_b).
// That bound holds through a body's own events with fixed obstacles (impacts and lasting contact
// never gain energy): its kinetic energy K(s) <= K(t) + m g . (c(s) - c(t)) <= K(t) + m |g| V T,
// so its centre's speed V <= |g| T + sqrt((|g| T)^2 + 2 K(t) / m) and its turning |w| <=
// sqrt(2 K_max / J_min), every point within V + |w| R (R its reach). A body struck by a moving
// obstacle in the step may gain energy past it (and a still one is taken as still): a pair found
// overlapping is reported (not modelled: never a silent pass-through).
//
// Where a pair touches closing (faster than a settled body's rebound, as an obstacle's impact:
// ShapedMotion), the impact is resolved at that instant: one point by Chatterjee and Ruina's law
// with the pair's friction, several at once by the same law over all of them (rigid_impact.h), both
// tracks going on from their states after it (their impacts with obstacles at that instant
// reported). Touching without closing (just struck, a graze), the pair is looked at again from
// the first instant its gap is past the touching band (ShapedRoom::parting; doubling steps, up to
// 1 ms). A pair whose touch lasts (closing slower than a settled body's, or not parting within
// 1 ms: two shaped bodies at rest on each other, pushing) is not modelled yet: both are held where
// they are until their next states, the pair not watched for the rest of the step, and the
// contact reported at the step's end (stepShaped).
#pragma once

#include <cstddef>
#include <vector>

#include "collision_response/core/monitor.h"
#include "model/monitor_world.h"
#include "monitor/shaped_tracks.h"

namespace collision_response::core::monitor {

/// Every known shaped track of `room` advanced from `from` to `time`, their impacts with obstacles
/// and with each other appended to `impacts` (time order is the caller's), the contacts whose
/// model is missing (a track held, a pair of shaped bodies found inside each other) to
/// `unmodelled`.
void advanceShapedTogether(const World& world, ShapedRoom& room, double from, double time,
                           std::vector<ImpactRecord>& impacts,
                           std::vector<UnmodelledContact>& unmodelled);

}  // namespace collision_response::core::monitor
