// The scene's material keys as the node reads them from the parameter server (XmlRpc values,
// built here as rosparam would from YAML). No master needed.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "collision_response/ros/scene_loader.h"

namespace collision_response {
namespace {

XmlRpc::XmlRpcValue sceneWithRubber() {
  XmlRpc::XmlRpcValue scene;
  scene["fixed_frame"] = "world";
  scene["restitution_combine"] = "max";
  scene["materials"]["rubber"]["restitution"] = 0.85;
  scene["materials"]["rubber"]["friction"] = 0.9;
  XmlRpc::XmlRpcValue pair;
  pair["materials"][0] = "rubber";
  pair["materials"][1] = "steel_ball_bearing";
  pair["restitution"] = 0.7;
  scene["pairs"][0] = pair;
  return scene;
}

std::string errorField(const XmlRpc::XmlRpcValue& scene) {
  const auto table = loadMaterials(scene, "/collision_response/scene");
  return table ? "" : table.error().field;
}

TEST(SceneLoader, MaterialsPairsAndRule) {
  const auto table = loadMaterials(sceneWithRubber(), "/collision_response/scene");
  ASSERT_TRUE(table.ok()) << table.error().message();
  EXPECT_EQ(table->combineRule(), core::CombineRule::kMax);
  EXPECT_EQ(*table->restitution("rubber", "steel_ball_bearing"), 0.7);
  EXPECT_EQ(*table->restitution("rubber", "concrete"), 0.85);
  EXPECT_EQ(*table->restitution("rubber", "tennis_ball"), 0.85);  // max(0.85, 0.712)
  EXPECT_EQ(*table->restitution("tennis_ball", "concrete"), 0.712);
}

TEST(SceneLoader, IntegersAreNumbers) {
  XmlRpc::XmlRpcValue scene = sceneWithRubber();
  scene["materials"]["rubber"]["restitution"] = 1;  // YAML "1"
  const auto table = loadMaterials(scene, "s");
  ASSERT_TRUE(table.ok()) << table.error().message();
  EXPECT_EQ(*table->restitution("rubber", "concrete"), 1.0);
}

TEST(SceneLoader, ErrorsNameTheKey) {
  XmlRpc::XmlRpcValue scene = sceneWithRubber();
  scene["colour"] = "red";
  EXPECT_EQ(errorField(scene), "/collision_response/scene/colour");

  scene = sceneWithRubber();
  scene["restitution_combine"] = "median";
  EXPECT_EQ(errorField(scene), "/collision_response/scene/restitution_combine");

  scene = sceneWithRubber();
  scene["materials"]["rubber"]["restitution"] = 1.2;
  EXPECT_EQ(errorField(scene), "/collision_response/scene/materials/rubber.restitution");

  scene = sceneWithRubber();
  scene["materials"]["rubber"]["hardness"] = 3.0;
  EXPECT_EQ(errorField(scene), "/collision_response/scene/materials/rubber/hardness");

  scene = sceneWithRubber();
  scene["materials"]["tennis_ball"]["restitution"] = 0.5;
  EXPECT_EQ(errorField(scene), "/collision_response/scene/materials/tennis_ball");

  scene = sceneWithRubber();
  scene["pairs"][0]["materials"][1] = "adamantium";
  EXPECT_EQ(errorField(scene), "/collision_response/scene/pairs[0].materials[1]");

  scene = sceneWithRubber();
  scene["pairs"][0]["restitution"] = "high";
  EXPECT_EQ(errorField(scene), "/collision_response/scene/pairs[0]/restitution");

  scene = sceneWithRubber();
  scene["pairs"] = "none";
  EXPECT_EQ(errorField(scene), "/collision_response/scene/pairs");
}

XmlRpc::XmlRpcValue fullScene() {
  XmlRpc::XmlRpcValue scene = sceneWithRubber();
  scene["detection"] = "discrete";
  scene["restitution_threshold"] = 0.25;
  scene["effects"].setSize(0);
  XmlRpc::XmlRpcValue ball;
  ball["id"] = "ball";
  ball["mass"] = 0.057;
  ball["radius"] = 0.033;
  ball["material"] = "tennis_ball";
  ball["topic"] = "/ball/state";
  ball["velocity"][0] = 1.0;
  ball["velocity"][1] = 0;
  ball["velocity"][2] = 0.0;
  scene["bodies"][0] = ball;
  XmlRpc::XmlRpcValue wall = ball;
  wall["id"] = "wall";
  wall["mass"] = std::numeric_limits<double>::infinity();
  scene["bodies"][1] = wall;
  XmlRpc::XmlRpcValue floor;
  floor["id"] = "floor";
  floor["type"] = "plane";
  floor["normal"][0] = 0.0;
  floor["normal"][1] = 0.0;
  floor["normal"][2] = 2.0;
  floor["material"] = "concrete";
  scene["obstacles"][0] = floor;
  XmlRpc::XmlRpcValue paddle;
  paddle["id"] = "paddle";
  paddle["type"] = "sphere";
  paddle["radius"] = 0.08;
  paddle["frame"] = "paddle_link";
  paddle["material"] = "wooden_ball";
  scene["obstacles"][1] = paddle;
  return scene;
}

std::string sceneErrorField(const XmlRpc::XmlRpcValue& scene) {
  const auto loaded = loadScene(scene, "~scene");
  return loaded ? "" : loaded.error().field;
}

TEST(SceneLoader, WholeScene) {
  const auto scene = loadScene(fullScene(), "~scene");
  ASSERT_TRUE(scene.ok()) << scene.error().message();
  EXPECT_EQ(scene->detection, core::Detection::kDiscrete);
  EXPECT_EQ(scene->restitution_threshold, 0.25);
  ASSERT_EQ(scene->bodies.size(), 2u);
  EXPECT_EQ(scene->bodies[0].topic, "/ball/state");
  EXPECT_EQ(scene->bodies[0].velocity, Eigen::Vector3d(1, 0, 0));
  EXPECT_TRUE(std::isinf(scene->bodies[1].mass));
  ASSERT_EQ(scene->obstacles.size(), 2u);
  EXPECT_EQ(scene->obstacles[0].shape, core::ObstacleShape::kPlane);
  EXPECT_EQ(scene->obstacles[1].frame, "paddle_link");
}

TEST(SceneLoader, SceneErrorsNameTheKey) {
  auto scene = fullScene();
  scene["detection"] = "psychic";
  EXPECT_EQ(sceneErrorField(scene), "~scene/detection");

  scene = fullScene();
  scene["effects"][0] = "magnetism";
  EXPECT_EQ(sceneErrorField(scene), "~scene/effects[0]");

  scene = fullScene();
  scene["effects"][0] = "gravity";
  scene["effects"][1] = "gravity";
  EXPECT_EQ(sceneErrorField(scene), "~scene/effects[1]");

  scene = fullScene();
  scene["bodies"][1]["id"] = "ball";
  EXPECT_EQ(sceneErrorField(scene), "~scene/bodies[1]/id");

  scene = fullScene();
  scene["obstacles"][1]["id"] = "ball";  // ids are shared by bodies and obstacles
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[1]/id");

  scene = fullScene();
  scene["bodies"][0]["material"] = "cheese";
  EXPECT_EQ(sceneErrorField(scene), "~scene/bodies[0]/material");

  scene = fullScene();
  scene["bodies"][0]["mass"] = -1.0;
  EXPECT_EQ(sceneErrorField(scene), "~scene/bodies[0]/mass");

  scene = fullScene();
  scene["bodies"][0]["colour"] = "red";
  EXPECT_EQ(sceneErrorField(scene), "~scene/bodies[0]/colour");

  scene = fullScene();
  scene["obstacles"][0]["type"] = "cylinder";
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[0]/type");

  scene = fullScene();
  scene["obstacles"][0]["normal"][2] = 0.0;
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[0]/normal");

  scene = fullScene();
  scene["obstacles"][0]["radius"] = 1.0;  // not a plane's key
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[0]/radius");

  scene = fullScene();
  scene["restitution_threshold"] = -1.0;
  EXPECT_EQ(sceneErrorField(scene), "~scene/restitution_threshold");

  // A concrete ball on a concrete floor: that pair was never measured.
  scene = fullScene();
  scene["bodies"][0]["material"] = "concrete";
  EXPECT_EQ(sceneErrorField(scene), "~scene/bodies[0]/material");
}

}  // namespace
}  // namespace collision_response
