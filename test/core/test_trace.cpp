// The trace that must not move: every scene of config/scenes/*.yaml and of the accuracy
// benchmark (bench/accuracy/scenes.cpp) played through the core's monitor as the benchmark's
// "ours" plays them (bench/accuracy/ours.cpp: a Playback publishes the states, the monitor finds
// the impacts, the Playback applies them), each field of each impact and contact record hashed
// bit for bit (doubles by their bit patterns), with the states sent and each step's counters,
// against test/core/trace_digest.txt: one line per run, "name impacts contacts hash".
//
// A refactor that changes no behaviour leaves every line as it is. Check:
//   .ws/devel/lib/collision_response/core_tests --gtest_filter='Trace.*'
// A failure names each run whose line changed (its counts and hash before and after). Only a
// change meant to move the trace regenerates the digest, in a commit of its own that says why:
//   COLLISION_RESPONSE_WRITE_TRACE=1 .ws/devel/lib/collision_response/core_tests
//   --gtest_filter='Trace.*'
//
// The scenes of config/scenes are restated here in C++ (the core reads no YAML), value for value:
// each double as the file writes it, the planes normalised as the loader does. The durations are
// cut so that the whole trace stays a few seconds.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "collision_response/core/monitor.h"
#include "collision_response/core/playback.h"
#include "harness.h"
#include "scene_builders.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using scene_builders::ball;
using scene_builders::plane;
using scene_builders::sphere;

void addMaterial(Scene& scene, const std::string& name, const Material& material) {
  EXPECT_TRUE(scene.materials.addMaterial(name, material, "materials/" + name).ok()) << name;
}

// config/scenes/billiards_break.yaml
Scene yamlBilliardsBreak() {
  Scene scene;
  addMaterial(scene, "cushion", Material{0.75, {}});
  scene.bodies.push_back(
      ball("cue", 0.17, 0.028575, "billiard_ball", V(0.635, 0.635, 0.0), V(6.0, 0.0, 0.0)));
  scene.bodies.push_back(ball("ball_01", 0.17, 0.028575, "billiard_ball", V(1.905, 0.635, 0.0)));
  scene.bodies.push_back(
      ball("ball_02", 0.17, 0.028575, "billiard_ball", V(1.9544933518262806, 0.606425, 0.0)));
  scene.bodies.push_back(
      ball("ball_03", 0.17, 0.028575, "billiard_ball", V(1.9544933518262806, 0.663575, 0.0)));
  scene.bodies.push_back(
      ball("ball_04", 0.17, 0.028575, "billiard_ball", V(2.0039867036525614, 0.57785, 0.0)));
  scene.bodies.push_back(
      ball("ball_05", 0.17, 0.028575, "billiard_ball", V(2.0039867036525614, 0.635, 0.0)));
  scene.bodies.push_back(
      ball("ball_06", 0.17, 0.028575, "billiard_ball", V(2.0039867036525614, 0.69215, 0.0)));
  scene.bodies.push_back(
      ball("ball_07", 0.17, 0.028575, "billiard_ball", V(2.053480055478842, 0.549275, 0.0)));
  scene.bodies.push_back(
      ball("ball_08", 0.17, 0.028575, "billiard_ball", V(2.053480055478842, 0.606425, 0.0)));
  scene.bodies.push_back(
      ball("ball_09", 0.17, 0.028575, "billiard_ball", V(2.053480055478842, 0.663575, 0.0)));
  scene.bodies.push_back(ball("ball_10", 0.17, 0.028575, "billiard_ball",
                              V(2.053480055478842, 0.7207250000000001, 0.0)));
  scene.bodies.push_back(
      ball("ball_11", 0.17, 0.028575, "billiard_ball", V(2.1029734073051225, 0.5207, 0.0)));
  scene.bodies.push_back(
      ball("ball_12", 0.17, 0.028575, "billiard_ball", V(2.1029734073051225, 0.57785, 0.0)));
  scene.bodies.push_back(
      ball("ball_13", 0.17, 0.028575, "billiard_ball", V(2.1029734073051225, 0.635, 0.0)));
  scene.bodies.push_back(
      ball("ball_14", 0.17, 0.028575, "billiard_ball", V(2.1029734073051225, 0.69215, 0.0)));
  scene.bodies.push_back(
      ball("ball_15", 0.17, 0.028575, "billiard_ball", V(2.1029734073051225, 0.7493, 0.0)));
  scene.obstacles.push_back(plane("cushion_head", V(1.0, 0.0, 0.0), 0.0, "cushion"));
  scene.obstacles.push_back(plane("cushion_foot", V(-1.0, 0.0, 0.0), -2.54, "cushion"));
  scene.obstacles.push_back(plane("cushion_right", V(0.0, 1.0, 0.0), 0.0, "cushion"));
  scene.obstacles.push_back(plane("cushion_left", V(0.0, -1.0, 0.0), -1.27, "cushion"));
  normalizePlanes(scene);
  return scene;
}

