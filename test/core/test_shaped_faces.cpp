// A shaped body against several obstacles at once (lastingOnFaces, pivotOnFaces in
// shaped_pivot.h; doc/model.md, "Against several obstacles at once"): a plank leaning on a wall,
// a box sliding down a gutter, a box in a corner. Before, held where it touched the second
// ("not yet: a shaped body's lasting contact with 2 obstacles at once").
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "collision_response/core/monitor.h"
#include "collision_response/core/prediction.h"
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
using lasting_bodies::plane;
using lasting_bodies::Q;
using lasting_bodies::V;

/// A plank of half sizes (a, w, b) leaning at theta above the floor z = 0 on the wall x = 0, its
/// long axis u = (-cos theta, 0, sin theta) from its foot up to the wall, v = (sin theta, 0,
/// cos theta) across it: its corner -a u - b v on the floor, +a u - b v on the wall, so its
/// centre is at f(theta) = (a cos theta + b sin theta, 0, a sin theta + b cos theta) while it
/// touches both. Turned by theta + pi about y: its x axis is u.
struct Plank {
  double a = 0.5, w = 0.1, b = 0.02, mass = 2.0;
  double theta0 = M_PI / 3;
  LastingBody at(double theta) const {
    return box(V(a, w, b), mass, centre(theta), Q(Eigen::AngleAxisd(theta + M_PI, V::UnitY())));
  }
  V centre(double theta) const {
    return V(a * std::cos(theta) + b * std::sin(theta), 0,
             a * std::sin(theta) + b * std::cos(theta));
  }
  /// Its angle from its orientation (x axis u).
  static double angleOf(const Q& orientation) {
    const Eigen::Matrix3d r = orientation.toRotationMatrix();
    return std::atan2(r(2, 0), -r(0, 0));
  }
  // The energy integral of the frictionless slide from rest at theta0, with both corners on:
  // m |f'|^2 theta'^2 / 2 + I theta'^2 / 2 + m g z(theta) = m g z(theta0), |f'|^2 = a^2 + b^2 -
  // 2 a b sin 2 theta, I = m (a^2 + b^2) / 3: theta'^2 = F(theta) = 2 g (z0 - z) / D.
  long double d(long double t) const {
    const long double aa = a, bb = b;
    return (aa * aa + bb * bb) * 4 / 3 - 2 * aa * bb * std::sin(2 * t);
  }
  long double f(long double t) const {
    const long double z0 = a * std::sin((long double)theta0) + b * std::cos((long double)theta0);
    const long double z = a * std::sin(t) + b * std::cos(t);
    return 2 * (long double)kG * (z0 - z) / d(t);
  }
  long double fRate(long double t) const {  // dF/dtheta
    const long double z0 = a * std::sin((long double)theta0) + b * std::cos((long double)theta0);
    const long double z = a * std::sin(t) + b * std::cos(t);
    const long double z_rate = a * std::cos(t) - b * std::sin(t);
    const long double d_rate = -4 * (long double)a * b * std::cos(2 * t);
    return 2 * (long double)kG * (-z_rate * d(t) - (z0 - z) * d_rate) / (d(t) * d(t));
  }
  /// The wall's force over m: x_c'' = x'' theta'^2 + x' theta'' (theta'' = F' / 2).
  long double wallForce(long double t) const {
    const long double x_rate = -a * std::sin(t) + b * std::cos(t);
    const long double x_rate2 = -a * std::cos(t) - b * std::sin(t);
    return x_rate2 * f(t) + x_rate * fRate(t) / 2;
  }
  /// Where the wall's force falls to 0 first, going down from theta0 (bisection in long double).
  double leaves() const {
    long double hi = theta0 - 1e-9L, lo = hi;
    while (wallForce(lo) > 0) lo -= 1e-3L;
    for (int i = 0; i < 200; ++i) {
      const long double mid = (lo + hi) / 2;
      (wallForce(mid) > 0 ? hi : lo) = mid;
    }
    return static_cast<double>((lo + hi) / 2);
  }
};

std::vector<FlatFace> floorAndWall(double mu_floor, double mu_wall) {
  return {plane(V::UnitZ(), mu_floor), plane(V::UnitX(), mu_wall)};
}

bool onWall(const LastingMotion& motion, double t) {
  for (const SupportForce& force : motion.forcesAt(t)) {
    if (force.face == 1) return true;
  }
  return false;
}

