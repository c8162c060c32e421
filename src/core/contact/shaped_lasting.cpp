// A shaped body's lasting contact with one flat face, by closed forms (shaped_lasting.h; the
// model and its rules: doc/model.md, "Lasting contact of a shaped body").
//
// The body touches the face at its manifold: a box's face 4 corners, a cylinder's cap 4 rim
// points, a cylinder's or capsule's side the two ends of its lowest line. What it does there:
// - without turning (resting or sliding, w = 0) every point moves with the centre, whose
//   acceleration is a = g_t - mu g_n v_hat sliding (Coulomb), 0 resting (|g_t| <= mu g_n);
// - a cylinder or capsule on its side, its axis across the slope, turns about its axis: rolling
//   without slip a = g_t / (1 + J / (m r^2)) where the friction this needs, m g_t J / (J + m r^2),
//   is within mu m g_n; slipping otherwise, a = g_t - mu g_n s_hat and J alpha = mu m g_n r
//   (s the slip of the contact line), until the slip stops.
// The contact force is m (a - g) in all (the centre's acceleration, the body not turning or
// turning about a principal axis fixed in the world): N = m g_n along n and F = m (a - g_t) in
// the face. Its moment about the centre of mass is the turning's (0, or J alpha about the axis),
// which puts the centre of pressure at P = foot + h (g_t - a) / g_n (the centre's foot, its
// height h above the face: where the line through the centre along g - a meets the face). The
// normal forces are the least-norm ones >= 0 with sum f_i = N and sum f_i q_i = N P; each point's
// friction is f_i (a - g_t) / g_n, in proportion to its normal force (the same ratio at every
// point, so each is within mu f_i where the whole is within mu N, and the friction has no moment
// about the normal).
#include "contact/shaped_lasting.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <variant>

#include <Eigen/Dense>

#include "collision_response/core/validation.h"
#include "contact/shaped_edge_roll.h"
#include "contact/shaped_edge_tip.h"
#include "contact/shaped_pivot.h"

namespace collision_response::core {

Eigen::Vector3d LastingMotion::centreAt(double t) const {
  if (pivot) return pivot->stateAt(t).centre;
  const double s = t - start;
  return centre0 + velocity0 * s + 0.5 * acceleration * s * s;
}

Eigen::Vector3d LastingMotion::velocityAt(double t) const {
  if (pivot) return pivot->stateAt(t).velocity;
  return velocity0 + acceleration * (t - start);
}

Eigen::Vector3d LastingMotion::angularVelocityAt(double t) const {
  if (pivot) return pivot->stateAt(t).angular_velocity;
  return angular_velocity0 + angular_acceleration * (t - start);
}

Eigen::Quaterniond LastingMotion::orientationAt(double t) const {
  if (pivot) return pivot->stateAt(t).orientation;
  const double s = t - start;
  const Eigen::Vector3d turn = angular_velocity0 * s + 0.5 * angular_acceleration * s * s;
  const double angle = turn.norm();
  if (!(angle > 0)) return orientation0;
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, turn / angle)) * orientation0;
}

LastingMotion LastingMotion::integrated(std::shared_ptr<const LastingPath> path, double until,
                                        std::string ends) {
  const PathState first = path->stateAt(path->start());
  LastingMotion motion;
  motion.state = first.state;
  motion.start = path->start();
  motion.until = until;
  motion.ends = std::move(ends);
  motion.centre0 = first.centre;
  motion.velocity0 = first.velocity;
  motion.angular_velocity0 = first.angular_velocity;
  motion.orientation0 = first.orientation;
  motion.forces = first.forces;
  motion.pivot = std::move(path);
  return motion;
}

std::vector<SupportForce> LastingMotion::forcesAt(double t) const {
  if (pivot) return pivot->stateAt(t).forces;
  if (forces_over) return forces_over(t);
  // The manifold's points stay under the body: they move with its centre (a body that does not
  // turn, or a round side turning about its axis), and the forces are constant.
  std::vector<SupportForce> moved = forces;
  const Eigen::Vector3d shift = centreAt(t) - centre0;
  for (SupportForce& force : moved) force.point += shift;
  return moved;
}

ContactState LastingMotion::stateAt(double t) const {
  return pivot ? pivot->stateAt(t).state : state;
}

