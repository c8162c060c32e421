// The distance between two convex shapes, each given by its exact support function (the point of
// the shape farthest along a direction), by the Gilbert-Johnson-Keerthi algorithm (Gilbert,
// Johnson and Keerthi, IEEE J. Robotics and Automation 4(2), 1988) with van den Bergen's
// stopping rule ("A fast and robust GJK implementation for collision detection of convex
// objects", J. Graphics Tools 4(2), 1999) and the closest point of each simplex by its Voronoi
// regions (Ericson, Real-Time Collision Detection, 2005, 5.1.5 and 5.1.6).
//
// What it returns is certified, not estimated: each support point w of the Minkowski difference
// A - B in the direction -v bounds the distance from below by v.w / |v| (every point x of A - B
// has x.v >= w.v), and the current closest point v of the simplex (a point of A - B) bounds it
// from above by |v|. The iteration stops when the two are within the tolerance asked for, or
// when no new support point comes (a polytope's distance is then exact to rounding); the lower
// bound is lowered by the rounding of the points (slack below) so that the true distance is
// never below it. A sphere and a capsule are a point and a segment (their cores) grown by their
// radius (their margin): GJK runs on the cores, exact in a few iterations, and the radii are
// subtracted after. Two refinements keep the bounds close near touching: where the nearest
// point is inside a triangle of the simplex, that face's normal (made of its edges, known to the
// shapes' relative rounding) gives a lower bound too, since v, a sum of corners as large as the
// shapes, loses its direction to their rounding when it is 1e-10 long; and where the simplex
// stalls short of the tolerance (a cylinder's round side or rim: its corners crowd together),
// Frank-Wolfe steps go on from its nearest point (to the nearest point of the segment to the next
// support point: nearer every step), each support point a lower bound. A round side still
// converges slowly: its bounds are as close as those steps bring them (a few nm to 1e-7 m near
// touching), the lower one certified all the same.
#pragma once

#include <Eigen/Core>
#include <array>
#include <variant>
#include <vector>

#include "collision_response/core/shape.h"

namespace collision_response::core {

/// The convex hull of a body's points (a mesh body is its hull: mass_properties.h, convexHull),
/// in the body's frame: its corners.
struct ConvexHull {
  std::vector<Eigen::Vector3d> vertices;
};

/// A convex shape in its own frame (a body's: its origin the centre of mass, its axes the
/// principal axes): a sphere about `Sphere::centre` (an offset in the frame, usually 0), a box, a
/// cylinder, a capsule (shape.h) or a convex hull.
using ConvexShape = std::variant<Sphere, Cuboid, Cylinder, Capsule, ConvexHull>;

/// The core's support point in the direction `d` (shape frame): a sphere's centre, a capsule's
/// segment end, a box's corner, a cylinder's rim point (its cap's centre where d is along the
/// axis), a hull's vertex; the shape is its core grown by marginOf.
Eigen::Vector3d coreSupport(const ConvexShape& shape, const Eigen::Vector3d& d);
/// m: the radius a shape's core is grown by: a sphere's and a capsule's radius, 0 otherwise.
double marginOf(const ConvexShape& shape);
/// m: the farthest point of the shape from its frame's origin (a box's half diagonal, ...).
double reachOf(const ConvexShape& shape);
/// The shape's points that may touch first along the direction `d` (shape frame, from the
/// shape towards what it meets): a box's 8 corners and a hull's vertices; a sphere's point
/// along d; a capsule's two ends' points along d; a cylinder's rim points at d's azimuth, a
/// quarter turn either side of it and opposite it, on each cap (8). A face or an edge that lands
/// flat touches at these (a contact manifold's candidates).
void contactCandidates(const ConvexShape& shape, const Eigen::Vector3d& d,
                       std::vector<Eigen::Vector3d>& out);

/// A convex set in the world given by its core's support function (world directions to world
/// points) and the margin the core is grown by.
class SupportMapping {
 public:
  virtual ~SupportMapping() = default;
  virtual Eigen::Vector3d support(const Eigen::Vector3d& d) const = 0;
  /// Some point of the core (its centre).
  virtual Eigen::Vector3d centre() const = 0;
  virtual double margin() const { return 0.0; }
  /// m: a size of the set and its position, for the rounding of its points (|centre| + reach).
  virtual double scale() const = 0;
};

/// A ConvexShape turned by `rotation` and moved to `translation` (world from shape).
class PlacedConvex final : public SupportMapping {
 public:
  PlacedConvex(const ConvexShape& shape, const Eigen::Matrix3d& rotation,
               const Eigen::Vector3d& translation)
      : shape_(&shape), rotation_(rotation), translation_(translation) {}
  Eigen::Vector3d support(const Eigen::Vector3d& d) const override {
    return translation_ + rotation_ * coreSupport(*shape_, rotation_.transpose() * d);
  }
  Eigen::Vector3d centre() const override { return translation_; }
  double margin() const override { return marginOf(*shape_); }
  double scale() const override { return translation_.norm() + reachOf(*shape_); }

 private:
  const ConvexShape* shape_;
  Eigen::Matrix3d rotation_;
  Eigen::Vector3d translation_;
};

/// A point grown by `margin` (a ball), or a point alone.
class PointSupport final : public SupportMapping {
 public:
  explicit PointSupport(const Eigen::Vector3d& point, double margin = 0.0)
      : point_(point), margin_(margin) {}
  Eigen::Vector3d support(const Eigen::Vector3d&) const override { return point_; }
  Eigen::Vector3d centre() const override { return point_; }
  double margin() const override { return margin_; }
  double scale() const override { return point_.norm() + margin_; }

 private:
  Eigen::Vector3d point_;
  double margin_;
};

/// A triangle (a mesh's, in the world).
class TriangleSupport final : public SupportMapping {
 public:
  TriangleSupport(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c)
      : corners_{a, b, c} {}
  Eigen::Vector3d support(const Eigen::Vector3d& d) const override;
  Eigen::Vector3d centre() const override { return (corners_[0] + corners_[1] + corners_[2]) / 3; }
  double scale() const override;

 private:
  std::array<Eigen::Vector3d, 3> corners_;
};

/// The distance between two convex sets (their surfaces, margins subtracted).
struct ConvexDistance {
  /// m: the distance is certainly in [lower, upper]; where the cores overlap, upper is minus the
  /// margins and lower is -infinity (no depth is computed).
  double lower = 0.0;
  double upper = 0.0;
  bool overlapping = false;  ///< the cores overlap (the sets do, by more than their margins)
  /// Unit, from a towards b (along the closest points of the cores; where they overlap, the
  /// direction of the last search).
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  /// The closest points of the surfaces (each core's closest point moved out by its margin along
  /// the normal): |point_b - point_a| is `upper` where the sets are apart.
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d point_b = Eigen::Vector3d::Zero();
  int iterations = 0;
};

/// The distance between `a` and `b`: GJK until upper - lower <= `tolerance` (m) or no new
/// support point, at most `max_iterations`.
ConvexDistance convexDistance(const SupportMapping& a, const SupportMapping& b, double tolerance,
                              int max_iterations = 128);

}  // namespace collision_response::core
