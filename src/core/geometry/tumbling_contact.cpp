#include "geometry/tumbling_contact.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "collision_response/core/triangle_mesh.h"
#include "geometry/narrow_phase.h"

namespace collision_response::core {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

std::string indexed(const char* field, std::size_t i) {
  return std::string(field) + "[" + std::to_string(i) + "]";
}

Status checkFiniteVector(const Eigen::Vector3d& v, const std::string& field) {
  const char* axes[] = {".x", ".y", ".z"};
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(v[i]))
      return Error{field + axes[i], "must be finite, got " + std::to_string(v[i])};
  }
  return Ok{};
}

Status checkPositive(double value, const std::string& field) {
  if (!(std::isfinite(value) && value > 0)) {
    return Error{field, "must be finite and > 0, got " + std::to_string(value)};
  }
  return Ok{};
}

Status checkConvexShape(const ConvexShape& shape) {
  if (const auto* sphere = std::get_if<Sphere>(&shape)) {
    if (Status s = checkFiniteVector(sphere->centre, "shape.centre"); !s) return s;
    return checkPositive(sphere->radius, "shape.radius");
  }
  if (const auto* box = std::get_if<Cuboid>(&shape)) {
    const char* names[] = {"shape.half_size.x", "shape.half_size.y", "shape.half_size.z"};
    for (int i = 0; i < 3; ++i) {
      if (Status s = checkPositive(box->half_size[i], names[i]); !s) return s;
    }
    return Ok{};
  }
  if (const auto* cylinder = std::get_if<Cylinder>(&shape)) {
    if (Status s = checkPositive(cylinder->radius, "shape.radius"); !s) return s;
    return checkPositive(cylinder->half_length, "shape.half_length");
  }
  if (const auto* capsule = std::get_if<Capsule>(&shape)) {
    if (Status s = checkPositive(capsule->radius, "shape.radius"); !s) return s;
    if (!(std::isfinite(capsule->half_length) && capsule->half_length >= 0)) {
      return Error{"shape.half_length",
                   "must be finite and >= 0, got " + std::to_string(capsule->half_length)};
    }
    return Ok{};
  }
  const auto& hull = std::get<ConvexHull>(shape);
  if (hull.vertices.size() < 4) {
    return Error{"shape.vertices",
                 "a hull needs at least 4 vertices, got " + std::to_string(hull.vertices.size())};
  }
  for (std::size_t i = 0; i < hull.vertices.size(); ++i) {
    if (!hull.vertices[i].allFinite()) {
      return Error{indexed("shape.vertices", i), "must be finite"};
    }
  }
  return Ok{};
}

/// The body placed at `time` (world from body).
PlacedConvex placedBody(const TumblingBody& body, double time) {
  return PlacedConvex(body.shape(), body.orientationAt(time).toRotationMatrix(),
                      body.positionAt(time));
}

/// A SurfaceGap from GJK's answer, the lever arms from the sides' centres.
SurfaceGap fromDistance(const ConvexDistance& d, const Eigen::Vector3d& centre_a,
                        const Eigen::Vector3d& centre_b) {
  SurfaceGap g;
  g.gap = d.lower;
  g.gap_upper = d.upper;
  g.overlapping = d.overlapping;
  g.normal = d.normal;
  g.point_a = d.point_a;
  g.point_b = d.point_b;
  g.lever_a = d.point_a - centre_a;
  g.lever_b = d.point_b - centre_b;
  return g;
}

/// What a side's surface says of the normal at its closest point: a flat face's (a box's face, a
/// cylinder's cap) is that face's normal, exactly; a cylinder's side's has no part along its
/// axis; elsewhere (an edge, a corner, a rim, a hull; a sphere or a capsule, whose point is
/// already its core's moved out along the normal) nothing.
struct SurfaceAt {
  enum class Kind { kNone, kFace, kSide } kind = Kind::kNone;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();   ///< the face's outward normal, the axis
  Eigen::Vector3d axis_point = Eigen::Vector3d::Zero();  ///< a side's axis at the point's height
  double radius = 0.0;                                   ///< a side's
};

SurfaceAt surfaceAt(const ConvexShape& shape, const Eigen::Matrix3d& turn,
                    const Eigen::Vector3d& centre, const Eigen::Vector3d& point) {
  const Eigen::Vector3d local = turn.transpose() * (point - centre);
  SurfaceAt at;
  if (const auto* cylinder = std::get_if<Cylinder>(&shape)) {
    const double r = cylinder->radius, h = cylinder->half_length, band = 1e-7 * (r + h);
    const double radial = std::hypot(local.x(), local.y());
    if (radial > r - band && std::abs(local.z()) < h - band) {
      at.kind = SurfaceAt::Kind::kSide;
      at.direction = turn.col(2);
      at.axis_point = centre + local.z() * turn.col(2);
      at.radius = r;
    } else if (radial < r - band && std::abs(local.z()) > h - band) {
      at.kind = SurfaceAt::Kind::kFace;
      at.direction = (local.z() > 0 ? 1.0 : -1.0) * turn.col(2);
    }
  } else if (const auto* box = std::get_if<Cuboid>(&shape)) {
    int faces = 0;
    const double band = 1e-7 * box->half_size.sum();
    for (int i = 0; i < 3; ++i) {
      if (std::abs(local[i]) > box->half_size[i] - band) {
        ++faces;
        at.direction = (local[i] > 0 ? 1.0 : -1.0) * turn.col(i);
      }
    }
    if (faces == 1) at.kind = SurfaceAt::Kind::kFace;
  }
  return at;
}