// config/scenes/corner.yaml
Scene yamlCorner() {
  Scene scene;
  scene.effects.gravity = true;
  scene.gravity = V(0.0, 0.0, -9.81);
  addMaterial(scene, "wet_clay", Material{0.0, {}});
  scene.bodies.push_back(ball("ball", 0.2, 0.05, "wet_clay", V(0.254, 0.0, -0.022)));
  scene.obstacles.push_back(plane("incline", V(7.0, 0.0, 24.0), 0.0, "wet_clay"));
  scene.obstacles.push_back(plane("wall", V(-1.0, 0.0, 0.0), -0.5, "wet_clay"));
  normalizePlanes(scene);
  return scene;
}

// config/scenes/cradle.yaml
Scene yamlCradle() {
  Scene scene;
  addMaterial(scene, "polished_steel", Material{1.0, {}});
  scene.bodies.push_back(
      ball("ball_1", 0.26, 0.02, "polished_steel", V(-0.06, 0.0, 0.0), V(0.5, 0.0, 0.0)));
  scene.bodies.push_back(ball("ball_2", 0.26, 0.02, "polished_steel", V(0.0, 0.0, 0.0)));
  scene.bodies.push_back(ball("ball_3", 0.26, 0.02, "polished_steel", V(0.04, 0.0, 0.0)));
  scene.bodies.push_back(ball("ball_4", 0.26, 0.02, "polished_steel", V(0.08, 0.0, 0.0)));
  scene.bodies.push_back(ball("ball_5", 0.26, 0.02, "polished_steel", V(0.12, 0.0, 0.0)));
  scene.obstacles.push_back(plane("left_wall", V(1.0, 0.0, 0.0), -0.1, "polished_steel"));
  scene.obstacles.push_back(plane("right_wall", V(-1.0, 0.0, 0.0), -0.22, "polished_steel"));
  normalizePlanes(scene);
  return scene;
}

// config/scenes/default.yaml
Scene yamlDefault() {
  Scene scene;
  scene.restitution_threshold = 0.0;
  normalizePlanes(scene);
  return scene;
}

// config/scenes/drop_test.yaml
Scene yamlDropTest() {
  Scene scene;
  scene.effects.gravity = true;
  scene.gravity = V(0.0, 0.0, -9.81);
  scene.restitution_threshold = 0.0;
  scene.bodies.push_back(
      ball("range_golf", 0.0459, 0.02135, "range_golf_ball", V(0.0, 0.0, 1.02135)));
  scene.bodies.push_back(ball("tennis", 0.057, 0.0335, "tennis_ball", V(0.3, 0.0, 1.0335)));
  scene.bodies.push_back(ball("billiard", 0.17, 0.028575, "billiard_ball", V(0.6, 0.0, 1.028575)));
  scene.bodies.push_back(ball("hand", 0.45, 0.095, "hand_ball", V(0.9, 0.0, 1.095)));
  scene.bodies.push_back(ball("wooden", 0.05, 0.03, "wooden_ball", V(1.2, 0.0, 1.03)));
  scene.bodies.push_back(ball("steel", 0.0084, 0.0127, "steel_ball_bearing", V(1.5, 0.0, 1.0127)));
  scene.bodies.push_back(ball("glass_marble", 0.0056, 0.008, "glass_marble", V(1.8, 0.0, 1.008)));
  scene.bodies.push_back(ball("rubber_band", 0.2, 0.04, "rubber_band_ball", V(2.1, 0.0, 1.04)));
  scene.bodies.push_back(
      ball("hollow_hard_plastic", 0.0027, 0.02, "hollow_hard_plastic_ball", V(2.4, 0.0, 1.02)));
  scene.obstacles.push_back(plane("floor", V(0.0, 0.0, 1.0), 0.0, "concrete"));
  normalizePlanes(scene);
  return scene;
}

