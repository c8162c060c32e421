// A shaped body's scenes and closed forms that the prediction's tests and the monitor's share: a
// box over a concrete floor, and the closed form of a box landing on an edge (edge_landing.h).
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "collision_response/core/monitor.h"
#include "collision_response/core/scene.h"
#include "edge_landing.h"
#include "quadrature.h"
#include "scene_builders.h"

namespace collision_response::core::shaped_scenes {

inline constexpr double kG = 9.81;

/// Every impact the monitor's steps reported, in order.
inline std::vector<ImpactRecord> impactsOf(const std::vector<StepReport>& reports) {
  std::vector<ImpactRecord> impacts;
  for (const StepReport& report : reports) {
    impacts.insert(impacts.end(), report.impacts.begin(), report.impacts.end());
  }
  return impacts;
}

/// The body's state every `dt` to `until` through the monitor, from `state` at 0.
struct Played {
  std::vector<StepReport> reports;
  std::vector<double> times;
  std::vector<Eigen::Vector3d> centres, velocities, spins;
  std::vector<Eigen::Quaterniond> orientations;
};

inline Played play(const Scene& scene, const BodyStateSample& state, double dt, double until) {
  ImpactMonitor monitor(scene, MonitorSettings{});
  Played played;
  played.reports.push_back(monitor.step(0.0, {state}));
  for (int k = 1; k * dt <= until + 1e-12; ++k) {
    const double t = k * dt;
    played.reports.push_back(monitor.step(t, {}));
    const auto at = monitor.predictedState(state.body, t);
    EXPECT_TRUE(at) << t;
    if (!at) break;
    played.times.push_back(t);
    played.centres.push_back(at->first);
    played.velocities.push_back(at->second);
    played.spins.push_back(monitor.predictedAngularVelocity(state.body, t));
    played.orientations.push_back(monitor.predictedOrientation(state.body, t));
  }
  return played;
}

/// The body's points that may touch: a box's corners, or 64 points of each rim of a cylinder.
inline std::vector<Eigen::Vector3d> outlineOf(const BodySpec& body) {
  std::vector<Eigen::Vector3d> points;
  if (body.shape == BodyShape::kBox) {
    for (int k = 0; k < 8; ++k) {
      points.push_back(Eigen::Vector3d((k & 1) ? 1 : -1, (k & 2) ? 1 : -1, (k & 4) ? 1 : -1)
                           .cwiseProduct(body.size / 2));
    }
  } else {
    for (int k = 0; k < 64; ++k) {
      const double a = 2 * M_PI * k / 64;
      for (const double z : {-0.5, 0.5}) {
        points.push_back(
            Eigen::Vector3d(body.radius * std::cos(a), body.radius * std::sin(a), z * body.length));
      }
    }
  }
  return points;
}

/// The body's moments of inertia about its own axes: a uniform box's or cylinder's.
inline Eigen::Vector3d momentsOf(const BodySpec& body) {
  const double m = body.mass;
  if (body.shape == BodyShape::kBox) {
    const Eigen::Vector3d s = body.size;
    return m / 12 *
           Eigen::Vector3d(s.y() * s.y() + s.z() * s.z(), s.x() * s.x() + s.z() * s.z(),
                           s.x() * s.x() + s.y() * s.y());
  }
  const double r = body.radius, l = body.length;
  const double across = m * (3 * r * r + l * l) / 12;
  return Eigen::Vector3d(across, across, m * r * r / 2);
}

/// The random slides' body: a box of half sizes 0.03 to 0.1 m, or a can (`can`) of radius 0.03
/// to 0.06 m, 0.08 to 0.25 m tall, drawn in that order; its half height.
inline double randomBlock(BodySpec& body, bool can, std::mt19937& random) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  if (can) {
    body.shape = BodyShape::kCylinder;
    body.size = Eigen::Vector3d::Zero();
    body.radius = 0.03 + 0.03 * unit(random);
    body.length = 0.08 + 0.17 * unit(random);
    return body.length / 2;
  }
  body.size = 2 * Eigen::Vector3d(0.03 + 0.07 * unit(random), 0.03 + 0.07 * unit(random),
                                  0.03 + 0.07 * unit(random));
  return body.size.z() / 2;
}

