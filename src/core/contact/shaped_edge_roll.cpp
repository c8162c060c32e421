// A cylinder or a capsule rolling off a bounded face's edge on its side (shaped_edge_roll.h).
//
// In the plane at right angles to the edge (n the face's normal, o the edge's `out`, a = n x o the
// axis): the centre is c = E + r u, u = cos theta n + sin theta o, E the edge's point in the
// centre's plane; t = -sin theta n + cos theta o. The body turns at w = psi' a, so its point on
// the edge slips at r (theta' - psi') t (a x u = t). The edge's force N u + F t at E gives
//   -m r theta'^2 = m g.u + N,   m r theta'' = m g.t + F,   I psi'' = -r F,
// the state (theta, psi, theta', psi') integrated by the Dormand-Prince 5(4) pair with dense
// output (Boost.Odeint), its events (N = 0, a stop or onset of slip, theta back to 0) found on
// the dense output by bisection. Rolling from rest at the top (a solid cylinder, I = m r^2 / 2),
// it leaves where cos theta = 4/7; at speed v0, cos theta = (4 g r + 3 v0^2) / (7 g r).
#include "contact/shaped_edge_roll.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "collision_response/core/validation.h"
#include "contact/planar_stretches.h"
#include "contact/shaped_pivot.h"
#include "geometry/convex_distance.h"

namespace collision_response::core {

namespace {

using Vec = Eigen::Vector3d;
using State = planar::State;  // theta, psi, theta', psi'
using Mode = planar::Grip;    // how the edge holds the side's point: sliding, or rolling
/// m: how far the side is kept from the edge's line (as the tipping over an edge keeps its face).
constexpr double kEdgeHair = 1e-11;

Error notYet(const std::string& what) { return Error{"contact", "not yet: " + what}; }

/// The side on the edge, fixed over the motion.
struct Roll {
  double mass = 0.0, moment = 0.0, radius = 0.0, mu = 0.0;
  double half_side = 0.0;  ///< half the length of the side's line (the axis' straight part)
  double edge_from = 0.0, edge_to = 0.0;  ///< the edge's extent along a, about E
  Vec gravity = Vec::Zero();
  Vec n, out, axis;  ///< the face's normal, the edge's out, a = n x out
  Vec edge_point;    ///< E: the edge's point in the centre's plane
  Eigen::Quaterniond orientation0;
};

struct Forces {
  double normal = 0.0, friction = 0.0, theta_rate = 0.0, psi_rate = 0.0;
};

Forces forcesOf(const Roll& k, const State& y, Mode mode, double sigma) {
  const double theta = y[0], td = y[2];
  const Vec u = std::cos(theta) * k.n + std::sin(theta) * k.out;
  const Vec t = std::cos(theta) * k.out - std::sin(theta) * k.n;
  const double g_u = k.gravity.dot(u), g_t = k.gravity.dot(t);
  const double m = k.mass, r = k.radius;
  Forces f;
  f.normal = -m * (g_u + r * td * td);
  if (mode == Mode::kHolding) {
    f.theta_rate = m * r * g_t / (k.moment + m * r * r);
    f.psi_rate = f.theta_rate;
    f.friction = m * r * f.theta_rate - m * g_t;
    return f;
  }
  f.friction = -sigma * k.mu * f.normal;
  f.theta_rate = (g_t + f.friction / m) / r;
  f.psi_rate = -r * f.friction / k.moment;
  return f;
}

PathState placed(const Roll& k, const State& y) {
  const double theta = y[0];
  const Vec u = std::cos(theta) * k.n + std::sin(theta) * k.out;
  const Vec t = std::cos(theta) * k.out - std::sin(theta) * k.n;
  PathState state;
  state.centre = k.edge_point + (k.radius + kEdgeHair) * u;
  state.velocity = k.radius * y[2] * t;
  state.angular_velocity = y[3] * k.axis;
  state.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(y[1], k.axis)) * k.orientation0;
  return state;
}

class EdgeRollPath : public LastingPath {
 public:
  Roll roll;
  double until_time = 0.0;
  planar::Stretches stretches;
  std::optional<std::pair<double, PathState>> flight;  // from when, and its state there

