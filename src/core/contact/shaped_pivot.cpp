// A box or hull tipping over one to four of its corners on a flat face, or lifted off them
// (shaped_pivot.h).
//
// The body (mass m, inertia I = R diag(moments) R^T in the world) touches the face (normal n)
// at points r_i from its centre. With forces f_i there,
//   a = g + sum f_i / m,   I w' = sum r_i x f_i - w x I w,
// and a point's acceleration is a + w' x r_i + w x (w x r_i). A sticking point's acceleration
// is 0 (three conditions, its force three unknowns); a sliding point's normal acceleration is
// 0, its force N_i (n - mu s_hat_i) (one unknown: Coulomb's law, against its slip s_i). The
// conditions are linear in the unknowns; where they do not fix them (two sticking points: the
// forces along the edge; a face's four), the least-norm ones (doc/model.md, "Tipping over a corner
// or an edge"). The state (orientation, w, centre, v) is integrated by the Dormand-Prince 5(4) pair
// with dense output (Boost.Odeint); the events are found on the dense output by bisection.
#include "contact/shaped_pivot.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <variant>

#include "collision_response/core/validation.h"
#include "contact/edge_crossing.h"
#include "contact/shaped_edge_tip.h"
#include "geometry/convex_distance.h"

namespace collision_response::core {

namespace {

using Vec = Eigen::Vector3d;
using State = std::array<double, 13>;  // orientation (w, x, y, z), w, centre, velocity
using Stepper = boost::numeric::odeint::runge_kutta_dopri5<State>;
using Dense = boost::numeric::odeint::result_of::make_dense_output<Stepper>::type;

/// Steps one motion may take before it is asked again from where it is ("stops").
constexpr std::size_t kMaxSteps = 1u << 14;
constexpr double kSlipStops = kPivotSlipStops;
/// m: how far above the face the lowest corner is put (within the touching band, 1e-9 m, and
/// beyond the first contact's distance tolerance against a box, 1e-12 m).
constexpr double kPivotHair = 1e-11;
/// Bisection of an event on the dense output: to this part of the instant (or of 1 s).
constexpr double kEventResolution = 1e-13;

Error notYet(const std::string& what) { return Error{"contact", "not yet: " + what}; }

/// A part of the body that can touch the face, in its principal frame: a corner (`radius` 0), a
/// capsule's end (a ball about `centre`: `axis` zero) or a cylinder's rim (the circle of
/// `radius` about `centre` across `axis`, the cap's unit normal out of the body).
struct Feature {
  Vec centre = Vec::Zero();
  Vec axis = Vec::Zero();
  double radius = 0.0;
};

/// One point touching: which feature of the body, and how it moves.
struct Point {
  std::size_t feature = 0;
  bool sliding = false;
  /// Unit, in the contact's tangent plane: the slip's direction while it is too slow to give one
  /// (its onset).
  Vec direction = Vec::Zero();
  /// A rim's: unit, in its plane (principal frame), the direction of its point touching where
  /// that plane is along the face (the cap flat: every point of the rim equally low).
  Vec lean = Vec::Zero();
  /// A rim's point fixed in the body at `lean` (a flat cap's four, carried as a face's corners
  /// are), not its lowest.
  bool fixed = false;
  /// >= 0: the body's edge (`feature`, into Setting::segments) or rim (`feature`, its crossing on
  /// `side` of its chord's middle) on the face's edge `line` (into Setting::lines), not the face.
  int line = -1;
  int side = 0;
  /// The face it touches (into Setting::faces; a crossing's: the first).
  std::size_t face = 0;
  /// >= 0: the face's corner `corner` (into Setting::corners) on the body's flat side `feature`
  /// (into Setting::sides), not the face: a box's face or a can's cap over the table's corner.
  int corner = -1;
};

/// On the face's plane (a feature's point), not on its edge or its corner.
bool onFace(const Point& p) { return p.line < 0 && p.corner < 0; }

/// A flat side of the body (a box's face, a cylinder's cap): its outward unit normal and its
/// distance from the centre, in the principal frame.
struct FlatSide {
  Vec normal = Vec::UnitZ();
  double offset = 0.0;
};

/// A face the body touches, with its normal (unit, towards the body), tangents and mu.
struct Side {
  FlatFace face;
  Vec n, e1, e2;
  double mu = 0.0;
};

/// The body and the faces, fixed over the motion.
struct Setting {
  Vec moments = Vec::Ones();
  double mass = 0.0;
  Vec gravity = Vec::Zero();
  /// One face, or several at once (a floor and a wall: pivotOnFaces), the first the one whose
  /// edges the body goes on over (`crosses`, one face only).
  std::vector<Side> faces;
  std::vector<Feature> features;  // every corner, end or rim of the body
  ConvexShape shape;
  /// A bounded face's four edges (each its `point` the middle, to `half_length` either side),
  /// and a box's twelve edges (its corners' indices): where the body goes on over the face's
  /// edges (`crosses`: a box or a cylinder).
  struct Line {
    FaceEdge edge;
    double half_length = 0.0;
  };
  std::vector<Line> lines;
  std::vector<std::array<std::size_t, 2>> segments;
  /// Where the body goes on over the face's edges: the face's four corners (world) and the body's
  /// flat sides they may touch.
  std::vector<Vec> corners;
  std::vector<FlatSide> sides;
  bool crosses = false;
};

const Side& sideOf(const Setting& s, const Point& p) { return s.faces[p.face]; }

struct Kinematics {
  Eigen::Quaterniond orientation;
  Eigen::Matrix3d rotation;
  Vec centre, velocity, spin;
};

Kinematics unpack(const State& y) {
  Kinematics k;
  k.orientation = Eigen::Quaterniond(y[0], y[1], y[2], y[3]).normalized();
  k.rotation = k.orientation.toRotationMatrix();
  k.spin = Vec(y[4], y[5], y[6]);
  k.centre = Vec(y[7], y[8], y[9]);
  k.velocity = Vec(y[10], y[11], y[12]);
  return k;
}

State pack(const Kinematics& k) {
  const Eigen::Quaterniond& q = k.orientation;
  return {q.w(),          q.x(),          q.y(),         q.z(),        k.spin.x(),
          k.spin.y(),     k.spin.z(),     k.centre.x(),  k.centre.y(), k.centre.z(),
          k.velocity.x(), k.velocity.y(), k.velocity.z()};
}

/// Below this |n x a|, a rim's plane is along the face: its point touching is its `lean`'s.
constexpr double kRimFlat = 1e-12;

/// Where a point touches: its lever from the centre of mass (world), the rate at which it moves
/// over the body (`over`, world: 0 at a corner), the contact's normal (into the body) and
/// tangents, and `bend`: n'.V, the normal's turning against the body's point's velocity V there
/// (0 on the face). A ball's lowest point is c - rho n, which moves over it at rho w x n; a rim's
/// is c + rho d with d the unit -(n - (n.a) a) in its plane (a its axis), which moves over it at
/// rho (d' - w x d), d' from a' = w x a; an edge's or a rim's crossing of the face's edge is
/// edge_crossing.h's.
struct Contact {
  Vec lever = Vec::Zero();
  Vec over = Vec::Zero();
  Vec normal = Vec::UnitZ();
  Vec e1 = Vec::UnitX();
  Vec e2 = Vec::UnitY();
  double bend = 0.0;
  Vec on = Vec::Zero();  // a crossing's point on the face's edge
  double gap = 0.0;      // a crossing's
};

BodyRates ratesOf(const Kinematics& k) { return {k.centre, k.velocity, k.spin}; }

/// A point on the face's edge: its edge's or rim's crossing of the line (empty where it has none).
std::optional<LineCrossing> crossingOf(const Setting& s, const Kinematics& k, const Point& p) {
  const FaceEdge& line = s.lines[static_cast<std::size_t>(p.line)].edge;
  if (!s.segments.empty()) {
    const auto& ends = s.segments[p.feature];
    return segmentCrossing(k.centre + k.rotation * s.features[ends[0]].centre,
                           k.centre + k.rotation * s.features[ends[1]].centre, ratesOf(k), line);
  }
  const Feature& f = s.features[p.feature];
  return rimCrossing(k.centre + k.rotation * f.centre, k.rotation * f.axis,
                     k.rotation.col(f.axis.cross(Vec::UnitX()).norm() > 0.5 ? 0 : 1), f.radius,
                     p.side, ratesOf(k), line);
}

Contact contactOf(const Setting& s, const Kinematics& k, const Point& p) {
  const Side& side = sideOf(s, p);
  Contact c;
  c.normal = side.n;
  c.e1 = side.e1;
  c.e2 = side.e2;
  if (p.corner >= 0) {
    // The face's corner X (fixed) on the body's side (normal N, turning with it): the gap
    // N.(X - c) - offset changes at -N.V (V the body's point's velocity at X, which moves over the
    // body at -V), and nu' = w x nu (edge_crossing.h's terms for a fixed point on a flat side).
    const FlatSide& side_of_body = s.sides[p.feature];
    const Vec out = k.rotation * side_of_body.normal;
    c.on = s.corners[static_cast<std::size_t>(p.corner)];
    c.lever = c.on - k.centre;
    c.normal = -out;
    c.e1 = c.normal.unitOrthogonal();
    c.e2 = c.normal.cross(c.e1);
    const Vec velocity = k.velocity + k.spin.cross(c.lever);
    c.over = -velocity;
    c.bend = k.spin.cross(c.normal).dot(velocity);
    c.gap = out.dot(c.lever) - side_of_body.offset;
    return c;
  }
  if (p.line >= 0) {
    const auto crossing = crossingOf(s, k, p);
    if (!crossing) return c;  // gone: its event (inside) ends the segment first
    c.lever = crossing->point - k.centre;
    c.over = crossing->over;
    c.normal = crossing->normal;
    c.e1 = s.lines[static_cast<std::size_t>(p.line)].edge.along;
    c.e2 = c.normal.cross(c.e1);
    c.bend = crossing->normal_rate.dot(k.velocity + k.spin.cross(c.lever));
    c.on = crossing->on;
    c.gap = crossing->gap;
    return c;
  }
  const Feature& f = s.features[p.feature];
  const Vec centre = k.rotation * f.centre;
  c.lever = centre;
  if (f.radius == 0.0) return c;
  if (f.axis.isZero()) {
    c.lever = centre - f.radius * side.n;
    c.over = f.radius * k.spin.cross(side.n);
    return c;
  }
  c.lever = centre + f.radius * (k.rotation * p.lean);
  if (p.fixed) return c;
  const Vec a = k.rotation * f.axis;
  const Vec across = a.cross(side.n.cross(a));  // n - (n.a) a, without its cancellation
  const double tilt = across.norm();
  if (tilt <= kRimFlat) return c;
  const Vec d = -across / tilt;
  const Vec a_rate = k.spin.cross(a);
  const Vec across_rate = -side.n.dot(a_rate) * a - side.n.dot(a) * a_rate;
  const Vec d_rate = (d * d.dot(across_rate) - across_rate) / tilt;
  c.lever = centre + f.radius * d;
  c.over = f.radius * (d_rate - k.spin.cross(d));
  return c;
}

/// A point's velocity's part in its contact's tangent plane (of the body's point there).
Vec slipOf(const Setting& s, const Kinematics& k, const Point& p) {
  const Contact c = contactOf(s, k, p);
  const Vec u = k.velocity + k.spin.cross(c.lever);
  return u - u.dot(c.normal) * c.normal;
}

/// The forces and accelerations of the body with its points as `points` say.
struct Dynamics {
  Vec acceleration = Vec::Zero();
  Vec angular_acceleration = Vec::Zero();
  std::vector<Vec> forces;
  std::vector<Vec> normals;  // each point's contact normal (the face's, or its crossing's)
  std::vector<double> mus;   // each point's face's mu
};

/// The unknowns' directions of the points (a sticking point's normal and two tangents; a sliding
/// point's n - mu s_hat), each with its point's index.
std::vector<std::pair<std::size_t, Vec>> columnsOf(const Setting& s, const Kinematics& k,
                                                   const std::vector<Point>& points,
                                                   const std::vector<Contact>& contacts,
                                                   double still) {
  std::vector<std::pair<std::size_t, Vec>> columns;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Contact& c = contacts[i];
    if (points[i].sliding) {
      // The slip's direction; below `still`, turned continuously towards the point's given one
      // (its onset's), which it is at 0.
      const Vec u = k.velocity + k.spin.cross(c.lever);
      const Vec slip = u - u.dot(c.normal) * c.normal;
      const double speed = slip.norm();
      const Vec towards = speed >= still ? slip : Vec(slip + (still - speed) * points[i].direction);
      const double length = towards.norm();
      const Vec direction = length > 0 ? Vec(towards / length) : points[i].direction;
      columns.emplace_back(i, c.normal - sideOf(s, points[i]).mu * direction);
    } else {
      columns.emplace_back(i, c.normal);
      columns.emplace_back(i, c.e1);
      columns.emplace_back(i, c.e2);
    }
  }
  return columns;
}

/// Rows of the conditions on the points (a sticking point's three, a sliding point's normal),
/// given what each unknown (`columns`) does at a point per unit, and `free` per point (the
/// points' acceleration or velocity without the forces; `bent`: the normal's turning, n'.V, added
/// to the normal row, at the accelerations' level): solved least-norm, the forces per point
/// (`scales`, one per column: least-norm in the unknowns divided by them instead).
std::vector<Vec> solveConditions(const Setting& s, const std::vector<Point>& points,
                                 const std::vector<Contact>& contacts,
                                 const std::vector<std::pair<std::size_t, Vec>>& columns,
                                 const std::vector<Vec>& free,
                                 const Eigen::Matrix3d& inverse_inertia, bool bent,
                                 const std::vector<double>& scales = {}) {
  if (points.empty()) return {};  // flying: no force
  struct Row {
    std::size_t point;
    Vec along;
    double extra;
  };
  std::vector<Row> rows;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Contact& c = contacts[i];
    rows.push_back({i, c.normal, bent ? c.bend : 0.0});
    if (!points[i].sliding) {
      rows.push_back({i, c.e1, 0.0});
      rows.push_back({i, c.e2, 0.0});
    }
  }
  Eigen::MatrixXd a(rows.size(), columns.size());
  Eigen::VectorXd b(rows.size());
  for (std::size_t c = 0; c < columns.size(); ++c) {
    const auto& [j, unit] = columns[c];
    const Vec force = scales.empty() ? unit : Vec(scales[c] * unit);
    const Vec turn = inverse_inertia * contacts[j].lever.cross(force);
    for (std::size_t r = 0; r < rows.size(); ++r) {
      a(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) =
          rows[r].along.dot(force / s.mass + turn.cross(contacts[rows[r].point].lever));
    }
  }
  for (std::size_t r = 0; r < rows.size(); ++r) {
    b(static_cast<Eigen::Index>(r)) = -rows[r].along.dot(free[rows[r].point]) - rows[r].extra;
  }
  const Eigen::VectorXd x = a.completeOrthogonalDecomposition().solve(b);
  std::vector<Vec> forces(points.size(), Vec::Zero());
  for (std::size_t c = 0; c < columns.size(); ++c) {
    const double scale = scales.empty() ? 1.0 : scales[c];
    forces[columns[c].first] += scale * x(static_cast<Eigen::Index>(c)) * columns[c].second;
  }
  return forces;
}

