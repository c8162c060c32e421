#include "geometry/free_rotation.h"

#include <algorithm>
#include <array>
#include <boost/math/special_functions/ellint_rf.hpp>
#include <boost/math/special_functions/ellint_rj.hpp>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <string>

#include "collision_response/core/validation.h"

namespace collision_response::core {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxAgmSteps = 40;
// Carlson's R_F and R_J in double precision (Boost otherwise carries doubles as long doubles, at
// several times the cost); their error stays a few ulps (Carlson 1995, the duplication's bound).
using InDouble = boost::math::policies::policy<boost::math::policies::promote_double<false>>;

const char* axisName(int i) { return i == 0 ? "x" : (i == 1 ? "y" : "z"); }

/// The rotation by `angle` about the unit `axis`.
Eigen::Quaterniond turn(const Eigen::Vector3d& axis, double angle) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis));
}

/// The least rotation taking e_3 to the unit l, l_3 > -1: (1 + l_3, e_3 x l) normalised.
Eigen::Quaterniond leastRotationFromZ(const Eigen::Vector3d& l) {
  Eigen::Quaterniond q(1.0 + l.z(), -l.y(), l.x(), 0.0);
  q.normalize();
  return q;
}

double sign(double x) { return x < 0.0 ? -1.0 : 1.0; }

/// A number to 17 significant digits (it reads back as the same double).
std::string exact(double x) {
  std::ostringstream text;
  text << std::setprecision(17) << x;
  return text.str();
}

/// FreeRotation::create's bad input, by name: moments finite and > 0 meeting the triangle
/// inequality, an orientation checkOrientation takes, a finite angular velocity.
Status checkRotationInput(const Eigen::Vector3d& principal_moments,
                          const Eigen::Quaterniond& orientation,
                          const Eigen::Vector3d& angular_velocity) {
  for (int i = 0; i < 3; ++i) {
    const double j = principal_moments[i];
    if (!std::isfinite(j) || j <= 0.0) {
      return Error{std::string("principal_moments.") + axisName(i),
                   "must be finite and > 0, got " + exact(j)};
    }
    if (!std::isfinite(angular_velocity[i])) {
      return Error{std::string("angular_velocity.") + axisName(i),
                   "must be finite, got " + exact(angular_velocity[i])};
    }
  }
  // The triangle inequality J_i <= J_j + J_k, to checkInertiaTensor's rounding (16 eps of the
  // sum): a flat body meets it with equality.
  const double sum = principal_moments.sum();
  for (int i = 0; i < 3; ++i) {
    const double others = principal_moments[(i + 1) % 3] + principal_moments[(i + 2) % 3];
    if (principal_moments[i] > others + 16.0 * std::numeric_limits<double>::epsilon() * sum) {
      return Error{std::string("principal_moments.") + axisName(i),
                   "breaks the triangle inequality: " + exact(principal_moments[i]) + " > " +
                       exact(others) + ", the sum of the other two"};
    }
  }
  return checkOrientation(orientation, "orientation");
}

/// The body axes in the ascending order of their moments: lo, mid, hi.
std::array<int, 3> ascendingAxes(const Eigen::Vector3d& moments) {
  std::array<int, 3> order{0, 1, 2};
  std::sort(order.begin(), order.end(), [&](int x, int y) { return moments[x] < moments[y]; });
  return order;
}

}  // namespace

JacobiElliptic jacobiElliptic(double u, double m, double m1) {
  // Abramowitz and Stegun 16.4: a_0 = 1, b_0 = sqrt(m1), c_0 = sqrt(m); a_n, b_n, c_n the
  // arithmetic and geometric means and half the difference, to c_N = 0; phi_N = 2^N a_N u and
  // sin(2 phi_{n-1} - phi_n) = (c_n / a_n) sin phi_n; sn = sin phi_0, cn = cos phi_0.
  std::array<double, kMaxAgmSteps + 1> a{};
  std::array<double, kMaxAgmSteps + 1> c{};
  a[0] = 1.0;
  double b = std::sqrt(m1);
  c[0] = std::sqrt(m);
  int n = 0;
  while (n < kMaxAgmSteps &&
         c[static_cast<std::size_t>(n)] >
             std::numeric_limits<double>::epsilon() * a[static_cast<std::size_t>(n)]) {
    const auto i = static_cast<std::size_t>(n);
    a[i + 1] = 0.5 * (a[i] + b);
    c[i + 1] = 0.5 * (a[i] - b);
    b = std::sqrt(a[i] * b);
    ++n;
  }
  const double quarter = kPi / (2.0 * a[static_cast<std::size_t>(n)]);  // K(m)
  const double reduced = u - 4.0 * quarter * std::nearbyint(u / (4.0 * quarter));
  double phi = std::ldexp(a[static_cast<std::size_t>(n)] * reduced, n);
  for (int k = n; k >= 1; --k) {
    const auto i = static_cast<std::size_t>(k);
    phi = 0.5 * (phi + std::asin(c[i] / a[i] * std::sin(phi)));
  }
  const double cn = std::cos(phi);
  return {std::sin(phi), cn, std::sqrt(m1 + m * cn * cn)};
}