/// GJK's normal (from a into b) and points of a gap made exact where a side's surface is smooth
/// at its point (surfaceAt; side b given by `shape_b`, `turn_b` and `centre_b`, or none): GJK's
/// normal is the direction between closest points found a hair apart, and its points come from
/// the simplex, each off by the rounding over the gap (2.6e-5 rad for a turning disc's rim on a
/// can's side), and a lever arm off its normal's line turns a body about an axis no impulse along
/// the true normal would (0.0017 rad/s about a struck can's axis). A flat face's normal is its
/// own; a cylinder's side's is GJK's less its part along the axis, or, against another side,
/// along the two axes' cross product, the points on their common perpendicular; a side's point
/// is then its axis's point moved out along the normal by the radius. Kept only where it is
/// within 1e-3 rad of GJK's.
void exactWhereSmooth(SurfaceGap& g, const ConvexShape& shape_a, const Eigen::Matrix3d& turn_a,
                      const Eigen::Vector3d& centre_a, const ConvexShape* shape_b,
                      const Eigen::Matrix3d& turn_b, const Eigen::Vector3d& centre_b) {
  if (g.overlapping) return;
  using Kind = SurfaceAt::Kind;
  SurfaceAt a = surfaceAt(shape_a, turn_a, centre_a, g.point_a);
  SurfaceAt b = shape_b ? surfaceAt(*shape_b, turn_b, centre_b, g.point_b) : SurfaceAt{};
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  if (a.kind == Kind::kFace) {
    n = a.direction;
  } else if (b.kind == Kind::kFace) {
    n = -b.direction;
  } else if (a.kind == Kind::kSide && b.kind == Kind::kSide &&
             a.direction.cross(b.direction).norm() > 1e-3) {
    // Two sides touch on their axes' common perpendicular.
    n = a.direction.cross(b.direction).normalized();
    if (n.dot(g.normal) < 0) n = -n;
    const double along = a.direction.dot(b.direction);
    const Eigen::Vector3d apart = a.axis_point - b.axis_point;
    const double da = a.direction.dot(apart), db = b.direction.dot(apart);
    const double denominator = 1 - along * along;
    a.axis_point += ((along * db - da) / denominator) * a.direction;
    b.axis_point += ((db - along * da) / denominator) * b.direction;
  } else if (a.kind == Kind::kSide) {
    n = (g.normal - g.normal.dot(a.direction) * a.direction).normalized();
  } else if (b.kind == Kind::kSide) {
    n = (g.normal - g.normal.dot(b.direction) * b.direction).normalized();
  }
  if (!(n.dot(g.normal) > 1 - 5e-7)) return;  // none, or more than 1e-3 rad from GJK's
  g.normal = n;
  if (a.kind == Kind::kSide) g.point_a = a.axis_point + a.radius * n;
  if (b.kind == Kind::kSide) g.point_b = b.axis_point - b.radius * n;
  g.lever_a = g.point_a - centre_a;
  g.lever_b = g.point_b - centre_b;
}

/// A finite obstacle's shape as a ConvexShape (boxes, cylinders and capsules are the same).
template <class Finite>
ConvexShape convexOf(const Finite& shape) {
  return ConvexShape(shape);
}

bool turns(const Shape& shape) {
  return !std::holds_alternative<Plane>(shape) && !std::holds_alternative<Sphere>(shape);
}

/// The body against a mesh placed at `pose` (both at one instant): the unsigned distance to its
/// triangles, those whose boxes meet the cube about the body's centre that holds every point
/// within U plus the body's reach, U the body's distance to the triangle nearest its centre (or
/// the centre's distance, whichever is less: both bound the gap from above, so the nearest
/// triangle is among them). Far from the mesh (the centre's distance beyond three times the
/// reach) a lower bound only: the centre's distance less the reach.
SurfaceGap meshGap(const TumblingBody& body, double time, const Mesh& mesh, const RigidPose& pose,
                   double tolerance, std::vector<std::uint32_t>* near_triangles) {
  const Eigen::Matrix3d axes = pose.transform.linear();
  const Eigen::Vector3d origin = pose.transform.translation();
  const Eigen::Vector3d centre = body.positionAt(time);
  const Eigen::Matrix3d turn = body.orientationAt(time).toRotationMatrix();
  const Eigen::Vector3d local_centre = axes.transpose() * (centre - origin);
  const Eigen::Matrix3d local_turn = axes.transpose() * turn;
  const PlacedConvex local_body(body.shape(), local_turn, local_centre);
  const TriangleMesh& triangles = *mesh.triangles;
  const TriangleMesh::NearestPoint nearest = triangles.nearest(local_centre);
  const double reach = body.reach();
  SurfaceGap g;
  const auto toWorld = [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
    return origin + axes * p;
  };
  if (nearest.distance > 3 * reach) {
    const Eigen::Vector3d towards = nearest.point - local_centre;
    const Eigen::Vector3d on_body =
        local_body.support(towards) + local_body.margin() * towards.normalized();
    const double slack = 64 * kEps * (local_centre.norm() + reach + nearest.point.norm());
    g.gap = nearest.distance - reach - slack;
    g.gap_upper = (nearest.point - on_body).norm() + slack;
    g.normal = axes * towards.normalized();
    g.point_a = toWorld(on_body);
    g.point_b = toWorld(nearest.point);
  } else {
    // The triangle nearest the centre bounds the gap from above: every triangle nearer the body
    // lies within that bound plus the reach of the centre.
    const auto& first = triangles.triangles()[nearest.triangle];
    const ConvexDistance nearest_triangle = convexDistance(
        local_body,
        TriangleSupport(triangles.vertices()[first[0]], triangles.vertices()[first[1]],
                        triangles.vertices()[first[2]]),
        tolerance);
    const double half = std::min(nearest.distance, std::max(0.0, nearest_triangle.upper)) + reach;
    std::vector<std::uint32_t> found;
    triangles.overlapping(local_centre - Eigen::Vector3d::Constant(half),
                          local_centre + Eigen::Vector3d::Constant(half), found);
    g.gap = INFINITY;
    g.gap_upper = INFINITY;
    double best_upper = INFINITY;
    for (const std::uint32_t t : found) {
      const auto& corners = triangles.triangles()[t];
      const TriangleSupport triangle(triangles.vertices()[corners[0]],
                                     triangles.vertices()[corners[1]],
                                     triangles.vertices()[corners[2]]);
      const ConvexDistance d = convexDistance(local_body, triangle, tolerance);
      g.gap = std::min(g.gap, d.lower);
      if (d.upper < best_upper) {
        best_upper = d.upper;
        g.gap_upper = d.upper;
        g.overlapping = d.overlapping;
        g.normal = axes * d.normal;
        g.point_a = toWorld(d.point_a);
        g.point_b = toWorld(d.point_b);
      }
      if (d.overlapping) g.overlapping = true;
    }
    if (near_triangles) *near_triangles = std::move(found);
  }
  g.lever_a = g.point_a - centre;
  g.lever_b = g.point_b - origin;
  return g;
}

