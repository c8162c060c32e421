#include "geometry/finite_shapes.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

#include "collision_response/core/time_of_impact.h"
#include "collision_response/core/triangle_mesh.h"
#include "geometry/polynomial_roots.h"

namespace collision_response::core {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

double signOf(double value) { return value < 0 ? -1.0 : 1.0; }

/// A point's nearest feature where it is inside a shape or on its surface: the face it is least
/// deep behind.
NearestFeature insideFace(const Eigen::Vector3d& point, const Eigen::Vector3d& outward,
                          double depth) {
  NearestFeature feature;
  feature.point = point;
  feature.outward = outward;
  feature.distance = -depth;
  return feature;
}

/// A point at `offset` from a feature's core point `core` (an edge's nearest point, a corner, a
/// rim's nearest point, an axis' nearest point) grown by `grown` (a capsule's radius; 0 for an
/// edge or a corner).
NearestFeature aroundCore(const Eigen::Vector3d& core, const Eigen::Vector3d& offset, double grown,
                          const Eigen::Vector3d& fallback_outward) {
  NearestFeature feature;
  // Scaled by its largest component: the squares of 1e185 m overflow (norm() gave infinity).
  const double largest = offset.lpNorm<Eigen::Infinity>();
  // (A NaN or an infinity stays one: a distance of 0 would be a touch.)
  const double length = largest == 0 ? 0.0 : largest * (offset / largest).norm();
  feature.outward = length > 0 ? Eigen::Vector3d(offset / length) : fallback_outward;
  feature.point = core + grown * feature.outward;
  feature.distance = length - grown;
  feature.turning_radius = length;
  return feature;
}

/// m: `ulps` roundings of the positions in play, each term scaled first (their sum would
/// overflow at 1e308 m and make every gap a touch).
double roundingOf(const RelativeMotion& motion, double size, double ulps) {
  return ulps * kEps * motion.centre.lpNorm<Eigen::Infinity>() + ulps * kEps * size +
         ulps * kEps * motion.radius;
}

/// A polynomial in t, lowest degree first, in long double.
using Polynomial = std::vector<long double>;

Polynomial operator*(const Polynomial& p, const Polynomial& q) {
  Polynomial product(p.size() + q.size() - 1, 0.0L);
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = 0; j < q.size(); ++j) product[i + j] += p[i] * q[j];
  }
  return product;
}

Polynomial operator+(Polynomial p, const Polynomial& q) {
  if (p.size() < q.size()) p.resize(q.size(), 0.0L);
  for (std::size_t i = 0; i < q.size(); ++i) p[i] += q[i];
  return p;
}

Polynomial operator*(long double factor, Polynomial p) {
  for (long double& c : p) c *= factor;
  return p;
}

/// The features' polynomials along one motion, in lengths scaled by a power of two `unit`
/// (exact) so that their squares keep to the range of the doubles.
class FeatureSearch {
 public:
  /// `gap_at(point)`: the ball's gap to the whole shape with its centre at `point` (m).
  FeatureSearch(const RelativeMotion& motion, double size, double horizon,
                std::function<double(const Eigen::Vector3d&)> gap_at)
      : motion_(motion), horizon_(horizon), gap_at_(std::move(gap_at)) {
    unit_ = powerOfTwoBelow(
        std::max({motion.centre.lpNorm<Eigen::Infinity>(), size + motion.radius, motion.radius}));
    radius_ = static_cast<long double>(motion.radius) / unit_;
    slack_ = roundingOf(motion, size, 8);
    travel_ = (motion.velocity.norm() + 0.5 * motion.acceleration.norm() * horizon) * horizon;
    size_ = size;
  }

  /// The centre's coordinate `axis` less `offset` (m), as a polynomial in t, scaled.
  Polynomial coordinate(int axis, double offset = 0.0) const {
    return {(static_cast<long double>(motion_.centre[axis]) - offset) / unit_,
            static_cast<long double>(motion_.velocity[axis]) / unit_,
            0.5L * static_cast<long double>(motion_.acceleration[axis]) / unit_};
  }
  long double scaled(double length) const { return static_cast<long double>(length) / unit_; }
  long double radius() const { return radius_; }

