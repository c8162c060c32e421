// A shaped body tipping over a bounded face's edge (shaped_edge_tip.h).
//
// In the plane at right angles to the edge (n the face's normal, o = the edge's `out`, a = n x o
// the axis of the turn): the body's face, turned by phi about a, has the normal
// u = cos phi n + sin phi o and the direction w = cos phi o - sin phi n; the edge's point E lies
// on it, s behind the centre's foot, so the centre is c = E + h u + s w (h: the centre's height
// above its own face). The contact force N u + F w acts at E; with I the moment about a through
// the centre and G_u = g.u, G_w = g.w:
//   m (s'' + h phi'' - s phi'^2) = m G_w + F,   -m (2 s' phi' + h phi'^2 + s phi'') = m G_u + N,
//   I phi'' = s N - h F,
// and the body's point at E slips at s' along w. Sliding, F = -sigma mu N (sigma the sign of
// s'): phi'' = -m (s + sigma mu h) (G_u + 2 s' phi' + h phi'^2) / (I + m s (s + sigma mu h));
// sticking (s' = 0): the pendulum about E, (I + m (s^2 + h^2)) phi'' = m (h G_w - s G_u). The
// state (s, phi, s', phi') is integrated by the Dormand-Prince 5(4) pair with dense output
// (Boost.Odeint); the events (N = 0, a stop or onset of slip, the edge leaving the footprint's
// chord) are found on the dense output by bisection.
#include "contact/shaped_edge_tip.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "collision_response/core/validation.h"
#include "contact/planar_stretches.h"
#include "contact/shaped_pivot.h"
#include "geometry/convex_distance.h"