/// Whether a gap carries its approach speed and its normal made exact (exactWhereSmooth): the
/// advancement looks at the gap alone, and those cost the body's orientation and angular
/// velocity once more.
enum class Approach { kWith, kWithout };

/// The body against `obstacle` already moved to `time`.
SurfaceGap obstacleGap(const TumblingBody& body, double time, const PlacedShape& moved,
                       double tolerance, std::vector<std::uint32_t>* near_triangles = nullptr,
                       Approach approach = Approach::kWith) {
  const Eigen::Vector3d centre = body.positionAt(time);
  const Eigen::Vector3d origin = moved.pose.transform.translation();
  SurfaceGap g;
  if (const auto* plane = std::get_if<Plane>(&moved.shape)) {
    // Exact by the support function: the body's point farthest along -n.
    const double length = plane->normal.norm();
    const Eigen::Vector3d n = plane->normal / length;
    const PlacedConvex placed = placedBody(body, time);
    const Eigen::Vector3d deepest = placed.support(-n) - placed.margin() * n;
    const double height = (plane->normal.dot(deepest) - plane->offset) / length;
    const double slack = 64 * kEps * (centre.norm() + body.reach() + std::abs(plane->offset));
    g.gap = height - slack;
    g.gap_upper = height + slack;
    g.overlapping = height < -slack;
    g.normal = -n;
    g.point_a = deepest;
    g.point_b = deepest - height * n;
    g.lever_a = g.point_a - centre;
    g.lever_b = g.point_b - origin;
  } else if (const auto* sphere = std::get_if<Sphere>(&moved.shape)) {
    const ConvexDistance d = convexDistance(
        placedBody(body, time), PointSupport(sphere->centre, sphere->radius), tolerance);
    g = fromDistance(d, centre, sphere->centre);
    if (approach == Approach::kWith) {
      exactWhereSmooth(g, body.shape(), body.orientationAt(time).toRotationMatrix(), centre,
                       nullptr, Eigen::Matrix3d::Identity(), sphere->centre);
    }
  } else if (const auto* mesh = std::get_if<Mesh>(&moved.shape)) {
    g = meshGap(body, time, *mesh, moved.pose, tolerance, near_triangles);
  } else {
    const ConvexShape shape = std::visit(
        [](const auto& finite) -> ConvexShape {
          using Kind = std::decay_t<decltype(finite)>;
          if constexpr (std::is_same_v<Kind, Cuboid> || std::is_same_v<Kind, Cylinder> ||
                        std::is_same_v<Kind, Capsule>) {
            return convexOf(finite);
          } else {
            return Sphere{};  // not reached: planes, spheres and meshes are above
          }
        },
        moved.shape);
    const PlacedConvex other(shape, moved.pose.transform.linear(), origin);
    g = fromDistance(convexDistance(placedBody(body, time), other, tolerance), centre, origin);
    if (approach == Approach::kWith) {
      exactWhereSmooth(g, body.shape(), body.orientationAt(time).toRotationMatrix(), centre, &shape,
                       moved.pose.transform.linear(), origin);
    }
  }
  if (approach == Approach::kWithout) return g;
  const Eigen::Vector3d surface =
      turns(moved.shape) ? moved.pose.velocityAt(g.point_b - origin) : moved.pose.velocity;
  g.approach_speed = g.normal.dot(body.pointVelocityAt(time, g.point_a) - surface);
  return g;
}

SurfaceGap bodiesGap(const TumblingBody& a, const TumblingBody& b, double time, double tolerance,
                     Approach approach = Approach::kWith) {
  SurfaceGap g = fromDistance(convexDistance(placedBody(a, time), placedBody(b, time), tolerance),
                              a.positionAt(time), b.positionAt(time));
  if (approach == Approach::kWithout) return g;  // the advancement's steps: the distance alone
  exactWhereSmooth(g, a.shape(), a.orientationAt(time).toRotationMatrix(), a.positionAt(time),
                   &b.shape(), b.orientationAt(time).toRotationMatrix(), b.positionAt(time));
  g.approach_speed =
      g.normal.dot(a.pointVelocityAt(time, g.point_a) - b.pointVelocityAt(time, g.point_b));
  return g;
}

