// Calls the running collision_response node's services over ROS (rostest: real master, real
// node) with good and bad requests. Expected numbers are closed forms worked out in comments.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <string>

#include "collision_response/ComputeCollision.h"
#include "collision_response/EstimateRestitution.h"
#include "seed_request.h"

namespace {

using collision_response::ComputeCollision;
using collision_response::EstimateRestitution;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

class Services : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(ros::service::waitForService("/collision_response/compute_collision", 20000));
    ASSERT_TRUE(ros::service::waitForService("/collision_response/estimate_restitution", 20000));
    compute_ = node_.serviceClient<ComputeCollision>("/collision_response/compute_collision", true);
    estimate_ =
        node_.serviceClient<EstimateRestitution>("/collision_response/estimate_restitution", true);
  }

  ComputeCollision::Response call(const ComputeCollision::Request& request) {
    ComputeCollision srv;
    srv.request = request;
    EXPECT_TRUE(compute_.call(srv)) << "the service must answer every request";
    return srv.response;
  }

  static ComputeCollision::Request seedRequest() {
    return collision_response::testing::seedHeadOnRequest();
  }

  void expectSeedAnswer() {
    const auto response = call(seedRequest());
    ASSERT_TRUE(response.success) << response.message;
    EXPECT_DOUBLE_EQ(response.velocity_a.x, collision_response::testing::kSeedVelocityA);
    EXPECT_DOUBLE_EQ(response.velocity_b.x, collision_response::testing::kSeedVelocityB);
  }

  void expectRefused(const ComputeCollision::Request& request, const std::string& field) {
    const auto response = call(request);
    EXPECT_FALSE(response.success);
    EXPECT_EQ(response.message.rfind(field + ":", 0), 0u)
        << "message must start with the field '" << field << "': " << response.message;
    EXPECT_EQ(response.velocity_a.x, 0.0) << "a refused request carries no numbers";
    // The node keeps serving, correctly.
    expectSeedAnswer();
  }

  ros::NodeHandle node_;
  ros::ServiceClient compute_;
  ros::ServiceClient estimate_;
};

TEST_F(Services, SeedCombinedFormulas) {
  const auto response = call(seedRequest());
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_EQ(response.velocity_a.x, collision_response::testing::kSeedVelocityA);
  EXPECT_EQ(response.velocity_b.x, collision_response::testing::kSeedVelocityB);
  EXPECT_EQ(response.normal.x, 1.0);  // derived from the positions
  EXPECT_TRUE(response.approaching);
  EXPECT_FALSE(response.oblique);
  EXPECT_DOUBLE_EQ(response.impulse, collision_response::testing::kSeedImpulse);
  EXPECT_DOUBLE_EQ(response.energy_lost, collision_response::testing::kSeedEnergyLost);
}

TEST_F(Services, ObliqueImpactChangesOnlyTheNormalComponent) {
  // Equal masses, e = 1, a at (3, 4, 0) hits b at rest; the line of impact (from the centres)
  // is x, so the x components are exchanged and y is kept: a' = (0, 4, 0), b' = (3, 0, 0).
  ComputeCollision::Request request;
  request.a.mass = 0.17;
  request.a.velocity.x = 3.0;
  request.a.velocity.y = 4.0;
  request.b.mass = 0.17;
  request.b.position.x = 0.06;
  request.restitution = 1.0;
  const auto response = call(request);
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_TRUE(response.oblique);
  EXPECT_EQ(response.velocity_a.x, 0.0);
  EXPECT_EQ(response.velocity_a.y, 4.0);
  EXPECT_EQ(response.velocity_b.x, 3.0);
  EXPECT_EQ(response.velocity_b.y, 0.0);
  EXPECT_EQ(response.energy_lost, 0.0);
}

