#include "monitor/shaped_motion.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "collision_response/core/body_shape.h"
#include "collision_response/core/mass_properties.h"
#include "collision_response/core/rigid_impact.h"
#include "collision_response/core/triangle_mesh.h"
#include "geometry/narrow_phase.h"

namespace collision_response::core {

namespace {

/// The shape's points about the centre of mass in the principal frame: a box's corners, where
/// the frame is turned or the centre moved.
ConvexHull boxCorners(const Cuboid& box, const Eigen::Matrix3d& principal_from_body,
                      const Eigen::Vector3d& centre_of_mass) {
  ConvexHull hull;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d sign((corner & 1) ? 1.0 : -1.0, (corner & 2) ? 1.0 : -1.0,
                               (corner & 4) ? 1.0 : -1.0);
    hull.vertices.push_back(principal_from_body *
                            (sign.cwiseProduct(box.half_size) - centre_of_mass));
  }
  return hull;
}

}  // namespace

SolverBody solverBodyOf(const PrincipalBody& principal, const TumblingBody& body, double time) {
  SolverBody solver;
  solver.inverse_mass = 1.0 / principal.mass;
  solver.velocity = body.velocityAt(time);
  solver.angular_velocity = body.angularVelocityAt(time);
  solver.inertia_kind = InverseInertiaKind::kTensor;
  const Eigen::Matrix3d rotation = body.orientationAt(time).toRotationMatrix();
  solver.inverse_inertia =
      rotation * principal.moments.cwiseInverse().asDiagonal() * rotation.transpose();
  return solver;
}

Expected<PrincipalBody> principalBody(const BodySpec& body, const std::string& field) {
  auto properties = bodyMassProperties(body, field + ".inertia");
  if (!properties) return properties.error();
  PrincipalBody principal;
  principal.mass = properties->mass;
  principal.centre_of_mass = properties->centre_of_mass;
  const Eigen::Matrix3d& inertia = properties->inertia;
  const bool diagonal = inertia(0, 1) == 0.0 && inertia(0, 2) == 0.0 && inertia(1, 2) == 0.0 &&
                        inertia(1, 0) == 0.0 && inertia(2, 0) == 0.0 && inertia(2, 1) == 0.0;
  Eigen::Matrix3d body_from_principal = Eigen::Matrix3d::Identity();
  if (diagonal) {
    principal.moments = inertia.diagonal();
  } else {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(inertia);
    principal.moments = solver.eigenvalues();
    body_from_principal = solver.eigenvectors();
    if (body_from_principal.determinant() < 0) body_from_principal.col(2) *= -1.0;
  }
  principal.body_from_principal = Eigen::Quaterniond(body_from_principal);
  const bool moved = !diagonal || !principal.centre_of_mass.isZero(0.0);
  const Eigen::Matrix3d principal_from_body = body_from_principal.transpose();
  const Shape shape = shapeOf(body);
  if (const auto* sphere = std::get_if<Sphere>(&shape)) {
    principal.shape =
        Sphere{principal_from_body * (sphere->centre - principal.centre_of_mass), sphere->radius};
  } else if (const auto* box = std::get_if<Cuboid>(&shape)) {
    if (moved) {
      principal.shape = boxCorners(*box, principal_from_body, principal.centre_of_mass);
    } else {
      principal.shape = *box;
    }
  } else if (const auto* mesh = std::get_if<Mesh>(&shape)) {
    // A mesh body is the convex hull of its vertices (its mass properties are the hull's).
    if (mesh->triangles == nullptr) return Error{field + ".resource", "has no loaded mesh"};
    const auto hull = convexHull(mesh->triangles->vertices(), field + ".resource");
    if (!hull) return hull.error();
    ConvexHull corners;
    for (const Eigen::Vector3d& vertex : hull->vertices) {
      corners.vertices.push_back(principal_from_body * (vertex - principal.centre_of_mass));
    }
    principal.shape = std::move(corners);
  } else if (moved) {
    return Error{field + ".inertia",
                 "not yet: a cylinder's or a capsule's tensor must have no products of inertia "
                 "(its axis and two across it principal), as its uniform solid's has"};
  } else if (const auto* cylinder = std::get_if<Cylinder>(&shape)) {
    principal.shape = *cylinder;
  } else if (const auto* capsule = std::get_if<Capsule>(&shape)) {
    principal.shape = *capsule;
  }
  return principal;
}