  /// (distance - grown)(distance + grown) at t = 0 from the distance itself: a gap of a few
  /// ulps keeps its digits (as timeOfImpactSpheres' c).
  static void startFromDistance(Polynomial& p, long double distance, long double grown) {
    p[0] = (distance - grown) * (distance + grown);
  }

  Eigen::Vector3d positionAt(double t) const {
    return motion_.centre + t * (motion_.velocity + (0.5 * t) * motion_.acceleration);
  }
  /// |value| <= bound, with the rounding of the positions (and `more`).
  bool within(double value, double bound, double more = 0.0) const {
    return std::abs(value) <= bound + slack_ + more;
  }
  /// value <= 0, with the rounding of the positions (and `more`).
  bool below(double value, double more = 0.0) const { return value <= slack_ + more; }
  double slack() const { return slack_; }
  /// m: the sizes in play at `t`: where the centre starts, how far it has moved, the shape's.
  /// In long double: at 1e308 m their sum is past the doubles.
  long double reach(double t) const {
    const long double time = std::abs(t);
    return static_cast<long double>(motion_.centre.lpNorm<Eigen::Infinity>()) +
           time *
               (static_cast<long double>(motion_.velocity.lpNorm<Eigen::Infinity>()) +
                time * static_cast<long double>(motion_.acceleration.lpNorm<Eigen::Infinity>())) +
           size_ + motion_.radius;
  }
  /// m: how far the centre can be from the chord of its motion between `low` and `high`, plus
  /// how far along it it moves: a root in the bracket is within this of either end's point.
  double spread(double low, double high) const {
    const double span = high - low;
    return span * (motion_.velocity.norm() + motion_.acceleration.norm() * (std::abs(high) + span));
  }

  /// A feature: its polynomial (> 0 outside it), and where along its surface the point must be.
  /// `region(point, more)`: the point is on the feature's part of the surface, within `more`.
  void feature(const Polynomial& p,
               const std::function<bool(const Eigen::Vector3d&, double)>& region) {
    // Only up to the earliest entry found so far (and a little past it, so that a feature
    // entered at the same instant is not at the very end): a later one cannot be the first.
    const double until = best_ ? std::min(horizon_, *best_ * (1 + 1e-9) + 1e-300) : horizon_;
    visitRoots(
        p, until,
        [&](const PolynomialRoot& root) {
          if (best_ && root.time >= *best_) return true;  // no later root is the first
          if (!root.falling) return false;
          const Eigen::Vector3d at = positionAt(root.time);
          if (!at.allFinite() || !region(at, 0.0)) return false;  // past the doubles: nothing
          // A root must be a touch by the distance itself: to 1e-8 of the sizes in play, and a
          // double root (a graze, known only to the square root of the polynomial's rounding:
          // a rim of a radius far below the ball's is a near-perfect square) to 1e-5 of the ball
          // and the shape besides. Where the motion's terms cancel (1e275 m less 1e275 m) or
          // span 300 orders of magnitude the polynomial's rounding hid gaps of 1e271 m (the
          // fuzzer's finds, fuzz/regressions/time-of-impact-box-* and -cylinder-*). Written to
          // refuse a NaN.
          const long double allowed =
              1e-8L * reach(root.time) +
              (root.simple ? 0.0L : 1e-5L * (static_cast<long double>(motion_.radius) + size_));
          if (!(std::abs(static_cast<long double>(gap_at_(at))) <= allowed)) return false;
          best_ = root.time;
          return true;
        },
        [&](double low, double high) {
          // Somewhere in the bracket: near its first end's point, by what the motion spreads.
          return (!best_ || low < *best_) && region(positionAt(low), spread(low, high));
        });
  }
  static bool anywhere(const Eigen::Vector3d&, double) { return true; }

  /// Whether a feature at `distance` (m) from the centre now, reached at `grown` (m) from it, can
  /// be reached within the horizon at all (at the speed and acceleration, head-on all the way).
  bool reachable(double distance, double grown) const {
    return distance - grown <= travel_ + slack_;
  }

  const std::optional<double>& best() const { return best_; }

 private:
  RelativeMotion motion_;
  double horizon_;
  std::function<double(const Eigen::Vector3d&)> gap_at_;
  double size_ = 0.0;
  double unit_ = 1.0, slack_ = 0.0, travel_ = 0.0;
  long double radius_ = 0;
  std::optional<double> best_;
};

