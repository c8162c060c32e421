// Coefficients from a tracked body's recorded states (issue 44): the bounces off plane obstacles
// found in the samples, the flights on either side fitted with the scene's own motion model, and
// e, the friction ratio and the air's drag coefficient with their 95 % intervals.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/friction.h"
#include "collision_response/core/scene.h"
#include "collision_response/core/shape.h"

namespace collision_response::core {

/// One tracked state: where the body's centre was at `time` (s, increasing), and what the tracker
/// measured of its spin (rad/s, fixed frame) when it gives it.
struct TrackedSample {
  double time = 0.0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> angular_velocity;
};

/// How the recording is read: the obstacles, the body and the motion model of the scene.
struct CalibrationOptions {
  /// The plane obstacles the body bounces off (unit normals, free side along the normal).
  std::vector<Plane> planes;
  double radius = 0.0;  ///< m, the body's: its centre is `radius` off a plane at contact
  Inertia inertia = Inertia::kSolid;
  /// m/s^2, the scene's; the flights' acceleration (besides drag).
  Eigen::Vector3d gravity = Eigen::Vector3d(0.0, 0.0, -9.81);
  /// Fit gravity as well (three more parameters) instead of taking it as given.
  bool fit_gravity = false;
  /// Flights with quadratic drag (the scene's `drag` effect), integrated by the core's AirFlight:
  /// its factor rho C_d A / (2 m) from these three and `drag_coefficient` (the start of the fit).
  bool drag = false;
  double air_density = 1.204;  ///< kg/m^3
  double mass = 1.0;           ///< kg
  double drag_coefficient = 0.47;
  /// With `drag`: fit C_d as well (one more parameter).
  bool fit_drag = false;
  /// Flights with the Magnus force (the scene's `magnus` effect), integrated by AirFlight as drag
  /// is: its factor rho C_L A / (2 m) from air_density, radius, mass and `lift_coefficient`; the
  /// spin in flight spin_before (required) over the first flight, turned at each bounce by its
  /// tangential impulse (BounceEstimate::spin_change).
  bool magnus = false;
  double lift_coefficient = 0.2;
  /// With `magnus`: fit C_L as well (one more parameter).
  bool fit_lift = false;
  double flight_integration_tolerance = 1e-11;
  /// The spin before the first bounce when the samples carry none (a ball dropped without spin:
  /// zero). Without either, friction gives only a lower bound (whether the contact slid cannot
  /// be told).
  std::optional<Eigen::Vector3d> spin_before;
  /// At most this many bounces, the first ones (0: all found).
  std::size_t max_bounces = 0;
  /// m/s: a bounce is a reversal of the speed towards a plane from at least this (slower ones,
  /// or a body settling, are not bounces).
  double min_bounce_speed = 0.2;
  /// A bounce whose neighbouring samples are further apart than this many sample periods (the
  /// median spacing; and half a period for jitter) lies in a gap of the recording and is refused:
  /// 3, two samples missing in a row are taken, three are not.
  double max_gap_periods = 3.0;
};

/// A fitted quantity and its 95 % interval, value -/+ 1.96 standard errors (the fit's
/// least-squares covariance, propagated to the quantity to first order).
struct Estimate {
  double value = 0.0;
  double standard_error = 0.0;
  double low() const { return value - 1.96 * standard_error; }
  double high() const { return value + 1.96 * standard_error; }
};

/// What a bounce says of friction. The ratio |tangential impulse| / normal impulse is always a
/// lower bound of Coulomb's mu; it is mu itself only when the contact slid throughout.
enum class FrictionReading {
  /// The contact point still slid after the bounce (its slip after 4 standard errors above 0,
  /// not 1.96: a stuck bounce read as sliding would give a wrong mu): mu = the ratio.
  kSliding,
  kStoppedSlipping,  ///< the slip stopped (stuck, or rolling): only mu >= the ratio
  kSpinUnknown,      ///< no spin before the bounce known: only mu >= the ratio
  kNoSlip,           ///< the contact did not slide before it: nothing about mu
};
const char* toString(FrictionReading reading);

struct BounceEstimate {
  std::size_t plane = 0;  ///< index into CalibrationOptions::planes
  Estimate time;          ///< s, the instant the fitted flights meet the plane
  Eigen::Vector3d point = Eigen::Vector3d::Zero();            ///< m, the centre at impact
  Eigen::Vector3d velocity_before = Eigen::Vector3d::Zero();  ///< m/s
  Eigen::Vector3d velocity_after = Eigen::Vector3d::Zero();   ///< m/s
  Estimate approach_speed;  ///< m/s, -v_n before (n the plane's normal)
  Estimate restitution;     ///< e = -v_n after / v_n before
  /// |dv_t| / dv_n: the tangential over the normal change of velocity (of impulse, the mass
  /// cancels); mu itself only when `friction` is kSliding.
  Estimate friction_ratio;
  FrictionReading friction = FrictionReading::kSpinUnknown;
  /// m/s: the contact point's slip after the bounce along its slip before (with a known spin).
  Estimate slip_after;
  /// rad/s, each component: the change of spin the bounce's tangential impulse implies, for a
  /// ball dw = (r x J_t) / I with r = -R n (the contact point from the centre), J_t = m dv_t and
  /// I = k m R^2: -(1 / (k R)) n x dv_t (1/k friction.h's spinFactor). Known without the spin
  /// before (the impulse is the fitted velocities'); 0 for a ball of radius 0.
  std::array<Estimate, 3> spin_change;
  /// rad/s, each component: the spin after the bounce, the spin before (the tracker's over the
  /// flight before, else spin_before carried through the earlier bounces) plus spin_change; none
  /// when the spin before is unknown.
  std::optional<std::array<Estimate, 3>> spin_after;
  /// rad/s, each component: what the tracker saw of the spin after the bounce, the mean of the
  /// samples' angular_velocity over the flight after it (its standard error their scatter over
  /// sqrt(count)), beside spin_after; none with fewer than 2 such samples.
  std::optional<std::array<Estimate, 3>> tracked_spin_after;
  std::size_t samples_before = 0;  ///< in the flight that ends here
  std::size_t samples_after = 0;   ///< in the flight that starts here
};

/// What a set of bounces (all, or those off one plane) says together.
struct Coefficients {
  std::size_t bounces = 0;
  /// e of the bounces together: their generalised least-squares mean under the fit's joint
  /// covariance (the same e at every bounce assumed; `restitution_spread` says whether the data
  /// agree).
  Estimate restitution;
  /// Chi-square of the bounces' e about the mean over its degrees of freedom (bounces - 1): about
  /// 1 when one e explains them; 0 for one bounce (one bounce gives no spread).
  double restitution_spread = 0.0;
  /// mu from the bounces that slid throughout (their generalised least-squares mean); none when
  /// none slid.
  std::optional<Estimate> friction;
  /// mu >= this, from the other bounces' ratios (the largest low end of their 95 % intervals);
  /// none when no bounce had friction to show.
  std::optional<double> friction_lower_bound;
  double slowest_approach = 0.0;  ///< m/s, the range of approach speeds the bounces cover
  double fastest_approach = 0.0;
};

struct Calibration {
  std::vector<BounceEstimate> bounces;
  Coefficients all;  ///< every bounce together
  /// Each plane's bounces together (obstacle pairs differ): per_plane[i] for planes[i] (no
  /// bounces: `bounces` 0).
  std::vector<Coefficients> per_plane;
  /// The joint covariance of the bounces' e, and of their friction ratios (combine() reads them).
  Eigen::MatrixXd restitution_covariance;
  Eigen::MatrixXd friction_ratio_covariance;
  Estimate gravity[3];  ///< m/s^2, the fitted gravity (or the given one, standard error 0)
  std::optional<Estimate> drag_coefficient;  ///< C_d when fitted
  std::optional<Estimate> lift_coefficient;  ///< C_L when fitted
  /// m: the tracker's noise, the root mean square residual of each coordinate (sqrt(RSS / dof)).
  double noise = 0.0;
  std::size_t samples_used = 0;
  std::size_t parameters = 0;
  int iterations = 0;
  /// The fitted motion's start (at the first sample used) and each bounce's velocity after:
  /// fittedPosition() replays it.
  std::vector<double> fitted_parameters;
  double start_time = 0.0;
  double end_time = 0.0;
};

/// What the fit takes from a scene, read in this one place for the live fit (LiveCalibration)
/// and `rosrun collision_response calibrate` (through calibrate_track).
struct SceneCalibration {
  /// The scene's fixed planes (no `frame`: only those are bounced off), gravity with the
  /// `gravity` effect (none without), drag and Magnus with their effects and the air's density; the
  /// body's part by forBody(), the fit's own settings (fit_gravity, max_bounces, ...) as given.
  CalibrationOptions options;
  std::vector<std::string> plane_ids;        ///< the obstacles' ids, of options.planes
  std::vector<std::string> plane_materials;  ///< their materials: one obstacle pair a material
};

/// The scene's part of the fit (with `magnus` the fit flies the Magnus force and needs
/// spin_before); refused, named, for a scene without a fixed plane obstacle.
Expected<SceneCalibration> sceneCalibration(const Scene& scene);

/// What the fit reads of a scene's body.
struct BodyCalibration {
  double radius = 0.0;  ///< m
  Inertia inertia = Inertia::kSolid;
  double mass = 1.0;  ///< kg
  double drag_coefficient = 0.47;
  double lift_coefficient = 0.2;
};
BodyCalibration bodyCalibration(const BodySpec& body);

/// `options` for the body: its radius, inertia, mass and C_d.
CalibrationOptions forBody(CalibrationOptions options, const BodyCalibration& body);

/// Why a recording gives no coefficients.
enum class RecordingProblem {
  kTooFewSamples,    ///< fewer than a flight's fit needs (3 a flight, 8 in all)
  kStampsGoBack,     ///< a sample's time is not after the one before it
  kBadValue,         ///< a sample, a plane or an option is not finite or out of range
  kNoBounce,         ///< no bounce off a plane was found
  kGapAcrossBounce,  ///< the samples around a bounce are further apart than max_gap_periods
  kFitFailed,        ///< the flights could not be fitted (a flight that never meets its plane)
};
const char* toString(RecordingProblem problem);

struct RecordingError {
  RecordingProblem problem = RecordingProblem::kBadValue;
  std::string field;   ///< "samples[12].time", "planes[0].normal", "bounce 2"
  std::string reason;  ///< in words, with the numbers
  /// "<problem>: <field>: <reason>".
  std::string message() const;
};

/// Either a T or why the recording gives none (the core's Expected, with the problem named).
template <typename T>
class RecordingResult {
 public:
  RecordingResult(T value) : storage_(std::move(value)) {}               // NOLINT: implicit
  RecordingResult(RecordingError error) : storage_(std::move(error)) {}  // NOLINT: implicit
  bool ok() const { return std::holds_alternative<T>(storage_); }
  explicit operator bool() const { return ok(); }
  const T& value() const { return std::get<T>(storage_); }
  const T& operator*() const { return value(); }
  const T* operator->() const { return &value(); }
  const RecordingError& error() const { return std::get<RecordingError>(storage_); }

