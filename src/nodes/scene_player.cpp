// scene_player: plays a scene file's bodies on `body_states` and applies the impacts it hears.
#include <ros/ros.h>

#include "collision_response/ros/prompt_shutdown.h"
#include "collision_response/ros/scene_player.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "scene_player", ros::init_options::NoSigintHandler);
  // SIGINT ends it within half a second, also in the middle of a long update.
  const collision_response::PromptShutdown prompt_shutdown(0.5);
  collision_response::ScenePlayer player(ros::NodeHandle(), ros::NodeHandle("~"));
  if (!player.initialize()) return 1;
  ros::spin();
  return 0;
}