TEST(ShapedFaces, TheLadderReferenceLeavesAtTwoThirdsOfItsHeightWhenThin) {
  // The reference's own check: a thin rod (b = 0) leaves the wall where sin theta = 2/3 sin
  // theta0 (the classic result of the same energy integral).
  Plank rod;
  rod.b = 0.0;
  EXPECT_NEAR(std::sin(rod.leaves()), 2.0 / 3.0 * std::sin(rod.theta0), 1e-12);
}

TEST(ShapedFaces, AFrictionlessPlankLeaningOnAWallLeavesItWhereItsEnergyIntegralSays) {
  const Plank plank;
  const LastingBody body = plank.at(plank.theta0);
  const auto motion = lastingOnFaces(body, floorAndWall(0, 0), 1e-11);
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  ASSERT_TRUE(motion->pivot);
  EXPECT_EQ(motion->ends, "resumes") << "it falls flat onto the floor";
  // The wall's points leave where their force is 0: bisected on the forces the motion gives.
  double lo = 0, hi = motion->until;
  ASSERT_TRUE(onWall(*motion, lo));
  ASSERT_FALSE(onWall(*motion, hi));
  while (hi - lo > 1e-13) {
    const double mid = (lo + hi) / 2;
    (onWall(*motion, mid) ? lo : hi) = mid;
  }
  const double leave_angle = plank.leaves();
  EXPECT_NEAR(Plank::angleOf(motion->orientationAt(hi)), leave_angle, 1e-8);
  // While on both: the centre on f(theta), theta'^2 = F(theta); throughout, the energy kept.
  const double e0 = lasting_bodies::energy(body, *motion, 0);
  double worst_centre = 0, worst_rate = 0, worst_energy = 0;
  for (int k = 0; k <= 400; ++k) {
    const double t = motion->until * k / 400;
    const double theta = Plank::angleOf(motion->orientationAt(t));
    worst_energy = std::max(worst_energy,
                            std::abs(lasting_bodies::energy(body, *motion, t) - e0) / std::abs(e0));
    if (t >= lo) continue;
    worst_centre = std::max(worst_centre, (motion->centreAt(t) - plank.centre(theta)).norm());
    const double rate = motion->angularVelocityAt(t).y();
    worst_rate = std::max(worst_rate, std::abs(rate * rate - static_cast<double>(plank.f(theta))));
  }
  EXPECT_LT(worst_centre, 1e-9);
  EXPECT_LT(worst_rate, 1e-8);
  EXPECT_LT(worst_energy, 1e-9);
  std::printf(
      "leaves the wall at %.9f rad (energy integral %.9f), centre %.3g m, rate^2 %.3g, "
      "energy %.3g\n",
      Plank::angleOf(motion->orientationAt(hi)), leave_angle, worst_centre, worst_rate,
      worst_energy);
}

TEST(ShapedFaces, APlankWhoseFloorFrictionHoldsItRestsOnTheWallWithTheStaticForces) {
  // Moments about its foot (2a cos theta, 0, 0): the wall's force N = m g (a cos theta - b sin
  // theta) / (2 a sin theta) at its top (0, 0, 2 a sin theta), the floor's friction N towards
  // the wall, its normal force m g: it rests where mu >= N / (m g).
  const Plank plank;
  const double t = plank.theta0;
  const double ratio =
      (plank.a * std::cos(t) - plank.b * std::sin(t)) / (2 * plank.a * std::sin(t));
  const double weight = plank.mass * kG;
  const LastingBody body = plank.at(t);
  const auto held = lastingOnFaces(body, floorAndWall(1.01 * ratio, 0), 1e-11);
  ASSERT_TRUE(held.ok()) << errorOf(held);
  EXPECT_EQ(held->state, ContactState::kResting);
  EXPECT_FALSE(held->pivot);
  EXPECT_EQ(held->until, std::numeric_limits<double>::infinity());
  EXPECT_EQ(held->velocityAt(5.0), V::Zero());
  V floor_force = V::Zero(), wall_force = V::Zero();
  for (const SupportForce& force : held->forcesAt(5.0)) {
    const V on_body =
        force.normal_force * (force.face == 0 ? V::UnitZ() : V::UnitX()) + force.friction_force;
    (force.face == 0 ? floor_force : wall_force) += on_body;
  }
  EXPECT_NEAR(floor_force.z(), weight, 1e-12 * weight);
  EXPECT_NEAR(floor_force.x(), -ratio * weight, 1e-12 * weight);
  EXPECT_NEAR(wall_force.x(), ratio * weight, 1e-12 * weight);
  EXPECT_NEAR(wall_force.z(), 0.0, 1e-12 * weight);
  // Just below the friction it needs, its foot slides away from the wall.
  const auto slides = lastingOnFaces(body, floorAndWall(0.99 * ratio, 0), 1e-11);
  ASSERT_TRUE(slides.ok()) << errorOf(slides);
  EXPECT_NE(slides->state, ContactState::kResting);
  EXPECT_GT(slides->velocityAt(std::min(0.05, slides->until)).x(), 1e-6);
}

