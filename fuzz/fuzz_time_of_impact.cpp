// libFuzzer target: the time of impact, straight (double and float), ballistic against a plane,
// and accelerated spheres, with any finite inputs. Invariants:
//  - a time found is finite and in [0, horizon], the bodies touch there (the gap within 1e-9 of
//    the sizes involved, plus the distance covered in two ulps of the time: the exact instant
//    may not be a double, below the smallest subnormal say) and approach;
//  - no time found although the spheres come clearly inside each other within the horizon (at
//    their closest, at 1 - 1e-6 of the contact distance) is a miss: a bug;
//  - against a box, cylinder or capsule (firstContactFinite): a time found is in [0, horizon]
//    with the ball touching the shape there (its distance by the shape's own formula, in long
//    double); no time found while one of 64 instants along the motion is clearly inside the
//    shape (1e-6 of the sizes), from a start clearly outside, is a miss.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "collision_response/core/time_of_impact.h"
#include "fuzz_input.h"
#include "geometry/finite_shapes.h"

using namespace collision_response;
using V = Eigen::Vector3d;

namespace {

void fail(const char* what) {
  std::fprintf(stderr, "invariant broken: %s\n", what);
  std::abort();
}

template <typename Scalar>
void checkStraight(const Eigen::Matrix<Scalar, 3, 1>& s, const Eigen::Matrix<Scalar, 3, 1>& v,
                   Scalar radius, Scalar horizon, double tolerance) {
  const auto t = core::timeOfImpactSpheres<Scalar>(s, v, radius, horizon);
  // Checked in long double.
  using L = Eigen::Matrix<long double, 3, 1>;
  const L sl = s.template cast<long double>(), vl = v.template cast<long double>();
  const long double r = radius;
  const long double scale = sl.norm() + vl.norm() * horizon + r;
  if (t) {
    if (!std::isfinite(*t) || *t < 0 || *t > horizon) fail("time outside [0, horizon]");
    const L at = sl + vl * static_cast<long double>(*t);
    const long double time_ulp = std::nextafter(*t, std::numeric_limits<Scalar>::infinity()) - *t;
    const long double resolution = tolerance * scale + 2 * vl.norm() * time_ulp;
    if (std::abs(at.norm() - r) > resolution) fail("no contact at the time found");
    // The direction at contact means something only where the contact is resolved at all.
    // (A tangent touch, the discriminant zero, has the velocity across the line: dot ~ 0.)
    // A graze is ill-conditioned: a gap known to a relative rounding u (the |s| - R of the
    // code, and the positions themselves) puts the contact's direction off the tangent by up
    // to sqrt(2 u), so the direction is checked to that too.
    const long double direction_tolerance =
        std::max<long double>(tolerance, 4 * std::sqrt(std::numeric_limits<Scalar>::epsilon()));
    if (r > 4 * resolution && !(at.dot(vl) < direction_tolerance * at.norm() * vl.norm())) {
      fail("not approaching at the time found");
    }
    return;
  }
  if (sl.norm() < r || !(sl.dot(vl) < 0)) return;  // overlapping, or not closing: none is right
  const long double closest_time = std::min<long double>(-sl.dot(vl) / vl.squaredNorm(), horizon);
  const L closest = sl + vl * closest_time;
  if (closest.norm() < r - tolerance * scale) fail("missed a contact");
}

/// The distance from `p` to each finite shape, by its own formula (not the code's features).
long double distanceTo(const core::Cuboid& box, const Eigen::Matrix<long double, 3, 1>& p) {
  const Eigen::Matrix<long double, 3, 1> h = box.half_size.cast<long double>();
  const Eigen::Matrix<long double, 3, 1> out = (p.cwiseAbs() - h).cwiseMax(0.0L);
  return out.norm();
}
long double distanceTo(const core::Cylinder& c, const Eigen::Matrix<long double, 3, 1>& p) {
  const long double radial = std::max(std::hypot(p.x(), p.y()) - c.radius, 0.0L);
  const long double axial = std::max(std::abs(p.z()) - c.half_length, 0.0L);
  return std::hypot(radial, axial);
}
long double distanceTo(const core::Capsule& c, const Eigen::Matrix<long double, 3, 1>& p) {
  const long double z = std::clamp<long double>(p.z(), -c.half_length, c.half_length);
  return std::max(std::hypot(std::hypot(p.x(), p.y()), p.z() - z) - c.radius, 0.0L);
}

template <class Shape>
void checkFinite(const Shape& shape, const core::RelativeMotion& motion, double horizon) {
  using L = Eigen::Matrix<long double, 3, 1>;
  const L c = motion.centre.cast<long double>(), v = motion.velocity.cast<long double>(),
          a = motion.acceleration.cast<long double>();
  const auto at = [&](long double t) -> L { return c + t * (v + (t / 2) * a); };
  const long double size = core::boundingRadius(shape) + motion.radius;
  const auto t = core::firstContactFinite(motion, shape, horizon);
  if (t) {
    if (!std::isfinite(*t) || *t < 0 || *t > horizon) fail("finite: time outside [0, horizon]");
    const long double tl = *t;
    const long double time_ulp = std::nextafter(*t, INFINITY) - *t;
    const long double scale = c.norm() + v.norm() * tl + a.norm() * tl * tl + size;
    const long double speed = v.norm() + a.norm() * (tl + time_ulp);
    if (std::abs(distanceTo(shape, at(tl)) - motion.radius) >
        1e-6L * scale + 4 * speed * time_ulp) {
      fail("finite: no contact at the time found");
    }
    return;
  }
  // A start clearly outside, and an instant clearly inside: a miss.
  const long double start_scale = c.norm() + size;
  if (distanceTo(shape, c) < motion.radius + 1e-6L * start_scale) return;
  for (int k = 1; k <= 64; ++k) {
    const long double s = horizon * static_cast<long double>(k) / 64;
    const long double scale = c.norm() + v.norm() * s + a.norm() * s * s + size;
    if (distanceTo(shape, at(s)) < motion.radius - 1e-6L * scale) fail("finite: missed a contact");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::FuzzInput in(data, size);
  V s, v, a;
  for (int i = 0; i < 3; ++i) s[i] = in.number();
  for (int i = 0; i < 3; ++i) v[i] = in.number();
  for (int i = 0; i < 3; ++i) a[i] = in.number();
  const double radius = std::abs(in.number());
  const double horizon = std::abs(in.number());
  if (!s.allFinite() || !v.allFinite() || !a.allFinite() || !std::isfinite(radius) ||
      !std::isfinite(horizon)) {
    return 0;  // the monitor only ever passes finite, validated values
  }
  // Magnitudes whose squares stay in long double's range after the core's scaling: all finite
  // doubles qualify.
  checkStraight<double>(s, v, radius, horizon, 1e-9);
  const Eigen::Vector3f sf = s.cast<float>(), vf = v.cast<float>();
  const float rf = static_cast<float>(radius), hf = static_cast<float>(horizon);
  if (sf.allFinite() && vf.allFinite() && std::isfinite(rf) && std::isfinite(hf)) {
    checkStraight<float>(sf, vf, rf, hf, 1e-3);
  }

  // A box, cylinder or capsule of the next numbers' sizes, straight or accelerating.
  {
    const double first = std::abs(in.number()), second = std::abs(in.number()),
                 third = std::abs(in.number());
    const int kind = static_cast<int>(in.byte() % 6);
    if (std::isfinite(first) && std::isfinite(second) && std::isfinite(third) && first > 0 &&
        second > 0 && third > 0) {
      core::RelativeMotion motion;
      motion.centre = s;
      motion.velocity = v;
      if (kind >= 3) motion.acceleration = a;
      motion.radius = radius;
      switch (kind % 3) {
        case 0:
          checkFinite(core::Cuboid{V(first, second, third)}, motion, horizon);
          break;
        case 1:
          checkFinite(core::Cylinder{first, second}, motion, horizon);
          break;
        default:
          checkFinite(core::Capsule{first, second}, motion, horizon);
          break;
      }
    }
  }

  // Ballistic, against a plane: gap(t) = gap + rate t + (acc/2) t^2.
  const double gap = s.x(), rate = v.x(), acceleration = a.x();
  if (const auto t = core::timeOfImpactPlaneBallistic(gap, rate, acceleration, horizon)) {
    if (!std::isfinite(*t) || *t < 0 || *t > horizon) fail("ballistic time outside [0, horizon]");
    const long double tl = *t;
    const long double at = gap + rate * tl + 0.5L * acceleration * tl * tl;
    const long double scale =
        std::abs(gap) + std::abs(rate) * tl + std::abs(acceleration) * tl * tl;
    const long double time_ulp = std::nextafter(*t, INFINITY) - *t;
    const long double speed = std::abs(rate) + std::abs(acceleration) * (tl + time_ulp);
    if (std::abs(at) > 1e-9L * scale + 2 * speed * time_ulp) {
      fail("ballistic: no contact at the time found");
    }
    if (!(rate + acceleration * tl < 1e-12L * (std::abs(rate) + std::abs(acceleration) * tl))) {
      fail("ballistic: leaving at the time found");
    }
  }

  // Accelerated spheres (one falls, one is held): a time found must be a contact.
  if (const auto t = core::timeOfImpactSpheresAccelerated(s, v, a, radius, horizon)) {
    if (!std::isfinite(*t) || *t < 0 || *t > horizon)
      fail("accelerated: time outside [0, horizon]");
    const long double tl = *t;
    using L = Eigen::Matrix<long double, 3, 1>;
    const L at =
        s.cast<long double>() + tl * (v.cast<long double>() + 0.5L * tl * a.cast<long double>());
    // Norms in long double: in double the squares of 1e-300 underflow.
    const long double sn = s.cast<long double>().norm(), vn = v.cast<long double>().norm(),
                      an = a.cast<long double>().norm();
    const long double scale = sn + vn * tl + an * tl * tl + radius;
    const long double time_ulp = std::nextafter(*t, INFINITY) - *t;
    const long double speed = vn + an * (tl + time_ulp);
    if (std::abs(at.norm() - radius) > 1e-6L * scale + 2 * speed * time_ulp) {
      fail("accelerated: no contact at the time found");
    }
  }
  return 0;
}