std::vector<Contact> contactsOf(const Setting& s, const Kinematics& k,
                                const std::vector<Point>& points) {
  std::vector<Contact> contacts;
  contacts.reserve(points.size());
  for (const Point& p : points) contacts.push_back(contactOf(s, k, p));
  return contacts;
}

Dynamics dynamicsOf(const Setting& s, const Kinematics& k, const std::vector<Point>& points) {
  const Eigen::Matrix3d inertia = k.rotation * s.moments.asDiagonal() * k.rotation.transpose();
  const Eigen::Matrix3d inverse_inertia =
      k.rotation * s.moments.cwiseInverse().asDiagonal() * k.rotation.transpose();
  const Vec gyroscopic = -inverse_inertia * k.spin.cross(inertia * k.spin);
  // A point's acceleration without the forces; where it moves over the body (a ball's, a rim's,
  // a crossing's) the body's point there changes at w x (its rate over the body) besides.
  const std::vector<Contact> contacts = contactsOf(s, k, points);
  std::vector<Vec> free;
  for (const Contact& c : contacts) {
    free.push_back(s.gravity + gyroscopic.cross(c.lever) +
                   k.spin.cross(k.spin.cross(c.lever) + c.over));
  }
  Dynamics d;
  for (const Contact& c : contacts) d.normals.push_back(c.normal);
  for (const Point& p : points) d.mus.push_back(sideOf(s, p).mu);
  d.forces = solveConditions(s, points, contacts, columnsOf(s, k, points, contacts, kSlipStops),
                             free, inverse_inertia, true);
  Vec total = Vec::Zero(), moment = Vec::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    total += d.forces[i];
    moment += contacts[i].lever.cross(d.forces[i]);
  }
  d.acceleration = s.gravity + total / s.mass;
  d.angular_acceleration = gyroscopic + inverse_inertia * moment;
  return d;
}

void derivative(const Setting& s, const std::vector<Point>& points, const State& y, State& rate) {
  const Kinematics k = unpack(y);
  const Dynamics d = dynamicsOf(s, k, points);
  const Eigen::Quaterniond q(y[0], y[1], y[2], y[3]);
  // q' = (0, w) q / 2 (w in the world).
  const Eigen::Quaterniond turn(0.0, 0.5 * k.spin.x(), 0.5 * k.spin.y(), 0.5 * k.spin.z());
  const Eigen::Quaterniond q_rate = turn * q;
  rate = {q_rate.w(),
          q_rate.x(),
          q_rate.y(),
          q_rate.z(),
          d.angular_acceleration.x(),
          d.angular_acceleration.y(),
          d.angular_acceleration.z(),
          k.velocity.x(),
          k.velocity.y(),
          k.velocity.z(),
          d.acceleration.x(),
          d.acceleration.y(),
          d.acceleration.z()};
}

/// The points' normal motion, and the slip of those that stick, taken out by one plastic
/// impulse (least-norm where the conditions do not fix it).
Kinematics settle(const Setting& s, Kinematics k, const std::vector<Point>& points) {
  const Eigen::Matrix3d inverse_inertia =
      k.rotation * s.moments.cwiseInverse().asDiagonal() * k.rotation.transpose();
  const std::vector<Contact> contacts = contactsOf(s, k, points);
  std::vector<Vec> free;
  for (const Contact& c : contacts) free.push_back(k.velocity + k.spin.cross(c.lever));
  // A sliding point's impulse is along n: it takes out a settled normal motion.
  Setting plain = s;
  for (Side& side : plain.faces) side.mu = 0.0;
  const std::vector<Vec> impulses = solveConditions(
      plain, points, contacts, columnsOf(plain, k, points, contacts, kLastingStillSpeed), free,
      inverse_inertia, false);
  Vec total = Vec::Zero(), moment = Vec::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    total += impulses[i];
    moment += contacts[i].lever.cross(impulses[i]);
  }
  k.velocity += total / s.mass;
  k.spin += inverse_inertia * moment;
  return k;
}
/// The height of a feature's lowest point above a face (a rim's: its centre's less rho |n x a|).
double heightOf(const Side& side, const Kinematics& k, const Feature& f) {
  const double centre = side.n.dot(k.centre + k.rotation * f.centre - side.face.point);
  if (f.radius == 0.0) return centre;
  if (f.axis.isZero()) return centre - f.radius;
  return centre - f.radius * side.n.cross(k.rotation * f.axis).norm();
}

/// How far a sticking point's force is within its cone (mu N, to the solve's rounding): < 0
/// outside. The sticking's event and the modes' choice both read it.
double coneMargin(double mu, const Vec& n, const Vec& force) {
  const double normal = force.dot(n);
  const double across = (force - normal * n).norm();
  return mu * normal + 1e-12 * std::abs(normal) - across;
}

/// Point i's normal force (along its contact's normal) and how far its force is within its cone.
double normalForce(const Dynamics& d, std::size_t i) { return d.forces[i].dot(d.normals[i]); }
double coneMarginOf(const Dynamics& d, std::size_t i) {
  return coneMargin(d.mus[i], d.normals[i], d.forces[i]);
}