namespace collision_response::core {

namespace {

using Vec = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;
using State = planar::State;  // s, phi, s', phi'
using Mode = planar::Grip;    // how the edge holds the body's face: sliding, or sticking

constexpr double kPi = 3.14159265358979323846;
/// m: how far the body's face is kept from the edge's line (as the corners' tipping keeps its
/// lowest corner above the face: within the touching band, beyond the distance's tolerance).
constexpr double kEdgeHair = 1e-11;

Error notYet(const std::string& what) { return Error{"contact", "not yet: " + what}; }

/// The body's own face on the edge, in 2-D coordinates about the centre of mass's foot on it (x
/// along w, y along the turn's axis a): a convex polygon (its corners, in order), or a disc (a
/// cylinder's cap) where `radius` > 0.
struct FootPrint {
  std::vector<Vec2> polygon;
  Vec2 centre = Vec2::Zero();
  double radius = 0.0;
};

/// The body, the edge and the footprint, fixed over the motion.
struct Setting {
  double mass = 0.0;
  double moment = 0.0;  ///< about the axis a through the centre
  double height = 0.0;  ///< h: the centre above its own face
  double mu = 0.0;
  Vec gravity = Vec::Zero();
  Vec n, out, axis;  ///< the face's normal, the edge's out, a = n x out
  Vec edge_point;    ///< E: the edge's point in the centre's plane
  Eigen::Quaterniond orientation0;
  FootPrint print;
};

/// N, F and the accelerations in a mode (sliding: sigma the slip's sign).
struct Forces {
  double normal = 0.0, friction = 0.0, s_rate = 0.0, phi_rate = 0.0;
  bool paradox = false;  ///< Painleve's: sliding has no solution with N >= 0
};

Forces forcesOf(const Setting& k, const State& y, Mode mode, double sigma) {
  const double s = y[0], phi = y[1], sd = y[2], pd = y[3];
  const Vec u = std::cos(phi) * k.n + std::sin(phi) * k.out;
  const Vec w = std::cos(phi) * k.out - std::sin(phi) * k.n;
  const double g_u = k.gravity.dot(u), g_w = k.gravity.dot(w);
  const double m = k.mass, h = k.height, I = k.moment;
  Forces f;
  if (mode == Mode::kHolding) {
    f.phi_rate = m * (h * g_w - s * g_u) / (I + m * (s * s + h * h));
    f.normal = -m * (g_u + h * pd * pd + s * f.phi_rate);
    f.friction = m * (h * f.phi_rate - s * pd * pd - g_w);
    f.s_rate = 0.0;
    return f;
  }
  const double lever = s + sigma * k.mu * h;
  const double d = I + m * s * lever;
  if (!(d > 0)) {
    f.paradox = true;
    return f;
  }
  f.phi_rate = -m * lever * (g_u + 2 * sd * pd + h * pd * pd) / d;
  f.normal = -m * (g_u + 2 * sd * pd + h * pd * pd + s * f.phi_rate);
  f.friction = -sigma * k.mu * f.normal;
  f.s_rate = g_w + f.friction / m - h * f.phi_rate + s * pd * pd;
  return f;
}

/// The footprint's chord at x (its extent along y), or none where x is off it.
std::optional<std::pair<double, double>> chordAt(const FootPrint& print, double x) {
  if (print.radius > 0) {
    const double dx = x - print.centre.x();
    const double half2 = print.radius * print.radius - dx * dx;
    if (!(half2 > 0)) return std::nullopt;
    const double half = std::sqrt(half2);
    return std::make_pair(print.centre.y() - half, print.centre.y() + half);
  }
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  const std::size_t count = print.polygon.size();
  for (std::size_t i = 0; i < count; ++i) {
    const Vec2& p = print.polygon[i];
    const Vec2& q = print.polygon[(i + 1) % count];
    if ((p.x() - x) * (q.x() - x) > 0 || p.x() == q.x()) continue;
    const double y = p.y() + (q.y() - p.y()) * (x - p.x()) / (q.x() - p.x());
    lo = std::min(lo, y);
    hi = std::max(hi, y);
  }
  if (!(lo < hi)) return std::nullopt;
  return std::make_pair(lo, hi);
}

/// The body at (s, phi, s', phi'): centre, velocity, turning, orientation; the face kEdgeHair
/// clear of the edge.
PathState placed(const Setting& k, const State& y) {
  const double s = y[0], phi = y[1], sd = y[2], pd = y[3];
  const Vec u = std::cos(phi) * k.n + std::sin(phi) * k.out;
  const Vec w = std::cos(phi) * k.out - std::sin(phi) * k.n;
  PathState state;
  state.centre = k.edge_point + (k.height + kEdgeHair) * u + s * w;
  state.velocity = (sd + k.height * pd) * w - s * pd * u;
  state.angular_velocity = pd * k.axis;
  state.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(phi, k.axis)) * k.orientation0;
  return state;
}

/// The free flight after the body leaves the edge: from `from` (its state there) to `until`.
struct Flight {
  double from = 0.0;
  PathState there;
};

class EdgeTipPath : public LastingPath {
 public:
  Setting setting;
  double until_time = 0.0;
  planar::Stretches stretches;
  std::optional<Flight> flight;

  PathState stateAt(double t) const override {
    const double time = std::clamp(t, stretches.start, until_time);
    if (flight && time >= flight->from) {
      return flownFrom(flight->there, setting.gravity, time - flight->from);
    }
    const auto [y, mode, sigma] = stretches.at(time);
    return withForces(y, mode, sigma);
  }

  /// The state at y with the edge's force shared by the chord's two ends.
  PathState withForces(const State& y, Mode mode, double sigma) const {
    PathState state = placed(setting, y);
    const Forces f = forcesOf(setting, y, mode, sigma);
    state.state = mode == Mode::kHolding ? ContactState::kRolling : ContactState::kSliding;
    const auto chord = chordAt(setting.print, -y[0]);
    if (!chord || f.paradox) return state;
    const auto [lo, hi] = *chord;
    const Vec along = setting.axis;  // the edge's line, at right angles to the plane
    const Vec u = std::cos(y[1]) * setting.n + std::sin(y[1]) * setting.out;
    const Vec w = std::cos(y[1]) * setting.out - std::sin(y[1]) * setting.n;
    const double normal = std::max(0.0, f.normal);
    // Shares with no moment about the centre's plane: f_lo lo + f_hi hi = 0.
    const std::array<std::pair<double, double>, 2> ends{std::make_pair(lo, hi / (hi - lo)),
                                                        std::make_pair(hi, -lo / (hi - lo))};
    for (const auto& [y_at, share] : ends) {
      SupportForce force;
      force.point = setting.edge_point + y_at * along;
      force.normal_force = share * normal;
      force.friction_force = share * f.friction * w;
      force.normal = u;
      state.forces.push_back(force);
    }
    return state;
  }