TEST(ShapedFaces, ABoxSlidingDownAGutterDeceleratesByBothFrictionsAndRestsWhereItStops) {
  // The floor z = 0 and the wall y = 0 form a gutter along x; gravity tilted: beta down along x,
  // gamma rolled towards the wall. The normal forces m g cos beta cos gamma and m g cos beta sin
  // gamma hold it across; each face's friction mu N against the slide: a = g sin beta - mu1 g
  // cos beta cos gamma - mu2 g cos beta sin gamma.
  const double beta = 20 * M_PI / 180, gamma = 30 * M_PI / 180, mu1 = 0.4, mu2 = 0.3;
  const double v0 = 0.6, half = 0.05;
  LastingBody body = box(V(half, half, half), 0.5, V(0, half, half));
  body.gravity =
      kG * V(std::sin(beta), -std::cos(beta) * std::sin(gamma), -std::cos(beta) * std::cos(gamma));
  body.velocity = V(v0, 0, 0);
  const std::vector<FlatFace> faces = {plane(V::UnitZ(), mu1), plane(V::UnitY(), mu2)};
  const double a = kG * (std::sin(beta) - mu1 * std::cos(beta) * std::cos(gamma) -
                         mu2 * std::cos(beta) * std::sin(gamma));
  ASSERT_LT(a, 0.0);
  const double stops = -v0 / a;
  const auto motion = lastingOnFaces(body, faces, 1e-11);
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  EXPECT_EQ(motion->ends, "stops");
  EXPECT_NEAR(motion->until, stops, 2e-6) << "the slip stops at kPivotSlipStops";
  double worst_centre = 0, worst_velocity = 0, worst_spin = 0;
  for (int k = 0; k <= 200; ++k) {
    const double t = std::min(motion->until, stops) * k / 200;
    const V centre(v0 * t + a * t * t / 2, half, half);
    worst_centre = std::max(worst_centre, (motion->centreAt(t) - centre).norm());
    if (t < motion->until) {  // (at it, at rest: the slip's last 1e-6 m/s taken out)
      worst_velocity =
          std::max(worst_velocity, (motion->velocityAt(t) - V(v0 + a * t, 0, 0)).norm());
    }
    worst_spin = std::max(worst_spin, motion->angularVelocityAt(t).norm());
  }
  EXPECT_LT(worst_centre, 1e-9);
  EXPECT_LT(worst_velocity, 1e-8);
  EXPECT_LT(worst_spin, 1e-9);
  // Asked again where it stopped: at rest there for ever, its friction within both cones.
  const auto rest =
      lastingOnFaces(lasting_bodies::bodyAt(body, *motion, motion->until), faces, 1e-11);
  ASSERT_TRUE(rest.ok()) << errorOf(rest);
  EXPECT_EQ(rest->state, ContactState::kResting);
  EXPECT_EQ(rest->until, std::numeric_limits<double>::infinity());
  EXPECT_NEAR(rest->centreAt(9.0).x(), v0 * v0 / (-2 * a), 1e-9);
}