/// Reduces a manifold to at most 4 points spanning the largest area across the normal: the
/// deepest (the first of equals), the farthest from it, the largest triangle with those, the
/// point that adds the most area outside that triangle (none where all are inside it).
void reduceManifold(std::vector<ManifoldPoint>& points, const Eigen::Vector3d& normal) {
  if (points.size() <= 4) return;
  const auto at = [&](std::size_t i) -> Eigen::Vector3d {
    const Eigen::Vector3d mid = 0.5 * (points[i].point_a + points[i].point_b);
    return mid - normal.dot(mid) * normal;
  };
  std::vector<std::size_t> chosen;
  std::size_t first = 0;
  for (std::size_t i = 1; i < points.size(); ++i) {
    if (points[i].gap < points[first].gap) first = i;
  }
  chosen.push_back(first);
  const auto best = [&](auto score) {
    std::size_t index = points.size();
    double value = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (std::find(chosen.begin(), chosen.end(), i) != chosen.end()) continue;
      const double s = score(at(i));
      if (s > value) {
        value = s;
        index = i;
      }
    }
    if (index < points.size()) chosen.push_back(index);
    return index < points.size();
  };
  const Eigen::Vector3d p1 = at(first);
  if (best([&](const Eigen::Vector3d& p) { return (p - p1).squaredNorm(); })) {
    const Eigen::Vector3d p2 = at(chosen[1]);
    if (best([&](const Eigen::Vector3d& p) {
          return std::abs(normal.dot((p2 - p1).cross(p - p1)));
        })) {
      const Eigen::Vector3d p3 = at(chosen[2]);
      const double turn = normal.dot((p2 - p1).cross(p3 - p1)) >= 0 ? 1.0 : -1.0;
      best([&](const Eigen::Vector3d& p) {
        // The area q adds outside each edge of the triangle (counter-clockwise about n).
        double added = 0;
        const Eigen::Vector3d corners[3] = {p1, p2, p3};
        for (int k = 0; k < 3; ++k) {
          const Eigen::Vector3d& from = corners[k];
          const Eigen::Vector3d& to = corners[(k + 1) % 3];
          added = std::max(added, -turn * normal.dot((to - from).cross(p - from)));
        }
        return added;
      });
    }
  }
  std::vector<ManifoldPoint> kept;
  for (const std::size_t i : chosen) kept.push_back(points[i]);
  points = std::move(kept);
}

/// Adds `point` unless one of `points` is within `band` of it (its pair's midpoint).
void addUnique(std::vector<ManifoldPoint>& points, const ManifoldPoint& point, double band) {
  const Eigen::Vector3d mid = 0.5 * (point.point_a + point.point_b);
  for (const ManifoldPoint& p : points) {
    if ((0.5 * (p.point_a + p.point_b) - mid).norm() <= band) return;
  }
  points.push_back(point);
}

/// s: the first root after 0 of g - V s - A s^2 / 2 (g > 0, V and A of either sign), infinite
/// where there is none, written without cancellation: closing (V > 0), 2 g / (V + sqrt(V^2 + 2 A
/// g)), the smaller root where both are positive (A < 0); opening (V <= 0), (sqrt(V^2 + 2 A g) -
/// V) / A where A > 0 pulls it back, none otherwise.
double firstRoot(double gap, double speed, double acceleration) {
  const double discriminant = speed * speed + 2 * acceleration * gap;
  if (speed > 0) {
    return discriminant >= 0 ? 2 * gap / (speed + std::sqrt(discriminant)) : INFINITY;
  }
  return acceleration > 0 ? (std::sqrt(discriminant) - speed) / acceleration : INFINITY;
}

/// s: how far the advancement may step from `time` where the other side is a plane (unit normal
/// n towards the body's side, fixed or moving straight on at v_o) and the body's gap to it is at
/// least `gap`: no contact before it. The gap is g(t) = n . c(t) - d(t) - h(t), d the plane's
/// offset, h(t) = max over the body's points p of -n . (p - c): how far the body reaches below
/// its centre c. Exactly on the parabola, n . c(t) - d(t) = n . c_0 - d_0 + n . (v_0 - v_o) s +
/// n . a s^2 / 2 (s = t - t_0). h changes as the body turns: at a point p* where the maximum is
/// reached, dh/dt <= -n . (w x r*) = w . (n x r*) <= |n x w| |n x r*| (r* = p* - c; the upper Dini
/// derivative of a maximum of smooth functions is at most the largest of theirs), and
/// |n x r*|^2 = |r*|^2 - (n . r*)^2 <= R^2 - h^2, R the body's reach (no point farther from c).
/// With h = R cos(theta), theta in [0, pi], theta therefore falls no faster than W >= |n x w(t)|
/// (spinAcrossBound: |w| <= sqrt(2 E / J_min) for all time where w is not fixed), and from h_0:
/// h(t_0 + s) <= R cos(max(0, theta_0 - W s)) = h_0 + R f(W s), f(x) = cos(max(0, theta_0 - x))
/// - cos(theta_0). Three quadratic bounds of f, each giving a lower bound of g whose first root
/// is a safe step (the largest of the three is): f(x) <= x (f' <= 1); f(x) <= sin(theta_0) x +
/// x^2 / 2 (Taylor's, f'' <= 1, and f constant after x = theta_0); f(x) <= 1 - cos(theta_0)
/// (the body reaches no lower than R). h_0 is taken from the gap's lower bound, n . c_0 - d_0 -
/// gap >= h(t_0), clamped to [-R, R] (conservative: the bound rises with h_0). A body moving
/// along the plane (n . v = 0) or spinning about its normal (n x w = 0) takes long steps, and a
/// corner straight below the centre (theta_0 = 0) rises only by its turning, quadratically.
/// Through air (TumblingBody::throughAir) the centre's height accelerates within `air` (the air's
/// bound over the query) of gravity's n . a, which the bounds then take as theirs.
/// s: no corner of a box or hull reaches the plane n.x = offset (n unit, moving at
/// `plane_velocity`) before it; 0 for other shapes. Each corner's height h_i and its rate h_i' are
/// exact at `time`, and |h_i''| <= |n.a| + |r_i| (|w'| + |w|^2) over any span (r_i from the centre:
/// (R v_i)'' = w' x r_i + w x (w x r_i)), so h_i stays > 0 until h_i + h_i' s - A_i s^2 / 2 = 0.
/// A corner just struck and leaving at e u keeps the step of order e u / A, where the body's
/// speed bound alone (planeStep's others) would step its gap over its whole turning speed.
double cornerStep(const TumblingBody& body, double time, const Eigen::Vector3d& n, double offset,
                  const Eigen::Vector3d& plane_velocity, double air) {
  std::vector<Eigen::Vector3d> corners;
  if (const auto* box = std::get_if<Cuboid>(&body.shape())) {
    for (int c = 0; c < 8; ++c) {
      corners.emplace_back((c & 1) ? box->half_size.x() : -box->half_size.x(),
                           (c & 2) ? box->half_size.y() : -box->half_size.y(),
                           (c & 4) ? box->half_size.z() : -box->half_size.z());
    }
  } else if (const auto* hull = std::get_if<ConvexHull>(&body.shape())) {
    corners = hull->vertices;
  } else {
    return 0.0;
  }
  const Eigen::Matrix3d rotation = body.orientationAt(time).toRotationMatrix();
  const Eigen::Vector3d centre = body.positionAt(time);
  const Eigen::Vector3d velocity = body.velocityAt(time) - plane_velocity;
  const Eigen::Vector3d spin = body.angularVelocityAt(time);
  const double w = body.angularSpeedBound();
  const double turning = body.angularAccelerationBound() + w * w;
  const double pulled = std::abs(n.dot(body.acceleration())) + air;
  double step = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& corner : corners) {
    const Eigen::Vector3d r = rotation * corner;
    const double height = n.dot(centre + r) - offset;
    if (!(height > 0)) return 0.0;
    const double closing = -n.dot(velocity + spin.cross(r));
    const double bound = (pulled + r.norm() * turning) * (1 + 64 * kEps);
    step = std::min(step, firstRoot(height, closing, bound));
  }
  return step;
}

