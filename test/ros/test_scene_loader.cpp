// The scene's material keys as the node reads them from the parameter server (XmlRpc values,
// built here as rosparam would from YAML). No master needed.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace collision_response
