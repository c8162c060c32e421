// Stepped clusters: one sub-step of solveSteppedSubstep against closed forms (a stack carries the
// weight above each contact, a bounce leaves at e u, a fall stops at the floor), and the monitor
// stepping a pile that settles in a box: never inside anything, never gaining energy, at rest,
// and bit for bit the same whatever the bodies are called.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "collision_response/core/monitor.h"
#include "scene_builders.h"
#include "solver/stepped_contact.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
constexpr double kG = 9.81;

// --- one sub-step ---------------------------------------------------------------------------

SteppedBody movable(double mass, double radius, const V& velocity, const V& kick) {
  SteppedBody body;
  body.inverse_mass = 1.0 / mass;
  body.radius = radius;
  body.velocity = velocity;
  body.kick = kick;
  return body;
}

SteppedBody fixedPlane() { return SteppedBody{}; }

/// A contact between participants a and b with the normal a -> b, a's centre at `centre_a`.
SteppedContact contact(std::size_t a, std::size_t b, const V& normal, const V& centre_a,
                       double radius_a, double gap, double band, double restitution = 0.5) {
  SteppedContact c;
  c.a = a;
  c.b = b;
  c.normal = normal;
  c.point = centre_a + radius_a * normal;
  c.gap = gap;
  c.band = band;
  c.restitution = restitution;
  return c;
}

double kinetic(const std::vector<SteppedBody>& bodies, const std::vector<V>& velocity) {
  double energy = 0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].inverse_mass > 0)
      energy += 0.5 * velocity[i].squaredNorm() / bodies[i].inverse_mass;
  }
  return energy;
}

// A stack of five balls (m, r) at rest on a floor, each touching the next. Over a sub-step h,
// gravity gives each ball -g h; staying at rest, the contact under ball k carries the weight of
// the balls from k up: (5 - k) m g h, a force (5 - k) m g. Every velocity stays 0.
TEST(SteppedSubstep, AStackCarriesTheWeightAboveEachContact) {
  const double m = 0.1, r = 0.05, h = 0.01, band = 1e-9 * 2 * r;
  std::vector<SteppedBody> bodies;
  std::vector<SteppedContact> contacts;
  for (int k = 0; k < 5; ++k) bodies.push_back(movable(m, r, V::Zero(), V(0, 0, -kG * h)));
  bodies.push_back(fixedPlane());  // the floor: participant 5
  contacts.push_back(contact(0, 5, V(0, 0, -1), V(0, 0, r), r, 0.0, band));
  for (int k = 0; k + 1 < 5; ++k) {
    contacts.push_back(contact(k, k + 1, V(0, 0, 1), V(0, 0, (2 * k + 1) * r), r, 0.0, band));
  }
  SteppedSettings settings;
  settings.duration = h;
  const SteppedOutcome outcome = solveSteppedSubstep(bodies, contacts, settings);
  ASSERT_TRUE(outcome.converged);
  EXPECT_FALSE(outcome.held);
  EXPECT_EQ(outcome.duration, h);
  // The residual the solve allows is a quarter of the band per sub-step (m/s).
  const double residual = 0.25 * band / h;
  for (int k = 0; k < 5; ++k)
    EXPECT_LE(outcome.velocity[static_cast<std::size_t>(k)].norm(), 2 * residual) << k;
  EXPECT_NEAR(outcome.contacts[0].keeping_impulse, 5 * m * kG * h, 5 * m * residual);
  for (int k = 1; k < 5; ++k) {
    EXPECT_NEAR(outcome.contacts[static_cast<std::size_t>(k)].keeping_impulse, (5 - k) * m * kG * h,
                5 * m * residual)
        << k;
    EXPECT_EQ(outcome.contacts[static_cast<std::size_t>(k)].bounce_impulse, 0.0);  // none strikes
  }
}

// A ball touching the floor and approaching at u = 2 m/s, e = 0.5: it leaves at e u = 1 m/s
// (Newton's and Poisson's laws agree for one contact), then gravity takes g h off. Its gap at the
// sub-step's end, (e u - g h) h > 0, needs no keeping.
TEST(SteppedSubstep, ABallStrikingTheFloorLeavesAtEU) {
  const double m = 0.2, r = 0.1, h = 0.01, u = 2.0, e = 0.5;
  std::vector<SteppedBody> bodies = {movable(m, r, V(0, 0, -u), V(0, 0, -kG * h)), fixedPlane()};
  std::vector<SteppedContact> contacts = {
      contact(0, 1, V(0, 0, -1), V(0, 0, r), r, 0.0, 1e-9 * r, e)};
  SteppedSettings settings;
  settings.duration = h;
  const SteppedOutcome outcome = solveSteppedSubstep(bodies, contacts, settings);
  ASSERT_TRUE(outcome.converged);
  EXPECT_TRUE(outcome.contacts[0].struck);
  EXPECT_DOUBLE_EQ(outcome.contacts[0].approach_speed, u);
  EXPECT_NEAR(outcome.velocity[0].z(), e * u - kG * h, 1e-15);
  EXPECT_NEAR(outcome.contacts[0].bounce_impulse, m * (1 + e) * u, 1e-15);
  EXPECT_EQ(outcome.contacts[0].keeping_impulse, 0.0);
}