double planeStep(const TumblingBody& body, double time, double gap, const Plane& plane,
                 const Eigen::Vector3d& plane_velocity, double air) {
  const double length = plane.normal.norm();
  const Eigen::Vector3d n = plane.normal / length;
  const double reach = body.reach() * (1 + 64 * kEps);
  const double spin = body.spinAcrossBound(n);
  const double closing = -n.dot(body.velocityAt(time) - plane_velocity);
  const double pulled = -n.dot(body.acceleration()) + air;
  const double centre_height = (plane.normal.dot(body.positionAt(time)) - plane.offset) / length;
  const double below = std::clamp(centre_height - gap, -reach, reach);  // h_0, at least h(t_0)
  const double across = std::sqrt((reach - below) * (reach + below));   // R sin(theta_0)
  const double lipschitz = firstRoot(gap, closing + reach * spin, pulled);
  const double taylor = firstRoot(gap, closing + across * spin, pulled + reach * spin * spin);
  const double lowest = gap - (reach - below);
  const double reached = lowest > 0 ? firstRoot(lowest, closing, pulled) : 0.0;
  return std::max({lipschitz, taylor, reached,
                   cornerStep(body, time, n, plane.offset / length, plane_velocity, air)});
}

/// The other side of a first-contact query: what it is at an instant and how fast its points
/// may move.
struct ObstacleSide {
  const PlacedShape& placed;
  double tolerance;
  PlacedShape at(double time) const { return shapeAt(placed, time); }
  SurfaceGap gap(const TumblingBody& body, double time, Approach approach = Approach::kWith) const {
    return obstacleGap(body, time, at(time), tolerance, nullptr, approach);
  }
  Eigen::Vector3d centreVelocity(double time) const { return at(time).pose.velocity; }
  /// s: no contact before it from `time`, where the gap is at least `gap`: the bound on every
  /// point's speed (`speed`, `acceleration`: the header's comment), or a plane's own (planeStep)
  /// where that is longer.
  double step(const TumblingBody& body, double time, double gap, double speed, double acceleration,
              double air) const {
    const double any = firstRoot(gap, speed, acceleration);
    if (std::holds_alternative<Plane>(placed.shape)) {
      const PlacedShape moved = at(time);
      return std::max(
          any, planeStep(body, time, gap, std::get<Plane>(moved.shape), placed.pose.velocity, air));
    }
    return any;
  }
  double angularSpeed() const {
    return turns(placed.shape) ? placed.pose.angular_velocity.norm() : 0.0;
  }
  double pointSpeedAboutCentre() const { return angularSpeed() * turningReach(placed.shape); }
  double accelerationBound(const TumblingBody& body, double from, double to) const {
    return body.accelerationBound(from, to) + angularSpeed() * placed.pose.velocity.norm();
  }
  void manifold(const TumblingBody& body, double time, const SurfaceGap& closest, double band,
                std::vector<ManifoldPoint>& out) const;
};

struct BodySide {
  const TumblingBody& other;
  double tolerance;
  SurfaceGap gap(const TumblingBody& body, double time, Approach approach = Approach::kWith) const {
    return bodiesGap(body, other, time, tolerance, approach);
  }
  Eigen::Vector3d centreVelocity(double time) const { return other.velocityAt(time); }
  double step(const TumblingBody&, double, double gap, double speed, double acceleration,
              double) const {
    return firstRoot(gap, speed, acceleration);
  }
  double pointSpeedAboutCentre() const { return other.angularSpeedBound() * other.reach(); }
  double accelerationBound(const TumblingBody& body, double from, double to) const {
    return (body.acceleration() - other.acceleration()).norm() +
           body.airAccelerationBound(from, to) + other.airAccelerationBound(from, to);
  }
  void manifold(const TumblingBody& body, double time, const SurfaceGap& closest, double band,
                std::vector<ManifoldPoint>& out) const;
};

