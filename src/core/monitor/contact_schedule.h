// The event queue of a continuous step: each candidate pair's next first contact, earliest on
// top, and what touches at that instant.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "model/monitor_world.h"

namespace collision_response::core::monitor {

/// The pending first contacts of the step's candidate pairs (world.scratch.pairs) up to the
/// step's end. An entry whose time no longer matches its pair's (rescheduled since) is stale and
/// skipped.
template <class Motion>
class ContactSchedule {
 public:
  ContactSchedule(World& world, double end);

  const Pair& pair(std::size_t k) const { return pairs_[k]; }

  /// The pairs that touch at the step's start, `instant` (every pair may: the states were just
  /// taken).
  void touchingAtStart(double instant, std::vector<std::size_t>& touching);
  /// Every pair's first contact after the start's impacts (positions do not jump at an impact,
  /// so the start's geometry serves), with the pairs first that the new motion of the bodies of
  /// `changed` may form (a stepped cluster let go of them, a group formed at the start: the
  /// candidate pairs were found from their motion before).
  void scheduleAll(double instant, const std::vector<std::size_t>& changed);
  /// After `body`'s motion changed at `instant`: the pairs its new motion may form, and all its
  /// pairs rescheduled (the others' next contact has not moved).
  void reschedule(std::size_t body, double instant);
  /// The instant of the next first contact; infinity when none is left before the step's end.
  double earliest();
  /// The next instant of contact and the contacts touching then: the struck pairs and every
  /// contact touching their bodies, transitively (a chain, a rack), in the canonical order of
  /// their bodies' sorted ids. False when no contact is left before the step's end.
  bool next(double& instant, std::vector<std::size_t>& touching);

 private:
  /// The next first contact of pair k from `from`, given its geometry then.
  void schedule(std::size_t k, double from, const Geometry& g);
  void index(std::size_t k);
  /// The candidate pairs `body`'s motion from `instant` may form that are not candidates yet
  /// (addReachablePairs), added unscheduled; returns their indices.
  std::vector<std::size_t> addPairsReached(std::size_t body, double instant);
  /// The pair touches at the instant of `g` (within its touching band, or a lasting contact).
  bool touches(const Pair& pair, const Geometry& g) const;

  World& world_;
  double end_;
  std::vector<Pair>& pairs_;
  std::vector<std::vector<std::size_t>>& pairs_of_;  // each body's pairs
  std::vector<double>& next_contact_;
  std::vector<std::pair<double, std::size_t>>& events_;  // a heap, earliest on top
  std::vector<Geometry>& start_geometry_;
  std::vector<char>& queued_;
  std::vector<std::size_t> frontier_, frontier_seen_;
};

}  // namespace collision_response::core::monitor