/// The direction in the face a sticking point `which` starts to slip in: where its acceleration
/// in the face, with friction mu N against it, is along it (Coulomb's law at the onset), found
/// over the angle by bisection; empty where there is none.
std::optional<Vec> slipOnset(const Setting& s, const Kinematics& k, std::vector<Point> points,
                             std::size_t which) {
  points[which].sliding = true;
  const Contact c = contactOf(s, k, points[which]);
  const auto along = [&](double angle) {
    points[which].direction = std::cos(angle) * c.e1 + std::sin(angle) * c.e2;
    const Dynamics d = dynamicsOf(s, k, points);
    const Vec a = d.acceleration + d.angular_acceleration.cross(c.lever) +
                  k.spin.cross(k.spin.cross(c.lever) + c.over);
    const Vec in_face = a - a.dot(c.normal) * c.normal;
    return std::make_pair(in_face.cross(points[which].direction).dot(c.normal),
                          in_face.dot(points[which].direction));
  };
  constexpr int kSamples = 72;
  constexpr double kTurn = 6.283185307179586;
  double previous_angle = 0.0;
  auto previous = along(0.0);
  for (int i = 1; i <= kSamples; ++i) {
    const double angle = kTurn * i / kSamples;
    const auto now = along(angle);
    if ((previous.first <= 0) != (now.first <= 0)) {
      double lo = previous_angle, hi = angle;
      const bool rising = previous.first <= 0;
      for (int b = 0; b < 60; ++b) {
        const double mid = 0.5 * (lo + hi);
        if ((along(mid).first <= 0) == rising) {
          lo = mid;
        } else {
          hi = mid;
        }
      }
      const double root = 0.5 * (lo + hi);
      if (along(root).second > 0) return Vec(std::cos(root) * c.e1 + std::sin(root) * c.e2);
    }
    previous = now;
    previous_angle = angle;
  }
  return std::nullopt;
}

/// A flat cap's fixed points once fewer than three are left (the others lifted): the cap tips
/// over its rim, whose lowest point (non-fixed) replaces them, at first where they were (their
/// mean's direction; two opposite ones: the lower). Other points as they are.
std::vector<Point> liftedCap(const Setting& s, const Kinematics& k, std::vector<Point> points) {
  std::vector<Point> fixed;
  for (const Point& p : points) {
    if (p.fixed) fixed.push_back(p);
  }
  if (fixed.empty() || fixed.size() >= 3) return points;
  points.erase(std::remove_if(points.begin(), points.end(), [](const Point& p) { return p.fixed; }),
               points.end());
  Vec mean = Vec::Zero();
  for (const Point& p : fixed) mean += p.lean;
  mean /= static_cast<double>(fixed.size());
  Point rim = fixed.front();
  const Side& side = sideOf(s, rim);
  if (mean.norm() > 0.5) {
    rim.lean = mean.normalized();
  } else {
    for (const Point& p : fixed) {
      const Feature& f = s.features[p.feature];
      const auto height = [&](const Point& q) {
        return side.n.dot(k.rotation * (f.centre + f.radius * q.lean));
      };
      if (height(p) < height(rim)) rim = p;
    }
  }
  rim.fixed = false;
  const Vec slip = slipOf(s, k, rim);
  rim.sliding = side.mu == 0.0 || slip.norm() > kLastingStillSpeed;
  rim.direction = slip.norm() > kLastingStillSpeed ? Vec(slip.normalized()) : side.e1;
  points.push_back(rim);
  return points;
}

/// The points' modes at a state, from what `points` say (sliding or not): a sticking point
/// whose force is outside the cone slides from its onset direction, and a point whose normal
/// force would be negative leaves (dropped). An Error where the onset has no direction.
Expected<std::vector<Point>> modesAt(const Setting& s, const Kinematics& k,
                                     std::vector<Point> points) {
  // Each round drops a point or sets one sliding (none comes back): at most two per point.
  const std::size_t rounds = 2 * points.size() + 1;
  for (std::size_t round = 0; round < rounds; ++round) {
    const Dynamics d = dynamicsOf(s, k, points);
    bool changed = false;
    for (std::size_t i = 0; i < points.size() && !changed; ++i) {
      if (normalForce(d, i) < 0) {
        points.erase(points.begin() + static_cast<std::ptrdiff_t>(i));
        points = liftedCap(s, k, std::move(points));
        changed = true;
      } else if (!points[i].sliding && coneMarginOf(d, i) < 0) {
        const auto onset = slipOnset(s, k, points, i);
        if (!onset) return notYet("a corner starting to slip with no direction of onset");
        points[i].sliding = true;
        points[i].direction = *onset;
        changed = true;
      }
    }
    if (!changed || points.empty()) return points;
  }
  return notYet("a tipping whose corners' sticking and sliding do not settle");
}

/// Every feature of the body that can touch a face: a box's or hull's corners, a cylinder's two
/// rims, a capsule's two ends (its axis z; the end at -half_length first); empty for a ball.
std::vector<Feature> featuresOf(const ConvexShape& shape) {
  std::vector<Feature> features;
  if (const auto* box = std::get_if<Cuboid>(&shape)) {
    for (int c = 0; c < 8; ++c) {
      features.push_back({Vec((c & 1) ? 1.0 : -1.0, (c & 2) ? 1.0 : -1.0, (c & 4) ? 1.0 : -1.0)
                              .cwiseProduct(box->half_size)});
    }
  } else if (const auto* hull = std::get_if<ConvexHull>(&shape)) {
    for (const Vec& vertex : hull->vertices) features.push_back({vertex});
  } else if (const auto* cylinder = std::get_if<Cylinder>(&shape)) {
    for (const double side : {-1.0, 1.0}) {
      features.push_back(
          {side * cylinder->half_length * Vec::UnitZ(), side * Vec::UnitZ(), cylinder->radius});
    }
  } else if (const auto* capsule = std::get_if<Capsule>(&shape)) {
    for (const double side : {-1.0, 1.0}) {
      features.push_back(
          {side * capsule->half_length * Vec::UnitZ(), Vec::Zero(), capsule->radius});
    }
  }
  return features;
}

/// What ends a segment of the motion: each a function of the state that reaches <= 0.
enum class What { kCorner, kLeaves, kSlips, kSticks, kEdge, kShift, kClear };
struct Event {
  What what;
  std::size_t point;
  std::function<double(const Kinematics&)> value;
};

/// How far a feature is off a bounded face's edges, where the body goes on over them (0
/// otherwise): the most, over the edges, of its distance past the edge's line along its out (a
/// rim's: of its lowest point, or of its nearest point where it lies flat). > 0: it is not over
/// the face, and reaching the face's plane there is no contact.
double offFace(const Setting& s, const Kinematics& k, const Feature& f) {
  if (!s.crosses) return -std::numeric_limits<double>::infinity();
  const Vec centre = k.centre + k.rotation * f.centre;
  Vec lowest = centre;
  Vec axis = Vec::Zero();
  if (f.radius > 0) {
    axis = k.rotation * f.axis;
    const Vec across = axis.cross(s.faces.front().n.cross(axis));
    if (across.norm() > kRimFlat) {
      lowest = centre - f.radius * across.normalized();
      axis = Vec::Zero();
    }
  }
  double off = -std::numeric_limits<double>::infinity();
  for (const Setting::Line& line : s.lines) {
    const double past = line.edge.out.dot(lowest - line.edge.point);
    const double reach = axis.isZero() ? 0.0 : f.radius * axis.cross(line.edge.out).norm();
    off = std::max(off, past - reach);
  }
  return off;
}

/// Each feature's height over the lowest point touching face `face` (the one stateAt puts on
/// it): their drift is not a feature's approach; where it is off the face (offFace), how far.
struct Above {
  const Setting& s;
  const std::vector<Point>& current;
  double operator()(const Kinematics& x, std::size_t face, const Feature& feature) const {
    const Side& side = s.faces[face];
    double base = std::numeric_limits<double>::infinity();
    for (const Point& p : current) {
      if (onFace(p) && p.face == face) {
        base = std::min(base, heightOf(side, x, s.features[p.feature]));
      }
    }
    if (!std::isfinite(base)) base = 0.0;
    return std::max(heightOf(side, x, feature) - base, offFace(s, x, feature));
  }
};

/// How far a touching rim's cap is from lying flat on the face, signed along `towards` (in the
/// face: where its point touching was at the step's start, so that the rim's turning about the
/// normal does not move it): rho (the cap's normal out of the body . -towards), which passes 0
/// where the cap lands flat.
double capTilt(const Kinematics& x, const Feature& rim, const Vec& towards) {
  return -rim.radius * towards.dot(x.rotation * rim.axis);
}

/// Where a touching rim's point is, in the face (unit), at `k`; zero for a corner, an end or a
/// flat cap's fixed point (its cap is flat while it touches).
Vec rimTowards(const Setting& s, const Kinematics& k, const Point& p) {
  if (!onFace(p)) return Vec::Zero();
  const Feature& f = s.features[p.feature];
  if (f.radius == 0.0 || f.axis.isZero() || p.fixed) return Vec::Zero();
  const Vec lever = contactOf(s, k, p).lever - k.rotation * f.centre;
  const Vec n = sideOf(s, p).n;
  const Vec in_face = lever - lever.dot(n) * n;
  // Against several faces, a cap at right angles to its face (its point straight below its
  // centre: its in-face part rounding) has no direction, and cannot land flat before it turns.
  // (On one face that rounding's direction is kept: its event restarts the step, and the one-face
  // tipping paths, a side rolling off a table's edge among them, were checked with it.)
  const double rounding = s.faces.size() > 1 ? 1e-12 * f.radius : 0.0;
  return in_face.norm() > rounding ? Vec(in_face.normalized()) : Vec::Zero();
}

/// How far the body is above the faces: its lowest feature's height over any; where it goes on
/// over the face's edges, its distance to the face (GJK against the face's rectangle).
double clearanceOf(const Setting& s, const Kinematics& k) {
  if (!s.crosses) {
    double lowest = std::numeric_limits<double>::infinity();
    for (const Side& side : s.faces) {
      for (const Feature& f : s.features) lowest = std::min(lowest, heightOf(side, k, f));
    }
    return lowest;
  }
  const Side& side = s.faces.front();
  const ConvexShape face_shape =
      Cuboid{Vec(side.face.half_extent.x(), side.face.half_extent.y(), 0.0)};
  Eigen::Matrix3d frame;
  frame << side.face.along_u, side.face.along_v, side.n;
  return convexDistance(PlacedConvex(s.shape, k.rotation, k.centre),
                        PlacedConvex(face_shape, frame, side.face.point), 1e-13)
      .lower;
}

/// m: a crossing within it of the face's edge's line touches it (the integration's drift and the
/// events' resolution within it); m/s: one opening faster does not.
constexpr double kCrossingBand = 1e-8;
constexpr double kCrossingOpens = 1e-6;