  double start() const override { return stretches.start; }
  double until() const override { return until_time; }
  std::size_t steps() const override { return stretches.list.size(); }
};

/// Why a stretch ended.
enum class What { kLeaves, kSlipStops, kSlips, kPassesFace, kOutOfPlane, kFlat, kUpright };

/// The events of a mode as functions > 0 while it lasts.
double eventValue(const Setting& k, const State& y, Mode mode, double sigma, What what) {
  const Forces f = forcesOf(k, y, mode, sigma);
  switch (what) {
    case What::kLeaves:
      return f.paradox ? 1.0 : f.normal;
    case What::kSlipStops:
      return mode == Mode::kSliding && k.mu > 0 ? sigma * y[2] : 1.0;
    case What::kSlips:
      return mode == Mode::kHolding ? k.mu * f.normal - std::abs(f.friction) : 1.0;
    case What::kPassesFace: {
      const auto chord = chordAt(k.print, -y[0]);
      return chord ? 1.0 : -1.0;
    }
    case What::kOutOfPlane: {
      // The centre's plane's place in the chord, 0 to 1 (a disc's chord shrinking about it to
      // the rim does not take it out).
      const auto chord = chordAt(k.print, -y[0]);
      if (!chord) return 1.0;
      const double at = -chord->first / (chord->second - chord->first);
      return std::min(at, 1 - at);
    }
    case What::kFlat:
      return y[1] >= 0 || y[3] >= 0 ? 1.0 : -1.0;  // turned back below flat, still turning back
    case What::kUpright:
      return 0.5 * kPi - y[1];
  }
  return 1.0;
}

constexpr std::array<What, 7> kEvents{What::kLeaves,     What::kSlipStops,  What::kSlips,
                                      What::kPassesFace, What::kOutOfPlane, What::kFlat,
                                      What::kUpright};

/// The body's own flat face whose outward normal is -up, in the plane's coordinates (x along
/// `w`, y along `a`) about the centre's foot on it, and h, the centre's height above it: a
/// cylinder's cap (a disc), a box's or a hull's face (its corners in order). Empty where there is
/// no flat face there (a sphere, a capsule, a cylinder's side, a box's edge).
std::optional<std::pair<FootPrint, double>> ownFace(const LastingBody& body,
                                                    const Eigen::Quaterniond& orientation,
                                                    const Vec& up, const Vec& w, const Vec& a) {
  const Eigen::Matrix3d r = orientation.toRotationMatrix();
  const Vec down = r.transpose() * (-up);  // the body's frame
  const double reach = reachOf(body.shape);
  const double h = down.dot(coreSupport(body.shape, down)) + marginOf(body.shape);
  const Vec foot = body.centre - h * up;
  const auto flat = [&](const Vec& point) {
    return Vec2((point - foot).dot(w), (point - foot).dot(a));
  };
  FootPrint print;
  if (const auto* can = std::get_if<Cylinder>(&body.shape)) {
    if (!(std::abs(std::abs(down.z()) - 1) <= 1e-12)) return std::nullopt;
    print.centre = flat(body.centre + r * Vec(0, 0, down.z() * can->half_length));
    print.radius = can->radius;
    return std::make_pair(print, h);
  }
  if (!std::holds_alternative<Cuboid>(body.shape) &&
      !std::holds_alternative<ConvexHull>(body.shape)) {
    return std::nullopt;
  }
  std::vector<Vec> candidates;
  contactCandidates(body.shape, down, candidates);
  Vec2 mean = Vec2::Zero();
  for (const Vec& corner : candidates) {
    if (down.dot(corner) < h - kLastingBand * std::max(1.0, reach)) continue;
    print.polygon.push_back(flat(body.centre + r * corner));
    mean += print.polygon.back();
  }
  if (print.polygon.size() < 3) return std::nullopt;
  mean /= static_cast<double>(print.polygon.size());
  std::sort(print.polygon.begin(), print.polygon.end(), [&](const Vec2& p, const Vec2& q) {
    return std::atan2(p.y() - mean.y(), p.x() - mean.x()) <
           std::atan2(q.y() - mean.y(), q.x() - mean.x());
  });
  return std::make_pair(print, h);
}

/// The tipping's setting from the body on the edge (`k`, filled) and its start: (s, phi, s',
/// phi'), the edge sticking or sliding (sigma). Refused by name where it is not modelled.
struct Start {
  State y{};
  Mode mode = Mode::kSliding;
  double sigma = 1.0;
};

Expected<Start> startOf(const LastingBody& body, const FlatFace& face, const FaceEdge& edge,
                        const Vec& up, Setting& k) {
  k.mass = body.mass;
  k.mu = face.friction;
  k.gravity = body.gravity;
  k.n = face.normal.normalized();
  k.out = edge.out.normalized();
  k.axis = k.n.cross(k.out);
  const Eigen::Quaterniond orientation = body.orientation.normalized();
  const Eigen::Matrix3d rotation = orientation.toRotationMatrix();
  const Eigen::Matrix3d inertia = rotation * body.moments.asDiagonal() * rotation.transpose();
  k.moment = k.axis.dot(inertia * k.axis);
  if ((inertia * k.axis - k.moment * k.axis).norm() > 1e-12 * body.moments.maxCoeff()) {
    return notYet(
        "tipping over the face's edge about an axis that is not a principal one of the body");
  }
  if (std::abs(body.gravity.dot(k.axis)) > kLastingAcrossGravity * body.gravity.norm()) {
    return notYet("tipping over the face's edge with gravity along it");
  }
  if (std::abs(body.velocity.dot(k.axis)) > kLastingStillSpeed) {
    return notYet("sliding off the face's edge along it too (not at right angles to it)");
  }
  const double spin = body.angular_velocity.dot(k.axis);
  if ((body.angular_velocity - spin * k.axis).norm() * reachOf(body.shape) > kLastingStillSpeed ||
      std::abs(up.dot(k.axis)) > kLastingBand) {
    return notYet("tipping over the face's edge while turning about another axis");
  }
  // Its face turned by phi0 about the edge (0: flat on the face), the path's reference
  // orientation the body's turned back by phi0.
  const double phi0 = std::atan2(up.dot(k.out), up.dot(k.n));
  const Vec w0 = std::cos(phi0) * k.out - std::sin(phi0) * k.n;
  k.orientation0 = Eigen::Quaterniond(Eigen::AngleAxisd(-phi0, k.axis)) * orientation;
  const auto own = ownFace(body, orientation, up, w0, k.axis);
  if (!own) return notYet("tipping over the face's edge on a part of the body that is not flat");
  k.print = own->first;
  k.height = own->second;
  k.edge_point = edge.point + edge.along.dot(body.centre - edge.point) * edge.along;
  // The state's part along the face's normal (settled) is dropped: v = (s' + h phi') w - s phi' u.
  Start start;
  start.y = {w0.dot(body.centre - k.edge_point), phi0, body.velocity.dot(w0) - k.height * spin,
             spin};
  start.sigma = start.y[2] >= 0 ? 1.0 : -1.0;
  if (k.mu > 0 && std::abs(start.y[2]) <= kLastingStillSpeed) {
    start.y[2] = 0;
    const Forces stick = forcesOf(k, start.y, Mode::kHolding, 1.0);
    if (std::abs(stick.friction) <= k.mu * stick.normal) {
      start.mode = Mode::kHolding;
    } else {
      start.sigma = stick.friction > 0 ? -1.0 : 1.0;
    }
  }
  if (eventValue(k, start.y, start.mode, start.sigma, What::kOutOfPlane) <= 0) {
    return notYet(
        "tipping over the face's edge with the centre of mass past an end of the edge's contact");
  }
  return start;
}

/// Integrates one mode from `y` at `t` to its first event (its instant and kind; `y` the state
/// there), or to `until` or the step budget (`taken`) with none, each step kept in `path`.
Expected<std::optional<std::pair<double, What>>> integrateMode(EdgeTipPath& path, State& y,
                                                               double& t, double until, Mode mode,
                                                               double sigma, double tolerance,
                                                               std::size_t& taken) {
  const Setting& k = path.setting;
  const auto rate = [&k, mode, sigma](const State& x) {
    const Forces f = forcesOf(k, x, mode, sigma);
    return State{x[2], x[3], f.s_rate, f.phi_rate};
  };
  const auto value = [&k, mode, sigma](const State& x, std::size_t e) {
    return eventValue(k, x, mode, sigma, kEvents[e]);
  };
  auto event =
      planar::integrateGrip(path.stretches, y, t, until, mode, sigma, tolerance, taken,
                            kEvents.size(), rate, value, "the tipping over the face's edge");
  if (!event) return event.error();
  if (!event.value()) return std::optional<std::pair<double, What>>{};
  return std::optional<std::pair<double, What>>(
      std::make_pair(event.value()->first, kEvents[event.value()->second]));
}

}  // namespace

