// The scene file as the node reads it from the parameter server (XmlRpc values, built here as
// rosparam would from YAML), and the README's tables of keys against the loader's own. No
// master needed.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "collision_response/core/triangle_mesh.h"
#include "collision_response/ros/scene_loader.h"
#include "collision_response/ros/scene_player.h"
#include "readme_tables.h"

namespace collision_response {
namespace {

XmlRpc::XmlRpcValue list3(double x, double y, double z) {
  XmlRpc::XmlRpcValue value;
  value[0] = x;
  value[1] = y;
  value[2] = z;
  return value;
}

/// A test mesh (test/meshes) as a file:// address.
std::string testMesh(const std::string& name) {
  return "file://" + std::string(COLLISION_RESPONSE_TEST_MESHES) + "/" + name;
}

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
  const auto loaded = loadScene(scene, "/collision_response/scene");
  return loaded ? "" : loaded.error().field;
}

TEST(SceneLoader, MaterialsPairsAndRule) {
  const auto scene = loadScene(sceneWithRubber(), "/collision_response/scene");
  ASSERT_TRUE(scene.ok()) << scene.error().message();
  const core::MaterialTable* table = &scene->materials;
  EXPECT_EQ(table->combineRule(), core::CombineRule::kMax);
  EXPECT_EQ(*table->restitution("rubber", "steel_ball_bearing"), 0.7);
  EXPECT_EQ(*table->restitution("rubber", "concrete"), 0.85);
  EXPECT_EQ(*table->restitution("rubber", "tennis_ball"), 0.85);  // max(0.85, 0.712)
  EXPECT_EQ(*table->restitution("tennis_ball", "concrete"), 0.712);
}

TEST(SceneLoader, IntegersAreNumbers) {
  XmlRpc::XmlRpcValue scene = sceneWithRubber();
  scene["materials"]["rubber"]["restitution"] = 1;  // YAML "1"
  const auto loaded = loadScene(scene, "s");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message();
  EXPECT_EQ(*loaded->materials.restitution("rubber", "concrete"), 1.0);
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
  EXPECT_EQ(errorField(scene), "/collision_response/scene/materials/rubber/restitution");

  scene = sceneWithRubber();
  scene["materials"]["rubber"]["hardness"] = 3.0;
  EXPECT_EQ(errorField(scene), "/collision_response/scene/materials/rubber/hardness");

  scene = sceneWithRubber();
  scene["materials"]["tennis_ball"]["restitution"] = 0.5;
  EXPECT_EQ(errorField(scene), "/collision_response/scene/materials/tennis_ball");

  scene = sceneWithRubber();
  scene["pairs"][0]["materials"][1] = "adamantium";
  EXPECT_EQ(errorField(scene), "/collision_response/scene/pairs[0]/materials[1]");

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

// The air (drag and magnus effects): the scene's density and flight tolerance, each body's
// coefficients, their defaults, and every bad value named.
TEST(SceneLoader, AirKeys) {
  auto tree = fullScene();
  tree["effects"][0] = "drag";
  const auto defaults = loadScene(tree, "~scene");
  ASSERT_TRUE(defaults.ok()) << defaults.error().message();
  EXPECT_TRUE(defaults->effects.drag);
  EXPECT_EQ(defaults->air_density, 1.204);
  EXPECT_EQ(defaults->flight_integration_tolerance, 1e-9);
  EXPECT_EQ(defaults->bodies[0].drag_coefficient, 0.47);
  EXPECT_EQ(defaults->bodies[0].lift_coefficient, 0.2);

  tree["effects"][1] = "spin";
  tree["effects"][2] = "magnus";
  tree["air_density"] = 1.2;
  tree["flight_integration_tolerance"] = 1e-12;
  tree["bodies"][0]["drag_coefficient"] = 0.5;
  tree["bodies"][0]["lift_coefficient"] = 0;
  const auto scene = loadScene(tree, "~scene");
  ASSERT_TRUE(scene.ok()) << scene.error().message();
  EXPECT_TRUE(scene->effects.magnus);
  EXPECT_EQ(scene->air_density, 1.2);
  EXPECT_EQ(scene->flight_integration_tolerance, 1e-12);
  EXPECT_EQ(scene->bodies[0].drag_coefficient, 0.5);
  EXPECT_EQ(scene->bodies[0].lift_coefficient, 0.0);

  auto bad = tree;
  bad["air_density"] = -1.0;
  EXPECT_EQ(sceneErrorField(bad), "~scene/air_density");
  bad = tree;
  bad["flight_integration_tolerance"] = 0.1;
  EXPECT_EQ(sceneErrorField(bad), "~scene/flight_integration_tolerance");
  bad = tree;
  bad["bodies"][0]["drag_coefficient"] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(sceneErrorField(bad), "~scene/bodies[0]/drag_coefficient");
  bad = tree;
  bad["bodies"][1]["lift_coefficient"] = -0.2;
  EXPECT_EQ(sceneErrorField(bad), "~scene/bodies[1]/lift_coefficient");
  bad = tree;
  bad["bodies"][0]["drag_coefficient"] = "smooth";
  EXPECT_EQ(sceneErrorField(bad), "~scene/bodies[0]/drag_coefficient");
  // Magnus needs the spin that makes it.
  bad = tree;
  bad["effects"][1] = "gravity";
  EXPECT_EQ(sceneErrorField(bad), "~scene/effects");
  // Unknown effect names list the five.
  bad = tree;
  bad["effects"][2] = "wind";
  const auto unknown = loadScene(bad, "~scene");
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().field, "~scene/effects[2]");
  EXPECT_NE(unknown.error().reason.find("drag, magnus"), std::string::npos);
}

// Issue 27, item 2: a body's initial spin (a draw shot, topspin) is a key of its own, in rad/s in
// the fixed frame, finite, and only with the spin effect (without it nothing would spin).
TEST(SceneLoader, BodyAngularVelocity) {
  auto tree = fullScene();
  tree["effects"][0] = "spin";
  tree["bodies"][0]["angular_velocity"][0] = 0.0;
  tree["bodies"][0]["angular_velocity"][1] = -30.5;
  tree["bodies"][0]["angular_velocity"][2] = 2;
  const auto scene = loadScene(tree, "~scene");
  ASSERT_TRUE(scene.ok()) << scene.error().message();
  EXPECT_EQ(scene->bodies[0].angular_velocity, Eigen::Vector3d(0, -30.5, 2));
  EXPECT_EQ(scene->bodies[1].angular_velocity, Eigen::Vector3d::Zero());  // the default

  auto bad = tree;
  bad["bodies"][0]["angular_velocity"][1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(sceneErrorField(bad).rfind("~scene/bodies[0]/angular_velocity", 0), 0u);
  bad = tree;
  bad["bodies"][0]["angular_velocity"][1] = "fast";
  EXPECT_EQ(sceneErrorField(bad), "~scene/bodies[0]/angular_velocity[1]");
  bad = tree;
  XmlRpc::XmlRpcValue two;
  two[0] = 1.0;
  two[1] = 2.0;
  bad["bodies"][0]["angular_velocity"] = two;
  EXPECT_EQ(sceneErrorField(bad), "~scene/bodies[0]/angular_velocity");

  // Without the spin effect a nonzero spin would be ignored: named, not dropped silently.
  bad = tree;
  bad["effects"][0] = "gravity";
  const auto ignored = loadScene(bad, "~scene");
  ASSERT_FALSE(ignored.ok());
  EXPECT_EQ(ignored.error().field, "~scene/bodies[0]/angular_velocity");
  EXPECT_NE(ignored.error().reason.find("spin"), std::string::npos) << ignored.error().reason;
  // A zero spin says nothing the model would ignore.
  bad["bodies"][0]["angular_velocity"][1] = 0.0;
  bad["bodies"][0]["angular_velocity"][2] = 0.0;
  EXPECT_TRUE(loadScene(bad, "~scene").ok());
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
  scene["obstacles"][0]["type"] = "torus";
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[0]/type");

  // A box, cylinder or capsule: its sizes, its orientation given once and not zero.
  const auto finite = [](const std::string& type) {
    XmlRpc::XmlRpcValue with = fullScene(), shape;
    shape["id"] = "table";
    shape["type"] = type;
    shape["material"] = "concrete";
    if (type == "box") {
      for (int i = 0; i < 3; ++i) shape["size"][i] = 0.5;
    } else {
      shape["radius"] = 0.1;
      shape["length"] = 0.4;
    }
    with["obstacles"][2] = shape;
    return with;
  };
  EXPECT_EQ(sceneErrorField(finite("box")), "");  // the base loads
  scene = finite("box");
  scene["obstacles"][2]["size"][1] = 0.0;  // a box of zero size has no inside
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[2]/size");
  scene = finite("box");
  scene["obstacles"][2]["size"] = 0.5;  // not a list
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[2]/size");
  for (const std::string type : {"cylinder", "capsule"}) {
    scene = finite(type);
    scene["obstacles"][2]["radius"] = -0.1;
    EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[2]/radius") << type;
    scene = finite(type);
    scene["obstacles"][2]["length"] = -1.0;
    EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[2]/length") << type;
  }
  scene = finite("cylinder");
  scene["obstacles"][2]["length"] = 0.0;  // a cylinder of no length has no inside
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[2]/length");
  scene = finite("capsule");
  scene["obstacles"][2]["length"] = 0.0;  // a capsule of no length is a sphere
  EXPECT_EQ(sceneErrorField(scene), "");
  scene = finite("box");
  for (int i = 0; i < 4; ++i) scene["obstacles"][2]["orientation"][i] = 0.0;
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[2]/orientation");
  scene = finite("box");
  for (int i = 0; i < 3; ++i) scene["obstacles"][2]["orientation"][i] = 1.0;
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[2]/orientation");  // three numbers
  scene = finite("box");
  for (int i = 0; i < 4; ++i) scene["obstacles"][2]["orientation"][i] = i == 3 ? 1.0 : 0.0;
  for (int i = 0; i < 3; ++i) scene["obstacles"][2]["rpy"][i] = 0.0;
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[2]/rpy");  // given twice
  scene = finite("box");
  scene["obstacles"][2]["normal"] = 1.0;  // a plane's key
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[2]/normal");

  // A mesh: its resource required, loaded (or named with the address and the reason), its scale
  // positive.
  const auto mesh = [&](const std::string& resource) {
    XmlRpc::XmlRpcValue with = finite("box");
    with["obstacles"][2] = XmlRpc::XmlRpcValue();
    with["obstacles"][2]["id"] = "grip";
    with["obstacles"][2]["type"] = "mesh";
    with["obstacles"][2]["material"] = "concrete";
    if (!resource.empty()) with["obstacles"][2]["resource"] = resource;
    return with;
  };
  EXPECT_EQ(sceneErrorField(mesh(testMesh("grip.stl"))), "");            // the base loads
  EXPECT_EQ(sceneErrorField(mesh("")), "~scene/obstacles[2]/resource");  // required
  for (const std::string& bad : {testMesh("no_such.stl"), testMesh("not_a_mesh.stl"),
                                 std::string("package://no_such_package/grip.stl"),
                                 std::string("http://example.com/grip.stl")}) {
    const auto loaded = loadScene(mesh(bad), "~scene");
    ASSERT_FALSE(loaded.ok()) << bad;
    EXPECT_EQ(loaded.error().field, "~scene/obstacles[2]/resource") << bad;
    EXPECT_NE(loaded.error().reason.find("'" + bad + "'"), std::string::npos)
        << loaded.error().reason;
  }
  scene = mesh(testMesh("grip.stl"));
  scene["obstacles"][2]["scale"] = list3(1, 0, 1);
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[2]/scale[1]");
  scene["obstacles"][2]["scale"] = list3(1, 1, -2);
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[2]/scale[2]");
  scene = mesh(testMesh("grip.stl"));
  scene["obstacles"][2]["size"] = list3(1, 1, 1);  // a box's key
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[2]/size");
  // Zero-area triangles are left out, and said.
  std::vector<std::string> warnings;
  const auto with_zero_area =
      loadScene(mesh(testMesh("zero_area.stl")), "~scene", nullptr, &warnings);
  ASSERT_TRUE(with_zero_area.ok()) << with_zero_area.error().message();
  const auto warned = [&](const std::string& text) {
    return std::any_of(warnings.begin(), warnings.end(), [&](const std::string& warning) {
      return warning.find(text) != std::string::npos;
    });
  };
  EXPECT_TRUE(warned("~scene/obstacles[2]/resource '" + testMesh("zero_area.stl") +
                     "': 1 triangle(s) of zero area left out"));
  // The base scene's balls (r = 0.033) are at the origin: inside the floor z = 0, and inside the
  // mesh there (0.03125 from its x faces); the paddle is on a tf frame, not placed yet.
  EXPECT_TRUE(warned("body 'ball' at [0, 0, 0] starts 0.033 m inside obstacle 'floor'"));
  EXPECT_TRUE(warned("body 'wall' at [0, 0, 0] starts 0.033 m inside obstacle 'floor'"));
  EXPECT_TRUE(warned("body 'ball' at [0, 0, 0] starts 0.06425 m inside obstacle 'grip'"));
  EXPECT_EQ(warnings.size(), 5u);

  scene = fullScene();
  scene["obstacles"][0]["normal"][2] = 0.0;
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[0]/normal");

  scene = fullScene();
  scene["obstacles"][0]["radius"] = 1.0;  // not a plane's key
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[0]/radius");

  scene = fullScene();
  scene["restitution_threshold"] = -1.0;
  EXPECT_EQ(sceneErrorField(scene), "~scene/restitution_threshold");

  // The integrator's tolerance: an error per step of 1 cm would open contacts; 0 cannot be met.
  for (const double tolerance : {1e-2, 0.0, 1e-300}) {
    scene = fullScene();
    scene["contact_integration_tolerance"] = tolerance;
    EXPECT_EQ(sceneErrorField(scene), "~scene/contact_integration_tolerance") << tolerance;
  }

  // Stepped clusters: a count of bodies is an integer >= 0 (YAML `32.0` and `true` are not);
  // the sub-step is in [1e-4, 1] s (0 would never advance; 2 s would leave a pile unwatched).
  const std::vector<XmlRpc::XmlRpcValue> counts = {
      XmlRpc::XmlRpcValue(-1), XmlRpc::XmlRpcValue(32.0), XmlRpc::XmlRpcValue(2.5),
      XmlRpc::XmlRpcValue(true), XmlRpc::XmlRpcValue("32")};
  for (std::size_t i = 0; i < counts.size(); ++i) {
    scene = fullScene();
    scene["stepped_cluster_min_bodies"] = counts[i];
    EXPECT_EQ(sceneErrorField(scene), "~scene/stepped_cluster_min_bodies") << "counts[" << i << "]";
    scene = fullScene();
    scene["exact_work_budget"] = counts[i];
    EXPECT_EQ(sceneErrorField(scene), "~scene/exact_work_budget") << "counts[" << i << "]";
  }
  for (const double time_step : {0.0, -0.01, 9e-5, 1.5, std::numeric_limits<double>::quiet_NaN(),
                                 std::numeric_limits<double>::infinity()}) {
    scene = fullScene();
    scene["stepped_cluster_time_step"] = time_step;
    EXPECT_EQ(sceneErrorField(scene), "~scene/stepped_cluster_time_step") << time_step;
  }
  scene = fullScene();
  scene["stepped_cluster_time_step"] = "fast";
  EXPECT_EQ(sceneErrorField(scene), "~scene/stepped_cluster_time_step");

  // A concrete ball on a concrete floor: that pair was never measured.
  scene = fullScene();
  scene["bodies"][0]["material"] = "concrete";
  EXPECT_EQ(sceneErrorField(scene), "~scene/bodies[0]/material");
}

// Stepped clusters' keys: the ends of their ranges load, and their absence leaves the
// documented defaults (README, "Scene file": 32 bodies, 0.01 s, a budget of 1024).
TEST(SceneLoader, SteppedClusterKeysLoadAtTheEndsOfTheirRanges) {
  const auto defaults = loadScene(fullScene(), "~scene");
  ASSERT_TRUE(defaults.ok()) << defaults.error().message();
  EXPECT_EQ(defaults->stepped_cluster_min_bodies, 32);
  EXPECT_EQ(defaults->stepped_cluster_time_step, 0.01);
  EXPECT_EQ(defaults->exact_work_budget, 1024);
  // The low ends: 0 (never) and 1e-4 s.
  auto scene = fullScene();
  scene["stepped_cluster_min_bodies"] = 0;
  scene["stepped_cluster_time_step"] = 1e-4;
  auto loaded = loadScene(scene, "~scene");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message();
  EXPECT_EQ(loaded->stepped_cluster_min_bodies, 0);
  EXPECT_EQ(loaded->stepped_cluster_time_step, 1e-4);
  // The high end, 1 s, written as the integer YAML makes of `1`; any count of bodies.
  scene = fullScene();
  scene["stepped_cluster_min_bodies"] = 100000;
  scene["stepped_cluster_time_step"] = 1;
  loaded = loadScene(scene, "~scene");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message();
  EXPECT_EQ(loaded->stepped_cluster_min_bodies, 100000);
  EXPECT_EQ(loaded->stepped_cluster_time_step, 1.0);
  // The message says what is wrong, with the value.
  scene = fullScene();
  scene["stepped_cluster_min_bodies"] = -3;
  loaded = loadScene(scene, "~scene");
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.error().message(),
            "~scene/stepped_cluster_min_bodies: must be an integer >= 0, got -3");
  scene = fullScene();
  scene["stepped_cluster_time_step"] = 2.0;
  loaded = loadScene(scene, "~scene");
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.error().message(),
            "~scene/stepped_cluster_time_step: must be in [1e-4, 1] s, got 2");
}