Polynomial square(const Polynomial& p) { return p * p; }

/// The common start of every shape: already overlapping (none), touching and approaching (now),
/// or out of reach within the horizon (none); otherwise the features are searched.
template <class Shape>
std::optional<double> search(const RelativeMotion& motion, const Shape& shape, double horizon,
                             const std::function<void(FeatureSearch&)>& features) {
  if (!(horizon >= 0)) return std::nullopt;
  const NearestFeature start = nearestFeature(shape, motion.centre);
  const double gap = start.distance - motion.radius;
  const double size = boundingRadius(shape);
  const double rounding = roundingOf(motion, size, 16);
  if (gap < -rounding) return std::nullopt;  // overlapping: its impact was when it began
  if (gap <= rounding && start.outward.dot(motion.velocity) < 0) return 0.0;
  const double reach =
      (motion.velocity.norm() + 0.5 * motion.acceleration.norm() * horizon) * horizon;
  if (gap > reach + rounding || !(horizon > 0)) return std::nullopt;
  FeatureSearch search(motion, size, horizon, [&](const Eigen::Vector3d& point) {
    return nearestFeature(shape, point).distance - motion.radius;
  });
  features(search);
  return search.best();
}

}  // namespace

NearestFeature nearestFeature(const Cuboid& box, const Eigen::Vector3d& p) {
  const Eigen::Vector3d& h = box.half_size;
  const Eigen::Vector3d clamped = p.cwiseMax(-h).cwiseMin(h);
  const Eigen::Vector3d offset = p - clamped;
  int outside = 0;
  for (int i = 0; i < 3; ++i) outside += offset[i] != 0;
  if (outside == 0) {
    int axis = 0;
    for (int i = 1; i < 3; ++i) {
      if (h[i] - std::abs(p[i]) < h[axis] - std::abs(p[axis])) axis = i;
    }
    Eigen::Vector3d point = p;
    point[axis] = signOf(p[axis]) * h[axis];
    return insideFace(point, signOf(p[axis]) * Eigen::Vector3d::Unit(axis),
                      h[axis] - std::abs(p[axis]));
  }
  if (outside == 1) {
    NearestFeature face;
    for (int i = 0; i < 3; ++i) {
      if (offset[i] != 0) {
        face.outward = signOf(offset[i]) * Eigen::Vector3d::Unit(i);
        face.distance = std::abs(offset[i]);
      }
    }
    face.point = clamped;
    return face;
  }
  NearestFeature feature = aroundCore(clamped, offset, 0.0, Eigen::Vector3d::UnitZ());
  if (outside == 2) {
    for (int i = 0; i < 3; ++i) {
      if (offset[i] == 0) feature.axis = Eigen::Vector3d::Unit(i);
    }
    feature.axial_share = 0.0;
  }
  return feature;
}

NearestFeature nearestFeature(const Cylinder& cylinder, const Eigen::Vector3d& p) {
  const double radial = std::hypot(p.x(), p.y());
  const Eigen::Vector3d across =
      radial > 0 ? Eigen::Vector3d(p.x() / radial, p.y() / radial, 0) : Eigen::Vector3d::UnitX();
  const double side_depth = cylinder.radius - radial;
  const double cap_depth = cylinder.half_length - std::abs(p.z());
  const double end = signOf(p.z()) * cylinder.half_length;
  if (side_depth >= 0 && cap_depth >= 0) {
    if (cap_depth <= side_depth) {
      return insideFace(Eigen::Vector3d(p.x(), p.y(), end),
                        signOf(p.z()) * Eigen::Vector3d::UnitZ(), cap_depth);
    }
    return insideFace(cylinder.radius * across + p.z() * Eigen::Vector3d::UnitZ(), across,
                      side_depth);
  }
  if (side_depth < 0 && cap_depth >= 0) {  // the side: a line's turning about the axis
    NearestFeature side;
    side.point = cylinder.radius * across + p.z() * Eigen::Vector3d::UnitZ();
    side.outward = across;
    side.distance = -side_depth;
    side.turning_radius = radial;
    side.axis = Eigen::Vector3d::UnitZ();
    side.axial_share = 0.0;
    return side;
  }
  if (side_depth >= 0) {  // a cap
    NearestFeature cap;
    cap.point = Eigen::Vector3d(p.x(), p.y(), end);
    cap.outward = signOf(p.z()) * Eigen::Vector3d::UnitZ();
    cap.distance = -cap_depth;
    return cap;
  }
  // A rim: the circle's nearest point; along the circle the normal turns at (1 - R / radial)
  // of its rate across it (the circle's own turning takes the rest).
  const Eigen::Vector3d core = cylinder.radius * across + end * Eigen::Vector3d::UnitZ();
  NearestFeature rim = aroundCore(core, p - core, 0.0, across);
  rim.axis = Eigen::Vector3d::UnitZ().cross(across);
  rim.axial_share = 1.0 - cylinder.radius / radial;
  return rim;
}