/// The random slides' checks on a played body: every point of its outline (outlineOf) outside
/// the obstacles, `outside(point)` >= -1e-9 m (its least distance past their surfaces, signed),
/// and no energy gained from one sample to the next (1e-8 J: the integration's tolerance).
template <class Outside>
void expectOutsideAndNotGaining(const Played& played, const BodySpec& body, int k,
                                const Outside& outside) {
  const std::vector<Eigen::Vector3d> outline = outlineOf(body);
  const Eigen::Vector3d moments = momentsOf(body);
  const double m = body.mass;
  double previous = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < played.times.size(); ++i) {
    const double t = played.times[i];
    const Eigen::Vector3d& c = played.centres[i];
    const Eigen::Matrix3d r = played.orientations[i].toRotationMatrix();
    for (const Eigen::Vector3d& p : outline) {
      EXPECT_GE(outside(Eigen::Vector3d(c + r * p)), -1e-9) << k << ": inside at " << t;
    }
    const Eigen::Vector3d& w = played.spins[i];
    const double energy = 0.5 * m * played.velocities[i].squaredNorm() +
                          0.5 * w.dot(r * moments.asDiagonal() * r.transpose() * w) +
                          m * kG * c.z();
    EXPECT_LE(energy, previous + 1e-8) << k << " at " << t;
    previous = energy;
  }
}

/// A box of edges 2 half over a concrete floor at z = 0, its material `e` against concrete.
inline Scene floorScene(double e, const Eigen::Vector3d& half, double mass = 2.0) {
  Scene scene;
  scene.effects.gravity = true;
  scene.gravity = Eigen::Vector3d(0, 0, -kG);
  EXPECT_TRUE(scene.materials.addMaterial("block", Material{e, 0.0}, "m").ok());
  BodySpec body;
  body.id = "block";
  body.mass = mass;
  body.material = "block";
  body.shape = BodyShape::kBox;
  body.size = 2 * half;
  scene.bodies = {body};
  scene.obstacles = {scene_builders::plane("floor", Eigen::Vector3d::UnitZ(), 0.0, "concrete")};
  return scene;
}

/// floorScene with a table: a box obstacle 1 m square and 0.5 m tall on the floor, its top at
/// z = 0.5 and its edges at x, y = +-0.5.
inline Scene tableScene(double e, const Eigen::Vector3d& half, double mass = 2.0) {
  Scene scene = floorScene(e, half, mass);
  scene.obstacles.push_back(scene_builders::box("table", Eigen::Vector3d(0, 0, 0.25),
                                                Eigen::Vector3d(1.0, 1.0, 0.5), "concrete"));
  return scene;
}

/// A solid cylinder (r = 0.05 m, 0.2 m long, 1 kg) over the frictionless floor of floorScene,
/// given at rest leaning on its rim: its axis turned by `tilt` about x, its rim's lowest point
/// on the floor. Its centre falls straight down (no force along the floor), at the height
/// z = r sin theta + h cos theta, and m z'^2 theta'^2 / 2 + I_x theta'^2 / 2 + m g z is kept
/// (I_x = m (3 r^2 + L^2) / 12): below atan(r / h) it falls back onto its cap at theta = 0,
/// the integral of dtheta / theta' later (landing()).
struct RimFall {
  double r = 0.05, h = 0.1, m = 1.0, tilt = 0.3;

  Scene scene() const {
    Scene made = floorScene(0.5, Eigen::Vector3d(0.05, 0.05, 0.05), m);
    made.bodies[0].shape = BodyShape::kCylinder;
    made.bodies[0].size = Eigen::Vector3d::Zero();
    made.bodies[0].radius = r;
    made.bodies[0].length = 2 * h;
    return made;
  }
  Eigen::Vector3d centre() const {
    return Eigen::Vector3d(0, 0, r * std::sin(tilt) + h * std::cos(tilt));
  }
  Eigen::Quaterniond orientation() const {
    return Eigen::Quaterniond(Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX()));
  }
  /// From rest at tilt to 0: with theta = tilt - s^2 the integrand 2 s / theta' is smooth at
  /// s = 0; 5-point Gauss-Legendre over 400 panels of s in [0, sqrt(tilt)].
  double landing() const {
    const double ix = m * (3 * r * r + 4 * h * h) / 12;
    const auto z = [&](double q) { return r * std::sin(q) + h * std::cos(q); };
    const auto dz = [&](double q) { return r * std::cos(q) - h * std::sin(q); };
    const auto rate = [&](double q) {
      return std::sqrt(2 * m * kG * (z(tilt) - z(q)) / (m * dz(q) * dz(q) + ix));
    };
    return quadrature::fromRest(rate, tilt, 0.0, 400);
  }
};