  PathState stateAt(double t) const override {
    const double time = std::clamp(t, stretches.start, until_time);
    if (flight && time >= flight->first) {
      return flownFrom(flight->second, roll.gravity, time - flight->first);
    }
    const auto [y, mode, sigma] = stretches.at(time);
    return withForces(y, mode, sigma);
  }

  /// The state at y, the edge's force shared by the side's two ends on the edge, with no moment
  /// about the centre's plane.
  PathState withForces(const State& y, Mode mode, double sigma) const {
    PathState state = placed(roll, y);
    state.state = mode == Mode::kHolding ? ContactState::kRolling : ContactState::kSliding;
    const Forces f = forcesOf(roll, y, mode, sigma);
    const double lo = std::max(-roll.half_side, roll.edge_from);
    const double hi = std::min(roll.half_side, roll.edge_to);
    const Vec u = std::cos(y[0]) * roll.n + std::sin(y[0]) * roll.out;
    const Vec t = std::cos(y[0]) * roll.out - std::sin(y[0]) * roll.n;
    const double normal = std::max(0.0, f.normal);
    const std::array<std::pair<double, double>, 2> ends{std::make_pair(lo, hi / (hi - lo)),
                                                        std::make_pair(hi, -lo / (hi - lo))};
    for (const auto& [at, share] : ends) {
      SupportForce force;
      force.point = roll.edge_point + at * roll.axis;
      force.normal_force = share * normal;
      force.friction_force = share * f.friction * t;
      force.normal = u;
      state.forces.push_back(force);
    }
    return state;
  }