namespace {

/// Contacts this close to the earliest (relative to the instant, 1e-12) strike together.
constexpr double kSimultaneous = 1e-12;
/// s: the longest step separation takes (a body's points part within far less).
constexpr double kSeparationSpan = 1.0;
/// s: a flight through air that stalls within this of its start is held still (holdIfStalled).
constexpr double kStallProbe = 1e-3;

/// An obstacle as the solver sees it at `time`: immovable, moving on as it moves.
SolverBody obstacleBody(const PlacedShape& placed, double time) {
  const PlacedShape now = shapeAt(placed, time);
  SolverBody solver;
  solver.velocity = now.pose.velocity;
  solver.angular_velocity = now.pose.angular_velocity;
  solver.inertia_kind = InverseInertiaKind::kTensor;
  return solver;
}

/// The body's flight from a state (`orientation`: world from principal): its parabola, or through
/// the scene's air.
Expected<TumblingBody> flightFrom(const PrincipalBody& principal, const ShapedScene& scene,
                                  double time, const Eigen::Vector3d& position,
                                  const Eigen::Vector3d& velocity,
                                  const Eigen::Quaterniond& orientation,
                                  const Eigen::Vector3d& angular_velocity) {
  auto flight = TumblingBody::create(principal.shape, principal.moments, time, position, velocity,
                                     scene.acceleration, orientation, angular_velocity);
  if (!flight) return flight.error();
  return flight->throughAir(scene.air, scene.flight_tolerance);
}

}  // namespace

Expected<ShapedMotion> ShapedMotion::create(PrincipalBody principal,
                                            std::vector<ShapedObstacle> placed, ShapedScene scene,
                                            const BodyStateSample& state) {
  const Eigen::Quaterniond orientation =
      state.orientation.normalized() * principal.body_from_principal;
  auto flight = flightFrom(principal, scene, state.time, state.position, state.velocity,
                           orientation, state.angular_velocity);
  if (!flight) return flight.error();
  ShapedMotion motion(std::move(principal), std::move(scene), std::move(flight.value()),
                      state.time);
  motion.holdIfStalled(state.time);
  for (ShapedObstacle& obstacle : placed) {
    motion.obstacles_.push_back({std::move(obstacle), state.time, false});
  }
  return motion;
}

Status ShapedMotion::restartFrom(const BodyStateSample& state) {
  const Eigen::Quaterniond orientation =
      state.orientation.normalized() * principal_.body_from_principal;
  auto flight = flightFrom(principal_, scene_, state.time, state.position, state.velocity,
                           orientation, state.angular_velocity);
  if (!flight) return flight.error();
  flight_ = std::move(flight.value());
  time_ = state.time;
  holdIfStalled(state.time);
  for (Watched& w : obstacles_) {
    w.clear_from = state.time;
    w.parted = false;
  }
  struck_.clear();
  lasting_.clear();
  landed_.reset();
  return Ok{};
}

namespace {

/// m/s and rad/s: bounds on a lasting motion's centre speed and turning speed over [from, until]
/// (from < until). Its closed forms (a constant acceleration, a constant angular acceleration
/// about a fixed axis) are affine in t, whose norms are convex: their largest is at an end. A
/// tipping never gains energy: its kinetic energy K(t) <= K(from) + m g . (c(t) - c(from)) <=
/// K(from) + m |g| V T over the span T, with V^2 = 2 K_max / m, so V <= |g| T + sqrt((|g| T)^2
/// + 2 K(from) / m) (its integration's energy error taken in by a margin of 1e-6 of the
/// energy), and |w| <= sqrt(2 K_max / J_min).
std::pair<double, double> lastingSpeedBounds(const LastingMotion& lasting,
                                             const PrincipalBody& principal,
                                             const Eigen::Vector3d& gravity, double from,
                                             double until) {
  constexpr double kMargin = 1 + 1e-12;
  if (!lasting.pivot) {
    return {kMargin * std::max(lasting.velocityAt(from).norm(), lasting.velocityAt(until).norm()),
            kMargin * std::max(lasting.angularVelocityAt(from).norm(),
                               lasting.angularVelocityAt(until).norm())};
  }
  return energySpeedBounds(principal, lasting.velocityAt(from), lasting.angularVelocityAt(from),
                           lasting.orientationAt(from), gravity, until - from);
}

}  // namespace