NearestFeature nearestFeature(const Capsule& capsule, const Eigen::Vector3d& p) {
  const double along = std::clamp(p.z(), -capsule.half_length, capsule.half_length);
  const Eigen::Vector3d core(0, 0, along);
  NearestFeature feature = aroundCore(core, p - core, capsule.radius, Eigen::Vector3d::UnitX());
  if (std::abs(p.z()) <= capsule.half_length) {
    feature.axis = Eigen::Vector3d::UnitZ();
    feature.axial_share = 0.0;
  }
  return feature;
}

double boundingRadius(const Cuboid& box) { return box.half_size.stableNorm(); }
double boundingRadius(const Cylinder& cylinder) {
  return std::hypot(cylinder.radius, cylinder.half_length);
}
double boundingRadius(const Capsule& capsule) { return capsule.radius + capsule.half_length; }
double boundingRadius(const Mesh& mesh) { return mesh.triangles->boundingRadius(); }

NearestFeature nearestFeature(const Mesh& mesh, const Eigen::Vector3d& p) {
  const TriangleMesh& triangles = *mesh.triangles;
  const TriangleMesh::NearestPoint near = triangles.nearest(p);
  const TriangleMesh::Triangle& corners = triangles.triangles()[near.triangle];
  NearestFeature feature;
  feature.point = near.point;
  if (near.part == TriangleMesh::Part::kFace) {
    // A face: the distance along its normal, signed; on an open mesh (a surface) its size, the
    // normal turned to the side the point is on.
    const Eigen::Vector3d& normal = triangles.normal(near.triangle);
    const double along = normal.dot(p - triangles.vertices()[corners[0]]);
    const bool behind = !triangles.closed() && along < 0;
    feature.outward = behind ? Eigen::Vector3d(-normal) : normal;
    feature.distance = behind ? -along : along;
    return feature;
  }
  const bool edge = near.part == TriangleMesh::Part::kEdge;
  const TriangleMesh::Edge* on_edge = edge ? &triangles.edgeOf(near.triangle, near.index) : nullptr;
  const std::uint32_t vertex = corners[near.index];
  const Eigen::Vector3d& pseudo_normal =
      edge ? on_edge->pseudo_normal : triangles.vertexPseudoNormal(vertex);
  const bool reachable = edge ? on_edge->reachable : triangles.vertexReachable(vertex);
  const Eigen::Vector3d offset = p - near.point;
  // Inside only a closed mesh, behind the pseudo-normal; an open one has no inside.
  const bool inside = triangles.closed() && offset.dot(pseudo_normal) < 0;
  if (near.distance > 0) {
    feature.outward = (inside ? -offset : offset) / near.distance;
  } else if (triangles.closed()) {
    feature.outward = pseudo_normal.stableNormalized();
  } else {
    // On an open mesh's edge or vertex: its triangle's side (faces back to back sum to zero).
    feature.outward = triangles.normal(near.triangle);
  }
  feature.distance = inside ? -near.distance : near.distance;
  if (reachable && !inside && near.distance > 0) {
    feature.turning_radius = near.distance;
    if (edge) {
      feature.axis =
          (triangles.vertices()[on_edge->to] - triangles.vertices()[on_edge->from]).normalized();
      feature.axial_share = 0.0;
    }
  }
  return feature;
}