/// The body's flat sides a face's corner may touch: a box's six faces, a cylinder's two caps.
std::vector<FlatSide> flatSidesOf(const ConvexShape& shape) {
  std::vector<FlatSide> sides;
  if (const auto* box = std::get_if<Cuboid>(&shape)) {
    for (int axis = 0; axis < 3; ++axis) {
      for (const double sign : {-1.0, 1.0}) {
        sides.push_back({sign * Vec::Unit(axis), box->half_size[axis]});
      }
    }
  } else if (const auto* cylinder = std::get_if<Cylinder>(&shape)) {
    for (const double sign : {-1.0, 1.0})
      sides.push_back({sign * Vec::UnitZ(), cylinder->half_length});
  }
  return sides;
}

/// How far within the body's flat side `side` the foot of the world point `x` is, and the rate
/// of that as the body moves past the fixed point (m, m/s): a box face's least distance to its
/// edges, a cap's radius less the foot's distance from its centre; < 0 off the side.
std::pair<double, double> withinSide(const Setting& s, const Kinematics& k, std::size_t side,
                                     const Vec& x) {
  const Vec lever = x - k.centre;
  const Vec local = k.rotation.transpose() * lever;
  const Vec rate = k.rotation.transpose() * -(k.velocity + k.spin.cross(lever));
  const FlatSide& flat = s.sides[side];
  if (const auto* box = std::get_if<Cuboid>(&s.shape)) {
    // The nearer edge's; at the side's corner (both within kCrossingBand), the slower inwards.
    std::array<double, 2> margins{}, rates{};
    std::size_t n = 0;
    for (int axis = 0; axis < 3; ++axis) {
      if (std::abs(flat.normal[axis]) > 0.5) continue;
      margins[n] = box->half_size[axis] - std::abs(local[axis]);
      rates[n++] = -(local[axis] < 0 ? -1.0 : 1.0) * rate[axis];
    }
    const double margin = std::min(margins[0], margins[1]);
    double inwards = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < 2; ++i) {
      if (margins[i] <= margin + kCrossingBand) inwards = std::min(inwards, rates[i]);
    }
    return {margin, inwards};
  }
  const double radius = std::get<Cylinder>(s.shape).radius;
  const double from_axis = std::hypot(local.x(), local.y());
  const double outward =
      from_axis > 0 ? (local.x() * rate.x() + local.y() * rate.y()) / from_axis : 0.0;
  return {radius - from_axis, -outward};
}

/// How deep the world point `x` is in the body, by its sides' planes (m: > 0 outside, 0 on its
/// surface): a box's max over its axes of |x_a| - h_a, a cylinder's of |z| - h and its distance
/// from the axis less its radius.
double depthOf(const Setting& s, const Kinematics& k, const Vec& x) {
  const Vec local = k.rotation.transpose() * (x - k.centre);
  if (const auto* box = std::get_if<Cuboid>(&s.shape)) {
    return (local.cwiseAbs() - box->half_size).maxCoeff();
  }
  const auto& cylinder = std::get<Cylinder>(s.shape);
  return std::max(std::abs(local.z()) - cylinder.half_length,
                  std::hypot(local.x(), local.y()) - cylinder.radius);
}

/// Whether a point on the face (not a crossing) is within its bounded extent (kLastingBand).
double withinFace(const Setting& s, const Kinematics& k, const Point& p) {
  const FlatFace& face = sideOf(s, p).face;
  const Vec offset = k.centre + contactOf(s, k, p).lever - face.point;
  return std::min(face.half_extent.x() + kLastingBand - std::abs(offset.dot(face.along_u)),
                  face.half_extent.y() + kLastingBand - std::abs(offset.dot(face.along_v)));
}

/// A point just touching, sliding where it slips (faster than kLastingStillSpeed, or the face
/// is frictionless) and sticking otherwise; its mode kept where `current` has it.
Point withMode(const Setting& s, const Kinematics& k, Point p, const std::vector<Point>& current) {
  for (const Point& q : current) {
    if (q.feature == p.feature && q.line == p.line && q.side == p.side && q.face == p.face &&
        q.corner == p.corner) {
      return q;
    }
  }
  const Vec slip = slipOf(s, k, p);
  p.sliding = sideOf(s, p).mu == 0.0 || slip.norm() > kLastingStillSpeed;
  p.direction = slip.norm() > kLastingStillSpeed ? Vec(slip.normalized()) : contactOf(s, k, p).e1;
  return p;
}

/// The points touching where the body goes on over the face's edges (`crosses`): those of
/// `current` on the face still within it, and every crossing of its edges (a box's) or rims (a
/// cylinder's) with the face's edges' lines that touches (within kCrossingBand), is within its
/// edge or entering it, within the line's length and not opening.
std::vector<Point> touchingAt(const Setting& s, const Kinematics& k,
                              const std::vector<Point>& current) {
  std::vector<Point> points;
  for (const Point& p : current) {
    if (onFace(p) && withinFace(s, k, p) > 0) points.push_back(p);
  }
  const std::size_t parts = s.segments.empty() ? s.features.size() : s.segments.size();
  for (std::size_t l = 0; l < s.lines.size(); ++l) {
    for (std::size_t f = 0; f < parts; ++f) {
      for (const int side : s.segments.empty() ? std::vector<int>{-1, 1} : std::vector<int>{0}) {
        Point p;
        p.feature = f;
        p.line = static_cast<int>(l);
        p.side = side;
        const auto c = crossingOf(s, k, p);
        if (!c || std::abs(c->gap) > kCrossingBand) continue;
        // Within its edge, or at an end moving into it (a box's edge: faster than the rounding
        // of a settled state: its upright edge whose lower end is on the line, sliding along, is
        // not; a rim's tangent to the line, its chord opening, is).
        if (c->inside < kCrossingBand &&
            !(c->inside > -kCrossingBand && c->entering &&
              (s.segments.empty() || std::abs(c->along_feature) > kCrossingOpens))) {
          continue;
        }
        const Vec velocity = k.velocity + k.spin.cross(c->point - k.centre);
        // Within the line's length, or at an end (the face's corner) moving along it inwards.
        const double end = s.lines[l].half_length - std::abs(c->on_line);
        const double inwards =
            -std::copysign(1.0, c->on_line) * (c->over + velocity).dot(s.lines[l].edge.along);
        if (end < kCrossingBand && !(end > -kCrossingBand && inwards > 0)) continue;
        if (c->normal.dot(velocity) > kCrossingOpens) continue;
        points.push_back(withMode(s, k, p, current));
      }
    }
  }
  // The face's corners on a flat side of the body (within it, or at its edge moving into it).
  for (std::size_t j = 0; j < s.corners.size(); ++j) {
    for (std::size_t side = 0; side < s.sides.size(); ++side) {
      Point p;
      p.corner = static_cast<int>(j);
      p.feature = side;
      const Contact c = contactOf(s, k, p);
      if (std::abs(c.gap) > kCrossingBand) continue;
      const auto [within, entering] = withinSide(s, k, side, c.on);
      if (within < kCrossingBand && !(within > -kCrossingBand && entering > kCrossingOpens)) {
        continue;
      }
      if (c.normal.dot(k.velocity + k.spin.cross(c.lever)) > kCrossingOpens) continue;
      points.push_back(withMode(s, k, p, current));
    }
  }
  return points;
}

/// The events that end a segment where something new touches (the body's events take over, or
/// the points are found again): the face's corner reaching the body (`below`'s last four: where
/// it comes back 1e-12 m below where it was, as the features'), another feature reaching the face
/// (one below it as the segment began, one that just left: `below`), a touching rim's cap landing
/// flat (where its tilt, signed along where its point touched at the step's start `start`, passes
/// `flat`: 0, or 1e-12 m below a segment's start flat), and, lifted off, the lowest feature
/// `clearance` above the face.
void arrivalEvents(const Setting& s, const std::vector<Point>& current, const Above& above,
                   const std::vector<double>& below, const std::vector<double>& flat,
                   double clearance, const Kinematics& start, std::vector<Event>& events) {
  for (std::size_t j = 0; j < s.corners.size(); ++j) {
    // A corner of the face that is neither touching nor an end of a line a crossing is on
    // (that crossing's end event takes it) reaching the body: it resumes.
    const bool taken = std::any_of(current.begin(), current.end(), [&](const Point& p) {
      if (p.corner == static_cast<int>(j)) return true;
      if (p.line < 0) return false;
      const Setting::Line& line = s.lines[static_cast<std::size_t>(p.line)];
      return std::abs((s.corners[j] - line.edge.point).dot(line.edge.along)) >=
                 line.half_length - kCrossingBand &&
             (s.corners[j] - line.edge.point).cross(line.edge.along).norm() <= kCrossingBand;
    });
    if (taken) continue;
    const double was = below[s.faces.size() * s.features.size() + j];
    const double level = was <= 0 ? was - 1e-12 : 0.0;
    events.push_back({What::kCorner, 0, [&s, j, level](const Kinematics& x) {
                        return depthOf(s, x, s.corners[j]) - level;
                      }});
  }
  for (std::size_t face = 0; face < s.faces.size(); ++face) {
    for (std::size_t c = 0; c < s.features.size(); ++c) {
      bool touching = false;
      for (const Point& p : current) {
        touching = touching || (onFace(p) && p.feature == c && p.face == face);
      }
      if (touching) continue;
      const double was = below[face * s.features.size() + c];
      const double level = was <= 0 ? was - 1e-12 : 0.0;
      events.push_back(
          {What::kCorner, 0, [&above, face, &feature = s.features[c], level](const Kinematics& x) {
             return above(x, face, feature) - level;
           }});
    }
  }
  for (std::size_t i = 0; i < current.size(); ++i) {
    const Vec towards = rimTowards(s, start, current[i]);
    const double level = flat[i];
    if (towards.isZero()) continue;
    events.push_back({What::kCorner, 0,
                      [&rim = s.features[current[i].feature], towards, level](const Kinematics& x) {
                        return capTilt(x, rim, towards) - level;
                      }});
  }
  if (current.empty()) {
    // Lifted off: flying until its lowest feature is kPivotClearance of its reach above the
    // face (the certified first contact takes it from there) or one lands.
    events.push_back({What::kClear, 0, [&s, clearance](const Kinematics& x) {
                        return clearance - clearanceOf(s, x);
                      }});
  }
}