std::pair<double, double> energySpeedBounds(const PrincipalBody& principal,
                                            const Eigen::Vector3d& velocity,
                                            const Eigen::Vector3d& angular_velocity,
                                            const Eigen::Quaterniond& orientation,
                                            const Eigen::Vector3d& gravity, double span) {
  constexpr double kMargin = 1 + 1e-12;
  const Eigen::Vector3d w = orientation.toRotationMatrix().transpose() * angular_velocity;
  const double kinetic = 0.5 * principal.mass * velocity.squaredNorm() +
                         0.5 * w.dot(principal.moments.cwiseProduct(w));
  const double g_span = gravity.norm() * span;
  const double speed =
      g_span + std::sqrt(g_span * g_span + 2 * (1 + 1e-6) * kinetic / principal.mass + 1e-300);
  const double kinetic_max = 0.5 * principal.mass * speed * speed;
  return {kMargin * speed, kMargin * std::sqrt(2 * kinetic_max / principal.moments.minCoeff())};
}

namespace {

/// The first of doubling spans from `from` (1e-9 s on) within `until` at which `moving` is more
/// than the manifold's band from `obstacle`; empty where there is none.
std::optional<double> apartFrom(const BoundedMotion& moving, const PlacedShape& obstacle,
                                double from, double until) {
  const double band = FirstContactOptions{}.manifold_band;
  for (double span = 1e-9; from + span < until; span *= 2) {
    const auto body = moving.at(from + span);
    if (!body) return std::nullopt;
    const SurfaceGap gap = gapAt(*body, obstacle, from + span);
    if (!gap.overlapping && gap.gap > band) return from + span;
  }
  return std::nullopt;
}

}  // namespace

std::optional<ShapedMotion::Strike> ShapedMotion::struckWhileLasting(
    const LastingMotion& lasting, const std::vector<std::size_t>& resting_on, double from,
    double until) const {
  if (!(from < until)) return std::nullopt;
  BoundedMotion moving;
  const auto [centre_speed, angular_speed] =
      lastingSpeedBounds(lasting, principal_, scene_.acceleration, from, until);
  moving.centre_speed = centre_speed;
  moving.angular_speed = angular_speed;
  moving.reach = flight_.reach();
  moving.at = [&](double t) -> std::optional<TumblingBody> {
    auto body = TumblingBody::create(principal_.shape, principal_.moments, t, lasting.centreAt(t),
                                     lasting.velocityAt(t), Eigen::Vector3d::Zero(),
                                     lasting.orientationAt(t), lasting.angularVelocityAt(t));
    if (!body) return std::nullopt;
    return std::move(body.value());
  };
  std::optional<Strike> first;
  for (const Watched& w : obstacles_) {
    if (std::find(resting_on.begin(), resting_on.end(), w.placed.obstacle) != resting_on.end()) {
      continue;
    }
    const double horizon = first ? first->time : until;
    // Its step budget may run out on a slow approach: it goes on from where it is known apart
    // (an obstacle just struck and parted from: from where it is apart).
    for (double clear = std::max(from, w.clear_from); clear < horizon;) {
      const FirstContactResult result =
          firstContact(moving, w.placed.placed, clear, horizon - clear);
      if (result.contact) {
        const double closing = result.contact->closest.approach_speed;
        if (closing < -kLastingStillSpeed && result.contact->time <= clear) {
          // Touching where it starts and parting (a link that has just struck it, left behind):
          // looked at again from where it is apart.
          if (const auto apart = apartFrom(moving, w.placed.placed, clear, horizon)) {
            clear = *apart;
            continue;
          }
        }
        if (!first || result.contact->time < first->time) {
          first = Strike{result.contact->time, w.placed.obstacle, closing > kLastingSettled};
        }
        break;
      }
      if (result.inside_at_start) {
        first = Strike{clear, w.placed.obstacle, false};
        break;
      }
      if (!(result.clear_until > clear)) break;
      clear = result.clear_until;
    }
  }
  return first;
}

void ShapedMotion::placeObstacles(std::vector<ShapedObstacle> placed, double time) {
  obstacles_.clear();
  for (ShapedObstacle& obstacle : placed) obstacles_.push_back({std::move(obstacle), time, false});
}

BodyStateSample ShapedMotion::stateOn(const TumblingBody& flight, double time) const {
  BodyStateSample state;
  state.body = scene_.body;
  state.time = time;
  state.position = flight.positionAt(time);
  state.velocity = flight.velocityAt(time);
  state.angular_velocity = flight.angularVelocityAt(time);
  state.orientation = flight.orientationAt(time) * principal_.body_from_principal.conjugate();
  return state;
}