// config/scenes/paddle.yaml
Scene yamlPaddle() {
  Scene scene;
  scene.bodies.push_back(
      ball("ball", 0.057, 0.033, "tennis_ball", V(0.0, 0.0, 0.0), V(1.0, 0.0, 0.0)));
  scene.obstacles.push_back(sphere("paddle", V(0.0, 0.0, 0.0), 0.08, "wooden_ball"));
  scene.obstacles.back().frame = "paddle_link";
  normalizePlanes(scene);
  return scene;
}

// config/scenes/pile.yaml
Scene yamlPile() {
  Scene scene;
  scene.effects.gravity = true;
  scene.gravity = V(0.0, 0.0, -9.81);
  scene.stepped_cluster_min_bodies = 32;
  addMaterial(scene, "pile_ball", Material{0.5, {}});
  scene.bodies.push_back(ball("ball_00", 0.1, 0.05, "pile_ball", V(0.105, 0.108, 0.112)));
  scene.bodies.push_back(ball("ball_01", 0.1, 0.05, "pile_ball", V(0.232, 0.113, 0.115)));
  scene.bodies.push_back(ball("ball_02", 0.1, 0.05, "pile_ball", V(0.348, 0.107, 0.107)));
  scene.bodies.push_back(ball("ball_03", 0.1, 0.05, "pile_ball", V(0.475, 0.112, 0.11)));
  scene.bodies.push_back(ball("ball_04", 0.1, 0.05, "pile_ball", V(0.111, 0.226, 0.113)));
  scene.bodies.push_back(ball("ball_05", 0.1, 0.05, "pile_ball", V(0.227, 0.231, 0.105)));
  scene.bodies.push_back(ball("ball_06", 0.1, 0.05, "pile_ball", V(0.354, 0.225, 0.108)));
  scene.bodies.push_back(ball("ball_07", 0.1, 0.05, "pile_ball", V(0.47, 0.23, 0.111)));
  scene.bodies.push_back(ball("ball_08", 0.1, 0.05, "pile_ball", V(0.106, 0.355, 0.114)));
  scene.bodies.push_back(ball("ball_09", 0.1, 0.05, "pile_ball", V(0.233, 0.349, 0.106)));
  scene.bodies.push_back(ball("ball_10", 0.1, 0.05, "pile_ball", V(0.349, 0.354, 0.109)));
  scene.bodies.push_back(ball("ball_11", 0.1, 0.05, "pile_ball", V(0.465, 0.348, 0.112)));
  scene.bodies.push_back(ball("ball_12", 0.1, 0.05, "pile_ball", V(0.112, 0.473, 0.115)));
  scene.bodies.push_back(ball("ball_13", 0.1, 0.05, "pile_ball", V(0.228, 0.467, 0.107)));
  scene.bodies.push_back(ball("ball_14", 0.1, 0.05, "pile_ball", V(0.355, 0.472, 0.11)));
  scene.bodies.push_back(ball("ball_15", 0.1, 0.05, "pile_ball", V(0.471, 0.466, 0.113)));
  scene.bodies.push_back(ball("ball_16", 0.1, 0.05, "pile_ball", V(0.107, 0.111, 0.225)));
  scene.bodies.push_back(ball("ball_17", 0.1, 0.05, "pile_ball", V(0.234, 0.105, 0.228)));
  scene.bodies.push_back(ball("ball_18", 0.1, 0.05, "pile_ball", V(0.35, 0.11, 0.231)));
  scene.bodies.push_back(ball("ball_19", 0.1, 0.05, "pile_ball", V(0.466, 0.115, 0.234)));
  scene.bodies.push_back(ball("ball_20", 0.1, 0.05, "pile_ball", V(0.113, 0.229, 0.226)));
  scene.bodies.push_back(ball("ball_21", 0.1, 0.05, "pile_ball", V(0.229, 0.234, 0.229)));
  scene.bodies.push_back(ball("ball_22", 0.1, 0.05, "pile_ball", V(0.345, 0.228, 0.232)));
  scene.bodies.push_back(ball("ball_23", 0.1, 0.05, "pile_ball", V(0.472, 0.233, 0.235)));
  scene.bodies.push_back(ball("ball_24", 0.1, 0.05, "pile_ball", V(0.108, 0.347, 0.227)));
  scene.bodies.push_back(ball("ball_25", 0.1, 0.05, "pile_ball", V(0.235, 0.352, 0.23)));
  scene.bodies.push_back(ball("ball_26", 0.1, 0.05, "pile_ball", V(0.351, 0.346, 0.233)));
  scene.bodies.push_back(ball("ball_27", 0.1, 0.05, "pile_ball", V(0.467, 0.351, 0.225)));
  scene.bodies.push_back(ball("ball_28", 0.1, 0.05, "pile_ball", V(0.114, 0.465, 0.228)));
  scene.bodies.push_back(ball("ball_29", 0.1, 0.05, "pile_ball", V(0.23, 0.47, 0.231)));
  scene.bodies.push_back(ball("ball_30", 0.1, 0.05, "pile_ball", V(0.346, 0.475, 0.234)));
  scene.bodies.push_back(ball("ball_31", 0.1, 0.05, "pile_ball", V(0.473, 0.469, 0.226)));
  scene.bodies.push_back(ball("ball_32", 0.1, 0.05, "pile_ball", V(0.109, 0.114, 0.349)));
  scene.bodies.push_back(ball("ball_33", 0.1, 0.05, "pile_ball", V(0.225, 0.108, 0.352)));
  scene.bodies.push_back(ball("ball_34", 0.1, 0.05, "pile_ball", V(0.352, 0.113, 0.355)));
  scene.bodies.push_back(ball("ball_35", 0.1, 0.05, "pile_ball", V(0.468, 0.107, 0.347)));
  scene.bodies.push_back(ball("ball_36", 0.1, 0.05, "pile_ball", V(0.115, 0.232, 0.35)));
  scene.bodies.push_back(ball("ball_37", 0.1, 0.05, "pile_ball", V(0.231, 0.226, 0.353)));
  scene.bodies.push_back(ball("ball_38", 0.1, 0.05, "pile_ball", V(0.347, 0.231, 0.345)));
  scene.bodies.push_back(ball("ball_39", 0.1, 0.05, "pile_ball", V(0.474, 0.225, 0.348)));
  scene.bodies.push_back(ball("ball_40", 0.1, 0.05, "pile_ball", V(0.11, 0.35, 0.351)));
  scene.bodies.push_back(ball("ball_41", 0.1, 0.05, "pile_ball", V(0.226, 0.355, 0.354)));
  scene.bodies.push_back(ball("ball_42", 0.1, 0.05, "pile_ball", V(0.353, 0.349, 0.346)));
  scene.bodies.push_back(ball("ball_43", 0.1, 0.05, "pile_ball", V(0.469, 0.354, 0.349)));
  scene.bodies.push_back(ball("ball_44", 0.1, 0.05, "pile_ball", V(0.105, 0.468, 0.352)));
  scene.bodies.push_back(ball("ball_45", 0.1, 0.05, "pile_ball", V(0.232, 0.473, 0.355)));
  scene.bodies.push_back(ball("ball_46", 0.1, 0.05, "pile_ball", V(0.348, 0.467, 0.347)));
  scene.bodies.push_back(ball("ball_47", 0.1, 0.05, "pile_ball", V(0.475, 0.472, 0.35)));
  scene.bodies.push_back(ball("ball_48", 0.1, 0.05, "pile_ball", V(0.111, 0.106, 0.473)));
  scene.bodies.push_back(ball("ball_49", 0.1, 0.05, "pile_ball", V(0.227, 0.111, 0.465)));
  scene.bodies.push_back(ball("ball_50", 0.1, 0.05, "pile_ball", V(0.354, 0.105, 0.468)));
  scene.bodies.push_back(ball("ball_51", 0.1, 0.05, "pile_ball", V(0.47, 0.11, 0.471)));
  scene.bodies.push_back(ball("ball_52", 0.1, 0.05, "pile_ball", V(0.106, 0.235, 0.474)));
  scene.bodies.push_back(ball("ball_53", 0.1, 0.05, "pile_ball", V(0.233, 0.229, 0.466)));
  scene.bodies.push_back(ball("ball_54", 0.1, 0.05, "pile_ball", V(0.349, 0.234, 0.469)));
  scene.bodies.push_back(ball("ball_55", 0.1, 0.05, "pile_ball", V(0.465, 0.228, 0.472)));
  scene.bodies.push_back(ball("ball_56", 0.1, 0.05, "pile_ball", V(0.112, 0.353, 0.475)));
  scene.bodies.push_back(ball("ball_57", 0.1, 0.05, "pile_ball", V(0.228, 0.347, 0.467)));
  scene.bodies.push_back(ball("ball_58", 0.1, 0.05, "pile_ball", V(0.355, 0.352, 0.47)));
  scene.bodies.push_back(ball("ball_59", 0.1, 0.05, "pile_ball", V(0.471, 0.346, 0.473)));
  scene.bodies.push_back(ball("ball_60", 0.1, 0.05, "pile_ball", V(0.107, 0.471, 0.465)));
  scene.bodies.push_back(ball("ball_61", 0.1, 0.05, "pile_ball", V(0.234, 0.465, 0.468)));
  scene.bodies.push_back(ball("ball_62", 0.1, 0.05, "pile_ball", V(0.35, 0.47, 0.471)));
  scene.bodies.push_back(ball("ball_63", 0.1, 0.05, "pile_ball", V(0.466, 0.475, 0.474)));
  scene.obstacles.push_back(plane("floor", V(0.0, 0.0, 1.0), 0.0, "concrete"));
  scene.obstacles.push_back(plane("ceiling", V(0.0, 0.0, -1.0), -0.58, "concrete"));
  scene.obstacles.push_back(plane("wall_x0", V(1.0, 0.0, 0.0), 0.0, "concrete"));
  scene.obstacles.push_back(plane("wall_x1", V(-1.0, 0.0, 0.0), -0.58, "concrete"));
  scene.obstacles.push_back(plane("wall_y0", V(0.0, 1.0, 0.0), 0.0, "concrete"));
  scene.obstacles.push_back(plane("wall_y1", V(0.0, -1.0, 0.0), -0.58, "concrete"));
  normalizePlanes(scene);
  return scene;
}