Expected<LastingMotion> tipOverFaceEdge(const LastingBody& body, const FlatFace& face,
                                        const FaceEdge& edge, const Eigen::Vector3d& up,
                                        double tolerance, double horizon) {
  if (!(tolerance > 0 && std::isfinite(tolerance))) {
    return Error{"tolerance", "must be finite and > 0, got " + formatNumber(tolerance)};
  }
  auto path = std::make_shared<EdgeTipPath>();
  Setting& k = path->setting;
  const auto start = startOf(body, face, edge, up, k);
  if (!start) {
    // Not in the plane at right angles to the edge (sliding along it too, turning about another
    // axis, the edge not a principal axis, ...): the body's points and crossings of the edge,
    // in three dimensions.
    if (start.error().field == "contact" && (std::holds_alternative<Cuboid>(body.shape) ||
                                             std::holds_alternative<Cylinder>(body.shape))) {
      return pivotOverFaceEdge(body, face, tolerance, horizon);
    }
    return start.error();
  }
  State y = start->y;
  Mode mode = start->mode;
  double sigma = start->sigma;
  path->stretches.start = body.time;
  path->stretches.initial = y;
  path->stretches.initial_grip = mode;
  path->stretches.initial_sigma = sigma;

  double t = body.time, until = body.time + horizon, last_change = -1;
  std::size_t taken = 0, changes_at_once = 0;
  std::optional<What> ended;
  while (!ended) {
    if (forcesOf(k, y, mode, sigma).paradox) {
      return notYet("Painleve's paradox: sliding over the face's edge has no force that holds it");
    }
    auto event = integrateMode(*path, y, t, until, mode, sigma, tolerance, taken);
    if (!event) return event.error();
    if (!event.value()) {
      until = t;  // the horizon, or the steps ran out: asked again from there
      break;
    }
    const auto [at, what] = *event.value();
    if (what != What::kSlipStops && what != What::kSlips) {
      ended = what;
      until = at;
      break;
    }
    // A stop: it sticks where the friction holding it is within the cone, else slips back; an
    // onset: it slips against the friction it needed.
    changes_at_once = at == last_change ? changes_at_once + 1 : 0;
    last_change = at;
    if (changes_at_once > 2) return notYet("the edge's stick and slip change at once, again");
    if (what == What::kSlipStops) y[2] = 0.0;
    const Forces stick = forcesOf(k, y, Mode::kHolding, 1.0);
    mode = what == What::kSlipStops && std::abs(stick.friction) <= k.mu * stick.normal
               ? Mode::kHolding
               : Mode::kSliding;
    if (mode == Mode::kSliding) sigma = stick.friction > 0 ? -1.0 : 1.0;
  }
  std::string ends = "stops";
  if (ended == What::kOutOfPlane) {
    ends = "stops";  // asked again there: it turns out of its plane (pivotOverFaceEdge)
  } else if (ended == What::kUpright) {
    ends = "tipping over the face's edge past upright";
  } else if (ended == What::kFlat) {
    ends = "resumes";
  } else if (ended == What::kLeaves || ended == What::kPassesFace) {
    // It flies on (closed form) until it is clear of the edge, then its events take over.
    Flight flight{until, placed(k, y)};
    const auto clear = clearAfter(
        [&](double tau) {
          return gapToEdge(body.shape, k.edge_point, k.axis, k.gravity, flight.there, tau);
        },
        kPivotClearance * reachOf(body.shape));
    ends = clear ? "resumes" : "its flight off the face's edge comes back to the edge";
    if (clear) {
      path->flight = flight;
      until += *clear;
    }
  }
  path->until_time = until;
  return LastingMotion::integrated(path, until, ends);
}

