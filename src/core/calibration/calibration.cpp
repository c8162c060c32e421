// Coefficients from a tracked body's recorded states: see calibration.h.
#include "collision_response/core/calibration.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <tuple>

#include "geometry/air_flight.h"
#include "geometry/motion.h"

namespace collision_response::core {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// Samples on each side of a bounce's sample in the lines that find it.
constexpr std::size_t kWindow = 4;
/// The fewest samples a flight's fit may have, and a recording.
constexpr std::size_t kMinFlightSamples = 3;
constexpr std::size_t kMinSamples = 8;
constexpr int kMaxIterations = 200;

std::string number(double value) {
  std::ostringstream out;
  out.precision(9);
  out << value;
  return out.str();
}

RecordingError problem(RecordingProblem kind, std::string field, std::string reason) {
  return RecordingError{kind, std::move(field), std::move(reason)};
}

/// Where the parameters are: the state at the first sample (position, velocity), each bounce's
/// velocity after, then gravity, C_d and C_L when they are fitted.
struct Layout {
  std::size_t bounces = 0;
  bool gravity = false;
  bool drag = false;
  bool lift = false;
  std::size_t gravityAt() const { return 6 + 3 * bounces; }
  std::size_t dragAt() const { return gravityAt() + (gravity ? 3 : 0); }
  std::size_t liftAt() const { return dragAt() + (drag ? 1 : 0); }
  std::size_t size() const { return liftAt() + (lift ? 1 : 0); }
};

Layout layoutOf(std::size_t bounces, const CalibrationOptions& options) {
  return Layout{bounces, options.fit_gravity, options.drag && options.fit_drag,
                options.magnus && options.fit_lift};
}

/// One flight of a candidate motion: its start and state there, and through air (drag, Magnus)
/// its integration.
struct Piece {
  double start = 0.0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  std::shared_ptr<AirFlight> air;
};

/// The turn a ball's tangential change of velocity dv_t at a bounce off the plane of normal n
/// gives its spin: the impulse J_t = m dv_t at r = -R n from the centre, dw = (r x J_t) / I with
/// I = k m R^2, -(1 / (k R)) n x dv_t (calibration.h; 1/k friction.h's spinFactor). 0 for R = 0.
Eigen::Vector3d spinChange(const Eigen::Vector3d& n, const Eigen::Vector3d& tangential_change,
                           double radius, Inertia inertia) {
  if (!(radius > 0.0)) return Eigen::Vector3d::Zero();
  return -(spinFactor(1.0, radius, inertia) / radius) * n.cross(tangential_change);
}

double height(const Plane& plane, double radius, const Eigen::Vector3d& position) {
  return plane.normal.dot(position) - plane.offset - radius;
}

/// The motion the parameters give: the flights, each from the instant the one before met its
/// bounce's plane (calibration.h).
class Motion {
 public:
  Motion(const CalibrationOptions& options, const Layout& layout,
         const std::vector<std::size_t>& bounce_planes, double start, double horizon)
      : options_(options),
        layout_(layout),
        bounce_planes_(bounce_planes),
        start_(start),
        horizon_(horizon) {}

  /// False when a flight does not meet its bounce's plane before the horizon.
  bool build(const Eigen::VectorXd& parameters) {
    pieces_.clear();
    gravity_ = layout_.gravity ? Eigen::Vector3d(parameters.segment<3>(layout_.gravityAt()))
                               : options_.gravity;
    if (air()) {
      const double drag = !options_.drag ? 0.0
                          : layout_.drag ? parameters[static_cast<Eigen::Index>(layout_.dragAt())]
                                         : options_.drag_coefficient;
      const double lift = !options_.magnus ? 0.0
                          : layout_.lift   ? parameters[static_cast<Eigen::Index>(layout_.liftAt())]
                                           : options_.lift_coefficient;
      if (!(drag >= 0.0) || !std::isfinite(lift)) return false;
      air_ = airFactors(options_.air_density, options_.radius, 1.0 / options_.mass, drag, lift);
    }
    // The spin in flight (Magnus): spin_before over the first flight (checkOptions; without it,
    // as fittedPosition may be given, no motion), then turned at each bounce by its tangential
    // impulse, as BounceQuantities carries it.
    if (options_.magnus && !options_.spin_before) return false;
    Eigen::Vector3d spin = options_.spin_before.value_or(Eigen::Vector3d::Zero());
    pieces_.push_back(makePiece(start_, parameters.segment<3>(0), parameters.segment<3>(3), spin));
    for (std::size_t j = 0; j < layout_.bounces; ++j) {
      const Plane& plane = options_.planes[bounce_planes_[j]];
      const auto meeting = nextMeeting(pieces_.back(), plane);
      if (!meeting) return false;
      const Eigen::Vector3d point = position(pieces_.back(), *meeting);
      const Eigen::Vector3d after = parameters.segment<3>(static_cast<Eigen::Index>(6 + 3 * j));
      if (options_.magnus) {
        const Eigen::Vector3d change = after - velocity(pieces_.back(), *meeting);
        spin += spinChange(plane.normal, change - change.dot(plane.normal) * plane.normal,
                           options_.radius, options_.inertia);
      }
      pieces_.push_back(makePiece(*meeting, point, after, spin));
    }
    return true;
  }

  std::size_t pieceAt(double time) const {
    std::size_t j = 0;
    while (j + 1 < pieces_.size() && time >= pieces_[j + 1].start) ++j;
    return j;
  }
  Eigen::Vector3d positionAt(double time) const { return position(pieces_[pieceAt(time)], time); }
  const std::vector<Piece>& pieces() const { return pieces_; }
  Eigen::Vector3d velocityBefore(std::size_t bounce) const {
    return velocity(pieces_[bounce], pieces_[bounce + 1].start);
  }
  const Eigen::Vector3d& gravity() const { return gravity_; }

 private:
  bool air() const { return options_.drag || options_.magnus; }
  Piece makePiece(double start, const Eigen::Vector3d& position, const Eigen::Vector3d& velocity,
                  const Eigen::Vector3d& spin) {
    Piece piece{start, position, velocity, nullptr};
    if (air()) {
      piece.air = std::make_shared<AirFlight>(start, position, velocity, spin, gravity_, air_,
                                              options_.flight_integration_tolerance);
    }
    return piece;
  }
  Eigen::Vector3d position(const Piece& piece, double time) const {
    if (piece.air) return piece.air->position(0, time);
    return positionAfter(piece.position, piece.velocity, gravity_, time - piece.start);
  }
  Eigen::Vector3d velocity(const Piece& piece, double time) const {
    if (piece.air) return piece.air->velocity(0, time);
    return velocityAfter(piece.velocity, gravity_, time - piece.start);
  }