  double start() const override { return stretches.start; }
  double until() const override { return until_time; }
  std::size_t steps() const override { return stretches.list.size(); }
};

enum class What { kLeaves, kSlipStops, kSlips, kBack };
constexpr std::array<What, 4> kEvents{What::kLeaves, What::kSlipStops, What::kSlips, What::kBack};

double eventValue(const Roll& k, const State& y, Mode mode, double sigma, What what) {
  const Forces f = forcesOf(k, y, mode, sigma);
  switch (what) {
    case What::kLeaves:
      return f.normal;
    case What::kSlipStops:
      return mode == Mode::kSliding && k.mu > 0 ? sigma * (y[2] - y[3]) : 1.0;
    case What::kSlips:
      return mode == Mode::kHolding ? k.mu * f.normal - std::abs(f.friction) : 1.0;
    case What::kBack:
      return y[0] >= 0 || y[2] >= 0 ? 1.0 : -1.0;  // back over the face, still rolling back
  }
  return 1.0;
}

/// The setting from the body on the edge, and its start (theta, 0, theta', psi'); refused by
/// name where the roll is not planar.
Expected<State> startOf(const LastingBody& body, const FlatFace& face, const FaceEdge& edge,
                        Roll& k) {
  double half_side = 0.0, radius = 0.0;
  if (const auto* can = std::get_if<Cylinder>(&body.shape)) {
    half_side = can->half_length;
    radius = can->radius;
  } else if (const auto* capsule = std::get_if<Capsule>(&body.shape)) {
    half_side = capsule->half_length;
    radius = capsule->radius;
  } else {
    return notYet("rolling over the face's edge on a part of the body that is not a side");
  }
  k.mass = body.mass;
  k.moment = body.moments.z();
  k.radius = radius;
  k.half_side = half_side;
  k.mu = face.friction;
  k.gravity = body.gravity;
  k.n = face.normal.normalized();
  k.out = edge.out.normalized();
  k.axis = k.n.cross(k.out);
  const Eigen::Quaterniond orientation = body.orientation.normalized();
  const Vec body_axis = orientation * Vec::UnitZ();
  if (body_axis.cross(k.axis).norm() > kSideAlongEdge) {
    return notYet("rolling over the face's edge with the side's axis not along the edge");
  }
  if (std::abs(body.gravity.dot(k.axis)) > kLastingAcrossGravity * body.gravity.norm()) {
    return notYet("rolling over the face's edge with gravity along it");
  }
  if (std::abs(body.velocity.dot(k.axis)) > kLastingStillSpeed) {
    return notYet("rolling over the face's edge while sliding along it");
  }
  const double spin = body.angular_velocity.dot(k.axis);
  if ((body.angular_velocity - spin * k.axis).norm() * reachOf(body.shape) > kLastingStillSpeed) {
    return notYet("rolling over the face's edge while turning about another axis");
  }
  const double middle = edge.along.dot(body.centre - edge.point);
  k.edge_point = edge.point + middle * edge.along;
  const double extent =
      std::abs(edge.along.dot(face.along_u)) > 0.5 ? face.half_extent.x() : face.half_extent.y();
  const double signed_along = edge.along.dot(k.axis);  // +-1: the edge's along, a's sense
  const double from_face = edge.along.dot(edge.point - face.point);
  k.edge_from = std::min(signed_along * (-extent - from_face - middle),
                         signed_along * (extent - from_face - middle));
  k.edge_to = std::max(signed_along * (-extent - from_face - middle),
                       signed_along * (extent - from_face - middle));
  if (!(k.edge_from < 0 && k.edge_to > 0)) {
    return notYet("rolling over the face's edge with the side's middle past an end of the edge");
  }
  const Vec arm = body.centre - k.edge_point;
  const double theta = std::atan2(arm.dot(k.out), arm.dot(k.n));
  const Vec t = std::cos(theta) * k.out - std::sin(theta) * k.n;
  k.orientation0 = orientation;
  // The state's radial part (settled) is dropped: v = r theta' t.
  return State{theta, 0.0, body.velocity.dot(t) / radius, spin};
}

/// Integrates one mode from `y` at `t` to its first event, or to `until` or the step budget.
Expected<std::optional<std::pair<double, What>>> integrateMode(EdgeRollPath& path, State& y,
                                                               double& t, double until, Mode mode,
                                                               double sigma, double tolerance,
                                                               std::size_t& taken) {
  const Roll& k = path.roll;
  const auto rate = [&k, mode, sigma](const State& x) {
    const Forces f = forcesOf(k, x, mode, sigma);
    return State{x[2], x[3], f.theta_rate, f.psi_rate};
  };
  const auto value = [&k, mode, sigma](const State& x, std::size_t e) {
    return eventValue(k, x, mode, sigma, kEvents[e]);
  };
  auto event = planar::integrateGrip(path.stretches, y, t, until, mode, sigma, tolerance, taken,
                                     kEvents.size(), rate, value, "the roll over the face's edge");
  if (!event) return event.error();
  if (!event.value()) return std::optional<std::pair<double, What>>{};
  return std::optional<std::pair<double, What>>(
      std::make_pair(event.value()->first, kEvents[event.value()->second]));
}

/// The mode at a stop or onset of slip: rolling where the friction it needs is within the cone,
/// else sliding against it.
std::pair<Mode, double> modeAt(const Roll& k, State& y, What what) {
  if (what == What::kSlipStops) y[3] = y[2];
  const Forces rolling = forcesOf(k, y, Mode::kHolding, 1.0);
  if (what == What::kSlipStops && std::abs(rolling.friction) <= k.mu * rolling.normal) {
    return {Mode::kHolding, 1.0};
  }
  // Sliding with the friction the roll needed: the slip grows against it.
  return {Mode::kSliding, rolling.friction > 0 ? -1.0 : 1.0};
}

}  // namespace