// A ball 1 mm above the floor falling at 1 m/s would be 9 mm inside it after 10 ms: it lands at
// the sub-step's end instead, moving at -gap / h = -0.1 m/s over the sub-step.
TEST(SteppedSubstep, AFallStopsAtTheFloorNotInIt) {
  const double m = 0.1, r = 0.05, h = 0.01, gap = 1e-3, band = 1e-9 * r;
  std::vector<SteppedBody> bodies = {movable(m, r, V(0.3, 0, -1.0), V(0, 0, -kG * h)),
                                     fixedPlane()};
  std::vector<SteppedContact> contacts = {
      contact(0, 1, V(0, 0, -1), V(0, 0, r + gap), r, gap, band)};
  SteppedSettings settings;
  settings.duration = h;
  const SteppedOutcome outcome = solveSteppedSubstep(bodies, contacts, settings);
  ASSERT_TRUE(outcome.converged);
  EXPECT_FALSE(outcome.contacts[0].struck);  // not touching yet: no bounce
  EXPECT_NEAR(outcome.velocity[0].z(), -gap / h, 0.25 * band / h);
  EXPECT_EQ(outcome.velocity[0].x(), 0.3);  // frictionless: the tangential part is untouched
}

// The same fall, one sub-step on: the ball touches the floor, closing at the -gap / h the gap
// keeping left it, but it arrived at 1 m/s + g h (its speed over the sub-step before, reported
// as arrival_speed). It leaves at e times the arrival speed, then gravity takes g h off.
TEST(SteppedSubstep, AnArrivalBouncesAtETimesItsSpeed) {
  const double m = 0.1, r = 0.05, h = 0.01, gap = 1e-3, band = 1e-9 * r, e = 0.5;
  std::vector<SteppedBody> bodies = {movable(m, r, V(0, 0, -1.0), V(0, 0, -kG * h)), fixedPlane()};
  std::vector<SteppedContact> contacts = {
      contact(0, 1, V(0, 0, -1), V(0, 0, r + gap), r, gap, band, e)};
  SteppedSettings settings;
  settings.duration = h;
  const SteppedOutcome landing = solveSteppedSubstep(bodies, contacts, settings);
  const double arrival = 1.0 + kG * h;
  EXPECT_NEAR(landing.contacts[0].arrival_speed, arrival, 1e-15);
  bodies[0].velocity = landing.velocity[0];
  contacts[0].gap = 0.0;
  contacts[0].point = V(0, 0, 0);
  contacts[0].arrival_speed = landing.contacts[0].arrival_speed;
  const SteppedOutcome bounce = solveSteppedSubstep(bodies, contacts, settings);
  ASSERT_TRUE(bounce.converged);
  EXPECT_TRUE(bounce.contacts[0].struck);
  EXPECT_NEAR(bounce.velocity[0].z(), e * arrival - kG * h, 1e-12);
  EXPECT_EQ(bounce.contacts[0].arrival_speed, 0.0);  // touching at its start: no arrival
}

