// Each slide of the seed (collisions-slides, whose physics the README, "What it is", lists) as
// tests of the core. Expected values come from test/exact/make_seed_cases.py (exact rational
// arithmetic, independent of the code under test) or from closed forms worked out in the comments.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "collision_response/core/collision.h"
#include "collision_response/core/impact.h"
#include "collision_response/core/materials.h"
#include "collision_response/core/restitution.h"

namespace collision_response::core {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kInf = std::numeric_limits<double>::infinity();

struct SeedCase {
  std::string name;
  double mass_a, mass_b, restitution;
  Eigen::Vector3d velocity_a, velocity_b, normal;
  Eigen::Vector3d expected_a, expected_b;
  double expected_impulse, expected_energy_lost;
};

std::vector<SeedCase> loadSeedCases() {
  std::ifstream file(std::string(COLLISION_RESPONSE_TEST_DATA) + "/seed_cases.txt");
  std::vector<SeedCase> cases;
  std::string line;
  while (std::getline(file, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream in(line);
    SeedCase c;
    std::vector<double> v(22);
    in >> c.name;
    for (double& x : v) {
      std::string token;
      in >> token;
      x = std::strtod(token.c_str(), nullptr);  // reads "inf" too
    }
    c.mass_a = v[0];
    c.velocity_a = {v[1], v[2], v[3]};
    c.mass_b = v[4];
    c.velocity_b = {v[5], v[6], v[7]};
    c.normal = {v[8], v[9], v[10]};
    c.restitution = v[11];
    c.expected_a = {v[12], v[13], v[14]};
    c.expected_b = {v[15], v[16], v[17]};
    c.expected_impulse = v[18];
    c.expected_energy_lost = v[19];
    cases.push_back(c);
  }
  return cases;
}

CollisionOutcome collide(const SeedCase& c) {
  CollisionRequest request;
  request.a.mass = c.mass_a;
  request.a.velocity = c.velocity_a;
  request.b.mass = c.mass_b;
  request.b.velocity = c.velocity_b;
  request.b.position = Eigen::Vector3d(0.06, 0, 0);
  request.normal = c.normal;
  request.restitution = c.restitution;
  const auto outcome = computeCollision(request, MaterialTable::seed());
  EXPECT_TRUE(outcome.ok()) << c.name << ": " << (outcome ? "" : outcome.error().message());
  return outcome ? *outcome : CollisionOutcome{};
}

double speedScale(const SeedCase& c) {
  return std::max(c.velocity_a.lpNorm<Eigen::Infinity>(), c.velocity_b.lpNorm<Eigen::Infinity>());
}

bool isAxis(const Eigen::Vector3d& n) { return n.cwiseAbs().maxCoeff() == 1.0; }

TEST(SeedSlides, DataFileHasTheCases) { EXPECT_GE(loadSeedCases().size(), 40u); }

// "Combining momentum and restitution laws": v_a', v_b' against the exact rational answers,
// within 4 ulps of the speeds involved; exactly where the line of impact is an axis and the
// exact answer is a double.
TEST(SeedSlides, CombinedFormulasMatchExactAnswers) {
  for (const SeedCase& c : loadSeedCases()) {
    const CollisionOutcome outcome = collide(c);
    const double tolerance = 4 * kEps * speedScale(c);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(outcome.impact.velocity_a[i], c.expected_a[i], tolerance) << c.name << " a" << i;
      EXPECT_NEAR(outcome.impact.velocity_b[i], c.expected_b[i], tolerance) << c.name << " b" << i;
    }
    EXPECT_NEAR(outcome.impact.normal_impulse, c.expected_impulse,
                8 * kEps * std::abs(c.expected_impulse) + 1e-300)
        << c.name;
    EXPECT_NEAR(outcome.impact.energy_lost, c.expected_energy_lost,
                16 * kEps * std::abs(c.expected_energy_lost) + 1e-300)
        << c.name;
    EXPECT_EQ(outcome.impact.approaching, c.expected_impulse > 0) << c.name;
  }
}

// "Conservation of momentum": m_a v_a + m_b v_b = m_a v_a' + m_b v_b', summed in long double
// (11 more bits than double), within 4 ulps of sum m |v| (see test_properties.cpp for why the
// scale is the vectors' norms).
TEST(SeedSlides, MomentumIsConserved) {
  for (const SeedCase& c : loadSeedCases()) {
    if (std::isinf(c.mass_a) || std::isinf(c.mass_b)) continue;  // no finite total momentum
    const CollisionOutcome outcome = collide(c);
    for (int i = 0; i < 3; ++i) {
      const long double before =
          (long double)c.mass_a * c.velocity_a[i] + (long double)c.mass_b * c.velocity_b[i];
      const long double after = (long double)c.mass_a * outcome.impact.velocity_a[i] +
                                (long double)c.mass_b * outcome.impact.velocity_b[i];
      const double scale = c.mass_a * (c.velocity_a.norm() + outcome.impact.velocity_a.norm()) +
                           c.mass_b * (c.velocity_b.norm() + outcome.impact.velocity_b.norm());
      EXPECT_LE(std::abs(static_cast<double>(after - before)), 4 * kEps * scale)
          << c.name << " axis " << i;
    }
  }
}

// "Collisions with immoveable objects": m_b -> inf gives v_a' = -e v_a for a still wall. The
// answer is the double nearest to -e v_a, to the last bit.
TEST(SeedSlides, ImmovableWallGivesExactlyMinusEV) {
  for (const SeedMeasurement& row : seedTable()) {
    for (const double speed : {4.43, 1.0, 0.1, 12.5, 1e-3}) {
      const Eigen::Vector3d down(0, 0, -speed);
      const ImpactResponse<double> response =
          resolveImpact(inverseMass(0.057), down, inverseMass(kImmovableMass),
                        Eigen::Vector3d::Zero().eval(), Eigen::Vector3d(0, 0, -1), row.restitution);
      EXPECT_EQ(response.velocity_a.z(), row.restitution * speed) << row.material;
      EXPECT_EQ(response.velocity_a.x(), 0.0);
      EXPECT_EQ(response.velocity_b, Eigen::Vector3d::Zero()) << "the wall does not move";
    }
  }
  // The exact-data cases of walls agree to the bit as well.
  for (const SeedCase& c : loadSeedCases()) {
    if (c.name.rfind("wall_", 0) != 0) continue;
    EXPECT_EQ(collide(c).impact.velocity_a, c.expected_a) << c.name;
  }
}

// The limit before the wall stands still: v_a' = v_b + e (v_b - v_a) (a moving paddle), and the
// paddle keeps its velocity.
TEST(SeedSlides, MovingImmovableBodyUsesTheLimitFormula) {
  // a at 3 m/s, paddle at -2 m/s along x, e = 0.5: v_a' = -2 + 0.5 (-2 - 3) = -4.5 exactly.
  const ImpactResponse<double> response =
      resolveImpact(inverseMass(0.057), Eigen::Vector3d(3, 0, 0), inverseMass(kImmovableMass),
                    Eigen::Vector3d(-2, 0, 0), Eigen::Vector3d(1, 0, 0), 0.5);
  EXPECT_EQ(response.velocity_a, Eigen::Vector3d(-4.5, 0, 0));
  EXPECT_EQ(response.velocity_b, Eigen::Vector3d(-2, 0, 0));
  // Impulse on the ball: m (v - v') = 0.057 * 7.5; energy lost (1/2) m (1 - e^2) d^2 with
  // d = 5: 0.5 * 0.057 * 0.75 * 25.
  EXPECT_NEAR(response.normal_impulse, 0.057 * 7.5, 4 * kEps);
  EXPECT_NEAR(response.energy_lost, 0.5 * 0.057 * 0.75 * 25, 4 * kEps);
}

// "Totally plastic collisions": e = 0 gives one common velocity (m_a v_a + m_b v_b)/(m_a + m_b),
// the same double for both bodies (its distance to the exact value is checked above).
TEST(SeedSlides, PlasticCollisionGivesOneCommonVelocity) {
  int plastic = 0;
  for (const SeedCase& c : loadSeedCases()) {
    if (c.restitution != 0.0) continue;
    ++plastic;
    const CollisionOutcome outcome = collide(c);
    EXPECT_EQ(outcome.impact.velocity_a, outcome.impact.velocity_b) << c.name;
  }
  EXPECT_GE(plastic, 2);
  // 2 kg at 3 m/s, 1 kg at -1 m/s: (6 - 1) / 3 = 5/3 for both.
  const ImpactResponse<double> response = resolveImpact(
      0.5, Eigen::Vector3d(3, 0, 0), 1.0, Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(1, 0, 0), 0.0);
  EXPECT_EQ(response.velocity_a.x(), response.velocity_b.x());
  EXPECT_NEAR(response.velocity_a.x(), 5.0 / 3.0, kEps * 2);
}

// "Totally elastic collisions": e = 1 conserves kinetic energy.
TEST(SeedSlides, ElasticCollisionConservesEnergy) {
  for (const SeedCase& c : loadSeedCases()) {
    if (c.restitution != 1.0) continue;
    const CollisionOutcome outcome = collide(c);
    EXPECT_EQ(outcome.impact.energy_lost, 0.0) << c.name;
    const long double before =
        0.5L * c.mass_a * c.velocity_a.squaredNorm() + 0.5L * c.mass_b * c.velocity_b.squaredNorm();
    const long double after = 0.5L * c.mass_a * outcome.impact.velocity_a.squaredNorm() +
                              0.5L * c.mass_b * outcome.impact.velocity_b.squaredNorm();
    EXPECT_LE(std::abs(static_cast<double>(after - before)), 8 * kEps * double(before)) << c.name;
  }
  // Equal masses, e = 1: the velocities are exchanged exactly.
  const ImpactResponse<double> response = resolveImpact(
      1.0, Eigen::Vector3d(2, 0, 0), 1.0, Eigen::Vector3d(-3, 0, 0), Eigen::Vector3d(1, 0, 0), 1.0);
  EXPECT_EQ(response.velocity_a, Eigen::Vector3d(-3, 0, 0));
  EXPECT_EQ(response.velocity_b, Eigen::Vector3d(2, 0, 0));
}

// "Oblique impacts": the components perpendicular to the line of impact are left unchanged,
// exactly when the line of impact is an axis.
TEST(SeedSlides, ObliqueImpactKeepsThePerpendicularComponent) {
  for (const SeedCase& c : loadSeedCases()) {
    const CollisionOutcome outcome = collide(c);
    const Eigen::Vector3d n = c.normal.normalized();
    const auto perpendicular = [&n](const Eigen::Vector3d& v) -> Eigen::Vector3d {
      return v - v.dot(n) * n;
    };
    const double tolerance = isAxis(c.normal) ? 0.0 : 4 * kEps * speedScale(c);
    EXPECT_LE((perpendicular(outcome.impact.velocity_a) - perpendicular(c.velocity_a))
                  .lpNorm<Eigen::Infinity>(),
              tolerance)
        << c.name;
    EXPECT_LE((perpendicular(outcome.impact.velocity_b) - perpendicular(c.velocity_b))
                  .lpNorm<Eigen::Infinity>(),
              tolerance)
        << c.name;
  }
  // The slide's kind of example: a at (3, 4, 0) hits b at rest along x, e = 1, equal masses:
  // a' = (0, 4, 0), b' = (3, 0, 0), reported oblique.
  CollisionRequest request;
  request.a.velocity = Eigen::Vector3d(3, 4, 0);
  request.b.position = Eigen::Vector3d(1, 0, 0);
  request.restitution = 1.0;
  const auto outcome = computeCollision(request, MaterialTable::seed());
  ASSERT_TRUE(outcome.ok());
  EXPECT_EQ(outcome->impact.velocity_a, Eigen::Vector3d(0, 4, 0));
  EXPECT_EQ(outcome->impact.velocity_b, Eigen::Vector3d(3, 0, 0));
  EXPECT_TRUE(outcome->oblique);
}

TEST(SeedSlides, DirectImpactIsNotOblique) {
  CollisionRequest request;
  request.a.velocity = Eigen::Vector3d(3, 0, 0);
  request.b.position = Eigen::Vector3d(1, 0, 0);
  request.b.velocity = Eigen::Vector3d(-1, 0, 0);
  request.restitution = 0.5;
  const auto outcome = computeCollision(request, MaterialTable::seed());
  ASSERT_TRUE(outcome.ok());
  EXPECT_FALSE(outcome->oblique);
  EXPECT_TRUE(outcome->impact.approaching);
}

// "Experimentally determining the coefficient of restitution": e = sqrt(h'/h).
TEST(SeedSlides, RestitutionFromDropAndBounceHeights) {
  // Exact squares: sqrt(0.25 / 1) = 0.5, sqrt(0.5 / 2) = 0.5, sqrt(0 / 1) = 0, sqrt(1 / 1) = 1.
  EXPECT_EQ(*restitutionFromHeights(1.0, 0.25), 0.5);
  EXPECT_EQ(*restitutionFromHeights(2.0, 0.5), 0.5);
  EXPECT_EQ(*restitutionFromHeights(1.0, 0.0), 0.0);
  EXPECT_EQ(*restitutionFromHeights(3.0, 3.0), 1.0);
  // Each table value back from h' = e^2 h, within one rounding of the square and one of the root.
  for (const SeedMeasurement& row : seedTable()) {
    const double bounce = row.restitution * row.restitution;
    EXPECT_NEAR(*restitutionFromHeights(1.0, bounce), row.restitution, 2 * kEps) << row.material;
  }
}

// "Some coefficients of restitution of balls bounced on a concrete surface".
TEST(SeedSlides, TableOfBallsOnConcrete) {
  const MaterialTable table = MaterialTable::seed();
  const std::vector<std::pair<std::string, double>> slide = {
      {"range_golf_ball", 0.858}, {"tennis_ball", 0.712},      {"billiard_ball", 0.804},
      {"hand_ball", 0.752},       {"wooden_ball", 0.603},      {"steel_ball_bearing", 0.597},
      {"glass_marble", 0.658},    {"rubber_band_ball", 0.828}, {"hollow_hard_plastic_ball", 0.688}};
  ASSERT_EQ(seedTable().size(), slide.size());
  for (const auto& [material, value] : slide) {
    EXPECT_EQ(*table.restitution(material, "concrete"), value) << material;
    EXPECT_EQ(*table.restitution("concrete", material), value) << material;
  }
  EXPECT_EQ(table.names().size(), slide.size() + 1);  // and concrete
}

}  // namespace
}  // namespace collision_response::core
