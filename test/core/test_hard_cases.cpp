// Hard cases that must stay numerically stable, each a named test. Expected values come from
// test/exact/make_hard_cases.py (exact rational arithmetic, outside the code under test) or from
// closed forms worked out in the comments. doc/development.md, "Hard cases", lists what each
// guarantees.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "collision_response/core/collision.h"
#include "collision_response/core/impact.h"
#include "collision_response/core/monitor.h"
#include "collision_response/core/time_of_impact.h"

namespace collision_response::core {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kInf = std::numeric_limits<double>::infinity();
using V = Eigen::Vector3d;
using LongVector = Eigen::Matrix<long double, 3, 1>;

struct HardCase {
  std::string name;
  double mass_a, mass_b, restitution;
  int axis;
  V velocity_a, velocity_b, expected_a, expected_b;
  double expected_impulse, expected_energy_lost;
};

std::vector<HardCase> loadHardCases() {
  std::ifstream file(std::string(COLLISION_RESPONSE_TEST_DATA) + "/hard_cases.txt");
  std::vector<HardCase> cases;
  std::string line;
  while (std::getline(file, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream in(line);
    HardCase c;
    std::vector<double> v(20);
    in >> c.name;
    for (double& x : v) {
      std::string token;
      in >> token;
      x = std::strtod(token.c_str(), nullptr);
    }
    c.mass_a = v[0];
    c.velocity_a = V(v[1], v[2], v[3]);
    c.mass_b = v[4];
    c.velocity_b = V(v[5], v[6], v[7]);
    c.axis = static_cast<int>(v[8]);
    c.restitution = v[9];
    c.expected_a = V(v[10], v[11], v[12]);
    c.expected_b = V(v[13], v[14], v[15]);
    c.expected_impulse = v[16];
    c.expected_energy_lost = v[17];
    cases.push_back(c);
  }
  return cases;
}

std::vector<HardCase> casesStartingWith(const std::string& prefix) {
  std::vector<HardCase> selected;
  for (const HardCase& c : loadHardCases()) {
    if (c.name.rfind(prefix, 0) == 0) selected.push_back(c);
  }
  EXPECT_FALSE(selected.empty()) << prefix;
  return selected;
}

/// Resolves a data case and checks it against the exact answer:
///  - the components across the line of impact unchanged, to the bit;
///  - the normal components within 8 ulps of the larger normal speed;
///  - no NaN anywhere; impulse and energy lost within 16 ulps where the exact value is a double,
///    +inf (never NaN) where it is beyond the doubles; energy lost >= 0;
///  - with finite masses, momentum conserved within 4 ulps of sum m |v| (summed in long double,
///    whose range holds 1e400).
void checkCase(const HardCase& c) {
  SCOPED_TRACE(c.name);
  V n = V::Zero();
  n[c.axis] = 1.0;
  const ImpactResponse<double> r = resolveImpact(
      inverseMass(c.mass_a), c.velocity_a, inverseMass(c.mass_b), c.velocity_b, n, c.restitution);
  ASSERT_TRUE(r.velocity_a.allFinite() && r.velocity_b.allFinite());
  ASSERT_FALSE(std::isnan(r.normal_impulse) || std::isnan(r.energy_lost));
  const double normal_scale =
      std::max(std::abs(c.velocity_a[c.axis]), std::abs(c.velocity_b[c.axis]));
  for (int i = 0; i < 3; ++i) {
    if (i == c.axis) {
      EXPECT_NEAR(r.velocity_a[i], c.expected_a[i], 8 * kEps * normal_scale);
      EXPECT_NEAR(r.velocity_b[i], c.expected_b[i], 8 * kEps * normal_scale);
    } else {
      EXPECT_EQ(r.velocity_a[i], c.velocity_a[i]);
      EXPECT_EQ(r.velocity_b[i], c.velocity_b[i]);
    }
  }
  const auto check_scalar = [](double value, double expected, const char* what) {
    if (std::isinf(expected)) {
      EXPECT_TRUE(std::isinf(value)) << what << " " << value;
    } else {
      EXPECT_NEAR(value, expected, 16 * kEps * std::abs(expected) + 1e-300) << what;
    }
  };
  check_scalar(r.normal_impulse, c.expected_impulse, "impulse");
  check_scalar(r.energy_lost, c.expected_energy_lost, "energy lost");
  EXPECT_GE(r.energy_lost, 0.0);
  if (std::isfinite(c.mass_a) && std::isfinite(c.mass_b)) {
    const long double ma = c.mass_a, mb = c.mass_b;
    const LongVector before =
        ma * c.velocity_a.cast<long double>() + mb * c.velocity_b.cast<long double>();
    const LongVector after =
        ma * r.velocity_a.cast<long double>() + mb * r.velocity_b.cast<long double>();
    const long double scale =
        ma * (c.velocity_a.cast<long double>().norm() + r.velocity_a.cast<long double>().norm()) +
        mb * (c.velocity_b.cast<long double>().norm() + r.velocity_b.cast<long double>().norm());
    EXPECT_LE((after - before).cwiseAbs().maxCoeff(), 4 * kEps * scale) << "momentum";
  }
}

// --- 1. Mass ratios and magnitudes ---------------------------------------------------------------

TEST(HardCases, MassRatiosFrom1eMinus15To1e15InBothOrders) {
  for (const HardCase& c : casesStartingWith("ratio_")) checkCase(c);
}

TEST(HardCases, InfiniteMassInBothOrders) {
  for (const HardCase& c : casesStartingWith("immovable_")) checkCase(c);
}

TEST(HardCases, MagnitudesFrom1eMinus150To1e200) {
  // Masses and speeds 1e-150 .. 1e200: no overflow where the exact answer is a double (energies
  // of 1e600 J are not, and come out +inf, never NaN).
  for (const HardCase& c : casesStartingWith("magnitude_")) checkCase(c);
}

// --- 2. e exactly 0 and 1, and a hair from them ------------------------------------------------

TEST(HardCases, RestitutionExactlyZeroGivesOneCommonVelocityExactly) {
  for (const HardCase& c : casesStartingWith("ratio_")) {
    if (c.restitution != 0.0) continue;
    V n = V::Zero();
    n[c.axis] = 1.0;
    const auto r = resolveImpact(inverseMass(c.mass_a), c.velocity_a, inverseMass(c.mass_b),
                                 c.velocity_b, n, 0.0);
    EXPECT_EQ(r.velocity_a[c.axis], r.velocity_b[c.axis]) << c.name;
  }
}

TEST(HardCases, RestitutionExactlyOneConservesEnergy) {
  for (const HardCase& c : casesStartingWith("ratio_")) {
    if (c.restitution != 1.0) continue;
    V n = V::Zero();
    n[c.axis] = 1.0;
    const auto r = resolveImpact(inverseMass(c.mass_a), c.velocity_a, inverseMass(c.mass_b),
                                 c.velocity_b, n, 1.0);
    EXPECT_EQ(r.energy_lost, 0.0);
    const auto energy = [&](const V& a, const V& b) {
      return 0.5L * c.mass_a * a.cast<long double>().squaredNorm() +
             0.5L * c.mass_b * b.cast<long double>().squaredNorm();
    };
    const long double before = energy(c.velocity_a, c.velocity_b);
    EXPECT_LE(std::abs(energy(r.velocity_a, r.velocity_b) - before), 8 * kEps * before) << c.name;
  }
}

TEST(HardCases, RestitutionAHairAboveZeroAndBelowOne) {
  for (const HardCase& c : casesStartingWith("e_")) checkCase(c);
}

// --- 3. Named errors, and a moving immovable body ----------------------------------------------

CollisionRequest simpleRequest() {
  CollisionRequest request;
  request.a.id = "a";
  request.a.velocity = V(1, 0, 0);
  request.b.id = "b";
  request.b.position = V(1, 0, 0);
  request.restitution = 0.5;
  return request;
}

TEST(HardCases, ImmovableAgainstImmovableIsANamedError) {
  CollisionRequest request = simpleRequest();
  request.a.mass = kInf;
  request.b.mass = kInf;
  EXPECT_EQ(computeCollision(request, MaterialTable::seed()).error().field, "b.mass");
}

TEST(HardCases, BodyAgainstItselfIsANamedError) {
  CollisionRequest request = simpleRequest();
  request.b.id = "a";
  EXPECT_EQ(computeCollision(request, MaterialTable::seed()).error().field, "b.id");
}

TEST(HardCases, CoincidentCentresWithoutNormalIsANamedError) {
  CollisionRequest request = simpleRequest();
  request.b.position = request.a.position;
  EXPECT_EQ(computeCollision(request, MaterialTable::seed()).error().field, "normal");
}

TEST(HardCases, MovingImmovableBody) {
  for (const HardCase& c : casesStartingWith("moving_immovable_")) checkCase(c);
}

// --- 4. Grazing, tangential and separating ---------------------------------------------------

TEST(HardCases, GrazingImpactsDownTo1eMinus9Rad) {
  // The normal component 1e-9 of the speed: it keeps its relative accuracy, the tangential
  // component is untouched, and the impact is oblique.
  for (const HardCase& c : casesStartingWith("grazing_")) {
    checkCase(c);
    V n = V::Zero();
    n[c.axis] = 1.0;
    EXPECT_TRUE(hasObliqueComponent(c.velocity_a, n)) << c.name;
  }
}

TEST(HardCases, RelativeVelocityExactlyAlongTheTangentGivesNoImpulse) {
  const auto r = resolveImpact(1.0, V(5, 2, 0), 3.0, V(-1, 2, 0), V(0, 1, 0), 0.9);
  EXPECT_FALSE(r.approaching);
  EXPECT_EQ(r.normal_impulse, 0.0);
  EXPECT_EQ(r.velocity_a, V(5, 2, 0));
  EXPECT_EQ(r.velocity_b, V(-1, 2, 0));
}

TEST(HardCases, SeparatingBodiesGetNoImpulse) {
  const auto r = resolveImpact(1.0, V(-1, 0, 0), 1.0, V(1e-300, 0, 0), V(1, 0, 0), 1.0);
  EXPECT_FALSE(r.approaching);
  EXPECT_EQ(r.normal_impulse, 0.0);
  EXPECT_EQ(r.energy_lost, 0.0);
}

// --- 5. Time of impact ---------------------------------------------------------------------

TEST(HardCases, TimeOfImpactFastSpheres1e8Apart) {
  // (1e8 - 1) m to close at 3e8 m/s; in float 1e8 and 3e8 are exact too.
  const auto t = timeOfImpactSpheres<double>(V(1e8, 0, 0), V(-3e8, 0, 0), 1.0, 1.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, (1e8 - 1) / 3e8, 2 * kEps);
  const auto f = timeOfImpactSpheres<float>(Eigen::Vector3f(1e8f, 0, 0),
                                            Eigen::Vector3f(-3e8f, 0, 0), 1.0f, 1.0f);
  ASSERT_TRUE(f);
  EXPECT_NEAR(*f, 1.0f / 3.0f, 4 * std::numeric_limits<float>::epsilon());
}

TEST(HardCases, TimeOfImpactGapsOf1eMinus12) {
  // A 1e-12 m gap at 1 m/s, with the contact distance 1: the gap is fl(1 + 1e-12) - 1 exactly
  // (Sterbenz), the time that gap over 1 m/s.
  const double separation = 1.0 + 1e-12;
  const double gap = separation - 1.0;
  const auto t = timeOfImpactSpheres<double>(V(separation, 0, 0), V(-1, 0, 0), 1.0, 1.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, gap, 4 * kEps * gap);
  const float gap_f = std::ldexp(1.0f, -20);
  const auto f = timeOfImpactSpheres<float>(Eigen::Vector3f(1.0f + gap_f, 0, 0),
                                            Eigen::Vector3f(-1, 0, 0), 1.0f, 1.0f);
  ASSERT_TRUE(f);
  EXPECT_NEAR(*f, gap_f, 4 * std::numeric_limits<float>::epsilon() * gap_f);
}

TEST(HardCases, TimeOfImpactNearZeroRelativeSpeed) {
  // A 1e-10 m gap closing at 1e-300 m/s: contact after gap / 1e-300 = ~1e290 s, found when the
  // horizon reaches it, not before, and no overflow or NaN on the way.
  const double separation = 1.0 + 1e-10;
  const long double expected = static_cast<long double>(separation - 1.0) / 1e-300L;
  EXPECT_FALSE(timeOfImpactSpheres<double>(V(separation, 0, 0), V(-1e-300, 0, 0), 1.0, 1e280));
  const auto t = timeOfImpactSpheres<double>(V(separation, 0, 0), V(-1e-300, 0, 0), 1.0, 1e300);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, static_cast<double>(expected), 4 * kEps * static_cast<double>(expected));
}

TEST(HardCases, TimeOfImpactOverlappingAtTheStart) {
  EXPECT_FALSE(timeOfImpactSpheres<double>(V(0.5, 0, 0), V(-1, 0, 0), 1.0, 10.0));
  EXPECT_FALSE(timeOfImpactSpheres<float>(Eigen::Vector3f(0.5f, 0, 0), Eigen::Vector3f(-1, 0, 0),
                                          1.0f, 10.0f));
  EXPECT_FALSE(timeOfImpactPlane(-0.01, -1.0, 10.0));
}

TEST(HardCases, TimeOfImpactDiscriminantExactlyZero) {
  // s = (3, 1, 0), v = (-1, 0, 0), R = 1: |v x s| = |v| R exactly, a tangent touch at t = 3.
  const auto t = timeOfImpactSpheres<double>(V(3, 1, 0), V(-1, 0, 0), 1.0, 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 3.0, 4 * kEps * 3);
  const auto f =
      timeOfImpactSpheres<float>(Eigen::Vector3f(3, 1, 0), Eigen::Vector3f(-1, 0, 0), 1.0f, 10.0f);
  ASSERT_TRUE(f);
  EXPECT_NEAR(*f, 3.0f, 4 * std::numeric_limits<float>::epsilon() * 3);
}

// --- 6. Simultaneous contacts ------------------------------------------------------------------

Scene rowScene(int balls, double restitution, bool rotate_listing = false) {
  Scene scene;
  EXPECT_TRUE(scene.materials.addMaterial("steel", Material{restitution, {}}, "m").ok());
  for (int i = 1; i <= balls; ++i) {
    BodySpec body;
    body.id = "ball_" + std::to_string(i);
    body.mass = 0.26;
    body.radius = 0.02;
    body.material = "steel";
    scene.bodies.push_back(body);
  }
  if (rotate_listing)
    std::rotate(scene.bodies.begin(), scene.bodies.begin() + 1, scene.bodies.end());
  return scene;
}

/// A row of touching balls, the first 0.02 m away moving at 1 m/s; the velocities after.
std::vector<double> strikeRow(const Scene& scene, int balls,
                              const std::vector<std::size_t>& order) {
  ImpactMonitor monitor(scene, MonitorSettings{});
  std::vector<BodyStateSample> states;
  for (const std::size_t i : order) {
    BodyStateSample state;
    state.body = *monitor.bodyIndex("ball_" + std::to_string(i + 1));
    state.position = V(i == 0 ? -0.06 : 0.04 * static_cast<double>(i - 1), 0, 0);
    state.velocity = V(i == 0 ? 1.0 : 0.0, 0, 0);
    states.push_back(state);
  }
  monitor.step(0.0, states);
  const StepReport report = monitor.step(0.03, {});
  EXPECT_FALSE(report.truncated);
  std::vector<double> velocities;
  for (int i = 1; i <= balls; ++i) {
    velocities.push_back(
        monitor.predictedState(*monitor.bodyIndex("ball_" + std::to_string(i)), 0.03)->second.x());
  }
  return velocities;
}

std::vector<std::size_t> identity(int balls) {
  std::vector<std::size_t> order(static_cast<std::size_t>(balls));
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  return order;
}

TEST(HardCases, NewtonsCradlesOf3And5WithEOneAndBelow) {
  std::ifstream file(std::string(COLLISION_RESPONSE_TEST_DATA) + "/cradle_cases.txt");
  std::string line;
  int cases = 0;
  while (std::getline(file, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream in(line);
    int balls = 0;
    double restitution = 0;
    in >> balls >> restitution;
    std::vector<double> expected(static_cast<std::size_t>(balls));
    for (double& v : expected) in >> v;
    const std::vector<double> velocities =
        strikeRow(rowScene(balls, restitution), balls, identity(balls));
    long double momentum = 0;
    for (int i = 0; i < balls; ++i) {
      EXPECT_NEAR(velocities[i], expected[i], 8 * kEps) << balls << " balls, e " << restitution;
      momentum += velocities[i];
    }
    EXPECT_NEAR(static_cast<double>(momentum), 1.0, 8 * kEps);
    ++cases;
  }
  EXPECT_EQ(cases, 6);
}

TEST(HardCases, PlasticCradleEndsInOneCommonVelocity) {
  // e = 0: the rounds converge to the common velocity 1/n (the exact rounds never end; they
  // stop when what approaches is below the approach tolerance, 64 ulps).
  for (const int balls : {3, 5}) {
    for (const double v : strikeRow(rowScene(balls, 0.0), balls, identity(balls))) {
      EXPECT_NEAR(v, 1.0 / balls, 1e-12) << balls;
    }
  }
}

// A ball touching two parallel walls at once (no gravity), moving at 1 m/s, e = 0.5: at one
// instant it strikes them in turn at 1, 1/2, 1/4, ... m/s (powers of two: exact). A wall struck
// again slower than 1e-12 of its first strike takes it plastically: the right wall at its 21st
// strike, at 2^-40 = 9.1e-13 m/s (the left one's 20th, 2^-39, is above 1e-12 x 1/2), so the
// instant ends after 41 impacts with the ball at rest, exactly, every joule dissipated. (The
// exact series would go on to the doubles' underflow, 2^-1074: 1,075 rounds.)
TEST(HardCases, WedgedBallStopsOnceItsBouncesAreBelowRounding) {
  Scene scene;
  ASSERT_TRUE(scene.materials.addMaterial("rubber", Material{0.5, {}}, "m").ok());
  BodySpec body;
  body.id = "ball";
  body.mass = 2.0;
  body.radius = 0.05;
  body.material = "rubber";
  scene.bodies = {body};
  for (const double side : {1.0, -1.0}) {
    ObstacleSpec wall;
    wall.id = side > 0 ? "left" : "right";
    wall.material = "rubber";
    wall.normal = V(side, 0, 0);
    wall.offset = -body.radius;  // touching the ball at x = 0
    scene.obstacles.push_back(wall);
  }
  ImpactMonitor monitor(scene, MonitorSettings{});
  BodyStateSample start;
  start.velocity = V(1, 0, 0);
  monitor.step(0.0, {start});
  const StepReport report = monitor.step(0.01, {});
  EXPECT_FALSE(report.truncated);
  ASSERT_EQ(report.impacts.size(), 41u);
  EXPECT_EQ(report.impacts.back().restitution, 0.0);
  EXPECT_EQ(report.impacts.back().velocity_a_before.x(), std::ldexp(1.0, -40));
  EXPECT_EQ(monitor.predictedState(0, 0.01)->second, V::Zero());
  double dissipated = 0;
  for (const ImpactRecord& impact : report.impacts) dissipated += impact.energy_lost;
  EXPECT_NEAR(dissipated, 0.5 * body.mass * 1.0, 8 * kEps);
}

TEST(HardCases, TwoBallsStrikeAMiddleOneSymmetrically) {
  // e = 1 and e = 0.5: the middle ball stays, the outer ones leave at -e v and +e v; the two
  // answers mirror each other to the bit.
  for (const double e : {1.0, 0.5}) {
    Scene scene = rowScene(3, e);
    ImpactMonitor monitor(scene, MonitorSettings{});
    std::vector<BodyStateSample> states(3);
    const double x[3] = {-0.1, 0.0, 0.1};
    const double v[3] = {1.0, 0.0, -1.0};
    for (int i = 0; i < 3; ++i) {
      states[i].body = *monitor.bodyIndex("ball_" + std::to_string(i + 1));
      states[i].position = V(x[i], 0, 0);
      states[i].velocity = V(v[i], 0, 0);
    }
    monitor.step(0.0, states);
    monitor.step(0.1, {});
    const V left = monitor.predictedState(*monitor.bodyIndex("ball_1"), 0.1)->second;
    const V middle = monitor.predictedState(*monitor.bodyIndex("ball_2"), 0.1)->second;
    const V right = monitor.predictedState(*monitor.bodyIndex("ball_3"), 0.1)->second;
    EXPECT_EQ(left.x(), -right.x()) << e;
    EXPECT_NEAR(left.x(), -e, 4 * kEps) << e;
    EXPECT_NEAR(middle.x(), 0.0, 4 * kEps) << e;
  }
}

TEST(HardCases, ThreeBallsStrikeACentralOneFrom120DegreesApart) {
  // A cyclic symmetry: by the joint solve (A = [[2, -1/2, -1/2], ...], J = (1 + e) v each) the
  // centre stays and each ball leaves along its line at -e v.
  const double e = 0.8;
  Scene scene;
  ASSERT_TRUE(scene.materials.addMaterial("steel", Material{e, {}}, "m").ok());
  for (const char* id : {"centre", "one", "two", "three"}) {
    BodySpec body;
    body.id = id;
    body.mass = 1.0;
    body.radius = 0.1;
    body.material = "steel";
    scene.bodies.push_back(body);
  }
  ImpactMonitor monitor(scene, MonitorSettings{});
  std::vector<BodyStateSample> states;
  BodyStateSample centre;
  centre.body = *monitor.bodyIndex("centre");
  states.push_back(centre);
  const char* ids[3] = {"one", "two", "three"};
  for (int k = 0; k < 3; ++k) {
    const double angle = 2 * M_PI * k / 3;
    const V direction(std::cos(angle), std::sin(angle), 0);
    BodyStateSample s;
    s.body = *monitor.bodyIndex(ids[k]);
    s.position = 0.3 * direction;  // surfaces 0.1 m apart
    s.velocity = -direction;
    states.push_back(s);
  }
  monitor.step(0.0, states);
  monitor.step(0.2, {});
  EXPECT_LE(monitor.predictedState(centre.body, 0.2)->second.norm(), 8 * kEps);
  for (int k = 0; k < 3; ++k) {
    const V after = monitor.predictedState(*monitor.bodyIndex(ids[k]), 0.2)->second;
    EXPECT_NEAR(after.norm(), e, 8 * kEps) << ids[k];
  }
}

TEST(HardCases, EveryPermutationOfTheBodyOrderGivesTheSameAnswer) {
  // The 5-ball cradle (e = 0.9) listed in every one of the 120 orders, its states in every order.
  const std::vector<double> reference = strikeRow(rowScene(5, 0.9), 5, identity(5));
  std::vector<std::size_t> order = identity(5);
  int permutations = 0;
  do {
    Scene scene = rowScene(5, 0.9);
    std::vector<BodySpec> listed;
    for (const std::size_t i : order) listed.push_back(scene.bodies[i]);
    scene.bodies = listed;
    ASSERT_EQ(strikeRow(scene, 5, order), reference) << "permutation " << permutations;
    ++permutations;
  } while (std::next_permutation(order.begin(), order.end()));
  EXPECT_EQ(permutations, 120);
}

// --- 7. The restitution threshold ---------------------------------------------------------------

/// A ball against a wall at `speed` (no gravity), the scene's threshold 0.5 m/s, e = 0.8: the
/// restitution the impact used.
double restitutionAtSpeed(double speed) {
  Scene scene;
  EXPECT_TRUE(scene.materials.addMaterial("rubber", Material{0.8, {}}, "m").ok());
  scene.restitution_threshold = 0.5;
  BodySpec ball;
  ball.id = "ball";
  ball.radius = 0.1;
  ball.material = "rubber";
  scene.bodies = {ball};
  ObstacleSpec wall;
  wall.id = "wall";
  wall.material = "rubber";
  wall.normal = V(-1, 0, 0);
  wall.offset = -1.0;  // the plane x = 1, free towards -x
  scene.obstacles = {wall};
  ImpactMonitor monitor(scene, MonitorSettings{});
  BodyStateSample state;
  state.position = V(0.5, 0, 0);  // 0.4 m from the wall: contact after 0.8 s
  state.velocity = V(speed, 0, 0);
  monitor.step(0.0, {state});
  const StepReport report = monitor.step(0.9, {});
  EXPECT_EQ(report.impacts.size(), 1u) << speed;
  return report.impacts.empty() ? NAN : report.impacts[0].restitution;
}

TEST(HardCases, ThresholdApproachExactlyAtItBounces) { EXPECT_EQ(restitutionAtSpeed(0.5), 0.8); }

TEST(HardCases, ThresholdApproachJustBelowItRests) {
  EXPECT_EQ(restitutionAtSpeed(std::nextafter(0.5, 0.0)), 0.0);
}

TEST(HardCases, ThresholdApproachJustAboveItBounces) {
  EXPECT_EQ(restitutionAtSpeed(std::nextafter(0.5, 1.0)), 0.8);
}

// 8. A ball bouncing to rest under gravity: Gravity.BallBouncesToRestInFinitelyManyImpacts and
// Gravity.ZeroThresholdStillComesToRest in test_effects.cpp.

}  // namespace
}  // namespace collision_response::core