/// A random cluster: `count` balls in a loose heap on a floor, touching or near each other,
/// with random velocities; every pair within `near` and every ball within `near` of the floor is
/// a contact. Restitution from `restitutions`, per contact.
struct RandomCluster {
  std::vector<SteppedBody> bodies;
  std::vector<SteppedContact> contacts;
  std::vector<V> centres;
};
RandomCluster randomCluster(std::mt19937_64& engine, int count,
                            const std::vector<double>& restitutions, bool gravity) {
  std::uniform_real_distribution<double> unit(-1, 1);
  std::uniform_int_distribution<std::size_t> pick(0, restitutions.size() - 1);
  RandomCluster cluster;
  const double r = 0.05, near = 0.02;
  const double h = 0.01;
  while (static_cast<int>(cluster.centres.size()) < count) {
    const V centre(0.3 * unit(engine), 0.3 * unit(engine), r + 0.15 * (1 + unit(engine)));
    bool clear = true;
    for (const V& other : cluster.centres) clear = clear && (other - centre).norm() >= 2 * r;
    if (!clear) continue;
    cluster.centres.push_back(centre);
    const double mass = 0.05 + 0.1 * (1 + unit(engine));
    cluster.bodies.push_back(movable(mass, r, V(unit(engine), unit(engine), unit(engine)),
                                     gravity ? V(0, 0, -kG * h) : V::Zero()));
  }
  cluster.bodies.push_back(fixedPlane());
  const std::size_t floor = cluster.bodies.size() - 1;
  for (std::size_t i = 0; i < cluster.centres.size(); ++i) {
    const double floor_gap = cluster.centres[i].z() - r;
    if (floor_gap <= near) {
      cluster.contacts.push_back(contact(i, floor, V(0, 0, -1), cluster.centres[i], r, floor_gap,
                                         1e-9 * r, restitutions[pick(engine)]));
    }
    for (std::size_t j = i + 1; j < cluster.centres.size(); ++j) {
      const V separation = cluster.centres[j] - cluster.centres[i];
      const double gap = separation.norm() - 2 * r;
      if (gap <= near) {
        cluster.contacts.push_back(contact(i, j, separation.normalized(), cluster.centres[i], r,
                                           gap, 1e-9 * 2 * r, restitutions[pick(engine)]));
      }
    }
  }
  return cluster;
}

// Without gravity every stage removes kinetic energy: the bounce stage's compression, its
// restitution (scaled down where contacts with different coefficients would add some), and the
// gap keeping (a projection whose targets keep or close gaps). Random heaps of 30 balls with e
// 0, 0.5, 1 and mixed: never a gain beyond rounding.
TEST(SteppedSubstep, NoStageAddsKineticEnergy) {
  std::mt19937_64 engine(7);
  const std::vector<std::vector<double>> mixes = {{0.0}, {0.5}, {1.0}, {0.0, 1.0}, {0.2, 0.9, 1.0}};
  for (int trial = 0; trial < 20; ++trial) {
    const RandomCluster cluster = randomCluster(engine, 30, mixes[trial % mixes.size()], false);
    SteppedSettings settings;
    settings.duration = 0.01;
    const SteppedOutcome outcome = solveSteppedSubstep(cluster.bodies, cluster.contacts, settings);
    std::vector<V> before;
    for (const SteppedBody& body : cluster.bodies) before.push_back(body.velocity);
    const double start = kinetic(cluster.bodies, before);
    EXPECT_LE(kinetic(cluster.bodies, outcome.velocity), start * (1 + 1e-12)) << trial;
  }
}

// Every contact's gap at the sub-step's end, gap + d' h (d' the normal relative velocity over
// it), is at most a quarter of its band below 0 (the residual the solve allows), whatever the
// velocities: random heaps under gravity, 20 of them.
TEST(SteppedSubstep, NoGapClosesPastAQuarterOfItsBand) {
  std::mt19937_64 engine(8);
  for (int trial = 0; trial < 20; ++trial) {
    const RandomCluster cluster = randomCluster(engine, 30, {0.5}, true);
    SteppedSettings settings;
    settings.duration = 0.01;
    const SteppedOutcome outcome = solveSteppedSubstep(cluster.bodies, cluster.contacts, settings);
    ASSERT_FALSE(outcome.held) << trial;
    for (const SteppedContact& c : cluster.contacts) {
      const double closing = c.normal.dot(outcome.velocity[c.b] - outcome.velocity[c.a]);
      EXPECT_GE(c.gap + closing * outcome.duration, -0.25 * c.band * (1 + 1e-9)) << trial;
    }
  }
}

// The solve visits contacts in the order of their points, so listing the bodies and contacts in
// another order gives the same velocities and impulses to the bit.
TEST(SteppedSubstep, TheOrderOfBodiesAndContactsChangesNoBit) {
  std::mt19937_64 engine(9);
  const RandomCluster cluster = randomCluster(engine, 30, {0.0, 0.5, 1.0}, true);
  SteppedSettings settings;
  settings.duration = 0.01;
  const SteppedOutcome reference = solveSteppedSubstep(cluster.bodies, cluster.contacts, settings);
  std::vector<std::size_t> body_order(cluster.bodies.size());
  std::iota(body_order.begin(), body_order.end(), 0);
  std::shuffle(body_order.begin(), body_order.end(), engine);
  std::vector<std::size_t> place(body_order.size());
  std::vector<SteppedBody> bodies;
  for (std::size_t i = 0; i < body_order.size(); ++i) {
    place[body_order[i]] = i;
    bodies.push_back(cluster.bodies[body_order[i]]);
  }
  std::vector<std::size_t> contact_order(cluster.contacts.size());
  std::iota(contact_order.begin(), contact_order.end(), 0);
  std::shuffle(contact_order.begin(), contact_order.end(), engine);
  std::vector<SteppedContact> contacts;
  for (const std::size_t k : contact_order) {
    SteppedContact c = cluster.contacts[k];
    c.a = place[c.a];
    c.b = place[c.b];
    contacts.push_back(c);
  }
  const SteppedOutcome shuffled = solveSteppedSubstep(bodies, contacts, settings);
  for (std::size_t i = 0; i < body_order.size(); ++i) {
    EXPECT_EQ(shuffled.velocity[i], reference.velocity[body_order[i]]) << i;
  }
  for (std::size_t j = 0; j < contact_order.size(); ++j) {
    EXPECT_EQ(shuffled.contacts[j].keeping_impulse,
              reference.contacts[contact_order[j]].keeping_impulse);
    EXPECT_EQ(shuffled.contacts[j].bounce_impulse,
              reference.contacts[contact_order[j]].bounce_impulse);
  }
}