  /// The first instant after the piece's start at which it crosses `plane` inwards (the height
  /// over it falling through 0).
  std::optional<double> nextMeeting(const Piece& piece, const Plane& plane) const {
    if (piece.air) return nextMeetingInAir(piece, plane);
    // h(s) = h0 + vn s + gn s^2 / 2, s after the start: the least positive root where h falls.
    const double h0 = height(plane, options_.radius, piece.position);
    const double vn = plane.normal.dot(piece.velocity);
    const double gn = plane.normal.dot(gravity_);
    std::optional<double> best;
    const auto consider = [&](double s) {
      if (std::isfinite(s) && s > 0.0 && vn + gn * s < 0.0 && (!best || s < *best)) best = s;
    };
    if (gn == 0.0) {
      if (vn != 0.0) consider(-h0 / vn);
    } else {
      const double discriminant = vn * vn - 2.0 * gn * h0;
      if (discriminant < 0.0) return std::nullopt;
      // Both roots without cancellation: q = -(vn + sign(vn) sqrt(D)), roots q / gn and 2 h0 / q.
      const double q = -(vn + std::copysign(std::sqrt(discriminant), vn));
      consider(q / gn);
      if (q != 0.0) consider(2.0 * h0 / q);
    }
    if (!best || piece.start + *best > horizon_) return std::nullopt;
    return piece.start + *best;
  }

  std::optional<double> nextMeetingInAir(const Piece& piece, const Plane& plane) const {
    const double step = 1e-3;
    double before = piece.start;
    double h_before = height(plane, options_.radius, piece.position);
    for (double t = piece.start + step; t <= horizon_ + step; t += step) {
      const double h = height(plane, options_.radius, position(piece, t));
      if (h < 0.0 && h_before >= 0.0 && t > piece.start + step / 2) {
        double low = before;
        double high = t;
        for (int i = 0; i < 80 && high - low > 0.0; ++i) {
          const double middle = 0.5 * (low + high);
          if (middle <= low || middle >= high) break;
          (height(plane, options_.radius, position(piece, middle)) >= 0.0 ? low : high) = middle;
        }
        return 0.5 * (low + high);
      }
      if (piece.air->stalledAt() < kInf) return std::nullopt;
      before = t;
      h_before = h;
    }
    return std::nullopt;
  }

