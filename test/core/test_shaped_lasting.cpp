// A shaped body's lasting contact with one flat face (contact/shaped_lasting.h), against closed
// forms worked by hand in the comments (rational where the geometry allows: the incline of
// tan theta = 3/4, sin 3/5, cos 4/5): resting (a cube's m g / 4 per corner, a box and a standing
// cylinder leaning their weight downhill, an off-centre body whose far corner the rule leaves
// unloaded), sliding (to a stop at |v| / (mu g) after v^2 / (2 mu g), down a steep incline for
// ever, up one to a stop), rolling (2/3 g sin theta for a solid cylinder, a given J's own), a
// slip that ends in a roll at its closed-form instant, a table top's edge, the accumulation
// instant of flat bounces, and what is refused by name. Every motion is sampled over its span:
// no point below the face, no energy gained, no force < 0.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <random>
#include <string>

#include <Eigen/LU>

#include "contact/shaped_lasting.h"
#include "lasting_bodies.h"

namespace collision_response::core {
namespace {

using namespace lasting_bodies;  // NOLINT(google-build-using-namespace): the tests' bodies

// The incline rising along +x with tan theta = 3/4: its normal (-sin, 0, cos), up the slope
// (cos, 0, sin), down the slope the opposite.
const V kInclineNormal(-0.6, 0.0, 0.8);
const V kUphill(0.8, 0.0, 0.6);
constexpr double kSin = 0.6, kCos = 0.8;

/// World from body: the body's x up the slope, y across it, z along the incline's normal.
Q onIncline() {
  Eigen::Matrix3d r;
  r.col(0) = kUphill;
  r.col(1) = V::UnitY();
  r.col(2) = kInclineNormal;
  return Q(r);
}

/// World from body: the body's z (a cylinder's axis) across the incline (world y), its x along
/// the incline's normal.
Q sideOnIncline() {
  Eigen::Matrix3d r;
  r.col(0) = kInclineNormal;
  r.col(1) = kUphill;
  r.col(2) = V::UnitY();
  return Q(r);
}

double lowest(const LastingBody& body, const FlatFace& face, const LastingMotion& motion,
              double t) {
  const Eigen::Matrix3d r = motion.orientationAt(t).toRotationMatrix();
  const V& n = face.normal;
  return n.dot(motion.centreAt(t) + r * coreSupport(body.shape, r.transpose() * -n) - face.point) -
         marginOf(body.shape);
}

/// Over [start, until] (or `horizon` s of a motion that lasts for ever), at 201 instants: no
/// point of the body below the face (beyond 1e-12 m: the rotations' rounding), the energy never
/// above the start's (`energy_tolerance`, 1e-12 for a closed form, of the body's m g reach and
/// kinetic energy), nor the start's above
/// the body's own, every normal force >= 0 and every friction within mu times it.
void expectNeverBelowNorGaining(const LastingBody& body, const FlatFace& face,
                                const LastingMotion& motion, double horizon = 2.0,
                                double energy_tolerance = 1e-12) {
  const double end = std::isfinite(motion.until) ? motion.until : motion.start + horizon;
  const double reach = reachOf(body.shape);
  const double scale = body.mass * (body.gravity.norm() * reach + body.velocity.squaredNorm()) +
                       body.angular_velocity.squaredNorm() * body.moments.maxCoeff();
  LastingMotion given = motion;
  given.velocity0 = body.velocity;
  given.angular_velocity0 = body.angular_velocity;
  const double start = energy(body, motion, motion.start);
  EXPECT_LE(start, energy(body, given, motion.start) + 1e-12 * scale);
  for (int k = 0; k <= 200; ++k) {
    const double t = motion.start + (end - motion.start) * k / 200.0;
    EXPECT_GE(lowest(body, face, motion, t), -1e-12) << "at t = " << t;
    const double now = energy(body, motion, t);
    EXPECT_LE(now, start + energy_tolerance * scale) << "at t = " << t;
    // A tipping's events are found to their resolution: there a force may pass its bound by
    // that much (1e-12 of m g for a normal force reaching 0, 1e-9 for a friction its cone).
    const double slack = motion.pivot ? body.mass * body.gravity.norm() : 0.0;
    for (const SupportForce& force : motion.forcesAt(t)) {
      EXPECT_GE(force.normal_force, -1e-12 * slack);
      EXPECT_LE(force.friction_force.norm(),
                face.friction * force.normal_force * (1 + 1e-12) + 1e-9 * slack)
          << std::setprecision(17) << force.normal_force << " mu " << face.friction << " state "
          << toString(motion.stateAt(t));
      EXPECT_NEAR(face.normal.dot(force.point - face.point), 0.0, 1e-12);
    }
  }
}

/// The forces' sum is m (a - g) and their moment about the centre of mass the turning's
/// I alpha (0 for a body that does not turn), each within `tolerance` of m g and m g reach.
void expectBalance(const LastingBody& body, const FlatFace& face, const LastingMotion& motion,
                   double tolerance) {
  V force = V::Zero(), torque = V::Zero();
  for (const SupportForce& f : motion.forces) {
    const V total = f.normal_force * face.normal + f.friction_force;
    force += total;
    torque += (f.point - body.centre).cross(total);
  }
  const double weight = body.mass * body.gravity.norm();
  EXPECT_LE((force - body.mass * (motion.acceleration - body.gravity)).norm(), tolerance * weight);
  const Eigen::Matrix3d r = motion.orientation0.toRotationMatrix();
  const V turning = r * body.moments.asDiagonal() * r.transpose() * motion.angular_acceleration;
  EXPECT_LE((torque - turning).norm(), tolerance * weight * reachOf(body.shape));
}

/// A tipping (pivotOnFace: integrated to 1e-9): sound over its span, its energy to 1e-8.
void expectTips(const LastingBody& body, const FlatFace& face,
                const Expected<LastingMotion>& motion) {
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  ASSERT_TRUE(motion->pivot);
  expectNeverBelowNorGaining(body, face, *motion, 1.0, 1e-8);
}

/// Refused, the reason saying `words` (what is not modelled yet, by name).
void expectNotYet(const Expected<LastingMotion>& refused, const std::string& words) {
  ASSERT_FALSE(refused.ok()) << "expected a refusal saying " << words;
  EXPECT_NE(refused.error().reason.find(words), std::string::npos) << refused.error().message();
}

}  // namespace

TEST(ShapedLasting, ACubeRestingFlatCarriesAQuarterOfItsWeightAtEachCorner) {
  // The 10.48 cm, 0.37 kg cube on a floor: by symmetry and the rule (least norm), m g / 4 at each
  // corner, no friction, at rest for ever.
  const double half = 0.0524, m = 0.37;
  const LastingBody body = box(V(half, half, half), m, V(0, 0, half));
  const FlatFace floor = plane(V::UnitZ(), 0.5);
  const auto motion = lastingOnFace(body, floor);
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  EXPECT_EQ(motion->state, ContactState::kResting);
  EXPECT_TRUE(std::isinf(motion->until));
  EXPECT_EQ(motion->ends, "");
  EXPECT_EQ(motion->velocity0, V::Zero());
  EXPECT_EQ(motion->acceleration, V::Zero());
  ASSERT_EQ(motion->forces.size(), 4u);
  double sum = 0;
  for (const SupportForce& force : motion->forces) {
    EXPECT_DOUBLE_EQ(force.normal_force, m * kG / 4);
    EXPECT_EQ(force.friction_force, V::Zero());
    EXPECT_NEAR(std::abs(force.point.x()), half, 1e-17);
    EXPECT_NEAR(std::abs(force.point.y()), half, 1e-17);
    EXPECT_EQ(force.point.z(), 0.0);
    sum += force.normal_force;
  }
  EXPECT_DOUBLE_EQ(sum, m * kG);
  expectBalance(body, floor, *motion, 1e-15);
  expectNeverBelowNorGaining(body, floor, *motion);

  // Turned by 0.7 rad about the vertical: the same quarters (its corners still symmetric about
  // the centre), to rounding.
  const LastingBody turned =
      box(V(half, half, half), m, V(0, 0, half), Q(Eigen::AngleAxisd(0.7, V::UnitZ())));
  const auto again = lastingOnFace(turned, floor);
  ASSERT_TRUE(again.ok()) << errorOf(again);
  for (const SupportForce& force : again->forces) {
    EXPECT_NEAR(force.normal_force, m * kG / 4, 1e-14 * m * kG);
  }
}

TEST(ShapedLasting, ACubeThatSettledRestsWithItsResidualMotionDropped) {
  // The shaped motion takes a contact to last where no point's normal motion could lift it by
  // more than 1e-6 of the body's reach (an elastic rise u^2 / (2 g)): for the cube (reach
  // 0.0524 sqrt 3 = 0.0908 m) u up to sqrt(2 g 1e-6 0.0908) = 1.33e-3 m/s, a tilt whose far corners
  // are up to 9.08e-8 m above the lowest. Such a cube rests, that motion dropped (energy lost);
  // beyond it, refused.
  const double half = 0.0524, m = 0.37;
  const FlatFace floor = plane(V::UnitZ(), 0.5);
  LastingBody body = box(V(half, half, half), m, V(0, 0, half));
  body.velocity = V(0, 0, -1e-3);
  body.angular_velocity = V(5e-3, 0, 0);  // rocking: its corners' normal speeds +-2.6e-4 m/s
  const auto settled = lastingOnFace(body, floor);
  ASSERT_TRUE(settled.ok()) << errorOf(settled);
  EXPECT_EQ(settled->state, ContactState::kResting);
  EXPECT_EQ(settled->velocity0, V::Zero());
  EXPECT_EQ(settled->angular_velocity0, V::Zero());
  expectNeverBelowNorGaining(body, floor, *settled);
  body.velocity = V(0, 0, -2e-3);
  body.angular_velocity = V::Zero();
  const auto approaching = lastingOnFace(body, floor);
  ASSERT_FALSE(approaching.ok());
  EXPECT_EQ(approaching.error().field, "body.velocity");
  // Tilted by 5e-7 rad about x: its corners 2 half sin(5e-7) = 5.2e-8 m apart in height, within
  // the settled band: it rests on its four corners, about m g / 4 each (the tilt moves the
  // centre's foot by half 5e-7 of the face's 0.0524 m half width).
  const Q tilt(Eigen::AngleAxisd(5e-7, V::UnitX()));
  const auto lowestCorner = [&](const Q& turn) {
    double z = 0;
    for (const double x : {-half, half}) {
      for (const double y : {-half, half}) {
        for (const double c : {-half, half}) z = std::min(z, (turn * V(x, y, c)).z());
      }
    }
    return -z;
  };
  const auto tilted =
      lastingOnFace(box(V(half, half, half), m, V(0, 0, lowestCorner(tilt)), tilt), floor);
  ASSERT_TRUE(tilted.ok()) << errorOf(tilted);
  ASSERT_EQ(tilted->forces.size(), 4u);
  for (const SupportForce& force : tilted->forces) {
    EXPECT_NEAR(force.normal_force, m * kG / 4, 1e-5 * m * kG);
  }
  // Tilted by 5e-6 rad (5.2e-7 m): on an edge, which it tips over (pivotOnFace), its two
  // corners carrying it.
  const Q more(Eigen::AngleAxisd(5e-6, V::UnitX()));
  const LastingBody edge = box(V(half, half, half), m, V(0, 0, lowestCorner(more)), more);
  const auto on_edge = lastingOnFace(edge, floor);
  expectTips(edge, floor, on_edge);
  ASSERT_TRUE(on_edge.ok());
  EXPECT_EQ(on_edge->forces.size(), 2u);
}

TEST(ShapedLasting, AFaceWhoseFourthCornerIsJustBeyondTheBandRestsOnAllFour) {
  // A cube (h = 0.05 m) turned by e about x and about y (e small): its bottom corners' heights
  // over the lowest, (h, -h), are 2 e h at (h, h) and (-h, -h) and 4 e h at (-h, h). With 2 e h =
  // 0.8 of a settled body's band (1e-6 of its reach h sqrt 3), three corners are within it and
  // the fourth at 1.6 of it: the face rests on all four (the fourth's height is the three's
  // h1 + h3 - h2), not balanced on its diagonal; the forces are each near m g / 4.
  const double half = 0.05, m = 0.4;
  const double band = 1e-6 * half * std::sqrt(3.0), e = 0.4 * band / half;
  const Q turn = Q(Eigen::AngleAxisd(e, V::UnitX())) * Q(Eigen::AngleAxisd(-e, V::UnitY()));
  double lowest = 0;
  for (const double x : {-half, half}) {
    for (const double y : {-half, half}) lowest = std::min(lowest, (turn * V(x, y, -half)).z());
  }
  const LastingBody body = box(V(half, half, half), m, V(0, 0, -lowest), turn);
  const FlatFace floor = plane(V::UnitZ(), 0.5);
  const auto motion = lastingOnFace(body, floor);
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  EXPECT_FALSE(motion->pivot);
  EXPECT_EQ(motion->state, ContactState::kResting);
  ASSERT_EQ(motion->forces.size(), 4u);
  for (const SupportForce& force : motion->forces) {
    EXPECT_NEAR(force.normal_force, m * kG / 4, 1e-4 * m * kG);
  }
}

TEST(ShapedLasting, ABoxRestingOnAnInclineWithinFrictionLeansItsWeightDownhill) {
  // Half sizes a = 0.5 up the slope, b = 0.3 across, c = 0.2 along the normal, 2 kg, on the
  // incline tan theta = 3/4 with mu = 0.8 >= 3/4: static friction holds it. N = m g cos theta;
  // friction m g sin theta up the slope. The moment about the centre puts the centre of pressure
  // c tan theta = 0.15 m down the slope of the centre's foot (the centre's projection along g).
  // The rule's shares f_i = l0 + l1 x_i + l2 y_i (x up the slope, y across, from the face's
  // centre): sum f = 4 l0 = N, sum f x = 4 a^2 l1 = N (-0.15), sum f y = 4 b^2 l2 = 0, so
  // f = N / 4 (1 + x_i (-0.15) / a^2): the lower corners N / 4 (1 + 0.3) = 0.325 N, the upper
  // N / 4 (1 - 0.3) = 0.175 N; each one's friction f_i tan theta, up the slope.
  const double a = 0.5, b = 0.3, c = 0.2, m = 2;
  const LastingBody body = box(V(a, b, c), m, c * kInclineNormal, onIncline());
  const FlatFace incline = plane(kInclineNormal, 0.8);
  const auto motion = lastingOnFace(body, incline);
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  EXPECT_EQ(motion->state, ContactState::kResting);
  const double N = m * kG * kCos;
  ASSERT_EQ(motion->forces.size(), 4u);
  for (const SupportForce& force : motion->forces) {
    const double up = force.point.dot(kUphill);
    ASSERT_NEAR(std::abs(up), a, 1e-15);
    const double expected = up < 0 ? 0.325 * N : 0.175 * N;
    EXPECT_NEAR(force.normal_force, expected, 1e-14 * N);
    EXPECT_LE((force.friction_force - expected * 0.75 * kUphill).norm(), 1e-14 * N);
  }
  expectBalance(body, incline, *motion, 1e-14);
  expectNeverBelowNorGaining(body, incline, *motion);

  // The same box at mu = 0.75 exactly (tan theta) would hold in exact arithmetic; at 0.7 it
  // slides from rest at g (sin - mu cos) = 0.04 g down the slope.
  const auto slides = lastingOnFace(body, plane(kInclineNormal, 0.7));
  ASSERT_TRUE(slides.ok()) << errorOf(slides);
  EXPECT_EQ(slides->state, ContactState::kSliding);
  EXPECT_LE((slides->acceleration + kG * (kSin - 0.7 * kCos) * kUphill).norm(), 1e-14 * kG);
}

/// A hexagonal prism hull (a tool's flat side: a regular hexagon of circumradius r, corners at
/// angles k pi / 3, 2 h thick) whose centre of mass is `offset` along x from the hexagon's centre.
LastingBody hexagonalPrism(double r, double h, double offset) {
  LastingBody body;
  ConvexHull hull;
  for (const double z : {-h, h}) {
    for (int k = 0; k < 6; ++k) {
      hull.vertices.emplace_back(r * std::cos(k * M_PI / 3) - offset, r * std::sin(k * M_PI / 3),
                                 z);
    }
  }
  body.shape = hull;
  body.mass = 0.8;
  body.moments = V(0.004, 0.004, 0.006);
  body.centre = V(0, 0, h);
  body.gravity = kDown;
  return body;
}

TEST(ShapedLasting, AHexagonalToolRestsOnItsSixCornersByTheLeastNormRule) {
  // A hexagon's six corners q_k = r (cos, sin)(k pi / 3), the centre of pressure p = (p_x, 0)
  // from its centre. The least-norm shares are f = l0 + l1 x + l2 y with sum 1 = 6, sum x = 0,
  // sum x^2 = 3 r^2: f_k = N (1/6 + p_x x_k / (3 r^2)). At p_x = 0.3 r: N (1/6 + 0.1 cos). At
  // p_x = 0.6 r that gives the corner at x = -r N (1/6 - 0.2) < 0: the least-norm f >= 0 leaves it
  // out; on the other five, sum 1 = 5, sum x = r, sum x^2 = 2 r^2: 5 l0 + r l1 = N,
  // r l0 + 2 r^2 l1 = N p_x, so l0 = N (2 r - p_x) / (9 r), l1 = N (5 p_x - r) / (9 r^2): the
  // corner at x = r 6.8 N / 18, those at r / 2 4.8 N / 18, those at -r / 2 0.8 N / 18, and
  // l0 - l1 r = N (3 r - 6 p_x) / (9 r) <= 0 where the sixth is left out (its optimality). Before,
  // a face of more than four points was refused (`not yet`). Past the hexagon (p_x = 1.2 r) it
  // tips over its two corners at x = r / 2... r.
  const double r = 0.06, h = 0.01, N = 0.8 * kG;
  const FlatFace floor = plane(V::UnitZ(), 0.0);
  for (const double p : {0.0, 0.3, 0.6}) {
    const LastingBody body = hexagonalPrism(r, h, p * r);
    const auto motion = lastingOnFace(body, floor);
    ASSERT_TRUE(motion.ok()) << errorOf(motion);
    EXPECT_EQ(motion->state, ContactState::kResting);
    ASSERT_EQ(motion->forces.size(), 6u) << p;
    for (const SupportForce& force : motion->forces) {
      const double x = (force.point.x() + p * r) / r;  // the corner's x / r about the hexagon
      double expected = N * (1.0 / 6 + p * x / 3);
      if (p == 0.6) {
        expected = x > 0.9 ? 6.8 : (x > 0 ? 4.8 : (x > -0.9 ? 0.8 : 0.0));
        expected *= N / 18;
      }
      EXPECT_NEAR(force.normal_force, expected, 1e-13 * N) << "p " << p << " x " << x;
    }
    expectBalance(body, floor, *motion, 1e-14);
  }
  const LastingBody past = hexagonalPrism(r, h, 1.2 * r);
  expectTips(past, floor, lastingOnFace(past, floor));
  // 200 centres of mass anywhere within the hexagon (0.95 of its inradius), any way: the forces
  // are >= 0, balance (1e-13 N), and are the least in norm: optimality's certificate, that some
  // l gives f_k = l . (1, x_k, y_k) on the corners that carry and l . (1, x_k, y_k) <= 0 on those
  // that do not (the l fitted here to the carrying ones, 1e-12 N).
  std::mt19937 random(61);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const double rho = 0.95 * std::sqrt(3.0) / 2 * r * std::sqrt(unit(random));
    const double angle = 2 * M_PI * unit(random);
    LastingBody body = hexagonalPrism(r, h, 0.0);
    for (V& vertex : std::get<ConvexHull>(body.shape).vertices) {
      vertex -= V(rho * std::cos(angle), rho * std::sin(angle), 0);
    }
    const auto motion = lastingOnFace(body, floor);
    ASSERT_TRUE(motion.ok()) << errorOf(motion);
    ASSERT_EQ(motion->forces.size(), 6u);
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    V moment = V::Zero();
    for (const SupportForce& force : motion->forces) {
      EXPECT_GE(force.normal_force, 0.0);
      const V b(1, force.point.x(), force.point.y());
      if (force.normal_force > 1e-12 * N) {
        normal += b * b.transpose();
        moment += force.normal_force * b;
      }
    }
    const V l = normal.fullPivLu().solve(moment);
    for (const SupportForce& force : motion->forces) {
      const double linear = l.dot(V(1, force.point.x(), force.point.y()));
      if (force.normal_force > 1e-12 * N) {
        EXPECT_NEAR(force.normal_force, linear, 1e-12 * N) << trial;
      } else {
        EXPECT_LE(linear, 1e-12 * N) << trial;
      }
    }
    expectBalance(body, floor, *motion, 1e-13);
  }
}

