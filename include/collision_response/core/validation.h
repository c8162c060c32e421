// Checks of every input the core accepts, each failure an Error naming the field and the reason.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <initializer_list>
#include <string>

#include "collision_response/core/body.h"
#include "collision_response/core/expected.h"

namespace collision_response::core {

/// The shortest text that reads back as the same double ("0.1", "-1", "nan", "inf").
std::string formatNumber(double value);
/// "[x, y, z]" with formatNumber.
std::string formatVector(const Eigen::Vector3d& value);

Status checkFinite(double value, const std::string& field);
Status checkFinite(const Eigen::Vector3d& value, const std::string& field);
/// 0 <= e <= 1 (e = 0 plastic, e = 1 elastic).
Status checkRestitution(double restitution, const std::string& field);
/// > 0 and 1/mass finite, or +inf (immovable).
Status checkMass(double mass, const std::string& field);
/// Finite and >= 0.
Status checkRadius(double radius, const std::string& field);
/// A material or body id: not empty, no whitespace or control characters.
Status checkName(const std::string& name, const std::string& field);
/// A tf2 frame id: a name (checkName) without the leading '/' that tf2 refuses.
Status checkFrameId(const std::string& frame, const std::string& field);
/// Coulomb mu: a finite number >= 0.
Status checkFriction(double friction, const std::string& field);
/// The restitution threshold, m/s: a finite number >= 0 (an approach at or above it bounces).
Status checkRestitutionThreshold(double threshold, const std::string& field);
/// A drag or lift coefficient (C_d, C_L): a finite number >= 0.
Status checkAirCoefficient(double coefficient, const std::string& field);
/// Surfaces within this fraction of their contact distance touch: finite, >= 0 and < 1.
Status checkContactTolerance(double tolerance, const std::string& field);

/// One number (or vector) of an answer, named as the answer's field.
struct NamedResult {
  const char* field;
  bool finite;
};
inline NamedResult namedResult(const char* field, double value) {
  return {field, std::isfinite(value)};
}
inline NamedResult namedResult(const char* field, const Eigen::Vector3d& value) {
  return {field, value.allFinite()};
}
/// Why an answer from finite inputs is refused when a number of it is not finite.
inline constexpr const char* kBeyondDoubles =
    "is beyond the range of double (the masses and speeds are too large for the answer to be "
    "represented)";
/// The first result that is not finite, refused by name (kBeyondDoubles): the one check of
/// every output, the service's answers and the monitor's impacts alike.
Status checkRepresentable(std::initializer_list<NamedResult> results);

/// The monitor resolves contacts only at positions whose every coordinate is below this, m:
/// 2^1022 (about 4.49e307). Its geometry adds the magnitudes of two positions: each pair's
/// touching band is 16 eps (|a| + |b| + r_a + r_b) (motion_model.h) and each swept box is padded
/// by 64 eps (|low| + |high|). Past 2^1023 (DBL_MAX / 2) those sums overflow to infinity and the
/// pair is lost without a word: a stack at x = 9e307 (or 1.7e308) fell through its floor, with
/// no contact, where at 8.9e307 it stayed. Half that, 2^1022, leaves the other half of the range
/// to the motion within a step (a box's corners, a body's reach), so the sums stay finite.
/// Far below it the contacts are coarse, not lost: the band, 2^-48 (|a| + |b|) (16 eps = 2^-48),
/// is as wide as a body of radius r from |x| = 2^47 r on (7.04e12 m for 5 cm), and bodies that
/// far apart touch (README, "Bad input on the topics").
inline constexpr double kMaxResolvedCoordinate = 0x1p1022;
/// Each coordinate of a position the monitor tracks: finite and |x| < kMaxResolvedCoordinate. The
/// error names the coordinate (`field`.x) and the bound.
Status checkResolvablePosition(const Eigen::Vector3d& position, const std::string& field);

/// The densest air the drag and magnus effects take, kg/m^3: denser than any liquid (mercury,
/// 13,546 kg/m^3), where a flight's speed would be spent at once.
inline constexpr double kMaxAirDensity = 2e4;
/// The largest air factor of a body, rho C A / (2 m) (drag's or lift's, 1/m; AirFactors), its
/// flight is integrated with: there the terminal speed sqrt(|g| / k) is 0.099 m/s and a flight
/// of the prediction's 60 s horizon takes about 3,800 of the integrator's steps; at 1e5 1/m
/// (explicit steps held by the drag's stiffness) the 16,384 a flight may take run out at 27 s
/// (doc/model.md, "Effects in detail").
inline constexpr double kMaxAirFactor = 1e3;

/// A length of an obstacle, m (a plane's offset, a box's edge, a radius or a length): its
/// magnitude below kMaxResolvedCoordinate, as a body's coordinates (their sums overflow past it).
Status checkResolvableLength(double length, const std::string& field);
/// An obstacle's position (its centre, a mesh's origin), where its contacts resolve: as a body's
/// (checkResolvablePosition), and each coordinate below 2^47 times `reach`, the radius of the
/// smallest sphere about the position that holds the obstacle (0: a point, no such bound). From
/// there on a body near it has a touching band, 2^-48 (|x_body| + |x| + reach + r), as wide as
/// the whole obstacle (a box at x = 1e300 met a ball 1.1 m above it at once): the bound that
/// makes contacts with a ball of radius r coarse from |x| = 2^47 r on (README, "Bad input on
/// the topics") holds the obstacle's own size. The error names the coordinate (`field`.x); a
/// scene warns with it (obstaclesBeyondResolution), as its bodies are coarse there, not lost.
Status checkResolvableObstaclePosition(const Eigen::Vector3d& position, double reach,
                                       const std::string& field);

/// Mass, radius, position, velocity and angular velocity of one body; `prefix` names it ("a").
Status checkBody(const Body& body, const std::string& prefix);

/// `v` (nonzero, finite) scaled to unit length at any magnitude, 1e-320 as 1e300: divided by
/// its largest component first (exactly 1 there, the others correctly rounded), then by the
/// norm of that (between 1 and sqrt 3). Eigen's stableNormalized() divides by their product
/// instead, which among the subnormals keeps a few bits only: (0, 1.1e-321, 2.7e-319) came out
/// 1e-5 away from unit length, and an elastic impact along it gained energy (a fuzzer's finding).
Eigen::Vector3d unitVector(const Eigen::Vector3d& v);

/// The unit line of impact, pointing from a to b: `normal` scaled to unit length when it is
/// nonzero; when it is zero, the direction from a's centre to b's. Errors: a non-finite normal,
/// or a zero normal with coincident centres (no line of impact).
Expected<Eigen::Vector3d> lineOfImpact(const Eigen::Vector3d& normal,
                                       const Eigen::Vector3d& position_a,
                                       const Eigen::Vector3d& position_b,
                                       const std::string& field = "normal");

/// How far a unit quaternion's squared length may be from 1: tf2's tolerance for a transform's
/// rotation (its buffer refuses a quaternion whose x^2 + y^2 + z^2 + w^2 is 0.01 or more away).
inline constexpr double kQuaternionNormTolerance = 0.01;
/// Whether checkOrientation takes it: every component finite, not zero, of length 1 to
/// kQuaternionNormTolerance on its square.
bool isRotation(const Eigen::Quaterniond& orientation);
/// An orientation (world from body): every component finite (`field`.x, .y, .z, .w named), not
/// zero (no rotation has it), and of unit length to kQuaternionNormTolerance in its square (a
/// quaternion of another length is a mistake, not a rotation: the caller then normalises it).
Status checkOrientation(const Eigen::Quaterniond& orientation, const std::string& field);

}  // namespace collision_response::core