// config/scenes/rough_pile.yaml
Scene yamlRoughPile() {
  Scene scene;
  scene.effects.gravity = scene.effects.friction = scene.effects.spin = true;
  scene.gravity = V(0.0, 0.0, -9.81);
  addMaterial(scene, "rough_ball", Material{0.5, 0.5});
  scene.bodies.push_back(ball("ball_0", 0.1, 0.05, "rough_ball", V(0.105, 0.108, 0.112)));
  scene.bodies.push_back(ball("ball_1", 0.1, 0.05, "rough_ball", V(0.232, 0.113, 0.115)));
  scene.bodies.push_back(ball("ball_2", 0.1, 0.05, "rough_ball", V(0.108, 0.227, 0.107)));
  scene.bodies.push_back(ball("ball_3", 0.1, 0.05, "rough_ball", V(0.235, 0.232, 0.11)));
  scene.bodies.push_back(ball("ball_4", 0.1, 0.05, "rough_ball", V(0.111, 0.106, 0.233)));
  scene.bodies.push_back(ball("ball_5", 0.1, 0.05, "rough_ball", V(0.227, 0.111, 0.225)));
  scene.bodies.push_back(ball("ball_6", 0.1, 0.05, "rough_ball", V(0.114, 0.225, 0.228)));
  scene.bodies.push_back(ball("ball_7", 0.1, 0.05, "rough_ball", V(0.23, 0.23, 0.231)));
  scene.obstacles.push_back(plane("floor", V(0.0, 0.0, 1.0), 0.0, "rough_ball"));
  scene.obstacles.push_back(plane("ceiling", V(0.0, 0.0, -1.0), -0.34, "rough_ball"));
  scene.obstacles.push_back(plane("wall_x0", V(1.0, 0.0, 0.0), 0.0, "rough_ball"));
  scene.obstacles.push_back(plane("wall_x1", V(-1.0, 0.0, 0.0), -0.34, "rough_ball"));
  scene.obstacles.push_back(plane("wall_y0", V(0.0, 1.0, 0.0), 0.0, "rough_ball"));
  scene.obstacles.push_back(plane("wall_y1", V(0.0, -1.0, 0.0), -0.34, "rough_ball"));
  normalizePlanes(scene);
  return scene;
}