TEST(ShapedLasting, AnOffCentreBodyLeavesItsFarCornerUnloadedWhereTheLinearRuleWouldPull) {
  // A hull (a box's corners) whose centre of mass is off its face's centre: x, y in {-0.2, 0.8},
  // on a floor, the centre of pressure at the centre's foot, (-0.3, -0.3) from the face's centre,
  // a = b = 0.5. The linear rule's shares N / 4 (1 + s_x (-0.3) / 0.5 + s_y (-0.3) / 0.5) give
  // the corner (+, +) N / 4 (1 - 1.2) < 0. The balance leaves one free direction, k_i = s_x s_y
  // (sum k = sum k x = sum k y = 0), orthogonal to the linear shares: the least |f| with f >= 0 is
  // where (+, +) is 0, t = N / 4 (0.2): (-, -) N / 4 (2.2 + 0.2) = 0.6 N, (+, -) and (-, +)
  // N / 4 (1 - 0.2) = 0.2 N. (Their sum N, their moment 0.6 (-0.5) + 0.2 (0.5 - 0.5) = -0.3 N.)
  LastingBody body;
  ConvexHull hull;
  for (const double x : {-0.2, 0.8}) {
    for (const double y : {-0.2, 0.8}) {
      for (const double z : {-0.1, 0.1}) hull.vertices.emplace_back(x, y, z);
    }
  }
  body.shape = hull;
  body.mass = 1.5;
  body.moments = V(0.2, 0.3, 0.4);
  body.centre = V(0, 0, 0.1);
  body.gravity = kDown;
  const FlatFace floor = plane(V::UnitZ(), 0.0);
  const auto motion = lastingOnFace(body, floor);
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  const double N = 1.5 * kG;
  ASSERT_EQ(motion->forces.size(), 4u);
  for (const SupportForce& force : motion->forces) {
    const bool low_x = force.point.x() < 0, low_y = force.point.y() < 0;
    const double expected = low_x && low_y ? 0.6 * N : (!low_x && !low_y ? 0.0 : 0.2 * N);
    EXPECT_NEAR(force.normal_force, expected, 1e-14 * N);
  }
  expectBalance(body, floor, *motion, 1e-14);
  expectNeverBelowNorGaining(body, floor, *motion);
}