// --- The README's keys against the loader's tables ----------------------------------------------

/// A documented key split into its entity (as sceneKeys() names it) and its name.
std::pair<std::string, std::string> entityAndKey(const std::string& documented) {
  const std::size_t dot = documented.rfind('.');
  if (dot == std::string::npos) return {"scene", documented};
  return {documented.substr(0, dot), documented.substr(dot + 1)};
}

/// A valid value for every key a scene may have, by entity and key: the test of "every
/// documented key loads" needs one for each documented key (a key without one fails it).
std::map<std::string, std::map<std::string, XmlRpc::XmlRpcValue>> examples() {
  std::map<std::string, std::map<std::string, XmlRpc::XmlRpcValue>> values;
  XmlRpc::XmlRpcValue effects;
  effects[0] = "gravity";
  effects[1] = "spin";  // bodies[].angular_velocity needs it
  values["scene"] = {{"fixed_frame", "world"},
                     {"detection", "discrete"},
                     {"effects", effects},
                     {"gravity", list3(0, 0, -9.8)},
                     {"restitution_threshold", 0.25},
                     {"contact_integration_tolerance", 1e-6},
                     {"air_density", 1.1},
                     {"flight_integration_tolerance", 1e-7},
                     {"stepped_cluster_min_bodies", 40},
                     {"stepped_cluster_time_step", 0.005},
                     {"exact_work_budget", 300},
                     {"max_mesh_bytes", 16777216},
                     {"restitution_combine", "max"}};
  values["materials.<name>"] = {{"restitution", 0.85}, {"friction", 0.9}};
  XmlRpc::XmlRpcValue pair;
  pair[0] = "rubber";
  pair[1] = "steel_ball_bearing";
  values["pairs[]"] = {{"materials", pair}, {"restitution", 0.7}, {"friction", 0.4}};
  values["bodies[]"] = {{"id", "ball"},
                        {"mass", 0.057},
                        {"radius", 0.033},
                        {"material", "tennis_ball"},
                        {"topic", "/ball/state"},
                        {"position", list3(1, 2, 3)},
                        {"velocity", list3(4, 5, 6)},
                        {"angular_velocity", list3(7, 8, 9)},
                        {"inertia", "hollow"},
                        {"drag_coefficient", 0.5},
                        {"lift_coefficient", 0.25},
                        {"shape", "sphere"},
                        {"rpy", list3(M_PI / 2, 0, 0)}};
  XmlRpc::XmlRpcValue quarter_turn;  // about z: [0, 0, 2, 2], normalised on load
  quarter_turn[0] = 0.0;
  quarter_turn[1] = 0.0;
  quarter_turn[2] = 2.0;
  quarter_turn[3] = 2.0;
  values["bodies[]"]["orientation"] = quarter_turn;
  XmlRpc::XmlRpcValue tensor;
  tensor["ixx"] = 1e-3;
  tensor["iyy"] = 2e-3;
  tensor["izz"] = 2.5e-3;
  tensor["ixy"] = 1e-4;
  for (const char* table : {"bodies[] box", "bodies[] cylinder, capsule", "bodies[] mesh"}) {
    values[table] = values["bodies[]"];
    values[table].erase("radius");
    values[table]["inertia"] = "solid";
  }
  values["bodies[] box"]["shape"] = "box";
  values["bodies[] box"]["size"] = list3(0.1048, 0.1048, 0.1048);
  values["bodies[] box"]["inertia"] = tensor;
  values["bodies[] cylinder, capsule"]["shape"] = "cylinder";
  values["bodies[] cylinder, capsule"]["radius"] = 0.033;
  values["bodies[] cylinder, capsule"]["length"] = 0.12;
  values["bodies[] mesh"]["shape"] = "mesh";
  values["bodies[] mesh"]["resource"] = testMesh("grip.stl");
  values["bodies[] mesh"]["scale"] = list3(2, 1, 1);
  values["bodies[] sphere"] = values["bodies[]"];
  values["obstacles[] plane"] = {
      {"id", "floor"},         {"type", "plane"},          {"material", "concrete"},
      {"frame", "floor_link"}, {"normal", list3(0, 0, 2)}, {"offset", 0.5}};
  values["obstacles[] sphere"] = {{"id", "post"},           {"type", "sphere"},
                                  {"material", "concrete"}, {"frame", "post_link"},
                                  {"radius", 0.1},          {"position", list3(1, 1, 1)}};
  XmlRpc::XmlRpcValue quaternion;
  quaternion[0] = 0.0;
  quaternion[1] = 0.0;
  quaternion[2] = 0.0;
  quaternion[3] = 2.0;  // normalised on load
  values["obstacles[] box"] = {{"id", "table"},
                               {"type", "box"},
                               {"material", "concrete"},
                               {"frame", "table_link"},
                               {"position", list3(0, 0, 0.4)},
                               {"orientation", quaternion},
                               {"size", list3(1.5, 0.8, 0.05)}};
  values["obstacles[] cylinder, capsule"] = {{"id", "paddle"},
                                             {"type", "cylinder"},
                                             {"material", "rubber"},
                                             {"frame", "paddle_link"},
                                             {"position", list3(0, 0, 0.1)},
                                             {"rpy", list3(M_PI / 2, 0, 0)},
                                             {"radius", 0.08},
                                             {"length", 0.01}};
  XmlRpc::XmlRpcValue turned;  // a quarter turn about z: [0, 0, sin(pi/4), cos(pi/4)]
  turned[0] = 0.0;
  turned[1] = 0.0;
  turned[2] = std::sqrt(0.5);
  turned[3] = std::sqrt(0.5);
  values["obstacles[] mesh"] = {{"id", "grip"},
                                {"type", "mesh"},
                                {"material", "rubber"},
                                {"frame", "grip_link"},
                                {"position", list3(0, 0.2, 0)},
                                {"orientation", turned},
                                {"resource", testMesh("grip.stl")},
                                {"scale", list3(2, 1, 1)}};
  values["player.frames[]"] = {{"frame", "paddle_link"},
                               {"parent", "world"},
                               {"position", list3(1, 0, 0)},
                               {"velocity", list3(-0.5, 0, 0)}};
  return values;
}

