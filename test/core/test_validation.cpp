// Every validation error of a single collision: refused, with the field named and the reason.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "collision_response/core/collision.h"
#include "collision_response/core/restitution.h"
#include "collision_response/core/scene.h"
#include "collision_response/core/validation.h"
#include "scene_builders.h"

namespace collision_response::core {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

CollisionRequest goodRequest() {
  CollisionRequest request;
  request.a.id = "a";
  request.a.mass = 2.0;
  request.a.velocity = Eigen::Vector3d(3, 0, 0);
  request.b.id = "b";
  request.b.mass = 1.0;
  request.b.position = Eigen::Vector3d(1, 0, 0);
  request.b.velocity = Eigen::Vector3d(-1, 0, 0);
  request.restitution = 0.5;
  return request;
}

// Refused, naming `field`, with `words` in the reason.
void expectRefused(const CollisionRequest& request, const std::string& field,
                   const std::string& words) {
  const auto outcome = computeCollision(request, MaterialTable::seed());
  ASSERT_FALSE(outcome.ok()) << "expected a refusal naming " << field;
  EXPECT_EQ(outcome.error().field, field) << outcome.error().message();
  EXPECT_NE(outcome.error().reason.find(words), std::string::npos) << outcome.error().message();
}

TEST(Validation, GoodRequestIsAccepted) {
  const auto outcome = computeCollision(goodRequest(), MaterialTable::seed());
  ASSERT_TRUE(outcome.ok());
  EXPECT_EQ(outcome->impact.velocity_a, Eigen::Vector3d(1, 0, 0));  // the seed's 2 kg / 1 kg case
  EXPECT_EQ(outcome->impact.velocity_b, Eigen::Vector3d(3, 0, 0));
}

TEST(Validation, Mass) {
  for (const double bad : {0.0, -1.0, kNan, -kInf, 1e-310}) {
    CollisionRequest request = goodRequest();
    request.a.mass = bad;
    expectRefused(request, "a.mass", "");
  }
  CollisionRequest request = goodRequest();
  request.b.mass = -1.0;
  expectRefused(request, "b.mass", "> 0");
}

TEST(Validation, BothImmovable) {
  CollisionRequest request = goodRequest();
  request.a.mass = kInf;
  request.b.mass = kInf;
  expectRefused(request, "b.mass", "both immovable");
}

TEST(Validation, Radius) {
  for (const double bad : {-0.1, kNan, kInf}) {
    CollisionRequest request = goodRequest();
    request.b.radius = bad;
    expectRefused(request, "b.radius", ">= 0");
  }
}

TEST(Validation, NonFiniteVectorsNameTheComponent) {
  CollisionRequest request = goodRequest();
  request.a.velocity.y() = kNan;
  expectRefused(request, "a.velocity.y", "finite");
  request = goodRequest();
  request.b.position.z() = kInf;
  expectRefused(request, "b.position.z", "finite");
  request = goodRequest();
  request.a.angular_velocity.x() = -kInf;
  expectRefused(request, "a.angular_velocity.x", "finite");
  request = goodRequest();
  request.normal.x() = kNan;
  expectRefused(request, "normal.x", "finite");
}

TEST(Validation, Restitution) {
  for (const double bad : {-0.01, 1.5, kNan, kInf}) {
    CollisionRequest request = goodRequest();
    request.restitution = bad;
    expectRefused(request, "restitution", "[0, 1]");
  }
}

TEST(Validation, NoLineOfImpact) {
  CollisionRequest request = goodRequest();
  request.b.position = request.a.position;
  expectRefused(request, "normal", "no line of impact");
  // A nonzero normal makes coincident centres fine.
  request.normal = Eigen::Vector3d(0, 0, 2);
  EXPECT_TRUE(computeCollision(request, MaterialTable::seed()).ok());
}

TEST(Validation, NormalIsScaledToUnitLength) {
  for (const double scale : {1e-300, 1e-5, 7.0, 1e300}) {
    const auto n = lineOfImpact(Eigen::Vector3d(0, 0, scale), Eigen::Vector3d::Zero(),
                                Eigen::Vector3d::Zero());
    ASSERT_TRUE(n.ok()) << scale;
    EXPECT_EQ(*n, Eigen::Vector3d(0, 0, 1)) << scale;
  }
  // Among the subnormals (a fuzzer's finding): 231 and 54,300 times the smallest double. The
  // unit vector along (0, 231, 54300) has length 1 to an ulp or two.
  const double tiny = std::numeric_limits<double>::denorm_min();
  const auto subnormal = lineOfImpact(Eigen::Vector3d(0, 231 * tiny, 54300 * tiny),
                                      Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  ASSERT_TRUE(subnormal.ok());
  EXPECT_NEAR(subnormal->norm(), 1.0, 4 * std::numeric_limits<double>::epsilon());
  EXPECT_NEAR(subnormal->y() / subnormal->z(), 231.0 / 54300.0, 1e-15);
  const auto derived =
      lineOfImpact(Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 1, -4));
  ASSERT_TRUE(derived.ok());
  EXPECT_EQ(*derived, Eigen::Vector3d(0, 0, -1));
}

TEST(Validation, BodyAgainstItself) {
  CollisionRequest request = goodRequest();
  request.b.id = "a";
  expectRefused(request, "b.id", "itself");
}

TEST(Validation, Materials) {
  CollisionRequest request = goodRequest();
  request.a.material = "tennis_ball";
  request.b.material = "kryptonite";
  request.restitution = 0.0;
  expectRefused(request, "b.material", "unknown material 'kryptonite'");

  request.b.material = "";
  expectRefused(request, "b.material", "name both");

  request.b.material = "concrete";
  request.restitution = 0.5;
  expectRefused(request, "restitution", "must be 0 when both bodies name a material");

  request.restitution = 0.0;
  const auto outcome = computeCollision(request, MaterialTable::seed());
  ASSERT_TRUE(outcome.ok());
  EXPECT_EQ(outcome->restitution, 0.712);
}

TEST(Validation, Effects) {
  CollisionRequest request = goodRequest();
  request.effects = {"magnetism"};
  expectRefused(request, "effects[0]", "unknown effect 'magnetism'");
}

TEST(Validation, DropTestHeights) {
  EXPECT_EQ(restitutionFromHeights(0.0, 0.0).error().field, "drop_height");
  EXPECT_EQ(restitutionFromHeights(-1.0, 0.0).error().field, "drop_height");
  EXPECT_EQ(restitutionFromHeights(kNan, 0.5).error().field, "drop_height");
  EXPECT_EQ(restitutionFromHeights(kInf, 0.5).error().field, "drop_height");
  EXPECT_EQ(restitutionFromHeights(1.0, -0.5).error().field, "bounce_height");
  EXPECT_EQ(restitutionFromHeights(1.0, kNan).error().field, "bounce_height");
  const auto higher = restitutionFromHeights(1.0, 1.5);
  ASSERT_FALSE(higher.ok());
  EXPECT_EQ(higher.error().field, "bounce_height");
  EXPECT_NE(higher.error().reason.find("e > 1"), std::string::npos);
}

TEST(Validation, AnAnswerBeyondTheDoublesIsRefusedByName) {
  // 1e200 kg at 1e200 m/s: the impulse (~1e400 N s) and the energy (~1e600 J) are not doubles.
  CollisionRequest request = goodRequest();
  request.a.mass = 1e200;
  request.b.mass = 1e200;
  request.a.velocity = Eigen::Vector3d(1e200, 0, 0);
  request.b.velocity = Eigen::Vector3d(-1e200, 0, 0);
  expectRefused(request, "impulse", "beyond the range of double");
}

TEST(Validation, NumbersInMessagesReadBack) {
  EXPECT_EQ(formatNumber(0.1), "0.1");
  EXPECT_EQ(formatNumber(-1.0), "-1");
  EXPECT_EQ(formatNumber(kNan), "nan");
  EXPECT_EQ(formatNumber(-kInf), "-inf");
  EXPECT_EQ(formatVector(Eigen::Vector3d(1, 2.5, -3)), "[1, 2.5, -3]");
}

// Issue 13, item 10: estimate_restitution(1e300, 1e-300) answered e = 0 (the ratio 1e-600
// underflows, while e = 1e-300 is a double), and (1, -0) answered e = -0.
TEST(Validation, DropTestHeightsAtTheEndsOfTheDoubles) {
  const auto tiny = restitutionFromHeights(1e300, 1e-300);
  ASSERT_TRUE(tiny.ok());
  EXPECT_NEAR(*tiny, 1e-300, 2 * std::numeric_limits<double>::epsilon() * 1e-300);
  const auto huge = restitutionFromHeights(1e-300, 1e-301);  // 1e-301 / 1e-300 = 0.1
  ASSERT_TRUE(huge.ok());
  EXPECT_NEAR(*huge, std::sqrt(0.1), 2 * std::numeric_limits<double>::epsilon());
  const auto subnormal = restitutionFromHeights(4e-320, 1e-320);  // e = sqrt(1/4) = 1/2
  ASSERT_TRUE(subnormal.ok());
  EXPECT_NEAR(*subnormal, 0.5, 1e-3);  // the subnormals hold 3 digits
  const auto minus_zero = restitutionFromHeights(1.0, -0.0);
  ASSERT_TRUE(minus_zero.ok());
  EXPECT_EQ(*minus_zero, 0.0);
  EXPECT_FALSE(std::signbit(*minus_zero)) << "e = -0 is not a coefficient";
  // Where the ratio is a normal double, the same bits as sqrt(h' / h).
  for (const auto& [drop, bounce] : std::vector<std::pair<double, double>>{
           {1.0, 0.25}, {2.0, 0.5}, {1.0, 0.712 * 0.712}, {3.7, 1.1}, {1e10, 3e9}, {0.5, 0.5}}) {
    EXPECT_EQ(*restitutionFromHeights(drop, bounce), std::sqrt(bounce / drop))
        << drop << " " << bounce;
  }
}

TEST(Validation, ThresholdFrictionToleranceAndFrames) {
  EXPECT_TRUE(checkRestitutionThreshold(0.0, "t").ok());
  EXPECT_TRUE(checkRestitutionThreshold(5000.0, "t").ok());
  for (const double bad : {-1.0, kInf, -kInf, kNan}) {
    const auto status = checkRestitutionThreshold(bad, "t");
    ASSERT_FALSE(status.ok()) << bad;
    EXPECT_EQ(status.error().message(),
              "t: must be a finite number >= 0 m/s, got " + formatNumber(bad));
  }
  EXPECT_TRUE(checkFriction(0.0, "f").ok());
  EXPECT_FALSE(checkFriction(-0.1, "f").ok());
  EXPECT_FALSE(checkFriction(kInf, "f").ok());
  EXPECT_TRUE(checkContactTolerance(0.0, "c").ok());
  EXPECT_TRUE(checkContactTolerance(0.5, "c").ok());
  EXPECT_FALSE(checkContactTolerance(1.0, "c").ok());
  EXPECT_FALSE(checkContactTolerance(1e6, "c").ok());
  EXPECT_FALSE(checkContactTolerance(-1e-9, "c").ok());
  EXPECT_TRUE(checkFrameId("world", "f").ok());
  const auto slash = checkFrameId("/world", "f");
  ASSERT_FALSE(slash.ok());
  EXPECT_EQ(slash.error().message(),
            "f: '/world' starts with '/': tf2 frame ids have none (use 'world')");
  EXPECT_FALSE(checkFrameId("", "f").ok());
  EXPECT_FALSE(checkFrameId("my frame", "f").ok());
}

TEST(Validation, OneRefusalForAnswersBeyondTheDoubles) {
  EXPECT_TRUE(
      checkRepresentable({namedResult("x", 1.0), namedResult("v", Eigen::Vector3d(1, 2, 3))}).ok());
  const auto status =
      checkRepresentable({namedResult("x", 1.0), namedResult("v", Eigen::Vector3d(1, kNan, 3)),
                          namedResult("y", kInf)});
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().field, "v");
  EXPECT_EQ(status.error().reason, kBeyondDoubles);
}