std::optional<std::size_t> ShapedMotion::insideAtStart() const {
  for (const Watched& w : obstacles_) {
    if (insideBeyond(flight_, w.placed.placed, time_, kLastingBand)) return w.placed.obstacle;
  }
  return std::nullopt;
}

std::vector<std::size_t> ShapedMotion::lastingWith() const {
  std::vector<std::size_t> with;
  for (const ObstacleContact& c : lasting_) with.push_back(c.obstacle);
  return with;
}

Expected<ShapedMotion::Found> ShapedMotion::next(double horizon, std::vector<ImpactRecord>& impacts,
                                                 bool through) {
  const std::vector<ObstacleContact> contacts = firstContacts(flight_, horizon, through);
  if (contacts.empty()) {
    if (through) {
      for (Watched& w : obstacles_) {
        if (w.clear_from < horizon) {
          w.clear_from = horizon;
          w.parted = false;
        }
      }
    }
    return Found{Event::kFree, horizon};
  }
  // An impact: every obstacle touching at the instant, each point of its manifold.
  const double at = contacts.front().contact.time;
  SolverBody moving = solverBody(flight_, at);
  const auto resolved = resolve(flight_, moving, contacts, at, impacts);
  if (!resolved) return resolved.error();
  if (!*resolved) {
    // Touching without approaching: parting, or a contact that lasts. Found again where the
    // body was last known apart from it (a slow graze, a roll on a rim), it lasts.
    bool again = false;
    for (const ObstacleContact& c : contacts) {
      const Watched& w = obstacles_[c.slot];
      again = again || (w.parted && at == w.clear_from);
    }
    // Past a step's end the motion goes on: the gap after the separation's step is looked at
    // whatever the horizon.
    const double beyond = through ? std::numeric_limits<double>::infinity() : horizon;
    const auto apart = again ? std::nullopt : separation(flight_, at, contacts, beyond);
    if (!apart) {
      lasting_ = contacts;
      lasting_time_ = at;
      return Found{Event::kLasting, at};
    }
    clearUntil(at, contacts, *apart);
    return Found{Event::kGrazed, at};
  }
  auto after = flightFrom(principal_, scene_, at, flight_.positionAt(at), moving.velocity,
                          flight_.orientationAt(at), moving.angular_velocity);
  if (!after) return after.error();
  landed_ = flight_;
  flight_ = std::move(after.value());
  time_ = at;
  holdIfStalled(at);
  struck_ = contacts;
  return Found{Event::kImpact, at};
}

void ShapedMotion::holdIfStalled(double time) {
  stalled_at_.reset();
  if (scene_.air.drag == 0.0 && scene_.air.lift == 0.0) return;
  flight_.positionAt(time + kStallProbe);  // its first steps, which any query takes
  const double stalled = flight_.stalledAt();
  if (!(stalled <= time + kStallProbe)) return;
  auto still = TumblingBody::create(principal_.shape, principal_.moments, stalled,
                                    flight_.positionAt(stalled), Eigen::Vector3d::Zero(),
                                    Eigen::Vector3d::Zero(), flight_.orientationAt(stalled),
                                    Eigen::Vector3d::Zero());
  if (still) flight_ = std::move(still.value());
  stalled_at_ = stalled;
}

double ShapedMotion::stalledAt() const { return stalled_at_.value_or(flight_.stalledAt()); }

bool ShapedMotion::leave(double horizon) {
  // The points just struck leave their obstacles: the next contact with those is looked for
  // once they are apart (separation), with every other obstacle from now.
  const auto apart = separation(flight_, time_, struck_, horizon);
  if (apart) {
    clearUntil(time_, struck_, *apart);
    return true;
  }
  // Struck at several obstacles at once (a wall the body slides into, and the floor under it):
  // those whose points part are looked at again once apart; the contact lasts with the others.
  lasting_.clear();
  lasting_time_ = time_;
  std::vector<std::pair<std::size_t, double>> parted;
  for (std::size_t slot = 0; slot < obstacles_.size(); ++slot) {
    std::vector<ObstacleContact> with;
    for (const ObstacleContact& c : struck_) {
      if (c.slot == slot) with.push_back(c);
    }
    if (with.empty()) continue;
    const auto own =
        with.size() < struck_.size() ? separation(flight_, time_, with, horizon) : std::nullopt;
    if (own) {
      parted.emplace_back(slot, *own);
    } else {
      lasting_.insert(lasting_.end(), with.begin(), with.end());
    }
  }
  clearUntil(time_, {}, time_);
  for (const auto& [slot, from] : parted) {
    obstacles_[slot].clear_from = from;
    obstacles_[slot].parted = true;
  }
  if (!lasting_.empty()) addTouching();
  return lasting_.empty();  // each obstacle's points part on their own: apart
}