/// The candidates of `body` (side a) towards the normal whose distance to the other side
/// (`distance(p)`: the distance and the other side's nearest point) is within the band.
template <class Distance>
void candidatesOfA(const TumblingBody& body, double time, const SurfaceGap& closest, double band,
                   const Distance& distance, const Eigen::Vector3d& centre_b,
                   std::vector<ManifoldPoint>& out) {
  const Eigen::Matrix3d turn = body.orientationAt(time).toRotationMatrix();
  const Eigen::Vector3d centre = body.positionAt(time);
  std::vector<Eigen::Vector3d> candidates;
  contactCandidates(body.shape(), turn.transpose() * closest.normal, candidates);
  for (const Eigen::Vector3d& local : candidates) {
    const Eigen::Vector3d p = centre + turn * local;
    const auto [d, q] = distance(p);
    if (d <= closest.gap_upper + band) {
      addUnique(out, ManifoldPoint{p, q, p - centre, q - centre_b, d}, band);
    }
  }
}

/// The candidates of a convex side b (world points) whose distance to the body is within the band.
void candidatesOfB(const TumblingBody& body, double time, const SurfaceGap& closest, double band,
                   double tolerance, const std::vector<Eigen::Vector3d>& candidates,
                   const Eigen::Vector3d& centre_b, std::vector<ManifoldPoint>& out) {
  const PlacedConvex a = placedBody(body, time);
  const Eigen::Vector3d centre = body.positionAt(time);
  for (const Eigen::Vector3d& p : candidates) {
    const ConvexDistance d = convexDistance(a, PointSupport(p), tolerance);
    if (d.upper <= closest.gap_upper + band) {
      addUnique(
          out,
          ManifoldPoint{d.point_a, p, d.point_a - centre, p - centre_b, std::max(d.upper, 0.0)},
          band);
    }
  }
}

void ObstacleSide::manifold(const TumblingBody& body, double time, const SurfaceGap& closest,
                            double band, std::vector<ManifoldPoint>& out) const {
  const PlacedShape moved = at(time);
  const Eigen::Vector3d origin = moved.pose.transform.translation();
  if (const auto* plane = std::get_if<Plane>(&moved.shape)) {
    const double length = plane->normal.norm();
    const Eigen::Vector3d n = plane->normal / length;
    candidatesOfA(
        body, time, closest, band,
        [&](const Eigen::Vector3d& p) {
          const double height = (plane->normal.dot(p) - plane->offset) / length;
          return std::pair<double, Eigen::Vector3d>(height, p - height * n);
        },
        origin, out);
    return;
  }
  if (const auto* mesh = std::get_if<Mesh>(&moved.shape)) {
    const Eigen::Matrix3d axes = moved.pose.transform.linear();
    const TriangleMesh& triangles = *mesh->triangles;
    candidatesOfA(
        body, time, closest, band,
        [&](const Eigen::Vector3d& p) {
          const TriangleMesh::NearestPoint q = triangles.nearest(axes.transpose() * (p - origin));
          return std::pair<double, Eigen::Vector3d>(q.distance, origin + axes * q.point);
        },
        origin, out);
    std::vector<std::uint32_t> near;
    obstacleGap(body, time, moved, tolerance, &near);
    std::vector<Eigen::Vector3d> corners;
    for (const std::uint32_t t : near) {
      for (const std::uint32_t v : triangles.triangles()[t]) {
        corners.push_back(origin + axes * triangles.vertices()[v]);
      }
    }
    candidatesOfB(body, time, closest, band, tolerance, corners, origin, out);
    return;
  }
  if (std::holds_alternative<Sphere>(moved.shape)) return;  // the closest pair alone
  const ConvexShape shape = std::visit(
      [](const auto& finite) -> ConvexShape {
        using Kind = std::decay_t<decltype(finite)>;
        if constexpr (std::is_same_v<Kind, Cuboid> || std::is_same_v<Kind, Cylinder> ||
                      std::is_same_v<Kind, Capsule>) {
          return convexOf(finite);
        } else {
          return Sphere{};
        }
      },
      moved.shape);
  const PlacedConvex other(shape, moved.pose.transform.linear(), origin);
  candidatesOfA(
      body, time, closest, band,
      [&](const Eigen::Vector3d& p) {
        const ConvexDistance d = convexDistance(PointSupport(p), other, tolerance);
        return std::pair<double, Eigen::Vector3d>(std::max(d.upper, 0.0), d.point_b);
      },
      origin, out);
  std::vector<Eigen::Vector3d> local;
  contactCandidates(shape, moved.pose.transform.linear().transpose() * (-closest.normal), local);
  for (Eigen::Vector3d& p : local) p = origin + moved.pose.transform.linear() * p;
  candidatesOfB(body, time, closest, band, tolerance, local, origin, out);
}

void BodySide::manifold(const TumblingBody& body, double time, const SurfaceGap& closest,
                        double band, std::vector<ManifoldPoint>& out) const {
  const PlacedConvex b = placedBody(other, time);
  const Eigen::Vector3d centre_b = other.positionAt(time);
  candidatesOfA(
      body, time, closest, band,
      [&](const Eigen::Vector3d& p) {
        const ConvexDistance d = convexDistance(PointSupport(p), b, tolerance);
        return std::pair<double, Eigen::Vector3d>(std::max(d.upper, 0.0), d.point_b);
      },
      centre_b, out);
  const Eigen::Matrix3d turn = other.orientationAt(time).toRotationMatrix();
  std::vector<Eigen::Vector3d> local;
  contactCandidates(other.shape(), turn.transpose() * (-closest.normal), local);
  for (Eigen::Vector3d& p : local) p = centre_b + turn * p;
  candidatesOfB(body, time, closest, band, tolerance, local, centre_b, out);
}