// Issue 27, item 5: a stack placed at x = 1.7e308 gave one empty `contacts` array and no word.
// The monitor's geometry sums two positions' magnitudes (a pair's touching band, a swept box's
// padding), which overflows past 2^1023 = 8.98846567431158e+307; the bound is half that, 2^1022
// (4.49423283715579e+307, shortest decimal that reads back as it), below which a coordinate is
// resolved. The largest double below it, 4.4942328371557893e+307, is accepted.
TEST(Validation, APositionPastTheMonitorsResolutionIsRefusedNamingTheCoordinate) {
  EXPECT_TRUE(checkResolvablePosition(Eigen::Vector3d(0, 0, 0), "p").ok());
  const double below = std::nextafter(0x1p1022, 0.0);
  EXPECT_TRUE(checkResolvablePosition(Eigen::Vector3d(below, -below, below), "p").ok());
  const auto stack = checkResolvablePosition(Eigen::Vector3d(1.7e308, 0, 0.05), "pose.position");
  ASSERT_FALSE(stack.ok());
  EXPECT_EQ(stack.error().message(),
            "pose.position.x: 1.7e+308 m is beyond where the monitor can resolve a contact (|x| "
            "must be below 2^1022 = 4.49423283715579e+307 m: past 2^1023 the sum of two bodies' "
            "coordinates overflows)");
  const auto edge = checkResolvablePosition(Eigen::Vector3d(0, -0x1p1022, 0), "p");
  ASSERT_FALSE(edge.ok());
  EXPECT_EQ(edge.error().message(),
            "p.y: -4.49423283715579e+307 m is beyond where the monitor can resolve a contact (|y| "
            "must be below 2^1022 = 4.49423283715579e+307 m: past 2^1023 the sum of two bodies' "
            "coordinates overflows)");
  const auto nan = checkResolvablePosition(Eigen::Vector3d(0, 0, kNan), "p");
  ASSERT_FALSE(nan.ok());
  EXPECT_EQ(nan.error().message(), "p.z: must be a finite number, got nan");
}