namespace {

using Vec = Eigen::Vector3d;

template <typename... Branches>
struct Visit : Branches... {
  using Branches::operator()...;
};
template <typename... Branches>
Visit(Branches...) -> Visit<Branches...>;

Error notYet(const std::string& what) { return Error{"contact", "not yet: " + what}; }

bool isUnit(const Vec& v) { return v.allFinite() && std::abs(v.norm() - 1.0) <= kLastingBand; }

/// A cylinder's or a capsule's (`what`) radius and half length: finite and > 0.
Status checkRound(const char* what, double radius, double half_length) {
  if (std::isfinite(radius) && radius > 0 && std::isfinite(half_length) && half_length > 0) {
    return Ok{};
  }
  return Error{"body.shape",
               std::string("a ") + what + "'s radius and half length must be finite and > 0"};
}

/// The body's and the face's numbers, each named where it is wrong (checkLasting's but gravity's).
Status checkBodyAndFace(const LastingBody& body, const FlatFace& face) {
  if (!(std::isfinite(body.mass) && body.mass > 0)) {
    return Error{"body.mass", "must be finite and > 0, got " + formatNumber(body.mass)};
  }
  if (!(body.moments.allFinite() && body.moments.minCoeff() > 0)) {
    return Error{"body.moments", "must be finite and > 0 (principal moments, kg m^2)"};
  }
  if (!std::isfinite(body.time)) return Error{"body.time", "must be finite"};
  if (!body.centre.allFinite()) return Error{"body.centre", "must be finite"};
  if (!body.velocity.allFinite()) return Error{"body.velocity", "must be finite"};
  if (!body.angular_velocity.allFinite()) {
    return Error{"body.angular_velocity", "must be finite"};
  }
  if (!body.gravity.allFinite()) return Error{"body.gravity", "must be finite"};
  if (!(body.orientation.coeffs().allFinite() &&
        std::abs(body.orientation.norm() - 1.0) <= kLastingBand)) {
    return Error{"body.orientation", "must be a unit quaternion (its norm within 1e-9 of 1)"};
  }
  if (!face.point.allFinite()) return Error{"face.point", "must be finite"};
  if (!isUnit(face.normal)) return Error{"face.normal", "must be a unit vector (within 1e-9)"};
  if (!(std::isfinite(face.friction) && face.friction >= 0)) {
    return Error{"face.friction", "must be finite and >= 0, got " + formatNumber(face.friction)};
  }
  if (face.bounded) {
    if (!(face.half_extent.allFinite() && face.half_extent.minCoeff() > 0)) {
      return Error{"face.half_extent", "must be finite and > 0 for a bounded face"};
    }
    if (!isUnit(face.along_u) || !isUnit(face.along_v) ||
        std::abs(face.along_u.dot(face.along_v)) > kLastingBand ||
        std::abs(face.along_u.dot(face.normal)) > kLastingBand ||
        std::abs(face.along_v.dot(face.normal)) > kLastingBand) {
      return Error{"face.along_u",
                   "along_u and along_v must be unit vectors in the face, at right angles "
                   "(within 1e-9)"};
    }
  }
  return std::visit(
      Visit{[](const Sphere& sphere) -> Status {
              if (!(std::isfinite(sphere.radius) && sphere.radius > 0)) {
                return Error{"body.shape", "a sphere's radius must be finite and > 0"};
              }
              return Ok{};
            },
            [](const Cuboid& box) -> Status {
              if (!(box.half_size.allFinite() && box.half_size.minCoeff() > 0)) {
                return Error{"body.shape", "a box's half sizes must be finite and > 0"};
              }
              return Ok{};
            },
            [](const Cylinder& cylinder) {
              return checkRound("cylinder", cylinder.radius, cylinder.half_length);
            },
            [](const Capsule& capsule) {
              return checkRound("capsule", capsule.radius, capsule.half_length);
            },
            [](const ConvexHull& hull) -> Status {
              if (hull.vertices.size() < 4) {
                return Error{"body.shape", "a hull needs at least 4 vertices"};
              }
              for (const Vec& vertex : hull.vertices) {
                if (!vertex.allFinite()) {
                  return Error{"body.shape", "a hull's vertices must be finite"};
                }
              }
              return Ok{};
            }},
      body.shape);
}

Status checkLasting(const LastingBody& body, const FlatFace& face) {
  if (Status status = checkBodyAndFace(body, face); !status) return status;
  const double pressing = -body.gravity.dot(face.normal);
  if (!(pressing > 0)) {
    return Error{"body.gravity",
                 "does not press the body onto the face (its part into the face is " +
                     formatNumber(pressing) + " m/s^2): no lasting contact"};
  }
  return Ok{};
}

/// Where the body touches the face.
enum class SupportKind {
  kPolygon,  ///< 3 or 4 corners (a box's face, a hull's)
  kDisc,     ///< a cylinder's cap: its rim
  kLine,     ///< a cylinder's or capsule's side: the two ends of its lowest line
  kCorners,  ///< one corner or one edge's two: the body tips over them (pivotOnFace)
  kRound,    ///< one point of a cylinder's rim or a capsule's end: it tips (pivotOnRound)
};

struct Support {
  SupportKind kind = SupportKind::kPolygon;
  std::vector<Vec> feet;      ///< on the face (polygon, line)
  Vec axis = Vec::Zero();     ///< a line's: unit, in the face, from its first foot to its second
  Vec centre = Vec::Zero();   ///< a disc's centre, on the face
  double radius = 0.0;        ///< a disc's, or a side's (the roll's)
  double axial_moment = 0.0;  ///< a side's moment about its axis (the roll's J)
  std::vector<Vec> corners;   ///< the feet's corners in the principal frame (kCorners)
  int end = 0;                ///< a cap's, or a rim's or end's touching (kRound): -1 or 1 along z
};

/// The face's frame and what the body is there.
struct Setting {
  Vec n, e1, e2;      ///< the normal and two unit directions in the face
  Vec g_t;            ///< gravity's part in the face
  double g_n = 0;     ///< gravity's part into the face (> 0)
  double height = 0;  ///< the centre's height above the face
  Vec foot;           ///< the centre's foot on the face
  double reach = 0;   ///< the body's farthest point from its centre
  /// The manifold's band: kLastingBand, or for a settled body kLastingSettled of its reach.
  double band = kLastingBand;
  /// m/s: the normal speed a point may have and be settled (kLastingSettled).
  double settled_speed = kLastingStillSpeed;
  bool settled = false;  ///< handed over as settled: its support's points move no faster
};

/// The face's frame and the body's place over it; `settled`: the bands of a body handed over as
/// settled (kLastingSettled), else the touching band alone.
Setting settingOf(const LastingBody& body, const FlatFace& face, bool settled) {
  Setting setting;
  setting.n = face.normal.normalized();
  setting.e1 = face.bounded ? face.along_u : setting.n.unitOrthogonal();
  setting.e2 = setting.n.cross(setting.e1);
  setting.g_n = -body.gravity.dot(setting.n);
  setting.g_t = body.gravity + setting.g_n * setting.n;
  setting.height = setting.n.dot(body.centre - face.point);
  setting.foot = body.centre - setting.height * setting.n;
  setting.reach = reachOf(body.shape);
  setting.settled = settled;
  if (settled) {
    setting.band = std::max(kLastingBand, kLastingSettled * setting.reach);
    setting.settled_speed =
        std::max(kLastingStillSpeed, std::sqrt(2 * setting.g_n * kLastingSettled * setting.reach));
  }
  return setting;
}

Vec onFace(const Vec& x, const FlatFace& face, const Vec& n) {
  return x - n.dot(x - face.point) * n;
}

/// Whether a body whose lowest point is `lowest` above the face touches it (within the band).
Status touchesFace(double lowest) {
  if (lowest > kLastingBand) {
    return Error{"body.centre", "the body does not touch the face: its lowest point is " +
                                    formatNumber(lowest) +
                                    " m above it (the touching band is 1e-9 m)"};
  }
  if (lowest < -kLastingBand) {
    return Error{"body.centre", "the body is " + formatNumber(-lowest) +
                                    " m inside the face (more than the touching band, 1e-9 m)"};
  }
  return Ok{};
}

/// A cylinder's or capsule's support (`radius`, `half_length` along its axis, rotation's z): on
/// its side, the lowest line's two ends; a cylinder on its cap, the cap's disc; else, leaning on
/// its rim or one end, the one point touching (kRound: it tips, pivotOnRound).
Expected<Support> roundSupport(const LastingBody& body, const Eigen::Matrix3d& rotation,
                               const FlatFace& face, const Setting& setting, double radius,
                               double half_length, bool cylinder) {
  const Vec& n = setting.n;
  Support support;
  const Vec axis = rotation.col(2);
  const double rise = 2 * half_length * std::abs(axis.dot(n));
  if (rise <= setting.band) {  // on its side: the lowest line's two ends
    support.kind = SupportKind::kLine;
    support.axis = (axis - axis.dot(n) * n).normalized();
    const Vec below = body.centre - radius * n;
    support.feet = {onFace(below - half_length * support.axis, face, n),
                    onFace(below + half_length * support.axis, face, n)};
    support.radius = radius;
    support.axial_moment = body.moments.z();
    return support;
  }
  const double side = axis.dot(n) > 0 ? -1.0 : 1.0;  // the cap or end nearer the face
  support.end = static_cast<int>(side);
  support.radius = radius;
  const Vec end = body.centre + side * half_length * axis;
  const double tilt = axis.cross(n).norm();
  if (cylinder && 2 * radius * tilt <= setting.band) {  // on its cap
    support.kind = SupportKind::kDisc;
    support.centre = onFace(end, face, n);
    return support;
  }
  // Leaning on its rim (its lowest point, radius along -(n - (n.a) a)) or on one end (under its
  // centre): that one point touches, and the body tips.
  support.kind = SupportKind::kRound;
  const Vec lowest =
      cylinder ? Vec(end - radius * axis.cross(n.cross(axis)) / tilt) : Vec(end - radius * n);
  support.feet = {onFace(lowest, face, n)};
  return support;
}

/// Three corners of one face of a box on the face: its fourth is within twice the band (its
/// height is the other three's h1 + h3 - h2) and the face rests on all four; taken alone, the
/// three would balance the body on the face's diagonal, an edge it tips over only by rounding.
/// The fourth is added to `support` (unless, settled, it moves faster than a settled point).
void addFourthCorner(const LastingBody& body, const Cuboid& box, const Eigen::Matrix3d& rotation,
                     const FlatFace& face, const Setting& setting, Support& support) {
  const Vec& n = setting.n;
  for (int axis = 0; axis < 3; ++axis) {
    const double side = support.corners[0][axis];
    if (support.corners[1][axis] != side || support.corners[2][axis] != side) continue;
    Vec fourth = Vec::Zero();
    fourth[axis] = side;
    for (int other = 0; other < 3; ++other) {
      if (other == axis) continue;
      // The sign the three show once: the fourth has the other.
      double sum = 0;
      for (const Vec& c : support.corners) sum += c[other] > 0 ? 1.0 : -1.0;
      fourth[other] = (sum > 0 ? -1.0 : 1.0) * box.half_size[other];
    }
    const Vec point = body.centre + rotation * fourth;
    const double speed = n.dot(body.velocity + body.angular_velocity.cross(rotation * fourth));
    if (setting.settled && std::abs(speed) > setting.settled_speed) return;
    support.feet.push_back(onFace(point, face, n));
    support.corners.push_back(fourth);
    return;
  }
}

/// A box's or hull's support from its points on the face: one corner, an edge (two, or the two
/// extreme ones of more collinear), or a polygon of three or more.
Expected<Support> cornersSupport(Support support) {
  if (support.feet.size() == 1) {
    support.kind = SupportKind::kCorners;
    return support;
  }
  if (support.feet.size() >= 3) {
    // Collinear corners are an edge: the polygon's area against its size.
    double area = 0, size = 0;
    for (std::size_t i = 1; i + 1 < support.feet.size(); ++i) {
      area = std::max(
          area,
          (support.feet[i] - support.feet[0]).cross(support.feet[i + 1] - support.feet[0]).norm());
    }
    for (const Vec& foot : support.feet) size = std::max(size, (foot - support.feet[0]).norm());
    if (area > kLastingBand * size) return support;
  }
  if (support.feet.size() > 2) {
    // Collinear: the edge's two extreme points carry it (the ones between add no support).
    const Vec along = support.feet[1] - support.feet[0];
    std::size_t low = 0, high = 0;
    for (std::size_t i = 0; i < support.feet.size(); ++i) {
      const double at = along.dot(support.feet[i] - support.feet[0]);
      if (at < along.dot(support.feet[low] - support.feet[0])) low = i;
      if (at > along.dot(support.feet[high] - support.feet[0])) high = i;
    }
    support.feet = {support.feet[low], support.feet[high]};
    support.corners = {support.corners[low], support.corners[high]};
  }
  support.kind = SupportKind::kCorners;
  return support;
}

Expected<Support> supportOf(const LastingBody& body, const Eigen::Matrix3d& rotation,
                            const FlatFace& face, const Setting& setting) {
  const Vec& n = setting.n;
  const Vec down = rotation.transpose() * (-n);
  const double lowest = n.dot(body.centre + rotation * coreSupport(body.shape, down) - face.point) -
                        marginOf(body.shape);
  if (Status status = touchesFace(lowest); !status) return status.error();
  if (const auto* cylinder = std::get_if<Cylinder>(&body.shape)) {
    return roundSupport(body, rotation, face, setting, cylinder->radius, cylinder->half_length,
                        true);
  }
  if (const auto* capsule = std::get_if<Capsule>(&body.shape)) {
    return roundSupport(body, rotation, face, setting, capsule->radius, capsule->half_length,
                        false);
  }
  Support support;
  std::vector<Vec> candidates;
  contactCandidates(body.shape, down, candidates);
  for (const Vec& corner : candidates) {
    const Vec point = body.centre + rotation * corner;
    const double above = n.dot(point - face.point) - lowest;
    // A point that approaches or leaves the face faster than a settled one does not rest on it:
    // it strikes it (an impact, the caller's) or parts from it, as the others tip.
    const double normal_speed =
        n.dot(body.velocity + body.angular_velocity.cross(rotation * corner));
    if (above <= setting.band &&
        (!setting.settled || std::abs(normal_speed) <= setting.settled_speed)) {
      support.feet.push_back(onFace(point, face, n));
      support.corners.push_back(corner);
    }
  }
  if (const auto* box = std::get_if<Cuboid>(&body.shape); box && support.corners.size() == 3) {
    addFourthCorner(body, *box, rotation, face, setting, support);
  }
  if (support.feet.empty()) {
    return Error{"body.velocity",
                 "every point of the body near the face approaches or leaves it faster than " +
                     formatNumber(setting.settled_speed) +
                     " m/s: not a lasting contact (settled: an elastic rise of 1e-6 of its "
                     "reach)"};
  }
  return cornersSupport(std::move(support));
}

/// The smallest s > 0 with v s + a s^2 / 2 = target (target >= 0), or infinity: written
/// without cancellation (the root 2 target / (v + sqrt(v^2 + 2 a target))).
double firstReach(double v, double a, double target) {
  if (target <= 0) {
    if (v > 0 || (v == 0 && a > 0)) return 0.0;
    return a > 0 ? -2 * v / a : std::numeric_limits<double>::infinity();
  }
  const double discriminant = v * v + 2 * a * target;
  if (discriminant < 0) return std::numeric_limits<double>::infinity();
  const double root = std::sqrt(discriminant);
  if (v >= 0) return 2 * target / (v + root);
  // v < 0: coming back only where a > 0, at the later root (-v + root) / a.
  if (!(a > 0)) return std::numeric_limits<double>::infinity();
  return (root - v) / a;
}

/// The centre's motion along one direction of the face: displacement v s + a s^2 / 2.
struct Track {
  Vec direction = Vec::Zero();  ///< unit (zero where the centre stays)
  double speed = 0;             ///< along it, at the start
  double acceleration = 0;      ///< along it
};

/// The first instant (after the start) a point of the manifold reaches a bounded face's edge.
/// (`skip`: the edge a support overhangs, its axis 0 or 1 and side -1 or 1, which its points
/// crossing do not end the motion: the support is cut there anew, overhangMotion.)
double edgeReached(const std::vector<Vec>& feet, const FlatFace& face, const Track& track,
                   std::optional<std::pair<int, double>> skip = std::nullopt) {
  double first = std::numeric_limits<double>::infinity();
  if (!face.bounded || track.direction.isZero(0.0)) return first;
  const std::array<Vec, 2> axes{face.along_u, face.along_v};
  for (int k = 0; k < 2; ++k) {
    const double along = track.direction.dot(axes[static_cast<std::size_t>(k)]);
    if (along == 0) continue;
    const double bound = face.half_extent[k];
    const bool skip_ahead = skip && skip->first == k && (skip->second > 0) == (along > 0);
    const bool skip_behind = skip && skip->first == k && !skip_ahead;
    for (const Vec& foot : feet) {
      const double u = (foot - face.point).dot(axes[static_cast<std::size_t>(k)]);
      // u + along x = +-bound: forward where the direction goes, backward the other way.
      const double forward = along > 0 ? (bound - u) / along : (-bound - u) / along;
      const double backward = along > 0 ? (u + bound) / along : (u - bound) / along;
      if (!skip_ahead)
        first = std::min(first, firstReach(track.speed, track.acceleration, forward));
      if (!skip_behind) {
        first = std::min(first, firstReach(-track.speed, -track.acceleration, backward));
      }
    }
  }
  return first;
}

/// The support's points and `point` in the face's coordinates (e1, e2) about the points'
/// centroid: the polygon and the point whose inside and forces the 2-D rules read.
std::pair<std::vector<Eigen::Vector2d>, Eigen::Vector2d> inFace(const Support& support,
                                                                const Setting& setting,
                                                                const Vec& point) {
  Vec centroid = Vec::Zero();
  for (const Vec& foot : support.feet) centroid += foot;
  centroid /= static_cast<double>(support.feet.size());
  std::vector<Eigen::Vector2d> q;
  for (const Vec& foot : support.feet) {
    q.emplace_back((foot - centroid).dot(setting.e1), (foot - centroid).dot(setting.e2));
  }
  return {q,
          Eigen::Vector2d((point - centroid).dot(setting.e1), (point - centroid).dot(setting.e2))};
}

/// Whether the point p lies strictly inside the convex polygon of `corners` (2D, any order).
bool strictlyInside(std::vector<Eigen::Vector2d> corners, const Eigen::Vector2d& p) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& corner : corners) mean += corner;
  mean /= static_cast<double>(corners.size());
  std::sort(corners.begin(), corners.end(), [&](const auto& a, const auto& b) {
    return std::atan2(a.y() - mean.y(), a.x() - mean.x()) <
           std::atan2(b.y() - mean.y(), b.x() - mean.x());
  });
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const Eigen::Vector2d edge = corners[(i + 1) % corners.size()] - corners[i];
    const Eigen::Vector2d to = p - corners[i];
    if (!(edge.x() * to.y() - edge.y() * to.x() > 0)) return false;
  }
  return true;
}

