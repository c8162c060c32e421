// Where a moving body's edge (a box's, between two of its corners) or rim (a cylinder's) crosses a
// fixed line (a table's edge), touching it: the contact point, its normal and how both move
// (issue 42, build step 6; doc/model.md, "Over a table's edge", "At an angle to the edge").
//
// The body's feature (a segment, or a circle) and the line touch at X where their common
// perpendicular is 0 long; the normal nu is along t x a (t the feature's unit tangent at X, a the
// line's), from the line into the body. The gap g = nu.(X_body - X_line) changes at g' = nu.V
// (V = v + w x (X - c): the body's point at X), and at
//   g'' = nu'.V + nu.(a_c + w' x r + w x (w x r) + w x (X' - V)),
// X' = lambda' a the contact's own motion along the line, found with the feature's s' from
// lambda' a - s' t = V (the part at right angles to nu), and nu' = (I - nu nu^T)(t' x a) / |t x a|,
// t' = w x t + s' kappa (kappa the feature's curvature vector: 0 on a segment, -(X - C) / rho^2
// on a rim of radius rho about C). The contact's constraint in the tipping (shaped_pivot.cpp) is
// linear in the body's accelerations with these terms.
#pragma once

#include <Eigen/Core>
#include <optional>

namespace collision_response::core {

/// A bounded face's edge: the line through `point` along `along` (unit); `out` (unit, in the
/// face, at right angles to `along`) points off the face.
struct FaceEdge {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d along = Eigen::Vector3d::UnitY();
  Eigen::Vector3d out = Eigen::Vector3d::UnitX();
};

/// The body's motion at an instant: its centre of mass, velocity and angular velocity (world).
struct BodyRates {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d spin = Eigen::Vector3d::Zero();
};

/// A body's feature crossing a line, as the header says.
struct LineCrossing {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();        ///< X, on the body's feature
  Eigen::Vector3d on = Eigen::Vector3d::Zero();           ///< the line's point nearest to it
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();       ///< nu, unit, into the body
  Eigen::Vector3d normal_rate = Eigen::Vector3d::Zero();  ///< nu'
  /// X' - V: the contact point's rate less the body's point's velocity there.
  Eigen::Vector3d over = Eigen::Vector3d::Zero();
  double gap = 0.0;      ///< m, nu.(X - on): > 0 apart
  double on_line = 0.0;  ///< m, from the line's point along it
  /// m, how far within its feature X is: a segment's least distance to its ends, a rim's
  /// rho - d (d the distance of its centre from the line, in the rim's plane); <= 0: no crossing.
  double inside = 0.0;
  /// m/s, X's rate along the feature's tangent, oriented from the segment's first end (a rim's:
  /// along its turning direction).
  double along_feature = 0.0;
  /// Moving into its feature (a segment's crossing near an end moving away from it; a rim's
  /// always).
  bool entering = true;
  Eigen::Vector3d tangent = Eigen::Vector3d::Zero();  ///< t, unit
};

/// The segment from `p0` to `p1` (the body's corners, world) and `line`: empty where the two
/// are parallel (within 1e-9 rad).
std::optional<LineCrossing> segmentCrossing(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                                            const BodyRates& body, const FaceEdge& line);

/// The rim of `radius` about `centre` in the plane across `axis` (unit), `u` a unit in that
/// plane, and `line`: its crossing on `side` (+1: towards +along, -1: towards -along) of the
/// middle of its chord, the point of the circle whose common perpendicular with the line is
/// shortest there (Newton's iteration from the chord's end in the rim's plane). Empty where the
/// line's shadow on the rim's plane misses the circle or runs along the axis.
std::optional<LineCrossing> rimCrossing(const Eigen::Vector3d& centre, const Eigen::Vector3d& axis,
                                        const Eigen::Vector3d& u, double radius, int side,
                                        const BodyRates& body, const FaceEdge& line);

}  // namespace collision_response::core