/// The containers: documented as keys of the scene, filled by the entries of their entity.
const std::set<std::string> kContainers = {"materials", "pairs", "bodies", "obstacles", "robot"};

TEST(SceneKeys, EveryDocumentedKeyIsReadAndEveryReadKeyDocumented) {
  const auto tables = testing::readmeTables("### Scene file");
  ASSERT_FALSE(tables.empty()) << "README.md: no table under '### Scene file'";
  const auto read = sceneKeys();
  std::set<std::pair<std::string, std::string>> documented;
  for (const auto& row : tables.front()) {
    ASSERT_FALSE(row.empty()) << "a row of the scene key table names no key";
    auto [entity, key] = entityAndKey(row.front());
    if (entity == "obstacles[]" || entity == "bodies[]") {
      // One row for a key of every obstacle type (body shape) that has it.
      bool in_any = false;
      for (const auto& [table, keys] : read) {
        if (table.rfind(entity + " ", 0) != 0) continue;
        if (std::find(keys.begin(), keys.end(), key) != keys.end()) {
          documented.emplace(table, key);
          in_any = true;
        }
      }
      EXPECT_TRUE(in_any) << row.front() << " is documented but not read";
      continue;
    }
    documented.emplace(entity, key);
    if (entity == "player.frames[]") continue;  // the scene player's: below
    ASSERT_EQ(read.count(entity), 1u) << row.front() << ": no such entity in the loader";
    const auto& keys = read.at(entity);
    EXPECT_NE(std::find(keys.begin(), keys.end(), key), keys.end())
        << row.front() << " is documented but the loader does not read it";
  }
  for (const auto& [entity, keys] : read) {
    for (const std::string& key : keys) {
      EXPECT_EQ(documented.count({entity, key}), 1u)
          << entity << " key '" << key << "' is read but not documented in README.md";
    }
  }
}

