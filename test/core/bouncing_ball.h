// A ball thrown onto a floor and tracked, in closed form (issue 44): the synthetic tracks of the
// calibration's tests (test/core/test_calibration.cpp) and of its cost of accuracy
// (bench/calibration_accuracy.cpp). Independent of the core: parabolas, the bounce instants the
// roots of their quadratics, Coulomb friction with sticking derived below.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "collision_response/core/calibration.h"

namespace collision_response::core::bouncing_ball {

using V = Eigen::Vector3d;

constexpr double kG = 9.81;

struct TrueBounce {
  double time = 0.0;
  V before = V::Zero();
  V after = V::Zero();
  V spin_before = V::Zero();  ///< rad/s
  V spin_after = V::Zero();
  bool stuck = false;
};

struct Track {
  std::vector<TrackedSample> samples;
  std::vector<TrueBounce> bounces;
};

struct Throw {
  double e = 0.9;
  double mu = 0.03;
  double radius = 0.02;
  V position = V(0.0, 0.0, 0.5);
  V velocity = V(3.0, 0.5, -1.0);
  V spin = V::Zero();
  int bounces = 5;
  double rate = 200.0;  ///< Hz
  double noise = 1e-3;  ///< m, each coordinate
  double drop = 0.0;    ///< the chance of a sample being dropped
  unsigned seed = 1;
};

/// The ball's flight on the floor z = 0 (its centre at z = r when it touches): between bounces a
/// parabola under g = (0, 0, -9.81); a bounce at the root of r = z + vz s - g s^2 / 2, s =
/// (vz + sqrt(vz^2 + 2 g (z - r))) / g. At a bounce vz' = -e vz, and the contact point's slip
/// u = v_t + w x (-r n) (n = +z) is stopped by a tangential impulse J_stick = m |u| / (1 + 5/2)
/// (a solid ball, I = 2/5 m r^2) when mu J_n (J_n = m (1 + e) |vz|) allows it, otherwise the
/// impulse is mu J_n against the slip; the spin changes by -(5/2) / r n x dv_t.
inline Track throwBall(const Throw& t) {
  Track track;
  std::vector<std::pair<double, std::pair<V, V>>> pieces;  // start, (position, velocity)
  V p = t.position;
  V v = t.velocity;
  V w = t.spin;
  double start = 0.0;
  const V n(0, 0, 1);
  for (int j = 0; j < t.bounces; ++j) {
    pieces.push_back({start, {p, v}});
    const double h = p.z() - t.radius;
    const double s = (v.z() + std::sqrt(v.z() * v.z() + 2.0 * kG * h)) / kG;
    TrueBounce bounce;
    bounce.time = start + s;
    V at = p + s * v;
    at.z() -= 0.5 * kG * s * s;
    at.z() = t.radius;
    bounce.before = v;
    bounce.before.z() -= kG * s;
    V after = bounce.before;
    after.z() = -t.e * bounce.before.z();
    const V u = bounce.before + w.cross(-t.radius * n);
    const V u_t(u.x(), u.y(), 0.0);
    const double normal_change = (1.0 + t.e) * std::abs(bounce.before.z());
    V tangential_change = V::Zero();
    if (u_t.norm() > 0) {
      const double stick = u_t.norm() / (1.0 + 2.5);
      bounce.stuck = stick <= t.mu * normal_change;
      tangential_change = -std::min(stick, t.mu * normal_change) * u_t.normalized();
    }
    after += tangential_change;
    bounce.spin_before = w;
    w -= (2.5 / t.radius) * n.cross(tangential_change);
    bounce.spin_after = w;
    bounce.after = after;
    track.bounces.push_back(bounce);
    p = at;
    v = after;
    start = bounce.time;
  }
  pieces.push_back({start, {p, v}});
  // Samples to the top of the last flight and a little past it.
  const double end = start + 1.1 * v.z() / kG;
  std::mt19937_64 random(t.seed);
  std::normal_distribution<double> noise(0.0, 1.0);  // scaled by t.noise (which may be 0)
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int k = 0;; ++k) {
    const double time = k / t.rate;
    if (time > end) break;
    std::size_t piece = 0;
    while (piece + 1 < pieces.size() && time >= pieces[piece + 1].first) ++piece;
    const double s = time - pieces[piece].first;
    V position = pieces[piece].second.first + s * pieces[piece].second.second;
    position.z() -= 0.5 * kG * s * s;
    const V error = t.noise * V(noise(random), noise(random), noise(random));
    if (t.drop > 0 && uniform(random) < t.drop) continue;
    track.samples.push_back(TrackedSample{time, position + error, std::nullopt});
  }
  return track;
}

inline CalibrationOptions floorOptions(const Throw& t) {
  CalibrationOptions options;
  options.planes = {Plane{V(0, 0, 1), 0.0}};
  options.radius = t.radius;
  options.gravity = V(0, 0, -kG);
  options.spin_before = t.spin;
  return options;
}

}  // namespace collision_response::core::bouncing_ball