// config/scenes/stack.yaml
Scene yamlStack() {
  Scene scene;
  scene.effects.gravity = true;
  scene.gravity = V(0.0, 0.0, -9.81);
  addMaterial(scene, "putty", Material{0.0, {}});
  scene.bodies.push_back(ball("bottom", 0.2, 0.05, "putty", V(0.0, 0.0, 0.05)));
  scene.bodies.push_back(ball("middle", 0.2, 0.05, "putty", V(0.0, 0.0, 0.15)));
  scene.bodies.push_back(ball("top", 0.2, 0.05, "putty", V(0.0, 0.0, 0.25)));
  scene.obstacles.push_back(plane("floor", V(0.0, 0.0, 1.0), 0.0, "concrete"));
  normalizePlanes(scene);
  return scene;
}

// config/scenes/two_balls_oblique.yaml
Scene yamlTwoBallsOblique() {
  Scene scene;
  scene.bodies.push_back(
      ball("a", 0.17, 0.028575, "billiard_ball", V(0.0, 0.0, 0.0), V(1.0, 0.0, 0.0)));
  scene.bodies.push_back(
      ball("b", 0.17, 0.028575, "billiard_ball", V(0.5, 0.0428625, 0.0), V(0.0, 0.0, 0.0)));
  normalizePlanes(scene);
  return scene;
}