TEST_F(Services, ImmovableWallGivesExactlyMinusEV) {
  ComputeCollision::Request request;
  request.a.mass = 0.057;
  request.a.material = "tennis_ball";
  request.a.velocity.z = -4.43;
  request.b.mass = kInf;
  request.b.material = "concrete";
  request.normal.z = -1.0;
  const auto response = call(request);
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_EQ(response.restitution, 0.712);
  EXPECT_EQ(response.velocity_a.z, 0.712 * 4.43);  // -e v, to the last bit
  EXPECT_EQ(response.velocity_b.z, 0.0);
}

TEST_F(Services, SceneMaterialsAndPairsAreUsed) {
  ComputeCollision::Request request = seedRequest();
  request.restitution = 0.0;
  request.a.material = "rubber";
  request.b.material = "steel_ball_bearing";
  auto response = call(request);
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_EQ(response.restitution, 0.7);  // the scene's pair
  request.b.material = "concrete";
  response = call(request);
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_EQ(response.restitution, 0.85);  // rubber's own coefficient
  request.b.material = "tennis_ball";
  response = call(request);
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_EQ(response.restitution, 0.712);  // min(0.85, 0.712)
}

TEST_F(Services, SeparatingBodiesAreNotApproaching) {
  ComputeCollision::Request request = seedRequest();
  request.a.velocity.x = -3.0;
  const auto response = call(request);
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_FALSE(response.approaching);
  EXPECT_EQ(response.velocity_a.x, -3.0);
  EXPECT_EQ(response.impulse, 0.0);
}

TEST_F(Services, BadRequestsNameTheFieldAndTheNodeKeepsServing) {
  auto request = seedRequest();
  request.a.mass = -1.0;
  expectRefused(request, "a.mass");

  request = seedRequest();
  request.restitution = 1.5;
  expectRefused(request, "restitution");

  request = seedRequest();
  request.b.velocity.y = kNan;
  expectRefused(request, "b.velocity.y");

  request = seedRequest();
  request.a.mass = kInf;
  request.b.mass = kInf;
  expectRefused(request, "b.mass");

  request = seedRequest();
  request.b.position = request.a.position;  // and normal zero: no line of impact
  expectRefused(request, "normal");

  request = seedRequest();
  request.a.material = "tennis_ball";
  request.b.material = "unobtainium";
  request.restitution = 0.0;
  expectRefused(request, "b.material");

  request = seedRequest();
  request.effects = {"warp"};
  expectRefused(request, "effects[0]");
}

// A solid ball (m, r) striking the floor at (3, 0, -4) m/s, e = 0.5, friction 0.2 and spin on:
// J_n = 1.5 m 4 bounds friction at 0.2 J_n = 1.2 m, stopping the slip takes m 3 / 3.5 (less),
// so it sticks and rolls away at (5/7) 3 m/s, spinning (5/7) 3 / r rad/s.
TEST_F(Services, FrictionAndSpinMakeTheBallRoll) {
  ComputeCollision::Request request;
  request.a.mass = 0.057;
  request.a.radius = 0.033;
  request.a.velocity.x = 3.0;
  request.a.velocity.z = -4.0;
  request.b.mass = kInf;
  request.normal.z = -1.0;
  request.restitution = 0.5;
  request.friction = 0.2;
  request.effects = {"friction", "spin"};
  const auto response = call(request);
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_TRUE(response.sticking);
  EXPECT_NEAR(response.velocity_a.x, 15.0 / 7.0, 1e-14);
  EXPECT_NEAR(response.angular_velocity_a.y, 15.0 / 7.0 / 0.033, 1e-12);
  EXPECT_EQ(response.velocity_a.z, 2.0);

  request.a.inertia = "cube";
  expectRefused(request, "a.inertia");
}