// Issue 39, item 6: a box at x = 1e300 with a ball 1.1 m above it reported impacts at +0 s and
// +0.2 s, the ball 1.1 and 0.5 m away, with no word: a body near it has a touching band of
// 2^-48 (|x_ball| + |x_box| + ...) = 7e285 m. As a body's contacts are coarse from |x| = 2^47 r on,
// an obstacle's are from 2^47 times its bounding radius, where that band is as wide as the whole
// obstacle: the scene warns, naming the field. A box of edges 2, 2 and 1 m holds in a sphere of
// radius sqrt(1 + 1 + 1/4) = 1.5 m: |x| < 2^47 x 1.5 = 211106232532992 m (exactly). As a body's
// coordinates, a plane's offset, every extent and a position are refused from 2^1022 on.
TEST(Validation, Issue39_Item6_AnObstacleBeyondItsResolutionIsWarnedOrRefusedNamingTheField) {
  using Eigen::Vector3d;
  const double bound = 211106232532992.0;
  Scene scene;
  scene.obstacles = {
      scene_builders::box("table", Vector3d(1e300, 0, 0), Vector3d(2, 2, 1), "concrete")};
  ASSERT_TRUE(validateScene(scene, "scene").ok());
  std::vector<std::string> warnings = obstaclesBeyondResolution(scene, "scene");
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0],
            "scene/obstacles[0]/position.x: 1e+300 m is beyond where a contact with this obstacle "
            "resolves (|x| must be below 2^47 times its bounding radius 1.5 m, 211106232532992 m: "
            "from there the touching band of a body near it, 2^-48 (|x_body| + |x| + ...), is as "
            "wide as the whole obstacle): a body touches obstacle 'table' from as far as it is "
            "large (its contacts are coarse)");
  scene.obstacles[0].position = Vector3d(0, 0, -bound);
  warnings = obstaclesBeyondResolution(scene, "scene");
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].find("scene/obstacles[0]/position.z: "), 0u) << warnings[0];
  scene.obstacles[0].position = Vector3d(0, 0, -std::nextafter(bound, 0.0));
  EXPECT_TRUE(obstaclesBeyondResolution(scene, "scene").empty());
  // A sphere's bound is its radius's; a point (radius 0) is held as a body of radius 0 is.
  scene.obstacles = {scene_builders::sphere("post", Vector3d(0, 0.5 * 0x1p47, 0), 1.0, "concrete")};
  EXPECT_TRUE(obstaclesBeyondResolution(scene, "scene").empty());
  scene.obstacles[0].position.y() = 0x1p47;
  EXPECT_EQ(obstaclesBeyondResolution(scene, "scene").size(), 1u);
  scene.obstacles[0].radius = 0.0;
  EXPECT_TRUE(obstaclesBeyondResolution(scene, "scene").empty());
  // Refused, as a body's position is: from 2^1022 on.
  scene.obstacles[0].position.y() = 0x1p1022;
  const Status post = validateScene(scene, "scene");
  ASSERT_FALSE(post.ok());
  EXPECT_EQ(post.error().message(),
            "scene/obstacles[0]/position.y: 4.49423283715579e+307 m is beyond where the monitor "
            "can resolve a contact (|y| must be below 2^1022 = 4.49423283715579e+307 m: past "
            "2^1023 the sum of two bodies' coordinates overflows)");
  scene.obstacles = {
      scene_builders::box("table", Vector3d::Zero(), Vector3d(2, 1e308, 1), "concrete")};
  EXPECT_EQ(validateScene(scene, "scene").error().field, "scene/obstacles[0]/size");
  scene.obstacles = {scene_builders::plane("floor", Vector3d::UnitZ(), 1.7e308, "concrete")};
  const Status plane = validateScene(scene, "scene");
  ASSERT_FALSE(plane.ok());
  EXPECT_EQ(plane.error().message(),
            "scene/obstacles[0]/offset: 1.7e+308 m is beyond where the monitor can resolve a "
            "contact (its magnitude must be below 2^1022 = 4.49423283715579e+307 m: past 2^1023 "
            "the sum of two coordinates overflows)");
  scene.obstacles[0].offset = std::nextafter(0x1p1022, 0.0);
  EXPECT_TRUE(validateScene(scene, "scene").ok());
}