/// The moving side a of the advancement in flight: exact at every instant, its own bounds (`air`:
/// the air's part of its acceleration's over the query).
struct FlightSide {
  const TumblingBody& body;
  double air = 0.0;
  const TumblingBody* at(double) const { return &body; }
  double turning() const { return body.angularSpeedBound() * body.reach(); }
  /// m/s: the centres' relative speed at `time`, the other's centre moving at `other`.
  double relativeSpeed(double time, const Eigen::Vector3d& other) const {
    return (body.velocityAt(time) - other).norm();
  }
  template <class Side>
  double accelerationBound(const Side& side, const TumblingBody&, double from, double to) const {
    return side.accelerationBound(body, from, to);
  }
  template <class Side>
  double step(const Side& side, double time, double gap, double speed, double acceleration) const {
    return side.step(body, time, gap, speed, acceleration, air);
  }
};

/// Side a of the advancement as a BoundedMotion: what it is at an instant (its state there, no
/// acceleration), its points' speeds bounded over the whole query (no acceleration term for it).
struct BoundedSide {
  const BoundedMotion& motion;
  mutable std::optional<TumblingBody> current;
  const TumblingBody* at(double time) const {
    current = motion.at(time);
    return current ? &*current : nullptr;
  }
  double turning() const { return motion.angular_speed * motion.reach; }
  double relativeSpeed(double, const Eigen::Vector3d& other) const {
    return motion.centre_speed + other.norm();
  }
  /// The other side's alone: `at`'s state has none.
  template <class Side>
  double accelerationBound(const Side& side, const TumblingBody& at_from, double from,
                           double to) const {
    return side.accelerationBound(at_from, from, to);
  }
  template <class Side>
  double step(const Side&, double, double gap, double speed, double acceleration) const {
    return firstRoot(gap, speed, acceleration);
  }
};

/// `body`, found overlapping `side` at `time`, shrunk by `band` (TumblingBody::shrunkBy) where
/// that is apart: it touches within the band (a box set flush on a table's top, where the
/// distance of the flush faces rounds below 0). Empty: deeper, it is inside.
template <class Side>
std::optional<TumblingBody> shrunkWhereTouching(const Side& side, const TumblingBody& body,
                                                double time, double band) {
  TumblingBody shrunk = body.shrunkBy(band);
  const SurfaceGap within = side.gap(shrunk, time, Approach::kWithout);
  if (within.overlapping || within.gap_upper < 0) return std::nullopt;
  return shrunk;
}

/// Conservative advancement (the header's comment) of side a (`moving`: FlightSide,
/// BoundedSide) against `side`.
template <class Moving, class Side>
FirstContactResult advance(const Moving& moving, const Side& side, double from, double horizon,
                           const FirstContactOptions& options) {
  FirstContactResult result;
  result.clear_until = from;
  const double end = from + horizon;
  const double turning = moving.turning() + side.pointSpeedAboutCentre();
  // The steps look at the gap alone; the contact found carries its approach speed too (the same
  // gap, computed once more with it).
  const auto contactAt = [&](const TumblingBody& body, double t) {
    const SurfaceGap g = side.gap(body, t);
    TumblingContact contact;
    contact.time = t;
    contact.closest = g;
    side.manifold(body, t, g, options.manifold_band, contact.manifold);
    addUnique(contact.manifold,
              ManifoldPoint{g.point_a, g.point_b, g.lever_a, g.lever_b, g.gap_upper},
              options.manifold_band);
    reduceManifold(contact.manifold, g.normal);
    result.contact = std::move(contact);
    result.clear_until = t;
  };
  double t = from;
  const TumblingBody* body = moving.at(t);
  if (body == nullptr) return result;
  const double acceleration = moving.accelerationBound(side, *body, from, end);
  SurfaceGap g = side.gap(*body, t, Approach::kWithout);
  if (g.overlapping || g.gap_upper < 0) {
    // Touching within the band: the contact there, its normal and points the shrunk body's.
    const auto touching = shrunkWhereTouching(side, *body, t, options.manifold_band);
    if (!touching) {
      result.inside_at_start = true;
      return result;
    }
    contactAt(*touching, t);
    return result;
  }
  for (; result.steps < options.max_steps; ++result.steps) {
    const double stop = options.time_tolerance + 4 * kEps * std::abs(t);
    if (!(g.gap > 0)) {
      contactAt(*body, t);
      return result;
    }
    const double speed = moving.relativeSpeed(t, side.centreVelocity(t)) + turning;
    // Touching where every point's speed bound would step less than the tolerance (the gap
    // within V time_tolerance: the header's comment), even where a plane's own bound steps
    // further: a point gliding along it within that gap would otherwise creep on in steps of
    // about the tolerance, millions of them.
    if (firstRoot(g.gap, speed, acceleration) <= stop) {
      contactAt(*body, t);
      return result;
    }
    const double step = moving.step(side, t, g.gap, speed, acceleration);
    if (step <= stop) {
      contactAt(*body, t);
      return result;
    }
    result.clear_until = std::min(t + step, end);
    if (!(t + step <= end)) return result;  // apart until the horizon's end
    t += step;
    body = moving.at(t);
    if (body == nullptr) return result;  // apart until t (its state there is refused)
    g = side.gap(*body, t, Approach::kWithout);
  }
  return result;  // the step budget ran out: apart until clear_until
}

}  // namespace