namespace collision_response::core {
namespace {

// --- Found by the fuzzers (fuzz/), each a regression test -------------------------------------

// (The 1e370 mass ratio is the data case ratio_1e370_heavy_share, in
// MassRatiosFrom1eMinus15To1e15InBothOrders.)

// A plane approached at 1e200 m/s under gravity: rate^2 overflowed the discriminant.
TEST(FuzzFindings, BallisticRootWithAHugeRate) {
  const auto t = timeOfImpactPlaneBallistic(1.0, -1e200, -9.81, 1.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 1e-200, 4 * kEps * 1e-200);  // gap / |rate|; gravity adds 1e-600 relative
  // Deep inside with a subnormal acceleration: gap / scale overflowed to a bogus root at -0.
  EXPECT_FALSE(timeOfImpactPlaneBallistic(-5.4861293007693085e+303, -1.9999847412109375e-235,
                                          3.9525251667299724e-323, 8.0));
}

// Rates and sqrt(2 a gap) near the doubles' largest: sqrt(D) overflowed, the root came out
// 0 (a contact 1e308 m away) or none. gap 1e308, rate -1.5e308, a = -1e308: t^2 + 3 t - 2 = 0;
// gap 1e308, rate -1.7e308, a = -1.7e308: 0.85 t^2 + 1.7 t - 1 = 0 (sqrt(2) u overflowed too).
TEST(FuzzFindings, BallisticRootPastTheDoubles) {
  // Divided by a: t^2 / 2 + r t + g = 0 with r = rate / a, g = gap / a (in long double, from
  // the doubles given); the entering root is -r + sqrt(r^2 - 2 g).
  const auto exact = [](double gap, double rate, double acceleration) {
    const long double r = static_cast<long double>(rate) / acceleration,
                      g = static_cast<long double>(gap) / acceleration;
    return static_cast<double>(-r + std::sqrt(r * r - 2 * g));
  };
  for (const auto& [gap, rate, acceleration] :
       {std::tuple{1e308, -1.5e308, -1e308}, std::tuple{1e308, -1.7e308, -1.7e308}}) {
    const auto t = timeOfImpactPlaneBallistic(gap, rate, acceleration, 10.0);
    ASSERT_TRUE(t) << rate;
    EXPECT_NEAR(*t, exact(gap, rate, acceleration), 8 * kEps) << rate;
  }
}

// A subnormal gap under a subnormal acceleration (7.3e-313 m, 1.2e-319 m/s^2, from rest):
// sqrt|a| sqrt|gap| fell among the subnormals and the root came out 1 % early. From rest,
// t = sqrt(2 gap / |a|).
TEST(FuzzFindings, BallisticRootAmongTheSubnormals) {
  const double gap = 7.2945696177e-313, acceleration = -1.17627e-319;
  const auto t = timeOfImpactPlaneBallistic(gap, 0.0, acceleration, 1e255);
  ASSERT_TRUE(t);
  const double exact =
      static_cast<double>(std::sqrt(2 * static_cast<long double>(gap) / -acceleration));
  EXPECT_NEAR(*t, exact, 8 * kEps * exact);
}

// A subnormal rate (3.2e-319 m/s, leaving) falling back under 1.2e-45 m/s^2: t = 2 rate / |a|,
// which halving the rate before summing lost to rounding.
TEST(FuzzFindings, BallisticReturnWithASubnormalRate) {
  const double rate = 3.2378592100206092e-319, acceleration = -1.1999969482421875e-45;
  const auto t = timeOfImpactPlaneBallistic(0.0, rate, acceleration, 1.0);
  ASSERT_TRUE(t);
  const long double expected = 2.0L * rate / -static_cast<long double>(acceleration);
  EXPECT_NEAR(*t, static_cast<double>(expected), 4 * kEps * static_cast<double>(expected));
}

// Falling at 1 m/s under 1e-300 m/s^2: the quartic's leading coefficient underflowed to zero
// and the companion matrix divided by it. Now it is the straight answer, t = 1.
TEST(FuzzFindings, AcceleratedSpheresWithANegligibleAcceleration) {
  const auto t =
      timeOfImpactSpheresAccelerated(V(0, 0, 2), V(0, 0, -1), V(0, 0, -1e-300), 1.0, 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 1.0, 1e-12);
}

// A huge ball (1e145 kg, radius 1e145 m) sliding on an immovable floor with friction and spin:
// its 1/I = w / (k r^2) underflowed to 0, the friction impulse came out 3.5 times too large,
// reversed the slip and added energy. Scale does not change the closed form: sticking, it rolls
// away at (5/7) v_x.
TEST(FuzzFindings, FrictionOnAHugeSpinningBall) {
  CollisionRequest request;
  request.a.mass = kImmovableMass;
  request.b.mass = 1e145;
  request.b.radius = 1e145;
  request.b.position = V(0, 0, 1e145);
  request.b.velocity = V(3, 0, -4);
  request.restitution = 0.5;
  request.friction = 1.0;
  request.effects = {"friction", "spin"};
  const auto outcome = computeCollision(request, MaterialTable::seed());
  ASSERT_TRUE(outcome.ok()) << outcome.error().message();
  EXPECT_TRUE(outcome->sticking);
  EXPECT_NEAR(outcome->impact.velocity_b.x(), 15.0 / 7.0, 8 * kEps * 3);
  EXPECT_NEAR(outcome->angular_velocity_b.y() * 1e145, 15.0 / 7.0, 1e-12);  // rolls: w r = v
}

/// A ball as the monitor fuzzer makes one (fuzz/fuzz_monitor.cpp, makeScene).
BodySpec fuzzedBall(const std::string& id, double mass, double radius, const std::string& material,
                    Inertia inertia = Inertia::kSolid) {
  BodySpec body;
  body.id = id;
  body.mass = mass;
  body.radius = radius;
  body.material = material;
  body.inertia = inertia;
  return body;
}

/// The monitor fuzzer's scene of the rounds findings: discrete detection, gravity and friction,
/// the balls given, a concrete plane "floor" and a wooden sphere "post"; checked and normalized
/// as the loader does.
Scene fuzzedFloorAndPost(std::vector<BodySpec> bodies, const V& floor_normal, double floor_offset,
                         const V& post_position, double post_radius) {
  Scene scene;
  scene.detection = Detection::kDiscrete;
  scene.effects.gravity = true;
  scene.effects.friction = true;
  scene.bodies = std::move(bodies);
  ObstacleSpec floor;
  floor.id = "floor";
  floor.material = "concrete";
  floor.normal = floor_normal;
  floor.offset = floor_offset;
  ObstacleSpec post;
  post.id = "post";
  post.shape = ObstacleShape::kSphere;
  post.material = "wooden_ball";
  post.position = post_position;
  post.radius = post_radius;
  scene.obstacles = {floor, post};
  EXPECT_TRUE(validateScene(scene, "scene").ok());
  normalizePlanes(scene);
  return scene;
}

/// A ball "b0" and a 1.5e175 kg ball "b1" between a floor of normal (1, floor_y, floor_z) at
/// x = -4.125 and a post at x = post_x, with the fuzzed masses and radii as they came.
struct FloorAndPost {
  double b0_mass, b0_radius, b1_mass, floor_y, floor_z, post_x, post_radius;
};
Scene floorAndPostScene(const FloorAndPost& v) {
  return fuzzedFloorAndPost({fuzzedBall("b0", v.b0_mass, v.b0_radius, "billiard_ball"),
                             fuzzedBall("b1", v.b1_mass, 1.380645751953125e-235, "hand_ball")},
                            V(1, v.floor_y, v.floor_z), -4.125,
                            V(v.post_x, -4.125, 1.2442169189453123e-240), v.post_radius);
}

/// The step's rounds ended early: under 1,000 impacts (each input took 10,000 rounds before),
/// one fallback, and both balls' velocities finite.
void expectRoundsEndedEarly(const ImpactMonitor& monitor, const StepReport& report, double now,
                            double b0_mass) {
  EXPECT_LT(report.impacts.size(), 1000u) << b0_mass;
  EXPECT_EQ(report.fallbacks, 1u) << b0_mass;
  for (const std::size_t body : {0u, 1u}) {
    EXPECT_TRUE(monitor.predictedState(body, now)->second.allFinite()) << b0_mass << " " << body;
  }
}

// Found by the monitor's fuzzer: b1 and b0 caught between the floor and the post at mass ratios
// past what a joint solve can resolve. b0 1e70 times heavier: the solve cannot stop it (its
// impulse is below its velocity's last bit), so every plastic round ended where the one before
// did; 1e100 heavier: the same, a last bit away each round; 1e410 lighter: b1 drives b0 against
// the post and is not slowed at all, b0's approach the same every round. Each spent the
// instant's 10,000 rounds (15,413, 19,950 and 15,000 impacts, 2.5 s to 15 s) before the
// fallback. Now a round that ends where one of the last few did, the eighth plastic round in a
// row in which only its own contacts strike again, or a contact of a body an impulse leaves
// unchanged struck 64 times in a row no slower than before, ends the rounds.
TEST(FuzzFindings, RoundsThatCannotConvergeEndEarly) {
  for (const FloorAndPost& variant :
       {FloorAndPost{1.4506683349609377e+245, 1.185089111328125e+240, 1.4509735107421873e+175,
                     -4.7259604762489261e-180, 5.8823125076715362e-180, 12431335449.21875,
                     1.5215606689453124e-240},
        FloorAndPost{1.1850738525390624e+275, 1.372589111328125e+240, 1.4509735107421873e+175,
                     -4.7259604762489261e-180, 5.8823125076715362e-180, 12431335449.21875,
                     1.5215606689453124e-240},
        FloorAndPost{1.4506683349609375e-235, 1.9999847412109377e+240, 1.4509735107421873e+175,
                     -4.9761418564375631e-180, 6.1937084808850516e-180, 12118835449.21875,
                     1.5215606689453124e-240}}) {
    ImpactMonitor monitor(floorAndPostScene(variant), MonitorSettings{});
    BodyStateSample first;
    first.body = *monitor.bodyIndex("b1");
    first.position =
        V(-1.5215606689453124e-240, -1.5215606689453124e-240, -1.5215606689453124e-240);
    first.velocity = V(-15215606689.453125, -4.125, -1.5686187744140626e-125);
    monitor.step(0.0, {first});
    BodyStateSample second;
    second.body = *monitor.bodyIndex("b0");
    second.time = 0.447;
    expectRoundsEndedEarly(monitor, monitor.step(0.447, {second}), 0.447, variant.b0_mass);
  }
}

// Found by the monitor's fuzzer (a slow unit: 42 s under the sanitizers): a 1.5e-235 kg ball
// sliding at 1.07 m/s in a wedge of the floor and a post whose normals are 1e-11 rad from
// opposite. The post was struck at the same approach every round (the plastic floor removing
// only its own component): 10,000 rounds and 10,002 impacts. Both are immovable, and a contact
// of an immovable body struck 64 times in a row no slower than before ends the rounds.
TEST(FuzzFindings, RoundsInAWedgeOfNearlyOppositeNormalsEndEarly) {
  const FloorAndPost wedge{1.4506683349609375e-235, 1.9999847412109377e+240,
                           1.4492340087890625e+175, -4.9761418564375631e-180,
                           6.1937084808850516e-180, 12431335449.21875,
                           1.5215606689453127e-295};
  ImpactMonitor monitor(floorAndPostScene(wedge), MonitorSettings{});
  BodyStateSample first;
  first.body = *monitor.bodyIndex("b1");
  first.position = V(-1.5215606689453124e-235, -1.5215606689453124e-240, -1.5215606689453124e-240);
  first.velocity = V(-1.5215606689453124e-240, 1.168914794921875e-180, -15669403076.171875);
  monitor.step(0.0, {first});
  const double now = 184000000 * 1e-9;  // the time line's nanoseconds, as the node takes them
  BodyStateSample b1_later;
  b1_later.body = first.body;
  b1_later.time = now;
  b1_later.position = V(1.848175048828125e-180, 1.997039794921875e-235, -12538909912.109375);
  BodyStateSample b0_state;
  b0_state.body = *monitor.bodyIndex("b0");
  b0_state.time = 39000000 * 1e-9;
  expectRoundsEndedEarly(monitor, monitor.step(now, {b1_later, b0_state}), now, wedge.b0_mass);
}

// Found by the monitor's fuzzer (a timeout: 160 s under the sanitizers, 13 s in release): a
// 1.2e275 kg ball b0 whose radius (1.4e240 m) holds every other body, falling onto the post
// beside a 1e80 kg ball b2. b0's row in the joint solve is 1e195 times below b2's, past the
// doubles: the solve gave its contact with the immovable post no impulse, so it struck again at the
// same approach (0.197 m/s) every round, 10,000 rounds and 39,999 impacts before the fallback.
// A contact struck again no slower that the solve gives no impulse is one it cannot move: like a
// contact of an unmoved body, 64 such strikes in a row end the rounds.
TEST(FuzzFindings, RoundsWithAContactTheSolveLeavesUnresolvedEndEarly) {
  const Scene scene = fuzzedFloorAndPost(
      {fuzzedBall("b0", 1.1850738525390624e+275, 1.372589111328125e+240, "billiard_ball"),
       fuzzedBall("b1", 1.4509735107421876e+270, 1.3749847412109374e-235, "rubber_band_ball"),
       fuzzedBall("b2", 1.00115966796875e+80, 1.29803466796875e+80, "wooden_ball",
                  Inertia::kHollow)},
      V(1.29803466796875e+80, -1.0900715865557387e-175, 12431335449.21875), 12431335449.21875,
      V(1.2436523437500001e-130, -5.875, -4.125), 4.125);
  MonitorSettings settings;
  settings.contact_tolerance = 0.296875;
  ImpactMonitor monitor(scene, settings);
  const double tiny = -1.5215606689453124e-240;
  BodyStateSample first;
  first.body = *monitor.bodyIndex("b2");
  first.position = V(tiny, tiny, tiny);
  first.velocity = V(tiny, tiny, tiny);
  monitor.step(0.0, {first});
  // The time line's nanoseconds, as the node takes them (stamps 0.593, 0.764 and 0.799 s).
  const double now = 206000000 * 1e-9;
  BodyStateSample b1_state;
  b1_state.body = *monitor.bodyIndex("b1");
  b1_state.time = now;
  b1_state.position = V(-1.1348419189453125e-240, -1.5215606689453124e-240, -1.29803466796875e+80);
  b1_state.velocity = V(1.5686187744140626e-125, 1.848175048828125e-180, 1.997039794921875e-235);
  BodyStateSample b0_state;
  b0_state.body = *monitor.bodyIndex("b0");
  b0_state.time = 171000000 * 1e-9;
  const StepReport report = monitor.step(now, {b1_state, b0_state});
  EXPECT_LT(report.impacts.size(), 1000u);
  EXPECT_EQ(report.fallbacks, 1u);
  for (const char* id : {"b0", "b1", "b2"}) {
    EXPECT_TRUE(monitor.predictedState(*monitor.bodyIndex(id), now)->second.allFinite()) << id;
  }
}

}  // namespace
}  // namespace collision_response::core