/// 64-bit FNV-1a over the bytes of every value added.
class TraceHash {
 public:
  void bytes(const void* data, std::size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) {
      hash_ ^= p[i];
      hash_ *= 1099511628211ULL;
    }
  }
  void add(double value) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &value, sizeof bits);
    bytes(&bits, sizeof bits);
  }
  void add(std::uint64_t value) { bytes(&value, sizeof value); }
  void add(bool value) { add(static_cast<std::uint64_t>(value ? 1 : 0)); }
  void add(const V& v) {
    for (int i = 0; i < 3; ++i) add(v[i]);
  }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 14695981039346656037ULL;
};

void addImpact(TraceHash& hash, const ImpactRecord& r) {
  hash.add(r.time);
  hash.add(static_cast<std::uint64_t>(r.body_a));
  hash.add(static_cast<std::uint64_t>(r.other));
  hash.add(r.other_is_obstacle);
  hash.add(r.contact_point);
  hash.add(r.normal);
  hash.add(r.restitution);
  hash.add(r.impulse);
  hash.add(r.friction_impulse);
  hash.add(r.energy_lost);
  hash.add(r.oblique);
  for (const V* v : {&r.velocity_a_before, &r.velocity_a_after, &r.velocity_b_before,
                     &r.velocity_b_after, &r.angular_velocity_a_before, &r.angular_velocity_a_after,
                     &r.angular_velocity_b_before, &r.angular_velocity_b_after}) {
    hash.add(*v);
  }
}

void addContact(TraceHash& hash, const ContactRecord& r) {
  hash.add(r.time);
  hash.add(static_cast<std::uint64_t>(r.body_a));
  hash.add(static_cast<std::uint64_t>(r.other));
  hash.add(r.other_is_obstacle);
  hash.add(r.contact_point);
  hash.add(r.normal);
  hash.add(r.normal_force);
  hash.add(r.friction_force);
  hash.add(static_cast<std::uint64_t>(r.state));
  hash.add(r.since);
}

/// An obstacle on a tf frame that moves in a straight line (the scene player's `player/frames`).
struct MovingFrame {
  std::string frame;
  V position = V::Zero();
  V velocity = V::Zero();
};

/// One run of the trace: a scene played at `rate` for `duration` s.
struct TraceRun {
  std::string name;
  Scene scene;
  double duration = 1.0;
  double rate = 100.0;
  std::vector<MovingFrame> frames;
};

struct TraceLine {
  std::size_t impacts = 0, contacts = 0;
  std::uint64_t hash = 0;
};