void ShapedMotion::addTouching() {
  // Obstacles the body touches without being struck there (the floor under a box whose corner
  // strikes a wall as it slides): within the touching band, neither approaching nor leaving
  // faster than a settled body's, the contact lasts with them too.
  const double band = FirstContactOptions{}.manifold_band;
  for (std::size_t slot = 0; slot < obstacles_.size(); ++slot) {
    const bool in = std::any_of(lasting_.begin(), lasting_.end(),
                                [slot](const ObstacleContact& c) { return c.slot == slot; });
    if (in) continue;
    const PlacedShape& placed = obstacles_[slot].placed.placed;
    const SurfaceGap gap = gapAt(flight_, placed, time_);
    if (gap.overlapping || !(gap.gap_upper <= band)) continue;
    FirstContactOptions at_once;
    at_once.time_tolerance = std::numeric_limits<double>::infinity();
    const FirstContactResult result = firstContact(flight_, placed, time_, 0.0, at_once);
    if (!result.contact || std::abs(result.contact->closest.approach_speed) > kLastingSettled) {
      continue;
    }
    lasting_.push_back({obstacles_[slot].placed.obstacle, slot, *result.contact});
  }
}

bool ShapedMotion::part(double horizon) {
  if (lasting_.empty()) return false;
  const double time = lasting_time_;
  const double speed =
      flight_.velocityAt(time).norm() + flight_.angularSpeedBound() * flight_.reach();
  const double acceleration = flight_.accelerationBound(time, time + 1e-3);  // its steps' span
  const double band = FirstContactOptions{}.manifold_band;
  double step = std::max(band / (speed + std::sqrt(speed * speed + acceleration * band)),
                         4 * std::numeric_limits<double>::epsilon() * std::abs(time));
  for (; step <= 1e-3; step *= 2) {
    const double apart = time + step;
    bool open = true;
    for (const ObstacleContact& c : lasting_) {
      const SurfaceGap gap =
          gapAt(flight_, obstacles_[c.slot].placed.placed, std::min(apart, horizon));
      open = open && !gap.overlapping && gap.gap > 0;
    }
    if (open || !(apart < horizon)) {
      clearUntil(time, lasting_, apart);
      lasting_.clear();
      return true;
    }
  }
  return false;
}

Expected<std::pair<LastingBody, std::vector<FlatFace>>> ShapedMotion::lastingFaces() const {
  if (lasting_.empty()) return faceOf(lasting_, flight_, lasting_time_).error();
  std::pair<LastingBody, std::vector<FlatFace>> faces;
  for (const ObstacleContact& contact : lasting_) {
    auto face = faceOf({contact}, flight_, lasting_time_);
    if (!face) return face.error();
    faces.first = face->first;
    faces.second.push_back(face->second);
  }
  return faces;
}

std::optional<double> ShapedMotion::flatBouncesEnd() const {
  // The series' closed form is the parabola's: through air the bounces are flown one by one
  // until they settle (resolve's rule).
  if (scene_.air.drag != 0.0 || scene_.air.lift != 0.0) return std::nullopt;
  if (!landed_ || struck_.empty()) return std::nullopt;
  const auto face = faceOf(struck_, *landed_, time_);
  if (!face) return std::nullopt;
  const auto restitution = scene_.restitution(struck_.front().obstacle);
  if (!restitution) return std::nullopt;
  return core::flatBouncesEnd(face->first, face->second, *restitution);
}