/// Point i's events of its force: it leaves (its normal force 0), a sticking point leaves its
/// cone, a sliding one's slip stops (from `start`, the step's start).
void forceEvents(const Setting& s, const std::vector<Point>& current, std::size_t i,
                 const Kinematics& start, std::vector<Event>& events) {
  events.push_back({What::kLeaves, i, [&s, &current, i](const Kinematics& x) {
                      return normalForce(dynamicsOf(s, x, current), i);
                    }});
  if (!current[i].sliding) {
    // Bisected to where the margin is < 0: there the modes' choice slides it.
    events.push_back({What::kSlips, i, [&s, &current, i](const Kinematics& x) {
                        const double margin = coneMarginOf(dynamicsOf(s, x, current), i);
                        return margin < 0 ? margin : std::max(margin, 1e-300);
                      }});
  } else if (sideOf(s, current[i]).mu > 0) {
    // Its slip stops: it falls to kSlipStops (its direction would turn ever faster as it
    // passes near 0); a slip just begun (slower at the step's start) stops where its part
    // along the onset's direction falls below -kLastingStillSpeed.
    const Vec before = slipOf(s, start, current[i]);
    if (before.norm() > kSlipStops) {
      events.push_back({What::kSticks, i, [&s, &current, i](const Kinematics& x) {
                          return slipOf(s, x, current[i]).norm() - kSlipStops;
                        }});
    } else {
      const Vec reference =
          before.norm() > kLastingStillSpeed ? Vec(before.normalized()) : current[i].direction;
      events.push_back({What::kSticks, i, [&s, &current, i, reference](const Kinematics& x) {
                          return slipOf(s, x, current[i]).dot(reference) + kLastingStillSpeed;
                        }});
      // ... or where the force that would hold it comes back within its cone (a slip that
      // began at the cone's edge and does not grow: it would hover below kSlipStops, its
      // friction's direction turning ever faster).
      std::vector<Point> held = current;
      held[i].sliding = false;
      events.push_back({What::kSticks, i, [&s, held, i](const Kinematics& x) {
                          const double margin = coneMarginOf(dynamicsOf(s, x, held), i);
                          return margin >= 0 ? -std::max(margin, 1e-300) : -margin;
                        }});
    }
  }
}

/// Point i's events of where it is: a crossing leaving its edge or reaching an end of the face's
/// edge (past `ends`, as `flat`), the face's corner leaving the body's side, a point on the face
/// reaching its bounded edge.
void placeEvents(const Setting& s, const std::vector<Point>& current, std::size_t i,
                 const std::vector<double>& flat, const std::vector<double>& ends,
                 std::vector<Event>& events) {
  if (current[i].line >= 0) {
    // Its crossing leaves its edge (at a corner) or the rim's chord vanishes, or it passes an
    // end of the face's edge (onto the face's corner): the points are found again there.
    const double level = flat[i], end = ends[i];
    events.push_back({What::kShift, i, [&s, &current, i, level](const Kinematics& x) {
                        const auto c = crossingOf(s, x, current[i]);
                        return c ? c->inside - level : -1.0;
                      }});
    events.push_back({What::kShift, i, [&s, &current, i, end](const Kinematics& x) {
                        const auto c = crossingOf(s, x, current[i]);
                        const auto& line = s.lines[static_cast<std::size_t>(current[i].line)];
                        return c ? line.half_length - std::abs(c->on_line) - end : -1.0;
                      }});
  } else if (current[i].corner >= 0) {
    // The face's corner leaves the body's side (over its edge or rim): found again there.
    const double level = flat[i];
    events.push_back(
        {What::kShift, i, [&s, &current, i, level](const Kinematics& x) {
           const Point& p = current[i];
           return withinSide(s, x, p.feature, s.corners[static_cast<std::size_t>(p.corner)]).first -
                  level;
         }});
  } else if (sideOf(s, current[i]).face.bounded) {
    events.push_back(
        {s.crosses ? What::kShift : What::kEdge, i,
         [&s, &current, i](const Kinematics& x) { return withinFace(s, x, current[i]); }});
  }
}

/// The events of a step of the segment with `current` touching, from `start` (the state at the
/// step's start): arrivalEvents, then each point's forceEvents and placeEvents (in this order:
/// of events at one instant, the first listed is taken).
std::vector<Event> eventsOf(const Setting& s, const std::vector<Point>& current, const Above& above,
                            const std::vector<double>& below, const std::vector<double>& flat,
                            const std::vector<double>& ends, double clearance,
                            const Kinematics& start) {
  std::vector<Event> events;
  arrivalEvents(s, current, above, below, flat, clearance, start, events);
  for (std::size_t i = 0; i < current.size(); ++i) {
    forceEvents(s, current, i, start, events);
    placeEvents(s, current, i, flat, ends, events);
  }
  return events;
}

/// The first event over a step (t0, t1] of the dense output `at`, bisected to kEventResolution
/// (the instant and the event's index); one already at its start is taken at t0. Empty: none.
template <class At>
std::optional<std::pair<double, std::size_t>> firstEvent(const std::vector<Event>& events,
                                                         const At& at, double t0, double t1) {
  std::optional<std::pair<double, std::size_t>> first;
  for (std::size_t e = 0; e < events.size(); ++e) {
    if (events[e].value(at(t1)) > 0) continue;
    if (events[e].value(at(t0)) <= 0) {
      // Already at its start (a point that left at once, a corner touching as it began).
      return std::make_pair(t0, e);
    }
    double lo = t0, hi = t1;
    while (hi - lo > kEventResolution * std::max(1.0, std::abs(hi))) {
      const double mid = 0.5 * (lo + hi);
      if (events[e].value(at(mid)) > 0) {
        lo = mid;
      } else {
        hi = mid;
      }
    }
    if (!first || hi < first->first) first = std::make_pair(hi, e);
  }
  return first;
}

/// Of a rim's radius: a chord of a rim on the face's edge shorter than it (half of it) has its two
/// ends' forces ill-conditioned: the moment they hold across the edge costs forces as 1 / its
/// length squared, and an end leaves on rounding. Where one end of such a chord leaves, the
/// other leaves with it: the rim passes the edge there (doc/model.md, "At an angle to the edge").
constexpr double kShortChord = 0.05;

/// Whether `other` is the other end of `leaving`'s chord (the same rim on the same edge) and that
/// chord is short (kShortChord).
bool shortChord(const Setting& s, const Kinematics& k, const Point& leaving, const Point& other) {
  if (!s.segments.empty() || leaving.line < 0 || other.line != leaving.line ||
      other.feature != leaving.feature || other.side == leaving.side) {
    return false;
  }
  const auto c = crossingOf(s, k, other);
  const double radius = s.features[other.feature].radius;
  return c && c->inside * (2 * radius - c->inside) < kShortChord * kShortChord * radius * radius;
}

/// holdingForces' weight of friction against the normal forces: the normal forces carry what they
/// can, friction the rest (shared as mu N).
constexpr double kFrictionShare = 1e-6;

/// Against several faces, the body still: forces that hold it with every point of a face with
/// friction sticking (a frictionless face's sliding), where there are such within every cone.
/// Where friction is statically indeterminate, each point's friction is taken in proportion to
/// mu N there: the least-norm forces in the unknowns, a friction unknown divided by
/// kFrictionShare sqrt(mu N / mean N) with N the previous round's normal force (four rounds,
/// from the least-norm forces): the closed forms' rule, each point's friction in proportion to
/// its normal force, for faces of different mu. Empty where those do not hold it (a normal force
/// < 0, a force outside its cone, an acceleration past 1e-12 of gravity's).
std::optional<std::vector<Vec>> holdingForces(const Setting& s, const Kinematics& k,
                                              std::vector<Point> points) {
  for (Point& p : points) p.sliding = sideOf(s, p).mu == 0.0;
  const Eigen::Matrix3d inverse_inertia =
      k.rotation * s.moments.cwiseInverse().asDiagonal() * k.rotation.transpose();
  const std::vector<Contact> contacts = contactsOf(s, k, points);
  const std::vector<Vec> free(points.size(), s.gravity);
  const auto columns = columnsOf(s, k, points, contacts, kSlipStops);
  std::vector<double> scales(columns.size(), 1.0);
  std::vector<Vec> forces;
  for (int round = 0; round < 4; ++round) {
    forces = solveConditions(s, points, contacts, columns, free, inverse_inertia, false, scales);
    double mean = 0.0;
    for (std::size_t i = 0; i < points.size(); ++i) mean += forces[i].dot(contacts[i].normal);
    mean /= static_cast<double>(points.size());
    if (!(mean > 0)) return std::nullopt;
    for (std::size_t c = 0; c < columns.size(); ++c) {
      const std::size_t i = columns[c].first;
      const double normal = forces[i].dot(contacts[i].normal);
      const bool tangential = std::abs(columns[c].second.dot(contacts[i].normal)) < 0.5;
      scales[c] =
          tangential
              ? kFrictionShare *
                    std::sqrt(std::max(sideOf(s, points[i]).mu * normal, 1e-12 * mean) / mean)
              : 1.0;
    }
  }
  Vec total = Vec::Zero(), moment = Vec::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    // (To rounding: 1e-12 of the weight; a point that carries nothing has no force to hold.)
    const double rounding = 1e-12 * s.mass * s.gravity.norm();
    const double normal = forces[i].dot(contacts[i].normal);
    if (normal < -rounding ||
        coneMargin(sideOf(s, points[i]).mu, contacts[i].normal, forces[i]) < -rounding) {
      return std::nullopt;
    }
    total += forces[i];
    moment += contacts[i].lever.cross(forces[i]);
  }
  double reach = 0.0;
  for (const Feature& f : s.features) reach = std::max(reach, f.centre.norm() + f.radius);
  const double held = 1e-12 * s.gravity.norm();
  if ((s.gravity + total / s.mass).norm() > held ||
      (inverse_inertia * moment).norm() * reach > held) {
    return std::nullopt;
  }
  return forces;
}

/// Against several faces: whether the body is still (its centre and its reach's turning slower
/// than kLastingStillSpeed) and its points hold it there (holdingForces): at rest (a box in a
/// corner, a plank leaning on a wall whose floor's friction holds it).
bool restingAt(const Setting& s, const Kinematics& k, const std::vector<Point>& points) {
  double reach = 0.0;
  for (const Feature& f : s.features) reach = std::max(reach, f.centre.norm() + f.radius);
  return !points.empty() && k.velocity.norm() <= kLastingStillSpeed &&
         k.spin.norm() * reach <= kLastingStillSpeed && holdingForces(s, k, points).has_value();
}

/// What a point's event (it leaves, sticks or slips) does at its instant: the points touching
/// after it and the state there (a stop's slip taken out), or why the motion ends (`ends`), or
/// that it rests (a face whose every corner sticks).
struct Change {
  std::string ends;    // empty: the motion goes on with `points` from `there`
  bool rests = false;  // at rest from `there` (the closed forms take it from there)
  std::vector<Point> points;
  Kinematics there;
};