/// The least-norm f >= 0 with balance f = target (3 rows, k > 4 columns), by its dual: f_i =
/// max(0, (B^T l)_i) where B max(0, B^T l) = target, solved by Newton's method on l over the
/// points that carry (the semismooth Newton step is the least-norm solve on them), from the
/// linear rule's l; empty where it does not settle in 64 steps or the points that carry do not
/// span the face (the caller takes a triangle).
std::vector<double> leastNonNegative(const Eigen::Matrix<double, 3, Eigen::Dynamic>& balance,
                                     const Vec& target, Vec l) {
  const Eigen::Index k = balance.cols();
  std::vector<bool> carries(static_cast<std::size_t>(k), true);
  for (int step = 0; step < 64; ++step) {
    const Eigen::VectorXd linear = balance.transpose() * l;
    std::vector<bool> now(static_cast<std::size_t>(k));
    for (Eigen::Index i = 0; i < k; ++i) now[static_cast<std::size_t>(i)] = linear(i) > 0;
    if (step > 0 && now == carries) {
      std::vector<double> f(static_cast<std::size_t>(k));
      for (Eigen::Index i = 0; i < k; ++i)
        f[static_cast<std::size_t>(i)] = std::max(0.0, linear(i));
      return f;
    }
    carries = now;
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    for (Eigen::Index i = 0; i < k; ++i) {
      if (carries[static_cast<std::size_t>(i)])
        normal += balance.col(i) * balance.col(i).transpose();
    }
    const auto solver = normal.fullPivLu();
    if (solver.rank() < 3) return {};
    l = solver.solve(target);
  }
  return {};
}