// Seven balls spanning a box of seven diameters exactly, one pair overlapping by 1e-13 m (the
// rounding of positions), gravity along the row pressing it into the end wall. No velocities
// open every gap (the row is wedged): the solve keeps them from closing instead. The row stays
// still, and the end wall carries the row's weight, 7 m g h.
TEST(SteppedSubstep, AWedgedRowIsHeldNotPushedApart) {
  const double m = 0.1, r = 0.05, h = 0.01, band = 1e-9 * 2 * r;
  std::vector<SteppedBody> bodies;
  for (int k = 0; k < 7; ++k) bodies.push_back(movable(m, r, V::Zero(), V(-kG * h, 0, 0)));
  bodies.push_back(fixedPlane());  // 7: the wall at x = 0
  bodies.push_back(fixedPlane());  // 8: the wall at x = 14 r
  std::vector<SteppedContact> contacts;
  contacts.push_back(contact(0, 7, V(-1, 0, 0), V(r, 0, 0), r, 0.0, 1e-9 * r));
  for (int k = 0; k + 1 < 7; ++k) {
    contacts.push_back(
        contact(k, k + 1, V(1, 0, 0), V((2 * k + 1) * r, 0, 0), r, k == 3 ? -1e-13 : 0.0, band));
  }
  contacts.push_back(contact(6, 8, V(1, 0, 0), V(13 * r, 0, 0), r, 0.0, 1e-9 * r));
  SteppedSettings settings;
  settings.duration = h;
  const SteppedOutcome outcome = solveSteppedSubstep(bodies, contacts, settings);
  EXPECT_FALSE(outcome.held);
  const double residual = 0.25 * 1e-9 * r / h;
  for (int k = 0; k < 7; ++k)
    EXPECT_LE(outcome.velocity[static_cast<std::size_t>(k)].norm(), 2 * residual) << k;
  EXPECT_NEAR(outcome.contacts[0].keeping_impulse, 7 * m * kG * h, 7 * m * residual);
}

// --- the monitor ------------------------------------------------------------------------------

BodySpec ball(const std::string& id, double mass, double radius) {
  return scene_builders::ball(id, mass, radius, "pile");
}

/// A closed box [0, size]^3 of six planes, e = 0.5 for every pair, gravity (0, 0, -g).
/// `box_floor`: the floor is the top face of a box (0.2 m thick, reaching past the walls) rather
/// than a plane.
Scene boxScene(double size, bool box_floor = false) {
  Scene scene;
  scene.effects.gravity = true;
  scene.gravity = V(0, 0, -kG);
  EXPECT_TRUE(scene.materials.addMaterial("pile", Material{0.5, {}}, "m").ok());
  const V normals[] = {V(1, 0, 0), V(-1, 0, 0), V(0, 1, 0), V(0, -1, 0), V(0, 0, 1), V(0, 0, -1)};
  for (int w = 0; w < 6; ++w) {
    ObstacleSpec wall;
    wall.id = "wall_" + std::to_string(w);
    wall.normal = normals[w];
    wall.offset = w % 2 ? -size : 0.0;
    wall.material = "pile";
    if (box_floor && w == 4) {
      wall.shape = ObstacleShape::kBox;
      wall.size = V(size + 1, size + 1, 0.2);
      wall.position = V(0.5 * size, 0.5 * size, -0.1);
    }
    scene.obstacles.push_back(wall);
  }
  return scene;
}

struct PileRun {
  std::vector<V> final_positions;  // by the order the balls were listed
  double deepest_into_ball = 0, deepest_into_wall = 0, gain = 0, kinetic_end = 0, released = 0;
  std::size_t most_stepped = 0, fallbacks = 0;
  std::size_t most_stepped_work = 0;  // of a step (MonitorSettings::max_stepped_work_per_step)
  std::size_t held_over_work = 0;     // bodies held over the stepped work, summed over the steps
};

