// collision_response as a nodelet: the same CollisionResponseNode, in a nodelet manager's
// process, so that body states published by another nodelet reach it without a copy.
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>

#include "collision_response/ros/collision_response_node.h"

namespace collision_response {

class CollisionResponseNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    node_ = std::make_unique<CollisionResponseNode>(getNodeHandle(), getPrivateNodeHandle());
    if (!node_->initialize()) {
      NODELET_FATAL("collision_response: not started (see the error above)");
      node_.reset();
    }
  }

  std::unique_ptr<CollisionResponseNode> node_;
};

}  // namespace collision_response

PLUGINLIB_EXPORT_CLASS(collision_response::CollisionResponseNodelet, nodelet::Nodelet)