std::optional<double> firstContactFinite(const RelativeMotion& motion, const Cuboid& box,
                                         double horizon) {
  return search(motion, box, horizon, [&](FeatureSearch& s) {
    const Eigen::Vector3d& h = box.half_size;
    const long double r = s.radius();
    // Faces: s q_i = h_i + r, the point within the face's rectangle.
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      for (const double side : {-1.0, 1.0}) {
        if (!s.reachable(side * motion.centre[i] - h[i], motion.radius)) continue;
        s.feature(side * s.coordinate(i, side * h[i]) + Polynomial{-r},
                  [&](const Eigen::Vector3d& q, double more) {
                    return s.within(q[j], h[j], more) && s.within(q[k], h[k], more);
                  });
      }
    }
    // Edges along axis i: the line q_j = s_j h_j, q_k = s_k h_k, within the edge's length.
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      for (const double side_j : {-1.0, 1.0}) {
        for (const double side_k : {-1.0, 1.0}) {
          if (!s.reachable(
                  std::hypot(motion.centre[j] - side_j * h[j], motion.centre[k] - side_k * h[k]),
                  motion.radius)) {
            continue;
          }
          const Polynomial dj = s.coordinate(j, side_j * h[j]);
          const Polynomial dk = s.coordinate(k, side_k * h[k]);
          Polynomial p = square(dj) + square(dk);
          FeatureSearch::startFromDistance(p, std::hypot(dj[0], dk[0]), r);
          s.feature(
              p, [&](const Eigen::Vector3d& q, double more) { return s.within(q[i], h[i], more); });
        }
      }
    }
    // Corners.
    for (const double x : {-1.0, 1.0}) {
      for (const double y : {-1.0, 1.0}) {
        for (const double z : {-1.0, 1.0}) {
          if (!s.reachable((motion.centre - Eigen::Vector3d(x, y, z).cwiseProduct(h)).stableNorm(),
                           motion.radius)) {
            continue;
          }
          const Polynomial dx = s.coordinate(0, x * h.x()), dy = s.coordinate(1, y * h.y()),
                           dz = s.coordinate(2, z * h.z());
          Polynomial p = square(dx) + square(dy) + square(dz);
          FeatureSearch::startFromDistance(
              p, std::sqrt(dx[0] * dx[0] + dy[0] * dy[0] + dz[0] * dz[0]), r);
          s.feature(p, FeatureSearch::anywhere);
        }
      }
    }
  });
}

std::optional<double> firstContactFinite(const RelativeMotion& motion, const Cylinder& cylinder,
                                         double horizon) {
  return search(motion, cylinder, horizon, [&](FeatureSearch& s) {
    const long double r = s.radius();
    const long double big = s.scaled(cylinder.radius);
    const Polynomial x = s.coordinate(0), y = s.coordinate(1);
    // The side: q_x^2 + q_y^2 = (R + r)^2 between the caps.
    Polynomial side = square(x) + square(y);
    FeatureSearch::startFromDistance(side, std::hypot(x[0], y[0]), big + r);
    s.feature(side, [&](const Eigen::Vector3d& q, double more) {
      return s.within(q.z(), cylinder.half_length, more);
    });
    for (const double end : {-1.0, 1.0}) {
      // A cap: end q_z = h + r, within the disc.
      s.feature(end * s.coordinate(2, end * cylinder.half_length) + Polynomial{-r},
                [&](const Eigen::Vector3d& q, double more) {
                  return s.within(std::hypot(q.x(), q.y()), cylinder.radius, more);
                });
      // A rim: the torus (|w|^2 + R^2 - r^2)^2 = 4 R^2 (w_x^2 + w_y^2), w = q - end h z, whose
      // value at the start is (d^2 - r^2)((rho + R)^2 + w_z^2 - r^2), d the distance to the
      // circle (so that a small gap keeps its digits).
      const Polynomial z = s.coordinate(2, end * cylinder.half_length);
      if (big <= 1e-6L * r) {
        // A rim far smaller than the ball (a thin rod's end): the torus is then a near-perfect
        // square whose double roots are known only to the square root of the rounding (the
        // fuzzer missed a contact there); the sphere of radius r about the cap's centre, within
        // R (at most 1e-6 r) of the torus everywhere, is the rim instead.
        Polynomial point = square(x) + square(y) + square(z);
        FeatureSearch::startFromDistance(point, std::sqrt(x[0] * x[0] + y[0] * y[0] + z[0] * z[0]),
                                         r);
        s.feature(point, FeatureSearch::anywhere);
        continue;
      }
      const Polynomial planar = square(x) + square(y);
      const Polynomial inner = planar + square(z) + Polynomial{big * big - r * r};
      Polynomial torus = square(inner) + (-4 * big * big) * planar;
      const long double rho = std::hypot(x[0], y[0]);
      const long double to_circle = std::hypot(rho - big, z[0]);
      torus[0] =
          (to_circle - r) * (to_circle + r) * ((rho + big) * (rho + big) + z[0] * z[0] - r * r);
      s.feature(torus, FeatureSearch::anywhere);
    }
  });
}