TEST(ShapedLasting, RandomBodiesRestOnTheLeastNonNegativeForcesOrTipWhereTheirCentreIsOff) {
  // 600 hulls (a box's corners, its centre of mass anywhere over its base or a little beyond it)
  // resting on random inclines (up to 0.5 rad, mu = 10), turned about the normal at random. The
  // test's own criterion: the centre's projection along g onto the face, in the body's axes,
  // strictly inside the base rectangle: then a rest whose forces balance (expectBalance), are
  // >= 0, and whose squared norm no feasible move along the balance's free direction (the
  // kernel of the 3x4 balance, by a full-pivot LU of the test's) lowers (1,000 steps over the
  // feasible interval); outside, it tips (expectTips).
  std::mt19937 random(20261206);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int rests = 0, unloaded = 0, tips = 0;
  for (int k = 0; k < 600; ++k) {
    const double a = 0.1 + 0.4 * unit(random), b = 0.1 + 0.4 * unit(random);
    const double c = 0.05 + 0.3 * unit(random);
    const double x0 = -2 * a * (-0.1 + 1.2 * unit(random));
    const double y0 = -2 * b * (-0.1 + 1.2 * unit(random));
    ConvexHull hull;
    for (const double x : {x0, x0 + 2 * a}) {
      for (const double y : {y0, y0 + 2 * b}) {
        for (const double z : {-c, 0.1}) hull.vertices.emplace_back(x, y, z);
      }
    }
    const double tilt = 0.5 * unit(random), azimuth = 2 * M_PI * unit(random);
    const V n(std::sin(tilt) * std::cos(azimuth), std::sin(tilt) * std::sin(azimuth),
              std::cos(tilt));
    const Q turn =
        Q(Eigen::AngleAxisd(2 * M_PI * unit(random), n)) * Q::FromTwoVectors(V::UnitZ(), n);
    LastingBody body;
    body.shape = hull;
    body.mass = 1 + 2 * unit(random);
    body.moments = V(0.1, 0.2, 0.3);
    body.orientation = turn;
    body.centre = c * n;
    body.gravity = kDown;
    const FlatFace face = plane(n, 10.0);
    // The centre's projection along g onto the face n.x = 0, in the body's axes.
    const V projected = body.centre + body.gravity * (n.dot(body.centre) / -body.gravity.dot(n));
    const V local = turn.conjugate() * (projected - body.centre);
    const double inside =
        std::min({local.x() - x0, x0 + 2 * a - local.x(), local.y() - y0, y0 + 2 * b - local.y()});
    if (std::abs(inside) < 1e-9) continue;
    const auto motion = lastingOnFace(body, face);
    if (inside < 0) {
      ++tips;
      expectTips(body, face, motion);
      continue;
    }
    ++rests;
    ASSERT_TRUE(motion.ok()) << k << ": " << errorOf(motion);
    EXPECT_EQ(motion->state, ContactState::kResting);
    ASSERT_EQ(motion->forces.size(), 4u);
    expectBalance(body, face, *motion, 1e-12);
    const V e1 = turn * V::UnitX(), e2 = turn * V::UnitY();
    Eigen::Matrix<double, 3, 4> balance;
    Eigen::Vector4d f;
    for (int i = 0; i < 4; ++i) {
      const SupportForce& force = motion->forces[static_cast<std::size_t>(i)];
      balance.col(i) = V(1, force.point.dot(e1), force.point.dot(e2));
      f[i] = force.normal_force;
      EXPECT_GE(f[i], 0.0);
    }
    if (f.minCoeff() < 1e-12 * body.mass * kG) ++unloaded;
    const Eigen::Vector4d free = Eigen::FullPivLU<Eigen::Matrix<double, 3, 4>>(balance).kernel();
    double lo = -INFINITY, hi = INFINITY;
    for (int i = 0; i < 4; ++i) {
      if (free[i] > 0) lo = std::max(lo, -f[i] / free[i]);
      if (free[i] < 0) hi = std::min(hi, -f[i] / free[i]);
    }
    for (int step = 0; step <= 1000; ++step) {
      const double t = lo + (hi - lo) * step / 1000.0;
      EXPECT_GE((f + t * free).squaredNorm(), f.squaredNorm() * (1 - 1e-12)) << k;
    }
  }
  EXPECT_GT(rests, 200);
  EXPECT_GT(unloaded, 20);  // the least-norm shares >= 0 where the linear rule would pull
  EXPECT_GT(tips, 20);
}