// Shaped bodies over ROS (issue 42): a 12 kg box of edges (1, 2, 3) m at rest, not turned, struck
// at its corner (1/2, 1, 3/2) by a 1 kg ball of radius 7/8 m moving at -(2, 3, 6) m/s, e = 1/2,
// frictionless. The node finds the contact (the corner) and the normal n = -(2, 3, 6)/7 from
// the shapes; the closed form (test/exact/shaped_collision.py): n.K.n = 1 + 1/12 + (9/196)/13 +
// (1/196)/5 = 41579/38220, j = 10.5 / n.K.n, v_box' = j n / 12, w_box' = j (-3/182, 0, 1/70).
ComputeCollision::Request ballOnABoxCorner() {
  ComputeCollision::Request request;
  request.a.mass = 1.0;
  request.a.radius = 7.0 / 8.0;
  request.a.position.x = 3.0 / 4.0;
  request.a.position.y = 11.0 / 8.0;
  request.a.position.z = 9.0 / 4.0;
  request.a.velocity.x = -2.0;
  request.a.velocity.y = -3.0;
  request.a.velocity.z = -6.0;
  request.b.mass = 12.0;
  request.b.shape = "box";
  request.b.size.x = 1.0;
  request.b.size.y = 2.0;
  request.b.size.z = 3.0;
  request.b.orientation.w = 1.0;
  request.restitution = 0.5;
  return request;
}

// The box's closed form (test/exact/shaped_collision.py): the impulse 10.5 / n.K.n with n.K.n =
// 41579/38220, along n = -(2, 3, 6)/7 at the corner (1/2, 1, 3/2); the box's velocity and spin
// after, and the energy lost. What differs between the ball and a box in its place is a's spin.
void expectTheBoxCornersClosedForm(const ComputeCollision::Response& response) {
  const double j = 10.5 / (41579.0 / 38220.0);
  const double tolerance = 1e-14;
  EXPECT_NEAR(response.impulse, j, tolerance * j);
  EXPECT_NEAR(response.normal.x, -2.0 / 7.0, tolerance);
  EXPECT_NEAR(response.normal.y, -3.0 / 7.0, tolerance);
  EXPECT_NEAR(response.normal.z, -6.0 / 7.0, tolerance);
  EXPECT_NEAR(response.contact_point.x, 0.5, tolerance);
  EXPECT_NEAR(response.contact_point.y, 1.0, tolerance);
  EXPECT_NEAR(response.contact_point.z, 1.5, tolerance);
  EXPECT_NEAR(response.velocity_b.x, -2.0 / 7.0 * j / 12.0, tolerance);
  EXPECT_NEAR(response.velocity_b.y, -3.0 / 7.0 * j / 12.0, tolerance);
  EXPECT_NEAR(response.velocity_b.z, -6.0 / 7.0 * j / 12.0, tolerance);
  EXPECT_NEAR(response.velocity_a.z, -6.0 + 6.0 / 7.0 * j, 8 * tolerance);
  EXPECT_NEAR(response.angular_velocity_b.x, -3.0 / 182.0 * j, tolerance);
  EXPECT_NEAR(response.angular_velocity_b.y, 0.0, tolerance);
  EXPECT_NEAR(response.angular_velocity_b.z, 1.0 / 70.0 * j, tolerance);
  const double lost = 0.5 * 0.75 * 49.0 / (41579.0 / 38220.0);
  EXPECT_NEAR(response.energy_lost, lost, tolerance * lost);
  EXPECT_TRUE(response.approaching);
}

TEST_F(Services, ABoxStruckAtACornerFrictionlessIsTheClosedForm) {
  const auto response = call(ballOnABoxCorner());
  ASSERT_TRUE(response.success) << response.message;
  expectTheBoxCornersClosedForm(response);
  EXPECT_EQ(response.angular_velocity_a.x, 0.0);  // a ball without the spin effect
}