/// The body on `body`'s flight at `time` touching the one obstacle of `contacts` on a flat face:
/// a fixed plane, or the face of a fixed box whose outward normal is the contact's (within the
/// manifold's band over the box's size: every point of the manifold on that face).
Expected<std::pair<LastingBody, FlatFace>> ShapedMotion::faceOf(
    const std::vector<ObstacleContact>& contacts, const TumblingBody& body, double time) const {
  if (contacts.size() != 1) {
    return Error{"contact", "not yet: a shaped body's lasting contact with " +
                                std::to_string(contacts.size()) + " obstacles at once"};
  }
  const ObstacleContact& contact = contacts.front();
  const PlacedShape& placed = obstacles_[contact.slot].placed.placed;
  if (placed.pose.velocity != Eigen::Vector3d::Zero() ||
      placed.pose.angular_velocity != Eigen::Vector3d::Zero()) {
    return Error{"contact", "not yet: a shaped body's lasting contact with a moving obstacle"};
  }
  FlatFace face;
  const auto friction = scene_.friction(contact.obstacle);
  if (!friction) return friction.error();
  face.friction = *friction;
  const Eigen::Vector3d outward = -contact.contact.closest.normal;  // out of the face
  if (const auto* plane = std::get_if<Plane>(&placed.shape)) {
    face.normal = plane->normal;
    face.point = plane->offset * plane->normal;
  } else if (const auto* box = std::get_if<Cuboid>(&placed.shape)) {
    const Eigen::Matrix3d axes = placed.pose.transform.linear();
    const Eigen::Vector3d local = axes.transpose() * outward;
    Eigen::Index axis = 0;
    local.cwiseAbs().maxCoeff(&axis);
    const double sign = local[axis] > 0 ? 1.0 : -1.0;
    face.normal = sign * axes.col(axis);
    const double band = FirstContactOptions{}.manifold_band;
    for (const ManifoldPoint& point : contact.contact.manifold) {
      const Eigen::Vector3d in_box =
          axes.transpose() * (point.point_b - placed.pose.transform.translation());
      if (!(std::abs(sign * in_box[axis] - box->half_size[axis]) <= band)) {
        return Error{"contact",
                     "not yet: a shaped body's lasting contact on an edge or a corner of a box"};
      }
    }
    face.point = placed.pose.transform.translation() + sign * box->half_size[axis] * axes.col(axis);
    face.bounded = true;
    const Eigen::Index u = (axis + 1) % 3, v = (axis + 2) % 3;
    face.along_u = axes.col(u);
    face.along_v = axes.col(v);
    face.half_extent = Eigen::Vector2d(box->half_size[u], box->half_size[v]);
  } else {
    return Error{"contact",
                 "not yet: a shaped body's lasting contact on an obstacle that is not a plane or "
                 "a box"};
  }
  LastingBody lasting;
  lasting.shape = principal_.shape;
  lasting.moments = principal_.moments;
  lasting.mass = principal_.mass;
  lasting.time = time;
  lasting.centre = body.positionAt(time);
  lasting.velocity = body.velocityAt(time);
  lasting.angular_velocity = body.angularVelocityAt(time);
  lasting.orientation = body.orientationAt(time);
  lasting.gravity = body.acceleration();
  return std::make_pair(lasting, face);
}

/// The earliest contacts (every obstacle touching then, within the instant's rounding), each
/// obstacle searched from the instant it is known apart until (Watched::clear_from); none
/// within the horizon: empty.
std::vector<ShapedMotion::ObstacleContact> ShapedMotion::firstContacts(const TumblingBody& body,
                                                                       double horizon,
                                                                       bool through) const {
  std::vector<ObstacleContact> found;
  for (std::size_t slot = 0; slot < obstacles_.size(); ++slot) {
    const PlacedShape& placed = obstacles_[slot].placed.placed;
    const double start = obstacles_[slot].clear_from;
    if (through && start == horizon) {
      // A motion that starts at the step's end (a state given there): an obstacle within the
      // touching band touches it from that instant (a played box resting 2e-15 m above the floor
      // would otherwise be found only as it falls the 2e-15 m, after the step).
      const SurfaceGap gap = gapAt(body, placed, horizon);
      if (gap.overlapping || !(gap.gap_upper <= FirstContactOptions{}.manifold_band)) continue;
      FirstContactOptions at_once;
      at_once.time_tolerance = std::numeric_limits<double>::infinity();
      const FirstContactResult result = firstContact(body, placed, horizon, 0.0, at_once);
      if (result.contact)
        found.push_back({obstacles_[slot].placed.obstacle, slot, *result.contact});
      continue;
    }
    if (!(start < horizon)) continue;
    // The advancement's step budget may run out on a slow graze before the horizon: it goes
    // on from where it is known apart.
    for (double clear = start;;) {
      const FirstContactResult result = firstContact(body, placed, clear, horizon - clear);
      if (result.contact) {
        found.push_back({obstacles_[slot].placed.obstacle, slot, *result.contact});
        break;
      }
      if (!(result.clear_until > clear && result.clear_until < horizon)) break;
      clear = result.clear_until;
    }
  }
  if (found.empty()) return found;
  double earliest = std::numeric_limits<double>::infinity();
  for (const ObstacleContact& c : found) earliest = std::min(earliest, c.contact.time);
  const double together = earliest + kSimultaneous * std::max(1.0, std::abs(earliest));
  std::vector<ObstacleContact> first;
  for (ObstacleContact& c : found) {
    if (c.contact.time <= together) first.push_back(std::move(c));
  }
  return first;
}