TEST(ShapedLasting, AStandingCylinderOnAnInclineLeansItsWeightTowardsItsLowerRim) {
  // r = 0.2, half length 0.1, 1 kg, standing on its cap on the incline (mu = 1): the centre of
  // pressure 0.1 x 3/4 = 0.075 m down the slope of the cap's centre. The rim points chosen there,
  // a quarter turn either side and opposite (+-r along p, +-r across): the shares
  // l0 + l1 x + l2 y with sum 4 l0 = N, sum x^2 = 2 r^2 so l1 = N p / (2 r^2): the lower point
  // N (1/4 + p / (2 r)) = 0.4375 N, the upper 0.0625 N, the two across N / 4.
  const double r = 0.2, h = 0.1, m = 1;
  const LastingBody body = cylinder(r, h, m, m * r * r / 2, h * kInclineNormal, onIncline());
  const FlatFace incline = plane(kInclineNormal, 1.0);
  const auto motion = lastingOnFace(body, incline);
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  EXPECT_EQ(motion->state, ContactState::kResting);
  const double N = m * kG * kCos;
  ASSERT_EQ(motion->forces.size(), 4u);
  for (const SupportForce& force : motion->forces) {
    const double up = force.point.dot(kUphill);
    const double expected = up < -0.1 ? 0.4375 * N : (up > 0.1 ? 0.0625 * N : 0.25 * N);
    EXPECT_NEAR(force.normal_force, expected, 1e-14 * N);
  }
  expectBalance(body, incline, *motion, 1e-14);
  expectNeverBelowNorGaining(body, incline, *motion);
  // Taller (h = 0.3): h tan theta = 0.225 > r, it tips over its lower rim's point, which alone
  // carries it (pivotOnRound): sound over its motion.
  const LastingBody tall = cylinder(r, 0.3, m, m * r * r / 2, 0.3 * kInclineNormal, onIncline());
  const auto tips = lastingOnFace(tall, incline);
  expectTips(tall, incline, tips);
  ASSERT_EQ(tips->forcesAt(tips->start).size(), 1u);
  EXPECT_LT(tips->forcesAt(tips->start)[0].point.dot(kUphill), -0.1) << "its lower rim";
}

TEST(ShapedLasting, ABoxSlidingOnAFloorStopsAfterVOverMuGAtVSquaredOverTwoMuG) {
  // Half sizes (0.3, 0.2, 0.1), 3 kg, at 2 m/s along (0.6, 0.8), mu = 0.5: a = -mu g v_hat until
  // t = |v| / (mu g), after |v|^2 / (2 mu g). While it slides the friction's moment about the
  // centre puts the centre of pressure mu c = 0.05 m ahead of the centre's foot.
  const double m = 3, mu = 0.5;
  LastingBody body = box(V(0.3, 0.2, 0.1), m, V(1, -2, 0.1));
  body.time = 4;
  const V ahead(0.6, 0.8, 0);
  body.velocity = 2 * ahead;
  const FlatFace floor = plane(V::UnitZ(), mu);
  const auto motion = lastingOnFace(body, floor);
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  EXPECT_EQ(motion->state, ContactState::kSliding);
  EXPECT_EQ(motion->ends, "stops");
  EXPECT_NEAR(motion->until, 4 + 2 / (mu * kG), 1e-15 * 4);
  EXPECT_LE((motion->acceleration + mu * kG * ahead).norm(), 1e-15 * kG);
  const V travelled = motion->centreAt(motion->until) - body.centre;
  EXPECT_LE((travelled - 4 / (2 * mu * kG) * ahead).norm(), 1e-14);
  EXPECT_LE(motion->velocityAt(motion->until).norm(), 1e-14);
  expectBalance(body, floor, *motion, 1e-14);
  expectNeverBelowNorGaining(body, floor, *motion);
  // The shares: the corners ahead carry more. In the box's axes (x, y), p = 0.05 (0.6, 0.8):
  // f = N / 4 (1 + x p_x / a^2 + y p_y / b^2) = N / 4 (1 + s_x 0.03 / 0.3 + s_y 0.04 / 0.2).
  const double N = m * kG;
  for (const SupportForce& force : motion->forces) {
    const double sx = force.point.x() > 1 ? 1 : -1, sy = force.point.y() > -2 ? 1 : -1;
    EXPECT_NEAR(force.normal_force, N / 4 * (1 + 0.1 * sx + 0.2 * sy), 1e-14 * N);
    EXPECT_LE((force.friction_force + mu * force.normal_force * ahead).norm(), 1e-14 * N);
  }
  // Asked again from its state at the stop: it rests.
  LastingBody stopped = body;
  stopped.time = motion->until;
  stopped.centre = motion->centreAt(motion->until);
  stopped.velocity = motion->velocityAt(motion->until);
  const auto rests = lastingOnFace(stopped, floor);
  ASSERT_TRUE(rests.ok()) << errorOf(rests);
  EXPECT_EQ(rests->state, ContactState::kResting);
}

