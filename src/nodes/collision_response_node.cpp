// collision_response_node: the collision services (and, with a scene, the impact monitor).
#include <ros/ros.h>

#include "collision_response/ros/collision_response_node.h"
#include "collision_response/ros/prompt_shutdown.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "collision_response", ros::init_options::NoSigintHandler);
  // SIGINT ends it within half a second, also in the middle of a long update.
  const collision_response::PromptShutdown prompt_shutdown(0.5);
  collision_response::CollisionResponseNode node(ros::NodeHandle(), ros::NodeHandle("~"));
  if (!node.initialize()) return 1;
  ros::spin();
  return 0;
}