/// Plays a run as bench/accuracy/ours.cpp does and hashes what the monitor reports.
TraceLine play(const TraceRun& run) {
  const Scene& scene = run.scene;
  MonitorSettings settings;
  settings.body_timeout = 2 * run.duration + 1;
  ImpactMonitor monitor(scene, settings);
  Playback playback(scene, settings.contact_tolerance, 0.0);
  std::vector<std::size_t> monitor_index;
  for (const BodySpec& body : scene.bodies) monitor_index.push_back(*monitor.bodyIndex(body.id));
  const bool exact_contact = scene.detection == Detection::kContinuous;

  TraceLine line;
  TraceHash hash;
  const auto updates = static_cast<long>(std::llround(run.duration * run.rate));
  std::vector<BodyStateSample> states(scene.bodies.size());
  for (long k = 0; k <= updates; ++k) {
    const double t = static_cast<double>(k) / run.rate;
    for (std::size_t i = 0; i < states.size(); ++i) {
      states[i].body = monitor_index[i];
      states[i].time = t;
      states[i].position = playback.position(i, t);
      states[i].velocity = playback.velocity(i, t);
      states[i].angular_velocity = playback.angularVelocity(i, t);
      hash.add(states[i].position);
      hash.add(states[i].velocity);
      hash.add(states[i].angular_velocity);
    }
    for (const MovingFrame& frame : run.frames) {
      for (std::size_t i = 0; i < monitor.obstacleCount(); ++i) {
        const ObstacleSpec& spec = monitor.obstacle(i);
        if (spec.frame != frame.frame) continue;
        RigidPose pose;  // the frame's; the obstacle's shape is placed on it
        pose.time = t;
        pose.transform.translation() = frame.position + frame.velocity * t;
        pose.velocity = frame.velocity;
        monitor.setObstaclePose(i, pose);
      }
    }
    const StepReport report = monitor.step(t, states);
    for (const ImpactRecord& impact : report.impacts) addImpact(hash, impact);
    for (const ContactRecord& contact : report.contacts) addContact(hash, contact);
    hash.add(static_cast<std::uint64_t>(report.impacts.size()));
    hash.add(static_cast<std::uint64_t>(report.contacts.size()));
    hash.add(static_cast<std::uint64_t>(report.stale_states));
    hash.add(report.truncated);
    hash.add(static_cast<std::uint64_t>(report.fallbacks));
    hash.add(static_cast<std::uint64_t>(report.stepped_bodies));
    line.impacts += report.impacts.size();
    line.contacts += report.contacts.size();
    const std::vector<std::size_t> refused =
        playback.applyImpacts(monitor, report.impacts, exact_contact);
    hash.add(static_cast<std::uint64_t>(refused.size()));
    for (const std::size_t index : refused) hash.add(static_cast<std::uint64_t>(index));
  }
  line.hash = hash.value();
  return line;
}

/// How long a benchmark scene is played in the trace: its own duration, but the large piles and
/// the longest runs cut to their first part, so that the whole trace takes seconds.
double traceDuration(const bench::BenchScene& bench) {
  if (bench.name == "ball_pile_1000" || bench.name == "ball_pile_300") return 0.3;
  if (bench.name == "ball_pile_100_4s") return 1.5;
  if (bench.name.rfind("ball_pile_", 0) == 0) return 1.0;
  if (bench.name == "sphere_gas_60s") return 5.0;
  return std::min(bench.duration, 20.0);  // bounce_e1: its first 20 s of 903.5
}

std::vector<TraceRun> traceRuns() {
  std::vector<TraceRun> runs;
  // config/scenes, as the scene player plays them (100 Hz).
  runs.push_back({"scenes/billiards_break", yamlBilliardsBreak(), 1.0, 100.0, {}});
  runs.push_back({"scenes/corner", yamlCorner(), 2.0, 100.0, {}});
  runs.push_back({"scenes/cradle", yamlCradle(), 1.0, 100.0, {}});
  runs.push_back({"scenes/default", yamlDefault(), 0.1, 100.0, {}});
  runs.push_back({"scenes/drop_test", yamlDropTest(), 3.0, 100.0, {}});
  // The paddle's frame: player/frames of paddle.yaml.
  runs.push_back({"scenes/paddle",
                  yamlPaddle(),
                  1.5,
                  100.0,
                  {{"paddle_link", V(1.0, 0.0, 0.0), V(-0.5, 0.0, 0.0)}}});
  runs.push_back({"scenes/pile", yamlPile(), 1.5, 100.0, {}});
  runs.push_back({"scenes/rough_pile", yamlRoughPile(), 1.0, 100.0, {}});
  runs.push_back({"scenes/stack", yamlStack(), 1.0, 100.0, {}});
  runs.push_back({"scenes/two_balls_oblique", yamlTwoBallsOblique(), 1.0, 100.0, {}});
  // The accuracy benchmark's scenes at 100 Hz: each effect variant under both detections, the
  // stepped run where the benchmark has one, and each integration tolerance it measures.
  for (const bench::BenchScene& bench : bench::benchScenes()) {
    const double duration = traceDuration(bench);
    std::vector<std::string> variants = {"none"};
    variants.insert(variants.end(), bench.effect_variants.begin(), bench.effect_variants.end());
    // Obstacles moving at a constant velocity (the moving paddle): on their frames, as
    // bench/accuracy/ours.cpp places them.
    std::vector<MovingFrame> frames;
    for (std::size_t o = 0; o < bench.obstacle_velocities.size(); ++o) {
      MovingFrame frame;
      frame.frame = bench.scene.obstacles[o].frame;
      frame.velocity = bench.obstacle_velocities[o];
      frames.push_back(frame);
    }
    for (const std::string& effects : variants) {
      const std::string name = "bench/" + bench::referenceName(bench, effects);
      Scene scene = bench::withEffects(bench, effects);
      scene.detection = Detection::kContinuous;
      runs.push_back({name + "/continuous", scene, duration, 100.0, frames});
      scene.detection = Detection::kDiscrete;
      runs.push_back({name + "/discrete", scene, duration, 100.0, frames});
    }
    if (!bench.stepped_rates.empty()) {
      Scene scene = bench.scene;
      scene.detection = Detection::kContinuous;
      scene.stepped_cluster_min_bodies = 1;
      runs.push_back({"bench/" + bench.name + "/stepped", scene, duration, 100.0, {}});
    }
    for (const double tolerance : bench.integration_tolerances) {
      Scene scene = bench.scene;
      scene.detection = Detection::kContinuous;
      scene.contact_integration_tolerance = tolerance;
      std::ostringstream name;
      name << "bench/" << bench.name << "/tolerance_" << tolerance;
      runs.push_back({name.str(), scene, duration, 100.0, {}});
    }
  }
  return runs;
}

