#include "monitor/contact_schedule.h"

#include <algorithm>
#include <cmath>

#include "model/candidate_pairs.h"
#include "model/motion_model.h"

namespace collision_response::core::monitor {
namespace {

using Event = std::pair<double, std::size_t>;
bool later(const Event& x, const Event& y) { return x.first > y.first; }

}  // namespace

template <class Motion>
ContactSchedule<Motion>::ContactSchedule(World& world, double end)
    : world_(world),
      end_(end),
      pairs_(world.scratch.pairs),
      pairs_of_(world.scratch.pairs_of),
      next_contact_(world.scratch.next_contact),
      events_(world.scratch.events),
      start_geometry_(world.scratch.geometry),
      queued_(world.scratch.queued) {
  pairs_of_.resize(world_.bodies.size());
  for (std::vector<std::size_t>& list : pairs_of_) list.clear();
  for (std::size_t k = 0; k < pairs_.size(); ++k) index(k);
  next_contact_.assign(pairs_.size(), INFINITY);
  events_.clear();
  queued_.assign(world_.bodies.size(), 0);
}

template <class Motion>
void ContactSchedule<Motion>::index(std::size_t k) {
  pairs_of_[pairs_[k].first].push_back(k);
  if (!world_.isObstacle(pairs_[k].second)) pairs_of_[pairs_[k].second].push_back(k);
}

template <class Motion>
bool ContactSchedule<Motion>::touches(const Pair& pair, const Geometry& g) const {
  if (!g.valid) return false;
  // A lasting contact whose integrated motion has drifted past the touching band (curved
  // contact, to its integration tolerance) still touches: a blow on one of its bodies reaches
  // the other.
  return std::abs(g.gap) <= g.tolerance || (g.gap < 0 && world_.lasting(pair));
}

template <class Motion>
void ContactSchedule<Motion>::touchingAtStart(double instant, std::vector<std::size_t>& touching) {
  start_geometry_.resize(pairs_.size());
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    start_geometry_[k] = geometry<Motion>(world_, pairs_[k], instant);
    const Geometry& g = start_geometry_[k];
    if (touches(pairs_[k], g)) touching.push_back(k);
  }
}

template <class Motion>
void ContactSchedule<Motion>::schedule(std::size_t k, double from, const Geometry& g) {
  next_contact_[k] = INFINITY;
  const Pair& pair = pairs_[k];
  if (!world_.settings.detect_impacts || !g.valid || world_.lasting(pair)) return;
  // A touching pair that does not approach (it was just resolved, or slides) never comes back
  // in a straight line; under gravity it may (a ball that bounced falls back), so its next entry
  // is looked for, except on the plane it rests on.
  const bool touching_now = std::abs(g.gap) <= g.tolerance;
  if (touching_now && approaching<Motion>(world_, pair, g, from)) {
    // Closing while it touches: an impact at this instant. The instant's resolver leaves none
    // of its pairs approaching; this is one whose motion changed after it (a group formed
    // again closes its contacts' normal velocities, which may turn a neighbouring touching pair
    // that is none of its contacts, a ball leaving the floor, into the floor).
    next_contact_[k] = from;
    events_.emplace_back(from, k);
    std::push_heap(events_.begin(), events_.end(), later);
    return;
  }
  if (!Motion::kAccelerates && touching_now) return;
  // Out of reach within the step even head-on (and accelerating all the way): no root needed.
  const double horizon = end_ - from;
  if (g.gap > reach<Motion>(world_, pair, from, horizon)) return;
  const auto delay = timeOfImpact<Motion>(world_, pair, from, horizon);
  if (!delay) return;
  const double when = std::min(from + *delay, end_);
  // No progress on a pair already handled at this instant would loop for ever.
  if (touching_now && !(when > from)) return;
  next_contact_[k] = when;
  events_.emplace_back(when, k);
  std::push_heap(events_.begin(), events_.end(), later);
}

template <class Motion>
std::vector<std::size_t> ContactSchedule<Motion>::addPairsReached(std::size_t body,
                                                                  double instant) {
  if (!world_.settings.broadphase) return {};  // every pair is a candidate already
  std::vector<std::size_t> added =
      addReachablePairs<Motion>(world_, body, instant, end_, pairs_, pairs_of_);
  for (const std::size_t k : added) {
    next_contact_.push_back(INFINITY);
    index(k);
  }
  return added;
}

template <class Motion>
void ContactSchedule<Motion>::scheduleAll(double instant, const std::vector<std::size_t>& changed) {
  for (const std::size_t body : changed) {
    for (const std::size_t k : addPairsReached(body, instant)) {
      start_geometry_.push_back(geometry<Motion>(world_, pairs_[k], instant));
    }
  }
  for (std::size_t k = 0; k < pairs_.size(); ++k) schedule(k, instant, start_geometry_[k]);
}

template <class Motion>
void ContactSchedule<Motion>::reschedule(std::size_t body, double instant) {
  // Its new motion may reach bodies its swept box did not: new candidate pairs.
  addPairsReached(body, instant);
  for (const std::size_t k : pairs_of_[body]) {
    schedule(k, instant, geometry<Motion>(world_, pairs_[k], instant));
  }
}

template <class Motion>
double ContactSchedule<Motion>::earliest() {
  while (!events_.empty() && events_.front().first != next_contact_[events_.front().second]) {
    std::pop_heap(events_.begin(), events_.end(), later);  // stale
    events_.pop_back();
  }
  return events_.empty() ? INFINITY : events_.front().first;
}

template <class Motion>
bool ContactSchedule<Motion>::next(double& instant, std::vector<std::size_t>& touching) {
  if (earliest() == INFINITY) return false;
  instant = events_.front().first;
  // The struck pairs, and every contact touching their bodies, transitively.
  for (const std::size_t body : frontier_seen_) queued_[body] = 0;
  frontier_seen_.clear();
  touching.clear();
  frontier_.clear();
  const auto visit = [this](std::size_t participant) {
    if (!world_.isObstacle(participant) && !queued_[participant]) {
      queued_[participant] = 1;
      frontier_seen_.push_back(participant);
      frontier_.push_back(participant);
    }
  };
  while (!events_.empty() && events_.front().first == instant) {
    const std::size_t k = events_.front().second;
    const bool current = next_contact_[k] == instant;
    std::pop_heap(events_.begin(), events_.end(), later);
    events_.pop_back();
    if (!current || std::find(touching.begin(), touching.end(), k) != touching.end()) continue;
    next_contact_[k] = INFINITY;
    touching.push_back(k);
    visit(pairs_[k].first);
    visit(pairs_[k].second);
  }
  while (!frontier_.empty()) {
    const std::size_t body = frontier_.back();
    frontier_.pop_back();
    for (const std::size_t k : pairs_of_[body]) {
      if (std::find(touching.begin(), touching.end(), k) != touching.end()) continue;
      const Geometry g = geometry<Motion>(world_, pairs_[k], instant);
      if (!touches(pairs_[k], g)) continue;
      touching.push_back(k);
      visit(pairs_[k].first == body ? pairs_[k].second : pairs_[k].first);
    }
  }
  // The canonical order of the pairs (by their bodies' sorted ids, not by when the broadphase
  // found them).
  std::sort(touching.begin(), touching.end(),
            [this](std::size_t x, std::size_t y) { return pairs_[x] < pairs_[y]; });
  return true;
}

template class ContactSchedule<StraightLine>;
template class ContactSchedule<UnderGravity>;

}  // namespace collision_response::core::monitor
