// Stepped clusters (gravity): dense sets of near bodies, a pile settling in a box, advanced by
// time steps (solveSteppedSubstep) on a grid of the time line, while every other body stays with
// the exact model. A body of a cluster moves in a straight line over its sub-step; every pair
// with one of its bodies is kept apart by the cluster's solve (World::lasting), so the step's
// event queue never looks at them.
#pragma once

#include <cstddef>
#include <vector>

#include "collision_response/core/monitor.h"
#include "contact/lasting_contact.h"
#include "model/monitor_world.h"

namespace collision_response::core::monitor {

/// The next instant before `time` (a step's end) the clusters need: the grid's next instant, or
/// the end of a sub-step whose solve fell short (then its cluster is solved again there);
/// infinity when there is none (an instant at the step's end, within a rounding, is the next
/// step's start: the states given then carry the velocities of the sub-step ending there).
double nextSteppedEvent(const World& world, double time);

/// At `time`: when a grid instant is due (nextSteppedEvent <= time), the clusters formed again
/// from every tracked body, near pair by near pair, each of at least Stepping::min_bodies solved
/// for its sub-step (the others, and the bodies of clusters that fell apart, go back to the
/// exact model); otherwise the clusters whose sub-step ended early, or whose members' states were
/// replaced, solved again from `time` to the grid's next instant. Every body whose track changed
/// is appended to `changed`, those that left every cluster also to `released` (they may touch
/// what they were closing on: the caller resolves that as an impact of the exact model); the
/// counts of held sub-steps go to `report.fallbacks`.
void advanceStepped(World& world, double time, std::vector<std::size_t>& changed,
                    std::vector<std::size_t>& released, StepReport& report);

/// The bodies of `over_budget` (exact work past World::work_budget in this step, none stepped
/// yet), marked Track::over_budget, are stepped from `time` to the grid's next instant with the
/// bodies near them, whatever their number; at the grid instants after, a connected set of near
/// bodies with one so marked is stepped however small, until the marked body is near no other
/// (then it goes back to the exact model, unmarked). Every body whose track changed is appended
/// to `changed`, those that left a cluster also to `released` (advanceStepped).
void stepOverBudget(World& world, double time, const std::vector<std::size_t>& over_budget,
                    std::vector<std::size_t>& changed, std::vector<std::size_t>& released,
                    StepReport& report);

/// After the exact motion of the bodies of `moved` changed at `time` (an impact, a state, a
/// group of lasting contact formed again): those that can now reach a body of a cluster before
/// its sub-step ends join it, and it is solved again from `time`.
void joinStepped(World& world, double time, const std::vector<std::size_t>& moved,
                 std::vector<std::size_t>& changed, StepReport& report);

/// The contacts of the clusters' sub-steps that carry a force, as lasting contacts.
void reportSteppedContacts(const World& world, double time, std::vector<ContactRecord>& contacts);

/// The candidate pairs of `bodies` (in `index`) that touch at `time`, none in a cluster, in the
/// canonical order.
std::vector<Pair> touchingPairsOf(const World& world, double time,
                                  const std::vector<std::size_t>& bodies, const PairIndex& index);

/// Forgets every cluster: their bodies go on from where they are at `time` with the exact model.
void clearStepped(World& world, double time);

/// How many bodies are in clusters.
std::size_t steppedBodies(const World& world);

/// A box about obstacle `o`'s origin at its placement that a ball's box nearBodyBox must overlap
/// for the ball's surface to be within `reach` + `moving` + the touching band of the obstacle's
/// at `time` (nearPairs' filter before the contact geometry; not finite for a plane).
Box nearObstacleBox(const World& world, std::size_t o, double time, double moving);

/// The ball's side of nearObstacleBox: a ball of `radius` at `centre` that may move `reach`.
Box nearBodyBox(const World& world, double radius, const Eigen::Vector3d& centre, double reach);

}  // namespace collision_response::core::monitor