/// The normal forces on 3 or more points q_i of the face (coordinates about their centroid) that
/// carry N with their centre of pressure at p: the least-norm f with sum f_i = N and
/// sum f_i q_i = N p (f_i = l0 + l1 x_i + l2 y_i, a 3x3 solve), and where that has a negative
/// share (p inside the polygon but outside the region the linear rule reaches), the least-norm
/// f >= 0: for 4 points along the one null direction of the balance (its closed form: the share
/// that went negative is 0), for more by leastNonNegative (else the fan triangle from the first
/// point that holds p: one documented choice).
std::vector<double> polygonForces(const std::vector<Eigen::Vector2d>& q, const Eigen::Vector2d& p,
                                  double total, bool nonnegative) {
  const std::size_t k = q.size();
  Eigen::Matrix<double, 3, Eigen::Dynamic> balance(3, static_cast<Eigen::Index>(k));
  for (std::size_t i = 0; i < k; ++i) {
    balance.col(static_cast<Eigen::Index>(i)) = Vec(1.0, q[i].x(), q[i].y());
  }
  const Vec target = total * Vec(1.0, p.x(), p.y());
  const Eigen::Matrix3d normal = balance * balance.transpose();
  const Vec l = normal.partialPivLu().solve(target);
  const Eigen::VectorXd least = balance.transpose() * l;
  std::vector<double> f(least.data(), least.data() + k);
  if (!nonnegative || k < 4 || *std::min_element(f.begin(), f.end()) >= 0) return f;
  if (k > 4) {
    std::vector<double> shares = leastNonNegative(balance, target, l);
    if (!shares.empty()) return shares;
    shares.assign(k, 0.0);
    for (std::size_t i = 1; i + 1 < k; ++i) {
      // p's weights in the triangle (q_0, q_i, q_i+1).
      Eigen::Matrix2d basis;
      basis << q[i] - q[0], q[i + 1] - q[0];
      const Eigen::Vector2d w = basis.partialPivLu().solve(p - q[0]);
      if (w.minCoeff() < -1e-12 || w.sum() > 1 + 1e-12) continue;
      shares[0] = total * (1 - w.sum()), shares[i] = total * w.x(), shares[i + 1] = total * w.y();
      break;
    }
    return shares;
  }
  // The null direction of the 3x4 balance: its signed 3x3 minors.
  std::array<double, 4> null{};
  for (int i = 0; i < 4; ++i) {
    Eigen::Matrix3d minor;
    int c = 0;
    for (int j = 0; j < 4; ++j) {
      if (j != i) minor.col(c++) = balance.col(j);
    }
    null[static_cast<std::size_t>(i)] = (i % 2 == 0 ? 1.0 : -1.0) * minor.determinant();
  }
  double lo = -std::numeric_limits<double>::infinity(), hi = -lo;
  std::size_t lo_at = 0, hi_at = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    if (null[i] > 0 && -f[i] / null[i] > lo) lo = -f[i] / null[i], lo_at = i;
    if (null[i] < 0 && -f[i] / null[i] < hi) hi = -f[i] / null[i], hi_at = i;
  }
  const double t = std::clamp(0.0, lo, std::max(lo, hi));
  for (std::size_t i = 0; i < 4; ++i) f[i] = std::max(0.0, f[i] + t * null[i]);
  if (t == lo) f[lo_at] = 0.0;
  if (t == hi) f[hi_at] = 0.0;
  return f;
}

/// The normal force on each point of the manifold, with the centre of pressure `pressure` (a
/// point of the face), or the Error that says which tipping it would be.
Expected<std::vector<SupportForce>> supportForces(Support& support, const Setting& setting,
                                                  const Vec& pressure, double total,
                                                  const Vec& friction_ratio,
                                                  const Eigen::Matrix3d& rotation,
                                                  const std::string& tipping) {
  std::vector<double> f;
  if (support.kind == SupportKind::kLine) {
    const double l1 = (support.feet[0] - setting.foot).dot(support.axis);
    const double l2 = (support.feet[1] - setting.foot).dot(support.axis);
    const double at = (pressure - setting.foot).dot(support.axis);
    if (!(l1 < at && at < l2)) {
      return notYet(tipping + ": the centre of pressure " + formatNumber(at) +
                    " m along the axis is not strictly between its ends' " + formatNumber(l1) +
                    " and " + formatNumber(l2) + " m");
    }
    f = {total * (l2 - at) / (l2 - l1), total * (at - l1) / (l2 - l1)};
  } else {
    if (support.kind == SupportKind::kDisc) {
      // The rim's 4 points: along the centre of pressure's offset from the cap's centre and a
      // quarter turn either side and opposite, so that the square they make reaches the rim
      // where the centre of pressure is (the disc's own criterion); where it is at the centre,
      // along the body's first principal axis.
      const Vec offset = pressure - support.centre;
      if (!(offset.norm() < support.radius)) {
        return notYet(tipping + ": the centre of pressure is " + formatNumber(offset.norm()) +
                      " m from the cap's centre, not strictly within its radius " +
                      formatNumber(support.radius) + " m");
      }
      Vec along = offset;
      if (!(along.norm() > 0)) along = rotation.col(0) - rotation.col(0).dot(setting.n) * setting.n;
      along.normalize();
      const Vec across = setting.n.cross(along);
      const double r = support.radius;
      support.feet = {support.centre + r * along, support.centre + r * across,
                      support.centre - r * along, support.centre - r * across};
    }
    const auto [q, p] = inFace(support, setting, pressure);
    if (support.kind == SupportKind::kPolygon && !strictlyInside(q, p)) {
      return notYet(tipping +
                    ": the centre of pressure (the centre of mass's projection along "
                    "g - a) is not strictly inside the support polygon");
    }
    f = polygonForces(q, p, total, true);
    for (double& share : f) share = std::max(0.0, share);  // rounding's -1e-17 near an edge
  }
  std::vector<SupportForce> forces;
  for (std::size_t i = 0; i < f.size(); ++i) {
    forces.push_back({support.feet[i], f[i], f[i] * friction_ratio});
  }
  return forces;
}

/// The motion before its forces.
struct Plan {
  ContactState state = ContactState::kResting;
  Vec velocity = Vec::Zero(), acceleration = Vec::Zero();
  Vec angular_velocity = Vec::Zero(), angular_acceleration = Vec::Zero();
  double lasts = std::numeric_limits<double>::infinity();  ///< s after the start
  std::string ends;
  Track track;
};

/// Resting or sliding without turning: Coulomb's closed form. `velocity` and `g_t` (gravity's
/// part) in the face, g_n gravity's part into it.
Expected<Plan> translationPlan(const Vec& velocity, const Vec& g_t, double g_n, double mu) {
  Plan plan;
  const double speed = velocity.norm();
  const double slope = g_t.norm();
  if (!(speed > kLastingStillSpeed)) {
    if (slope <= mu * g_n) return plan;  // static friction holds it
    // It starts sliding down: v_hat = g_t's direction, a = (|g_t| - mu g_n) along it.
    const Vec down = g_t / slope;
    plan.state = ContactState::kSliding;
    plan.track = {down, 0.0, slope - mu * g_n};
    plan.acceleration = plan.track.acceleration * down;
    return plan;
  }
  const Vec ahead = velocity / speed;
  const double downhill = g_t.dot(ahead);
  if ((g_t - downhill * ahead).norm() > kLastingAcrossGravity * (slope + g_n)) {
    return notYet(
        "sliding across the slope (gravity's part in the face not along the velocity: the slide "
        "turns)");
  }
  plan.state = ContactState::kSliding;
  plan.velocity = speed * ahead;
  plan.track = {ahead, speed, downhill - mu * g_n};
  plan.acceleration = plan.track.acceleration * ahead;
  if (plan.track.acceleration < 0) {  // it stops: speed + a t = 0
    plan.lasts = speed / -plan.track.acceleration;
    plan.ends = "stops";
  }
  return plan;
}

/// A cylinder or capsule on its side, turning about its axis (or still): rolling or slipping.
Expected<Plan> rollPlan(const LastingBody& body, const Support& support, const Setting& setting,
                        double mu, const Vec& velocity, double spin) {
  const Vec& axis = support.axis;
  const Vec across = axis.cross(setting.n);  // the roll's direction: the contact line's slip
  const double g_across = setting.g_t.dot(across), g_along = setting.g_t.dot(axis);
  const double v_across = velocity.dot(across), v_along = velocity.dot(axis);
  const double r = support.radius, m = body.mass, J = support.axial_moment;
  const double still = kLastingStillSpeed;
  const double scale = setting.g_t.norm() + setting.g_n;
  if (std::abs(v_across) <= still && std::abs(spin) * r <= still &&
      std::abs(g_across) <= kLastingAcrossGravity * scale) {
    // Not rolling: resting or sliding along its axis, as a body that does not turn (gravity's
    // part across the axis, below kLastingAcrossGravity, left out).
    return translationPlan(v_along * axis, g_along * axis, setting.g_n, mu);
  }
  if (std::abs(v_along) > still) {
    return notYet("a cylinder or capsule sliding along its axis while it rolls");
  }
  if (std::abs(g_along) > kLastingAcrossGravity * scale) {
    return notYet("rolling with the axis not across the slope (gravity along the axis too)");
  }
  Plan plan;
  plan.track.direction = across;
  plan.track.speed = v_across;
  plan.velocity = v_across * across;
  plan.angular_velocity = spin * axis;
  // The contact line's slip: v + w x (-r n) = (v_across - spin r) along `across`.
  const double slip = v_across - spin * r;
  const double rolling = g_across * m * r * r / (m * r * r + J);  // a = g / (1 + J / (m r^2))
  const double friction_needed = std::abs(g_across - rolling);  // per unit mass: g J / (J + m r^2)
  if (std::abs(slip) <= still && friction_needed <= mu * setting.g_n) {
    plan.state = ContactState::kRolling;
    plan.track.acceleration = rolling;
    plan.acceleration = rolling * across;
    plan.angular_acceleration = (rolling / r) * axis;
    return plan;
  }
  // Slipping: friction mu N against the slip (its sign; from no slip, the way gravity drives it).
  const double sign =
      std::abs(slip) > still ? (slip > 0 ? 1.0 : -1.0) : (g_across > 0 ? 1.0 : -1.0);
  plan.state = ContactState::kSliding;
  plan.track.acceleration = g_across - sign * mu * setting.g_n;
  plan.acceleration = plan.track.acceleration * across;
  // J alpha = -r F, F = -sign mu m g_n along `across`.
  const double alpha = sign * mu * m * setting.g_n * r / J;
  plan.angular_acceleration = alpha * axis;
  const double slip_rate = plan.track.acceleration - alpha * r;
  if (std::abs(slip) > still && slip_rate * sign < 0) {  // the slip stops: it rolls from there
    plan.lasts = std::abs(slip) / std::abs(slip_rate);
    plan.ends = "stops";
  }
  return plan;
}

}  // namespace