  const CalibrationOptions& options_;
  Layout layout_;
  std::vector<std::size_t> bounce_planes_;
  double start_;
  double horizon_;
  Eigen::Vector3d gravity_ = Eigen::Vector3d::Zero();
  AirFactors air_;
  std::vector<Piece> pieces_;
};

/// The residuals of the samples against the motion of `parameters` (3 a sample); false when the
/// motion cannot be built.
bool residuals(Motion& motion, const std::vector<TrackedSample>& samples,
               const Eigen::VectorXd& parameters, Eigen::VectorXd& out) {
  if (!motion.build(parameters)) return false;
  out.resize(static_cast<Eigen::Index>(3 * samples.size()));
  for (std::size_t k = 0; k < samples.size(); ++k) {
    out.segment<3>(static_cast<Eigen::Index>(3 * k)) =
        motion.positionAt(samples[k].time) - samples[k].position;
  }
  return out.allFinite();
}

double stepFor(double value) { return 1e-6 * std::max(1.0, std::abs(value)); }

/// d f / d parameters by central differences; false where f cannot be evaluated.
template <typename F>
bool jacobian(const F& f, const Eigen::VectorXd& parameters, Eigen::Index rows,
              Eigen::MatrixXd& out) {
  out.resize(rows, parameters.size());
  Eigen::VectorXd plus;
  Eigen::VectorXd minus;
  for (Eigen::Index i = 0; i < parameters.size(); ++i) {
    const double step = stepFor(parameters[i]);
    Eigen::VectorXd shifted = parameters;
    shifted[i] = parameters[i] + step;
    if (!f(shifted, plus)) return false;
    shifted[i] = parameters[i] - step;
    if (!f(shifted, minus)) return false;
    out.col(i) = (plus - minus) / (2.0 * step);
  }
  return out.allFinite();
}

struct Fit {
  Eigen::VectorXd parameters;
  Eigen::MatrixXd covariance;
  double noise = 0.0;
  int iterations = 0;
};

/// Levenberg-Marquardt from `start`; the covariance sigma^2 (J^T J)^-1 at the end.
std::optional<Fit> leastSquares(Motion& motion, const std::vector<TrackedSample>& samples,
                                Eigen::VectorXd parameters) {
  const auto f = [&](const Eigen::VectorXd& p, Eigen::VectorXd& r) {
    return residuals(motion, samples, p, r);
  };
  Eigen::VectorXd r;
  if (!f(parameters, r)) return std::nullopt;
  double cost = r.squaredNorm();
  Eigen::MatrixXd j;
  double lambda = 1e-3;
  int iteration = 0;
  for (; iteration < kMaxIterations; ++iteration) {
    if (!jacobian(f, parameters, r.size(), j)) return std::nullopt;
    const Eigen::MatrixXd normal = j.transpose() * j;
    const Eigen::VectorXd gradient = j.transpose() * r;
    bool improved = false;
    bool converged = false;
    while (lambda < 1e16) {
      Eigen::MatrixXd damped = normal;
      damped.diagonal() += lambda * normal.diagonal().cwiseMax(1e-300);
      const Eigen::VectorXd step = damped.ldlt().solve(-gradient);
      const Eigen::VectorXd tried = parameters + step;
      Eigen::VectorXd tried_r;
      if (step.allFinite() && f(tried, tried_r) && tried_r.squaredNorm() <= cost) {
        const double decrease = cost - tried_r.squaredNorm();
        converged = decrease <= 1e-14 * cost || step.norm() <= 1e-13 * (1.0 + parameters.norm());
        parameters = tried;
        r = tried_r;
        cost = r.squaredNorm();
        lambda = std::max(lambda / 10.0, 1e-12);
        improved = true;
        break;
      }
      lambda *= 10.0;
    }
    if (!improved || converged) break;
  }
  if (iteration == kMaxIterations) return std::nullopt;  // never settled: no fit to answer
  if (!f(parameters, r) || !jacobian(f, parameters, r.size(), j)) return std::nullopt;
  const auto dof = static_cast<double>(r.size() - parameters.size());
  if (!(dof > 0)) return std::nullopt;
  Fit fit;
  fit.parameters = parameters;
  fit.noise = std::sqrt(r.squaredNorm() / dof);
  const Eigen::MatrixXd normal = j.transpose() * j;
  const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(normal.rows(), normal.cols());
  fit.covariance = fit.noise * fit.noise * normal.ldlt().solve(identity);
  fit.iterations = iteration + 1;
  if (!fit.covariance.allFinite()) return std::nullopt;
  return fit;
}

/// The slope of h over t on samples [first, last] (least squares), or 0 with fewer than 2.
double slope(const std::vector<double>& t, const std::vector<double>& h, std::size_t first,
             std::size_t last) {
  double mean_t = 0.0;
  double mean_h = 0.0;
  const auto count = static_cast<double>(last - first + 1);
  for (std::size_t k = first; k <= last; ++k) {
    mean_t += t[k];
    mean_h += h[k];
  }
  mean_t /= count;
  mean_h /= count;
  double sxy = 0.0;
  double sxx = 0.0;
  for (std::size_t k = first; k <= last; ++k) {
    sxy += (t[k] - mean_t) * (h[k] - mean_h);
    sxx += (t[k] - mean_t) * (t[k] - mean_t);
  }
  return sxx > 0.0 ? sxy / sxx : 0.0;
}

struct FoundBounce {
  std::size_t sample = 0;  ///< the sample nearest the plane
  std::size_t plane = 0;
  double height = 0.0;
};

/// The tracker's noise (m, each coordinate) before any fit: the median absolute second
/// difference of the positions over evenly spaced triples, gravity's g dt^2 taken out, as a
/// normal distribution's standard deviation (1.4826 median |d|; d = p+ - 2 p + p- has 6 sigma^2).
/// A few bounces among the triples do not move a median.
double noiseBeforeTheFit(const std::vector<TrackedSample>& samples,
                         const Eigen::Vector3d& gravity) {
  std::vector<double> second;
  for (std::size_t k = 1; k + 1 < samples.size(); ++k) {
    const double before = samples[k].time - samples[k - 1].time;
    const double after = samples[k + 1].time - samples[k].time;
    if (std::abs(before - after) > 0.01 * std::max(before, after)) continue;
    const Eigen::Vector3d d = samples[k + 1].position - 2.0 * samples[k].position +
                              samples[k - 1].position - (before * after) * gravity;
    for (int i = 0; i < 3; ++i) second.push_back(std::abs(d[i]));
  }
  if (second.empty()) return 0.0;
  std::nth_element(second.begin(), second.begin() + static_cast<std::ptrdiff_t>(second.size() / 2),
                   second.end());
  return 1.4826 * second[second.size() / 2] / std::sqrt(6.0);
}

/// Bounces: the speed towards a plane reversing (calibration.h), one per window.
std::vector<FoundBounce> findBounces(const std::vector<TrackedSample>& samples,
                                     const CalibrationOptions& options) {
  std::vector<FoundBounce> found;
  const std::size_t n = samples.size();
  const double noise = noiseBeforeTheFit(samples, options.gravity);
  std::vector<double> t(n);
  for (std::size_t k = 0; k < n; ++k) t[k] = samples[k].time;
  for (std::size_t i = 0; i < options.planes.size(); ++i) {
    std::vector<double> h(n);
    for (std::size_t k = 0; k < n; ++k) {
      h[k] = height(options.planes[i], options.radius, samples[k].position);
    }
    for (std::size_t k = kWindow; k + kWindow < n; ++k) {
      const double lowest =
          *std::min_element(h.begin() + static_cast<std::ptrdiff_t>(k - kWindow),
                            h.begin() + static_cast<std::ptrdiff_t>(k + kWindow + 1));
      if (h[k] != lowest) continue;
      const double before = slope(t, h, k - kWindow, k);
      const double after = slope(t, h, k, k + kWindow);
      // At a bounce the sample nearest the plane is within a sample's travel of it (and the
      // noise): a reversal far from the plane is the noise at a flight's top.
      const double spacing = std::max(t[k] - t[k - 1], t[k + 1] - t[k]);
      const double near = 1.5 * std::max(-before, after) * spacing + 4.0 * noise + 1e-3;
      if (before < -options.min_bounce_speed && after > 0.0 &&
          after - before > 2.0 * options.min_bounce_speed && h[k] <= near) {
        found.push_back(FoundBounce{k, i, h[k]});
      }
    }
  }
  std::sort(found.begin(), found.end(),
            [](const FoundBounce& a, const FoundBounce& b) { return a.sample < b.sample; });
  std::vector<FoundBounce> merged;
  for (const auto& bounce : found) {
    if (!merged.empty() && bounce.sample <= merged.back().sample + kWindow) {
      if (bounce.height < merged.back().height) merged.back() = bounce;
    } else {
      merged.push_back(bounce);
    }
  }
  return merged;
}

std::optional<RecordingError> checkSamples(const std::vector<TrackedSample>& samples) {
  if (samples.size() < kMinSamples) {
    return problem(RecordingProblem::kTooFewSamples, "samples",
                   std::to_string(samples.size()) + " samples; a fit needs at least " +
                       std::to_string(kMinSamples));
  }
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const std::string field = "samples[" + std::to_string(k) + "]";
    if (!std::isfinite(samples[k].time)) {
      return problem(RecordingProblem::kBadValue, field + ".time",
                     "must be finite, got " + number(samples[k].time));
    }
    if (!samples[k].position.allFinite()) {
      return problem(RecordingProblem::kBadValue, field + ".position", "must be finite");
    }
    if (samples[k].angular_velocity && !samples[k].angular_velocity->allFinite()) {
      return problem(RecordingProblem::kBadValue, field + ".angular_velocity", "must be finite");
    }
    if (k > 0 && !(samples[k].time > samples[k - 1].time)) {
      return problem(RecordingProblem::kStampsGoBack, field + ".time",
                     number(samples[k].time) + " s is not after the sample before it (" +
                         number(samples[k - 1].time) + " s)");
    }
  }
  return std::nullopt;
}