// Two boxes, the contact found by the node: the ball replaced by a 1 kg box of edges (7/4, 1, 1)
// m turned so that its x axis is along n = -(2, 3, 6)/7 (the rational rotation of columns
// (-2, -3, -6)/7, (3, -6, 2)/7, (-6, -2, 3)/7, its quaternion Eigen's from the matrix, to the
// rounding), its +x face's centre touching the corner
// (1/2, 1, 3/2): its centre the ball's, (3/4, 11/8, 9/4). Its lever arm (7/8) n is along n, so
// it adds only 1/m to n.K.n and does not turn: the same closed form (test/exact/
// shaped_collision.py, box_on_a_box_corner), the contact point the corner, the normal n.
ComputeCollision::Request boxOnABoxCorner() {
  ComputeCollision::Request request = ballOnABoxCorner();
  request.a.radius = 0.0;
  request.a.shape = "box";
  request.a.size.x = 7.0 / 4.0;
  request.a.size.y = 1.0;
  request.a.size.z = 1.0;
  Eigen::Matrix3d turn;
  turn.col(0) = Eigen::Vector3d(-2, -3, -6) / 7.0;
  turn.col(1) = Eigen::Vector3d(3, -6, 2) / 7.0;
  turn.col(2) = Eigen::Vector3d(-6, -2, 3) / 7.0;
  const Eigen::Quaterniond q(turn);
  request.a.orientation.x = q.x();
  request.a.orientation.y = q.y();
  request.a.orientation.z = q.z();
  request.a.orientation.w = q.w();
  return request;
}

TEST_F(Services, TwoBoxesContactFoundByTheNodeIsTheCornersClosedForm) {
  const auto response = call(boxOnABoxCorner());
  ASSERT_TRUE(response.success) << response.message;
  expectTheBoxCornersClosedForm(response);
  EXPECT_NEAR(response.angular_velocity_a.x, 0.0, 64e-14);  // its lever arm along n
  EXPECT_NE(response.message.find("contact found from the shapes, touching"), std::string::npos)
      << response.message;
}

// Kane and Levinson's rod over ROS (test/exact/rigid_impact.py; ShapedCollision.ARodOnItsEnd...
// in the core): a 1 kg box of edges (0.2, 2, 0.2) m turned by theta about z (sin 5/13), struck
// at its lower end's centre (5/13, -12/13, 0), given, by an immovable box floor (normal y),
// falling at (-0.1, -1, 0) m/s, e = 1, mu = 1/2. Newton's law with Coulomb friction along the
// initial slip would gain 0.678 J; the service's law sticks and loses
// 24158795761/333003312200 J: v' = (-22320/67769, 928257361/1665016561, 0),
// w' = (0, 0, 147351840/128078197).
TEST_F(Services, ARodOnItsEndWithFrictionLosesEnergyWhereNewtonsLawWouldGainIt) {
  ComputeCollision::Request request;
  request.a.mass = kInf;
  request.a.shape = "box";
  request.a.size.x = 10.0;
  request.a.size.y = 2.0;
  request.a.size.z = 10.0;
  request.a.position.x = 5.0 / 13.0;
  request.a.position.y = -12.0 / 13.0 - 1.0;
  request.a.orientation.w = 1.0;
  request.b.mass = 1.0;
  request.b.shape = "box";
  request.b.size.x = 0.2;
  request.b.size.y = 2.0;
  request.b.size.z = 0.2;
  request.b.velocity.x = -0.1;
  request.b.velocity.y = -1.0;
  request.b.orientation.z = 1.0 / std::sqrt(26.0);
  request.b.orientation.w = 5.0 / std::sqrt(26.0);
  request.normal.y = 1.0;
  request.contact_point_given = true;
  request.contact_point.x = 5.0 / 13.0;
  request.contact_point.y = -12.0 / 13.0;
  request.restitution = 1.0;
  request.friction = 0.5;
  request.effects = {"friction"};
  const auto response = call(request);
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_TRUE(response.sticking);
  EXPECT_NEAR(response.velocity_b.x, -22320.0 / 67769.0, 1e-14);
  EXPECT_NEAR(response.velocity_b.y, 928257361.0 / 1665016561.0, 1e-14);
  EXPECT_NEAR(response.angular_velocity_b.z, 147351840.0 / 128078197.0, 1e-14);
  EXPECT_NEAR(response.energy_lost, 24158795761.0 / 333003312200.0, 1e-14);
}