namespace {

/// The turn a side keeps about its axis (a roll; 0 for a body on a face or a cap), or the Error
/// of a turning not modelled: a spin about the normal beyond kLastingStillSpeed, a rocking turn
/// about an axis in the face beyond the settled speed (within it, dropped: with it, energy,
/// since a side's axis is principal).
Expected<double> keptSpin(const Support& support, const Setting& setting, const Vec& w) {
  const double spin = support.kind == SupportKind::kLine ? w.dot(support.axis) : 0.0;
  const Vec rest = support.kind == SupportKind::kLine ? Vec(w - spin * support.axis) : w;
  const double about_normal = rest.dot(setting.n);
  if (std::abs(about_normal) * setting.reach > kLastingStillSpeed) {
    return notYet("spin about the face's normal while sliding or resting (pivoting friction)");
  }
  if ((rest - about_normal * setting.n).norm() * setting.reach > setting.settled_speed) {
    return notYet("rocking: turning about an axis in the face that is not a side's own");
  }
  return spin;
}

/// The support's outline on the face: a cap's rim at its extremes along `along` and `across`,
/// or the manifold's points.
std::vector<Vec> outlineOf(const Support& support, const Vec& along, const Vec& across) {
  if (support.kind != SupportKind::kDisc) return support.feet;
  const Vec& c = support.centre;
  const double r = support.radius;
  return {c + r * along, c - r * along, c + r * across, c - r * across};
}

/// Neither approaching nor leaving the face (beyond the settled speed), nor off a bounded face.
Status checkOnFace(const LastingBody& body, const FlatFace& face, const Support& support,
                   const Setting& setting) {
  for (const Vec& point : outlineOf(support, setting.e1, setting.e2)) {
    const double normal_speed =
        (body.velocity + body.angular_velocity.cross(point - body.centre)).dot(setting.n);
    if (std::abs(normal_speed) > setting.settled_speed) {
      return Error{"body.velocity", std::string("a point of the contact ") +
                                        (normal_speed < 0 ? "approaches" : "leaves") +
                                        " the face at " + formatNumber(std::abs(normal_speed)) +
                                        " m/s: not a lasting contact (settled within " +
                                        formatNumber(setting.settled_speed) +
                                        " m/s: an elastic rise of 1e-6 of the body's reach)"};
    }
  }
  // A face or a cap over a bounded face's edge: overhangMotion's.
  if (!face.bounded || support.kind == SupportKind::kPolygon ||
      support.kind == SupportKind::kDisc) {
    return Ok{};
  }
  for (const Vec& point : outlineOf(support, face.along_u, face.along_v)) {
    const Vec offset = point - face.point;
    if (std::abs(offset.dot(face.along_u)) > face.half_extent.x() + kLastingBand ||
        std::abs(offset.dot(face.along_v)) > face.half_extent.y() + kLastingBand) {
      return notYet("the body overhangs the face's edge (a point of its support is off it)");
    }
  }
  return Ok{};
}

const char* tippingOf(ContactState state) {
  switch (state) {
    case ContactState::kResting:
      return "tipping over";
    case ContactState::kSliding:
      return "tipping while sliding";
    case ContactState::kRolling:
      return "tipping while rolling";
  }
  return "tipping";
}

}  // namespace