std::optional<RecordingError> checkOptions(const CalibrationOptions& options, bool planes) {
  if (planes && options.planes.empty()) {
    return problem(RecordingProblem::kBadValue, "planes", "no plane to bounce off");
  }
  for (std::size_t i = 0; i < options.planes.size(); ++i) {
    const auto& plane = options.planes[i];
    const std::string field = "planes[" + std::to_string(i) + "]";
    if (!plane.normal.allFinite() || std::abs(plane.normal.norm() - 1.0) > 1e-9) {
      return problem(RecordingProblem::kBadValue, field + ".normal", "must be a unit vector");
    }
    if (!std::isfinite(plane.offset)) {
      return problem(RecordingProblem::kBadValue, field + ".offset", "must be finite");
    }
  }
  if (!(options.radius >= 0.0) || !std::isfinite(options.radius)) {
    return problem(RecordingProblem::kBadValue, "radius",
                   "must be finite and >= 0, got " + number(options.radius));
  }
  if (!options.gravity.allFinite()) {
    return problem(RecordingProblem::kBadValue, "gravity", "must be finite");
  }
  if (options.drag || options.magnus) {
    if (!(options.air_density > 0.0) || !std::isfinite(options.air_density)) {
      return problem(RecordingProblem::kBadValue, "air_density", "must be finite and > 0");
    }
    if (!(options.mass > 0.0) || !std::isfinite(options.mass)) {
      return problem(RecordingProblem::kBadValue, "mass", "must be finite and > 0");
    }
    if (!(options.radius > 0.0)) {
      return problem(RecordingProblem::kBadValue, "radius", "must be > 0 with drag or magnus");
    }
    if (!(options.drag_coefficient >= 0.0) || !std::isfinite(options.drag_coefficient)) {
      return problem(RecordingProblem::kBadValue, "drag_coefficient", "must be finite and >= 0");
    }
  }
  if (options.magnus) {
    if (!(options.lift_coefficient >= 0.0) || !std::isfinite(options.lift_coefficient)) {
      return problem(RecordingProblem::kBadValue, "lift_coefficient", "must be finite and >= 0");
    }
    if (!options.spin_before) {
      return problem(RecordingProblem::kBadValue, "spin_before",
                     "magnus flies the spin: give the spin before the first bounce (the "
                     "tracker's spin is not flown)");
    }
  }
  if (!(options.min_bounce_speed > 0.0) || !std::isfinite(options.min_bounce_speed)) {
    return problem(RecordingProblem::kBadValue, "min_bounce_speed", "must be finite and > 0");
  }
  if (!(options.max_gap_periods >= 1.0)) {
    return problem(RecordingProblem::kBadValue, "max_gap_periods", "must be >= 1");
  }
  if (options.spin_before && !options.spin_before->allFinite()) {
    return problem(RecordingProblem::kBadValue, "spin_before", "must be finite");
  }
  return std::nullopt;
}

/// The longest spacing of samples a bounce may lie in: max_gap_periods periods, and half a period
/// for the jitter of stamps (and their rounding: 3 periods of 1/60 s are 0.05 s, or just above).
double longestSpacing(const CalibrationOptions& options, double period) {
  return (options.max_gap_periods + 0.5) * period;
}

double medianSpacing(const std::vector<TrackedSample>& samples) {
  std::vector<double> spacing;
  for (std::size_t k = 1; k < samples.size(); ++k) {
    spacing.push_back(samples[k].time - samples[k - 1].time);
  }
  std::nth_element(spacing.begin(),
                   spacing.begin() + static_cast<std::ptrdiff_t>(spacing.size() / 2),
                   spacing.end());
  return spacing[spacing.size() / 2];
}

/// A line fitted to one flight's samples with gravity taken out, p - g s^2 / 2 = a + b s (s
/// after `origin`): its start `a` and velocity `b`, the start of the fit.
std::pair<Eigen::Vector3d, Eigen::Vector3d> lineThrough(const std::vector<TrackedSample>& samples,
                                                        std::size_t first, std::size_t last,
                                                        double origin,
                                                        const Eigen::Vector3d& gravity) {
  Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
  Eigen::Matrix<double, 2, 3> right = Eigen::Matrix<double, 2, 3>::Zero();
  for (std::size_t k = first; k <= last; ++k) {
    const double s = samples[k].time - origin;
    const Eigen::Vector3d y = samples[k].position - 0.5 * s * s * gravity;
    const Eigen::Vector2d row(1.0, s);
    normal += row * row.transpose();
    right += row * y.transpose();
  }
  const Eigen::Matrix<double, 2, 3> solution = normal.ldlt().solve(right);
  return {solution.row(0).transpose(), solution.row(1).transpose()};
}

Estimate estimate(double value, double variance) {
  return Estimate{value, std::sqrt(std::max(variance, 0.0))};
}

/// The generalised least-squares mean of `values` under `covariance`, and the chi-square of the
/// values about it over its degrees of freedom.
std::pair<Estimate, double> commonMean(const Eigen::VectorXd& values,
                                       const Eigen::MatrixXd& covariance) {
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(values.size());
  const auto solver = covariance.ldlt();
  const Eigen::VectorXd weights = solver.solve(ones);
  const double information = ones.dot(weights);
  const double mean = weights.dot(values) / information;
  const Eigen::VectorXd deviation = values - mean * ones;
  const double chi_square = deviation.dot(solver.solve(deviation));
  const double spread =
      values.size() > 1 ? chi_square / static_cast<double>(values.size() - 1) : 0.0;
  return {estimate(mean, 1.0 / information), spread};
}

/// What each bounce gives, from a motion built of the parameters: per bounce its instant, the
/// approach speed, e, the friction ratio, the slip before and after (along the slip before), the
/// spin change (3) and the spin after (3; 0 while the spin is unknown).
constexpr Eigen::Index kPerBounce = 12;
constexpr Eigen::Index kSpinChangeAt = 6;
constexpr Eigen::Index kSpinAfterAt = 9;

/// The recording with times counted from its first sample's (a stamp of 1.7e9 s, a ROS clock's,
/// has a resolution of 2e-7 s).
std::vector<TrackedSample> fromTheFirstSample(const std::vector<TrackedSample>& recorded) {
  std::vector<TrackedSample> samples = recorded;
  for (auto& sample : samples) sample.time -= recorded.front().time;
  return samples;
}

/// The bounces to fit and the samples they are fitted from.
struct BouncesToFit {
  std::vector<FoundBounce> found;
  std::size_t end = 0;  ///< the samples [0, end) are fitted
};

/// Stage 1: the bounces found (none is a problem), each with samples close enough on either side,
/// the first max_bounces of them, and where the last flight ends: at the next bounce found, else
/// where past its top it has fallen halfway back (a body settling afterwards is no flight).
RecordingResult<BouncesToFit> bouncesToFit(const std::vector<TrackedSample>& samples,
                                           const std::vector<TrackedSample>& recorded,
                                           const CalibrationOptions& options, double spacing) {
  BouncesToFit fit;
  fit.found = findBounces(samples, options);
  if (fit.found.empty()) {
    return problem(RecordingProblem::kNoBounce, "samples",
                   "no bounce off a plane: no reversal of the speed towards one from at least " +
                       number(options.min_bounce_speed) + " m/s (min_bounce_speed)");
  }
  for (std::size_t j = 0; j < fit.found.size(); ++j) {
    const std::size_t k = fit.found[j].sample;
    const double gap =
        std::max(samples[k].time - samples[k - 1].time, samples[k + 1].time - samples[k].time);
    if (gap > longestSpacing(options, spacing)) {
      return problem(RecordingProblem::kGapAcrossBounce, "bounce " + std::to_string(j + 1),
                     "near " + number(recorded[k].time) + " s the samples are " + number(gap) +
                         " s apart, more than " + number(options.max_gap_periods) +
                         " sample periods (" + number(spacing) + " s)");
    }
  }
  std::size_t used = fit.found.size();
  if (options.max_bounces > 0 && used > options.max_bounces) used = options.max_bounces;
  fit.end = samples.size();
  if (used < fit.found.size()) {
    fit.end = fit.found[used].sample - 1;
  } else {
    // A top is one well above the noise (a noisy sample just after the bounce is none).
    const Plane& plane = options.planes[fit.found[used - 1].plane];
    const double noise = noiseBeforeTheFit(samples, options.gravity);
    double top = -kInf;
    for (std::size_t k = fit.found[used - 1].sample + 1; k < samples.size(); ++k) {
      const double h = height(plane, options.radius, samples[k].position);
      top = std::max(top, h);
      if (top > 10.0 * noise && h < 0.5 * top && plane.normal.dot(options.gravity) < 0.0) {
        fit.end = k;
        break;
      }
    }
  }
  fit.found.resize(used);
  return fit;
}

