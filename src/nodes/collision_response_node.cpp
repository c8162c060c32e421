// collision_response_node: the collision services (and, with a scene, the impact monitor).
#include <ros/ros.h>

#include "collision_response/ros/collision_response_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "collision_response");
  collision_response::CollisionResponseNode node(ros::NodeHandle(), ros::NodeHandle("~"));
  if (!node.initialize()) return 1;
  ros::spin();
  return 0;
}
