// Start-up with bad parameters, against the real executables (node, nodelet, scene player): each
// refuses to start with an error naming the key and the reason, where it once aborted ("terminate
// called after throwing ros::InvalidNameException"), silently clamped or took a default. The
// test sets the parameters on its own master and runs each executable under a fresh name.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>

namespace {

struct Outcome {
  int status = -1;  ///< exit status, or 128 + signal
  std::string output;
};

/// Runs `command` (stdout and stderr) under `timeout` seconds; its exit status and output.
Outcome run(const std::string& command, int timeout = 30) {
  Outcome result;
  const std::string line = "timeout -s INT " + std::to_string(timeout) + " " + command + " 2>&1";
  FILE* pipe = popen(line.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) result.output += buffer.data();
  const int status = pclose(pipe);
  result.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

XmlRpc::XmlRpcValue ball(const std::string& id, const std::string& topic = "") {
  XmlRpc::XmlRpcValue body;
  body["id"] = id;
  body["mass"] = 1.0;
  body["radius"] = 0.1;
  body["material"] = "tennis_ball";
  if (!topic.empty()) body["topic"] = topic;
  return body;
}

XmlRpc::XmlRpcValue scene(const std::vector<XmlRpc::XmlRpcValue>& bodies) {
  XmlRpc::XmlRpcValue value;
  value["fixed_frame"] = "world";
  for (std::size_t i = 0; i < bodies.size(); ++i) value["bodies"][static_cast<int>(i)] = bodies[i];
  return value;
}

int next_name = 0;

/// Sets `~scene` (and whatever `extra` sets, relative to the node's name) for a fresh node
/// name, runs `executable` under it and returns what happened.
Outcome start(const std::string& executable, const XmlRpc::XmlRpcValue& scene_value,
              const std::function<void(const std::string&)>& extra = nullptr, int timeout = 30) {
  const std::string name = "/bad_" + std::to_string(next_name++);
  ros::param::set(name + "/scene", scene_value);
  if (extra) extra(name);
  return run(executable + " __name:=" + name.substr(1), timeout);
}

const std::string kNode = "rosrun collision_response collision_response_node";

/// Refused at start-up: exit status 1, the message names `key` (under the node's name) and
/// `words`, and nothing aborted.
void expectRefused(const Outcome& result, const std::string& key, const std::string& words) {
  EXPECT_EQ(result.status, 1) << result.output;
  EXPECT_NE(result.output.find(key), std::string::npos) << "no '" << key << "' in:\n"
                                                        << result.output;
  EXPECT_NE(result.output.find(words), std::string::npos) << "no '" << words << "' in:\n"
                                                          << result.output;
  EXPECT_EQ(result.output.find("terminate called"), std::string::npos) << result.output;
}

// Issue 13, item 6: a body's `topic:` that is not a valid name, or is `body_states`, aborted the
// node (terminate called after throwing ros::InvalidNameException / ConflictingSubscription).
TEST(StartupErrors, Item6_ABodyTopicThatIsNotAValidNameStopsTheNodeByName) {
  const Outcome result = start(kNode, scene({ball("ball", "bad topic")}));
  expectRefused(result, "/scene/bodies[0]/topic", "is not a valid topic name");
}

TEST(StartupErrors, Item6_ABodyTopicThatIsBodyStatesStopsTheNodeByName) {
  const Outcome result = start(kNode, scene({ball("ball", "body_states")}));
  expectRefused(result, "/scene/bodies[0]/topic", "the topic of every body's states");
}

// As a nodelet the manager only said "Failed to load": now the nodelet names the key.
TEST(StartupErrors, Item6_AsANodeletTheErrorNamesTheKey) {
  const Outcome result =
      start("rosrun nodelet nodelet standalone collision_response/CollisionResponseNodelet",
            scene({ball("ball", "bad topic")}), nullptr, 10);
  EXPECT_NE(result.output.find("/scene/bodies[0]/topic: 'bad topic' is not a valid topic name"),
            std::string::npos)
      << result.output;
  EXPECT_EQ(result.output.find("terminate called"), std::string::npos) << result.output;
}

// Issue 13, item 7: two bodies given the same topic were accepted, and a correct state on it was
// then warned as belonging to the other one.
TEST(StartupErrors, Item7_TwoBodiesOnOneTopicStopTheNodeByName) {
  const Outcome result =
      start(kNode, scene({ball("one", "/common/state"), ball("two", "/common/state")}));
  expectRefused(result, "/scene/bodies[1]/topic", "is already the topic of 'one'");
}

// Issue 13, item 7: `fixed_frame: /world` was accepted, then every state naming a frame dropped.
TEST(StartupErrors, Item7_AFixedFrameWithALeadingSlashStopsTheNodeByName) {
  XmlRpc::XmlRpcValue value = scene({ball("ball")});
  value["fixed_frame"] = "/world";
  const Outcome result = start(kNode, value);
  expectRefused(result, "/scene/fixed_frame", "tf2 frame ids have none (use 'world')");
}

// Issue 13, item 7: `contact_tolerance: 1e6` (a fraction) was accepted: bodies 10 m apart touched.
TEST(StartupErrors, Item7_AContactToleranceBeyondAFractionStopsTheNodeByName) {
  const Outcome result = start(kNode, scene({ball("ball")}), [](const std::string& name) {
    ros::param::set(name + "/contact_tolerance", 1e6);
  });
  expectRefused(result, "/contact_tolerance",
                "must be a fraction of the contact distance in [0, 1)");
}

// Issue 13, item 8: wrong-typed parameters started the node with the defaults and no word.
TEST(StartupErrors, Item8_WrongTypedParametersStopTheNodeByName) {
  const std::vector<std::tuple<std::string, XmlRpc::XmlRpcValue, std::string>> cases = [] {
    XmlRpc::XmlRpcValue list;
    list[0] = 1;
    list[1] = 2;
    return std::vector<std::tuple<std::string, XmlRpc::XmlRpcValue, std::string>>{
        {"transform_timeout", "abc", "must be a number, got a string ('abc')"},
        {"max_states", "lots", "must be an integer, got a string ('lots')"},
        {"queue_size", true, "must be an integer, got a boolean (true)"},
        {"body_timeout", list, "must be a number, got a list of 2"}};
  }();
  for (const auto& [key, value, words] : cases) {
    const Outcome result =
        start(kNode, scene({ball("ball")}), [&key = key, &value = value](const std::string& name) {
          ros::param::set(name + "/" + key, value);
        });
    expectRefused(result, "/" + key + ": ", words);
  }
}

TEST(StartupErrors, Item8_AMisspelledParameterStopsTheNodeByName) {
  const Outcome result = start(kNode, scene({ball("ball")}), [](const std::string& name) {
    ros::param::set(name + "/transform_timout", 0.5);
  });
  expectRefused(result, "/transform_timout", "unknown key");
}

TEST(StartupErrors, Item8_TheScenePlayersParametersAreTypedToo) {
  const Outcome result =
      start("rosrun collision_response scene_player", scene({ball("ball")}),
            [](const std::string& name) { ros::param::set(name + "/rate", "fast"); });
  expectRefused(result, "/rate", "must be a number, got a string ('fast')");
}

// Issue 27, item 4: `~diagnostic_period: 1e10` ended the node with "Duration is out of dual
// 32-bit range", naming no key; `~frame_velocity_interval: 1e10` and
// `~impact_marker_lifetime: 1e10` started it, and then every message was an internal error. A
// duration a ros::Duration cannot hold (its seconds an int32: at most 2147483647 s) now stops
// the node at start-up with the key named; so does the scene player's rate whose period is one.
TEST(StartupErrors, Issue27_Item4_ADurationNoRosDurationHoldsStopsTheNodeByName) {
  for (const std::string key :
       {"diagnostic_period", "frame_velocity_interval", "impact_marker_lifetime"}) {
    const Outcome result = start(kNode, scene({ball("ball")}), [&key](const std::string& name) {
      ros::param::set(name + "/" + key, 1e10);
    });
    expectRefused(result, "/" + key + ": ",
                  "1e+10 s is longer than a ros::Duration can hold (2147483647 s)");
    EXPECT_EQ(result.output.find("out of dual 32-bit range"), std::string::npos) << result.output;
  }
  const Outcome player =
      start("rosrun collision_response scene_player", scene({ball("ball")}),
            [](const std::string& name) { ros::param::set(name + "/rate", 1e-10); });
  expectRefused(player, "/rate: ", "1e-10 Hz is too slow");
}

// Issue 27, item 5: a body placed past where the monitor resolves contacts (x = 1.7e308) is
// refused at start-up by the node and the scene player, naming the coordinate.
TEST(StartupErrors, Issue27_Item5_ABodyPlacedAtXOf1point7e308StopsTheNodeAndThePlayerByName) {
  for (const std::string& executable :
       {kNode, std::string("rosrun collision_response scene_player")}) {
    XmlRpc::XmlRpcValue body = ball("ball");
    body["position"][0] = 1.7e308;
    body["position"][1] = 0.0;
    body["position"][2] = 0.05;
    expectRefused(start(executable, scene({body})), "/scene/bodies[0]/position.x: ",
                  "1.7e+308 m is beyond where the monitor can resolve a contact");
  }
}

// The stepped clusters' keys (README, "Scene file"), checked at start-up by the node and the
// scene player alike, each refusal naming the key and the value.
TEST(StartupErrors, SteppedClusterKeysOutOfRangeStopTheNodeAndThePlayerByName) {
  for (const std::string& executable :
       {kNode, std::string("rosrun collision_response scene_player")}) {
    XmlRpc::XmlRpcValue value = scene({ball("ball")});
    value["stepped_cluster_min_bodies"] = -1;
    expectRefused(start(executable, value),
                  "/scene/stepped_cluster_min_bodies: ", "must be an integer >= 0, got -1");
    value = scene({ball("ball")});
    value["stepped_cluster_time_step"] = 2.0;
    expectRefused(start(executable, value),
                  "/scene/stepped_cluster_time_step: ", "must be in [1e-4, 1] s, got 2");
  }
}

// The other side: every scene the package ships (config/scenes/, and the tests' own) starts the
// node and the scene player: no shipped key or value is refused.
TEST(StartupErrors, EveryShippedSceneStartsTheNodeAndThePlayer) {
  for (const std::string file :
       {"billiards_break", "cradle", "default", "drop_test", "paddle", "two_balls_oblique"}) {
    for (const std::string& executable :
         {kNode, std::string("rosrun collision_response scene_player")}) {
      const std::string name = "/shipped_" + std::to_string(next_name++);
      ASSERT_EQ(std::system(("rosparam load " + std::string(COLLISION_RESPONSE_SCENES) + "/" +
                             file + ".yaml " + name)
                                .c_str()),
                0);
      const Outcome result = run(executable + " __name:=" + name.substr(1), 5);
      EXPECT_EQ(result.status, 124) << file << " did not keep running:\n" << result.output;
      const bool node = executable == kNode;
      EXPECT_NE(
          result.output.find(node ? "collision_response: scene: fixed_frame" : "scene_player: "),
          std::string::npos)
          << file << " did not start:\n"
          << result.output;
      EXPECT_EQ(result.output.find("FATAL"), std::string::npos) << file << ":\n" << result.output;
      EXPECT_EQ(result.output.find("terminate called"), std::string::npos) << result.output;
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "startup_errors_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