/// Stage 2: the flights, [first, last] samples, between the samples found nearest each bounce
/// (which side of it that sample is on is left to the fit); each needs kMinFlightSamples.
using Flights = std::vector<std::pair<std::size_t, std::size_t>>;
RecordingResult<Flights> flightsBetween(const std::vector<FoundBounce>& found,
                                        std::size_t samples) {
  Flights flights;
  const std::size_t bounces = found.size();
  std::size_t first = 0;
  for (std::size_t j = 0; j <= bounces; ++j) {
    const std::size_t last = j < bounces ? found[j].sample - 1 : samples - 1;
    if (last < first || last - first + 1 < kMinFlightSamples) {
      return problem(RecordingProblem::kTooFewSamples, "flight " + std::to_string(j),
                     std::to_string(last >= first ? last - first + 1 : 0) + " samples between " +
                         (j == 0 ? "the start" : "bounce " + std::to_string(j)) + " and " +
                         (j < bounces ? "bounce " + std::to_string(j + 1) : "the end") +
                         "; a flight's fit needs " + std::to_string(kMinFlightSamples));
    }
    flights.emplace_back(first, last);
    if (j < bounces) first = found[j].sample + 1;
  }
  return flights;
}

/// Stage 3: where the fit starts: each flight's line with gravity taken out (its start for the
/// first, its velocity for the others), the given gravity and C_d.
Eigen::VectorXd startOfTheFit(const std::vector<TrackedSample>& samples, const Flights& flights,
                              const std::vector<FoundBounce>& found, const Layout& layout,
                              const CalibrationOptions& options) {
  Eigen::VectorXd start = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(layout.size()));
  {
    const auto [position, velocity] = lineThrough(samples, flights[0].first, flights[0].second,
                                                  samples.front().time, options.gravity);
    start.segment<3>(0) = position;
    start.segment<3>(3) = velocity;
  }
  for (std::size_t j = 0; j < found.size(); ++j) {
    const double bounce_time = samples[found[j].sample].time;
    const auto line = lineThrough(samples, flights[j + 1].first, flights[j + 1].second, bounce_time,
                                  options.gravity);
    start.segment<3>(static_cast<Eigen::Index>(6 + 3 * j)) = line.second;
  }
  if (layout.gravity)
    start.segment<3>(static_cast<Eigen::Index>(layout.gravityAt())) = options.gravity;
  if (layout.drag) start[static_cast<Eigen::Index>(layout.dragAt())] = options.drag_coefficient;
  if (layout.lift) start[static_cast<Eigen::Index>(layout.liftAt())] = options.lift_coefficient;
  return start;
}

/// The tracker's spin before each bounce: its mean over the flight before, where the samples
/// carry it.
std::vector<std::optional<Eigen::Vector3d>> trackedSpinBefore(
    const std::vector<TrackedSample>& samples, const Flights& flights, std::size_t bounces) {
  std::vector<std::optional<Eigen::Vector3d>> measured(bounces);
  for (std::size_t j = 0; j < bounces; ++j) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    for (std::size_t k = flights[j].first; k <= flights[j].second; ++k) {
      if (samples[k].angular_velocity) {
        sum += *samples[k].angular_velocity;
        ++count;
      }
    }
    if (count > 0) measured[j] = sum / count;
  }
  return measured;
}

/// Stage 5: what each bounce gives (kPerBounce values a bounce, and C_d last when fitted) as a
/// function of the parameters, so that the fit's covariance is carried to them by their gradient.
/// The spin before each bounce: the tracker's, else carried from spin_before through the earlier
/// bounces' friction impulses, else unknown.
class BounceQuantities {
 public:
  BounceQuantities(Motion& motion, const CalibrationOptions& options, const Layout& layout,
                   const std::vector<std::size_t>& planes,
                   std::vector<std::optional<Eigen::Vector3d>> measured_spin)
      : motion_(motion),
        options_(options),
        layout_(layout),
        planes_(planes),
        measured_spin_(std::move(measured_spin)),
        spin_factor_(spinFactor(1.0, options.radius, options.inertia)) {}

  bool operator()(const Eigen::VectorXd& p, Eigen::VectorXd& out) const {
    if (!motion_.build(p)) return false;
    const std::size_t bounces = layout_.bounces;
    out.resize(static_cast<Eigen::Index>(kPerBounce * bounces + (layout_.drag ? 1 : 0) +
                                         (layout_.lift ? 1 : 0)));
    // A flag beside a vector, not an optional: GCC takes the optional's vector for uninitialised.
    bool spin_known = options_.spin_before.has_value();
    Eigen::Vector3d spin = options_.spin_before.value_or(Eigen::Vector3d::Zero());
    for (std::size_t j = 0; j < bounces; ++j) {
      const Eigen::Vector3d& n = options_.planes[planes_[j]].normal;
      const Eigen::Vector3d before = motion_.velocityBefore(j);
      const Eigen::Vector3d after = motion_.pieces()[j + 1].velocity;
      const Eigen::Vector3d change = after - before;
      const Eigen::Vector3d tangential_change = change - change.dot(n) * n;
      if (measured_spin_[j]) {
        spin = *measured_spin_[j];
        spin_known = true;
      }
      const Eigen::Vector3d spin_change =
          spinChange(n, tangential_change, options_.radius, options_.inertia);
      double slip_before = 0.0;
      double slip_after = 0.0;
      if (spin_known) {
        // The contact point (at -r n from the centre) slips at u = v + w x (-r n), tangentially;
        // the tangential impulse changes u by (1 + 1/k) dv_t and w by spin_change: friction.h's
        // tangential inverse mass.
        const Eigen::Vector3d u = before + spin.cross(-options_.radius * n);
        const Eigen::Vector3d u_t = u - u.dot(n) * n;
        slip_before = u_t.norm();
        const Eigen::Vector3d u_after = u_t + (1.0 + spin_factor_) * tangential_change;
        slip_after = slip_before > 0.0 ? u_after.dot(u_t) / slip_before : u_after.norm();
        spin += spin_change;
      }
      const auto row = static_cast<Eigen::Index>(kPerBounce * j);
      out[row] = motion_.pieces()[j + 1].start;
      out[row + 1] = -before.dot(n);
      out[row + 2] = -after.dot(n) / before.dot(n);
      out[row + 3] = tangential_change.norm() / change.dot(n);
      out[row + 4] = slip_before;
      out[row + 5] = slip_after;
      out.segment<3>(row + kSpinChangeAt) = spin_change;
      out.segment<3>(row + kSpinAfterAt) = spin_known ? spin : Eigen::Vector3d::Zero();
    }
    Eigen::Index at = kPerBounce * static_cast<Eigen::Index>(bounces);
    if (layout_.drag) out[at++] = p[static_cast<Eigen::Index>(layout_.dragAt())];
    if (layout_.lift) out[at] = p[static_cast<Eigen::Index>(layout_.liftAt())];
    return out.allFinite();
  }