std::optional<double> firstContactFinite(const RelativeMotion& motion, const Capsule& capsule,
                                         double horizon) {
  return search(motion, capsule, horizon, [&](FeatureSearch& s) {
    const long double grown = s.scaled(capsule.radius) + s.radius();
    const Polynomial x = s.coordinate(0), y = s.coordinate(1);
    Polynomial side = square(x) + square(y);
    FeatureSearch::startFromDistance(side, std::hypot(x[0], y[0]), grown);
    s.feature(side, [&](const Eigen::Vector3d& q, double more) {
      return s.within(q.z(), capsule.half_length, more);
    });
    for (const double end : {-1.0, 1.0}) {
      const Polynomial z = s.coordinate(2, end * capsule.half_length);
      Polynomial ball = square(x) + square(y) + square(z);
      FeatureSearch::startFromDistance(ball, std::sqrt(x[0] * x[0] + y[0] * y[0] + z[0] * z[0]),
                                       grown);
      s.feature(ball, FeatureSearch::anywhere);
    }
  });
}

namespace {

/// The box the ball's path sweeps over [from, to] (its ends, and where a coordinate turns back
/// under the acceleration), grown by the ball and the rounding: the mesh's triangles it may meet.
void pathBox(const FeatureSearch& s, const RelativeMotion& motion, double from, double to,
             Eigen::Vector3d& low, Eigen::Vector3d& high) {
  low = s.positionAt(from).cwiseMin(s.positionAt(to));
  high = s.positionAt(from).cwiseMax(s.positionAt(to));
  for (int i = 0; i < 3; ++i) {
    if (motion.acceleration[i] == 0) continue;
    const double turn = -motion.velocity[i] / motion.acceleration[i];
    if (turn > from && turn < to) {
      low[i] = std::min(low[i], s.positionAt(turn)[i]);
      high[i] = std::max(high[i], s.positionAt(turn)[i]);
    }
  }
  const double grow = motion.radius + 2 * s.slack() + 1e-12 * (high - low).norm();
  low.array() -= grow;
  high.array() += grow;
}

/// A triangle's face: side n.(q - a) = r, q over the triangle; `side` +1 its outer side, -1 its
/// back (an open mesh's, a surface met from either side).
void meshFace(FeatureSearch& s, const RelativeMotion& motion, const TriangleMesh& triangles,
              std::uint32_t t, double side) {
  const std::vector<Eigen::Vector3d>& vertices = triangles.vertices();
  const TriangleMesh::Triangle& corners = triangles.triangles()[t];
  const Eigen::Vector3d& a = vertices[corners[0]];
  const Eigen::Vector3d& normal = triangles.normal(t);
  if (!s.reachable(side * normal.dot(motion.centre - a), motion.radius)) return;
  Polynomial face{-s.radius()};
  for (int i = 0; i < 3; ++i) {
    face = face + static_cast<long double>(side * normal[i]) * s.coordinate(i, a[i]);
  }
  s.feature(face, [&](const Eigen::Vector3d& q, double more) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& u = vertices[corners[k]];
      const Eigen::Vector3d across =
          (vertices[corners[(k + 1) % 3]] - u).cross(normal).normalized();
      if (!s.below(across.dot(q - u), more)) return false;
    }
    return true;
  });
}