Change changeAt(const Setting& s, const std::vector<Point>& current, What what, std::size_t point,
                Kinematics there) {
  Change change;
  std::vector<Point> next = current;
  if (what == What::kLeaves && !onFace(current[point])) {
    // A crossing of the face's edge (or its corner on the body) leaves, and with it every other
    // one whose normal force is 0 there to rounding (1e-9 of the weight): a chord's two ends
    // leave together where the body is symmetric about the chord's middle, as the planar model
    // has it.
    const Dynamics d = dynamicsOf(s, there, current);
    next.clear();
    for (std::size_t i = 0; i < current.size(); ++i) {
      const bool leaves = i == point || (!onFace(current[i]) &&
                                         (normalForce(d, i) <= 1e-9 * s.mass * s.gravity.norm() ||
                                          shortChord(s, there, current[point], current[i])));
      if (!leaves) next.push_back(current[i]);
    }
  } else if (what == What::kLeaves) {
    next.erase(next.begin() + static_cast<std::ptrdiff_t>(point));
    next = liftedCap(s, there, std::move(next));
  } else if (what == What::kSticks) {
    next[point].sliding = false;
    // A face's corners (three or more) stop slipping together (Goyal, Ruina and
    // Papadopoulos, Wear 143:307, 1991: a planar slide's translation and turning stop at the
    // same instant): where every one slips slower than 100 kSlipStops, all stick.
    // (Against several faces, the corners of the face of the point that sticks.)
    const std::size_t face = next[point].face;
    double fastest = 0.0;
    std::size_t of_face = 0;
    for (const Point& p : next) {
      if (p.face != face) continue;
      fastest = std::max(fastest, slipOf(s, there, p).norm());
      ++of_face;
    }
    if (of_face >= 3 && fastest <= 100 * kSlipStops) {
      for (Point& p : next) p.sliding = p.sliding && p.face != face;
      // Stopped together on the face: where its friction can hold the body there (|g_t| <=
      // mu g_n, the closed forms' rule) it rests, whichever of the statically indeterminate
      // distributions holds it (the least-norm one may put a corner past its cone, which
      // would slip again, stop again, for ever: stick and slip chattering at nanoseconds).
      const Side& side = s.faces.front();
      const double g_n = -s.gravity.dot(side.n);
      const Vec g_t = s.gravity + g_n * side.n;
      const bool on_face =
          std::all_of(next.begin(), next.end(), [](const Point& p) { return onFace(p); });
      if (s.faces.size() == 1 && on_face && g_n > 0 && g_t.norm() <= side.mu * g_n) {
        change.points = next;
        change.rests = true;
        change.there = settle(s, there, next);
        return change;
      }
      // Against several faces, or over the face's edges: where forces within every cone hold it
      // (restingAt), whichever the least-norm ones are.
      const Kinematics stopped = settle(s, there, next);
      if ((s.faces.size() > 1 || s.crosses) && restingAt(s, stopped, next)) {
        change.points = next;
        change.rests = true;
        change.there = stopped;
        return change;
      }
    }
    there = settle(s, there, next);  // the slip's rounding left at its stop
  } else if (what == What::kShift) {
    // Where a crossing moves onto another edge of the body, or a point on the face passes its
    // edge: the points touching found again, their normal motion settled.
    next = touchingAt(s, there, current);
    there = settle(s, there, next);
  } else {
    auto onset = slipOnset(s, there, next, point);
    if (!onset) {
      change.ends = "a corner starting to slip with no direction of onset";
      return change;
    }
    next[point].sliding = true;
    next[point].direction = *onset;
  }
  auto settled = modesAt(s, there, next);
  if (!settled) {
    change.ends = settled.error().reason;
    return change;
  }
  change.points = std::move(settled.value());
  // A face whose every corner sticks: it rests, as the closed forms say (lastingOnFace), its last
  // slip (within the event's resolution) taken out.
  // (A crossing of the face's edge only where the body's face is flat on the face.)
  // Against several faces, or over the face's edges: where it is still and its points hold it
  // (restingAt).
  change.rests =
      (change.points.size() >= 3 &&
       std::none_of(change.points.begin(), change.points.end(),
                    [&](const Point& p) {
                      return p.sliding ||
                             (!onFace(p) &&
                              contactOf(s, there, p).normal.dot(s.faces.front().n) < 1.0 - 1e-12);
                    })) ||
      ((s.faces.size() > 1 || s.crosses) && restingAt(s, there, change.points));
  change.there = change.rests ? settle(s, there, change.points) : there;
  return change;
}

/// The least translation that puts each point touching (on the face, or a crossing of its edge)
/// kPivotHair apart along its own normal: the integration's drift taken out.
Vec hairApart(const Setting& s, const Kinematics& k, const std::vector<Point>& points) {
  Eigen::MatrixXd rows(points.size(), 3);
  Eigen::VectorXd gaps(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Contact c = contactOf(s, k, points[i]);
    const auto r = static_cast<Eigen::Index>(i);
    rows.row(r) = c.normal.transpose();
    const Side& side = sideOf(s, points[i]);
    gaps(r) = kPivotHair -
              (!onFace(points[i]) ? c.gap : side.n.dot(k.centre + c.lever - side.face.point));
  }
  // Normals that differ by rounding (a chord's two ends on one face) count as one.
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> solver;
  solver.setThreshold(1e-6);
  solver.compute(rows);
  return solver.solve(gaps);
}

/// Against several faces: the least translation that puts each face's lowest feature a hair
/// (kPivotHair) above it, of the faces it touches or whose lowest feature is below the hair (as
/// one face's rule, each along its own normal).
Vec hairOver(const Setting& s, const Kinematics& k, const std::vector<Point>& points) {
  std::vector<std::pair<Vec, double>> apart;
  for (std::size_t face = 0; face < s.faces.size(); ++face) {
    const Side& side = s.faces[face];
    double lowest = std::numeric_limits<double>::infinity();
    for (const Feature& f : s.features) lowest = std::min(lowest, heightOf(side, k, f));
    const bool touching =
        std::any_of(points.begin(), points.end(), [&](const Point& p) { return p.face == face; });
    if (touching || lowest < kPivotHair) apart.emplace_back(side.n, kPivotHair - lowest);
  }
  if (apart.empty()) return Vec::Zero();
  Eigen::MatrixXd rows(apart.size(), 3);
  Eigen::VectorXd gaps(apart.size());
  for (std::size_t i = 0; i < apart.size(); ++i) {
    rows.row(static_cast<Eigen::Index>(i)) = apart[i].first.transpose();
    gaps(static_cast<Eigen::Index>(i)) = apart[i].second;
  }
  return rows.completeOrthogonalDecomposition().solve(gaps);
}

}  // namespace

/// The path's steps: each a copy of the dense stepper after it (its dense output covers it), with
/// the points touching over it.
struct PivotPath::Steps {
  Setting setting;
  double start = 0.0;
  double until = 0.0;
  Kinematics initial;
  std::vector<Point> initial_points;
  /// The state from `until` on where the motion ends at rest on a face (every corner sticking,
  /// its last slip taken out): the closed forms take it from there.
  std::optional<Kinematics> final;
  struct Step {
    Dense dense;
    double to = 0.0;     // the step holds over (dense.previous_time(), to]
    std::size_t points;  // into modes
  };
  std::vector<Step> steps;
  std::vector<std::vector<Point>> modes;
};

PivotPath::PivotPath(std::unique_ptr<Steps> steps) : steps_(std::move(steps)) {}
PivotPath::~PivotPath() = default;
double PivotPath::start() const { return steps_->start; }
double PivotPath::until() const { return steps_->until; }
std::size_t PivotPath::steps() const { return steps_->steps.size(); }

PathState PivotPath::stateAt(double t) const {
  const Steps& path = *steps_;
  const double time = std::clamp(t, path.start, path.until);
  Kinematics k = path.initial;
  const std::vector<Point>* points = &path.initial_points;
  if (path.final && time >= path.until) {
    k = *path.final;
    points = &path.modes.back();
  }
  const auto covering =
      std::lower_bound(path.steps.begin(), path.steps.end(), time,
                       [](const Steps::Step& step, double at) { return step.to < at; });
  if (!path.steps.empty() && time > path.start && !(path.final && time >= path.until)) {
    const Steps::Step& step = covering == path.steps.end() ? path.steps.back() : *covering;
    State y;
    step.dense.calc_state(std::clamp(time, step.dense.previous_time(), step.to), y);
    k = unpack(y);
    points = &path.modes[step.points];
  }
  const Setting& s = path.setting;
  // The lowest feature a hair (kPivotHair) above the face: the integration's drift of the
  // points' height (within its tolerance) is taken out along n, and no feature is below the face
  // (one that reaches it ends the motion: its events take over from a body touching, never
  // overlapping, even by the distance's tolerance against a box). Lifted off (no point
  // touching), only a feature below the hair is lifted.
  // On the face's edge, each point touching is put a hair apart along its own normal (the
  // least translation that does so). Features off the face (past its edges) are not on it.
  const bool crossing =
      std::any_of(points->begin(), points->end(), [](const Point& p) { return !onFace(p); });
  if (crossing) {
    k.centre += hairApart(s, k, *points);
    // ... and no feature over the face below the hair (the crossings' normals turned with the
    // body: their shift may lower a corner on the face's side).
    const Side& side = s.faces.front();
    double lowest = std::numeric_limits<double>::infinity();
    for (const Feature& f : s.features) {
      if (offFace(s, k, f) < 0) lowest = std::min(lowest, heightOf(side, k, f));
    }
    if (lowest < kPivotHair) k.centre += (kPivotHair - lowest) * side.n;
  } else if (s.faces.size() == 1) {
    const Side& side = s.faces.front();
    double lowest = std::numeric_limits<double>::infinity();
    for (const Feature& f : s.features) {
      if (offFace(s, k, f) < 0) lowest = std::min(lowest, heightOf(side, k, f));
    }
    if (!points->empty() || lowest < kPivotHair) k.centre += (kPivotHair - lowest) * side.n;
  } else {
    k.centre += hairOver(s, k, *points);
  }
  PathState state;
  state.centre = k.centre;
  state.velocity = k.velocity;
  state.angular_velocity = k.spin;
  state.orientation = k.orientation;
  std::vector<Vec> forces = dynamicsOf(s, k, *points).forces;
  if ((s.faces.size() > 1 || s.crosses) && path.final && time >= path.until) {
    // At rest against several faces, or over the face's edges: the forces that hold it
    // (holdingForces).
    if (const auto held = holdingForces(s, k, *points)) forces = *held;
  }
  bool sliding = false;
  for (std::size_t i = 0; i < points->size(); ++i) {
    const Point& p = (*points)[i];
    sliding = sliding || p.sliding;
    SupportForce force;
    const Contact c = contactOf(s, k, p);
    if (!onFace(p)) {
      force.point = c.on;
      force.normal = c.normal;
      force.normal_force = forces[i].dot(c.normal);
      force.friction_force = forces[i] - force.normal_force * c.normal;
    } else {
      const Side& side = sideOf(s, p);
      const Vec at = k.centre + c.lever;
      force.point = at - side.n.dot(at - side.face.point) * side.n;
      force.normal_force = forces[i].dot(side.n);
      force.friction_force = forces[i] - force.normal_force * side.n;
      force.face = p.face;
    }
    state.forces.push_back(force);
  }
  state.state = sliding ? ContactState::kSliding : ContactState::kRolling;
  return state;
}