 private:
  std::variant<T, RecordingError> storage_;
};

/// The bounces of one body's recording off `options.planes`, and the coefficients they give.
///
/// Bounces are found where the speed towards a plane reverses (a line fitted to the height over
/// the plane on 4 samples each side falls faster than min_bounce_speed before, rises after) near
/// the plane (the lowest sample within 1.5 samples' travel and 4 times the noise, estimated from
/// the positions' second differences, of it: not the noise at a flight's top). The
/// whole recording is then one least-squares fit (Levenberg-Marquardt, Jacobian by central
/// differences) of a piecewise motion: the state at the first sample, flown with the scene's
/// model (parabolas, motion.h; with drag the core's AirFlight) to where it meets the first
/// bounce's plane, there leaving with a velocity of its own, and so on: the instants and points
/// of impact are where the fitted pieces meet the plane (radius included), never free
/// parameters, so the pieces always meet. The covariance is the linearised least-squares one,
/// sigma^2 (J^T J)^-1 with sigma^2 = RSS / (3 n - parameters), propagated to e, mu and the rest
/// by their gradients (chosen over a bootstrap: exact for a linear model with Gaussian noise,
/// close to it here at the trackers' noise, and a thousandth of the cost). The samples of the
/// last flight are used up to where, past its top, it has fallen halfway back (a body settling
/// afterwards is no flight).
RecordingResult<Calibration> calibrate(const std::vector<TrackedSample>& samples,
                                       const CalibrationOptions& options);

/// The bounces `which` (indices into calibration.bounces) together: a plane's, or those of
/// several planes of one material (one obstacle pair).
Coefficients combine(const Calibration& calibration, const std::vector<std::size_t>& which);

/// A flight alone (no bounce: the samples before a first contact): its start and, with
/// fit_gravity, gravity, and the tracker's noise. `planes` are not used.
RecordingResult<Calibration> fitFlight(const std::vector<TrackedSample>& samples,
                                       const CalibrationOptions& options);

/// The fitted motion's centre at `time` (within the fit's samples' span); NaN where `options`
/// cannot fly it (`magnus` without spin_before).
Eigen::Vector3d fittedPosition(const Calibration& calibration, const CalibrationOptions& options,
                               double time);

}  // namespace collision_response::core