/// 64 balls (r 0.05 m, 0.1 kg) on a loose 4 x 4 x 4 lattice (0.12 m apart, offsets up to 5 mm)
/// dropped into a box of 0.58 m, the monitor moving them itself at 100 Hz for `duration` s.
/// `name(i)`: ball i's id. At every step: the deepest overlap of any pair or wall, the energy.
PileRun dropPile(double duration, const std::function<std::string(int)>& name,
                 bool box_floor = false,
                 std::size_t stepped_work_bound = MonitorSettings{}.max_stepped_work_per_step) {
  const int side = 4, count = side * side * side;
  const double r = 0.05, m = 0.1, spacing = 0.12, size = spacing * side + 0.1;
  Scene scene = boxScene(size, box_floor);
  std::mt19937_64 engine(11);
  std::uniform_real_distribution<double> offset(-0.005, 0.005);
  std::vector<V> start;
  for (int i = 0; i < count; ++i) {
    scene.bodies.push_back(ball(name(i), m, r));
    const V cell(i % side, (i / side) % side, i / (side * side));
    start.push_back(V(0.11, 0.11, 0.11) + spacing * cell +
                    V(offset(engine), offset(engine), offset(engine)));
  }
  MonitorSettings settings;
  settings.body_timeout = 1e9;  // the monitor moves the bodies itself: no states after the first
  settings.max_stepped_work_per_step = stepped_work_bound;
  ImpactMonitor monitor(scene, settings);
  std::vector<std::size_t> index;
  std::vector<BodyStateSample> states;
  PileRun out;
  for (int i = 0; i < count; ++i) {
    index.push_back(*monitor.bodyIndex(name(i)));
    BodyStateSample sample;
    sample.body = index.back();
    sample.position = start[static_cast<std::size_t>(i)];
    states.push_back(sample);
    out.released += m * kG * start[static_cast<std::size_t>(i)].z();
  }
  monitor.step(0.0, states);
  out.gain = -out.released;
  const int steps = static_cast<int>(std::lround(duration * 100));
  for (int k = 1; k <= steps; ++k) {
    const double t = k / 100.0;
    const StepReport report = monitor.step(t, {});
    out.most_stepped = std::max(out.most_stepped, report.stepped_bodies);
    out.fallbacks += report.fallbacks;
    out.most_stepped_work = std::max(out.most_stepped_work, report.stepped_work);
    out.held_over_work += report.over_stepped_work.size();
    double energy = 0, kinetic_energy = 0;
    std::vector<V> p(static_cast<std::size_t>(count));
    for (int i = 0; i < count; ++i) {
      const auto [position, velocity] =
          *monitor.predictedState(index[static_cast<std::size_t>(i)], t);
      p[static_cast<std::size_t>(i)] = position;
      energy += m * kG * position.z() + 0.5 * m * velocity.squaredNorm();
      kinetic_energy += 0.5 * m * velocity.squaredNorm();
      for (int axis = 0; axis < 3; ++axis) {
        out.deepest_into_wall =
            std::max({out.deepest_into_wall, r - position[axis], position[axis] - (size - r)});
      }
    }
    for (int i = 0; i < count; ++i) {
      for (int j = i + 1; j < count; ++j) {
        out.deepest_into_ball = std::max(
            out.deepest_into_ball,
            2 * r - (p[static_cast<std::size_t>(j)] - p[static_cast<std::size_t>(i)]).norm());
      }
    }
    out.gain = std::max(out.gain, energy - out.released);
    out.kinetic_end = kinetic_energy;
    if (k == steps) out.final_positions = p;
  }
  return out;
}

std::string plainName(int i) {
  std::string digits = std::to_string(i);
  return "ball_" + std::string(4 - std::min<std::size_t>(4, digits.size()), '0') + digits;
}

// 64 balls dropped into a box (e = 0.5): more than the 32 a stepped cluster needs, so the pile
// they make is time-stepped. Over 4 s at 100 Hz no ball is ever more than a quarter of the
// touching band (1e-9 of the contact distance) into another or into a wall, the energy never
// rises above the drop's, and the pile settles: its kinetic energy falls below 1e-6 of the drop's
// potential energy. (Not to 0: frictionless, a ball sliding on the floor keeps its speed until
// it meets a wall; seen: 1.2e-7 J, a ball at 1.5 mm/s, from 2.9 s to 3.9 s.)
TEST(SteppedClusters, APileSettlesInABoxNeverInsideAnything) {
  const PileRun run = dropPile(4.0, plainName);
  EXPECT_GE(run.most_stepped, 32u);
  EXPECT_EQ(run.fallbacks, 0u);
  EXPECT_LE(run.deepest_into_ball, 0.25 * 1e-9 * 0.1);
  EXPECT_LE(run.deepest_into_wall, 0.25 * 1e-9 * 0.05 + 1e-16);
  EXPECT_LE(run.gain, 1e-12 * run.released);
  EXPECT_LE(run.kinetic_end, 1e-6 * run.released);
}