namespace {

/// The body's state as the integration holds it.
Kinematics kinematicsOf(const LastingBody& body) {
  Kinematics k;
  k.orientation = body.orientation.normalized();
  k.rotation = k.orientation.toRotationMatrix();
  k.centre = body.centre;
  k.velocity = body.velocity;
  k.spin = body.angular_velocity;
  return k;
}

/// The motion's start: the body's state as `k`, `touching` touching, each sliding where it slips
/// (faster than kLastingStillSpeed, or the face is frictionless) and sticking with its slip
/// taken out otherwise (settle), then the modes the forces there allow (modesAt).
Expected<std::vector<Point>> startOf(const Setting& s, const LastingBody& body,
                                     std::vector<Point> touching, Kinematics& k) {
  k = kinematicsOf(body);
  std::vector<Point> points;
  for (const Point& p : touching) points.push_back(withMode(s, k, p, {}));
  k = settle(s, k, points);
  return modesAt(s, k, points);
}

/// How a segment of the motion (one set of points touching) ended: at `until`, by an event
/// (`what`, of point `point`, the state there), at the horizon, or where the steps ran out.
struct SegmentEnd {
  double until = 0.0;
  std::optional<What> what;
  std::size_t point = 0;
  std::optional<Kinematics> there;  // with `what`
};

/// Integrates the segment of `path`'s mode `mode` from `y` at `t` to its first event, `end` or
/// kMaxSteps (counted in `taken`), each step's dense output kept in `path`.
Expected<SegmentEnd> integrateSegment(const Setting& s, PivotPath::Steps& path, std::size_t mode,
                                      const State& y, double t, double end, double tolerance,
                                      double clearance, std::size_t& taken) {
  const std::vector<Point> current = path.modes[mode];
  const auto system = [&s, &current](const State& x, State& rate, double) {
    derivative(s, current, x, rate);
  };
  const Above above{s, current};
  // A feature below the lowest point touching at the segment's start (one that just left)
  // reaches the face where it comes back 1e-12 m below where it was; a touching rim's cap lands
  // where its tilt passes 0, or 1e-12 m below where it began if flat or past.
  const Kinematics initial = unpack(y);
  std::vector<double> below;
  for (std::size_t face = 0; face < s.faces.size(); ++face) {
    for (const Feature& f : s.features) below.push_back(std::min(0.0, above(initial, face, f)));
  }
  for (const Vec& corner : s.corners) below.push_back(std::min(0.0, depthOf(s, initial, corner)));
  // Where one is at or past its limit as the segment begins (one just entering): 1e-12 m beyond.
  const auto beyond = [](double within) { return within <= 1e-12 ? within - 1e-12 : 0.0; };
  std::vector<double> flat, ends(current.size(), 0.0);
  for (std::size_t i = 0; i < current.size(); ++i) {
    const Point& p = current[i];
    if (p.line >= 0) {
      // A crossing's: how far within its edge, where it leaves it, and within the face's edge.
      const auto c = crossingOf(s, initial, p);
      flat.push_back(beyond(c ? c->inside : 0.0));
      const double half = s.lines[static_cast<std::size_t>(p.line)].half_length;
      ends[i] = beyond(c ? half - std::abs(c->on_line) : 0.0);
      continue;
    }
    if (p.corner >= 0) {
      // The face's corner's: how far within the body's side.
      flat.push_back(beyond(
          withinSide(s, initial, p.feature, s.corners[static_cast<std::size_t>(p.corner)]).first));
      continue;
    }
    const Vec towards = rimTowards(s, initial, p);
    const double tilt = towards.isZero() ? 0.0 : capTilt(initial, s.features[p.feature], towards);
    flat.push_back(tilt <= 1e-12 ? tilt - 1e-12 : 0.0);
  }
  Dense dense = boost::numeric::odeint::make_dense_output(tolerance, tolerance, Stepper());
  dense.initialize(y, t, 1e-4);
  for (;;) {
    if (++taken > kMaxSteps) return SegmentEnd{t, std::nullopt, 0, std::nullopt};
    try {
      dense.do_step(system);
    } catch (const std::exception&) {
      return Error{"contact", "the tipping motion could not be integrated past +" +
                                  formatNumber(t - path.start) + " s"};
    }
    const double t0 = dense.previous_time();
    const double t1 = std::min(dense.current_time(), end);
    const auto at = [&](double time) {
      State x;
      dense.calc_state(time, x);
      return unpack(x);
    };
    const std::vector<Event> events =
        eventsOf(s, current, above, below, flat, ends, clearance, at(t0));
    const auto first = firstEvent(events, at, t0, t1);
    path.steps.push_back({dense, first ? first->first : t1, mode});
    if (first) {
      const Event& event = events[first->second];
      return SegmentEnd{first->first, event.what, event.point, at(first->first)};
    }
    t = t1;
    if (t1 >= end) return SegmentEnd{end, std::nullopt, 0, std::nullopt};
  }
}

/// The body and the faces as the motion sees them: its features (featuresOf), none for a ball.
std::unique_ptr<PivotPath::Steps> pathFor(const LastingBody& body,
                                          const std::vector<FlatFace>& faces) {
  auto path = std::make_unique<PivotPath::Steps>();
  Setting& s = path->setting;
  s.moments = body.moments;
  s.mass = body.mass;
  s.gravity = body.gravity;
  for (const FlatFace& face : faces) {
    Side side;
    side.face = face;
    side.n = face.normal.normalized();
    side.e1 = side.n.unitOrthogonal();
    side.e2 = side.n.cross(side.e1);
    side.mu = face.friction;
    s.faces.push_back(side);
  }
  s.features = featuresOf(body.shape);
  s.shape = body.shape;
  // A box or a cylinder goes on over one bounded face's edges (its edges or rims crossing them).
  const FlatFace& face = faces.front();
  s.crosses =
      faces.size() == 1 && face.bounded &&
      (std::holds_alternative<Cuboid>(body.shape) || std::holds_alternative<Cylinder>(body.shape));
  if (s.crosses) {
    for (const BoundEdge& bound : edgesOf(face)) {
      s.lines.push_back(
          {bound.edge.point, bound.edge.along, bound.edge.out, face.half_extent[1 - bound.axis]});
    }
    for (const double u : {-1.0, 1.0}) {
      for (const double v : {-1.0, 1.0}) {
        s.corners.push_back(face.point + u * face.half_extent.x() * face.along_u +
                            v * face.half_extent.y() * face.along_v);
      }
    }
    s.sides = flatSidesOf(body.shape);
  }
  if (s.crosses && std::holds_alternative<Cuboid>(body.shape)) {
    for (std::size_t c = 0; c < 8; ++c) {
      for (std::size_t bit = 1; bit < 8; bit <<= 1) {
        if ((c & bit) == 0) s.segments.push_back({c, c | bit});
      }
    }
  }
  return path;
}

/// Against several faces, still and held from the path's start: at rest there for ever (its
/// velocity's rounding taken out), the forces its points hold it with.
LastingMotion restingFrom(std::unique_ptr<PivotPath::Steps> path) {
  path->initial.velocity.setZero();
  path->initial.spin.setZero();
  path->final = path->initial;
  path->until = path->start;
  const PivotPath still(std::move(path));
  const PathState there = still.stateAt(still.start());
  LastingMotion rest;
  rest.state = ContactState::kResting;
  rest.start = still.start();
  rest.centre0 = there.centre;
  rest.orientation0 = there.orientation;
  rest.forces = there.forces;
  return rest;
}

/// The motion of the body of `path` (pathFor) from `touching` touching the face.
Expected<LastingMotion> pivotFrom(const LastingBody& body, std::unique_ptr<PivotPath::Steps> path,
                                  const std::vector<Point>& touching, double tolerance,
                                  double horizon) {
  if (!(tolerance > 0 && std::isfinite(tolerance))) {
    return Error{"tolerance", "must be finite and > 0, got " + formatNumber(tolerance)};
  }
  const Setting& s = path->setting;
  double reach = 0.0;
  for (const Feature& f : s.features) reach = std::max(reach, f.centre.norm() + f.radius);
  const double clearance = kPivotClearance * reach;

  path->start = body.time;
  if (s.faces.size() > 1 || s.crosses) {
    // Still against several faces, or over the face's edges, and held there (restingAt): at
    // rest, each point of a face with friction sticking, its slip's rounding taken out.
    std::vector<Point> held = touching;
    for (Point& p : held) {
      p.sliding = sideOf(s, p).mu == 0.0;
      p.direction = sideOf(s, p).e1;
    }
    const Kinematics still = kinematicsOf(body);
    if (restingAt(s, still, held)) {
      path->initial = settle(s, still, held);
      path->initial_points = held;
      path->modes.push_back(held);
      return restingFrom(std::move(path));
    }
  }
  Kinematics k;
  auto start = startOf(s, body, touching, k);
  if (!start) return start.error();
  const std::vector<Point> points = std::move(start.value());
  path->initial = k;
  path->initial_points = points;
  path->modes.push_back(points);

  const double end = body.time + horizon;
  double t = body.time;
  State y = pack(k);
  std::size_t mode = 0;
  std::string ends = "stops";
  double last_change = -std::numeric_limits<double>::infinity();
  int changes_at_once = 0;
  double until = end;
  std::size_t taken = 0;
  for (;;) {
    auto segment = integrateSegment(s, *path, mode, y, t, end, tolerance, clearance, taken);
    if (!segment) return segment.error();
    until = t = segment->until;
    if (!segment->what) break;  // the horizon, or the steps ran out: asked again from there
    const What what = *segment->what;
    if (what == What::kCorner || what == What::kClear) {
      ends = "resumes";
      break;
    }
    if (what == What::kEdge) {
      ends = "a point of its support reaches the face's edge";
      break;
    }
    if (what == What::kShift) {
      changes_at_once = until == last_change ? changes_at_once + 1 : 0;
      last_change = until;
      if (changes_at_once > 8) {
        return notYet("the points on the face's edge change at once, again and again");
      }
    }
    // (A point leaving at once is one whose force is 0 there: the centre of pressure on the
    // face's edge; the points only grow fewer.)
    if (until <= path->start && what != What::kSticks && what != What::kShift &&
        what != What::kLeaves) {
      return notYet("the tipping's contact changes at once where it starts");
    }
    Change change = changeAt(s, path->modes[mode], what, segment->point, *segment->there);
    if (!change.ends.empty()) {
      ends = change.ends;
      break;
    }
    path->modes.push_back(change.points);
    if (change.rests) {
      path->final = change.there;
      break;
    }
    mode = path->modes.size() - 1;
    y = pack(change.there);
  }
  path->until = until;
  return LastingMotion::integrated(std::make_shared<const PivotPath>(std::move(path)), until, ends);
}

}  // namespace