TEST(SceneKeys, EveryDocumentedKeyLoadsWithItsValue) {
  const auto tables = testing::readmeTables("### Scene file");
  ASSERT_FALSE(tables.empty());
  const auto values = examples();
  const auto read = sceneKeys();
  XmlRpc::XmlRpcValue scene, body, material, pair, frame;
  std::map<std::string, XmlRpc::XmlRpcValue> obstacles;      // by the loader's table
  std::map<std::string, XmlRpc::XmlRpcValue> shaped_bodies;  // by the loader's table
  const auto put = [&](XmlRpc::XmlRpcValue& target, const std::string& entity,
                       const std::string& key) {
    const auto found = values.find(entity);
    ASSERT_TRUE(found != values.end() && found->second.count(key))
        << "no example value for the documented key " << entity << " " << key;
    target[key] = found->second.at(key);
  };
  for (const auto& row : tables.front()) {
    const auto [entity, key] = entityAndKey(row.front());
    if (entity == "scene" && kContainers.count(key)) continue;
    if (entity == "scene") put(scene, entity, key);
    if (entity == "bodies[]") {
      // The ball takes the sphere's keys; each other shape's table is read on its own below.
      for (const auto& [table, keys] : read) {
        if (table.rfind("bodies[] ", 0) != 0) continue;
        if (std::find(keys.begin(), keys.end(), key) == keys.end()) continue;
        // An orientation is given one way or the other: the cylinder's as roll, pitch and yaw,
        // the others' as a quaternion.
        if ((table == "bodies[] cylinder, capsule") == (key == "orientation") &&
            (key == "orientation" || key == "rpy")) {
          continue;
        }
        put(table == "bodies[] sphere" ? body : shaped_bodies[table], table, key);
      }
    }
    if (entity == "materials.<name>") put(material, entity, key);
    if (entity == "pairs[]") put(pair, entity, key);
    if (entity == "player.frames[]") put(frame, entity, key);
    if (entity == "obstacles[]") {
      for (const auto& [table, keys] : read) {
        if (table.rfind("obstacles[] ", 0) != 0) continue;
        if (std::find(keys.begin(), keys.end(), key) == keys.end()) continue;
        // An orientation is given one way or the other: the box's as a quaternion, the
        // cylinder's as roll, pitch and yaw.
        if (((table == "obstacles[] box" || table == "obstacles[] mesh") && key == "rpy") ||
            (table == "obstacles[] cylinder, capsule" && key == "orientation")) {
          continue;
        }
        put(obstacles[table], table, key);
      }
    }
  }
  const XmlRpc::XmlRpcValue& plane = obstacles["obstacles[] plane"];
  const XmlRpc::XmlRpcValue& sphere = obstacles["obstacles[] sphere"];
  scene["materials"]["rubber"] = material;
  scene["pairs"][0] = pair;
  scene["bodies"][0] = body;
  scene["obstacles"][0] = plane;
  scene["obstacles"][1] = sphere;
  scene["obstacles"][2] = obstacles["obstacles[] box"];
  scene["obstacles"][3] = obstacles["obstacles[] cylinder, capsule"];
  scene["obstacles"][4] = obstacles["obstacles[] mesh"];
  const auto loaded = loadScene(scene, "~scene");
  ASSERT_TRUE(loaded.ok()) << "a documented key is refused: " << loaded.error().message();
  // Each value arrived where it belongs.
  EXPECT_EQ(loaded->detection, core::Detection::kDiscrete);
  EXPECT_TRUE(loaded->effects.gravity);
  EXPECT_EQ(loaded->gravity, Eigen::Vector3d(0, 0, -9.8));
  EXPECT_EQ(loaded->restitution_threshold, 0.25);
  EXPECT_EQ(loaded->contact_integration_tolerance, 1e-6);
  EXPECT_EQ(loaded->air_density, 1.1);
  EXPECT_EQ(loaded->flight_integration_tolerance, 1e-7);
  EXPECT_EQ(loaded->stepped_cluster_min_bodies, 40);
  EXPECT_EQ(loaded->stepped_cluster_time_step, 0.005);
  EXPECT_EQ(loaded->exact_work_budget, 300);
  EXPECT_EQ(loaded->materials.combineRule(), core::CombineRule::kMax);
  EXPECT_EQ(*loaded->materials.restitution("rubber", "concrete"), 0.85);
  EXPECT_EQ(*loaded->materials.friction("rubber", "concrete"), 0.9);
  EXPECT_EQ(*loaded->materials.restitution("rubber", "steel_ball_bearing"), 0.7);
  EXPECT_EQ(*loaded->materials.friction("rubber", "steel_ball_bearing"), 0.4);
  ASSERT_EQ(loaded->bodies.size(), 1u);
  const core::BodySpec& ball = loaded->bodies[0];
  EXPECT_EQ(ball.id, "ball");
  EXPECT_EQ(ball.mass, 0.057);
  EXPECT_EQ(ball.radius, 0.033);
  EXPECT_EQ(ball.material, "tennis_ball");
  EXPECT_EQ(ball.topic, "/ball/state");
  EXPECT_EQ(ball.position, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(ball.velocity, Eigen::Vector3d(4, 5, 6));
  EXPECT_EQ(ball.angular_velocity, Eigen::Vector3d(7, 8, 9));
  EXPECT_EQ(ball.inertia, core::Inertia::kHollow);  // once refused as an unknown key
  EXPECT_EQ(ball.drag_coefficient, 0.5);
  EXPECT_EQ(ball.lift_coefficient, 0.25);
  EXPECT_EQ(ball.shape, core::BodyShape::kSphere);
  EXPECT_NEAR((ball.orientation * Eigen::Vector3d::UnitX() - Eigen::Vector3d(0, 1, 0)).norm(), 0,
              1e-15);  // the quarter turn about z, normalised
  // The other shapes' keys, each read into its body (a scene with one is refused, "not yet").
  core::BodySpec block, can, grip_body;
  ASSERT_TRUE(readBody(shaped_bodies["bodies[] box"], "b", block).ok());
  EXPECT_EQ(block.shape, core::BodyShape::kBox);
  EXPECT_EQ(block.size, Eigen::Vector3d(0.1048, 0.1048, 0.1048));
  ASSERT_TRUE(block.inertia_tensor.has_value());
  EXPECT_EQ(block.inertia_tensor->ixx, 1e-3);
  EXPECT_EQ(block.inertia_tensor->iyy, 2e-3);
  EXPECT_EQ(block.inertia_tensor->izz, 2.5e-3);
  EXPECT_EQ(block.inertia_tensor->ixy, 1e-4);
  EXPECT_EQ(block.inertia_tensor->ixz, 0.0);
  ASSERT_TRUE(readBody(shaped_bodies["bodies[] cylinder, capsule"], "b", can).ok());
  EXPECT_EQ(can.shape, core::BodyShape::kCylinder);
  EXPECT_EQ(can.radius, 0.033);
  EXPECT_EQ(can.length, 0.12);
  // Roll pi/2 about x: the can's axis z lies along -y.
  EXPECT_NEAR((can.orientation * Eigen::Vector3d::UnitZ() - Eigen::Vector3d(0, -1, 0)).norm(), 0,
              1e-15);
  ASSERT_TRUE(readBody(shaped_bodies["bodies[] mesh"], "b", grip_body).ok());
  EXPECT_EQ(grip_body.shape, core::BodyShape::kMesh);
  EXPECT_EQ(grip_body.resource, testMesh("grip.stl"));
  EXPECT_EQ(grip_body.scale, Eigen::Vector3d(2, 1, 1));
  ASSERT_EQ(loaded->obstacles.size(), 5u);
  EXPECT_EQ(loaded->obstacles[0].frame, "floor_link");
  EXPECT_EQ(loaded->obstacles[0].normal, Eigen::Vector3d(0, 0, 1));  // scaled to unit length
  EXPECT_EQ(loaded->obstacles[0].offset, 0.5);
  EXPECT_EQ(loaded->obstacles[1].shape, core::ObstacleShape::kSphere);
  EXPECT_EQ(loaded->obstacles[1].radius, 0.1);
  EXPECT_EQ(loaded->obstacles[1].position, Eigen::Vector3d(1, 1, 1));
  const core::ObstacleSpec& table = loaded->obstacles[2];
  EXPECT_EQ(table.shape, core::ObstacleShape::kBox);
  EXPECT_EQ(table.size, Eigen::Vector3d(1.5, 0.8, 0.05));
  EXPECT_EQ(table.position, Eigen::Vector3d(0, 0, 0.4));
  EXPECT_EQ(table.orientation.coeffs(), Eigen::Vector4d(0, 0, 0, 1));  // [x, y, z, w], unit
  const core::ObstacleSpec& paddle = loaded->obstacles[3];
  EXPECT_EQ(paddle.shape, core::ObstacleShape::kCylinder);
  EXPECT_EQ(paddle.radius, 0.08);
  EXPECT_EQ(paddle.length, 0.01);
  // Roll pi/2 about x: the paddle's axis z lies along -y.
  EXPECT_NEAR((paddle.orientation * Eigen::Vector3d::UnitZ() - Eigen::Vector3d(0, -1, 0)).norm(), 0,
              1e-15);
  const core::ObstacleSpec& grip = loaded->obstacles[4];
  EXPECT_EQ(grip.shape, core::ObstacleShape::kMesh);
  EXPECT_EQ(grip.frame, "grip_link");
  EXPECT_EQ(grip.resource, testMesh("grip.stl"));
  EXPECT_EQ(grip.scale, Eigen::Vector3d(2, 1, 1));
  EXPECT_EQ(grip.position, Eigen::Vector3d(0, 0.2, 0));
  EXPECT_NEAR((grip.orientation * Eigen::Vector3d::UnitX() - Eigen::Vector3d(0, 1, 0)).norm(), 0,
              1e-15);
  ASSERT_TRUE(grip.mesh);
  EXPECT_EQ(grip.mesh->triangles().size(), 12u);  // its x scaled: the corners at x = +-0.0625
  EXPECT_EQ(grip.mesh->vertices()[grip.mesh->triangles()[0][0]].cwiseAbs(),
            Eigen::Vector3d(0.0625, 0.0625, 0.046875));

  // The scene player's part of the file.
  XmlRpc::XmlRpcValue tree;
  tree["scene"] = scene;
  tree["player"]["frames"][0] = frame;
  const auto player = ScenePlayerParams::load(tree, "/scene_player");
  ASSERT_TRUE(player.ok()) << "a documented key is refused: " << player.error().message();
  ASSERT_EQ(player->frames.size(), 1u);
  EXPECT_EQ(player->frames[0].frame, "paddle_link");
  EXPECT_EQ(player->frames[0].parent, "world");
  EXPECT_EQ(player->frames[0].position, Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(player->frames[0].velocity, Eigen::Vector3d(-0.5, 0, 0));
}

// Issue 42, build step 2: a body's shape keys. Each bad value is named at its key; a good box,
// cylinder or capsule body (or a sphere given its tensor) is read, checked and taken, as the
// monitor moves it (issue 42, step 7; it was refused "not yet: only spheres move" until the
// monitor took shaped bodies), and so is a mesh body (its convex hull; refused "not yet" until
// the monitor moved one).
TEST(SceneLoader, Issue42_ShapedBodiesAreReadCheckedAndTaken) {
  const auto withBody = [](const std::function<void(XmlRpc::XmlRpcValue&)>& shape_it) {
    XmlRpc::XmlRpcValue scene = fullScene();
    XmlRpc::XmlRpcValue body;
    body["id"] = "block";
    body["mass"] = 0.37;
    body["material"] = "tennis_ball";
    shape_it(body);
    scene["bodies"][2] = body;
    return scene;
  };
  const auto refused = [](const XmlRpc::XmlRpcValue& scene, const std::string& field,
                          const std::string& words) {
    const auto loaded = loadScene(scene, "~scene");
    ASSERT_FALSE(loaded.ok()) << "expected a refusal naming " << field;
    EXPECT_EQ(loaded.error().field, field) << loaded.error().message();
    EXPECT_NE(loaded.error().reason.find(words), std::string::npos) << loaded.error().message();
  };
  const std::string at = "~scene/bodies[2]/";
  const auto taken = [](const XmlRpc::XmlRpcValue& scene, core::BodyShape shape) {
    const auto loaded = loadScene(scene, "~scene");
    ASSERT_TRUE(loaded.ok()) << loaded.error().message();
    const auto block = std::find_if(loaded->bodies.begin(), loaded->bodies.end(),
                                    [](const core::BodySpec& b) { return b.id == "block"; });
    ASSERT_NE(block, loaded->bodies.end());
    EXPECT_EQ(block->shape, shape);
  };
  // Good shapes: read, checked and taken.
  taken(withBody([](XmlRpc::XmlRpcValue& b) {
          b["shape"] = "box";
          b["size"] = list3(0.1, 0.2, 0.3);
        }),
        core::BodyShape::kBox);
  taken(withBody([](XmlRpc::XmlRpcValue& b) {
          b["shape"] = "capsule";
          b["radius"] = 0.05;
          b["length"] = 0.0;
        }),
        core::BodyShape::kCapsule);
  taken(withBody([](XmlRpc::XmlRpcValue& b) {
          b["shape"] = "mesh";
          b["resource"] = testMesh("grip.stl");
        }),
        core::BodyShape::kMesh);
  // A ball given a tensor: a shaped body of a sphere's shape.
  taken(withBody([](XmlRpc::XmlRpcValue& b) {
          b["radius"] = 0.05;
          b["inertia"]["ixx"] = 1e-3;
          b["inertia"]["iyy"] = 1e-3;
          b["inertia"]["izz"] = 1e-3;
        }),
        core::BodyShape::kSphere);
  // Bad values, each at its key.
  refused(withBody([](XmlRpc::XmlRpcValue& b) { b["shape"] = "plane"; }), at + "shape",
          "unknown body shape 'plane'");
  refused(withBody([](XmlRpc::XmlRpcValue& b) { b["shape"] = "box"; }), at + "size", "is required");
  refused(withBody([](XmlRpc::XmlRpcValue& b) {
            b["shape"] = "box";
            b["size"] = list3(0.1, 0.0, 0.3);
          }),
          at + "size", "> 0");
  refused(withBody([](XmlRpc::XmlRpcValue& b) {
            b["shape"] = "box";
            b["size"] = list3(0.1, 0.1, 0.1);
            b["radius"] = 0.05;
          }),
          at + "radius", "");  // not a box's key
  refused(withBody([](XmlRpc::XmlRpcValue& b) {
            b["shape"] = "cylinder";
            b["radius"] = 0.05;
          }),
          at + "length", "is required");
  refused(withBody([](XmlRpc::XmlRpcValue& b) {
            b["shape"] = "cylinder";
            b["radius"] = -0.05;
            b["length"] = 0.1;
          }),
          at + "radius", "");
  refused(withBody([](XmlRpc::XmlRpcValue& b) {
            b["shape"] = "mesh";
            b["resource"] = testMesh("no_such_file.stl");
          }),
          at + "resource", "no_such_file.stl");
  refused(withBody([](XmlRpc::XmlRpcValue& b) {
            b["shape"] = "box";
            b["size"] = list3(0.1, 0.1, 0.1);
            b["inertia"] = "hollow";
          }),
          at + "inertia", "`hollow` is a sphere's");
  refused(withBody([](XmlRpc::XmlRpcValue& b) {
            b["shape"] = "box";
            b["size"] = list3(0.1, 0.1, 0.1);
            b["inertia"]["ixx"] = 1.0;
            b["inertia"]["iyy"] = 1.0;
          }),
          at + "inertia/izz", "is required");
  refused(withBody([](XmlRpc::XmlRpcValue& b) {
            b["shape"] = "box";
            b["size"] = list3(0.1, 0.1, 0.1);
            b["inertia"]["ixx"] = 1.0;
            b["inertia"]["iyy"] = 1.0;
            b["inertia"]["izz"] = 3.0;
          }),
          at + "inertia", "triangle inequality");
  refused(withBody([](XmlRpc::XmlRpcValue& b) {
            b["shape"] = "box";
            b["size"] = list3(0.1, 0.1, 0.1);
            b["inertia"]["ixx"] = 1.0;
            b["inertia"]["iyy"] = 1.0;
            b["inertia"]["izz"] = 1.0;
            b["inertia"]["ixy"] = 1.5;
          }),
          at + "inertia.ixy", "not positive definite");
  refused(withBody([](XmlRpc::XmlRpcValue& b) {
            b["shape"] = "box";
            b["size"] = list3(0.1, 0.1, 0.1);
            b["inertia"]["ixx"] = 1.0;
            b["inertia"]["iyy"] = 1.0;
            b["inertia"]["izz"] = 1.0;
            b["inertia"]["density"] = 3.0;
          }),
          at + "inertia/density", "");
  refused(withBody([](XmlRpc::XmlRpcValue& b) {
            b["radius"] = 0.05;
            b["inertia"] = 7.0;
          }),
          at + "inertia", "a tensor");
}

// A body's orientation at the start (issue 42, step 2): `orientation: [x, y, z, w]` normalised,
// or `rpy` as an obstacle's (roll about x, then pitch about y, then yaw about z, about the fixed
// axes): rpy (0, 0, pi/2) is the quarter turn about z, q = (0, 0, sin(pi/4), cos(pi/4)); a zero
// quaternion, a number that is not finite and both keys at once are refused by name.
TEST(SceneLoader, ABodysOrientationIsReadAsAnObstaclesIs) {
  const auto blockOf = [](const std::function<void(XmlRpc::XmlRpcValue&)>& turn_it) {
    XmlRpc::XmlRpcValue scene = fullScene();
    XmlRpc::XmlRpcValue body;
    body["id"] = "block";
    body["mass"] = 0.37;
    body["material"] = "tennis_ball";
    body["shape"] = "box";
    body["size"] = list3(0.1, 0.2, 0.3);
    turn_it(body);
    scene["bodies"][2] = body;
    return loadScene(scene, "~scene");
  };
  const auto orientationOf = [](const core::Expected<core::Scene>& loaded) {
    EXPECT_TRUE(loaded.ok()) << loaded.error().message();
    for (const core::BodySpec& b : loaded->bodies) {
      if (b.id == "block") return b.orientation;
    }
    ADD_FAILURE() << "no block";
    return Eigen::Quaterniond::Identity();
  };
  const double s = std::sqrt(0.5);
  const Eigen::Quaterniond quarter(s, 0.0, 0.0, s);
  const auto given = orientationOf(blockOf([](XmlRpc::XmlRpcValue& b) {
    b["orientation"][0] = 0.0;
    b["orientation"][1] = 0.0;
    b["orientation"][2] = 2.0;  // normalised on load
    b["orientation"][3] = 2.0;
  }));
  EXPECT_NEAR(given.angularDistance(quarter), 0.0, 1e-15);
  EXPECT_NEAR(given.norm(), 1.0, 1e-15);
  const auto rpy = orientationOf(
      blockOf([](XmlRpc::XmlRpcValue& b) { b["rpy"] = list3(0.0, 0.0, 1.5707963267948966); }));
  EXPECT_NEAR(rpy.angularDistance(quarter), 0.0, 1e-15);
  EXPECT_EQ(orientationOf(blockOf([](XmlRpc::XmlRpcValue&) {})).coeffs(),
            Eigen::Quaterniond::Identity().coeffs());
  const auto refusal = [](const core::Expected<core::Scene>& loaded) {
    return loaded.ok() ? std::string("taken") : loaded.error().message();
  };
  const std::string at = "~scene/bodies[2]/";
  EXPECT_EQ(refusal(blockOf([](XmlRpc::XmlRpcValue& b) {
              for (int i = 0; i < 4; ++i) b["orientation"][i] = 0.0;
            })).rfind(at + "orientation: must not be zero", 0),
            0u);
  EXPECT_EQ(refusal(blockOf([](XmlRpc::XmlRpcValue& b) {
              b["rpy"] = list3(0.0, std::numeric_limits<double>::infinity(), 0.0);
            })).rfind(at + "rpy", 0),
            0u);
  EXPECT_EQ(refusal(blockOf([](XmlRpc::XmlRpcValue& b) {
              b["rpy"] = list3(0.0, 0.0, 0.0);
              b["orientation"] = list3(0.0, 0.0, 0.0);
            })).rfind(at + "rpy: give the orientation as `orientation` or as `rpy`, not both", 0),
            0u);
}

// Issue 13, item 7: a plane normal "of any length" is one, also 1e-200 and 1e200 long (where
// normalising once under- and overflowed and the plane was never hit).
TEST(SceneLoader, PlaneNormalsOfAnyLengthAreUnitAfterLoading) {
  for (const double length : {1e-200, 1e-310, 1e200, 1.7e308}) {
    auto scene = fullScene();
    scene["obstacles"][0]["normal"] = list3(0, 0, length);
    const auto loaded = loadScene(scene, "~scene");
    ASSERT_TRUE(loaded.ok()) << length << ": " << loaded.error().message();
    EXPECT_EQ(loaded->obstacles[0].normal, Eigen::Vector3d(0, 0, 1)) << length;
  }
  auto scene = fullScene();
  scene["obstacles"][0]["normal"] = list3(3e200, 0, 4e200);
  const auto loaded = loadScene(scene, "~scene");
  ASSERT_TRUE(loaded.ok());
  EXPECT_NEAR(loaded->obstacles[0].normal.x(), 0.6, 2.5e-16);
  EXPECT_NEAR(loaded->obstacles[0].normal.z(), 0.8, 2.5e-16);
}

// Issue 13, item 7: `fixed_frame: /world` was accepted, then every state naming a frame was
// dropped (tf2 frame ids have no leading slash).
// Issue 27, item 5: a stack placed at x = 1.7e308 was loaded, played, and fell through its
// floor with no contact and no word (past 2^1023 the monitor's sums of two positions overflow).
// A body's position must be below 2^1022 on every axis (core::kMaxResolvedCoordinate).
TEST(SceneLoader, ABodyPlacedPastTheMonitorsResolutionIsRefusedNamingTheCoordinate) {
  auto scene = fullScene();
  scene["bodies"][0]["position"][0] = 1.7e308;
  scene["bodies"][0]["position"][1] = 0.0;
  scene["bodies"][0]["position"][2] = 0.05;
  const auto loaded = loadScene(scene, "~scene");
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.error().message(),
            "~scene/bodies[0]/position.x: 1.7e+308 m is beyond where the monitor can resolve a "
            "contact (|x| must be below 2^1022 = 4.49423283715579e+307 m: past 2^1023 the sum of "
            "two bodies' coordinates overflows)");
  scene["bodies"][0]["position"][0] = std::nextafter(0x1p1022, 0.0);
  EXPECT_EQ(sceneErrorField(scene), "");
}

// Issue 39, item 6: a box placed at x = 1e300 was loaded and met a ball 1.1 m above it at once,
// with no word. An obstacle whose position is at or beyond 2^47 times its bounding radius (where
// the touching band of a body near it is as wide as the obstacle) is a start-up warning naming
// the field; a plane's offset from 2^1022 on is refused, as a body's position is.
TEST(SceneLoader, Issue39_Item6_AnObstacleBeyondItsResolutionIsNamed) {
  auto scene = fullScene();
  XmlRpc::XmlRpcValue box;
  box["id"] = "far_table";
  box["type"] = "box";
  box["material"] = "concrete";
  box["position"][0] = 1e300;
  box["position"][1] = 0.0;
  box["position"][2] = 0.0;
  box["size"][0] = 2.0;
  box["size"][1] = 2.0;
  box["size"][2] = 1.0;
  const int index = scene["obstacles"].size();
  scene["obstacles"][index] = box;
  // (The scene's two balls start inside its floor: warned too.)
  const std::string named = "~scene/obstacles[" + std::to_string(index) + "]/position.x: ";
  const auto about = [&named](const std::vector<std::string>& warnings) {
    std::vector<std::string> found;
    for (const std::string& warning : warnings) {
      if (warning.rfind(named, 0) == 0) found.push_back(warning);
    }
    return found;
  };
  std::vector<std::string> warnings;
  ASSERT_TRUE(loadScene(scene, "~scene", nullptr, &warnings).ok());
  ASSERT_EQ(about(warnings).size(), 1u);
  EXPECT_EQ(
      about(warnings)[0].find(named + "1e+300 m is beyond where a contact with this obstacle "
                                      "resolves (|x| must be below 2^47 times its bounding radius "
                                      "1.5 m, 211106232532992 m"),
      0u)
      << about(warnings)[0];
  scene["obstacles"][index]["position"][0] = 1e14;
  warnings.clear();
  ASSERT_TRUE(loadScene(scene, "~scene", nullptr, &warnings).ok());
  EXPECT_TRUE(about(warnings).empty());
  scene = fullScene();
  scene["obstacles"][0]["offset"] = 1.7e308;
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[0]/offset");
}

TEST(SceneLoader, FramesWithALeadingSlashAreRefused) {
  auto scene = fullScene();
  scene["fixed_frame"] = "/world";
  const auto loaded = loadScene(scene, "~scene");
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.error().field, "~scene/fixed_frame");
  EXPECT_NE(loaded.error().reason.find("use 'world'"), std::string::npos)
      << loaded.error().message();
  scene = fullScene();
  scene["obstacles"][1]["frame"] = "/paddle_link";
  EXPECT_EQ(sceneErrorField(scene), "~scene/obstacles[1]/frame");
}