Expected<LastingMotion> rollOverFaceEdge(const LastingBody& body, const FlatFace& face,
                                         const FaceEdge& edge, double tolerance, double horizon) {
  if (!(tolerance > 0 && std::isfinite(tolerance))) {
    return Error{"tolerance", "must be finite and > 0, got " + formatNumber(tolerance)};
  }
  auto path = std::make_shared<EdgeRollPath>();
  Roll& k = path->roll;
  const auto start = startOf(body, face, edge, k);
  if (!start) return start.error();
  State y = start.value();
  const double slip = y[2] - y[3];
  Mode mode = Mode::kSliding;
  double sigma = slip >= 0 ? 1.0 : -1.0;
  if (k.mu > 0 && std::abs(slip) * k.radius <= kLastingStillSpeed) {
    std::tie(mode, sigma) = modeAt(k, y, What::kSlipStops);
  }
  path->stretches.start = body.time;
  path->stretches.initial = y;
  path->stretches.initial_grip = mode;
  path->stretches.initial_sigma = sigma;

  double t = body.time, until = body.time + horizon, last_change = -1;
  std::size_t taken = 0, changes_at_once = 0;
  std::optional<What> ended;
  while (!ended) {
    auto event = integrateMode(*path, y, t, until, mode, sigma, tolerance, taken);
    if (!event) return event.error();
    if (!event.value()) {
      until = t;  // the horizon, or the steps ran out: asked again from there
      break;
    }
    const auto [at, what] = *event.value();
    if (what == What::kLeaves || what == What::kBack) {
      ended = what;
      until = at;
      break;
    }
    changes_at_once = at == last_change ? changes_at_once + 1 : 0;
    last_change = at;
    if (changes_at_once > 2) return notYet("the edge's roll and slip change at once, again");
    std::tie(mode, sigma) = modeAt(k, y, what);
  }
  std::string ends = "stops";
  if (ended == What::kBack) {
    ends = "resumes";
  } else if (ended == What::kLeaves) {
    // It flies on (closed form) until it is clear of the edge, then its events take over.
    // The side's distance to the edge's line (parallel to its axis): the axis' distance less r.
    const PathState there = placed(k, y);
    const auto clear = clearAfter(
        [&](double tau) {
          const Vec arm = flownFrom(there, k.gravity, tau).centre - k.edge_point;
          return (arm - arm.dot(k.axis) * k.axis).norm() - k.radius;
        },
        kPivotClearance * reachOf(body.shape));
    ends = clear ? "resumes" : "its flight off the face's edge comes back to the edge";
    if (clear) {
      path->flight = std::make_pair(until, there);
      until += *clear;
    }
  }
  path->until_time = until;
  return LastingMotion::integrated(path, until, ends);
}

std::optional<FaceEdge> sideOnEdge(const LastingBody& body, const FlatFace& face) {
  if (!face.bounded) return std::nullopt;
  double radius = 0.0;
  if (const auto* can = std::get_if<Cylinder>(&body.shape)) {
    radius = can->radius;
  } else if (const auto* capsule = std::get_if<Capsule>(&body.shape)) {
    radius = capsule->radius;
  } else {
    return std::nullopt;
  }
  const Vec n = face.normal.normalized();
  const Vec body_axis = body.orientation.normalized() * Vec::UnitZ();
  for (const BoundEdge& bound : edgesOf(face)) {
    const FaceEdge& edge = bound.edge;
    if (body_axis.cross(edge.along).norm() > kSideAlongEdge) continue;
    const Vec e = edge.point + edge.along.dot(body.centre - edge.point) * edge.along;
    const Vec arm = body.centre - e;
    const double out = arm.dot(edge.out), up = arm.dot(n);
    if (std::abs(arm.norm() - radius) > kLastingBand || !(up > 0)) continue;
    // On the edge: the centre past its line, or at it (within the band) and not rolling back.
    if (out > kLastingBand || (out >= -kLastingBand && body.velocity.dot(edge.out) >= 0)) {
      return edge;
    }
  }
  return std::nullopt;
}

}  // namespace collision_response::core