  /// Whether the spin before bounce j is known: given (spin_before), or tracked over the flight
  /// before it or an earlier one, and carried from there.
  bool spinKnown(std::size_t j) const {
    if (options_.spin_before) return true;
    for (std::size_t i = 0; i <= j; ++i) {
      if (measured_spin_[i]) return true;
    }
    return false;
  }

 private:
  Motion& motion_;
  const CalibrationOptions& options_;
  Layout layout_;
  std::vector<std::size_t> planes_;
  std::vector<std::optional<Eigen::Vector3d>> measured_spin_;
  double spin_factor_;
};

/// Standard errors the slip after must lie above 0 for a bounce to read kSliding. A stuck bounce
/// read as sliding gives a wrong mu (its ratio, below mu, joins the sliding bounces' mean and
/// pulls it down), where a sliding one read as stuck gives only a weaker, true, lower bound: the
/// test is one-sided at 4 (a stuck contact passes it 3e-5 of the time), not at the intervals'
/// 1.96 (2.5 %: Calibration.AStuckBounceIsNotReadAsSliding).
constexpr double kSlidingStandardErrors = 4.0;

/// How a bounce's friction reads, from its slip before and after (calibration.h).
FrictionReading frictionReading(bool spin_known, const Estimate& slip_before,
                                const Estimate& slip_after, const Estimate& approach_speed) {
  if (!spin_known) return FrictionReading::kSpinUnknown;
  if (slip_before.low() <= 0.0 || slip_before.value <= 1e-9 * (1.0 + approach_speed.value)) {
    // No slip, or one within the rounding of a track without noise (a vertical drop played).
    return FrictionReading::kNoSlip;
  }
  if (slip_after.value > kSlidingStandardErrors * slip_after.standard_error) {
    return FrictionReading::kSliding;
  }
  return FrictionReading::kStoppedSlipping;
}

/// The tracker's spin over a flight (samples [first, last]): each component's mean over the
/// samples that carry it, its standard error their scatter over sqrt(count); none with fewer
/// than 2 such samples.
std::optional<std::array<Estimate, 3>> trackedSpinOver(const std::vector<TrackedSample>& samples,
                                                       std::size_t first, std::size_t last) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (std::size_t k = first; k <= last; ++k) {
    if (!samples[k].angular_velocity) continue;
    sum += *samples[k].angular_velocity;
    ++count;
  }
  if (count < 2) return std::nullopt;
  const Eigen::Vector3d mean = sum / count;
  Eigen::Vector3d squares = Eigen::Vector3d::Zero();  // about the mean
  for (std::size_t k = first; k <= last; ++k) {
    if (samples[k].angular_velocity) squares += (*samples[k].angular_velocity - mean).cwiseAbs2();
  }
  std::array<Estimate, 3> spin;
  for (Eigen::Index i = 0; i < 3; ++i) {
    // The samples' variance over n - 1, over n again for the mean's.
    spin[static_cast<std::size_t>(i)] = estimate(mean[i], squares[i] / (count - 1) / count);
  }
  return spin;
}

/// Stage 6: bounce j's estimate from the quantities' values and covariance (its instant still
/// counted from the first sample), refused when the samples either side of the fitted instant
/// are too far apart or a flight either side has too few.
RecordingResult<BounceEstimate> bounceEstimate(
    std::size_t j, const Eigen::VectorXd& values, const Eigen::MatrixXd& covariance,
    const Motion& motion, std::size_t plane, bool spin_known,
    const Eigen::Vector3d& spin_source_error,
    const std::pair<std::size_t, std::size_t>& flight_after,
    const std::vector<TrackedSample>& samples, const CalibrationOptions& options, double spacing,
    double epoch) {
  const auto row = static_cast<Eigen::Index>(kPerBounce * j);
  const auto at = [&](Eigen::Index i) { return estimate(values[i], covariance(i, i)); };
  BounceEstimate bounce;
  bounce.plane = plane;
  bounce.time = at(row);
  bounce.point = motion.pieces()[j + 1].position;
  bounce.velocity_before = motion.velocityBefore(j);
  bounce.velocity_after = motion.pieces()[j + 1].velocity;
  bounce.approach_speed = at(row + 1);
  bounce.restitution = at(row + 2);
  bounce.friction_ratio = at(row + 3);
  bounce.slip_after = at(row + 5);
  bounce.friction =
      frictionReading(spin_known, at(row + 4), bounce.slip_after, bounce.approach_speed);
  std::array<Estimate, 3> spin_after;
  for (Eigen::Index i = 0; i < 3; ++i) {
    bounce.spin_change[static_cast<std::size_t>(i)] = at(row + kSpinChangeAt + i);
    spin_after[static_cast<std::size_t>(i)] = at(row + kSpinAfterAt + i);
  }
  if (spin_known) {
    // Beside the fit's, the variance of the tracked spin it starts from (independent of the
    // positions' noise; 0 for a given spin_before).
    for (std::size_t i = 0; i < 3; ++i) {
      const double se = spin_after[i].standard_error;
      const double source = spin_source_error[static_cast<Eigen::Index>(i)];
      spin_after[i].standard_error = std::sqrt(se * se + source * source);
    }
    bounce.spin_after = spin_after;
  }
  bounce.tracked_spin_after = trackedSpinOver(samples, flight_after.first, flight_after.second);
  for (const auto& sample : samples) {
    const std::size_t piece = motion.pieceAt(sample.time);
    if (piece == j) ++bounce.samples_before;
    if (piece == j + 1) ++bounce.samples_after;
  }
  // The samples either side of the fitted instant.
  double last_before = -kInf;
  double first_after = kInf;
  for (const auto& sample : samples) {
    if (sample.time <= bounce.time.value) last_before = std::max(last_before, sample.time);
    if (sample.time > bounce.time.value) first_after = std::min(first_after, sample.time);
  }
  if (!(first_after - last_before <= longestSpacing(options, spacing))) {
    return problem(RecordingProblem::kGapAcrossBounce, "bounce " + std::to_string(j + 1),
                   "at " + number(bounce.time.value + epoch) + " s the samples either side are " +
                       number(first_after - last_before) + " s apart, more than " +
                       number(options.max_gap_periods) + " sample periods (" + number(spacing) +
                       " s)");
  }
  if (bounce.samples_before < kMinFlightSamples || bounce.samples_after < kMinFlightSamples) {
    return problem(RecordingProblem::kTooFewSamples, "bounce " + std::to_string(j + 1),
                   "the fitted flights on either side have " +
                       std::to_string(bounce.samples_before) + " and " +
                       std::to_string(bounce.samples_after) + " samples; each needs " +
                       std::to_string(kMinFlightSamples));
  }
  return bounce;
}