double completeEllipticK(double m1) { return boost::math::ellint_rf(0.0, m1, 1.0); }

double ellipticF(double sine, double cosine, double m1) {
  if (sine < 0.0) return -ellipticF(-sine, cosine, m1);
  const double c2 = cosine * cosine;
  const double first = sine * boost::math::ellint_rf(c2, c2 + m1 * sine * sine, 1.0);
  return cosine < 0.0 ? 2.0 * completeEllipticK(m1) - first : first;
}

Expected<FreeRotation> FreeRotation::create(const Eigen::Vector3d& principal_moments,
                                            const Eigen::Quaterniond& orientation,
                                            const Eigen::Vector3d& angular_velocity) {
  const Status input_ok = checkRotationInput(principal_moments, orientation, angular_velocity);
  if (!input_ok) return input_ok.error();
  FreeRotation r;
  r.orientation0_ = orientation.normalized();
  r.omega0_world_ = angular_velocity;
  const Eigen::Matrix3d rotation0 = r.orientation0_.toRotationMatrix();
  const Eigen::Vector3d w = rotation0.transpose() * angular_velocity;
  r.omega0_body_ = w;
  const Eigen::Vector3d& j = principal_moments;
  r.momentum_world_ = rotation0 * j.cwiseProduct(w);
  if (!r.momentum_world_.allFinite()) {
    return Error{"angular_velocity",
                 "its angular momentum about the principal moments is beyond the doubles"};
  }
  if (w.isZero(0.0)) {
    r.kind_ = Kind::kResting;
    return r;
  }
  r.momentum_axis_ = r.momentum_world_.stableNormalized();
  const std::array<int, 3> order = ascendingAxes(j);
  const int lo = order[0], mid = order[1], hi = order[2];
  const bool low_pair = j[lo] == j[mid];
  const bool high_pair = j[mid] == j[hi];
  if (low_pair && high_pair) {
    r.kind_ = Kind::kIsotropic;
  } else if (low_pair || high_pair) {
    r.startAxisymmetric(j, low_pair ? hi : lo, mid);
  } else if ((w.array() != 0.0).count() == 1) {
    r.kind_ = Kind::kIsotropic;  // a steady turn about a principal axis
  } else {
    r.startAsymmetric(j, order);
  }
  return r;
}

void FreeRotation::startAxisymmetric(const Eigen::Vector3d& moments, int symmetry, int transverse) {
  kind_ = Kind::kAxisymmetric;
  const double js = moments[symmetry];
  const double jt = moments[transverse];
  symmetry_axis_ = Eigen::Vector3d::Unit(symmetry);
  body_rate_ = (js - jt) / jt * omega0_body_[symmetry];
  precession_rate_ = momentum_world_.stableNorm() / jt;
}

void FreeRotation::startAsymmetric(const Eigen::Vector3d& moments,
                                   const std::array<int, 3>& ascending) {
  // The asymmetric body's parameters are homogeneous in w (the amplitudes and the rates of
  // degree 1, the rest of degree 0): computed for w scaled by a power of two to |w|_max in
  // [1, 2), exactly, so that no square underflows or overflows, and scaled back.
  const int exponent = std::ilogb(omega0_body_.cwiseAbs().maxCoeff());
  const Eigen::Vector3d ws =
      omega0_body_.unaryExpr([&](double x) { return std::ldexp(x, -exponent); });
  setWorkingFrame(moments, ws, ascending);
  const Eigen::Vector3d ww = working_ * ws;
  const WorkingStart start = setEllipticMotion(ww, exponent);
  setPhase(start.phase);
  frame0_ = orientation0_ * Eigen::Quaterniond(working_.transpose()) *
            leastRotationFromZ(start.momentum_direction);
}