namespace {

/// The first instant (after the start) a point moving by x0 + v s + a s^2 / 2 in a bounded face
/// reaches its edge (+inf on an unbounded face).
double pointReachesEdge(const Vec& x0, const Vec& v, const Vec& a, const FlatFace& face) {
  double first = std::numeric_limits<double>::infinity();
  if (!face.bounded) return first;
  const std::array<Vec, 2> axes{face.along_u, face.along_v};
  for (std::size_t k = 0; k < 2; ++k) {
    const double u = (x0 - face.point).dot(axes[k]), bound = face.half_extent[static_cast<int>(k)];
    const double v_k = v.dot(axes[k]), a_k = a.dot(axes[k]);
    first = std::min({first, firstReach(v_k, a_k, bound - u), firstReach(-v_k, -a_k, u + bound)});
  }
  return first;
}

/// A sphere (its moment I about any axis) touching a face at one point, its normal motion
/// settled: the closed forms of a ball on a plane (doc/model.md, "Balls among shaped bodies").
/// The contact point's slip is u = v - r w x n; with k = 1 + m r^2 / I:
///  - no slip, and friction enough (|g_t| I / (I + m r^2) <= mu g_n): it rolls, a = g_t / (1 + I
///    / (m r^2)), alpha = n x a / r; with no velocity and no slope it rests;
///  - else it slides, friction mu m g_n against the slip u^ (along g_t from no slip): a = g_t -
///    mu g_n u^, alpha = mu m g_n r (n x u^) / I, the slip changing at g_t.u^ - mu g_n k, so
///    stopping (then it rolls: asked again) where that is < 0.
/// A point contact has no torque about the normal: a spin about it is kept. The orientation is
/// the closed form's only where w stays about one axis: a turn about another axis while alpha
/// is not 0, or a slide across the slope (the slip's direction turns), is not yet.
Expected<LastingMotion> ballOnFace(const LastingBody& body, const FlatFace& face, double radius) {
  const Setting setting = settingOf(body, face, true);
  const Vec& n = setting.n;
  const double lowest = setting.height - radius;
  if (Status status = touchesFace(lowest); !status) return status.error();
  const double normal_speed = body.velocity.dot(n);
  if (std::abs(normal_speed) > setting.settled_speed) {
    return Error{"body.velocity", std::string("its point of contact ") +
                                      (normal_speed < 0 ? "approaches" : "leaves") +
                                      " the face at " + formatNumber(std::abs(normal_speed)) +
                                      " m/s: not a lasting contact"};
  }
  const Vec point = setting.foot;
  if (face.bounded &&
      (std::abs((point - face.point).dot(face.along_u)) > face.half_extent.x() + kLastingBand ||
       std::abs((point - face.point).dot(face.along_v)) > face.half_extent.y() + kLastingBand)) {
    return notYet("the body overhangs the face's edge (its point of contact is off it)");
  }
  if (body.moments.maxCoeff() - body.moments.minCoeff() > 1e-12 * body.moments.maxCoeff()) {
    return notYet("a sphere whose moments of inertia differ (a given tensor) in lasting contact");
  }
  const double m = body.mass, r = radius, I = body.moments.x(), mu = face.friction;
  const double g_n = setting.g_n, still = kLastingStillSpeed;
  const Vec& g_t = setting.g_t;
  const Vec v = body.velocity - normal_speed * n;
  const Vec& w = body.angular_velocity;
  const Vec slip = v - r * w.cross(n);
  const Vec rolling = g_t / (1 + I / (m * r * r));
  LastingMotion motion;
  motion.start = body.time;
  motion.centre0 = body.centre;
  motion.orientation0 = body.orientation.normalized();
  motion.velocity0 = v;
  motion.angular_velocity0 = w;
  Vec slip_direction = Vec::Zero();
  if (slip.norm() <= still && (g_t - rolling).norm() <= mu * g_n) {
    const bool level = g_t.norm() <= kLastingAcrossGravity * (g_t.norm() + g_n);
    motion.state = level && v.norm() <= still ? ContactState::kResting : ContactState::kRolling;
    if (motion.state == ContactState::kResting) {
      motion.velocity0.setZero();
      motion.angular_velocity0 = w.dot(n) * n;  // a spin about the normal is kept
    } else if (!level) {
      motion.acceleration = rolling;
      motion.angular_acceleration = n.cross(rolling) / r;
    }
  } else {
    // Sliding: from no slip, the way gravity drives it (friction cannot hold the roll).
    slip_direction = slip.norm() > still ? Vec(slip.normalized()) : Vec(g_t.normalized());
    const double downhill = g_t.dot(slip_direction);
    if ((g_t - downhill * slip_direction).norm() > kLastingAcrossGravity * (g_t.norm() + g_n)) {
      return notYet(
          "a ball sliding across the slope (gravity's part in the face not along its slip: the "
          "slide turns)");
    }
    motion.state = ContactState::kSliding;
    motion.acceleration = g_t - mu * g_n * slip_direction;
    motion.angular_acceleration = (mu * m * g_n * r / I) * n.cross(slip_direction);
    const double slip_rate = downhill - mu * g_n * (1 + m * r * r / I);
    if (slip.norm() > still && slip_rate < 0) {
      motion.until = body.time + slip.norm() / -slip_rate;
      motion.ends = "stops";
    }
  }
  const double alpha = motion.angular_acceleration.norm();
  if (alpha > 0) {
    const Vec axis = motion.angular_acceleration / alpha;
    const Vec& w0 = motion.angular_velocity0;
    if ((w0 - w0.dot(axis) * axis).norm() * r > still) {
      return notYet(
          "a ball turning about an axis other than its roll's while it slides or rolls down a "
          "slope (its orientation has no closed form here)");
    }
  }
  SupportForce force;
  force.point = point;
  force.normal_force = m * g_n;
  force.friction_force = m * (motion.acceleration - g_t);
  motion.forces = {force};
  const double edge = pointReachesEdge(point, motion.velocity0, motion.acceleration, face);
  if (body.time + edge < motion.until) {
    motion.until = body.time + edge;
    motion.ends = "a point of its support reaches the face's edge";
  }
  return motion;
}

/// A support past a bounded face's edge: the edge and which of the face's bounds it is.
struct Overhang {
  FaceEdge edge;
  std::pair<int, double> bound;  ///< the face's axis (0: along_u, 1: along_v) and side (-1, 1)
  bool corner = false;           ///< past two of the face's edges: over its corner
};

/// The face's edge the support's outline is past or at (within the touching band); none on an
/// unbounded face or where nothing is; past two, the first, `corner` set (over the face's corner).
std::optional<Overhang> overhangOf(const std::vector<Vec>& outline, const FlatFace& face) {
  std::optional<Overhang> found;
  if (!face.bounded) return found;
  for (const BoundEdge& bound : edgesOf(face)) {
    // At the edge within the band counts: a support that reached it goes on over it.
    const bool past = std::any_of(outline.begin(), outline.end(), [&](const Vec& point) {
      return bound.edge.out.dot(point - face.point) > face.half_extent[bound.axis] - kLastingBand;
    });
    if (!past) continue;
    if (found) {
      found->corner = true;
      return found;
    }
    found = Overhang{bound.edge, {bound.axis, bound.side}, false};
  }
  return found;
}

/// The weights of p in the triangle (a, b, c) of the face (in its frame e1, e2).
std::array<double, 3> barycentric(const Setting& setting, const Vec& a, const Vec& b, const Vec& c,
                                  const Vec& p) {
  const auto flat = [&](const Vec& x) {
    return Eigen::Vector2d((x - a).dot(setting.e1), (x - a).dot(setting.e2));
  };
  Eigen::Matrix2d basis;
  basis << flat(b), flat(c);
  const Eigen::Vector2d l = basis.partialPivLu().solve(flat(p));
  return {1 - l.x() - l.y(), l.x(), l.y()};
}

/// The normal forces of a support cut by the face's edge, with its centre of pressure
/// `pressure` strictly inside the part on the face: a face's polygon cut by the edge's line
/// (Sutherland and Hodgman's clipping), the least-norm forces >= 0 on up to four points
/// (polygonForces) or, on five, the fan triangle from its first point that holds the centre of
/// pressure; a cap's disc cut to a segment, its chord's two ends and the rim's point on the ray
/// from the chord's middle through the centre of pressure, which hold it in their triangle. One
/// documented choice among the statically indeterminate distributions, as the whole face's.
Expected<std::vector<SupportForce>> overhangForces(const Support& support, const Setting& setting,
                                                   const FaceEdge& edge, const Vec& pressure,
                                                   double total, const Vec& friction_ratio) {
  const auto past = [&](const Vec& x) { return edge.out.dot(x - edge.point); };
  std::vector<Vec> points;
  std::vector<double> f;
  if (support.kind == SupportKind::kDisc) {
    const Vec& c = support.centre;
    const double r = support.radius, d = past(c);
    const Vec middle = c - d * edge.out;
    const double half = std::sqrt(std::max(0.0, r * r - d * d));
    const Vec ray = pressure - middle;
    if (!((pressure - c).norm() < r && past(pressure) < 0 && ray.norm() > 0)) {
      return notYet("tipping: the centre of pressure leaves the cap's part on the face");
    }
    const Vec dir = ray.normalized();
    const double b = dir.dot(middle - c);
    const double reach = -b + std::sqrt(b * b - ((middle - c).squaredNorm() - r * r));
    const double l = ray.norm() / reach;
    points = {middle - half * edge.along, middle + half * edge.along, middle + reach * dir};
    f = {total * (1 - l) / 2, total * (1 - l) / 2, total * l};
  } else {
    // The polygon in order about its centroid, then cut by the edge's line.
    std::vector<Vec> ring = support.feet;
    Vec centroid = Vec::Zero();
    for (const Vec& foot : ring) centroid += foot;
    centroid /= static_cast<double>(ring.size());
    std::sort(ring.begin(), ring.end(), [&](const Vec& a, const Vec& b) {
      return std::atan2((a - centroid).dot(setting.e2), (a - centroid).dot(setting.e1)) <
             std::atan2((b - centroid).dot(setting.e2), (b - centroid).dot(setting.e1));
    });
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const Vec& p = ring[i];
      const Vec& q = ring[(i + 1) % ring.size()];
      const double dp = past(p), dq = past(q);
      if (dp <= 0) points.push_back(p);
      if ((dp < 0 && dq > 0) || (dp > 0 && dq < 0))
        points.push_back(p + (q - p) * (dp / (dp - dq)));
    }
    Support cut = support;
    cut.feet = points;
    const auto [q, p] = inFace(cut, setting, pressure);
    if (points.size() < 3 || !strictlyInside(q, p)) {
      return notYet("tipping: the centre of pressure leaves the face's part on the face");
    }
    if (points.size() <= 4) f = polygonForces(q, p, total, true);
    if (f.empty() || *std::min_element(f.begin(), f.end()) < -1e-12 * total) {
      f.assign(points.size(), 0.0);
      for (std::size_t i = 1; i + 1 < points.size(); ++i) {
        const auto w = barycentric(setting, points[0], points[i], points[i + 1], pressure);
        if (*std::min_element(w.begin(), w.end()) < -1e-12) continue;
        f[0] = total * w[0], f[i] = total * w[1], f[i + 1] = total * w[2];
        break;
      }
    }
  }
  std::vector<SupportForce> forces;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double share = std::max(0.0, f[i]);
    forces.push_back({points[i], share, share * friction_ratio});
  }
  return forces;
}

/// The closed-form motion `plan` from `body` (its orientation `orientation`), its manifold
/// `forces` at the start.
LastingMotion plannedMotion(const LastingBody& body, const Plan& plan,
                            const Eigen::Quaterniond& orientation,
                            std::vector<SupportForce> forces) {
  LastingMotion motion;
  motion.state = plan.state;
  motion.start = body.time;
  motion.centre0 = body.centre;
  motion.velocity0 = plan.velocity;
  motion.acceleration = plan.acceleration;
  motion.angular_velocity0 = plan.angular_velocity;
  motion.angular_acceleration = plan.angular_acceleration;
  motion.orientation0 = orientation;
  motion.forces = std::move(forces);
  return motion;
}