/// Stage 7: the joint covariance of the bounces' e and of their friction ratios (for combine()),
/// and the bounces together, all and each plane's.
void summarise(Calibration& result, const Eigen::MatrixXd& covariance, std::size_t planes) {
  const std::size_t bounces = result.bounces.size();
  result.restitution_covariance.resize(static_cast<Eigen::Index>(bounces),
                                       static_cast<Eigen::Index>(bounces));
  result.friction_ratio_covariance.resizeLike(result.restitution_covariance);
  for (std::size_t a = 0; a < bounces; ++a) {
    for (std::size_t b = 0; b < bounces; ++b) {
      const auto row = static_cast<Eigen::Index>(kPerBounce * a);
      const auto column = static_cast<Eigen::Index>(kPerBounce * b);
      result.restitution_covariance(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) =
          covariance(row + 2, column + 2);
      result.friction_ratio_covariance(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) =
          covariance(row + 3, column + 3);
    }
  }
  std::vector<std::size_t> every(bounces);
  for (std::size_t j = 0; j < bounces; ++j) every[j] = j;
  result.all = combine(result, every);
  for (std::size_t i = 0; i < planes; ++i) {
    std::vector<std::size_t> on_plane;
    for (std::size_t j = 0; j < bounces; ++j) {
      if (result.bounces[j].plane == i) on_plane.push_back(j);
    }
    result.per_plane.push_back(combine(result, on_plane));
  }
}

/// What the fit says of the motion as a whole: the noise, the parameters, gravity and C_d.
Calibration fittedMotion(const Fit& fit, const Layout& layout, const CalibrationOptions& options,
                         const Eigen::VectorXd& values, const Eigen::MatrixXd& covariance) {
  Calibration result;
  result.noise = fit.noise;
  result.parameters = layout.size();
  result.iterations = fit.iterations;
  result.fitted_parameters.assign(fit.parameters.data(),
                                  fit.parameters.data() + fit.parameters.size());
  for (int i = 0; i < 3; ++i) {
    if (layout.gravity) {
      const auto at = static_cast<Eigen::Index>(layout.gravityAt()) + i;
      result.gravity[i] = estimate(fit.parameters[at], fit.covariance(at, at));
    } else {
      result.gravity[i] = Estimate{options.gravity[i], 0.0};
    }
  }
  Eigen::Index at = kPerBounce * static_cast<Eigen::Index>(layout.bounces);
  if (layout.drag) {
    result.drag_coefficient = estimate(values[at], covariance(at, at));
    ++at;
  }
  if (layout.lift) result.lift_coefficient = estimate(values[at], covariance(at, at));
  return result;
}

/// The fit (calibration.h): the recording checked, its bounces found (stage 1, with_bounces), the
/// flights between them (2), the fit's start (3), the least-squares fit (4), what each bounce
/// gives with its covariance (5), each bounce's estimate (6), the bounces together (7).
RecordingResult<Calibration> run(const std::vector<TrackedSample>& recorded,
                                 const CalibrationOptions& options, bool with_bounces) {
  if (auto error = checkSamples(recorded)) return *error;
  if (auto error = checkOptions(options, with_bounces)) return *error;
  const double epoch = recorded.front().time;
  std::vector<TrackedSample> samples = fromTheFirstSample(recorded);
  const double spacing = medianSpacing(samples);
  std::vector<FoundBounce> found;
  if (with_bounces) {
    auto to_fit = bouncesToFit(samples, recorded, options, spacing);
    if (!to_fit) return to_fit.error();
    found = to_fit->found;
    samples.resize(to_fit->end);
  }
  const std::size_t bounces = found.size();
  const auto flights = flightsBetween(found, samples.size());
  if (!flights) return flights.error();

  const Layout layout = layoutOf(bounces, options);
  std::vector<std::size_t> planes;
  for (const auto& bounce : found) planes.push_back(bounce.plane);
  const double origin = samples.front().time;
  Motion motion(options, layout, planes, origin, samples.back().time + 1.0);
  const auto fit =
      leastSquares(motion, samples, startOfTheFit(samples, *flights, found, layout, options));
  if (!fit) {
    return problem(RecordingProblem::kFitFailed, "samples",
                   "the flights could not be fitted (a flight that does not meet its bounce's "
                   "plane, a motion past the doubles, or no settling in " +
                       std::to_string(kMaxIterations) + " iterations)");
  }

  const auto tracked_spin = trackedSpinBefore(samples, *flights, bounces);
  const BounceQuantities quantities(motion, options, layout, planes, tracked_spin);
  Eigen::VectorXd values;
  Eigen::MatrixXd gradient;
  if (!quantities(fit->parameters, values) ||
      !jacobian(quantities, fit->parameters, values.size(), gradient)) {
    return problem(RecordingProblem::kFitFailed, "samples",
                   "the fitted flights give no coefficients (a bounce without an approach)");
  }
  const Eigen::MatrixXd covariance = gradient * fit->covariance * gradient.transpose();
  motion.build(fit->parameters);

  Calibration result = fittedMotion(*fit, layout, options, values, covariance);
  result.samples_used = samples.size();
  result.start_time = origin + epoch;
  result.end_time = samples.back().time + epoch;
  // The standard error of the tracked spin each bounce's spin after starts from (the mean over
  // the latest flight before it that carries one; 0 from spin_before or a single sample).
  Eigen::Vector3d spin_source_error = Eigen::Vector3d::Zero();
  for (std::size_t j = 0; j < bounces; ++j) {
    if (tracked_spin[j]) {
      const auto spread = trackedSpinOver(samples, (*flights)[j].first, (*flights)[j].second);
      for (std::size_t i = 0; i < 3; ++i) {
        spin_source_error[static_cast<Eigen::Index>(i)] =
            spread ? (*spread)[i].standard_error : 0.0;
      }
    }
    auto bounce =
        bounceEstimate(j, values, covariance, motion, planes[j], quantities.spinKnown(j),
                       spin_source_error, (*flights)[j + 1], samples, options, spacing, epoch);
    if (!bounce) return bounce.error();
    result.bounces.push_back(*bounce);
    result.bounces.back().time.value += epoch;
  }
  summarise(result, covariance, options.planes.size());
  return result;
}

}  // namespace

