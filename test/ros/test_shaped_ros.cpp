// Shaped bodies on the ROS side (issue 42, step 7), without a master: the state intake reads a
// body's orientation (checked, turned into the fixed frame, normalised), and the markers draw
// every body as its shape at its orientation. Every number is exact or a quaternion product
// worked out by hand below.
#include <gtest/gtest.h>
#include <tf2/buffer_core.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "collision_response/core/body_shape.h"
#include "collision_response/ros/markers.h"
#include "collision_response/ros/monitor_cycle.h"
#include "collision_response/ros/monitor_diagnostics.h"
#include "collision_response/ros/state_intake.h"

namespace collision_response {
namespace {

const double kHalfRoot2 = std::sqrt(0.5);

BodyState stateOf(const std::string& id, double x, double y, double z, double w,
                  const std::string& frame = "world") {
  BodyState state;
  state.header.stamp = ros::Time(1000, 0);
  state.header.frame_id = frame;
  state.id = id;
  state.pose.position.x = 1.0;
  state.pose.orientation.x = x;
  state.pose.orientation.y = y;
  state.pose.orientation.z = z;
  state.pose.orientation.w = w;
  return state;
}

/// A ball and a box: the box's state needs its orientation, the ball's may leave it all zero.
class ShapedIntake : public ::testing::Test {
 protected:
  ShapedIntake() : intake_({"ball", "block"}, {false, true}, IntakeSettings{}) {
    // "camera": turned a quarter turn about the world's x, (sqrt 1/2, 0, 0, sqrt 1/2).
    geometry_msgs::TransformStamped camera;
    camera.header.frame_id = "world";
    camera.child_frame_id = "camera";
    camera.transform.rotation.x = kHalfRoot2;
    camera.transform.rotation.w = kHalfRoot2;
    tf_.setTransform(camera, "test", /*is_static=*/true);
  }

  /// The states converted: the samples kept, the reports into reports_.
  StampedSamples convert(const std::vector<BodyState>& states) {
    StampedSamples samples;
    reports_.clear();
    intake_.convert(states, "", ros::Time(), false, tf_, samples, reports_);
    return samples;
  }

