// empty_service: a std_srvs/Empty service that does nothing, served by a node of this build:
// the floor a ROS service round trip costs, beside ~compute_collision (scripts/performance.sh).
#include <ros/ros.h>
#include <std_srvs/Empty.h>

namespace {
bool nothing(std_srvs::Empty::Request&, std_srvs::Empty::Response&) { return true; }
}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "empty_service");
  ros::NodeHandle private_node("~");
  ros::ServiceServer server = private_node.advertiseService("empty", &nothing);
  ros::spin();
  return 0;
}