/// A face or a cap past a bounded face's edge (`overhang`), moving by `plan` (resting or
/// sliding, without turning) with its centre of pressure `pressure`: where that is past the
/// edge's line (within the touching band), the body tips over the edge (tipOverFaceEdge); else
/// it rests or slides on by the closed form, its support the part on the face (overhangForces,
/// cut anew at each instant: forces_over), until its centre of pressure reaches the edge's line
/// ("stops": asked again there, it tips), a point reaches another of the face's edges, or the
/// plan's own end.
Expected<LastingMotion> overhangMotion(const LastingBody& body, const FlatFace& face,
                                       const Support& support, const Setting& setting,
                                       const Overhang& overhang, const Plan& plan,
                                       const Vec& pressure, double total, const Vec& friction_ratio,
                                       double tolerance) {
  const FaceEdge& edge = overhang.edge;
  if (support.kind != SupportKind::kPolygon && support.kind != SupportKind::kDisc) {
    return notYet("the body overhangs the face's edge (a point of its support is off it)");
  }
  const double behind = -edge.out.dot(pressure - edge.point);
  if (behind <= kLastingBand) {
    return tipOverFaceEdge(body, face, edge, setting.n, tolerance);
  }
  auto forces = overhangForces(support, setting, edge, pressure, total, friction_ratio);
  if (!forces) return forces.error();
  LastingMotion motion =
      plannedMotion(body, plan, body.orientation.normalized(), std::move(forces.value()));
  motion.forces_over = [support, setting, edge, pressure, total, friction_ratio, start = body.time,
                        v = plan.velocity, a = plan.acceleration](double t) {
    const double s = t - start;
    const Vec shift = v * s + 0.5 * a * s * s;
    Support moved = support;
    for (Vec& foot : moved.feet) foot += shift;
    moved.centre += shift;
    auto at = overhangForces(moved, setting, edge, pressure + shift, total, friction_ratio);
    return at ? at.value() : std::vector<SupportForce>{};
  };
  const Track& track = plan.track;
  const double toward = track.direction.dot(edge.out);
  const double tips = firstReach(toward * track.speed, toward * track.acceleration, behind);
  const double edge_reached =
      edgeReached(outlineOf(support, face.along_u, face.along_v), face, track, overhang.bound);
  double lasts = plan.lasts;
  motion.ends = plan.ends;
  if (tips < lasts) {
    lasts = tips;
    motion.ends = "stops";  // asked again there: it tips over the edge
  }
  if (edge_reached < lasts) {
    lasts = edge_reached;
    motion.ends = "stops";  // asked again there: over the face's corner (pivotOverFaceEdge)
  }
  if (std::isfinite(lasts)) motion.until = body.time + lasts;
  return motion;
}

/// The tipping motion of a support the closed forms do not carry: a box's (or a hull's) corners
/// (one, an edge's two, a face's), each sticking, sliding or leaving (pivotOnFace); a side's two
/// rims' or ends' lowest points; one point of a rim or an end, or a cap's rim point towards
/// `lean` (world, in the cap's plane: where it tips or rocks) (pivotOnRound).
Expected<LastingMotion> pivotOnSupport(const LastingBody& body, const FlatFace& face,
                                       const Support& support, const Eigen::Matrix3d& rotation,
                                       const Vec& lean, double tolerance) {
  if (!support.corners.empty()) return pivotOnFace(body, face, support.corners, tolerance);
  if (support.kind == SupportKind::kLine) {
    return pivotOnRound(body, face, {-1, 1}, Vec::Zero(), tolerance);
  }
  return pivotOnRound(body, face, {support.end}, rotation.transpose() * lean, tolerance);
}

/// A support whose turning the closed forms do not carry (keptSpin's `refused`): a face's
/// corners and a side that spin or rock tip (pivotOnSupport); a cap rocks over the rim's point
/// its turning lowers fastest (w x n), and spinning about the normal alone turns on four points
/// of its rim (spinOnCap); over a table's edge, or a shape without such a motion, refused.
Expected<LastingMotion> turningOnFace(const LastingBody& body, const FlatFace& face,
                                      const Support& support, const Setting& setting,
                                      const Eigen::Matrix3d& rotation, bool overhanging,
                                      const Error& refused, double tolerance) {
  if (overhanging) {
    // Over a table's edge, spinning or rocking: its corners (or its rim's point farthest from
    // the edge) on the table and its crossings of the edge (pivotOverFaceEdge).
    if (std::holds_alternative<Cuboid>(body.shape) ||
        std::holds_alternative<Cylinder>(body.shape)) {
      return pivotOverFaceEdge(body, face, tolerance);
    }
    return refused;
  }
  const Vec lowered = body.angular_velocity.cross(setting.n);
  const bool rocks = lowered.norm() * setting.reach > kLastingStillSpeed;
  if (support.kind == SupportKind::kDisc) {
    if (rocks) return pivotOnSupport(body, face, support, rotation, lowered, tolerance);
    return spinOnCap(body, face, support.end, tolerance);
  }
  if (support.kind == SupportKind::kLine || !support.corners.empty()) {
    return pivotOnSupport(body, face, support, rotation, lowered, tolerance);
  }
  return refused;
}

/// Whether a side (a cylinder's or a capsule's, its axis the principal z) moving along `track`
/// reaches a bounded face's edge all along its line: its axis along one of the face's sides and
/// its track square to the axis (each within kSideAlongEdge).
bool acrossEdges(const LastingBody& body, const FlatFace& face, const Track& track) {
  const Vec axis = body.orientation.normalized() * Vec::UnitZ();
  return (axis.cross(face.along_u).norm() <= kSideAlongEdge ||
          axis.cross(face.along_v).norm() <= kSideAlongEdge) &&
         std::abs(track.direction.dot(axis)) <= kSideAlongEdge;
}

/// The closed forms on a face or a cap, a side or a face's polygon: the plan (resting, sliding
/// or rolling), the centre of pressure and the forces it puts on the support's points, until the
/// plan's end or the support reaching the face's edge; over an edge, overhangMotion; where the
/// centre of pressure leaves the support, the tipping (pivotOnSupport, towards it).
Expected<LastingMotion> plannedOnFace(const LastingBody& body, const FlatFace& face,
                                      Support support, const Setting& setting,
                                      const Eigen::Quaterniond& orientation,
                                      const std::vector<Vec>& outline,
                                      const std::optional<Overhang>& overhang, double roll,
                                      double tolerance) {
  const Eigen::Matrix3d rotation = orientation.toRotationMatrix();
  // The motion: the velocity's part in the face (its normal part settled), a roll kept.
  const Vec in_face = body.velocity - body.velocity.dot(setting.n) * setting.n;
  const double mu = face.friction;
  Expected<Plan> planned = support.kind == SupportKind::kLine
                               ? rollPlan(body, support, setting, mu, in_face, roll)
                               : translationPlan(in_face, setting.g_t, setting.g_n, mu);
  if (!planned && !overhang) {
    // A slide whose direction turns (across a slope), or a side rolling while it slides along
    // its axis (its contact line's slip turns: its parts along and across the axis slow at
    // different rates, gravity along the axis too): no closed form here carries them; its
    // corners, its cap's four rim points or its side's two ends, each sticking or sliding, do
    // (pivotOnFace, spinOnCap, pivotOnRound).
    if (support.kind == SupportKind::kLine ||
        (support.kind == SupportKind::kPolygon && !support.corners.empty())) {
      return pivotOnSupport(body, face, support, rotation, Vec::Zero(), tolerance);
    }
    if (support.kind == SupportKind::kDisc) return spinOnCap(body, face, support.end, tolerance);
  }
  if (!planned) return planned.error();
  const Plan& plan = planned.value();

  // The forces: N = m g_n, friction m (a - g_t), the centre of pressure h (g_t - a) / g_n from
  // the centre's foot. A side's centre of pressure is taken along its axis only: across it, the
  // roll's J alpha balances the friction's moment. The friction's moment about the normal is 0
  // there too: gravity has no part along the axis while the body rolls, none across it while it
  // rests or slides (rollPlan's cases).
  const double total = body.mass * setting.g_n;
  const Vec friction_ratio = (plan.acceleration - setting.g_t) / setting.g_n;
  const Vec pressure =
      setting.foot + setting.height * (setting.g_t - plan.acceleration) / setting.g_n;
  if (overhang) {
    return overhangMotion(body, face, support, setting, *overhang, plan, pressure, total,
                          friction_ratio, tolerance);
  }
  auto forces = supportForces(support, setting, pressure, total, friction_ratio, rotation,
                              tippingOf(plan.state));
  if (!forces && (support.kind != SupportKind::kPolygon || !support.corners.empty())) {
    // Tipping: a face over its corners, a side over an end, a cap over its rim's point towards
    // the centre of pressure.
    return pivotOnSupport(body, face, support, rotation, pressure - support.centre, tolerance);
  }
  if (!forces) return forces.error();

  LastingMotion motion = plannedMotion(body, plan, orientation, std::move(forces.value()));
  const double edge = edgeReached(outline, face, plan.track);
  double lasts = plan.lasts;
  motion.ends = plan.ends;
  if (edge < lasts) {
    lasts = edge;
    // A face or a cap goes on over the edge (asked again there: overhangMotion), and a side
    // whose line reaches it all along, rolling across it (rollOverFaceEdge); a side reaching it
    // at one end is not modelled yet.
    motion.ends = support.kind == SupportKind::kLine && !acrossEdges(body, face, plan.track)
                      ? "a point of its support reaches the face's edge"
                      : "stops";
  }
  if (std::isfinite(lasts)) motion.until = body.time + lasts;
  return motion;
}