/// The body as the impact's solver sees it at `time`.
SolverBody ShapedMotion::solverBody(const TumblingBody& body, double time) const {
  return solverBodyOf(principal_, body, time);
}

/// After an impact or a graze at `time` with `contacts`' obstacles, apart from them at `apart`:
/// those are looked at again from `apart`, every other one from `time` (no contact with it
/// before: the contacts were the earliest), never from an earlier instant than it was known
/// apart until. Each obstacle keeps its own instant: one struck before a graze of another is not
/// looked at again from that impact's instant, where its points still touch it and would be found
/// again at once, for ever.
void ShapedMotion::clearUntil(double time, const std::vector<ObstacleContact>& contacts,
                              double apart) {
  for (Watched& w : obstacles_) {
    w.clear_from = std::max(w.clear_from, time);
    w.parted = false;
  }
  for (const ObstacleContact& c : contacts) {
    obstacles_[c.slot].clear_from = apart;
    obstacles_[c.slot].parted = true;
  }
}

/// Resolves the impact at `time` of `moving` (updated) with the contacts' points: one point by
/// Chatterjee and Ruina's law with the pair's friction, several at once by the same law over all
/// of them (resolveRigidSimultaneous with friction, rigid_impact.h). False where no point
/// approaches (a lasting contact).
Expected<bool> ShapedMotion::resolve(const TumblingBody& body, SolverBody& moving,
                                     const std::vector<ObstacleContact>& contacts, double time,
                                     std::vector<ImpactRecord>& impacts) {
  std::vector<SolverBody> bodies{moving};
  std::vector<ClusterContact> points;
  std::vector<std::size_t> point_obstacle;
  double fastest = 0.0;
  for (const ObstacleContact& c : contacts) {
    const PlacedShape& placed = obstacles_[c.slot].placed.placed;
    bodies.push_back(obstacleBody(placed, time));
    const auto restitution = scene_.restitution(c.obstacle);
    if (!restitution) return restitution.error();
    for (const ManifoldPoint& point : c.contact.manifold) {
      ClusterContact contact;
      contact.a = 0;
      contact.b = bodies.size() - 1;
      contact.normal = c.contact.closest.normal;
      contact.point = 0.5 * (point.point_a + point.point_b);
      contact.lever_a = point.lever_a;
      contact.lever_b = point.lever_b;
      contact.restitution = *restitution;
      const Eigen::Vector3d relative = body.pointVelocityAt(time, point.point_a) -
                                       bodies.back().velocity -
                                       bodies.back().angular_velocity.cross(point.lever_b);
      fastest = std::max(fastest, contact.normal.dot(relative));
      points.push_back(contact);
      point_obstacle.push_back(c.obstacle);
    }
  }
  if (!(fastest > 0)) return false;
  // Bounces that accumulate (a body settling, rocking from edge to edge) would go on for ever in
  // finitely many seconds: where even an elastic rebound could lift no point by more than
  // kLastingSettled of the body's reach, the contact is taken to last (lastingOnFace's own
  // rule for a settled body: one constant for both).
  const double lift = body.acceleration().norm() * kLastingSettled * body.reach();
  if (fastest * fastest <= 2 * lift) return false;
  const bool bounces = fastest >= scene_.restitution_threshold;
  if (!bounces) {
    for (ClusterContact& point : points) point.restitution = 0.0;
  }
  const Eigen::Vector3d velocity_before = moving.velocity;
  const Eigen::Vector3d angular_before = moving.angular_velocity;
  std::vector<ImpactRecord> records;
  if (points.size() == 1) {
    const auto friction = scene_.friction(point_obstacle.front());
    if (!friction) return friction.error();
    auto outcome = resolveRigidImpact(bodies[0], bodies[1], points.front(),
                                      points.front().restitution, *friction);
    if (!outcome) return outcome.error();
    ImpactRecord record = recordOf(points.front(), point_obstacle.front(), time, bodies[1]);
    record.impulse = outcome->normal_impulse;
    record.friction_impulse = outcome->tangential_impulse.norm();
    record.energy_lost = outcome->energy_lost;
    records.push_back(record);
  } else {
    std::vector<double> frictions;
    for (const std::size_t o : point_obstacle) {
      const auto friction = scene_.friction(o);
      if (!friction) return friction.error();
      frictions.push_back(*friction);
    }
    auto outcomes = resolveRigidSimultaneous(bodies, points, frictions);
    if (!outcomes) return outcomes.error();
    for (std::size_t k = 0; k < points.size(); ++k) {
      const FrictionalOutcome& outcome = (*outcomes)[k];
      if (outcome.frictionless_rule && !frictionless_at_) frictionless_at_ = time;
      ImpactRecord record = recordOf(points[k], point_obstacle[k], time, bodies[points[k].b]);
      record.impulse = outcome.normal.impulse;
      record.friction_impulse = outcome.friction_impulse;
      record.energy_lost = outcome.normal.energy_lost + outcome.friction_energy_lost;
      records.push_back(record);
    }
  }
  moving = bodies[0];
  for (ImpactRecord& record : records) {
    record.velocity_a_before = velocity_before;
    record.angular_velocity_a_before = angular_before;
    record.velocity_a_after = moving.velocity;
    record.angular_velocity_a_after = moving.angular_velocity;
    impacts.push_back(record);
  }
  return true;
}

