// impact_printer: prints each impact on `impacts` as one readable line, its time counted from
// the first state seen on `body_states` (the start of the scene).
//   ~idle_exit (s, default 0 = never): exit once states have stopped for this long.
#include <ros/ros.h>

#include <cstdio>
#include <string>

#include "collision_response/BodyStateArray.h"
#include "collision_response/ImpactArray.h"

namespace {

std::string vectorText(const geometry_msgs::Vector3& v) {
  char text[96];
  std::snprintf(text, sizeof(text), "(%.4g, %.4g, %.4g)", v.x, v.y, v.z);
  return text;
}

class ImpactPrinter {
 public:
  explicit ImpactPrinter(ros::NodeHandle& node) {
    states_ = node.subscribe("body_states", 10, &ImpactPrinter::onStates, this);
    impacts_ = node.subscribe("impacts", 100, &ImpactPrinter::onImpacts, this);
  }

  bool idleFor(double seconds) const {
    return !last_state_.isZero() && (ros::WallTime::now() - last_state_).toSec() > seconds;
  }
  int count() const { return count_; }

 private:
  void onStates(const collision_response::BodyStateArray::ConstPtr& message) {
    if (start_.isZero()) start_ = message->header.stamp;
    last_state_ = ros::WallTime::now();
  }

  void onImpacts(const collision_response::ImpactArray::ConstPtr& message) {
    for (const auto& impact : message->impacts) {
      const double time = start_.isZero() ? 0.0 : (impact.header.stamp - start_).toSec();
      std::printf(
          "impact %9.6f s  a %-10s b %-10s e %.3f  J %.4g N s  lost %.4g J  a %s -> %s  b %s -> "
          "%s\n",
          time, impact.body_a.c_str(), impact.body_b.c_str(), impact.restitution, impact.impulse,
          impact.energy_lost, vectorText(impact.velocity_a_before.linear).c_str(),
          vectorText(impact.velocity_a_after.linear).c_str(),
          vectorText(impact.velocity_b_before.linear).c_str(),
          vectorText(impact.velocity_b_after.linear).c_str());
      ++count_;
    }
    std::fflush(stdout);
  }

  ros::Subscriber states_;
  ros::Subscriber impacts_;
  ros::Time start_;
  ros::WallTime last_state_;
  int count_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "impact_printer");
  ros::NodeHandle node;
  ros::NodeHandle private_node("~");
  const double idle_exit = private_node.param("idle_exit", 0.0);
  ImpactPrinter printer(node);
  ros::Rate rate(50.0);
  while (ros::ok()) {
    ros::spinOnce();
    if (idle_exit > 0 && printer.idleFor(idle_exit)) break;
    rate.sleep();
  }
  std::printf("done: %d impacts\n", printer.count());
  return 0;
}