PathState flownFrom(const PathState& there, const Eigen::Vector3d& gravity, double tau) {
  PathState state = there;
  state.centre += there.velocity * tau + 0.5 * gravity * tau * tau;
  state.velocity += gravity * tau;
  const double turn = there.angular_velocity.norm() * tau;
  if (turn > 0) {
    state.orientation =
        Eigen::Quaterniond(Eigen::AngleAxisd(turn, there.angular_velocity.normalized())) *
        there.orientation;
  }
  state.state = ContactState::kSliding;
  state.forces.clear();
  return state;
}

double gapToEdge(const ConvexShape& shape, const Eigen::Vector3d& point,
                 const Eigen::Vector3d& along, const Eigen::Vector3d& gravity,
                 const PathState& there, double tau) {
  const double reach = reachOf(shape);
  const TriangleSupport line(point - reach * along, point + reach * along, point + reach * along);
  const PathState flown = flownFrom(there, gravity, tau);
  return convexDistance(PlacedConvex(shape, flown.orientation.toRotationMatrix(), flown.centre),
                        line, 1e-13)
      .lower;
}

std::optional<double> clearAfter(const std::function<double(double)>& gap, double clearance) {
  for (double tau = 1e-6; tau < 10.0; tau *= 2) {
    if (gap(tau) < clearance) continue;
    for (int i = 1; i < 64; ++i) {
      if (!(gap(tau * i / 64.0) > 0)) return std::nullopt;
    }
    return tau;
  }
  return std::nullopt;
}