// A body placed inside a fixed obstacle is named with the obstacle and its depth; one touching
// it, one outside, and one inside an obstacle on a tf frame (placed only at run time) are not.
TEST(Validation, BodiesStartingInsideAFixedObstacleAreNamed) {
  using Eigen::Vector3d;
  Scene scene;
  scene.bodies = {scene_builders::ball("deep", 0.1, 0.1, "concrete"),
                  scene_builders::ball("resting", 0.1, 0.1, "concrete"),
                  scene_builders::ball("below", 0.1, 0.1, "concrete")};
  scene.bodies[0].position = Vector3d(0.2, 0, 0.7);    // the box's top at 0.75: 0.15 m in
  scene.bodies[1].position = Vector3d(-0.2, 0, 0.85);  // on the top, touching
  scene.bodies[2].position = Vector3d(3, 0, -0.25);    // under the floor by 0.35
  scene.obstacles = {
      scene_builders::box("table", Vector3d(0, 0, 0.5), Vector3d(1, 1, 0.5), "concrete"),
      scene_builders::plane("floor", Vector3d(0, 0, 1), 0.0, "concrete")};
  ObstacleSpec moving =
      scene_builders::box("paddle", Vector3d(0.2, 0, 0.7), Vector3d(1, 1, 1), "concrete");
  moving.frame = "paddle_link";
  scene.obstacles.push_back(moving);
  const std::vector<std::string> warnings = bodiesStartingInside(scene);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_EQ(warnings[0], "body 'deep' at [0.2, 0, 0.7] starts 0.15 m inside obstacle 'table'");
  EXPECT_EQ(warnings[1], "body 'below' at [3, 0, -0.25] starts 0.35 m inside obstacle 'floor'");
}

}  // namespace
}  // namespace collision_response::core