// The same pile on the top face of a box instead of a floor plane (the stepped sub-steps keep
// their gaps to the box's face as to a plane's: the same contact geometry), over 2 s.
TEST(SteppedClusters, APileOnABoxFloorNeverInsideIt) {
  const PileRun run = dropPile(2.0, plainName, true);
  EXPECT_GE(run.most_stepped, 32u);
  EXPECT_EQ(run.fallbacks, 0u);
  EXPECT_LE(run.deepest_into_ball, 0.25 * 1e-9 * 0.1);
  EXPECT_LE(run.deepest_into_wall, 0.25 * 1e-9 * 0.05 + 1e-16);
  EXPECT_LE(run.gain, 1e-12 * run.released);
}

// Issue 41: a stepped update has a work bound of its own. The same pile with a stepped work
// bound of 20,000 a step (the default is 6,000,000): no step spends more than that and one search
// for near pairs (at most its 64 balls placed, their 2,016 pairs and 64 x 6 ball-wall pairs
// looked at), the sub-steps it cannot pay for hold their bodies still (named, and not counted as
// a wedge's fallback), and still no ball goes into another or a wall, no energy is gained.
TEST(SteppedClusters, PastTheStepsSteppedWorkItsBodiesAreHeldNeverInsideAnything) {
  const std::size_t bound = 20000;
  const PileRun run = dropPile(2.0, plainName, false, bound);
  EXPECT_GE(run.most_stepped, 32u);
  EXPECT_LE(run.most_stepped_work, bound + 64 + 64 * 63 / 2 + 64 * 6);
  EXPECT_GT(run.held_over_work, 0u);
  EXPECT_EQ(run.fallbacks, 0u);
  EXPECT_LE(run.deepest_into_ball, 0.25 * 1e-9 * 0.1);
  EXPECT_LE(run.deepest_into_wall, 0.25 * 1e-9 * 0.05 + 1e-16);
  EXPECT_LE(run.gain, 1e-12 * run.released);
}

// The same pile with every ball named otherwise (the monitor indexes bodies by sorted id, so the
// reversed names reverse its order): the same motion to the bit.
TEST(SteppedClusters, RenamingTheBodiesChangesNoBit) {
  const PileRun plain = dropPile(0.8, plainName);
  const PileRun renamed = dropPile(0.8, [](int i) { return plainName(63 - i) + "_renamed"; });
  ASSERT_GE(plain.most_stepped, 32u);
  ASSERT_EQ(plain.final_positions.size(), renamed.final_positions.size());
  for (std::size_t i = 0; i < plain.final_positions.size(); ++i) {
    EXPECT_EQ(plain.final_positions[i], renamed.final_positions[i]) << i;
  }
}

// 32 balls stacked in two touching layers of 4 x 4 in a box that fits them exactly, at rest: one
// stepped cluster. Nothing moves (each ball is held by the one below or the floor), and the
// contacts with the floor carry the whole weight, 32 m g, each ball of the lower layer 2 m g;
// frictionless, and with friction and spin (mu = 0.5: the friction sweeps start from the
// sub-step before's impulses and find none needed).
class SteppedPileAtRest : public ::testing::TestWithParam<bool> {};