/// The gutter of ABoxSlidingDownAGutter... as a scene: the floor z = 0 (concrete, mu1) and the
/// wall y = 0 (wallboard, mu2), e = 0, gravity tilted by beta along x and gamma towards the wall.
struct Gutter {
  double beta = 20 * M_PI / 180, gamma = 30 * M_PI / 180, mu1 = 0.4, mu2 = 0.3;
  double v0 = 0.6, half = 0.05, mass = 0.5;
  V gravity() const {
    return kG *
           V(std::sin(beta), -std::cos(beta) * std::sin(gamma), -std::cos(beta) * std::cos(gamma));
  }
  double deceleration() const {  // a, < 0
    return kG * (std::sin(beta) - mu1 * std::cos(beta) * std::cos(gamma) -
                 mu2 * std::cos(beta) * std::sin(gamma));
  }
  Scene scene() const {
    Scene scene;
    scene.effects.gravity = true;
    scene.effects.friction = true;
    scene.gravity = gravity();
    EXPECT_TRUE(scene.materials.addMaterial("block", Material{0.0, mu1}, "m").ok());
    EXPECT_TRUE(scene.materials.addMaterial("wallboard", Material{0.0, mu2}, "m").ok());
    EXPECT_TRUE(scene.materials.addPair("block", "concrete", PairCoefficients{0.0, mu1}, "p").ok());
    EXPECT_TRUE(
        scene.materials.addPair("block", "wallboard", PairCoefficients{0.0, mu2}, "p").ok());
    BodySpec body;
    body.id = "block";
    body.mass = mass;
    body.material = "block";
    body.shape = BodyShape::kBox;
    body.size = V::Constant(2 * half);
    scene.bodies = {body};
    scene.obstacles = {scene_builders::plane("floor", V::UnitZ(), 0.0, "concrete"),
                       scene_builders::plane("wall", V::UnitY(), 0.0, "wallboard")};
    return scene;
  }
};

