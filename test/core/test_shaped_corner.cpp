// A box or a can over a table's corner (pivotOverFaceEdge in shaped_pivot.h: the table's corner
// on the body's face; doc/model.md, "Over a table's corner"): before, held where its support
// passed two of the table's edges ("not yet: the body overhangs two of the face's edges (its
// corner)").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "collision_response/core/monitor.h"
#include "contact/shaped_lasting.h"
#include "contact/shaped_pivot.h"
#include "lasting_bodies.h"
#include "scene_builders.h"
#include "shaped_scenes.h"

namespace collision_response::core {
namespace {

using lasting_bodies::box;
using lasting_bodies::errorOf;
using lasting_bodies::kG;
using lasting_bodies::Q;
using lasting_bodies::tableTop;
using lasting_bodies::V;

/// tableTop's corner, and the diagonal d out of it.
const V kCorner(1, 0.5, 0.7);
const V kOut = V(1, 1, 0).normalized();
const V kAxis = V::UnitZ().cross(kOut);  // s: tipping out turns z towards d about it

/// A cube (half side h, mass m) flat on the table, its faces square to the table's edges, its
/// centre delta beyond the corner along d: its face covers the corner (delta < h sqrt 2), and it
/// is symmetric about the vertical plane through the corner along d. The corner alone holds it:
/// turned by theta about s through the corner (sticking), its centre is at rho (sin phi d +
/// cos phi z) from it, phi = phi0 + theta, rho = |(delta, h)|, phi0 = atan2(delta, h); with I_P
/// = 2/3 m h^2 + m rho^2 (a cube's moment about its centre is 2/3 m h^2 about any axis),
///   theta'^2 = 2 m g rho (cos phi0 - cos phi) / I_P,  theta'' = m g rho sin phi / I_P,
/// and the corner's force on the cube, m a_c + m g z, along the cube's face normal n = (sin
/// theta, cos theta) and along its face t = (cos theta, -sin theta) in (d, z):
///   N = m (g cos theta - rho theta'' sin phi0 - rho theta'^2 cos phi0),
///   F = m (rho theta'' cos phi0 - rho theta'^2 sin phi0 - g sin theta).
struct CornerPendulum {
  double h = 0.05, delta = 0.02, m = 1.0, mu = 0.6;
  double rho() const { return std::hypot(delta, h); }
  double phi0() const { return std::atan2(delta, h); }
  double inertia() const { return m * (2.0 / 3.0 * h * h + rho() * rho()); }
  LastingBody body() const { return box(V(h, h, h), m, kCorner + delta * kOut + h * V::UnitZ()); }
  double rate2(double theta) const {
    return 2 * m * kG * rho() * (std::cos(phi0()) - std::cos(phi0() + theta)) / inertia();
  }
  double acceleration(double theta) const {
    return m * kG * rho() * std::sin(phi0() + theta) / inertia();
  }
  double normal(double theta) const {
    return m * (kG * std::cos(theta) - rho() * acceleration(theta) * std::sin(phi0()) -
                rho() * rate2(theta) * std::cos(phi0()));
  }
  double friction(double theta) const {
    return m * (rho() * acceleration(theta) * std::cos(phi0()) -
                rho() * rate2(theta) * std::sin(phi0()) - kG * std::sin(theta));
  }
  /// Where |F| first reaches mu N (bisection of the closed forms).
  double slips() const {
    const auto margin = [&](double theta) {
      return mu * normal(theta) - std::abs(friction(theta));
    };
    double lo = 0, hi = 0;
    while (margin(hi) > 0) hi += 1e-3;
    for (int i = 0; i < 200; ++i) {
      const double mid = 0.5 * (lo + hi);
      (margin(mid) > 0 ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }
  /// Its turn about s from its orientation (identity at the start).
  static double angleOf(const Q& orientation) {
    const Q q = orientation.normalized();
    return 2 * std::atan2(q.vec().dot(kAxis), q.w());
  }
};

TEST(ShapedCorner, ACubeOverTheTableCornerTurnsAboutItAsAPendulumUntilItSlips) {
  const CornerPendulum cube;
  const LastingBody body = cube.body();
  const auto tips = lastingOnFace(body, tableTop(cube.mu), 1e-12);
  ASSERT_TRUE(tips.ok()) << errorOf(tips);
  ASSERT_TRUE(tips->pivot);
  // The table's corner alone holds it.
  const std::vector<SupportForce> start = tips->forcesAt(tips->start);
  ASSERT_EQ(start.size(), 1u);
  EXPECT_LT((start.front().point - kCorner).norm(), 1e-12);
  // While it sticks: the pendulum's closed forms.
  double lo = tips->start, hi = tips->start;
  while (hi < tips->until && tips->stateAt(hi) != ContactState::kSliding) hi += 1e-3;
  ASSERT_LT(hi, tips->until) << "it slips before it leaves the corner";
  while (hi - lo > 1e-13) {
    const double mid = 0.5 * (lo + hi);
    (tips->stateAt(mid) == ContactState::kSliding ? hi : lo) = mid;
  }
  const double slips = cube.slips();
  EXPECT_NEAR(CornerPendulum::angleOf(tips->orientationAt(hi)), slips, 1e-8);
  const double largest = cube.rate2(slips);
  double worst_centre = 0, worst_rate = 0, worst_force = 0;
  for (int k = 1; k < 100; ++k) {
    const double t = tips->start + (lo - tips->start) * k / 100.0;
    const double theta = CornerPendulum::angleOf(tips->orientationAt(t));
    const double phi = cube.phi0() + theta;
    const V on_circle = kCorner + cube.rho() * (std::sin(phi) * kOut + std::cos(phi) * V::UnitZ());
    worst_centre = std::max(worst_centre, (tips->centreAt(t) - on_circle).norm());
    const V w = tips->angularVelocityAt(t);
    worst_rate =
        std::max({worst_rate, std::abs(w.dot(kAxis) * w.dot(kAxis) - cube.rate2(theta)) / largest,
                  (w - w.dot(kAxis) * kAxis).norm()});
    const std::vector<SupportForce> forces = tips->forcesAt(t);
    ASSERT_EQ(forces.size(), 1u) << t;
    const V n = std::sin(theta) * kOut + std::cos(theta) * V::UnitZ();
    const V along = std::cos(theta) * kOut - std::sin(theta) * V::UnitZ();
    const V force =
        forces.front().normal_force * forces.front().normal + forces.front().friction_force;
    worst_force =
        std::max({worst_force, std::abs(force.dot(n) - cube.normal(theta)) / (cube.m * kG),
                  std::abs(force.dot(along) - cube.friction(theta)) / (cube.m * kG),
                  (forces.front().point - kCorner).norm()});
  }
  EXPECT_LT(worst_centre, 1e-9);
  EXPECT_LT(worst_rate, 1e-8);
  EXPECT_LT(worst_force, 1e-8);
  // Then it slips, leaves the corner and falls: never inside the table, never gaining energy.
  const double e0 = lasting_bodies::energy(body, *tips, tips->start);
  for (int k = 0; k <= 400; ++k) {
    const double t = tips->start + (tips->until - tips->start) * k / 400.0;
    EXPECT_LE(lasting_bodies::energy(body, *tips, t), e0 + 1e-9 * std::abs(e0)) << t;
    const Eigen::Matrix3d r = tips->orientationAt(t).toRotationMatrix();
    for (int c = 0; c < 8; ++c) {
      const V corner =
          tips->centreAt(t) +
          r * V((c & 1) ? cube.h : -cube.h, (c & 2) ? cube.h : -cube.h, (c & 4) ? cube.h : -cube.h);
      if (corner.x() < 1 && corner.y() < 0.5) {
        EXPECT_GT(corner.z(), 0.7 - 1e-9) << t;
      }
    }
    const V in_cube = r.transpose() * (kCorner - tips->centreAt(t));
    EXPECT_GT((in_cube.cwiseAbs() - V::Constant(cube.h)).maxCoeff(), -1e-9) << t;
  }
  std::printf(
      "slips at %.9f rad (closed form %.9f), centre %.3g m, rate^2 %.3g, force %.3g of mg; %s at "
      "+%.6f s\n",
      CornerPendulum::angleOf(tips->orientationAt(hi)), slips, worst_centre, worst_rate,
      worst_force, tips->ends.c_str(), tips->until - tips->start);
}

/// A cube (half side h, mass m, its faces square to the table's edges), or a can standing on its
/// cap (radius r, half length h), sliding along the diagonal d with mu against the table: on the
/// table or over its corner alike, s(t) = s0 + u t - mu g
/// t^2 / 2 along d, without turning, and the centre of pressure is h mu ahead of the centre's foot
/// (the friction's moment: h (g_t - a) / g_n). Over the corner, the part of its face on the
/// table ends at the corner along d: it holds the cube until the centre of pressure reaches the
/// corner, where s = -h mu (s measured from the corner along d), then it tips over it. The can's
/// cap covers the corner from s0 = -0.04 (r = 0.06).
struct CornerSlide {
  double h = 0.05, m = 2.0, mu = 0.4, s0 = -0.06, u = 1.0, r = 0.06;
  bool can = false;
  double along(double t) const { return s0 + u * t - 0.5 * mu * kG * t * t; }
  double tips() const {  // s(t) = -h mu: the smaller root
    const double a = mu * kG, c = s0 + h * mu;
    return (u - std::sqrt(u * u + 2 * a * c)) / a;
  }
  LastingBody body() const {
    const V centre = kCorner + s0 * kOut + h * V::UnitZ();
    LastingBody made = can ? lasting_bodies::cylinder(r, h, m, m * r * r / 2, centre, Q::Identity())
                           : box(V(h, h, h), m, centre);
    made.velocity = u * kOut;
    return made;
  }
  /// Its points that may touch (a cube's corners, 64 points of each rim), in its frame.
  std::vector<V> outline() const {
    std::vector<V> points;
    for (int c = 0; c < (can ? 128 : 8); ++c) {
      const double a = 2 * M_PI * (c / 2) / 64, z = (c & 1) ? h : -h;
      points.push_back(can ? V(r * std::cos(a), r * std::sin(a), z)
                           : V((c & 1) ? h : -h, (c & 2) ? h : -h, (c & 4) ? h : -h));
    }
    return points;
  }
  /// How deep a point (its frame) is in it: <= 0 inside.
  double depth(const V& x) const {
    return can ? std::max(std::abs(x.z()) - h, std::hypot(x.x(), x.y()) - r)
               : (x.cwiseAbs() - V::Constant(h)).maxCoeff();
  }
};

/// CornerSlide's closed forms against lastingOnFace from its start (over the corner already):
/// the slide until the tip (1e-9 m, no turning), the table's forces (1e-9 of the weight), the
/// tip where the corner alone carries it (1e-9 s); then never inside the table, never gaining
/// energy.
void expectTheSlideOverTheCorner(const CornerSlide& slide) {
  const LastingBody body = slide.body();
  const auto motion = lastingOnFace(body, tableTop(slide.mu), 1e-12);
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  ASSERT_TRUE(motion->pivot);
  const double tips = slide.tips();
  ASSERT_GT(motion->until, tips);
  // The table's corner alone holds it from where its centre of pressure reaches the corner
  // (bisected on the points carrying it), and from there it turns.
  double lo = motion->start, hi = std::min(motion->until, tips + 0.01);
  ASSERT_EQ(motion->forcesAt(hi).size(), 1u);
  ASSERT_GT(motion->angularVelocityAt(hi).norm(), 1e-3);
  while (hi - lo > 1e-13) {
    const double mid = 0.5 * (lo + hi);
    (motion->forcesAt(mid).size() == 1 ? hi : lo) = mid;
  }
  EXPECT_NEAR(lo, tips, 1e-9);
  double worst = 0, worst_force = 0;
  bool on_corner = false;
  const double weight = slide.m * kG;
  for (int k = 0; k <= 100; ++k) {
    const double t = tips * k / 100.0;
    const V centre = kCorner + slide.along(t) * kOut + slide.h * V::UnitZ();
    worst = std::max({worst, (motion->centreAt(t) - centre).norm(),
                      motion->angularVelocityAt(t).norm() * slide.h});
    // The table carries its weight and the friction mu m g against the slide, its centre of
    // pressure h mu ahead of the centre's foot.
    V normal = V::Zero(), friction = V::Zero(), pressure = V::Zero();
    for (const SupportForce& f : motion->forcesAt(t)) {
      normal += f.normal_force * (f.normal.isZero() ? V::UnitZ() : f.normal);
      friction += f.friction_force;
      pressure += f.normal_force * f.point;
      on_corner = on_corner || (f.point - kCorner).norm() < 1e-12;
    }
    pressure /= normal.z();
    const V ahead = centre + (slide.mu * slide.h) * kOut - slide.h * V::UnitZ();
    worst_force = std::max({worst_force, (normal - weight * V::UnitZ()).norm() / weight,
                            (friction + slide.mu * weight * kOut).norm() / weight,
                            k < 100 ? (pressure - ahead).norm() : 0.0});
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(worst_force, 1e-9);
  EXPECT_TRUE(on_corner) << "the table's corner carries part of its weight";
  // Then it tips over the corner: never inside the table, never gaining energy.
  const double e0 = lasting_bodies::energy(body, *motion, motion->start);
  for (int k = 0; k <= 400; ++k) {
    const double t = motion->start + (motion->until - motion->start) * k / 400.0;
    EXPECT_LE(lasting_bodies::energy(body, *motion, t), e0 + 1e-9 * std::abs(e0)) << t;
    const Eigen::Matrix3d r = motion->orientationAt(t).toRotationMatrix();
    for (const V& point : slide.outline()) {
      const V at = motion->centreAt(t) + r * point;
      if (at.x() < 1 && at.y() < 0.5) {
        EXPECT_GT(at.z(), 0.7 - 1e-9) << t;
      }
    }
    EXPECT_GT(slide.depth(r.transpose() * (kCorner - motion->centreAt(t))), -1e-9) << t;
  }
  std::printf(
      "tips at +%.12f s (closed form %.12f), centre %.3g m, forces %.3g of mg; %s at +%.6f s\n", lo,
      tips, worst, worst_force, motion->ends.c_str(), motion->until);
}

TEST(ShapedCorner, ACubeOrACanSlidingOverTheCornerSlidesAsOnTheTableUntilItsPressureReachesIt) {
  CornerSlide cube, can;
  can.can = true;
  can.s0 = -0.04;
  for (const CornerSlide& slide : {cube, can}) {
    SCOPED_TRACE(slide.can ? "can" : "cube");
    expectTheSlideOverTheCorner(slide);
  }
}
// The same cube, e = 0 and mu 0.4 against the table of tableScene (top z = 0.5, its corner
// (0.5, 0.5)), through the monitor: slid along the diagonal from 0.3 m before the corner at u =
// sqrt(2 mu g 0.27), it reaches both edges at once, slides on over the corner by the same closed
// form and stops 0.03 m before it, at u / (mu g): its centre of pressure never reaches the corner
// (h mu = 0.02 m ahead of its centre), and at rest it is on the centre's foot.
TEST(ShapedCorner, TheMonitorSlidesACubeOverTheCornerToTheClosedFormsStopAndRestsItThere) {
  const double h = 0.05, m = 2.0, mu = 0.4, s0 = -0.3, stop = -0.03;
  const double u = std::sqrt(2 * mu * kG * (stop - s0)), stops = u / (mu * kG);
  Scene scene = shaped_scenes::tableScene(0.0, V(h, h, h), m);
  scene.effects.friction = true;
  if (std::getenv("CAN")) {
    scene.bodies[0].shape = BodyShape::kCylinder;
    scene.bodies[0].size = V::Zero();
    scene.bodies[0].radius = 0.06;
    scene.bodies[0].length = 0.1;
  }
  ASSERT_TRUE(scene.materials.addPair("block", "concrete", PairCoefficients{0.0, mu}, "p").ok());
  const V corner(0.5, 0.5, 0.5);
  ImpactMonitor monitor(scene, MonitorSettings{});
  BodyStateSample state;
  state.body = 0;
  state.position = corner + s0 * kOut + h * V::UnitZ();
  state.velocity = u * kOut;
  EXPECT_TRUE(monitor.step(0.0, {state}).unmodelled.empty());
  double worst = 0, worst_force = 0;
  int unmodelled = 0, impacts = 0, over_corner = 0;
  const double weight = m * kG;
  for (int k = 1; k <= 80; ++k) {
    const double t = 0.005 * k;
    const StepReport report = monitor.step(t, {});
    unmodelled += static_cast<int>(report.unmodelled.size());
    impacts += static_cast<int>(report.impacts.size());
    const auto at = monitor.predictedState(0, t);
    ASSERT_TRUE(at) << t;
    const double s = std::min(t, stops);
    const V centre = corner + (s0 + u * s - 0.5 * mu * kG * s * s) * kOut + h * V::UnitZ();
    worst = std::max(
        {worst, (at->first - centre).norm(), monitor.predictedAngularVelocity(0, t).norm() * h});
    if (t > stops) {
      EXPECT_EQ(at->second, V::Zero()) << t;
    }
    // The table carries the weight, the friction against the slide (none at rest), the centre of
    // pressure h mu ahead of the centre's foot (on it at rest); the corner carries part of it.
    V normal = V::Zero(), friction = V::Zero(), pressure = V::Zero();
    for (const ContactRecord& contact : report.contacts) {
      normal += contact.normal_force * contact.normal;
      friction += contact.friction_force;
      pressure += contact.normal_force * contact.contact_point;
      if ((contact.contact_point - corner).norm() < 1e-12 && contact.normal_force > 0)
        ++over_corner;
    }
    ASSERT_FALSE(report.contacts.empty()) << t;
    pressure /= -normal.z();
    const V ahead = at->first + (t < stops ? mu * h : 0.0) * kOut - h * V::UnitZ();
    worst_force = std::max({worst_force, (normal + weight * V::UnitZ()).norm() / weight,
                            (friction - (t < stops ? mu * weight : 0.0) * kOut).norm() / weight,
                            (pressure - ahead).norm()});
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(worst_force, 1e-9);
  EXPECT_GT(over_corner, 10);
  EXPECT_EQ(unmodelled, 0);
  EXPECT_EQ(impacts, 0);
  std::printf("centre %.3g m, forces %.3g; %d samples with the corner carrying it\n", worst,
              worst_force, over_corner);
}

// 40 boxes of random sides and 20 cans standing on their caps (shaped_scenes::randomBlock), at
// random e and mu against the table and the floor, slid on tableScene's table (top z = 0.5,
// edges at x, y = +-0.5) at 0.5 to 2 m/s towards its corner (0.5, 0.5) within 20 degrees of its
// diagonal, turned at random about the vertical, 20 of them spinning at up to 5 rad/s about it.
// Through the monitor for 1 s (over the corner, off it, onto the floor): no corner (or rim point)
// inside the table or below the floor (1e-9 m), no energy gained from one sample to the next
// (1e-8 J), nothing unmodelled. A few draws (4 in this build, which ones depending on the
// compiler's rounding) meet what the README's "does not hold yet" names, none of them at the
// corner, each held and reported with one of `kSaid`'s reasons: those are counted (at most 6),
// their samples not checked.
TEST(ShapedCorner, RandomSlidesOffTheCornerNeverGoInsideNorGainEnergy) {
  // A box rocking between two corners on the table (held where its tipping chatters, or 1.1e-9 m
  // above the table after a corner's impact, or where a point approaching is taken as lasting: the
  // sanitizers' build); a can tipping on a rim beside the table's edge, its
  // other rim over the edge, which comes down into the edge before it is held; cans on the floor
  // against the table's side.
  const std::vector<std::string> kSaid = {
      "its tipping chatters between supports", "body.centre: the body does not touch the face",
      "its tipping ends inside the obstacle",
      "body.velocity: a point of the contact approaches the face"};
  int held = 0;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int off = 0;
  for (int k = 0; k < 60; ++k) {
    std::mt19937 random(7007 + k);
    const bool can = k >= 40, spins = k >= 50 || (k >= 30 && k < 40);
    Scene scene = shaped_scenes::tableScene(unit(random), V(0.05, 0.05, 0.05), 0.2 + unit(random));
    scene.effects.friction = true;
    scene.materials = MaterialTable{};
    ASSERT_TRUE(
        scene.materials.addMaterial("block", Material{unit(random), unit(random)}, "m").ok());
    ASSERT_TRUE(
        scene.materials.addMaterial("concrete", Material{unit(random), unit(random)}, "m").ok());
    BodySpec& body = scene.bodies[0];
    const double height = shaped_scenes::randomBlock(body, can, random);
    const double angle = M_PI / 4 + (2 * unit(random) - 1) * M_PI / 9;
    const double speed = 0.5 + 1.5 * unit(random);
    BodyStateSample state;
    state.body = 0;
    state.position = V(0.1, 0.1, 0.5 + height);
    state.orientation = Q(Eigen::AngleAxisd(2 * M_PI * unit(random), V::UnitZ()));
    state.velocity = speed * V(std::cos(angle), std::sin(angle), 0);
    state.angular_velocity = V(0, 0, spins ? 5 * (2 * unit(random) - 1) : 0.0);
    const shaped_scenes::Played played = shaped_scenes::play(scene, state, 0.005, 1.0);
    bool said = false;
    for (const StepReport& report : played.reports) {
      for (const UnmodelledContact& c : report.unmodelled) {
        const bool known = std::any_of(kSaid.begin(), kSaid.end(), [&](const std::string& why) {
          return c.what.rfind(why, 0) == 0;
        });
        if (!known) ADD_FAILURE() << k << ": " << c.what << " at " << c.time;
        said = true;
      }
    }
    if (said) {
      ++held;
      continue;
    }
    shaped_scenes::expectOutsideAndNotGaining(played, body, k, [](const V& at) {
      return std::min(std::max({at.x() - 0.5, at.y() - 0.5, at.z() - 0.5}), at.z());
    });
    for (const V& c : played.centres) off += c.z() < 0.5 ? 1 : 0;
  }
  EXPECT_GT(off, 800);  // they went off the table
  EXPECT_LE(held, 6);
  std::printf("held and said: %d of 60\n", held);
}

}  // namespace
}  // namespace collision_response::core