TEST(SceneLoader, WrongTypesNameTheKeyAndTheValue) {
  auto scene = fullScene();
  scene["bodies"][0]["mass"] = "heavy";
  const auto loaded = loadScene(scene, "~scene");
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.error().message(),
            "~scene/bodies[0]/mass: must be a number, got a string ('heavy')");
  scene = fullScene();
  scene["bodies"][0]["inertia"] = "cube";
  EXPECT_EQ(sceneErrorField(scene), "~scene/bodies[0]/inertia");
  scene = fullScene();
  scene["bodies"][0].clear();
  scene["bodies"][0]["mass"] = 1.0;
  EXPECT_EQ(sceneErrorField(scene), "~scene/bodies[0]/id");  // required, first in the table
}

// Start-up once grew with the square of the bodies (every pair of bodies checked for a
// coefficient): the check is per pair of materials now, and still finds the first bad pair
// where a check of every pair would.
TEST(SceneLoader, AMissingCoefficientIsFoundAtTheFirstPairThatNeedsIt) {
  XmlRpc::XmlRpcValue scene;
  for (int i = 0; i < 5; ++i) {
    XmlRpc::XmlRpcValue ball;
    ball["id"] = "b" + std::to_string(i);
    ball["mass"] = 1.0;
    ball["radius"] = 0.1;
    ball["material"] = i == 3 ? "concrete" : "tennis_ball";
    scene["bodies"][i] = ball;
  }
  // concrete against concrete has no coefficient: bodies[3] against itself comes first.
  auto loaded = loadScene(scene, "s");
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.error().field, "s/bodies[3]/material");
  EXPECT_NE(loaded.error().reason.find("against 'b3'"), std::string::npos);
  // With a concrete floor, bodies[3] meets it only after meeting itself; a concrete body
  // before every other meets the floor... after itself too.
  scene["obstacles"][0]["id"] = "floor";
  scene["obstacles"][0]["type"] = "plane";
  scene["obstacles"][0]["normal"] = list3(0, 0, 1);
  scene["obstacles"][0]["material"] = "concrete";
  loaded = loadScene(scene, "s");
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.error().field, "s/bodies[3]/material");
  EXPECT_NE(loaded.error().reason.find("against 'b3'"), std::string::npos);
}