TEST_P(SteppedPileAtRest, AStackedPileAtRestCarriesItsWeight) {
  const double r = 0.05, m = 0.1;
  Scene scene = boxScene(8 * r);
  if (GetParam()) {
    scene.effects.friction = true;
    scene.effects.spin = true;
    scene.materials = MaterialTable::seed();
    EXPECT_TRUE(scene.materials.addMaterial("pile", Material{0.5, 0.5}, "m").ok());
  }
  std::vector<V> start;
  for (int i = 0; i < 32; ++i) {
    scene.bodies.push_back(ball(plainName(i), m, r));
    start.push_back(V(r + 2 * r * (i % 4), r + 2 * r * ((i / 4) % 4), r + 2 * r * (i / 16)));
  }
  MonitorSettings settings;
  settings.body_timeout = 1e9;
  ImpactMonitor monitor(scene, settings);
  std::vector<BodyStateSample> states;
  for (int i = 0; i < 32; ++i) {
    BodyStateSample sample;
    sample.body = *monitor.bodyIndex(plainName(i));
    sample.position = start[static_cast<std::size_t>(i)];
    states.push_back(sample);
  }
  monitor.step(0.0, states);
  StepReport report;
  for (int k = 1; k <= 50; ++k) report = monitor.step(k / 100.0, {});
  EXPECT_EQ(report.stepped_bodies, 32u);
  for (int i = 0; i < 32; ++i) {
    const auto [position, velocity] =
        *monitor.predictedState(*monitor.bodyIndex(plainName(i)), 0.5);
    EXPECT_LE((position - start[static_cast<std::size_t>(i)]).norm(), 1e-9 * r) << i;
  }
  const std::size_t floor = 4;  // wall_4: normal +z, the obstacles sorted by id
  ASSERT_EQ(monitor.obstacle(floor).id, "wall_4");
  double floor_force = 0;
  for (const ContactRecord& contact : report.contacts) {
    if (contact.other_is_obstacle && contact.other == floor) {
      EXPECT_NEAR(contact.normal_force, 2 * m * kG, 1e-6 * m * kG);
      EXPECT_EQ(contact.state, ContactState::kResting);
      floor_force += contact.normal_force;
    }
  }
  EXPECT_NEAR(floor_force, 32 * m * kG, 1e-6 * m * kG);
}

INSTANTIATE_TEST_SUITE_P(FrictionOffAndOn, SteppedPileAtRest, ::testing::Bool());

// Below the size a cluster needs (stepped_cluster_min_bodies), or with stepping off (0), the
// exact model moves the bodies: no body is ever in a stepped cluster.
TEST(SteppedClusters, SmallerSetsAndSteppingOffStayExact) {
  for (const int min_bodies : {0, 65}) {
    const double r = 0.05;
    Scene scene = boxScene(8 * r);
    scene.stepped_cluster_min_bodies = min_bodies;
    for (int i = 0; i < 32; ++i) scene.bodies.push_back(ball(plainName(i), 0.1, r));
    MonitorSettings settings;
    settings.body_timeout = 1e9;
    ImpactMonitor monitor(scene, settings);
    std::vector<BodyStateSample> states;
    for (int i = 0; i < 32; ++i) {
      BodyStateSample sample;
      sample.body = *monitor.bodyIndex(plainName(i));
      sample.position = V(r + 2 * r * (i % 4), r + 2 * r * ((i / 4) % 4), r + 2 * r * (i / 16));
      states.push_back(sample);
    }
    monitor.step(0.0, states);
    for (int k = 1; k <= 10; ++k) EXPECT_EQ(monitor.step(k / 100.0, {}).stepped_bodies, 0u);
  }
}

/// Two balls of r 0.05 m and 0.1 kg in a box of 2 m: `a` resting on the floor at (1, 1, r), `b`
/// dropped from rest at `dropped`; exact_work_budget `budget`; the monitor moving them at 100 Hz.
ImpactMonitor twoBallsOverABudget(const V& dropped, int budget) {
  Scene scene = boxScene(2.0);
  scene.exact_work_budget = budget;
  scene.bodies = {ball("a", 0.1, 0.05), ball("b", 0.1, 0.05)};
  MonitorSettings settings;
  settings.body_timeout = 1e9;
  ImpactMonitor monitor(scene, settings);
  std::vector<BodyStateSample> states(2);
  states[0].body = *monitor.bodyIndex("a");
  states[0].position = V(1.0, 1.0, 0.05);
  states[1].body = *monitor.bodyIndex("b");
  states[1].position = dropped;
  monitor.step(0.0, states);
  return monitor;
}

// A ball dropped onto the top of one resting on the floor bounces on it ever lower (e = 0.5): the
// lower ball, struck and pressed into the floor at each bounce, runs over an exact_work_budget of
// 4 within one update (named in the report, one fallback), and is stepped from there with the
// ball near it, two bodies far below stepped_cluster_min_bodies; they stay so while they touch:
// a stack at rest, the floor carrying 2 m g and the lower ball m g, never more than a quarter of
// the band into either.
TEST(SteppedClusters, BodiesOverTheirWorkBudgetAreSteppedWithTheBodiesNearThem) {
  const double r = 0.05, m = 0.1;
  ImpactMonitor monitor = twoBallsOverABudget(V(1.0, 1.0, 5 * r), 4);
  std::vector<std::size_t> over_budget;
  StepReport report;
  for (int k = 1; k <= 100; ++k) {
    const double t = k / 100.0;
    report = monitor.step(t, {});
    over_budget.insert(over_budget.end(), report.over_budget.begin(), report.over_budget.end());
    EXPECT_EQ(report.fallbacks, report.over_budget.size()) << t;
    const V a = monitor.predictedState(0, t)->first, b = monitor.predictedState(1, t)->first;
    EXPECT_GE((b - a).norm() - 2 * r, -1e-9 * r) << t;
    EXPECT_GE(std::min(a.z(), b.z()) - r, -1e-9 * r) << t;
  }
  ASSERT_FALSE(over_budget.empty());
  for (const std::size_t body : over_budget) EXPECT_EQ(body, 0u);  // "a"
  EXPECT_EQ(report.stepped_bodies, 2u);
  ASSERT_EQ(report.contacts.size(), 2u);
  for (const ContactRecord& contact : report.contacts) {
    const double carried = contact.other_is_obstacle ? 2 * m * kG : m * kG;
    EXPECT_NEAR(contact.normal_force, carried, 1e-6 * m * kG);
  }
}