std::array<BoundEdge, 4> edgesOf(const FlatFace& face) {
  const std::array<Vec, 2> axes{face.along_u, face.along_v};
  std::array<BoundEdge, 4> edges;
  for (int k = 0; k < 2; ++k) {
    for (int s = 0; s < 2; ++s) {
      BoundEdge& bound = edges[static_cast<std::size_t>(2 * k + s)];
      bound.axis = k;
      bound.side = s == 0 ? -1.0 : 1.0;
      bound.edge.out = bound.side * axes[static_cast<std::size_t>(k)];
      bound.edge.along = axes[static_cast<std::size_t>(1 - k)];
      bound.edge.point = face.point + face.half_extent[k] * bound.edge.out;
    }
  }
  return edges;
}

std::optional<std::pair<FaceEdge, Eigen::Vector3d>> tiltedOverEdge(const LastingBody& body,
                                                                   const FlatFace& face) {
  if (!face.bounded) return std::nullopt;
  const Vec n = face.normal.normalized();
  const Eigen::Matrix3d r = body.orientation.normalized().toRotationMatrix();
  // The body's flat faces' inward normals: a box's six, a cylinder's two caps.
  std::vector<Vec> ups;
  if (std::holds_alternative<Cuboid>(body.shape)) {
    for (int i = 0; i < 3; ++i) ups.insert(ups.end(), {Vec(r.col(i)), Vec(-r.col(i))});
  } else if (std::holds_alternative<Cylinder>(body.shape)) {
    ups = {Vec(r.col(2)), Vec(-r.col(2))};
  }
  for (const BoundEdge& bound : edgesOf(face)) {
    const FaceEdge& edge = bound.edge;
    const Vec a = n.cross(edge.out);
    const Vec e = edge.point + edge.along.dot(body.centre - edge.point) * edge.along;
    for (const Vec& up : ups) {
      const double phi = std::atan2(up.dot(edge.out), up.dot(n));
      if (std::abs(up.dot(a)) > kLastingBand || !(phi > 0 && phi < 0.5 * kPi)) continue;
      const Vec down = r.transpose() * (-up);
      const double h = down.dot(coreSupport(body.shape, down)) + marginOf(body.shape);
      if (std::abs(up.dot(body.centre - e) - h) <= kLastingBand) return std::make_pair(edge, up);
    }
  }
  return std::nullopt;
}

}  // namespace collision_response::core