/// A cap or a face whose turning lifts part of its support off the face faster than a settled
/// body's while no point of it approaches (a can rocking onto its cap, a box onto its face): it
/// tips over what its turning lowers, the rest leaving (a cap's rim point along w x n; a face's
/// corners that do not leave), never an impulse that holds the leaving points down. Empty where
/// it is not so.
std::optional<Expected<LastingMotion>> rockingOff(const LastingBody& body, const FlatFace& face,
                                                  const Support& support, const Setting& setting,
                                                  const Eigen::Matrix3d& rotation,
                                                  double tolerance) {
  const Vec lowered = body.angular_velocity.cross(setting.n);
  if (!(lowered.norm() * setting.reach > kLastingStillSpeed)) return std::nullopt;
  const auto speed = [&](const Vec& point) {
    return (body.velocity + body.angular_velocity.cross(point - body.centre)).dot(setting.n);
  };
  const std::vector<Vec> outline = outlineOf(support, setting.e1, setting.e2);
  if (std::any_of(outline.begin(), outline.end(),
                  [&](const Vec& p) { return speed(p) < -setting.settled_speed; })) {
    return std::nullopt;  // a point approaches: an impact, not a lasting contact
  }
  if (support.kind == SupportKind::kDisc) {
    return pivotOnSupport(body, face, support, rotation, lowered, tolerance);
  }
  if (support.kind == SupportKind::kLine && support.feet.size() == 2) {
    // A side with one end rising: it tips over the other end's rim (or a capsule's end).
    const int staying = speed(support.feet[0]) <= speed(support.feet[1]) ? 0 : 1;
    const Vec axis = rotation.col(2);
    const int end =
        axis.dot(support.feet[static_cast<std::size_t>(staying)] - body.centre) < 0 ? -1 : 1;
    return pivotOnRound(body, face, {end}, Vec::Zero(), tolerance);
  }
  if (support.kind == SupportKind::kPolygon && support.corners.size() == support.feet.size()) {
    Support staying = support;
    staying.corners.clear();
    for (std::size_t i = 0; i < support.feet.size(); ++i) {
      if (speed(support.feet[i]) <= setting.settled_speed) {
        staying.corners.push_back(support.corners[i]);
      }
    }
    if (!staying.corners.empty()) {
      return pivotOnSupport(body, face, staying, rotation, lowered, tolerance);
    }
  }
  return std::nullopt;
}

}  // namespace

Expected<LastingMotion> lastingOnFace(const LastingBody& body, const FlatFace& face,
                                      double tolerance) {
  if (Status status = checkLasting(body, face); !status) return status.error();
  if (const auto* sphere = std::get_if<Sphere>(&body.shape)) {
    return ballOnFace(body, face, sphere->radius);
  }
  const Eigen::Quaterniond orientation = body.orientation.normalized();
  const Eigen::Matrix3d rotation = orientation.toRotationMatrix();
  const Setting setting = settingOf(body, face, true);
  auto found = supportOf(body, rotation, face, setting);
  if (!found && found.error().field == "body.centre") {
    // Below the face's plane past its edge: turned over the edge (a state halfway over it), or a
    // side rolling over it.
    if (const auto tilted = tiltedOverEdge(body, face)) {
      return tipOverFaceEdge(body, face, tilted->first, tilted->second, tolerance);
    }
    if (const auto edge = sideOnEdge(body, face)) {
      return rollOverFaceEdge(body, face, *edge, tolerance);
    }
    // Or on the face's edge by an edge or a rim of its own, no point of it on the face (a box
    // that struck the table's edge with its own): its crossings of the edge.
    if (face.bounded && (std::holds_alternative<Cuboid>(body.shape) ||
                         std::holds_alternative<Cylinder>(body.shape))) {
      auto over = pivotOverFaceEdge(body, face, tolerance);
      if (over || over.error().field != "body.centre") return over;
    }
  }
  if (!found) return found.error();
  const Support& support = found.value();
  if (Status status = checkOnFace(body, face, support, setting); !status) {
    if (const auto rocking = rockingOff(body, face, support, setting, rotation, tolerance)) {
      return *rocking;
    }
    return status.error();
  }
  // A side whose line lies on the face's edge, going over it: it rolls over the edge.
  if (support.kind == SupportKind::kLine) {
    if (const auto edge = sideOnEdge(body, face)) {
      return rollOverFaceEdge(body, face, *edge, tolerance);
    }
  }
  // One corner, an edge, one point of a rim or an end: it tips.
  if (support.kind == SupportKind::kCorners || support.kind == SupportKind::kRound) {
    return pivotOnSupport(body, face, support, rotation, Vec::Zero(), tolerance);
  }
  // Outlines taken before supportForces chooses a cap's four points. A side's line over the
  // edge is checkOnFace's (not modelled yet); a face or a cap goes on over it.
  const std::vector<Vec> outline = outlineOf(support, face.along_u, face.along_v);
  const std::optional<Overhang> overhang =
      support.kind == SupportKind::kLine ? std::nullopt : overhangOf(outline, face);
  if (overhang && overhang->corner) {
    // Over the face's corner: its corners (or its rims' lowest points) on the table, its
    // crossings of the table's edges and the table's corner on its face (pivotOverFaceEdge).
    if (std::holds_alternative<Cuboid>(body.shape) ||
        std::holds_alternative<Cylinder>(body.shape)) {
      return pivotOverFaceEdge(body, face, tolerance);
    }
    return notYet("a hull over the face's corner (past two of its edges)");
  }
  const auto spin = keptSpin(support, setting, body.angular_velocity);
  if (!spin) {
    return turningOnFace(body, face, support, setting, rotation, overhang.has_value(), spin.error(),
                         tolerance);
  }
  return plannedOnFace(body, face, support, setting, orientation, outline, overhang, spin.value(),
                       tolerance);
}

Expected<LastingMotion> lastingOnFaces(const LastingBody& body, const std::vector<FlatFace>& faces,
                                       double tolerance) {
  if (faces.empty()) return Error{"faces", "must hold at least one face"};
  if (faces.size() == 1) return lastingOnFace(body, faces.front(), tolerance);
  bool pressed = false;
  for (std::size_t i = 0; i < faces.size(); ++i) {
    if (Status status = checkBodyAndFace(body, faces[i]); !status) {
      Error error = status.error();
      if (error.field.rfind("face", 0) == 0) {
        error.field = "faces[" + std::to_string(i) + "]" + error.field.substr(4);
      }
      return error;
    }
    pressed = pressed || -body.gravity.dot(faces[i].normal) > 0;
  }
  if (!pressed) {
    return Error{"body.gravity", "presses the body onto none of the faces: no lasting contact"};
  }
  return pivotOnFaces(body, faces, tolerance);
}

std::optional<double> flatBouncesEnd(const LastingBody& body, const FlatFace& face,
                                     double restitution) {
  if (!(std::isfinite(restitution) && restitution >= 0 && restitution < 1)) return std::nullopt;
  if (!checkLasting(body, face)) return std::nullopt;
  const Setting setting = settingOf(body, face, false);
  // Flat: approaching along the normal, no slip and no turning (every point of the manifold
  // approaches at u, to 1e-9 m/s).
  const double approach = -body.velocity.dot(setting.n);
  const Vec slip = body.velocity + approach * setting.n;
  if (!(approach > kLastingStillSpeed) || slip.norm() > kLastingStillSpeed ||
      body.angular_velocity.norm() * setting.reach > kLastingStillSpeed) {
    return std::nullopt;
  }
  // A ball's one point is under its centre: the impact sends it back at e u. A body of corners
  // or sides: the joint frictionless rule sends every point back at e u without turning only
  // where its least-norm impulses, centred under the centre of mass, are >= 0 (none dropped).
  if (!std::holds_alternative<Sphere>(body.shape)) {
    const Eigen::Matrix3d rotation = body.orientation.normalized().toRotationMatrix();
    auto found = supportOf(body, rotation, face, setting);
    if (!found) return std::nullopt;
    Support support = found.value();
    if (support.kind == SupportKind::kCorners || support.kind == SupportKind::kRound) {
      return std::nullopt;
    }
    if (support.kind == SupportKind::kPolygon) {
      const auto [q, p] = inFace(support, setting, setting.foot);
      const std::vector<double> shares = polygonForces(q, p, 1.0, false);
      if (*std::min_element(shares.begin(), shares.end()) < 0) return std::nullopt;
    } else if (support.kind == SupportKind::kLine) {
      const double l1 = (support.feet[0] - setting.foot).dot(support.axis);
      const double l2 = (support.feet[1] - setting.foot).dot(support.axis);
      if (!(l1 <= 0 && 0 <= l2)) return std::nullopt;
    }
  }
  // The k-th bounce leaves at e^k e u and lands 2 e^k e u / g_n later: the sum
  // 2 e u / (g_n (1 - e)) (doc/model.md, "Coming to rest (Zeno)").
  return body.time + 2 * restitution * approach / (setting.g_n * (1 - restitution));
}

}  // namespace collision_response::core