/// An edge: |w x u|^2 = r^2, w = q - from, u the edge's direction (for an edge along an axis two
/// of the products are the plain coordinates: a box's polynomial), within the edge's length.
void meshEdge(FeatureSearch& s, const RelativeMotion& motion, const TriangleMesh& triangles,
              const TriangleMesh::Edge& edge) {
  const Eigen::Vector3d& start = triangles.vertices()[edge.from];
  const Eigen::Vector3d along = triangles.vertices()[edge.to] - start;
  const double length = along.norm();
  const Eigen::Vector3d unit = along / length;
  const Eigen::Vector3d to_centre = motion.centre - start;
  if (!s.reachable((to_centre - to_centre.dot(unit) * unit).norm(), motion.radius)) return;
  const Polynomial wx = s.coordinate(0, start.x()), wy = s.coordinate(1, start.y()),
                   wz = s.coordinate(2, start.z());
  const long double ux = unit.x(), uy = unit.y(), uz = unit.z();
  const Polynomial cx = uz * wy + (-uy) * wz, cy = ux * wz + (-uz) * wx, cz = uy * wx + (-ux) * wy;
  Polynomial p = square(cx) + square(cy) + square(cz);
  FeatureSearch::startFromDistance(p, std::sqrt(cx[0] * cx[0] + cy[0] * cy[0] + cz[0] * cz[0]),
                                   s.radius());
  s.feature(p, [&](const Eigen::Vector3d& q, double more) {
    return s.within(unit.dot(q - start) - 0.5 * length, 0.5 * length, more);
  });
}

/// A vertex: |q - v| = r.
void meshVertex(FeatureSearch& s, const RelativeMotion& motion, const Eigen::Vector3d& corner) {
  if (!s.reachable((motion.centre - corner).stableNorm(), motion.radius)) return;
  const Polynomial dx = s.coordinate(0, corner.x()), dy = s.coordinate(1, corner.y()),
                   dz = s.coordinate(2, corner.z());
  Polynomial p = square(dx) + square(dy) + square(dz);
  FeatureSearch::startFromDistance(p, std::sqrt(dx[0] * dx[0] + dy[0] * dy[0] + dz[0] * dz[0]),
                                   s.radius());
  s.feature(p, FeatureSearch::anywhere);
}

/// Appends `index` to `seen` and says so, unless it is there already.
bool firstTime(std::vector<std::uint32_t>& seen, std::uint32_t index) {
  if (std::find(seen.begin(), seen.end(), index) != seen.end()) return false;
  seen.push_back(index);
  return true;
}

}  // namespace

std::optional<double> firstContactFinite(const RelativeMotion& motion, const Mesh& mesh,
                                         double horizon) {
  const TriangleMesh& triangles = *mesh.triangles;
  return search(motion, mesh, horizon, [&](FeatureSearch& s) {
    // Pieces of the path about four radii long (at most 256): the triangles near each, each
    // feature once, the reachable ones only.
    const double travel =
        (motion.velocity.norm() + 0.5 * motion.acceleration.norm() * horizon) * horizon;
    const double piece_length =
        std::max(4 * motion.radius, 1e-9 * (travel + triangles.boundingRadius()));
    const int pieces = static_cast<int>(std::clamp(std::ceil(travel / piece_length), 1.0, 256.0));
    std::vector<std::uint32_t> near, seen_triangles, seen_edges, seen_vertices;
    for (int piece = 0; piece < pieces; ++piece) {
      const double from = horizon * piece / pieces;
      const double to = piece + 1 == pieces ? horizon : horizon * (piece + 1) / pieces;
      Eigen::Vector3d low, high;
      pathBox(s, motion, from, to, low, high);
      near.clear();
      triangles.overlapping(low, high, near);
      for (const std::uint32_t t : near) {
        if (!firstTime(seen_triangles, t)) continue;
        meshFace(s, motion, triangles, t, 1.0);
        if (!triangles.closed()) meshFace(s, motion, triangles, t, -1.0);
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t index = triangles.edgeIndex(t, k);
          if (triangles.edge(index).reachable && firstTime(seen_edges, index)) {
            meshEdge(s, motion, triangles, triangles.edge(index));
          }
        }
        for (const std::uint32_t v : triangles.triangles()[t]) {
          if (triangles.vertexReachable(v) && firstTime(seen_vertices, v)) {
            meshVertex(s, motion, triangles.vertices()[v]);
          }
        }
      }
      if (s.best() && *s.best() <= to) break;  // a later piece's contact is later
    }
  });
}

}  // namespace collision_response::core