void FreeRotation::setWorkingFrame(const Eigen::Vector3d& moments, const Eigen::Vector3d& ws,
                                   const std::array<int, 3>& ascending) {
  const Eigen::Vector3d& j = moments;
  const int lo = ascending[0], mid = ascending[1], hi = ascending[2];
  // M^2 - 2 E J_mid, written so that nothing cancels but the separatrix's own difference.
  const double separation =
      j[lo] * (j[lo] - j[mid]) * ws[lo] * ws[lo] + j[hi] * (j[hi] - j[mid]) * ws[hi] * ws[hi];
  // The working frame: axis 3 the one the polhode goes round, axis 2 the middle one.
  const std::array<int, 3> p =
      separation < 0.0 ? std::array<int, 3>{hi, mid, lo} : std::array<int, 3>{lo, mid, hi};
  kind_ = separation == 0.0 ? Kind::kSeparatrix : Kind::kAsymmetric;
  const double s3 = sign(omega0_body_[p[2]]);
  const double s1 = kind_ == Kind::kSeparatrix ? sign(omega0_body_[p[0]]) : 1.0;
  Eigen::Matrix3d frame = Eigen::Matrix3d::Zero();
  frame(0, p[0]) = s1;
  frame(2, p[2]) = s3;
  frame(1, p[1]) = 1.0;
  if (frame.determinant() < 0.0) frame(1, p[1]) = -1.0;
  working_ = frame;
  moments_ = Eigen::Vector3d(j[p[0]], j[p[1]], j[p[2]]);
}

FreeRotation::WorkingStart FreeRotation::setEllipticMotion(const Eigen::Vector3d& ww,
                                                           int exponent) {
  const Eigen::Vector3d& jw = moments_;
  const double w1 = ww.x(), w2 = ww.y(), w3 = ww.z();
  const double j1 = jw.x(), j2 = jw.y(), j3 = jw.z();
  // 2 E J_3 - M^2, M^2 - 2 E J_1, M^2 - 2 E J_2 (signed: in the frame of the smallest axis
  // the first two are negative and their ratios as in Landau's).
  const double top = j1 * (j3 - j1) * w1 * w1 + j2 * (j3 - j2) * w2 * w2;
  const double bottom = j2 * (j2 - j1) * w2 * w2 + j3 * (j3 - j1) * w3 * w3;
  const double middle = j1 * (j1 - j2) * w1 * w1 + j3 * (j3 - j2) * w3 * w3;
  const double m2 = ww.cwiseProduct(jw).squaredNorm();
  const double momentum = std::sqrt(m2);
  const double two_energy = ww.dot(jw.cwiseProduct(ww));
  amplitude_ = Eigen::Vector3d(std::sqrt(w1 * w1 + j2 * (j3 - j2) / (j1 * (j3 - j1)) * w2 * w2),
                               std::sqrt(j1 * (j3 - j1) / (j2 * (j3 - j2)) * w1 * w1 + w2 * w2),
                               std::sqrt(j2 * (j2 - j1) / (j3 * (j3 - j1)) * w2 * w2 + w3 * w3));
  rate_ = sign(j3 - j2) * std::sqrt((j3 - j2) * bottom / (j1 * j2 * j3));
  m_ = (j2 - j1) * top / ((j3 - j2) * bottom);
  m1_ = (j3 - j1) * middle / ((j3 - j2) * bottom);
  WorkingStart start;
  // sn u0 and cn u0: (w_2 / A_2, w_1 / A_1), scaled alike (A_1 / A_2 is sqrt(J_2 |J_3 - J_2|) /
  // sqrt(J_1 |J_3 - J_1|)) and made a unit vector; no angle in between, whose rounding near
  // pi / 2 the near-separatrix F would magnify.
  start.phase = Eigen::Vector2d(w2 * std::sqrt(j2 * std::abs(j3 - j2)),
                                w1 * std::sqrt(j1 * std::abs(j3 - j1)))
                    .normalized();
  start.momentum_direction = jw.cwiseProduct(ww) / momentum;
  a_ = j3 * amplitude_.z() / momentum;
  // 1 - a^2 = (J_1 A_1 / M)^2 (at sn u = 0, w = (A_1, 0, A_3)), without cancelling as a -> 1;
  // the angle's factor J_1 J_2 A_1 A_2 / M^2 over it, J_2 A_2 / (J_1 A_1), stays bounded there.
  const double lever = j1 * amplitude_.x() / momentum;
  one_minus_a2_ = lever * lever;
  psi_factor_ = j2 * amplitude_.y() / (j1 * amplitude_.x());
  energy_rate_ = std::ldexp(two_energy / momentum, exponent);
  amplitude_ = amplitude_.unaryExpr([&](double x) { return std::ldexp(x, exponent); });
  rate_ = std::ldexp(rate_, exponent);
  return start;
}

