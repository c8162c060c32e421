// The scene's `robot:` key: a URDF's <collision> elements as obstacles on their links' frames,
// named and placed as the URDF says (sizes in full lengths, a cylinder along z), grown by
// `padding`; a mesh loaded from its filename at its scale; every error named by its key.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "collision_response/core/triangle_mesh.h"
#include "collision_response/ros/robot_obstacles.h"
#include "collision_response/ros/scene_loader.h"

namespace collision_response {
namespace {

/// A test mesh (test/meshes) as a file:// address.
std::string meshFile(const std::string& name) {
  return "file://" + std::string(COLLISION_RESPONSE_TEST_MESHES) + "/" + name;
}

/// The arm, its paddle's grip the mesh `grip` (test/meshes/grip.stl: a box 0.0625 x 0.125 x
/// 0.09375 m about its origin) at scale 2 along x.
std::string arm(const std::string& grip = meshFile("grip.stl")) {
  return R"(<?xml version="1.0"?>
<robot name="arm">
  <link name="base_link"/>
  <link name="upper_arm">
    <collision>
      <origin xyz="0 0 0.2" rpy="1.5707963267948966 0 0"/>
      <geometry><cylinder radius="0.04" length="0.4"/></geometry>
    </collision>
  </link>
  <link name="paddle">
    <collision>
      <origin xyz="0.1 0 0" rpy="0 0 0"/>
      <geometry><box size="0.02 0.3 0.2"/></geometry>
    </collision>
    <collision>
      <origin xyz="0 0 0.3"/>
      <geometry><sphere radius="0.05"/></geometry>
    </collision>
    <collision>
      <origin xyz="0 0.2 0"/>
      <geometry><mesh filename=")" +
         grip + R"(" scale="2 1 1"/></geometry>
    </collision>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base_link"/><child link="upper_arm"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="wrist" type="fixed">
    <parent link="upper_arm"/><child link="paddle"/><origin xyz="0 0 0.4"/>
  </joint>
</robot>)";
}
const std::string kArm = arm();

TEST(RobotObstacles, EveryCollisionOfTheLinksNamedAndPlacedAsTheUrdfSays) {
  RobotLinks robot;
  robot.material = "wooden_ball";
  std::vector<std::string> skipped;
  const auto obstacles = robotObstacles(kArm, robot, "~scene/robot", skipped);
  ASSERT_TRUE(obstacles.ok()) << obstacles.error().message();
  // In link-name order: paddle (three collisions), upper_arm (one).
  ASSERT_EQ(obstacles->size(), 4u);
  const core::ObstacleSpec& box = (*obstacles)[0];
  EXPECT_EQ(box.id, "paddle/0");
  EXPECT_EQ(box.frame, "paddle");
  EXPECT_EQ(box.material, "wooden_ball");
  EXPECT_EQ(box.shape, core::ObstacleShape::kBox);
  EXPECT_EQ(box.size, Eigen::Vector3d(0.02, 0.3, 0.2));  // URDF sizes are full lengths
  EXPECT_EQ(box.position, Eigen::Vector3d(0.1, 0, 0));
  const core::ObstacleSpec& ball = (*obstacles)[1];
  EXPECT_EQ(ball.id, "paddle/1");
  EXPECT_EQ(ball.shape, core::ObstacleShape::kSphere);
  EXPECT_EQ(ball.radius, 0.05);
  EXPECT_EQ(ball.position, Eigen::Vector3d(0, 0, 0.3));
  const core::ObstacleSpec& grip = (*obstacles)[2];
  EXPECT_EQ(grip.id, "paddle/2");
  EXPECT_EQ(grip.shape, core::ObstacleShape::kMesh);
  EXPECT_EQ(grip.resource, meshFile("grip.stl"));
  EXPECT_EQ(grip.scale, Eigen::Vector3d(2, 1, 1));
  EXPECT_EQ(grip.position, Eigen::Vector3d(0, 0.2, 0));
  ASSERT_TRUE(grip.mesh);
  // The STL's 12 triangles, its 8 corners (each repeated in the file) joined, the x scaled by 2:
  // every corner at (+-0.0625, +-0.0625, +-0.046875), exact in the file's single precision.
  EXPECT_EQ(grip.mesh->triangles().size(), 12u);
  std::set<std::tuple<double, double, double>> corners;
  for (const auto& triangle : grip.mesh->triangles()) {
    for (const std::uint32_t v : triangle) {
      const Eigen::Vector3d& p = grip.mesh->vertices()[v];
      corners.insert({p.x(), p.y(), p.z()});
      EXPECT_EQ(p.cwiseAbs(), Eigen::Vector3d(0.0625, 0.0625, 0.046875)) << p.transpose();
    }
  }
  EXPECT_EQ(corners.size(), 8u);
  const core::ObstacleSpec& arm_link = (*obstacles)[3];
  EXPECT_EQ(arm_link.id, "upper_arm");  // its only collision: the link's name alone
  EXPECT_EQ(arm_link.frame, "upper_arm");
  EXPECT_EQ(arm_link.shape, core::ObstacleShape::kCylinder);
  EXPECT_EQ(arm_link.radius, 0.04);
  EXPECT_EQ(arm_link.length, 0.4);
  EXPECT_EQ(arm_link.position, Eigen::Vector3d(0, 0, 0.2));
  // Roll pi/2: the cylinder's axis z turned onto -y.
  EXPECT_NEAR((arm_link.orientation * Eigen::Vector3d::UnitZ() - Eigen::Vector3d(0, -1, 0)).norm(),
              0, 1e-12);
  EXPECT_TRUE(skipped.empty());
}

TEST(RobotObstacles, AMeshIsNotPaddedAndItsZeroAreaTrianglesAreNamed) {
  RobotLinks robot;
  robot.material = "concrete";
  robot.padding = 0.01;
  std::vector<std::string> warnings;
  const auto obstacles =
      robotObstacles(arm(meshFile("zero_area.stl")), robot, "~scene/robot", warnings);
  ASSERT_TRUE(obstacles.ok()) << obstacles.error().message();
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("link 'paddle' <collision> 2: "), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("zero_area.stl': 1 triangle(s) of zero area left out"),
            std::string::npos)
      << warnings[0];
  EXPECT_NE(warnings[1].find("is not grown by the padding"), std::string::npos) << warnings[1];
  EXPECT_EQ((*obstacles)[2].mesh->triangles().size(), 12u);
}