TEST(ShapedLasting, ABoxOnASteepInclineSlidesDownForEverAndUpItToAStop) {
  // tan theta = 3/4 > mu = 0.5: from rest a = g (sin - mu cos) = 0.2 g down the slope, for ever.
  // The centre of pressure h (g_t - a) / g_n = 0.2 (0.4 g) / (0.8 g) = 0.1 m down the slope: the
  // lower corners N / 4 (1 + 0.1 / 0.5), the upper N / 4 (1 - 0.2).
  const double a = 0.5, b = 0.3, c = 0.2, m = 2, mu = 0.5;
  LastingBody body = box(V(a, b, c), m, c * kInclineNormal, onIncline());
  const FlatFace incline = plane(kInclineNormal, mu);
  const auto down = lastingOnFace(body, incline);
  ASSERT_TRUE(down.ok()) << errorOf(down);
  EXPECT_EQ(down->state, ContactState::kSliding);
  EXPECT_TRUE(std::isinf(down->until));
  EXPECT_LE((down->acceleration + 0.2 * kG * kUphill).norm(), 1e-14 * kG);
  const double N = m * kG * kCos;
  for (const SupportForce& force : down->forces) {
    const double expected = force.point.dot(kUphill) < 0 ? 0.3 * N : 0.2 * N;
    EXPECT_NEAR(force.normal_force, expected, 1e-14 * N);
    EXPECT_LE((force.friction_force - mu * force.normal_force * kUphill).norm(), 1e-14 * N);
  }
  expectBalance(body, incline, *down, 1e-14);
  expectNeverBelowNorGaining(body, incline, *down);

  // Up the slope at 3 m/s: a = -g (sin + mu cos) = -g, it stops after 3 / g s.
  body.velocity = 3 * kUphill;
  const auto up = lastingOnFace(body, incline);
  ASSERT_TRUE(up.ok()) << errorOf(up);
  EXPECT_EQ(up->ends, "stops");
  EXPECT_NEAR(up->until, 3 / kG, 1e-15);
  EXPECT_LE((up->acceleration + kG * kUphill).norm(), 1e-14 * kG);
  expectNeverBelowNorGaining(body, incline, *up);

  // Across the slope the slide's direction turns (no closed form here): its corners slide on
  // the incline, each by Coulomb's law (pivotOnFace; the closed form of its turning,
  // ShapedMonitor.ACubeSlidingAcrossAnInclineTurnsDownItAndStopsAsTheClosedFormSays).
  body.velocity = V(0, 1, 0);
  expectTips(body, incline, lastingOnFace(body, incline));
}

TEST(ShapedLasting, ATallBoxSlidingTipsForwardOverItsFrontEdge) {
  // Half sizes (0.05, 0.05, 0.5) sliding at 1 m/s along x with mu = 0.5: the centre of pressure
  // mu c = 0.25 m ahead, beyond its front edge at 0.05: it tips forwards over that edge (its two
  // front corners carry it, the rear ones leave), turning about +y.
  LastingBody body = box(V(0.05, 0.05, 0.5), 1, V(0, 0, 0.5));
  body.velocity = V(1, 0, 0);
  const FlatFace floor = plane(V::UnitZ(), 0.5);
  const auto motion = lastingOnFace(body, floor);
  expectTips(body, floor, motion);
  ASSERT_TRUE(motion.ok());
  ASSERT_EQ(motion->forces.size(), 2u);
  for (const SupportForce& force : motion->forces) EXPECT_NEAR(force.point.x(), 0.05, 1e-12);
  const double later = motion->start + 0.5 * (motion->until - motion->start);
  EXPECT_GT(motion->angularVelocityAt(later).y(), 0.0);
}

TEST(ShapedLasting, ABoxOnAnEdgeOrACornerOrTooTallOnAnInclineTips) {
  const FlatFace floor = plane(V::UnitZ(), 0.5);
  // On an edge: turned by 45 degrees about y, its edge down (half sizes 0.1: the centre
  // 0.1 sqrt 2 above the floor), at rest: balanced, each of the edge's corners carrying m g / 2.
  const LastingBody edge = box(V(0.1, 0.1, 0.1), 1, V(0, 0, 0.1 * std::sqrt(2.0)),
                               Q(Eigen::AngleAxisd(M_PI / 4, V::UnitY())));
  const auto on_edge = lastingOnFace(edge, floor);
  expectTips(edge, floor, on_edge);
  ASSERT_TRUE(on_edge.ok());
  ASSERT_EQ(on_edge->forces.size(), 2u);
  for (const SupportForce& force : on_edge->forces) EXPECT_NEAR(force.normal_force, kG / 2, 1e-9);
  // On a corner: the cube's diagonal vertical, the centre 0.1 sqrt 3 above the floor: the corner
  // carries m g.
  const Q corner_up = Q::FromTwoVectors(V(1, 1, 1).normalized(), V::UnitZ());
  const LastingBody corner = box(V(0.1, 0.1, 0.1), 1, V(0, 0, 0.1 * std::sqrt(3.0)), corner_up);
  const auto on_corner = lastingOnFace(corner, floor);
  expectTips(corner, floor, on_corner);
  ASSERT_TRUE(on_corner.ok());
  ASSERT_EQ(on_corner->forces.size(), 1u);
  EXPECT_NEAR(on_corner->forces.front().normal_force, kG, 1e-9);
  // Flat on the incline but tall: c tan theta = 0.6 x 3/4 = 0.45 > a = 0.3: the centre's
  // projection along g is outside its face: it tips over its lower edge.
  const LastingBody tall = box(V(0.3, 0.3, 0.6), 1, 0.6 * kInclineNormal, onIncline());
  const FlatFace incline = plane(kInclineNormal, 1.0);
  const auto tipping = lastingOnFace(tall, incline);
  expectTips(tall, incline, tipping);
  ASSERT_TRUE(tipping.ok());
  EXPECT_EQ(tipping->forces.size(), 2u);
}

TEST(ShapedLasting, ASpinOnAFaceIsTheTippingsAndARockingTurnIsNoLastingContact) {
  const FlatFace floor = plane(V::UnitZ(), 0.5);
  LastingBody body = box(V(0.2, 0.1, 0.05), 1, V(0, 0, 0.05));
  body.angular_velocity = V(0, 0, 1);
  expectTips(body, floor, lastingOnFace(body, floor));
  body.velocity = V(1, 0, 0);  // sliding and spinning: the same
  expectTips(body, floor, lastingOnFace(body, floor));
  // Rocking at 0.5 rad/s about x: its corners approach or leave at 0.05 m/s, far beyond a settled
  // body's: not a lasting contact (the caller's impacts).
  body.velocity = V::Zero();
  body.angular_velocity = V(0.5, 0, 0);
  expectNotYet(lastingOnFace(body, floor), "approaches or leaves");
}

TEST(ShapedLasting, ASolidCylinderRollsDownAnInclineAtTwoThirdsGSinTheta) {
  // r = 0.1, half length 0.2, 2 kg, J = m r^2 / 2, its axis across the incline (world y), from
  // rest, mu = 0.5: a = g sin / (1 + J / (m r^2)) = 2/3 g sin = 0.4 g down the slope; the friction
  // it needs, m g sin J / (J + m r^2) = m g 0.2, within mu m g cos = m g 0.4: it rolls, w' = a / r
  // about -y (rolling towards -x). Each end carries m g cos / 2 and half the friction, up the
  // slope.
  const double r = 0.1, m = 2;
  const LastingBody body = cylinder(r, 0.2, m, m * r * r / 2, r * kInclineNormal, sideOnIncline());
  const FlatFace incline = plane(kInclineNormal, 0.5);
  const auto motion = lastingOnFace(body, incline);
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  EXPECT_EQ(motion->state, ContactState::kRolling);
  EXPECT_TRUE(std::isinf(motion->until));
  EXPECT_LE((motion->acceleration + 0.4 * kG * kUphill).norm(), 1e-14 * kG);
  EXPECT_LE((motion->angular_acceleration + 0.4 * kG / r * V::UnitY()).norm(), 1e-14 * kG / r);
  ASSERT_EQ(motion->forces.size(), 2u);
  for (const SupportForce& force : motion->forces) {
    EXPECT_NEAR(force.normal_force, m * kG * kCos / 2, 1e-14 * m * kG);
    EXPECT_LE((force.friction_force - m * kG * 0.2 / 2 * kUphill).norm(), 1e-14 * m * kG);
  }
  expectBalance(body, incline, *motion, 1e-14);
  expectNeverBelowNorGaining(body, incline, *motion);
  // No slip at any instant, and no energy lost (rolling): the energy the same to rounding.
  const double start = energy(body, *motion, 0);
  for (const double t : {0.5, 1.0, 2.0}) {
    const V slip = motion->velocityAt(t) + motion->angularVelocityAt(t).cross(-r * kInclineNormal);
    EXPECT_LE(slip.norm(), 1e-14 * kG * t);
    EXPECT_NEAR(energy(body, *motion, t), start, 1e-13 * m * kG);
  }
}