TEST_F(Services, BadShapedBodiesNameTheFieldAndTheNodeKeepsServing) {
  auto request = ballOnABoxCorner();
  request.b.orientation.w = 0.0;  // all zero: not given
  expectRefused(request, "b.orientation");

  request = ballOnABoxCorner();
  request.b.shape = "cube";
  expectRefused(request, "b.shape");

  request = ballOnABoxCorner();
  request.b.shape = "mesh";
  expectRefused(request, "b.shape");

  request = ballOnABoxCorner();
  request.b.size.y = 0.0;
  expectRefused(request, "b.size");

  request = ballOnABoxCorner();
  request.b.radius = 0.5;  // a box has none: not silently ignored
  expectRefused(request, "b.radius");

  request = ballOnABoxCorner();
  request.b.inertia_tensor.ixx = 1.0;
  request.b.inertia_tensor.iyy = 1.0;
  request.b.inertia_tensor.izz = 1.0;
  request.b.inertia_tensor.ixy = 1.5;  // not positive definite
  expectRefused(request, "b.inertia_tensor.ixy");

  request.b.inertia_tensor.ixy = 0.0;
  request.b.inertia = "solid";  // and a tensor: which?
  expectRefused(request, "b.inertia");

  request = ballOnABoxCorner();
  request.a.shape = "cylinder";
  request.a.length = 1.0;
  request.a.orientation.w = 1.0;  // its cap over the box's top face: they meet flat, no one point
  expectRefused(request, "contact_point_given");

  request = boxOnABoxCorner();
  request.a.position.z = 1.5;  // the striker's centre 3/4 m inside the box: they overlap
  expectRefused(request, "contact_point_given");

  request = seedRequest();
  request.contact_point_given = true;  // two balls: their contact is on the line of impact
  expectRefused(request, "contact_point_given");
}

TEST_F(Services, EstimateRestitutionFromHeights) {
  EstimateRestitution srv;
  srv.request.drop_height = 2.0;
  srv.request.bounce_height = 0.5;  // e = sqrt(0.25) = 0.5 exactly
  ASSERT_TRUE(estimate_.call(srv));
  ASSERT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.restitution, 0.5);

  srv.request.drop_height = 1.0;
  srv.request.bounce_height = 0.712 * 0.712;
  ASSERT_TRUE(estimate_.call(srv));
  ASSERT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_NEAR(srv.response.restitution, 0.712, 1e-15);
  EXPECT_EQ(srv.response.nearest_material, "tennis_ball");
  EXPECT_EQ(srv.response.nearest_material_restitution, 0.712);

  // e = sqrt(0.9) = 0.9487: range_golf_ball (0.858) is nearer than the scene's rubber (0.85).
  srv.request.bounce_height = 0.9;
  ASSERT_TRUE(estimate_.call(srv));
  EXPECT_EQ(srv.response.nearest_material, "range_golf_ball");

  srv.request.drop_height = 1.0;
  srv.request.bounce_height = 2.0;
  ASSERT_TRUE(estimate_.call(srv));
  EXPECT_FALSE(srv.response.success);
  EXPECT_EQ(srv.response.message.rfind("bounce_height:", 0), 0u) << srv.response.message;

  srv.request.drop_height = kNan;
  ASSERT_TRUE(estimate_.call(srv));
  EXPECT_FALSE(srv.response.success);
  EXPECT_EQ(srv.response.message.rfind("drop_height:", 0), 0u) << srv.response.message;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "services_test");
  ros::NodeHandle node;  // keeps the node alive for the test's lifetime
  return RUN_ALL_TESTS();
}