void FreeRotation::setPhase(const Eigen::Vector2d& phase) {
  if (kind_ == Kind::kSeparatrix) {
    m_ = 1.0;
    m1_ = 0.0;
    u0_ = std::asinh(phase.x() / phase.y());  // F(phi | 1) = asinh(tan phi); cn u0 > 0
    quarter_period_ = std::numeric_limits<double>::infinity();
    start_integral_ = angleIntegral(u0_, {});
    return;
  }
  u0_ = ellipticF(phase.x(), phase.y(), m1_);
  quarter_period_ = completeEllipticK(m1_);
  // The third kind's characteristic n = -a^2 m / (1 - a^2), sqrt(1 - n) and a m / (3 (1 - a^2)).
  const double ratio = m_ / one_minus_a2_;
  characteristic_ = -a_ * a_ * ratio;
  root_ = std::sqrt(1.0 + a_ * a_ * ratio);
  rj_factor_ = a_ * ratio / 3.0;
  // Over a half period (phi from -pi / 2 to pi / 2): T = pi / sqrt(1 - n), F = 2 K and the third
  // kind's complete R_J(0, m1, 1, 1 - n) (DLMF 19.25.2).
  period_integral_ =
      2.0 * ((0.5 * kPi / root_ - a_ * quarter_period_) +
             rj_factor_ * boost::math::ellint_rj(0.0, m1_, 1.0, 1.0 - characteristic_));
  start_integral_ = angleIntegral(u0_, jacobiElliptic(u0_, m_, m1_));
}

double FreeRotation::angleIntegral(double u, const JacobiElliptic& f) const {
  if (kind_ == Kind::kSeparatrix) {
    // integral_0^u sech / (1 + a sech) = integral_0^u 1 / (cosh s + a) ds
    // = 2 / sqrt(1 - a^2) atan(sqrt((1 - a) / (1 + a)) tanh(u / 2)), 0 <= a < 1 (with
    // tau = tanh(s / 2): cosh s + a = ((1 + a) + (1 - a) tau^2) / (1 - tau^2), ds = 2 dtau /
    // (1 - tau^2)); times 1 - a^2, sqrt((1 - a) / (1 + a)) = sqrt(1 - a^2) / (1 + a).
    const double root = std::sqrt(one_minus_a2_);
    return 2.0 * root * std::atan(root / (1.0 + a_) * std::tanh(0.5 * u));
  }
  // u = 2 K j + v, |v| <= K: G is odd and G(u + 2 K) = G(u) + G(2 K) (dn is even, of period
  // 2 K). sn v = (-1)^j sn u, cn v = |cn u| >= 0 (either sign of cn's rounding at v = +-K).
  const double half_periods = std::nearbyint(u / (2.0 * quarter_period_));
  const double flip = std::fmod(half_periods, 2.0) == 0.0 ? 1.0 : -1.0;
  const double whole = half_periods == 0.0 ? 0.0 : half_periods * period_integral_;
  return whole + angleIntegralWithin(flip * f.sn, std::abs(f.cn));
}