// A solid ball (r = 0.1, 2 kg, I = 2/5 m r^2) at rest on the incline: with mu = 0.5 it rolls at a
// = g sin / (1 + I / (m r^2)) = 5/7 g sin down the slope, w' = a / r, its one point carrying m g
// cos and the friction m g sin 2/7 up the slope (within mu m g cos); with mu = 0.05 (below 2/7
// tan) it slides at g (sin - mu cos), turning at w' = mu m g cos r / I, the slip growing.
TEST(ShapedLasting, ABallRollsDownAnInclineAtFiveSeventhsGSinThetaOrSlidesBelowItsFriction) {
  const double r = 0.1, m = 2;
  LastingBody ball;
  ball.shape = Sphere{V::Zero(), r};
  ball.mass = m;
  ball.moments = V::Constant(0.4 * m * r * r);
  ball.centre = r * kInclineNormal;
  ball.gravity = kDown;
  const auto rolling = lastingOnFace(ball, plane(kInclineNormal, 0.5));
  ASSERT_TRUE(rolling.ok()) << errorOf(rolling);
  EXPECT_EQ(rolling->state, ContactState::kRolling);
  EXPECT_LE((rolling->acceleration + 5.0 / 7 * kG * kSin * kUphill).norm(), 1e-14 * kG);
  EXPECT_LE(
      (rolling->angular_acceleration - kInclineNormal.cross(-5.0 / 7 * kG * kSin * kUphill) / r)
          .norm(),
      1e-14 * kG / r);
  ASSERT_EQ(rolling->forces.size(), 1u);
  EXPECT_NEAR(rolling->forces[0].normal_force, m * kG * kCos, 1e-14 * m * kG);
  EXPECT_LE((rolling->forces[0].friction_force - m * kG * kSin * 2 / 7 * kUphill).norm(),
            1e-14 * m * kG);
  for (const double t : {0.5, 1.0}) {
    const V slip =
        rolling->velocityAt(t) + rolling->angularVelocityAt(t).cross(-r * kInclineNormal);
    EXPECT_LE(slip.norm(), 1e-14 * kG * t);
  }
  const double mu = 0.05;
  const auto sliding = lastingOnFace(ball, plane(kInclineNormal, mu));
  ASSERT_TRUE(sliding.ok()) << errorOf(sliding);
  EXPECT_EQ(sliding->state, ContactState::kSliding);
  EXPECT_TRUE(std::isinf(sliding->until));
  EXPECT_LE((sliding->acceleration + kG * (kSin - mu * kCos) * kUphill).norm(), 1e-14 * kG);
  EXPECT_NEAR(sliding->angular_acceleration.norm(), mu * m * kG * kCos * r / (0.4 * m * r * r),
              1e-12);
}

TEST(ShapedLasting, ACylinderOfAGivenAxialMomentRollsAtItsOwnRate) {
  // J = 0.8 m r^2 (a hollow-ish tensor): a = g sin / 1.8 = g / 3; the friction it needs,
  // m g sin 0.8 / 1.8 = m g 4/15 = 0.267 m g, within mu m g cos = 0.4 m g.
  const double r = 0.1, m = 2;
  const LastingBody body =
      cylinder(r, 0.2, m, 0.8 * m * r * r, r * kInclineNormal, sideOnIncline());
  const FlatFace incline = plane(kInclineNormal, 0.5);
  const auto motion = lastingOnFace(body, incline);
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  EXPECT_EQ(motion->state, ContactState::kRolling);
  EXPECT_LE((motion->acceleration + kG / 3 * kUphill).norm(), 1e-14 * kG);
  for (const SupportForce& force : motion->forces) {
    EXPECT_LE((force.friction_force - m * kG * 4 / 15 / 2 * kUphill).norm(), 1e-14 * m * kG);
  }
  expectBalance(body, incline, *motion, 1e-14);
  expectNeverBelowNorGaining(body, incline, *motion);
  // A capsule of the same J, radius and core: the same roll.
  LastingBody capsule = body;
  capsule.shape = Capsule{r, 0.2};
  const auto rolls = lastingOnFace(capsule, incline);
  ASSERT_TRUE(rolls.ok()) << errorOf(rolls);
  EXPECT_LE((rolls->acceleration + kG / 3 * kUphill).norm(), 1e-14 * kG);
}

TEST(ShapedLasting, ACylinderThatSlipsThenRollsAtTheClosedFormInstant) {
  // On a floor, a solid cylinder (J = m r^2 / 2) sliding across its axis at v0 = 1.5 m/s without
  // turning, mu = 0.3: friction mu m g against the slip: v' = -mu g, w' = mu m g r / J =
  // 2 mu g / r; the slip v - w r falls at 3 mu g and is 0 at t = v0 / (3 mu g), where
  // v = v0 - mu g t = 2 v0 / 3 = 1 m/s (and w r the same). From there it rolls on at 1 m/s.
  const double r = 0.1, m = 2, mu = 0.3;
  const Q axis_y(Eigen::AngleAxisd(-M_PI / 2, V::UnitX()));  // its z along world y
  LastingBody body = cylinder(r, 0.2, m, m * r * r / 2, V(0, 0, r), axis_y);
  body.velocity = V(1.5, 0, 0);
  const FlatFace floor = plane(V::UnitZ(), mu);
  const auto motion = lastingOnFace(body, floor);
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  EXPECT_EQ(motion->state, ContactState::kSliding);
  EXPECT_EQ(motion->ends, "stops");
  EXPECT_NEAR(motion->until, 1.5 / (3 * mu * kG), 1e-15);
  EXPECT_NEAR(motion->velocityAt(motion->until).x(), 1.0, 1e-14);
  EXPECT_NEAR(motion->angularVelocityAt(motion->until).y() * r, 1.0, 1e-14);
  expectBalance(body, floor, *motion, 1e-14);
  expectNeverBelowNorGaining(body, floor, *motion);
  // At rest on its side it rests, m g / 2 on each end of its lowest line.
  LastingBody still = body;
  still.velocity = V::Zero();
  const auto rests = lastingOnFace(still, floor);
  ASSERT_TRUE(rests.ok()) << errorOf(rests);
  EXPECT_EQ(rests->state, ContactState::kResting);
  ASSERT_EQ(rests->forces.size(), 2u);
  for (const SupportForce& force : rests->forces) {
    EXPECT_NEAR(force.normal_force, m * kG / 2, 1e-14 * m * kG);
    EXPECT_NEAR(std::abs(force.point.y()), 0.2, 1e-15);
  }
  const LastingBody rolling = bodyAt(body, *motion, motion->until);
  const auto then = lastingOnFace(rolling, floor);
  ASSERT_TRUE(then.ok()) << errorOf(then);
  EXPECT_EQ(then->state, ContactState::kRolling);
  EXPECT_EQ(then->acceleration, V::Zero());
  EXPECT_TRUE(std::isinf(then->until));

  // On the incline with mu = 0.1 it cannot roll (it needs 0.2 g of friction, has 0.08 g): from
  // rest it slides and spins up for ever, a = g (sin - mu cos) = 0.52 g, w' = mu m g cos r / J =
  // 0.16 g / r.
  const LastingBody steep = cylinder(r, 0.2, m, m * r * r / 2, r * kInclineNormal, sideOnIncline());
  const FlatFace slippery = plane(kInclineNormal, 0.1);
  const auto slides = lastingOnFace(steep, slippery);
  ASSERT_TRUE(slides.ok()) << errorOf(slides);
  EXPECT_EQ(slides->state, ContactState::kSliding);
  EXPECT_TRUE(std::isinf(slides->until));
  EXPECT_LE((slides->acceleration + 0.52 * kG * kUphill).norm(), 1e-14 * kG);
  EXPECT_LE((slides->angular_acceleration + 0.16 * kG / r * V::UnitY()).norm(), 1e-13 * kG / r);
  expectBalance(steep, slippery, *slides, 1e-14);
  expectNeverBelowNorGaining(steep, slippery, *slides);
}

