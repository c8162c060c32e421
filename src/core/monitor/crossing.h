// Where a predicted body's centre first crosses a plane (PredictImpacts' crossing): one rule for
// a ball's prediction and a shaped body's.
#pragma once

#include <Eigen/Core>

#include "collision_response/core/monitor.h"
#include "collision_response/core/shape.h"

namespace collision_response::core {

/// Which side of `plane` a point is on, and how far along its normal.
inline double across(const Plane& plane, const Eigen::Vector3d& position) {
  return plane.normal.dot(position) - plane.offset;
}

/// The first crossing of `plane` within (from, to] (the centre changes sides there) by the body
/// whose state at an instant is `stateAt(t)`: bisected to the last bit of the instant.
template <class StateAt>
BodyStateSample bisectCrossing(const Plane& plane, double from, double to, StateAt stateAt) {
  const double side = across(plane, stateAt(from).position);
  double open = from, closed = to;
  for (int i = 0; i < 200; ++i) {
    const double middle = open + 0.5 * (closed - open);
    if (!(middle > open && middle < closed)) break;
    const double now = across(plane, stateAt(middle).position);
    ((now > 0) == (side > 0) && now != 0 ? open : closed) = middle;
  }
  return stateAt(closed);
}

}  // namespace collision_response::core