TEST(RobotObstacles, AMeshThatDoesNotLoadIsNamedWithItsReason) {
  RobotLinks robot;
  robot.material = "concrete";
  std::vector<std::string> warnings;
  const std::string missing = meshFile("no_such_grip.stl");
  auto result = robotObstacles(arm(missing), robot, "~scene/robot", warnings);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().field, "~scene/robot/description");
  EXPECT_NE(result.error().reason.find("link 'paddle' <collision> 2, <mesh> filename: '" + missing +
                                       "' does not load: "),
            std::string::npos)
      << result.error().reason;
  result = robotObstacles(arm(meshFile("not_a_mesh.stl")), robot, "~scene/robot", warnings);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().reason.find("is not a mesh assimp reads"), std::string::npos)
      << result.error().reason;
}

TEST(RobotObstacles, ChosenLinksAndPadding) {
  RobotLinks robot;
  robot.material = "concrete";
  robot.all_links = false;
  robot.links = {"upper_arm"};
  robot.padding = 0.01;
  std::vector<std::string> skipped;
  const auto obstacles = robotObstacles(kArm, robot, "~scene/robot", skipped);
  ASSERT_TRUE(obstacles.ok());
  ASSERT_EQ(obstacles->size(), 1u);
  EXPECT_DOUBLE_EQ((*obstacles)[0].radius, 0.05);
  EXPECT_DOUBLE_EQ((*obstacles)[0].length, 0.42);
  EXPECT_TRUE(skipped.empty());
}

TEST(RobotObstacles, ErrorsNameTheKey) {
  RobotLinks robot;
  robot.material = "concrete";
  std::vector<std::string> skipped;
  auto result = robotObstacles("<robot", robot, "~scene/robot", skipped);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().field, "~scene/robot/description");
  robot.all_links = false;
  robot.links = {"upper_arm", "elbow"};
  result = robotObstacles(kArm, robot, "~scene/robot", skipped);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().field, "~scene/robot/links[1]");  // no such link
  // ... answered with the URDF's links, in name order.
  EXPECT_NE(result.error().message().find(
                "the URDF has no link 'elbow'; its links: base_link, paddle, upper_arm"),
            std::string::npos)
      << result.error().message();
  robot.links = {"base_link"};
  result = robotObstacles(kArm, robot, "~scene/robot", skipped);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().field, "~scene/robot/links[0]");  // no <collision>
  EXPECT_NE(result.error().message().find("has no <collision>"), std::string::npos);
}