TEST(ShapedLasting, SlidingOnATableTopEndsWhereTheSupportReachesTheEdge) {
  // Half size 0.1 along x on a table top 2 m long (half extent 1): its front corners reach the
  // edge after 0.9 m. At 3 m/s with mu = 0.2 (stopping after 9 / (2 mu g) = 2.29 m): the first
  // root of 3 t - mu g t^2 / 2 = 0.9.
  LastingBody body = box(V(0.1, 0.1, 0.1), 1, V(0, 0, 0.8));
  body.velocity = V(3, 0, 0);
  FlatFace table = plane(V::UnitZ(), 0.2);
  table.point = V(0, 0, 0.7);
  table.bounded = true;
  table.half_extent = Eigen::Vector2d(1, 0.5);
  const auto motion = lastingOnFace(body, table);
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  // Asked again there ("stops"), it goes on over the edge (test_shaped_edge_tip.cpp).
  EXPECT_EQ(motion->ends, "stops");
  const double A = 0.2 * kG / 2;
  EXPECT_NEAR(motion->until, (3 - std::sqrt(9 - 4 * A * 0.9)) / (2 * A), 1e-14);
  EXPECT_NEAR(motion->centreAt(motion->until).x(), 0.9, 1e-14);
  expectNeverBelowNorGaining(body, table, *motion);
  // A cylinder standing on its cap (r = 0.2, half length 0.1) from the middle at 3 m/s along
  // (0.6, 0.8): its rim reaches the side y = 0.5 first, when its centre is at y = 0.3, after
  // 0.3 / 0.8 = 0.375 m: the first root of 3 t - mu g t^2 / 2 = 0.375.
  LastingBody can = cylinder(0.2, 0.1, 1, 0.02, V(0, 0, 0.8), Q::Identity());
  can.velocity = V(1.8, 2.4, 0);
  const auto slides = lastingOnFace(can, table);
  ASSERT_TRUE(slides.ok()) << errorOf(slides);
  EXPECT_EQ(slides->ends, "stops");
  EXPECT_NEAR(slides->until, (3 - std::sqrt(9 - 4 * A * 0.375)) / (2 * A), 1e-14);
  expectNeverBelowNorGaining(can, table, *slides);
  // Slower, it stops on the table.
  body.velocity = V(1, 0, 0);
  const auto stops = lastingOnFace(body, table);
  ASSERT_TRUE(stops.ok()) << errorOf(stops);
  EXPECT_EQ(stops->ends, "stops");
  // Overhanging the edge at the start (its foot 0.05 m from it), it slides on until its centre
  // of pressure, h mu = 0.02 m ahead of its foot, reaches the edge: the first root of
  // t - mu g t^2 / 2 = 0.03 (test_shaped_edge_tip.cpp: what follows).
  body.centre.x() = 0.95;
  const auto over = lastingOnFace(body, table);
  ASSERT_TRUE(over.ok()) << errorOf(over);
  EXPECT_EQ(over->ends, "stops");
  EXPECT_NEAR(over->until, (1 - std::sqrt(1 - 4 * A * 0.03)) / (2 * A), 1e-14);
}

TEST(ShapedLasting, ABoxSlidingDownARampEndsAtItsLowerEdge) {
  // A ramp: the face of a box obstacle on the incline, 4 m long up the slope (half extent 2) and
  // 2 m across, its centre at the origin. The box (a = 0.5 up the slope) from rest at its middle,
  // mu = 0.5: a = 0.2 g down the slope; its lower corners, 0.5 m below its centre, reach the
  // ramp's lower edge after 1.5 m: 0.1 g t^2 = 1.5, t = sqrt(15 / g).
  const double a = 0.5, c = 0.2;
  const LastingBody body = box(V(a, 0.3, c), 2, c * kInclineNormal, onIncline());
  FlatFace ramp = plane(kInclineNormal, 0.5);
  ramp.bounded = true;
  ramp.along_u = kUphill;
  ramp.along_v = V::UnitY();
  ramp.half_extent = Eigen::Vector2d(2, 1);
  const auto motion = lastingOnFace(body, ramp);
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  EXPECT_EQ(motion->state, ContactState::kSliding);
  EXPECT_EQ(motion->ends, "stops");  // asked again there, it goes on over the edge
  EXPECT_NEAR(motion->until, std::sqrt(15 / kG), 1e-14);
  EXPECT_NEAR(motion->centreAt(motion->until).dot(kUphill), -1.5, 1e-14);
  expectNeverBelowNorGaining(body, ramp, *motion);
}

TEST(ShapedLasting, ACylinderRollingOnATableTopEndsWhereItsSideReachesTheEdge) {
  // Rolling at 1 m/s along x on a level table top (half extent 1 along x), its centre at
  // x = -0.5, its axis along y: the contact line, under the centre, reaches x = 1 after 1.5 s,
  // where it is asked again ("stops": it rolls over the edge, test_shaped_edge_tip.cpp).
  const double r = 0.1, m = 2;
  LastingBody body = cylinder(r, 0.2, m, m * r * r / 2, V(-0.5, 0, 0.7 + r),
                              Q(Eigen::AngleAxisd(-M_PI / 2, V::UnitX())));
  body.velocity = V(1, 0, 0);
  body.angular_velocity = V(0, 1 / r, 0);
  FlatFace table = plane(V::UnitZ(), 0.4);
  table.point = V(0, 0, 0.7);
  table.bounded = true;
  table.half_extent = Eigen::Vector2d(1, 0.5);
  const auto motion = lastingOnFace(body, table);
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  EXPECT_EQ(motion->state, ContactState::kRolling);
  EXPECT_EQ(motion->ends, "stops");
  EXPECT_NEAR(motion->until, 1.5, 1e-15);
  EXPECT_EQ(motion->acceleration, V::Zero());
  expectNeverBelowNorGaining(body, table, *motion);
  // Turning about the vertical as well: each end of its side slides its own way (Coulomb's
  // friction at each), which the tipping on its two rims carries (pivotOnRound): sound.
  body.angular_velocity.z() = 0.5;
  expectTips(body, table, lastingOnFace(body, table));
}