const char* toString(FrictionReading reading) {
  switch (reading) {
    case FrictionReading::kSliding:
      return "sliding";
    case FrictionReading::kStoppedSlipping:
      return "stopped slipping";
    case FrictionReading::kSpinUnknown:
      return "spin unknown";
    case FrictionReading::kNoSlip:
      return "no slip";
  }
  return "?";
}

const char* toString(RecordingProblem problem) {
  switch (problem) {
    case RecordingProblem::kTooFewSamples:
      return "too few samples";
    case RecordingProblem::kStampsGoBack:
      return "stamps going back";
    case RecordingProblem::kBadValue:
      return "bad value";
    case RecordingProblem::kNoBounce:
      return "no bounce";
    case RecordingProblem::kGapAcrossBounce:
      return "gap across the bounce";
    case RecordingProblem::kFitFailed:
      return "fit failed";
  }
  return "?";
}

std::string RecordingError::message() const {
  return std::string(toString(problem)) + ": " + field + ": " + reason;
}

Coefficients combine(const Calibration& calibration, const std::vector<std::size_t>& which) {
  Coefficients summary;
  summary.bounces = which.size();
  if (which.empty()) return summary;
  const auto pick = [&](const std::vector<std::size_t>& at, const Eigen::MatrixXd& covariance,
                        bool restitution, Eigen::VectorXd& v, Eigen::MatrixXd& c) {
    const auto m = static_cast<Eigen::Index>(at.size());
    v.resize(m);
    c.resize(m, m);
    for (Eigen::Index a = 0; a < m; ++a) {
      const auto& bounce = calibration.bounces[at[static_cast<std::size_t>(a)]];
      v[a] = restitution ? bounce.restitution.value : bounce.friction_ratio.value;
      for (Eigen::Index b = 0; b < m; ++b) {
        c(a, b) = covariance(static_cast<Eigen::Index>(at[static_cast<std::size_t>(a)]),
                             static_cast<Eigen::Index>(at[static_cast<std::size_t>(b)]));
      }
    }
  };
  Eigen::VectorXd v;
  Eigen::MatrixXd c;
  pick(which, calibration.restitution_covariance, true, v, c);
  std::tie(summary.restitution, summary.restitution_spread) = commonMean(v, c);
  summary.slowest_approach = kInf;
  summary.fastest_approach = 0.0;
  std::vector<std::size_t> sliding;
  for (const std::size_t j : which) {
    const auto& bounce = calibration.bounces[j];
    summary.slowest_approach = std::min(summary.slowest_approach, bounce.approach_speed.value);
    summary.fastest_approach = std::max(summary.fastest_approach, bounce.approach_speed.value);
    if (bounce.friction == FrictionReading::kSliding) {
      sliding.push_back(j);
    } else if (bounce.friction != FrictionReading::kNoSlip) {
      const double bound = std::max(0.0, bounce.friction_ratio.low());
      summary.friction_lower_bound = std::max(summary.friction_lower_bound.value_or(0.0), bound);
    }
  }
  if (!sliding.empty()) {
    pick(sliding, calibration.friction_ratio_covariance, false, v, c);
    summary.friction = commonMean(v, c).first;
  }
  return summary;
}

RecordingResult<Calibration> calibrate(const std::vector<TrackedSample>& samples,
                                       const CalibrationOptions& options) {
  return run(samples, options, true);
}

RecordingResult<Calibration> fitFlight(const std::vector<TrackedSample>& samples,
                                       const CalibrationOptions& options) {
  return run(samples, options, false);
}

Expected<SceneCalibration> sceneCalibration(const Scene& scene) {
  SceneCalibration reading;
  CalibrationOptions& options = reading.options;
  options.gravity = scene.effects.gravity ? scene.gravity : Eigen::Vector3d::Zero();
  options.drag = scene.effects.drag;
  options.magnus = scene.effects.magnus;
  options.air_density = scene.air_density;
  for (const ObstacleSpec& obstacle : scene.obstacles) {
    if (obstacle.shape != ObstacleShape::kPlane || !obstacle.frame.empty()) continue;
    options.planes.push_back(Plane{obstacle.normal, obstacle.offset});
    reading.plane_ids.push_back(obstacle.id);
    reading.plane_materials.push_back(obstacle.material);
  }
  if (options.planes.empty()) {
    return Error{"obstacles",
                 "the scene has no fixed plane obstacle to bounce off (only planes are fitted "
                 "yet)"};
  }
  return reading;
}

BodyCalibration bodyCalibration(const BodySpec& body) {
  return BodyCalibration{body.radius, body.inertia, body.mass, body.drag_coefficient,
                         body.lift_coefficient};
}

CalibrationOptions forBody(CalibrationOptions options, const BodyCalibration& body) {
  options.radius = body.radius;
  options.inertia = body.inertia;
  options.mass = body.mass;
  options.drag_coefficient = body.drag_coefficient;
  options.lift_coefficient = body.lift_coefficient;
  return options;
}

Eigen::Vector3d fittedPosition(const Calibration& calibration, const CalibrationOptions& options,
                               double time) {
  const Layout layout = layoutOf(calibration.bounces.size(), options);
  std::vector<std::size_t> planes;
  for (const auto& bounce : calibration.bounces) planes.push_back(bounce.plane);
  // The fit's times are from its first sample's (run()).
  Motion motion(options, layout, planes, 0.0, calibration.end_time - calibration.start_time + 1.0);
  const Eigen::VectorXd parameters = Eigen::Map<const Eigen::VectorXd>(
      calibration.fitted_parameters.data(),
      static_cast<Eigen::Index>(calibration.fitted_parameters.size()));
  if (!motion.build(parameters)) return Eigen::Vector3d::Constant(std::nan(""));
  return motion.positionAt(time - calibration.start_time);
}

}  // namespace collision_response::core
