// Lasting contact (gravity): bodies that touch without approaching form groups; their contact
// forces (solveContactForces) give them the motion they rest, slide or roll with, and the
// instants that motion changes (a slip that stops) are the groups' events.
#pragma once

#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include "collision_response/core/monitor.h"
#include "model/monitor_world.h"

namespace collision_response::core::monitor {

/// The candidate pairs of a search, and each body's pairs among them.
struct PairIndex {
  const std::vector<Pair>& pairs;
  const std::vector<std::vector<std::size_t>>& of;
};

/// Lasting contact at `time` for the bodies of `seeds`: every body that touches one of them
/// without approaching or separating (faster than restSpeed of gravity in the touching band)
/// joins them, transitively, and so do the groups they were in. Each connected set solves its
/// contact forces; the pressed contacts last, and their bodies' tracks continue from `time`
/// with the accelerations the forces leave (their normal relative velocities set to 0, so they
/// stay in contact). Every body whose track was set is appended to `changed`.
void formGroups(World& world, double time, const std::vector<std::size_t>& seeds,
                const PairIndex& index, std::vector<std::size_t>& changed);

/// Every tracked body at `time`, with candidate pairs from the broadphase at that instant.
void formAllGroups(World& world, double time, std::vector<std::size_t>& changed);

/// How far past the instant a group was solved its event must be to solve it again: 1e-12 of
/// the step's span, and the time line's rounding at `when`. Solved again at that very instant it
/// would be so for ever, and a group whose modes change back within a rounding (events a few
/// ulps apart: seen for three balls rolling in contact on a floor with friction and spin, 20,000
/// in one 10 ms step) would spend the step's budget on nothing.
inline double eventResolution(double when, double span) {
  return 1e-12 * span + 4e-16 * std::abs(when);
}

/// The earliest event of any group and that group; {infinity, 0} when there is none.
std::pair<double, std::size_t> nextGroupEvent(const World& world);

/// A curved group's event from its integrated motion (ConstrainedStep): its end while it is
/// integrated on demand (the frontier), or where its mode changed; infinity once complete or
/// taken.
double integratedEvent(const ContactGroup& group);

bool integrateFurther(World& world, std::size_t group, double when);

/// The group's events at `when` are taken (it is formed again, or goes on as it is).
void takeGroupEvents(ContactGroup& group, double when);

/// m/s: how fast the surfaces of `pair` move relative to each other at `time`: the norm of their
/// relative velocity plus the first's radius times the norm of their relative turning.
double surfaceSpeed(const World& world, const Pair& pair, double time);

/// The record of the lasting contact of `pair` at `time` (its other side numbered as a body or
/// as an obstacle), at `point` along `normal`, with the forces on the other side.
ContactRecord contactRecord(const World& world, double time, const Pair& pair,
                            const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                            double normal_force, const Eigen::Vector3d& friction_force,
                            ContactState state, double since);

/// The lasting contacts as the groups hold them at `time`.
void reportContacts(const World& world, double time, std::vector<ContactRecord>& contacts);

/// Forgets every group (the tracks keep their motion).
void clearGroups(World& world);

/// The solves of the group's integrated motion since it was last charged, added to each of its
/// bodies' World::work (and to World::work_total).
void chargeIntegration(World& world, ContactGroup& group);

}  // namespace collision_response::core::monitor