TEST(ShapedLasting, RandomSlidesAndRollsBalanceNeverGoBelowNorGainEnergy) {
  // 300 boxes flat on random inclines (up to 0.6 rad, or level), turned about the normal, sliding
  // along the slope (or any way on a level face) at up to 3 m/s either way, mu in [0, 1]; 300
  // cylinders on their side across the slope (J from 0.3 to 1 m r^2), rolling or slipping either
  // way. Each: its forces balance m (a - g) and the turning (1e-12), and over its span (or 1 s)
  // no point below the face, no energy gained, no force < 0, friction within mu (the helper's
  // sampling); a box may instead tip (expectTips), a side never.
  std::mt19937 random(4242);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int slides = 0, tips = 0, rolls = 0, slips = 0;
  for (int k = 0; k < 600; ++k) {
    const bool level = k % 5 == 0;
    const double tilt = level ? 0.0 : 0.6 * unit(random), azimuth = 2 * M_PI * unit(random);
    const V n(std::sin(tilt) * std::cos(azimuth), std::sin(tilt) * std::sin(azimuth),
              std::cos(tilt));
    const V g_t = kDown - kDown.dot(n) * n;
    V down = g_t.norm() > 0 ? V(g_t.normalized()) : V(n.unitOrthogonal());
    if (level) down = Eigen::AngleAxisd(2 * M_PI * unit(random), n) * down;
    const FlatFace face = plane(n, unit(random));
    const double speed = 3 * (2 * unit(random) - 1);
    if (k < 300) {
      const V half(0.05 + 0.25 * unit(random), 0.05 + 0.25 * unit(random),
                   0.05 + 0.25 * unit(random));
      const Q turn =
          Q(Eigen::AngleAxisd(2 * M_PI * unit(random), n)) * Q::FromTwoVectors(V::UnitZ(), n);
      LastingBody body = box(half, 1 + unit(random), half.z() * n, turn);
      body.velocity = speed * down;
      const auto motion = lastingOnFace(body, face);
      if (motion.ok() && motion->pivot) {
        ++tips;
        expectTips(body, face, motion);
        continue;
      }
      ASSERT_TRUE(motion.ok()) << k << ": " << errorOf(motion);
      ++slides;
      expectBalance(body, face, *motion, 1e-12);
      expectNeverBelowNorGaining(body, face, *motion, 1.0);
      continue;
    }
    const double r = 0.05 + 0.2 * unit(random), m = 1 + unit(random);
    const V axis = n.cross(down);
    Eigen::Matrix3d frame;
    frame.col(0) = n;
    frame.col(1) = axis.cross(n);
    frame.col(2) = axis;
    LastingBody body = cylinder(r, 0.05 + 0.3 * unit(random), m,
                                (0.3 + 0.7 * unit(random)) * m * r * r, r * n, Q(frame));
    body.velocity = speed * down;
    const double slip = unit(random) < 0.5 ? 0.0 : 2 * unit(random) - 1;
    // The contact line's velocity v + w x (-r n) is slip along `down` for w = (speed - slip) / r
    // about n x down (its axis): (n x down) x n = down.
    body.angular_velocity = ((speed - slip) / r) * axis;
    const auto motion = lastingOnFace(body, face);
    ASSERT_TRUE(motion.ok()) << k << ": " << errorOf(motion);
    (motion->state == ContactState::kRolling ? rolls : slips) += 1;
    expectBalance(body, face, *motion, 1e-12);
    expectNeverBelowNorGaining(body, face, *motion, 1.0);
  }
  EXPECT_GT(slides, 100);
  EXPECT_GT(tips, 10);
  EXPECT_GT(rolls, 50);
  EXPECT_GT(slips, 50);
}

TEST(ShapedLasting, FlatBouncesEndAtTheGeometricSeriesSum) {
  // A box landing flat at u = 2 m/s, e = 1/2, g_n = g: 2 e u / (g (1 - e)) = 4 / g after it.
  LastingBody body = box(V(0.3, 0.2, 0.1), 1, V(0, 0, 0.1));
  body.time = 1.25;
  body.velocity = V(0, 0, -2);
  const FlatFace floor = plane(V::UnitZ(), 0.5);
  const auto end = flatBouncesEnd(body, floor, 0.5);
  ASSERT_TRUE(end.has_value());
  EXPECT_DOUBLE_EQ(*end, 1.25 + 4 / kG);
  // e = 0: it stops at once; e = 0.9: 2 (0.9) 2 / (0.1 g) = 36 / g.
  EXPECT_DOUBLE_EQ(*flatBouncesEnd(body, floor, 0.0), 1.25);
  EXPECT_NEAR(*flatBouncesEnd(body, floor, 0.9), 1.25 + 36 / kG, 1e-13);
  // On the incline, landing along its normal at 1 m/s: g_n = g cos, 2 (0.5) / (0.8 g 0.5).
  LastingBody tilted = box(V(0.5, 0.3, 0.2), 2, 0.2 * kInclineNormal, onIncline());
  tilted.velocity = -kInclineNormal;
  const auto on_incline = flatBouncesEnd(tilted, plane(kInclineNormal, 1.0), 0.5);
  ASSERT_TRUE(on_incline.has_value());
  EXPECT_NEAR(*on_incline, 1 / (0.4 * kG), 1e-14);
  // Not such a landing: e = 1, drifting, turning, leaving, on an edge.
  EXPECT_FALSE(flatBouncesEnd(body, floor, 1.0).has_value());
  LastingBody drifting = body;
  drifting.velocity.x() = 0.1;
  EXPECT_FALSE(flatBouncesEnd(drifting, floor, 0.5).has_value());
  LastingBody turning = body;
  turning.angular_velocity = V(0, 0, 1);
  EXPECT_FALSE(flatBouncesEnd(turning, floor, 0.5).has_value());
  LastingBody leaving = body;
  leaving.velocity = V(0, 0, 1);
  EXPECT_FALSE(flatBouncesEnd(leaving, floor, 0.5).has_value());
  LastingBody edge = box(V(0.1, 0.1, 0.1), 1, V(0, 0, 0.1 * std::sqrt(2.0)),
                         Q(Eigen::AngleAxisd(M_PI / 4, V::UnitY())));
  edge.velocity = V(0, 0, -1);
  EXPECT_FALSE(flatBouncesEnd(edge, floor, 0.5).has_value());
  // A cylinder landing on its side: its two ends, under the centre.
  LastingBody side =
      cylinder(0.1, 0.2, 1, 0.005, V(0, 0, 0.1), Q(Eigen::AngleAxisd(M_PI / 2, V::UnitX())));
  side.velocity = V(0, 0, -2);
  const auto side_end = flatBouncesEnd(side, floor, 0.5);
  ASSERT_TRUE(side_end.has_value());
  EXPECT_DOUBLE_EQ(*side_end, 4 / kG);
}

TEST(ShapedLasting, BadInputIsNamed) {
  const FlatFace floor = plane(V::UnitZ(), 0.5);
  const LastingBody good = box(V(0.1, 0.1, 0.1), 1, V(0, 0, 0.1));
  const auto fieldOf = [](const Expected<LastingMotion>& motion) {
    return motion.ok() ? std::string("(ok)") : motion.error().field;
  };
  LastingBody body = good;
  body.mass = 0;
  EXPECT_EQ(fieldOf(lastingOnFace(body, floor)), "body.mass");
  body = good;
  body.velocity.x() = NAN;
  EXPECT_EQ(fieldOf(lastingOnFace(body, floor)), "body.velocity");
  body = good;
  body.gravity = V(0, 0, 9.81);
  EXPECT_EQ(fieldOf(lastingOnFace(body, floor)), "body.gravity");
  body = good;
  body.centre.z() = 0.2;  // 0.1 m above the floor
  EXPECT_EQ(fieldOf(lastingOnFace(body, floor)), "body.centre");
  body.centre.z() = 0.05;  // 0.05 m inside
  EXPECT_EQ(fieldOf(lastingOnFace(body, floor)), "body.centre");
  body = good;
  body.velocity = V(0, 0, -0.5);  // approaching: an impact
  EXPECT_EQ(fieldOf(lastingOnFace(body, floor)), "body.velocity");
  body = good;
  body.shape = Sphere{V::Zero(), -0.1};
  EXPECT_EQ(fieldOf(lastingOnFace(body, floor)), "body.shape");
  body = good;
  body.moments.y() = -1;
  EXPECT_EQ(fieldOf(lastingOnFace(body, floor)), "body.moments");
  body = good;
  body.orientation = Q(2, 0, 0, 0);
  EXPECT_EQ(fieldOf(lastingOnFace(body, floor)), "body.orientation");
  FlatFace face = floor;
  face.bounded = true;
  face.half_extent = Eigen::Vector2d(1, 1);
  face.along_u = V(1, 1, 0).normalized();
  EXPECT_EQ(fieldOf(lastingOnFace(good, face)), "face.along_u");
  face = floor;
  face.friction = -1;
  EXPECT_EQ(fieldOf(lastingOnFace(good, face)), "face.friction");
  face = floor;
  face.normal = V(0, 0, 2);
  EXPECT_EQ(fieldOf(lastingOnFace(good, face)), "face.normal");
  face = floor;
  face.bounded = true;
  EXPECT_EQ(fieldOf(lastingOnFace(good, face)), "face.half_extent");
}

}  // namespace collision_response::core