// --- Issue 41 item 6: mesh resources with limits --------------------------------------------

/// A scene of one mesh obstacle, `grip`, at `resource`.
XmlRpc::XmlRpcValue meshScene(const std::string& resource) {
  XmlRpc::XmlRpcValue scene;
  scene["obstacles"][0]["id"] = "grip";
  scene["obstacles"][0]["type"] = "mesh";
  scene["obstacles"][0]["material"] = "concrete";
  scene["obstacles"][0]["resource"] = resource;
  return scene;
}

/// The error loading `scene` gives, as "field: reason" ("" when it loads).
std::string loadError(const XmlRpc::XmlRpcValue& scene) {
  const auto loaded = loadScene(scene, "~scene");
  return loaded.ok() ? "" : loaded.error().message();
}

/// A directory of its own under /tmp, for the files a test makes.
std::string scratchDirectory() {
  std::string pattern = "/tmp/collision_response_mesh_XXXXXX";
  const char* made = ::mkdtemp(pattern.data());
  return made ? std::string(made) : std::string();
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// /dev/zero and /dev/urandom never end: read as meshes they were read until memory ran out
// (2.1 GB, then std::bad_alloc with no key named). A device is refused before it is opened,
// however it is addressed (a package:// address that leaves its package too).
TEST(SceneLoader, Issue41_Item6_ADeviceIsRefusedNotReadUntilMemoryRunsOut) {
  for (const std::string& device :
       {std::string("file:///dev/zero"), std::string("file:///dev/urandom"),
        std::string("package://collision_response/../../../../../../../../../../dev/zero")}) {
    const std::string error = loadError(meshScene(device));
    EXPECT_TRUE(contains(error, "~scene/obstacles[0]/resource: '" + device +
                                    "' is a character "
                                    "device (/"))
        << error;
    EXPECT_TRUE(contains(error, "not a regular file")) << error;
  }
  // A directory is no mesh either.
  const std::string directory = loadError(meshScene("file:///tmp"));
  EXPECT_TRUE(contains(directory, "~scene/obstacles[0]/resource: 'file:///tmp' is a directory"))
      << directory;
}

// A FIFO is refused without being opened: opening it would wait for a writer, for ever.
TEST(SceneLoader, Issue41_Item6_AFifoIsRefusedWithoutWaitingForAWriter) {
  const std::string directory = scratchDirectory();
  ASSERT_FALSE(directory.empty());
  const std::string fifo = directory + "/grip.stl";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string error = loadError(meshScene("file://" + fifo));
  ::unlink(fifo.c_str());
  ::rmdir(directory.c_str());
  EXPECT_TRUE(contains(error, "~scene/obstacles[0]/resource: 'file://" + fifo + "' is a FIFO"))
      << error;
}

// Only the documented package:// and file:// addresses are read. An http:// address on a server
// that never answers (here a socket that listens and never accepts) held the scene's loading
// for ever; now it, like any other scheme or a bare path, is refused at once naming the scheme.
TEST(SceneLoader, Issue41_Item6_OnlyPackageAndFileAddressesAreRead) {
  const int server = ::socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(server, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;  // any free port
  ASSERT_EQ(::bind(server, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  ASSERT_EQ(::listen(server, 8), 0);
  socklen_t length = sizeof address;
  ASSERT_EQ(::getsockname(server, reinterpret_cast<sockaddr*>(&address), &length), 0);
  const std::string silent =
      "http://127.0.0.1:" + std::to_string(ntohs(address.sin_port)) + "/grip.stl";
  const std::string error = loadError(meshScene(silent));
  ::close(server);
  EXPECT_TRUE(contains(error, "~scene/obstacles[0]/resource: '" + silent +
                                  "' has the scheme http://, which is not read: a mesh is a "
                                  "package:// or file:// address"))
      << error;
  for (const std::string& other :
       {std::string("https://example.com/grip.stl"), std::string("ftp://example.com/grip.stl")}) {
    const std::string refused = loadError(meshScene(other));
    EXPECT_TRUE(contains(refused, "' has the scheme " + other.substr(0, other.find("://") + 3)))
        << refused;
  }
  // A bare path, and a file:// address of a relative path, are not addresses of a file.
  const std::string bare = std::string(COLLISION_RESPONSE_TEST_MESHES) + "/grip.stl";
  EXPECT_TRUE(contains(loadError(meshScene(bare)), "' is not an address")) << bare;
  EXPECT_TRUE(contains(loadError(meshScene("file://grip.stl")), "absolute path"));
  EXPECT_EQ(loadError(meshScene(testMesh("grip.stl"))), "");  // the base loads
  EXPECT_EQ(loadError(meshScene("package://collision_response/meshes/table.stl")), "");
  EXPECT_TRUE(contains(loadError(meshScene("package://collision_response")),
                       "is not a package://<package>/<path> address"));
}

// A file larger than the scene's max_mesh_bytes is refused before it is read, and one that
// grows past it as it is read (as /proc's files, whose size stat gives as 0) as soon as it does.
TEST(SceneLoader, Issue41_Item6_AFileLargerThanMaxMeshBytesIsRefused) {
  XmlRpc::XmlRpcValue scene = meshScene(testMesh("grip.stl"));  // 2,175 bytes
  scene["max_mesh_bytes"] = 2175;
  EXPECT_EQ(loadError(scene), "");
  scene["max_mesh_bytes"] = 2174;
  std::string error = loadError(scene);
  EXPECT_TRUE(contains(
      error, "~scene/obstacles[0]/resource: '" + testMesh("grip.stl") + "' is 2175 bytes ("))
      << error;
  EXPECT_TRUE(contains(error, "more than max_mesh_bytes (2174")) << error;
  scene = meshScene("file:///proc/self/maps");
  scene["max_mesh_bytes"] = 100;
  error = loadError(scene);
  EXPECT_TRUE(contains(error,
                       "~scene/obstacles[0]/resource: 'file:///proc/self/maps' grew past "
                       "100 bytes as it was read"))
      << error;
  // The key itself: an integer >= 1.
  for (const XmlRpc::XmlRpcValue& bad : {XmlRpc::XmlRpcValue(0), XmlRpc::XmlRpcValue(-5),
                                         XmlRpc::XmlRpcValue(1e9), XmlRpc::XmlRpcValue("large")}) {
    scene = meshScene(testMesh("grip.stl"));
    scene["max_mesh_bytes"] = bad;
    EXPECT_EQ(sceneErrorField(scene), "~scene/max_mesh_bytes");
  }
}

// A robot's <mesh filename="file:///dev/zero"> is refused as the scene's mesh is, naming the
// link and the filename, and the scene's max_mesh_bytes holds for the robot's meshes too.
TEST(SceneLoader, Issue41_Item6_ARobotsMeshHasTheSameLimits) {
  const auto robot = [](const std::string& filename, const std::string& scale) {
    return R"(<?xml version="1.0"?>
<robot name="arm">
  <link name="paddle">
    <collision><geometry><mesh filename=")" +
           filename + R"(" scale=")" + scale + R"("/></geometry></collision>
  </link>
</robot>)";
  };
  XmlRpc::XmlRpcValue scene;
  scene["robot"]["material"] = "concrete";
  std::string urdf;
  const UrdfSource source = [&](const std::string&) -> core::Expected<std::string> { return urdf; };
  const auto error = [&] {
    const auto loaded = loadScene(scene, "~scene", source);
    return loaded.ok() ? std::string() : loaded.error().message();
  };
  urdf = robot("file:///dev/zero", "1 1 1");
  EXPECT_TRUE(contains(error(),
                       "~scene/robot/description: link 'paddle' <collision> 0, <mesh> "
                       "filename: 'file:///dev/zero' is a character device"))
      << error();
  urdf = robot(testMesh("grip.stl"), "1 1 1");
  EXPECT_EQ(error(), "");
  scene["max_mesh_bytes"] = 1000;
  EXPECT_TRUE(contains(error(), "more than max_mesh_bytes (1000")) << error();
  scene = XmlRpc::XmlRpcValue();
  scene["robot"]["material"] = "concrete";
  urdf = robot(testMesh("grip.stl"), "1e300 1e300 1e300");
  EXPECT_TRUE(contains(error(),
                       "~scene/robot/description: link 'paddle' <collision> 0, <mesh> "
                       "scale: "))
      << error();
}

// --- Issue 41 item 8: a scale the doubles cannot take is the scale's fault, not the file's ------

// grip.stl (a box 0.0625 x 0.125 x 0.09375 m about its origin) at scale 1e300 was refused as
// "has no triangle of nonzero area", blaming the file. A triangle's area is the length of its
// edges' cross product, whose components are products of two edges: at 1e200 and 1e300 (edges
// of 6e198 m and more) they overflow to infinity; at 1e-100 (cross products of about 1e-202
// m^2) their squares, about 1e-404, underflow to 0, and so do smaller ones. A scale whose
// product with a coordinate overflows (4 m at 1e308) is named on its axis.
TEST(SceneLoader, Issue41_Item8_AScaleBeyondTheDoublesIsNamedNotTheFile) {
  for (const double factor : {1e300, 1e200, 1e-100, 1e-200, 1e-300}) {
    XmlRpc::XmlRpcValue scene = meshScene(testMesh("grip.stl"));
    scene["obstacles"][0]["scale"] = list3(factor, factor, factor);
    const std::string error = loadError(scene);
    EXPECT_TRUE(contains(error, "~scene/obstacles[0]/scale: [")) << factor << ": " << error;
    EXPECT_TRUE(contains(error, "leaves 12 of the 12 triangles of nonzero area of '" +
                                    testMesh("grip.stl") + "' without area in doubles"))
        << factor << ": " << error;
  }
  // Cross products of about 1e197 m^2 (their components doubles) and 1e-103 m^2 (their squares,
  // 1e-206, too): these load.
  for (const double factor : {1e100, 1e-50}) {
    XmlRpc::XmlRpcValue scene = meshScene(testMesh("grip.stl"));
    scene["obstacles"][0]["scale"] = list3(factor, factor, factor);
    EXPECT_EQ(loadError(scene), "") << factor;
  }
  // Flattened along z only: the 8 triangles of the box's sides lose their area, the 4 of its top
  // and bottom keep theirs; it is still the scale's fault.
  XmlRpc::XmlRpcValue flat = meshScene(testMesh("grip.stl"));
  flat["obstacles"][0]["scale"] = list3(1, 1, 1e-300);
  EXPECT_TRUE(contains(loadError(flat),
                       "~scene/obstacles[0]/scale: [1, 1, 1e-300] leaves 8 of "
                       "the 12 triangles"))
      << loadError(flat);
  // A vertex 4 m out, times 1e308, is beyond the doubles: scale[0] is named.
  const std::string directory = scratchDirectory();
  ASSERT_FALSE(directory.empty());
  const std::string path = directory + "/corner.stl";
  std::ofstream(path)
      << "solid corner\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n"
         "   vertex 4 0 0\n   vertex 0 4 0\n  endloop\n endfacet\nendsolid corner\n";
  XmlRpc::XmlRpcValue far = meshScene("file://" + path);
  far["obstacles"][0]["scale"] = list3(1e308, 1, 1);
  const std::string error = loadError(far);
  ::unlink(path.c_str());
  ::rmdir(directory.c_str());
  EXPECT_TRUE(contains(error, "~scene/obstacles[0]/scale[0]: 1e+308 times the extent of")) << error;
  EXPECT_TRUE(contains(error, "(4 m at scale 1) overflows the doubles")) << error;
}

}  // namespace
}  // namespace collision_response