  StateIntake intake_;
  tf2::BufferCore tf_;
  std::vector<Report> reports_;
};

// Item 1: a shaped body's state whose orientation is no rotation (all zero, or of another
// length) is dropped under its own reason, the warning naming the field; the intake once read
// only that it was finite, so the box's zero quaternion went into the monitor as it was.
TEST_F(ShapedIntake, AShapedBodysOrientationThatIsNoRotationIsDroppedByName) {
  struct Case {
    BodyState state;
    const char* words;
  };
  const std::vector<Case> cases = {
      {stateOf("block", 0, 0, 0, 0), "pose.orientation: is zero"},
      {stateOf("block", 0, 0, 0, 2), "pose.orientation: must have length 1"},
      {stateOf("block", 0, 0, 0.8, 0.8), "got length 1.13137"},
      {stateOf("ball", 0, 0, 0, 0.5), "pose.orientation: must have length 1"},
  };
  for (const Case& c : cases) {
    const StampedSamples samples = convert({c.state});
    EXPECT_TRUE(samples.empty()) << c.words;
    ASSERT_EQ(reports_.size(), 1u) << c.words;
    EXPECT_EQ(reports_[0].reason, Reason::kBadOrientation);
    EXPECT_NE(reports_[0].text.find("dropped states[0] ('" + c.state.id + "')"), std::string::npos)
        << reports_[0].text;
    EXPECT_NE(reports_[0].text.find(c.words), std::string::npos) << reports_[0].text;
  }
  // Its own counter, a drop (the summary warns), as /diagnostics shows it.
  EXPECT_EQ(std::string(counterName(Reason::kBadOrientation)),
            "dropped: orientation not a rotation");
  EXPECT_TRUE(isDrop(Reason::kBadOrientation));
  // A non-finite component stays a non-finite value, named as before.
  convert({stateOf("block", 0, NAN, 0, 1)});
  ASSERT_EQ(reports_.size(), 1u);
  EXPECT_EQ(reports_[0].reason, Reason::kNonFinite);
  EXPECT_NE(reports_[0].text.find("pose.orientation.y"), std::string::npos) << reports_[0].text;
}

// Item 1: a good orientation reaches the monitor's sample, normalised, and turned by the state's
// frame as its position is. The box's quarter turn about z, q_z = (0, 0, s, s) with s = sqrt 1/2,
// given 0.1 % long (its squared length 1.002, within tf2's 0.01), in "camera" (q_x = (s, 0, 0,
// s)): q_x q_z = (w_x w_z - v_x.v_z, w_x v_z + w_z v_x + v_x x v_z) = (1/2, (1/2, 0, 1/2) +
// (0, -1/2, 0)) = (x, y, z, w) = (1/2, -1/2, 1/2, 1/2).
TEST_F(ShapedIntake, AGoodOrientationIsNormalisedAndTurnedIntoTheFixedFrame) {
  const double s = 1.001 * kHalfRoot2;
  StampedSamples samples = convert({stateOf("block", 0, 0, s, s)});
  ASSERT_EQ(samples.size(), 1u);
  EXPECT_TRUE(reports_.empty());
  const Eigen::Vector4d world = samples.samples[0].orientation.coeffs();  // x, y, z, w
  EXPECT_NEAR((world - Eigen::Vector4d(0, 0, kHalfRoot2, kHalfRoot2)).norm(), 0, 4e-16) << world;

  samples = convert({stateOf("block", 0, 0, s, s, "camera")});
  ASSERT_EQ(samples.size(), 1u);
  EXPECT_TRUE(reports_.empty());
  const Eigen::Vector4d turned = samples.samples[0].orientation.coeffs();
  EXPECT_NEAR((turned - Eigen::Vector4d(0.5, -0.5, 0.5, 0.5)).norm(), 0, 4e-16) << turned;
  // The position turned alike: (1, 0, 0) lies on the turn's axis.
  EXPECT_EQ(samples.samples[0].position, Eigen::Vector3d(1, 0, 0));
}

// A ball's orientation does not matter: all zero (a geometry_msgs/Quaternion's default, what
// most trackers of balls send) is not given, and the ball's sample keeps the identity.
TEST_F(ShapedIntake, ABallsOrientationLeftAllZeroIsNotGiven) {
  const StampedSamples samples = convert({stateOf("ball", 0, 0, 0, 0)});
  ASSERT_EQ(samples.size(), 1u);
  EXPECT_TRUE(reports_.empty());
  EXPECT_EQ(samples.samples[0].orientation.coeffs(), Eigen::Vector4d(0, 0, 0, 1));
}

core::BodySpec bodyOf(const std::string& id, core::BodyShape shape) {
  core::BodySpec body;
  body.id = id;
  body.mass = 0.5;
  body.material = "wooden_ball";
  body.shape = shape;
  return body;
}

void expectQuaternion(const geometry_msgs::Quaternion& q, double x, double y, double z, double w) {
  EXPECT_DOUBLE_EQ(q.x, x);
  EXPECT_DOUBLE_EQ(q.y, y);
  EXPECT_DOUBLE_EQ(q.z, z);
  EXPECT_DOUBLE_EQ(q.w, w);
}

// Item 2: every body drawn as its shape, at its centre and orientation, as the obstacles of
// that shape are: a box a CUBE of its edges, a cylinder a CYLINDER of its diameter and length,
// a capsule a CYLINDER (its segment) and its two ends, a ball a SPHERE unturned.
TEST(ShapedMarkers, EveryBodyIsDrawnAsItsShapeAtItsOrientation) {
  const ros::Time stamp(1000, 0);
  const BodyPose turned_about_z{{1, 2, 3}, {kHalfRoot2, 0, 0, kHalfRoot2}};  // (w, x, y, z)
  const BodyPose turned_about_x{{1, 2, 3}, {kHalfRoot2, kHalfRoot2, 0, 0}};

  core::BodySpec box = bodyOf("block", core::BodyShape::kBox);
  box.size = Eigen::Vector3d(0.1, 0.2, 0.3);
  visualization_msgs::MarkerArray array;
  appendBodyMarkers(box, 4, turned_about_z, "world", stamp, array);
  ASSERT_EQ(array.markers.size(), 1u);
  const visualization_msgs::Marker& cube = array.markers[0];
  EXPECT_EQ(cube.type, visualization_msgs::Marker::CUBE);
  EXPECT_EQ(cube.action, visualization_msgs::Marker::ADD);
  EXPECT_EQ(cube.ns, "bodies");
  EXPECT_EQ(cube.id, 4);
  EXPECT_EQ(cube.header.frame_id, "world");
  EXPECT_EQ(cube.text, "block");
  EXPECT_EQ(cube.scale.x, 0.1);
  EXPECT_EQ(cube.scale.y, 0.2);
  EXPECT_EQ(cube.scale.z, 0.3);
  EXPECT_EQ(cube.pose.position.x, 1.0);
  EXPECT_EQ(cube.pose.position.y, 2.0);
  EXPECT_EQ(cube.pose.position.z, 3.0);
  expectQuaternion(cube.pose.orientation, 0, 0, kHalfRoot2, kHalfRoot2);

  core::BodySpec can = bodyOf("can", core::BodyShape::kCylinder);
  can.radius = 0.05;
  can.length = 0.2;
  array.markers.clear();
  appendBodyMarkers(can, 1, turned_about_x, "world", stamp, array);
  ASSERT_EQ(array.markers.size(), 1u);
  EXPECT_EQ(array.markers[0].type, visualization_msgs::Marker::CYLINDER);
  EXPECT_EQ(array.markers[0].scale.x, 0.1);
  EXPECT_EQ(array.markers[0].scale.y, 0.1);
  EXPECT_EQ(array.markers[0].scale.z, 0.2);
  expectQuaternion(array.markers[0].pose.orientation, kHalfRoot2, 0, 0, kHalfRoot2);

  // A capsule turned a quarter about x: its axis z goes to -y, so its ends' centres are at the
  // centre -/+ 0.1 m along y (+half_length along the axis first).
  core::BodySpec pill = bodyOf("pill", core::BodyShape::kCapsule);
  pill.radius = 0.05;
  pill.length = 0.2;
  array.markers.clear();
  appendBodyMarkers(pill, 2, turned_about_x, "world", stamp, array);
  ASSERT_EQ(array.markers.size(), 2u);
  EXPECT_EQ(array.markers[0].type, visualization_msgs::Marker::CYLINDER);
  EXPECT_EQ(array.markers[0].ns, "bodies");
  EXPECT_EQ(array.markers[0].scale.z, 0.2);
  const visualization_msgs::Marker& ends = array.markers[1];
  EXPECT_EQ(ends.type, visualization_msgs::Marker::SPHERE_LIST);
  EXPECT_EQ(ends.ns, "body_ends");
  EXPECT_EQ(ends.id, 2);
  EXPECT_EQ(ends.scale.x, 0.1);
  ASSERT_EQ(ends.points.size(), 2u);
  EXPECT_NEAR(ends.points[0].x, 1.0, 1e-16);
  EXPECT_NEAR(ends.points[0].y, 1.9, 1e-15);
  EXPECT_NEAR(ends.points[0].z, 3.0, 1e-15);
  EXPECT_NEAR(ends.points[1].y, 2.1, 1e-15);

  // A ball: a sphere of its diameter, unturned whatever its state's orientation.
  core::BodySpec ball = bodyOf("ball", core::BodyShape::kSphere);
  ball.radius = 0.05;
  array.markers.clear();
  appendBodyMarkers(ball, 0, turned_about_z, "world", stamp, array);
  ASSERT_EQ(array.markers.size(), 1u);
  EXPECT_EQ(array.markers[0].type, visualization_msgs::Marker::SPHERE);
  EXPECT_EQ(array.markers[0].scale.x, 0.1);
  EXPECT_EQ(array.markers[0].pose.position.z, 3.0);
  expectQuaternion(array.markers[0].pose.orientation, 0, 0, 0, 1);

  // Not tracked: the capsule's markers deleted in both namespaces.
  array.markers.clear();
  appendBodyMarkers(pill, 2, std::nullopt, "world", stamp, array);
  ASSERT_EQ(array.markers.size(), 2u);
  for (const visualization_msgs::Marker& gone : array.markers) {
    EXPECT_EQ(gone.action, visualization_msgs::Marker::DELETE);
    EXPECT_EQ(gone.id, 2);
  }
  EXPECT_EQ(array.markers[0].ns, "bodies");
  EXPECT_EQ(array.markers[1].ns, "body_ends");
}

/// A box (0.1 m cube, 2 kg) at rest with its centre at (0, 0, 0.5) and a ball (radius 0.02 m)
/// at (0.2, 0, 0.5) moving at -1 m/s, no gravity: the ball reaches the box's face x = 0.05 when
/// its centre is at 0.07, at (0.2 - 0.07) / 1 = 0.13 s. With friction and without spin the ball
/// stays a ball (doc/model.md, "Balls among shaped bodies"), and a shaped body touching a ball is
/// not modelled (core::StepReport::unmodelled).
core::Scene boxAndBallScene() {
  core::Scene scene;
  scene.effects.friction = true;
  scene.materials.addMaterial("test_half", core::Material{0.5, std::nullopt}, "materials");
  core::BodySpec box = bodyOf("block", core::BodyShape::kBox);
  box.mass = 2.0;
  box.size = Eigen::Vector3d(0.1, 0.1, 0.1);
  box.material = "test_half";
  core::BodySpec ball = bodyOf("ball", core::BodyShape::kSphere);
  ball.mass = 0.1;
  ball.radius = 0.02;
  ball.material = "test_half";
  scene.bodies = {box, ball};
  return scene;
}

std::string diagnosticValue(const diagnostic_updater::DiagnosticStatusWrapper& status,
                            const std::string& key) {
  for (const diagnostic_msgs::KeyValue& value : status.values) {
    if (value.key == key) return value.value;
  }
  return "(none)";
}

// Item 4: a contact of a shaped body that the model does not carry yet is said (a warning naming
// the body, the other and why) and counted on /diagnostics under its own counter, once when it
// begins, never passing silently; it drops nothing (the summary stays OK). Before, the node
// did not read StepReport::unmodelled at all.
TEST(ShapedDiagnostics, AnUnmodelledContactIsNamedAndCounted) {
  MonitorCycle cycle(boxAndBallScene(), MonitorParams{});
  tf2::BufferCore tf;
  const ros::Time start(1000, 0);
  std::vector<Report> reports;
  MonitorDiagnostics diagnostics;
  std::deque<std::vector<BodyState>> inputs;  // kept alive: the cycle reads them in place
  for (int k = 0; k <= 3; ++k) {
    const ros::Time stamp = start + ros::Duration(0.1 * k);
    BodyState box = stateOf("block", 0, 0, 0, 1);
    box.header.stamp = stamp;
    box.pose.position.x = 0.0;
    box.pose.position.z = 0.5;
    inputs.push_back({box});
    if (k == 0) {  // the ball once: the monitor moves it on from there
      BodyState ball = stateOf("ball", 0, 0, 0, 0);
      ball.header.stamp = stamp;
      ball.pose.position.x = 0.2;
      ball.pose.position.z = 0.5;
      ball.twist.linear.x = -1.0;
      inputs.back().push_back(ball);
    }
    const MonitorCycle::Input input{&inputs.back(), "/body_states", "/source", ""};
    const MonitorCycle::Update update = cycle.process(input, start, false, tf);
    diagnostics.received(inputs.back().size());
    for (const Report& report : update.reports) {
      diagnostics.count(report.reason, report.count);
      reports.push_back(report);
    }
  }
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_EQ(reports[0].reason, Reason::kUnmodelledContact);
  EXPECT_NE(reports[0].text.find("the contact of 'block' and 'ball'"), std::string::npos)
      << reports[0].text;
  EXPECT_NE(reports[0].text.find("not modelled yet"), std::string::npos) << reports[0].text;
  EXPECT_FALSE(isDrop(Reason::kUnmodelledContact));
  diagnostic_updater::DiagnosticStatusWrapper status;
  diagnostics.report(status, cycle, 0);
  EXPECT_EQ(diagnosticValue(status, "contacts of shaped bodies not modelled yet (total)"), "1");
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::OK) << status.message;
}

// Item 4: the contacts topic carries a shaped body's lasting contact as a ball's, one Contact a
// point: a box (0.1 x 0.08 x 0.06 m, 2 kg) given at rest flat on a floor rests on its four
// corners, each carrying m g / 4 by symmetry (the four supports symmetric about the centre), the
// normal from the box into the floor.
TEST(ShapedContacts, ABoxRestingFlatIsPublishedAsOneContactACorner) {
  core::Scene scene;
  scene.effects.gravity = true;
  scene.gravity = Eigen::Vector3d(0, 0, -9.81);
  scene.materials.addMaterial("test_half", core::Material{0.5, std::nullopt}, "materials");
  core::BodySpec box = bodyOf("block", core::BodyShape::kBox);
  box.mass = 2.0;
  box.size = Eigen::Vector3d(0.1, 0.08, 0.06);
  box.material = "test_half";
  scene.bodies = {box};
  core::ObstacleSpec floor;
  floor.id = "floor";
  floor.material = "test_half";
  scene.obstacles = {floor};
  MonitorCycle cycle(scene, MonitorParams{});
  tf2::BufferCore tf;
  const ros::Time start(1000, 0);
  std::deque<std::vector<BodyState>> inputs;
  MonitorCycle::Update update;
  for (int k = 0; k <= 2; ++k) {
    BodyState state = stateOf("block", 0, 0, 0, 1);
    state.header.stamp = start + ros::Duration(0.01 * k);
    state.pose.position.x = 0.1;
    state.pose.position.z = 0.03;
    inputs.push_back({state});
    update = cycle.process({&inputs.back(), "/body_states", "/source", ""}, start, false, tf);
    EXPECT_TRUE(update.reports.empty()) << update.reports.front().text;
  }
  ASSERT_EQ(update.contacts.contacts.size(), 4u);
  std::vector<std::pair<double, double>> corners;
  for (const Contact& contact : update.contacts.contacts) {
    EXPECT_EQ(contact.body_a, "block");
    EXPECT_EQ(contact.body_b, "floor");
    EXPECT_NEAR(contact.normal_force, 2.0 * 9.81 / 4, 1e-12);
    EXPECT_NEAR(contact.normal.z, -1.0, 1e-15);
    EXPECT_NEAR(contact.contact_point.z, 0.0, 1e-12);
    corners.emplace_back(contact.contact_point.x, contact.contact_point.y);
  }
  std::sort(corners.begin(), corners.end());
  const std::vector<std::pair<double, double>> expected = {
      {0.05, -0.04}, {0.05, 0.04}, {0.15, -0.04}, {0.15, 0.04}};
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_NEAR(corners[k].first, expected[k].first, 1e-12);
    EXPECT_NEAR(corners[k].second, expected[k].second, 1e-12);
  }
}

}  // namespace
}  // namespace collision_response