TEST(ShapedFaces, TheMonitorSlidesABoxDownAGutterToTheClosedFormsStopAndRestsItThere) {
  const Gutter gutter;
  const double a = gutter.deceleration(), stops = -gutter.v0 / a;
  ImpactMonitor monitor(gutter.scene(), MonitorSettings{});
  BodyStateSample state;
  state.body = 0;
  state.position = V(0, gutter.half, gutter.half);
  state.velocity = V(gutter.v0, 0, 0);
  StepReport first = monitor.step(0.0, {state});
  EXPECT_TRUE(first.unmodelled.empty());
  double worst = 0.0;
  int unmodelled = 0, impacts = 0;
  for (int k = 1; k <= 100; ++k) {
    const double t = 0.01 * k;
    const StepReport report = monitor.step(t, {});
    unmodelled += static_cast<int>(report.unmodelled.size());
    impacts += static_cast<int>(report.impacts.size());
    const auto at = monitor.predictedState(0, t);
    ASSERT_TRUE(at) << t;
    const double s = std::min(t, stops);
    const V centre(gutter.v0 * s + a * s * s / 2, gutter.half, gutter.half);
    worst = std::max(worst, (at->first - centre).norm());
    if (t < stops - 1e-5) {
      EXPECT_NEAR(at->second.x(), gutter.v0 + a * t, 1e-8) << t;
    } else {
      EXPECT_EQ(at->second, V::Zero()) << t;
    }
    // Both obstacles carry it: their normal forces as the closed form's (1e-9 of the weight),
    // and, at rest, the friction that holds it against gravity along the gutter.
    V floor = V::Zero(), wall = V::Zero();
    for (const ContactRecord& contact : report.contacts) {
      const V on_body = -(contact.normal_force * contact.normal + contact.friction_force);
      (contact.other == 0 ? floor : wall) += on_body;
    }
    const double weight = gutter.mass * kG;
    EXPECT_NEAR(floor.z(), weight * std::cos(gutter.beta) * std::cos(gutter.gamma), 1e-9 * weight)
        << t;
    EXPECT_NEAR(wall.y(), weight * std::cos(gutter.beta) * std::sin(gutter.gamma), 1e-9 * weight)
        << t;
    const double along = floor.x() + wall.x();
    EXPECT_NEAR(along,
                t < stops ? gutter.mass * (a - kG * std::sin(gutter.beta))
                          : -weight * std::sin(gutter.beta),
                1e-9 * weight)
        << t;
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_EQ(unmodelled, 0);
  EXPECT_EQ(impacts, 0);
}

TEST(ShapedFaces, ACanOrACapsuleSlidingDownAGutterDeceleratesAsTheBoxAndRests) {
  // The gutter's closed form holds for any body that slides without turning: a can lying on its
  // side along the gutter (its two rims' lowest points on each face) and a capsule so (its two
  // ends' points on each). (A can standing on its cap does turn: the wall's friction on its side
  // has a moment about its axis that its sliding cap cannot hold.)
  const double beta = 20 * M_PI / 180, gamma = 30 * M_PI / 180, mu1 = 0.4, mu2 = 0.3;
  const double v0 = 0.6, r = 0.04, half_length = 0.08, mass = 0.4;
  const V gravity =
      kG * V(std::sin(beta), -std::cos(beta) * std::sin(gamma), -std::cos(beta) * std::cos(gamma));
  const double a = kG * (std::sin(beta) - mu1 * std::cos(beta) * std::cos(gamma) -
                         mu2 * std::cos(beta) * std::sin(gamma));
  const std::vector<FlatFace> faces = {plane(V::UnitZ(), mu1), plane(V::UnitY(), mu2)};
  const Q along_x(Eigen::AngleAxisd(M_PI / 2, V::UnitY()));  // its axis along the gutter
  struct Case {
    const char* name;
    LastingBody body;
  };
  LastingBody lying =
      lasting_bodies::cylinder(r, half_length, mass, mass * r * r / 2, V(0, r, r), along_x);
  LastingBody capsule = lying;
  capsule.shape = Capsule{r, half_length};
  for (const Case& c : {Case{"lying", lying}, Case{"capsule", capsule}}) {
    SCOPED_TRACE(c.name);
    LastingBody body = c.body;
    body.gravity = gravity;
    body.velocity = V(v0, 0, 0);
    const auto motion = lastingOnFaces(body, faces, 1e-11);
    ASSERT_TRUE(motion.ok()) << errorOf(motion);
    EXPECT_EQ(motion->ends, "stops");
    EXPECT_NEAR(motion->until, -v0 / a, 2e-6);
    double worst = 0.0;
    for (int k = 0; k <= 100; ++k) {
      const double t = motion->until * k / 100;
      const V centre = body.centre + V(v0 * t + a * t * t / 2, 0, 0);
      worst = std::max(worst, (motion->centreAt(t) - centre).norm());
      EXPECT_LT(motion->angularVelocityAt(t).norm(), 1e-9) << t;
    }
    EXPECT_LT(worst, 1e-9);
    const auto rest =
        lastingOnFaces(lasting_bodies::bodyAt(body, *motion, motion->until), faces, 1e-11);
    ASSERT_TRUE(rest.ok()) << errorOf(rest);
    EXPECT_EQ(rest->state, ContactState::kResting);
    EXPECT_EQ(rest->until, std::numeric_limits<double>::infinity());
  }
}

TEST(ShapedFaces, ThePredictionSlidesABoxDownAGutterToTheClosedFormsRest) {
  const Gutter gutter;
  const double a = gutter.deceleration(), stops = -gutter.v0 / a;
  const Scene scene = gutter.scene();
  PredictionRequest request;
  request.body = scene.bodies[0];
  request.state.position = V(0, gutter.half, gutter.half);
  request.state.velocity = V(gutter.v0, 0, 0);
  request.horizon = 1.0;
  request.max_impacts = 4;
  request.sample_period = 0.01;
  request.effects = scene.effects;
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  EXPECT_FALSE(prediction->cut_short) << prediction->message;
  EXPECT_TRUE(prediction->impacts.empty());
  ASSERT_FALSE(prediction->samples.empty());
  for (const BodyStateSample& sample : prediction->samples) {
    const double t = std::min(sample.time, stops);
    EXPECT_NEAR(sample.position.x(), gutter.v0 * t + a * t * t / 2, 1e-9) << sample.time;
  }
  EXPECT_NEAR(prediction->final_state.position.x(), gutter.v0 * gutter.v0 / (-2 * a), 1e-9);
  EXPECT_EQ(prediction->final_state.velocity, V::Zero());
  // It rests on both: each one's contacts at the horizon.
  bool floor = false, wall = false;
  for (const ContactRecord& contact : prediction->contacts) {
    floor = floor || contact.other == 0;
    wall = wall || contact.other == 1;
  }
  EXPECT_TRUE(floor && wall);
}

TEST(ShapedFaces, ABoxSlidingIntoAWallStrikesItPlasticallyAndRestsAgainstIt) {
  // Square to the wall x = 0.5 (e = 0, the floor's mu = 0.4): it slides to it decelerating at mu
  // g, reaches it at v1 = sqrt(v0^2 - 2 mu g d) at (v0 - v1) / (mu g), and stays there.
  Gutter room;
  room.gamma = 0;
  room.beta = 0;
  Scene scene = room.scene();
  scene.obstacles[1] = scene_builders::plane("wall", -V::UnitX(), -0.5, "wallboard");
  const double v0 = 1.5, d = 0.2, mu_g = room.mu1 * kG;
  const double v1 = std::sqrt(v0 * v0 - 2 * mu_g * d), strikes = (v0 - v1) / mu_g;
  ImpactMonitor monitor(scene, MonitorSettings{});
  BodyStateSample state;
  state.body = 0;
  state.position = V(0.5 - room.half - d, 0.3, room.half);
  state.velocity = V(v0, 0, 0);
  monitor.step(0.0, {state});
  std::vector<ImpactRecord> impacts;
  int unmodelled = 0;
  std::vector<ContactRecord> last;
  for (int k = 1; k <= 100; ++k) {
    const StepReport report = monitor.step(0.01 * k, {});
    impacts.insert(impacts.end(), report.impacts.begin(), report.impacts.end());
    unmodelled += static_cast<int>(report.unmodelled.size());
    last = report.contacts;
  }
  // One impact, reported at each point struck: the wall's four corners, and the floor's four
  // (touching as it is struck, they take part).
  ASSERT_FALSE(impacts.empty());
  bool wall_struck = false;
  for (const ImpactRecord& impact : impacts) {
    wall_struck = wall_struck || impact.other == 1;
    EXPECT_NEAR(impact.time, strikes, 1e-9);
    EXPECT_NEAR(impact.velocity_a_before.x(), v1, 1e-9);
    EXPECT_NEAR(impact.velocity_a_after.norm(), 0.0, 1e-9);
  }
  EXPECT_TRUE(wall_struck);
  EXPECT_EQ(unmodelled, 0);
  const auto at = monitor.predictedState(0, 1.0);
  ASSERT_TRUE(at);
  EXPECT_NEAR(at->first.x(), 0.5 - room.half, 1e-9);
  EXPECT_NEAR(at->first.z(), room.half, 1e-9);
  EXPECT_LT(at->second.norm(), 1e-12);  // (the impact's rounding, 1e-20 m/s, carried on)
  // At rest on the floor (its weight) against the wall (no force: nothing presses it there).
  double floor = 0.0, wall = 0.0;
  for (const ContactRecord& contact : last)
    (contact.other == 0 ? floor : wall) += contact.normal_force;
  EXPECT_NEAR(floor, room.mass * kG, 1e-9);
  EXPECT_NEAR(wall, 0.0, 1e-9);
}

TEST(ShapedFaces, ABoxSlidingOntoAWallWithoutStrikingItSlidesOnAlongItToRest) {
  // On the floor (mu 0.4), 2e-9 m from the wall y = 0, sliding along it at 0.05 m/s and towards
  // it at 8e-7 m/s (slower than a strike: kLastingSettled): it touches the wall and slides on
  // along it, on both, until the floor's friction stops it at v0^2 / (2 mu g) along x (the wall
  // carries no force: nothing presses the box on it). Before, it was held where it touched the
  // wall ("not yet: ... without striking it"). (Its approach, 1e-5 of its speed, costs the
  // lasting motion's certified watch for the wall some 6e4 advancement steps.)
  Gutter room;
  room.beta = room.gamma = 0;
  const Scene scene = room.scene();
  ImpactMonitor monitor(scene, MonitorSettings{});
  BodyStateSample state;
  state.body = 0;
  state.position = V(0, room.half + 2e-9, room.half);
  const double v0 = 0.05, mu_g = room.mu1 * kG;
  state.velocity = V(v0, -8e-7, 0);
  monitor.step(0.0, {state});
  int unmodelled = 0;
  std::size_t impacts = 0;
  bool on_wall = false;
  for (int k = 1; k <= 100; ++k) {
    const StepReport report = monitor.step(0.01 * k, {});
    unmodelled += static_cast<int>(report.unmodelled.size());
    impacts += report.impacts.size();
    for (const ContactRecord& contact : report.contacts) on_wall = on_wall || contact.other == 1;
  }
  EXPECT_EQ(unmodelled, 0);
  EXPECT_TRUE(on_wall);
  const auto at = monitor.predictedState(0, 1.0);
  ASSERT_TRUE(at);
  EXPECT_NEAR(at->first.x(), v0 * v0 / (2 * mu_g), 1e-8);
  EXPECT_NEAR(at->first.y(), room.half, 1e-9);
  EXPECT_LT(at->second.norm(), 1e-12);
  EXPECT_EQ(impacts, 0u);
  // The prediction from the same state: the same rest, not cut short at the wall.
  PredictionRequest request;
  request.body = scene.bodies[0];
  request.state = state;
  request.horizon = 1.0;
  request.max_impacts = 4;
  request.effects = scene.effects;
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  EXPECT_FALSE(prediction->cut_short) << prediction->message;
  EXPECT_NEAR(prediction->final_state.position.x(), v0 * v0 / (2 * mu_g), 1e-8);
  EXPECT_NEAR(prediction->final_state.position.y(), room.half, 1e-9);
}

TEST(ShapedFaces, TheMonitorLetsAFrictionlessPlankSlideDownTheWallAsItsEnergyIntegralSays) {
  const Plank plank;
  Gutter room;
  room.beta = room.gamma = 0;
  room.mu1 = room.mu2 = 0;
  Scene scene = room.scene();
  scene.effects.friction = false;
  scene.obstacles[1] = scene_builders::plane("wall", V::UnitX(), 0.0, "wallboard");
  scene.bodies[0].mass = plank.mass;
  scene.bodies[0].size = 2 * V(plank.a, plank.w, plank.b);
  ImpactMonitor monitor(scene, MonitorSettings{});
  const LastingBody body = plank.at(plank.theta0);
  BodyStateSample state;
  state.body = 0;
  state.position = body.centre;
  state.orientation = body.orientation;
  monitor.step(0.0, {state});
  const double leaves = plank.leaves();
  double worst_centre = 0, worst_rate = 0;
  int on_wall = 0, unmodelled = 0;
  for (int k = 1; k <= 200; ++k) {
    const double t = 0.001 * k;
    const StepReport report = monitor.step(t, {});
    unmodelled += static_cast<int>(report.unmodelled.size());
    const bool wall = std::any_of(report.contacts.begin(), report.contacts.end(),
                                  [](const ContactRecord& c) { return c.other == 1; });
    const double theta = Plank::angleOf(monitor.predictedOrientation(0, t));
    if (!wall || theta <= leaves) break;
    ++on_wall;
    const auto at = monitor.predictedState(0, t);
    ASSERT_TRUE(at);
    worst_centre = std::max(worst_centre, (at->first - plank.centre(theta)).norm());
    const double rate = monitor.predictedAngularVelocity(0, t).y();
    worst_rate = std::max(worst_rate, std::abs(rate * rate - static_cast<double>(plank.f(theta))));
  }
  EXPECT_GT(on_wall, 100);
  EXPECT_EQ(unmodelled, 0);
  EXPECT_LT(worst_centre, 1e-9);
  EXPECT_LT(worst_rate, 1e-8);
}

// 30 boxes of random sides and 10 cans standing on their caps, sliding on a floor into a room's
// corner (the walls x = 0.5 and y = 0.5; mu in [0, 1] for each pair, e in [0, 1] against the
// floor, and against the walls 0 for half of them, at random for the others), at 0.5 to 2.5 m/s
// within 36 degrees of the corner's diagonal, turning at up to 5 rad/s about the vertical.
// Through the monitor for 1 s (they strike the walls, slide along them or stay against them,
// tip, come to rest in the corner): no corner (or rim point) inside a wall or the floor (1e-9 m),
// no energy gained from one 5 ms sample to the next (1e-8 J), many samples in lasting contact
// with two obstacles at once, and nothing unmodelled but a wall touched alone in the air (2 of
// the 40: held there, said; doc/model.md, "Against several obstacles at once").
TEST(ShapedFaces, RandomSlidesIntoACornerNeverGoInsideNorGainEnergy) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int against_both = 0, on_a_wall_in_the_air = 0;
  for (int k = 0; k < 40; ++k) {
    std::mt19937 random(4242 + k);
    const bool can = k >= 30;
    Scene scene = shaped_scenes::floorScene(0.5, V(0.05, 0.05, 0.05), 0.2 + unit(random));
    scene.effects.friction = true;
    scene.effects.spin = true;
    scene.materials = MaterialTable{};
    const double wall_e = k % 2 == 0 ? 0.0 : unit(random);
    const std::array<std::pair<const char*, double>, 3> restitutions = {
        {{"block", unit(random)}, {"concrete", unit(random)}, {"wallboard", wall_e}}};
    for (const auto& [name, e] : restitutions) {
      ASSERT_TRUE(scene.materials.addMaterial(name, Material{e, unit(random)}, "m").ok());
    }
    scene.obstacles.push_back(scene_builders::plane("wall_x", -V::UnitX(), -0.5, "wallboard"));
    scene.obstacles.push_back(scene_builders::plane("wall_y", -V::UnitY(), -0.5, "wallboard"));
    BodySpec& body = scene.bodies[0];
    const double height = shaped_scenes::randomBlock(body, can, random);
    const double angle = M_PI / 4 + (2 * unit(random) - 1) * M_PI / 5;
    const double speed = 0.5 + 2 * unit(random);
    BodyStateSample state;
    state.body = 0;
    state.position = V(0.0, 0.0, height);
    state.orientation = Q(Eigen::AngleAxisd(2 * M_PI * unit(random), V::UnitZ()));
    state.velocity = speed * V(std::cos(angle), std::sin(angle), 0);
    state.angular_velocity = V(0, 0, 5 * (2 * unit(random) - 1));
    const shaped_scenes::Played played = shaped_scenes::play(scene, state, 0.005, 1.0);
    for (const StepReport& report : played.reports) {
      for (const UnmodelledContact& c : report.unmodelled) {
        // Not modelled yet, said: a body touching a wall alone in the air, its normal motion 0
        // (a can bouncing on the floor as it strikes the wall plastically).
        if (c.what.rfind("body.gravity: does not press the body onto the face", 0) == 0) {
          ++on_a_wall_in_the_air;
        } else {
          ADD_FAILURE() << k << ": " << c.what;
        }
      }
      std::size_t touched = 0;  // a bit per obstacle
      for (const ContactRecord& c : report.contacts) touched |= std::size_t{1} << c.other;
      if ((touched & (touched - 1)) != 0) ++against_both;
    }
    shaped_scenes::expectOutsideAndNotGaining(played, body, k, [](const V& at) {
      return std::min(0.5 - std::max(at.x(), at.y()), at.z());
    });
  }
  EXPECT_GT(against_both, 100) << "samples in lasting contact with two obstacles at once";
  EXPECT_LE(on_a_wall_in_the_air, 2);
  std::printf("samples on two obstacles at once: %d; held on a wall in the air: %d of 40\n",
              against_both, on_a_wall_in_the_air);
}

