// empty_service: two services that do no work, served by a node of this build (both measured by
// bench/node_benchmark.cpp, run by scripts/performance.sh):
//   ~empty            std_srvs/Empty: the floor a ROS service round trip costs, beside
//                     ~compute_collision.
//   ~echo_prediction  collision_response/PredictImpacts with no physics: it answers a response of
//                     the size the node's ~predict_impacts gives a request of that shape (README,
//                     "Prediction"): success, a message as long as the node's summary
//                     ("2 impact(s) in 0.5776324075360783 s, effects gravity, spin, drag,
//                     magnus" for the serve), max_impacts impacts of the body on "table", a final
//                     state, no lasting contacts, no crossing, and ceil(horizon / sample_period)
//                     + 1 samples when sample_period > 0. Every number is zero, every string as
//                     long as the node's. It is the floor of a round trip carrying the same bytes
//                     as ~predict_impacts: what the node's round trip costs beyond it is the
//                     prediction's.
#include <ros/ros.h>
#include <std_srvs/Empty.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>

#include "collision_response/PredictImpacts.h"

namespace {

using collision_response::BodyState;
using collision_response::Impact;
using collision_response::PredictImpacts;

// The node's budgets (srv/PredictImpacts.srv, README "Prediction"): a request past them is cut.
constexpr std::size_t kMaxImpacts = 1000;
constexpr double kMaxHorizon = 60.0;  // s
constexpr double kMaxSamples = 100000;
// The node's answers are in the scene's fixed frame: "world" in config/scenes/*.yaml.
const char* const kFixedFrame = "world";

bool nothing(std_srvs::Empty::Request&, std_srvs::Empty::Response&) { return true; }

BodyState stateOf(const std::string& id) {
  BodyState state;
  state.header.frame_id = kFixedFrame;
  state.id = id;
  state.pose.orientation.w = 1.0;
  return state;
}

bool echoPrediction(PredictImpacts::Request& request, PredictImpacts::Response& response) {
  const std::string& id = request.body.id;
  const std::size_t impacts = std::min<std::size_t>(request.max_impacts, kMaxImpacts);
  response.success = true;
  // The node's summary: the count, the end's instant as the shortest decimal that reads back
  // (16 significant digits for the serve's second bounce, 0.5776324075360783 s), and the effects
  // (the request's, else the serve scene's).
  std::string effects;
  for (const std::string& effect : request.effects) {
    effects += (effects.empty() ? "" : ", ") + effect;
  }
  if (effects.empty()) effects = "gravity, spin, drag, magnus";
  char instant[32];
  std::snprintf(instant, sizeof instant, "%.16f", 0.5);
  response.message =
      std::to_string(impacts) + " impact(s) in " + instant + " s, effects " + effects;
  response.impacts.resize(impacts);
  for (Impact& impact : response.impacts) {
    impact.header.frame_id = kFixedFrame;
    impact.body_a = id;
    impact.body_b = "table";
  }
  response.final_state = stateOf(id);
  // The path as the node samples one that runs to the horizon: its start, then one sample at the
  // end of each of ceil(horizon / sample_period) pieces (at most 100,000).
  const double horizon = std::min(request.horizon, kMaxHorizon);
  if (request.sample_period > 0.0 && horizon > 0.0) {
    const double pieces = std::min(std::ceil(horizon / request.sample_period), kMaxSamples);
    response.samples.assign(static_cast<std::size_t>(pieces) + 1, stateOf(id));
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "empty_service");
  ros::NodeHandle private_node("~");
  ros::ServiceServer server = private_node.advertiseService("empty", &nothing);
  ros::ServiceServer echo = private_node.advertiseService("echo_prediction", &echoPrediction);
  ros::spin();
  return 0;
}