Expected<LastingMotion> pivotOnFace(const LastingBody& body, const FlatFace& face,
                                    const std::vector<Eigen::Vector3d>& corners, double tolerance,
                                    double horizon) {
  if (corners.empty() || corners.size() > kPivotMaxPoints) {
    return Error{"corners", "must be one to " + std::to_string(kPivotMaxPoints) +
                                " of the body's corners, got " + std::to_string(corners.size())};
  }
  if (!std::holds_alternative<Cuboid>(body.shape) &&
      !std::holds_alternative<ConvexHull>(body.shape)) {
    return Error{"body.shape", "corners are a box's or a hull's (a round body: pivotOnRound)"};
  }
  auto path = pathFor(body, {face});
  std::vector<Point> touching;
  for (const Vec& corner : corners) {
    const auto& features = path->setting.features;
    const auto found = std::find_if(features.begin(), features.end(), [&](const Feature& f) {
      return (f.centre - corner).norm() == 0.0;
    });
    if (found == features.end()) {
      return Error{"corners", "each must be one of the body's corners"};
    }
    touching.push_back({static_cast<std::size_t>(found - features.begin())});
  }
  return pivotFrom(body, std::move(path), touching, tolerance, horizon);
}

namespace {

/// The points by which feature `f` of the body may touch face `face`: a corner or a capsule's end
/// itself; a cylinder's rim its lowest point over the face, or, its cap flat on the face, four
/// points of it fixed in the body (spinOnCap's).
std::vector<Point> pointsOf(const Setting& s, const Kinematics& k, std::size_t face,
                            std::size_t f) {
  const Feature& feature = s.features[f];
  Point p;
  p.feature = f;
  p.face = face;
  if (feature.radius == 0.0 || feature.axis.isZero()) return {p};
  const Vec axis = k.rotation * feature.axis;
  const Vec across = axis.cross(s.faces[face].n.cross(axis));
  if (across.norm() > kRimFlat) {
    const Vec down = k.rotation.transpose() * (-across);
    p.lean = Vec(down.x(), down.y(), 0.0).normalized();
    return {p};
  }
  std::vector<Point> cap;
  for (const Vec& lean : {Vec(1, 0, 0), Vec(0, 1, 0), Vec(-1, 0, 0), Vec(0, -1, 0)}) {
    p.lean = lean;
    p.fixed = true;
    cap.push_back(p);
  }
  return cap;
}

}  // namespace

Expected<LastingMotion> pivotOnFaces(const LastingBody& body, const std::vector<FlatFace>& faces,
                                     double tolerance, double horizon) {
  if (faces.empty()) return Error{"faces", "must hold at least one face"};
  if (std::holds_alternative<Sphere>(body.shape)) {
    return Error{"body.shape", "a sphere's lasting contact is a ball's"};
  }
  auto path = pathFor(body, faces);
  const Setting& s = path->setting;
  const Kinematics k = kinematicsOf(body);
  double reach = 0.0;
  for (const Feature& f : s.features) reach = std::max(reach, f.centre.norm() + f.radius);
  // As lastingOnFace's manifold: within the settled band of the lowest point, moving along the
  // face's normal no faster than a settled point (an elastic rise of kLastingSettled of the
  // reach under the whole of gravity: a wall's points as a floor's).
  const double band = std::max(kLastingBand, kLastingSettled * reach);
  const double settled_speed =
      std::max(kLastingStillSpeed, std::sqrt(2 * s.gravity.norm() * kLastingSettled * reach));
  std::vector<Point> touching;
  for (std::size_t face = 0; face < s.faces.size(); ++face) {
    const Side& side = s.faces[face];
    const std::string field = "faces[" + std::to_string(face) + "]";
    double lowest = std::numeric_limits<double>::infinity();
    for (const Feature& f : s.features) lowest = std::min(lowest, heightOf(side, k, f));
    if (!(lowest >= -kLastingBand)) {
      return Error{field, "the body's lowest point over it is " + formatNumber(-lowest) +
                              " m inside it (beyond " + formatNumber(kLastingBand) + " m)"};
    }
    // A face it does not touch (just left, bouncing off it) carries nothing: its events watch it.
    if (lowest > kLastingBand) continue;
    const std::size_t before = touching.size();
    for (std::size_t f = 0; f < s.features.size(); ++f) {
      for (const Point& p : pointsOf(s, k, face, f)) {
        const Vec lever = contactOf(s, k, p).lever;
        const double height = side.n.dot(k.centre + lever - side.face.point);
        const double speed = side.n.dot(k.velocity + k.spin.cross(lever));
        if (height - lowest <= band && std::abs(speed) <= settled_speed) touching.push_back(p);
      }
    }
    if (touching.size() == before) {
      return Error{"body.velocity", "every point of the body near " + field +
                                        " approaches or leaves it faster than " +
                                        formatNumber(settled_speed) +
                                        " m/s: not a lasting contact with it"};
    }
  }
  if (touching.empty()) {
    return Error{"body.centre",
                 "touches none of the faces (within " + formatNumber(kLastingBand) + " m)"};
  }
  return pivotFrom(body, std::move(path), touching, tolerance, horizon);
}

Expected<LastingMotion> spinOnCap(const LastingBody& body, const FlatFace& face, int end,
                                  double tolerance, double horizon) {
  if (!std::holds_alternative<Cylinder>(body.shape)) {
    return Error{"body.shape", "a cap is a cylinder's"};
  }
  if (end != -1 && end != 1) {
    return Error{"end", "must be -1 or 1 (the cap at -half_length or +half_length)"};
  }
  auto path = pathFor(body, {face});
  std::vector<Point> touching;
  for (const Vec& lean : {Vec(1, 0, 0), Vec(0, 1, 0), Vec(-1, 0, 0), Vec(0, -1, 0)}) {
    Point p;
    p.feature = end < 0 ? 0 : 1;
    p.lean = lean;
    p.fixed = true;
    touching.push_back(p);
  }
  return pivotFrom(body, std::move(path), touching, tolerance, horizon);
}

Expected<LastingMotion> pivotOverFaceEdge(const LastingBody& body, const FlatFace& face,
                                          double tolerance, double horizon) {
  if (!face.bounded) return Error{"face", "must be bounded (a box obstacle's face)"};
  if (!std::holds_alternative<Cuboid>(body.shape) &&
      !std::holds_alternative<Cylinder>(body.shape)) {
    return notYet("turning over the face's edge at an angle to it: a hull or a capsule");
  }
  auto path = pathFor(body, {face});
  const Setting& s = path->setting;
  const Kinematics k = kinematicsOf(body);
  // Its corners, or its rims' lowest points, on the face within the touching band (a rim lying
  // flat: its point farthest from the edge it crosses), then its crossings of the face's edges.
  std::vector<Point> on_face;
  for (std::size_t f = 0; f < s.features.size(); ++f) {
    const Feature& feature = s.features[f];
    if (heightOf(s.faces.front(), k, feature) > kLastingBand) continue;
    Point p;
    p.feature = f;
    if (feature.radius > 0) {
      const FaceEdge* crossed = &s.lines.front().edge;
      for (const Setting::Line& line : s.lines) {
        const Vec centre = k.centre + k.rotation * feature.centre;
        if (line.edge.out.dot(centre - line.edge.point) >
            crossed->out.dot(centre - crossed->point)) {
          crossed = &line.edge;
        }
      }
      const Vec away = k.rotation.transpose() * (-crossed->out);
      p.lean = Vec(away.x(), away.y(), 0.0).normalized();
    }
    if (withinFace(s, k, p) > 0) on_face.push_back(p);
  }
  const std::vector<Point> touching = touchingAt(s, k, on_face);
  if (touching.empty()) {
    return Error{"body.centre", "does not touch the face or its edges (within " +
                                    formatNumber(kCrossingBand) + " m)"};
  }
  return pivotFrom(body, std::move(path), touching, tolerance, horizon);
}

Expected<LastingMotion> pivotOnRound(const LastingBody& body, const FlatFace& face,
                                     const std::vector<int>& ends, const Eigen::Vector3d& lean,
                                     double tolerance, double horizon) {
  if (!std::holds_alternative<Cylinder>(body.shape) &&
      !std::holds_alternative<Capsule>(body.shape)) {
    return Error{"body.shape", "rims and ends are a cylinder's or a capsule's"};
  }
  if (ends.empty() || ends.size() > 2) {
    return Error{"ends",
                 "must be one or both of the body's ends, got " + std::to_string(ends.size())};
  }
  // No lean given: the rim's point touching as the body is (its lowest; its direction kept
  // where the cap lands flat, the motion's end).
  Vec in_plane(lean.x(), lean.y(), 0.0);
  const Eigen::Matrix3d rotation = body.orientation.normalized().toRotationMatrix();
  const Vec n = face.normal.normalized(), axis = rotation.col(2);
  const Vec across = axis.cross(n.cross(axis));
  if (in_plane.isZero() && across.norm() > kRimFlat) {
    const Vec down = rotation.transpose() * (-across);
    in_plane = Vec(down.x(), down.y(), 0.0);
  }
  auto path = pathFor(body, {face});
  std::vector<Point> touching;
  for (const int end : ends) {
    if (end != -1 && end != 1) {
      return Error{"ends", "each must be -1 or 1 (the end at -half_length or +half_length)"};
    }
    Point p;
    p.feature = end < 0 ? 0 : 1;
    p.lean = in_plane.norm() > 0 ? Vec(in_plane.normalized()) : Vec::UnitX();
    touching.push_back(p);
  }
  return pivotFrom(body, std::move(path), touching, tolerance, horizon);
}

}  // namespace collision_response::core