double FreeRotation::angleIntegralWithin(double sine, double cosine) const {
  // With phi = am v: G = integral_0^phi dtheta / (1 + a Delta), Delta^2 = 1 - m sin^2 theta = dn^2.
  // 1 / (1 + a Delta) = (1 - a Delta) / ((1 - a^2) (1 - n sin^2 theta)), and Delta / (1 - n
  // sin^2) = ((m / n) (1 - n sin^2) + 1 - m / n) / (Delta (1 - n sin^2)): (1 - a^2) G = (T - a F)
  // + a m / (3 (1 - a^2)) sin^3 phi R_J(cos^2, Delta^2, 1, 1 - n sin^2), T = atan(sqrt(1 - n)
  // tan phi) / sqrt(1 - n) (elementary), F = sin phi R_F(cos^2, Delta^2, 1) and Pi(n; phi | m) =
  // F + (n / 3) sin^3 phi R_J(...) (Carlson, DLMF 19.25.5 and 19.25.14).
  const double c2 = cosine * cosine;
  const double d2 = m1_ + m_ * c2;
  const double t = std::atan2(root_ * sine, cosine) / root_;
  const double f = sine * boost::math::ellint_rf(c2, d2, 1.0, InDouble());
  if (sine == 0.0) return t - a_ * f;
  const double s2 = sine * sine;
  return (t - a_ * f) +
         rj_factor_ * sine * s2 *
             boost::math::ellint_rj(c2, d2, 1.0, 1.0 - characteristic_ * s2, InDouble());
}

Eigen::Vector3d FreeRotation::workingAngularVelocity(double u, const JacobiElliptic& f) const {
  if (kind_ == Kind::kSeparatrix) {
    const double sech = 1.0 / std::cosh(u);
    return amplitude_.cwiseProduct(Eigen::Vector3d(sech, std::tanh(u), sech));
  }
  return amplitude_.cwiseProduct(Eigen::Vector3d(f.cn, f.sn, f.dn));
}

Eigen::Vector3d FreeRotation::bodyAngularVelocity(double time) const {
  switch (kind_) {
    case Kind::kResting:
    case Kind::kIsotropic:
      return omega0_body_;
    case Kind::kAxisymmetric:
      return turn(symmetry_axis_, body_rate_ * time) * omega0_body_;
    case Kind::kAsymmetric:
    case Kind::kSeparatrix:
      break;
  }
  const double u = rate_ * time + u0_;
  const JacobiElliptic f =
      kind_ == Kind::kSeparatrix ? JacobiElliptic{} : jacobiElliptic(u, m_, m1_);
  return working_.transpose() * workingAngularVelocity(u, f);
}

Eigen::Vector3d FreeRotation::angularVelocity(double time) const {
  if (kind_ == Kind::kResting || kind_ == Kind::kIsotropic) return omega0_world_;
  return orientation(time) * bodyAngularVelocity(time);
}

double FreeRotation::psi(double time, const JacobiElliptic& f) const {
  return energy_rate_ * time -
         psi_factor_ * (angleIntegral(rate_ * time + u0_, f) - start_integral_);
}

Eigen::Quaterniond FreeRotation::orientation(double time) const {
  switch (kind_) {
    case Kind::kResting:
      return orientation0_;
    case Kind::kIsotropic: {
      const double speed = omega0_world_.stableNorm();
      return turn(omega0_world_.stableNormalized(), speed * time) * orientation0_;
    }
    case Kind::kAxisymmetric: {
      return turn(momentum_axis_, precession_rate_ * time) * orientation0_ *
             turn(symmetry_axis_, -body_rate_ * time);
    }
    case Kind::kAsymmetric:
    case Kind::kSeparatrix:
      break;
  }
  const double u = rate_ * time + u0_;
  const JacobiElliptic f =
      kind_ == Kind::kSeparatrix ? JacobiElliptic{} : jacobiElliptic(u, m_, m1_);
  const Eigen::Vector3d l = moments_.cwiseProduct(workingAngularVelocity(u, f)).stableNormalized();
  const Eigen::Quaterniond working =
      turn(momentum_axis_, psi(time, f)) * frame0_ * leastRotationFromZ(l).conjugate();
  return (working * Eigen::Quaterniond(working_)).normalized();
}

double FreeRotation::period() const {
  switch (kind_) {
    case Kind::kAxisymmetric:
      return body_rate_ == 0.0 ? std::numeric_limits<double>::infinity()
                               : 2.0 * kPi / std::abs(body_rate_);
    case Kind::kAsymmetric:
      return 4.0 * quarter_period_ / std::abs(rate_);
    default:
      return std::numeric_limits<double>::infinity();
  }
}

}  // namespace collision_response::core