TEST(ShapedFaces, WhatIsNotModelledOrWrongIsNamed) {
  const Plank plank;
  const LastingBody body = plank.at(plank.theta0);
  EXPECT_EQ(errorOf(lastingOnFaces(body, {})), "faces: must hold at least one face");
  // Inside the second face: named; 0.1 m off it, it carries nothing (the plank falls freely
  // along its floor, frictionless, until it meets the wall or lands).
  std::vector<FlatFace> inside = floorAndWall(0, 0);
  inside[1].point = V(0.1, 0, 0);
  EXPECT_NE(errorOf(lastingOnFaces(body, inside)).find("faces[1]: the body's lowest point"),
            std::string::npos)
      << errorOf(lastingOnFaces(body, inside));
  std::vector<FlatFace> off = floorAndWall(0, 0);
  off[1].point = V(-0.1, 0, 0);
  const auto falls = lastingOnFaces(body, off, 1e-11);
  ASSERT_TRUE(falls.ok()) << errorOf(falls);
  for (const SupportForce& force : falls->forcesAt(0.0)) EXPECT_EQ(force.face, 0u);
  std::vector<FlatFace> neither = off;
  neither[0].point = V(0, 0, -0.1);
  EXPECT_EQ(errorOf(lastingOnFaces(body, neither)),
            "body.centre: touches none of the faces (within 1e-09 m)");
  std::vector<FlatFace> zero = floorAndWall(0, 0);
  zero[1].normal = V::Zero();
  EXPECT_EQ(errorOf(lastingOnFaces(body, zero)).rfind("faces[1].normal", 0), 0u)
      << errorOf(lastingOnFaces(body, zero));
}

}  // namespace
}  // namespace collision_response::core