TEST(RobotObstacles, TheSceneKeyReadsTheUrdfItNames) {
  XmlRpc::XmlRpcValue scene;
  scene["robot"]["description"] = "arm_description";
  scene["robot"]["links"] = "all";
  scene["robot"]["material"] = "concrete";
  std::string asked;
  const UrdfSource source = [&](const std::string& parameter) -> core::Expected<std::string> {
    asked = parameter;
    return kArm;
  };
  std::vector<std::string> skipped;
  const auto loaded = loadScene(scene, "~scene", source, &skipped);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message();
  EXPECT_EQ(asked, "arm_description");
  EXPECT_EQ(loaded->obstacles.size(), 4u);
  EXPECT_TRUE(skipped.empty());
  // Without a source (no parameter server), and with a bad key, named errors.
  EXPECT_EQ(loadScene(scene, "~scene").error().field, "~scene/robot");
  scene["robot"]["padding"] = -1.0;
  EXPECT_EQ(loadScene(scene, "~scene", source).error().field, "~scene/robot/padding");
  scene["robot"]["padding"] = 0.0;
  scene["robot"]["links"] = "some";
  EXPECT_EQ(loadScene(scene, "~scene", source).error().field, "~scene/robot/links");
  scene["robot"]["links"] = "all";
  scene["robot"]["colour"] = "red";
  EXPECT_EQ(loadScene(scene, "~scene", source).error().field, "~scene/robot/colour");
  // A robot link's id taken by a body: ids are shared.
  XmlRpc::XmlRpcValue clash;
  clash["robot"]["material"] = "concrete";
  clash["bodies"][0]["id"] = "upper_arm";
  clash["bodies"][0]["mass"] = 1.0;
  clash["bodies"][0]["radius"] = 0.1;
  clash["bodies"][0]["material"] = "tennis_ball";
  const auto clashed = loadScene(clash, "~scene", source);
  ASSERT_FALSE(clashed.ok());
  EXPECT_NE(clashed.error().message().find("upper_arm"), std::string::npos);
}

// Issue 41, item 7: urdfdom drops every <collision> of a link for one number it cannot read (a
// `nan`, or `1e400` past the doubles: size, radius, origin, scale), with a log line only; the
// link would be missing as an obstacle. Each is refused at start-up, naming the link, the
// <collision>, the attribute and the word, whether the link is chosen by `all` or by name.
TEST(RobotObstacles, Issue41_Item7_ACollisionUrdfdomCannotReadIsRefusedNamingTheLink) {
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      {"<box size=\"nan 0.1 0.1\"/>", "", "<box> size=\"nan 0.1 0.1\": 'nan'"},
      {"<sphere radius=\"1e400\"/>", "", "<sphere> radius=\"1e400\": '1e400'"},
      {"<cylinder radius=\"0.1\" length=\"inf\"/>", "", "<cylinder> length=\"inf\": 'inf'"},
      {"<box size=\"0.1 0.1 0.1\"/>", "<origin xyz=\"0 nan 0\"/>",
       "<origin> xyz=\"0 nan 0\": 'nan'"},
      {"<box size=\"0.1 0.1 0.1\"/>", "<origin rpy=\"1e400 0 0\"/>",
       "<origin> rpy=\"1e400 0 0\": '1e400'"},
      {"<mesh filename=\"" + meshFile("grip.stl") + "\" scale=\"nan 1 1\"/>", "",
       "<mesh> scale=\"nan 1 1\": 'nan'"},
  };
  for (const auto& [geometry, origin, named] : cases) {
    const std::string urdf =
        "<robot name=\"r\"><link name=\"base\"/><link name=\"paddle\">"
        "<collision><geometry><sphere radius=\"0.1\"/></geometry></collision><collision>" +
        origin + "<geometry>" + geometry +
        "</geometry></collision></link><joint name=\"j\" type=\"fixed\"><parent "
        "link=\"base\"/><child link=\"paddle\"/></joint></robot>";
    for (const bool all : {true, false}) {
      RobotLinks robot;
      robot.material = "concrete";
      robot.all_links = all;
      if (!all) robot.links = {"paddle"};
      std::vector<std::string> warnings;
      const auto result = robotObstacles(urdf, robot, "~scene/robot", warnings);
      ASSERT_FALSE(result.ok()) << geometry << origin;
      EXPECT_EQ(result.error().field, "~scene/robot/description");
      EXPECT_EQ(result.error().reason, "link 'paddle' <collision> 1, " + named +
                                           " is not a finite number (urdfdom drops every "
                                           "<collision> of the link for it)");
    }
  }
  // A <collision> urdfdom drops for another reason (no <geometry>): the count tells.
  RobotLinks robot;
  robot.material = "concrete";
  std::vector<std::string> warnings;
  const auto result = robotObstacles(
      "<robot name=\"r\"><link name=\"paddle\"><collision><geometry><sphere radius=\"0.1\"/>"
      "</geometry></collision><collision/></link></robot>",
      robot, "~scene/robot", warnings);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().reason,
            "link 'paddle' has 2 <collision> element(s), of which urdfdom read 1 (its message is "
            "in the log above)");
}
}  // namespace
}  // namespace collision_response