std::string formatLine(const std::string& name, const TraceLine& line) {
  std::ostringstream out;
  out << name << ' ' << line.impacts << ' ' << line.contacts << ' ' << std::hex << std::setfill('0')
      << std::setw(16) << line.hash;
  return out.str();
}

std::map<std::string, std::string> readDigest(const std::string& path) {
  std::map<std::string, std::string> lines;
  std::ifstream file(path);
  std::string text;
  while (std::getline(file, text)) {
    if (text.empty() || text[0] == '#') continue;
    lines[text.substr(0, text.find(' '))] = text;
  }
  return lines;
}

TEST(Trace, EveryRecordOfEveryScenePlayedIsAsTheDigestSays) {
  const std::string path = COLLISION_RESPONSE_TRACE_DIGEST;
  const std::vector<TraceRun> runs = traceRuns();
  std::vector<std::string> lines;
  for (const TraceRun& run : runs) {
    const auto start = std::chrono::steady_clock::now();
    lines.push_back(formatLine(run.name, play(run)));
    const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
    if (std::getenv("COLLISION_RESPONSE_TRACE_TIMES") != nullptr) {
      std::printf("%8.3f s  %s\n", took.count(), lines.back().c_str());
    }
  }
  const char* write = std::getenv("COLLISION_RESPONSE_WRITE_TRACE");
  if (write != nullptr && std::string(write) == "1") {
    std::ofstream file(path);
    file << "# The trace of test/core/test_trace.cpp: run, impacts, contacts, 64-bit hash.\n";
    file << "# Regenerate only for a change meant to move it (see the test's first lines).\n";
    for (const std::string& line : lines) file << line << '\n';
    ASSERT_TRUE(file.good()) << "could not write " << path;
    std::printf("wrote %zu lines to %s\n", lines.size(), path.c_str());
    return;
  }
  const std::map<std::string, std::string> digest = readDigest(path);
  ASSERT_FALSE(digest.empty()) << "no digest at " << path;
  std::size_t changed = 0;
  std::map<std::string, bool> seen;
  for (const std::string& line : lines) {
    const std::string name = line.substr(0, line.find(' '));
    seen[name] = true;
    const auto it = digest.find(name);
    if (it == digest.end()) {
      ADD_FAILURE() << "run not in the digest: " << line;
      ++changed;
    } else if (it->second != line) {
      ADD_FAILURE() << "the trace of " << name << " moved:\n  digest: " << it->second
                    << "\n  now:    " << line;
      ++changed;
    }
  }
  for (const auto& [name, line] : digest) {
    if (seen.count(name) == 0) {
      ADD_FAILURE() << "run in the digest but not played: " << line;
      ++changed;
    }
  }
  EXPECT_EQ(changed, 0u) << changed << " of " << lines.size() << " runs differ from " << path;
}

}  // namespace
}  // namespace collision_response::core