Expected<TumblingBody> TumblingBody::create(const ConvexShape& shape,
                                            const Eigen::Vector3d& principal_moments, double time,
                                            const Eigen::Vector3d& position,
                                            const Eigen::Vector3d& velocity,
                                            const Eigen::Vector3d& acceleration,
                                            const Eigen::Quaterniond& orientation,
                                            const Eigen::Vector3d& angular_velocity) {
  if (Status s = checkConvexShape(shape); !s) return s.error();
  if (!std::isfinite(time)) return Error{"time", "must be finite, got " + std::to_string(time)};
  if (Status s = checkFiniteVector(position, "position"); !s) return s.error();
  if (Status s = checkFiniteVector(velocity, "velocity"); !s) return s.error();
  if (Status s = checkFiniteVector(acceleration, "acceleration"); !s) return s.error();
  Expected<FreeRotation> rotation =
      FreeRotation::create(principal_moments, orientation, angular_velocity);
  if (!rotation) return rotation.error();
  TumblingBody body(shape, rotation.value());
  body.time_ = time;
  body.position_ = position;
  body.velocity_ = velocity;
  body.acceleration_ = acceleration;
  body.reach_ = reachOf(shape);
  // |w| <= sqrt(2 E / J_min): 2 E = sum J_i w_i^2 >= J_min |w|^2 (body frame), a few ulps over
  // for the rounding of E and of the rotation's w(t).
  const Eigen::Vector3d w_body = orientation.normalized().conjugate() * angular_velocity;
  const double twice_energy = principal_moments.dot(w_body.cwiseAbs2());
  body.angular_speed_bound_ =
      std::sqrt(twice_energy / principal_moments.minCoeff()) * (1 + 64 * kEps);
  const FreeRotation::Kind kind = body.rotation_.kind();
  body.steady_spin_ =
      kind == FreeRotation::Kind::kResting || kind == FreeRotation::Kind::kIsotropic;
  if (!body.steady_spin_) {
    const Eigen::Vector3d& j = principal_moments;
    const double spread = std::abs(j.y() - j.z()) / j.x() + std::abs(j.z() - j.x()) / j.y() +
                          std::abs(j.x() - j.y()) / j.z();
    body.angular_acceleration_bound_ =
        0.5 * body.angular_speed_bound_ * body.angular_speed_bound_ * spread * (1 + 64 * kEps);
  }
  body.angular_velocity_ = angular_velocity;
  return body;
}

TumblingBody TumblingBody::throughAir(const AirFactors& air, double tolerance) const {
  if (air.drag == 0.0 && air.lift == 0.0) return *this;
  TumblingBody through = *this;
  // A steady turn (at rest, an isotropic body) is a constant w, as a ball's flight takes it.
  if (steady_spin_) {
    through.air_ = std::make_shared<const AirFlight>(time_, position_, velocity_, angular_velocity_,
                                                     acceleration_, air, tolerance);
  } else {
    through.air_ = std::make_shared<const AirFlight>(
        time_, position_, velocity_,
        [rotation = rotation_, start = time_](double t) {
          return rotation.angularVelocity(t - start);
        },
        acceleration_, air, tolerance);
  }
  return through;
}

TumblingBody TumblingBody::shrunkBy(double distance) const {
  TumblingBody shrunk = *this;
  // Each size less `distance`, but never below half of itself (a body smaller than the band).
  const auto less = [distance](double size) { return std::max(size - distance, 0.5 * size); };
  std::visit(
      [&](auto& shape) {
        using Kind = std::decay_t<decltype(shape)>;
        if constexpr (std::is_same_v<Kind, Sphere>) {
          shape.radius = less(shape.radius);
        } else if constexpr (std::is_same_v<Kind, Cuboid>) {
          shape.half_size = shape.half_size.unaryExpr(less);
        } else if constexpr (std::is_same_v<Kind, Cylinder> || std::is_same_v<Kind, Capsule>) {
          shape.radius = less(shape.radius);
          shape.half_length = less(shape.half_length);
        } else {
          const double scale = less(reach_) / reach_;
          for (Eigen::Vector3d& vertex : shape.vertices) vertex *= scale;
        }
      },
      shrunk.shape_);
  return shrunk;
}

SurfaceGap gapAt(const TumblingBody& body, const PlacedShape& obstacle, double time,
                 double distance_tolerance) {
  return obstacleGap(body, time, shapeAt(obstacle, time), distance_tolerance);
}

bool insideBeyond(const TumblingBody& body, const PlacedShape& obstacle, double time, double band) {
  const ObstacleSide side{obstacle, FirstContactOptions{}.distance_tolerance};
  const SurfaceGap gap = side.gap(body, time, Approach::kWithout);
  return (gap.overlapping || gap.gap_upper < 0) && !shrunkWhereTouching(side, body, time, band);
}

SurfaceGap gapAt(const TumblingBody& a, const TumblingBody& b, double time,
                 double distance_tolerance) {
  return bodiesGap(a, b, time, distance_tolerance);
}

FirstContactResult firstContact(const TumblingBody& body, const PlacedShape& obstacle, double from,
                                double horizon, const FirstContactOptions& options) {
  return advance(FlightSide{body, body.airAccelerationBound(from, from + horizon)},
                 ObstacleSide{obstacle, options.distance_tolerance}, from, horizon, options);
}

FirstContactResult firstContact(const BoundedMotion& body, const PlacedShape& obstacle, double from,
                                double horizon, const FirstContactOptions& options) {
  return advance(BoundedSide{body, std::nullopt},
                 ObstacleSide{obstacle, options.distance_tolerance}, from, horizon, options);
}

FirstContactResult firstContact(const TumblingBody& a, const TumblingBody& b, double from,
                                double horizon, const FirstContactOptions& options) {
  return advance(FlightSide{a, a.airAccelerationBound(from, from + horizon)},
                 BodySide{b, options.distance_tolerance}, from, horizon, options);
}

}  // namespace collision_response::core