ImpactRecord ShapedMotion::recordOf(const ClusterContact& point, std::size_t obstacle, double time,
                                    const SolverBody& other) const {
  ImpactRecord record;
  record.time = time;
  record.body_a = scene_.body;
  record.other = obstacle;
  record.other_is_obstacle = true;
  record.contact_point = point.point;
  record.normal = point.normal;
  record.restitution = point.restitution;
  record.velocity_b_before = other.velocity;
  record.velocity_b_after = other.velocity;
  record.angular_velocity_b_before = other.angular_velocity;
  record.angular_velocity_b_after = other.angular_velocity;
  return record;
}

/// After an impact at `time`: the instant from which the obstacles it left are looked at again,
/// once every point of the body is apart from them: a step short enough that no point of the
/// body moves by half the manifold's band relative to them (V s + A s^2 / 2 <= band / 2, V the
/// bound on the points' relative speed, A on their acceleration: a point further than the band
/// from an obstacle at the impact was not struck, and cannot reach it within the step), after
/// which the gap to each obstacle must be open. Where it is not (the points struck leave too
/// slowly to part: plastic, or bounces that accumulate), or where nothing moves at all, the
/// contact lasts: empty.
std::optional<double> ShapedMotion::separation(const TumblingBody& body, double time,
                                               const std::vector<ObstacleContact>& left,
                                               double horizon) const {
  double speed = body.velocityAt(time).norm() + body.angularSpeedBound() * body.reach();
  // Its step is at most kSeparationSpan (below), over which the air's part is bounded.
  double acceleration = body.accelerationBound(time, time + kSeparationSpan);
  for (const ObstacleContact& c : left) {
    const PlacedShape now = shapeAt(obstacles_[c.slot].placed.placed, time);
    const double turning = now.pose.angular_velocity.norm();
    const double arm =
        (body.positionAt(time) - now.pose.transform.translation()).norm() + body.reach();
    speed += now.pose.velocity.norm() + turning * arm;
    acceleration += turning * (now.pose.velocity.norm() + turning * arm);
  }
  if (!(speed > 0) && !(acceleration > 0)) return std::nullopt;  // at rest, touching
  const double band = FirstContactOptions{}.manifold_band;
  const double step = std::min(
      kSeparationSpan, std::max(band / (speed + std::sqrt(speed * speed + acceleration * band)),
                                4 * std::numeric_limits<double>::epsilon() * std::abs(time)));
  const double apart = time + step;
  if (!(apart < horizon)) return apart;
  for (const ObstacleContact& c : left) {
    // Apart: the gap opened over the step (a body handed over a hair above a face's edge it
    // turns over, its face sliding along the edge, keeps the hair: it lasts).
    const SurfaceGap now = gapAt(body, obstacles_[c.slot].placed.placed, time);
    const SurfaceGap gap = gapAt(body, obstacles_[c.slot].placed.placed, apart);
    const double opened = now.gap > 0 ? now.gap + FirstContactOptions{}.distance_tolerance : 0.0;
    if (gap.overlapping || !(gap.gap > opened)) return std::nullopt;
  }
  return apart;
}

}  // namespace collision_response::core