/// A cube (0.1 m, 1 kg) at rest on an incline of tan theta = 3/4 (its normal (0, -3/5, 4/5),
/// through the origin; no other obstacle), mu 0.9 >= 3/4, given sliding across the slope at
/// 1 m/s. It does not turn (each corner's friction mu N_i is against the one slip, and the
/// centre of pressure is h mu along it: no moment about the normal), and its slide's direction
/// turns down the slope: with G = g sin theta, F = mu g cos theta, k = F / G = 1.2 and phi the
/// angle of its velocity from straight down the slope, v' = G cos phi - F and v phi' = -G sin phi,
/// so v = v0 (sin phi0 / sin phi) (tan(phi / 2) / tan(phi0 / 2))^k (phi0 = pi / 2 here), the
/// instant t(phi) = the integral from phi to phi0 of v / (G sin psi) dpsi and the centre's path
/// the integral of v^2 (cos psi down + sin psi across) / (G sin psi) dpsi, its state at t that at
/// phi(t) (t(phi) inverted); it stops at t(0) (k > 1:
/// the integrand ~ psi^(k - 2), integrable), at rest there (mu >= tan theta). The integrals by
/// 5-point Gauss-Legendre over 400 panels of u = psi^(1/5) (smooth at psi = 0).
struct AcrossSlope {
  Scene scene() const {
    Scene made = floorScene(0.5, Eigen::Vector3d(0.05, 0.05, 0.05), 1.0);
    EXPECT_TRUE(made.materials.addMaterial("rough", Material{0.5, 0.9}, "m").ok());
    made.bodies[0].material = "rough";
    made.effects.friction = true;
    made.obstacles = {scene_builders::plane("incline", normal(), 0.0, "concrete")};
    return made;
  }
  static Eigen::Vector3d normal() { return Eigen::Vector3d(0, -0.6, 0.8); }
  BodyStateSample state(std::size_t body, double time) const {
    BodyStateSample made;
    made.body = body;
    made.time = time;
    made.position = 0.05 * normal();
    made.orientation = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), normal());
    made.velocity = across();
    return made;
  }
  static Eigen::Vector3d down() { return Eigen::Vector3d(0, -0.8, -0.6); }
  static Eigen::Vector3d across() { return Eigen::Vector3d(1, 0, 0); }
  static double slope() { return kG * 0.6; }
  static double k() { return 0.9 * 0.8 / 0.6; }
  /// m/s: its speed where its velocity is phi from straight down.
  static double speed(double phi) { return std::pow(std::tan(phi / 2), k()) / std::sin(phi); }
  /// s: when it is there.
  static double instant(double phi) {
    return integral(phi, [](double psi) { return speed(psi) / (slope() * std::sin(psi)); });
  }
  /// rad: where it is at `t` (in [0, instant(0)]): t(phi) = t by bisection (t decreases with phi).
  static double angleAt(double t) {
    double lo = 0.0, hi = M_PI / 2;
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      (instant(mid) > t ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }
  /// m: its centre then, from where it started.
  static Eigen::Vector3d moved(double phi) {
    const auto along = [](const Eigen::Vector3d& axis) {
      return [axis](double psi) {
        const double v = speed(psi);
        return v * v * (std::cos(psi) * down() + std::sin(psi) * across()).dot(axis) /
               (slope() * std::sin(psi));
      };
    };
    return integral(phi, along(down())) * down() + integral(phi, along(across())) * across();
  }

 private:
  template <class F>
  static double integral(double phi, const F& f) {
    return quadrature::gaussLegendre(
        [&](double u) { return f(std::pow(u, 5)) * 5 * std::pow(u, 4); }, std::pow(phi, 0.2),
        std::pow(M_PI / 2, 0.2), 400);
  }
};

/// The edge landing's impacts at one instant against its closed form: at edge.fall() (1e-11 s,
/// the first contact's certification), each leaving with v_z' and w_y' and no other spin (1e-9),
/// their impulses adding up to J (1e-9).
inline void expectTheEdgeLanding(const EdgeLanding& edge,
                                 const std::vector<ImpactRecord>& impacts) {
  double total = 0.0;
  for (const ImpactRecord& impact : impacts) {
    EXPECT_NEAR(impact.time, edge.fall(), 1e-11);
    total += impact.impulse;
    EXPECT_NEAR(impact.velocity_a_after.z(), edge.velocityAfter(), 1e-9);
    EXPECT_NEAR(impact.angular_velocity_a_after.y(), edge.spinAfter(), 1e-9);
    EXPECT_NEAR(impact.angular_velocity_a_after.x(), 0.0, 1e-9);
    EXPECT_NEAR(impact.angular_velocity_a_after.z(), 0.0, 1e-9);
  }
  EXPECT_NEAR(total, edge.impulse(), 1e-9);
}

}  // namespace collision_response::core::shaped_scenes