// The same ball dropped off-centre (the line of centres 30 degrees from the vertical) glances
// off sideways; with an exact_work_budget of 1, the resting ball's bounces on the floor after the
// blow pass it, and it is stepped alone (whatever the number near it). Near no other body, it is
// back with the exact model at the next update, and both end exact; the dropped ball's flights
// are the exact parabolas (a stepped flight falls g h t / 2 below them).
TEST(SteppedClusters, ABodyOverItsBudgetNearNoOtherIsExactAgainAtTheNextUpdate) {
  const double r = 0.05;
  ImpactMonitor monitor = twoBallsOverABudget(V(1.0 + r, 1.0, 5 * r), 1);
  std::size_t over_budget = 0;
  int exact_after = 0;
  StepReport report;
  for (int k = 1; k <= 60; ++k) {
    const double t = k / 100.0, h = 0.01;
    report = monitor.step(t, {});
    over_budget += report.over_budget.size();
    const V a = monitor.predictedState(0, t)->first, b = monitor.predictedState(1, t)->first;
    EXPECT_GE((b - a).norm() - 2 * r, -1e-9 * r) << t;
    EXPECT_GE(std::min(a.z(), b.z()) - r, -1e-9 * r) << t;
    const auto [position, velocity] = *monitor.predictedState(1, t);
    const V expected = position + velocity * h + 0.5 * V(0, 0, -kG) * h * h;
    if (over_budget > 0 && report.stepped_bodies == 0 && b.z() > 1.1 * r &&
        expected.z() > 1.1 * r) {
      // Back with the exact model and in flight over the next update: its parabola.
      EXPECT_LE((monitor.predictedState(1, t + h)->first - expected).norm(), 1e-12) << t;
      ++exact_after;
    }
  }
  EXPECT_GE(over_budget, 1u);
  EXPECT_EQ(report.stepped_bodies, 0u);
  EXPECT_GE(exact_after, 3);
}

// The three scene keys are checked once, at start-up, each error naming its key: a count of
// bodies (0: never), a sub-step in [1e-4, 1] s, and a work budget (0: none).
TEST(SteppedClusters, TheSceneKeysAreChecked) {
  Scene scene = boxScene(1.0);
  EXPECT_TRUE(validateScene(scene, "scene").ok());
  scene.stepped_cluster_min_bodies = 0;
  EXPECT_TRUE(validateScene(scene, "scene").ok());
  scene.stepped_cluster_min_bodies = -1;
  const Status negative = validateScene(scene, "scene");
  ASSERT_FALSE(negative.ok());
  EXPECT_EQ(negative.error().message(),
            "scene/stepped_cluster_min_bodies: must be 0 (never) or a number of bodies, got -1");
  scene.stepped_cluster_min_bodies = 32;
  scene.exact_work_budget = -1;
  const Status budget = validateScene(scene, "scene");
  ASSERT_FALSE(budget.ok());
  EXPECT_EQ(budget.error().message(),
            "scene/exact_work_budget: must be 0 (no budget) or a number of solves, got -1");
  scene.exact_work_budget = 0;
  EXPECT_TRUE(validateScene(scene, "scene").ok());
  for (const double good : {1e-4, 0.01, 1.0}) {
    scene.stepped_cluster_time_step = good;
    EXPECT_TRUE(validateScene(scene, "scene").ok()) << good;
  }
  for (const double bad :
       {0.0, 9e-5, 1.5, -0.01, std::nan(""), std::numeric_limits<double>::infinity()}) {
    scene.stepped_cluster_time_step = bad;
    const Status status = validateScene(scene, "scene");
    ASSERT_FALSE(status.ok()) << bad;
    EXPECT_EQ(status.error().field, "scene/stepped_cluster_time_step") << bad;
  }
}

}  // namespace
}  // namespace collision_response::core
